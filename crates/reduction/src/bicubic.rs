//! Bicubic splines over a tensor grid: the tensor product of two natural C²
//! cubic splines ([`crate::CubicSpline`]), for vector-valued data, with the
//! partial derivatives up to the third order that an interpolated basis over
//! two configuration coordinates needs ((F.6) in two parameters).
//!
//! A cubic spline is linear in its data: on interval i its value and
//! derivatives are weights times (y_i, y_(i+1), m_i, m_(i+1)), m the second
//! derivatives at the knots. The tensor product on the cell (i, j) is then
//! the sum over the four corners of the weights in s1 times the weights in
//! s2 applied to F (the values), F,11 (the natural spline's second
//! derivatives along each row), F,22 (along each column) and F,1122 (F,11's
//! second derivatives along each column). At a fixed s2 this is the spline
//! in s1 through the column splines' values there, and the other way round.

use crate::spline::{check_knots, interval_weights, natural_second_derivatives};
use crate::ReductionError;

/// The partial derivative orders (o1, o2) that [`BicubicSpline::eval`]
/// writes, in this order: value, first, second and third derivatives.
pub const ORDERS: [(usize, usize); 10] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (2, 0),
    (1, 1),
    (0, 2),
    (3, 0),
    (2, 1),
    (1, 2),
    (0, 3),
];

/// The index in [`ORDERS`] of the partial derivative (o1, o2), o1 + o2 ≤ 3.
pub const fn order_index(o1: usize, o2: usize) -> usize {
    let total = o1 + o2;
    // orders of lower total come first: 1 + 2 + … + total of them
    total * (total + 1) / 2 + o2
}

/// A bicubic spline through y(s1_i, s2_j) ∈ ℝᵈ on a tensor grid.
#[derive(Clone, Debug)]
pub struct BicubicSpline {
    s1: Vec<f64>,
    s2: Vec<f64>,
    /// Per grid point (index i + n1 j): F, F,11, F,22, F,1122.
    data: [Vec<Vec<f64>>; 4],
}

impl BicubicSpline {
    /// Builds the spline through `y` at the grid points (i, j), index
    /// i + n1 j (s1 fastest); both knot vectors need at least 2 finite,
    /// strictly increasing values.
    pub fn new(s1: Vec<f64>, s2: Vec<f64>, y: Vec<Vec<f64>>) -> Result<Self, ReductionError> {
        let (n1, n2) = (s1.len(), s2.len());
        if n1 < 2 || n2 < 2 || y.len() != n1 * n2 {
            return Err(ReductionError::Invalid(format!(
                "a bicubic spline needs ≥ 2 knots in each coordinate and one value per grid \
                 point: {n1} × {n2} knots, {} values",
                y.len()
            )));
        }
        check_knots(&s1, "the first coordinate's")?;
        check_knots(&s2, "the second coordinate's")?;
        let d = y[0].len();
        if y.iter().any(|v| v.len() != d) {
            return Err(ReductionError::Invalid(
                "bicubic spline values of different lengths".into(),
            ));
        }
        let row = |f: &[Vec<f64>], j: usize| -> Vec<Vec<f64>> { f[n1 * j..n1 * (j + 1)].to_vec() };
        let col = |f: &[Vec<f64>], i: usize| -> Vec<Vec<f64>> {
            (0..n2).map(|j| f[i + n1 * j].clone()).collect()
        };
        let mut f11 = vec![vec![]; n1 * n2];
        for j in 0..n2 {
            for (i, m) in natural_second_derivatives(&s1, &row(&y, j))
                .into_iter()
                .enumerate()
            {
                f11[i + n1 * j] = m;
            }
        }
        let (mut f22, mut f1122) = (vec![vec![]; n1 * n2], vec![vec![]; n1 * n2]);
        for i in 0..n1 {
            let a = natural_second_derivatives(&s2, &col(&y, i));
            let b = natural_second_derivatives(&s2, &col(&f11, i));
            for (j, (a, b)) in a.into_iter().zip(b).enumerate() {
                f22[i + n1 * j] = a;
                f1122[i + n1 * j] = b;
            }
        }
        Ok(Self {
            s1,
            s2,
            data: [y, f11, f22, f1122],
        })
    }

    /// The knots of the two coordinates.
    pub fn knots(&self) -> (&[f64], &[f64]) {
        (&self.s1, &self.s2)
    }

    /// The length d of each value.
    pub fn dim(&self) -> usize {
        self.data[0][0].len()
    }

    /// A work array for [`eval`](Self::eval): one vector per entry of
    /// [`ORDERS`].
    pub fn work(&self) -> Vec<Vec<f64>> {
        vec![vec![0.0; self.dim()]; ORDERS.len()]
    }

