//! Natural C² cubic splines of vector-valued data, with derivatives up to the
//! third order (thesis (F.6): the third derivative is constant per interval),
//! and cubic Hermite interpolants of values with their first derivatives.

use crate::ReductionError;

/// A natural cubic spline through (s_i, y_i), y_i ∈ ℝᵈ, or the cubic
/// Hermite interpolant of (s_i, y_i, y′_i).
#[derive(Clone, Debug)]
pub struct CubicSpline {
    s: Vec<f64>,
    y: Vec<Vec<f64>>,
    /// Second derivatives at the knots (natural), or the given first
    /// derivatives (Hermite).
    m: Vec<Vec<f64>>,
    hermite: bool,
}

impl CubicSpline {
    /// Builds the spline; the knots must be strictly increasing (at least 2).
    pub fn new(s: Vec<f64>, y: Vec<Vec<f64>>) -> Result<Self, ReductionError> {
        let n = s.len();
        if n < 2 || y.len() != n {
            return Err(ReductionError::Invalid(format!(
                "a spline needs ≥ 2 knots and one value per knot, got {n} knots and {} values",
                y.len()
            )));
        }
        check_knots(&s, "spline")?;
        let d = y[0].len();
        if y.iter().any(|v| v.len() != d) {
            return Err(ReductionError::Invalid(
                "spline values of different lengths".into(),
            ));
        }
        let m = natural_second_derivatives(&s, &y);
        Ok(Self {
            s,
            y,
            m,
            hermite: false,
        })
    }

    /// The cubic Hermite interpolant of the values `y` and first derivatives
    /// `dy` at the knots `s` (C¹; its derivative at a knot is the given one).
    pub fn hermite(
        s: Vec<f64>,
        y: Vec<Vec<f64>>,
        dy: Vec<Vec<f64>>,
    ) -> Result<Self, ReductionError> {
        let mut sp = Self::new(s, y)?;
        let d = sp.y[0].len();
        if dy.len() != sp.s.len() || dy.iter().any(|v| v.len() != d) {
            return Err(ReductionError::Invalid(format!(
                "a Hermite spline needs one derivative of length {d} per knot ({} knots, {} derivatives)",
                sp.s.len(),
                dy.len()
            )));
        }
        if dy.iter().flatten().any(|v| !v.is_finite()) {
            return Err(ReductionError::Invalid(
                "a Hermite spline's derivative is not finite".into(),
            ));
        }
        sp.m = dy;
        sp.hermite = true;
        Ok(sp)
    }

    /// The range of the knots.
    pub fn range(&self) -> (f64, f64) {
        (self.s[0], self.s[self.s.len() - 1])
    }

    /// Value and the first three derivatives at s (outside the knots the end
    /// cubic is extended), written into `out[0..4]` (each of length d).
    pub fn eval(&self, s: f64, out: &mut [Vec<f64>; 4]) {
        let (i, w) = if self.hermite {
            hermite_interval_weights(&self.s, s)
        } else {
            interval_weights(&self.s, s)
        };
        let (y0, y1, m0, m1) = (&self.y[i], &self.y[i + 1], &self.m[i], &self.m[i + 1]);
        for (o, w) in w.iter().enumerate() {
            for c in 0..y0.len() {
                out[o][c] = w[0] * y0[c] + w[1] * y1[c] + w[2] * m0[c] + w[3] * m1[c];
            }
        }
    }

    /// A work array for [`eval`](Self::eval).
    pub fn work(&self) -> [Vec<f64>; 4] {
        let d = self.y[0].len();
        [vec![0.0; d], vec![0.0; d], vec![0.0; d], vec![0.0; d]]
    }
}

/// An error naming `what` unless the knots are finite and strictly increasing.
pub(crate) fn check_knots(s: &[f64], what: &str) -> Result<(), ReductionError> {
    if s.windows(2).any(|w| w[1] <= w[0]) || s.iter().any(|v| !v.is_finite()) {
        return Err(ReductionError::Invalid(format!(
            "{what} knots must be finite and strictly increasing"
        )));
    }
    Ok(())
}

/// The second derivatives at the knots `s` of the natural cubic spline
/// through the values `y` (one vector per knot, all of one length; the knots
/// already checked: at least 2, strictly increasing): the tridiagonal system
/// of the interior knots with zero curvature at both ends, solved by the
/// Thomas algorithm for each component.
pub(crate) fn natural_second_derivatives(s: &[f64], y: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = s.len();
    let d = y.first().map_or(0, |v| v.len());
    let mut m = vec![vec![0.0; d]; n];
    if n <= 2 {
        return m;
    }
    let k = n - 2;
    let h: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
    let mut cp = vec![0.0; k];
    let mut dp = vec![0.0; k];
    cp[0] = h[1] / (2.0 * (h[0] + h[1]));
    dp[0] = 2.0 * (h[0] + h[1]);
    for i in 1..k {
        dp[i] = 2.0 * (h[i] + h[i + 1]) - h[i] * cp[i - 1];
        cp[i] = h[i + 1] / dp[i];
    }
    let mut z = vec![0.0; k];
    for c in 0..d {
        let rhs = |i: usize| {
            6.0 * ((y[i + 2][c] - y[i + 1][c]) / h[i + 1] - (y[i + 1][c] - y[i][c]) / h[i])
        };
        z[0] = rhs(0) / dp[0];
        for i in 1..k {
            z[i] = (rhs(i) - h[i] * z[i - 1]) / dp[i];
        }
        for i in (0..k - 1).rev() {
            z[i] -= cp[i] * z[i + 1];
        }
        for i in 0..k {
            m[i + 1][c] = z[i];
        }
    }
    m
}

/// The interval i of the knots `s` (at least 2) that holds `x`, the end
/// intervals extended beyond the knots.
fn knot_interval(s: &[f64], x: f64) -> usize {
    let n = s.len();
    match s.partition_point(|v| *v <= x) {
        0 => 0,
        p if p >= n => n - 2,
        p => p - 1,
    }
}

/// The interval i of the knots `s` that holds `x` (the end intervals
/// extended beyond the knots) and the weights of a cubic spline's value and
/// first three derivatives there: derivative o at x is
/// w[o][0] y_i + w[o][1] y_(i+1) + w[o][2] m_i + w[o][3] m_(i+1), with y the
/// values and m the second derivatives at the knots. A spline is linear in
/// its data, so the same weights serve every component and the tensor
/// product of two of them (the bicubic spline of [`crate::GridBasis`]).
pub(crate) fn interval_weights(s: &[f64], x: f64) -> (usize, [[f64; 4]; 4]) {
    let i = knot_interval(s, x);
    let h = s[i + 1] - s[i];
    let a = (s[i + 1] - x) / h;
    let b = (x - s[i]) / h;
    (
        i,
        [
            [
                a,
                b,
                (a * a * a - a) * h * h / 6.0,
                (b * b * b - b) * h * h / 6.0,
            ],
            [
                -1.0 / h,
                1.0 / h,
                -(3.0 * a * a - 1.0) * h / 6.0,
                (3.0 * b * b - 1.0) * h / 6.0,
            ],
            [0.0, 0.0, a, b],
            [0.0, 0.0, -1.0 / h, 1.0 / h],
        ],
    )
}

/// The first derivatives at the knots `s` of the natural cubic spline
/// through `y` (as [`natural_second_derivatives`]).
pub(crate) fn natural_first_derivatives(s: &[f64], y: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let m = natural_second_derivatives(s, y);
    (0..s.len())
        .map(|k| {
            let (i, w) = interval_weights(s, s[k]);
            (0..y[k].len())
                .map(|c| {
                    w[1][0] * y[i][c]
                        + w[1][1] * y[i + 1][c]
                        + w[1][2] * m[i][c]
                        + w[1][3] * m[i + 1][c]
                })
                .collect()
        })
        .collect()
}