    /// The partial derivatives of the first `count` entries of [`ORDERS`]
    /// (1: the value, 3: and the gradient, 6: up to the second, 10: up to
    /// the third derivatives) at (s1, s2), written into `out[0..count]`
    /// (outside the grid the end cells are extended).
    pub fn eval(&self, s1: f64, s2: f64, count: usize, out: &mut [Vec<f64>]) {
        let (i, w1) = interval_weights(&self.s1, s1);
        let (j, w2) = interval_weights(&self.s2, s2);
        let n1 = self.s1.len();
        for o in out.iter_mut().take(count) {
            o.fill(0.0);
        }
        // corner (a, b) of the cell; kind k: F, F,11, F,22, F,1122, whose
        // weights are the value weights (y) or the curvature weights (m)
        // in each coordinate
        for b in 0..2 {
            for a in 0..2 {
                let p = (i + a) + n1 * (j + b);
                for (k, (m1, m2)) in [(false, false), (true, false), (false, true), (true, true)]
                    .into_iter()
                    .enumerate()
                {
                    let src = &self.data[k][p];
                    let (c1, c2) = (a + 2 * usize::from(m1), b + 2 * usize::from(m2));
                    for (o, (o1, o2)) in ORDERS.iter().enumerate().take(count) {
                        let w = w1[*o1][c1] * w2[*o2][c2];
                        if w != 0.0 {
                            for (y, s) in out[o].iter_mut().zip(src) {
                                *y += w * s;
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CubicSpline;

    fn grid() -> (Vec<f64>, Vec<f64>) {
        (vec![-0.4, -0.1, 0.0, 0.3, 0.7], vec![0.0, 0.2, 0.5, 0.6])
    }

    fn f(x: f64, y: f64) -> Vec<f64> {
        vec![(1.3 * x).sin() * (0.7 + y * y), x * y.exp()]
    }

    #[test]
    fn order_indices_follow_the_list() {
        for (k, (a, b)) in ORDERS.iter().enumerate() {
            assert_eq!(order_index(*a, *b), k);
        }
    }

    #[test]
    fn interpolates_and_its_derivatives_match_differences() {
        let (s1, s2) = grid();
        let y: Vec<Vec<f64>> = s2
            .iter()
            .flat_map(|b| s1.iter().map(move |a| f(*a, *b)))
            .collect();
        let sp = BicubicSpline::new(s1.clone(), s2.clone(), y).unwrap();
        let mut w = sp.work();
        for b in &s2 {
            for a in &s1 {
                sp.eval(*a, *b, 1, &mut w);
                let e = f(*a, *b);
                assert!((w[0][0] - e[0]).abs() < 1e-14 && (w[0][1] - e[1]).abs() < 1e-14);
            }
        }
        // every partial derivative against central differences of the one
        // below it, inside cells and beyond the grid's ends
        let h = 1e-5;
        let (mut p, mut m) = (sp.work(), sp.work());
        for &(x, yv) in &[(0.15, 0.33), (-0.3, 0.55), (0.65, 0.05), (0.8, -0.1)] {
            sp.eval(x, yv, 10, &mut w);
            for (o, (o1, o2)) in ORDERS.iter().enumerate().skip(1) {
                // differentiate the lower order along a coordinate it has
                let (lower, dx, dy) = if *o1 > 0 {
                    (order_index(o1 - 1, *o2), h, 0.0)
                } else {
                    (order_index(*o1, o2 - 1), 0.0, h)
                };
                sp.eval(x + dx, yv + dy, 10, &mut p);
                sp.eval(x - dx, yv - dy, 10, &mut m);
                for c in 0..2 {
                    let fd = (p[lower][c] - m[lower][c]) / (2.0 * h);
                    assert!(
                        (fd - w[o][c]).abs() < 1e-5 * (1.0 + w[o][c].abs()),
                        "order ({o1}, {o2}) component {c} at ({x}, {yv}): {fd} against {}",
                        w[o][c]
                    );
                }
            }
        }
    }

    #[test]
    fn data_of_one_coordinate_give_its_cubic_spline() {
        let (s1, s2) = grid();
        let g = |x: f64| vec![(2.0 * x).cos(), x.powi(3)];
        let y: Vec<Vec<f64>> = s2.iter().flat_map(|_| s1.iter().map(|a| g(*a))).collect();
        let sp = BicubicSpline::new(s1.clone(), s2.clone(), y).unwrap();
        let one = CubicSpline::new(s1.clone(), s1.iter().map(|a| g(*a)).collect()).unwrap();
        let (mut w, mut w1) = (sp.work(), one.work());
        for &(x, yv) in &[(0.1, 0.1), (-0.35, 0.58), (0.5, 0.3)] {
            sp.eval(x, yv, 10, &mut w);
            one.eval(x, &mut w1);
            for o1 in 0..4 {
                for c in 0..2 {
                    assert!((w[order_index(o1, 0)][c] - w1[o1][c]).abs() < 1e-13);
                }
            }
            for o in [(0, 1), (1, 1), (0, 2), (2, 1), (1, 2), (0, 3)] {
                assert!(w[order_index(o.0, o.1)].iter().all(|v| v.abs() < 1e-12));
            }
        }
    }

    #[test]
    fn bad_grids_are_refused() {
        let y = vec![vec![0.0]; 4];
        assert!(BicubicSpline::new(vec![0.0, 1.0], vec![0.0, 1.0], y.clone()).is_ok());
        assert!(BicubicSpline::new(vec![0.0], vec![0.0, 1.0, 2.0, 3.0], y.clone()).is_err());
        assert!(BicubicSpline::new(vec![1.0, 0.0], vec![0.0, 1.0], y.clone()).is_err());
        assert!(BicubicSpline::new(vec![0.0, f64::NAN], vec![0.0, 1.0], y.clone()).is_err());
        assert!(BicubicSpline::new(vec![0.0, 1.0, 2.0], vec![0.0, 1.0], y).is_err());
    }
}