/// As [`interval_weights`] for the cubic Hermite interpolant, whose data
/// are the values and the first derivatives at the knots: derivative o at
/// x is w[o][0] y_i + w[o][1] y_(i+1) + w[o][2] y′_i + w[o][3] y′_(i+1).
/// C¹ where the derivatives are exact (an equilibrium path's tangents,
/// [`crate::equilibrium_tangents`]), so that the interpolant's derivative
/// at a knot is the path's own.
pub(crate) fn hermite_interval_weights(s: &[f64], x: f64) -> (usize, [[f64; 4]; 4]) {
    let i = knot_interval(s, x);
    let h = s[i + 1] - s[i];
    let t = (x - s[i]) / h;
    let (t2, t3) = (t * t, t * t * t);
    (
        i,
        [
            [
                2.0 * t3 - 3.0 * t2 + 1.0,
                -2.0 * t3 + 3.0 * t2,
                h * (t3 - 2.0 * t2 + t),
                h * (t3 - t2),
            ],
            [
                (6.0 * t2 - 6.0 * t) / h,
                (-6.0 * t2 + 6.0 * t) / h,
                3.0 * t2 - 4.0 * t + 1.0,
                3.0 * t2 - 2.0 * t,
            ],
            [
                (12.0 * t - 6.0) / (h * h),
                (-12.0 * t + 6.0) / (h * h),
                (6.0 * t - 4.0) / h,
                (6.0 * t - 2.0) / h,
            ],
            [
                12.0 / (h * h * h),
                -12.0 / (h * h * h),
                6.0 / (h * h),
                6.0 / (h * h),
            ],
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Hermite interpolant takes the given slopes, is exact for cubics,
    /// its derivatives match central differences, and bad slopes are refused.
    #[test]
    fn the_hermite_form_takes_its_slopes_and_is_exact_for_cubics() {
        let s: Vec<f64> = vec![0.0, 0.3, 0.5, 1.1, 1.4];
        let f = |x: f64| vec![x * x * x - 2.0 * x, 1.0 + x];
        let df = |x: f64| vec![3.0 * x * x - 2.0, 1.0];
        let sp = CubicSpline::hermite(
            s.clone(),
            s.iter().map(|x| f(*x)).collect(),
            s.iter().map(|x| df(*x)).collect(),
        )
        .unwrap();
        let mut w = sp.work();
        for x in [0.0, 0.1, 0.42, 0.8, 1.4, 1.6] {
            sp.eval(x, &mut w);
            for c in 0..2 {
                assert!((w[0][c] - f(x)[c]).abs() < 1e-14, "value at {x}");
                assert!((w[1][c] - df(x)[c]).abs() < 1e-13, "slope at {x}");
            }
            assert!((w[2][0] - 6.0 * x).abs() < 1e-12 && (w[3][0] - 6.0).abs() < 1e-11);
        }
        let (h, mut p, mut m) = (1e-6, sp.work(), sp.work());
        sp.eval(0.7, &mut w);
        sp.eval(0.7 + h, &mut p);
        sp.eval(0.7 - h, &mut m);
        for o in 1..4 {
            let fd = (p[o - 1][0] - m[o - 1][0]) / (2.0 * h);
            assert!(
                (fd - w[o][0]).abs() < 1e-5 * (1.0 + w[o][0].abs()),
                "order {o}"
            );
        }
        let y: Vec<Vec<f64>> = s.iter().map(|x| f(*x)).collect();
        assert!(CubicSpline::hermite(s.clone(), y.clone(), vec![vec![0.0, 0.0]; 4]).is_err());
        assert!(CubicSpline::hermite(s.clone(), y.clone(), vec![vec![0.0]; 5]).is_err());
        assert!(CubicSpline::hermite(s, y, vec![vec![f64::NAN, 0.0]; 5]).is_err());
    }

    #[test]
    fn interpolates_is_c2_and_its_derivatives_match_differences() {
        let s: Vec<f64> = vec![0.0, 0.3, 0.5, 1.1, 1.4, 2.0];
        let y: Vec<Vec<f64>> = s.iter().map(|v| vec![v.sin(), v * v]).collect();
        let sp = CubicSpline::new(s.clone(), y.clone()).unwrap();
        let mut w = sp.work();
        for (k, sk) in s.iter().enumerate() {
            sp.eval(*sk, &mut w);
            assert!((w[0][0] - y[k][0]).abs() < 1e-14 && (w[0][1] - y[k][1]).abs() < 1e-14);
        }
        // continuity of value, first and second derivatives at interior knots
        let (mut l, mut r) = (sp.work(), sp.work());
        for sk in &s[1..s.len() - 1] {
            sp.eval(sk - 1e-12, &mut l);
            sp.eval(sk + 1e-12, &mut r);
            for o in 0..3 {
                assert!((l[o][0] - r[o][0]).abs() < 1e-9, "order {o} at {sk}");
            }
        }
        // derivatives against central differences inside an interval
        let h = 1e-6;
        for &x in &[0.1, 0.7, 1.7] {
            let (mut p, mut m) = (sp.work(), sp.work());
            sp.eval(x, &mut w);
            sp.eval(x + h, &mut p);
            sp.eval(x - h, &mut m);
            for o in 0..3 {
                let fd = (p[o][0] - m[o][0]) / (2.0 * h);
                assert!(
                    (fd - w[o + 1][0]).abs() < 1e-6 * (1.0 + w[o + 1][0].abs()),
                    "order {} at {x}",
                    o + 1
                );
            }
        }
        // natural ends: zero curvature
        sp.eval(0.0, &mut w);
        assert!(w[2][0].abs() < 1e-12);
        assert!(CubicSpline::new(vec![0.0, 0.0], vec![vec![1.0], vec![2.0]]).is_err());
    }
}
