//! Natural C² cubic splines of vector-valued data, with derivatives up to the
//! third order (thesis (F.6): the third derivative is constant per interval).

use crate::ReductionError;

/// A natural cubic spline through (s_i, y_i), y_i ∈ ℝᵈ.
#[derive(Clone, Debug)]
pub struct CubicSpline {
    s: Vec<f64>,
    y: Vec<Vec<f64>>,
    /// Second derivatives at the knots.
    m: Vec<Vec<f64>>,
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
        if s.windows(2).any(|w| w[1] <= w[0]) || s.iter().any(|v| !v.is_finite()) {
            return Err(ReductionError::Invalid(
                "spline knots must be finite and strictly increasing".into(),
            ));
        }
        let d = y[0].len();
        if y.iter().any(|v| v.len() != d) {
            return Err(ReductionError::Invalid(
                "spline values of different lengths".into(),
            ));
        }
        // tridiagonal system for the interior second derivatives (natural ends)
        let mut m = vec![vec![0.0; d]; n];
        if n > 2 {
            let k = n - 2;
            let h: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
            let mut diag = vec![0.0; k];
            let mut off = vec![0.0; k];
            for i in 0..k {
                diag[i] = 2.0 * (h[i] + h[i + 1]);
                off[i] = h[i + 1];
            }
            // Thomas algorithm, one right-hand side per component
            let mut cp = vec![0.0; k];
            let mut dp = vec![0.0; k];
            cp[0] = off[0] / diag[0];
            dp[0] = diag[0];
            for i in 1..k {
                dp[i] = diag[i] - h[i] * cp[i - 1];
                cp[i] = off[i] / dp[i];
            }
            for c in 0..d {
                let rhs: Vec<f64> = (0..k)
                    .map(|i| {
                        6.0 * ((y[i + 2][c] - y[i + 1][c]) / h[i + 1]
                            - (y[i + 1][c] - y[i][c]) / h[i])
                    })
                    .collect();
                let mut z = vec![0.0; k];
                z[0] = rhs[0] / dp[0];
                for i in 1..k {
                    z[i] = (rhs[i] - h[i] * z[i - 1]) / dp[i];
                }
                for i in (0..k - 1).rev() {
                    z[i] -= cp[i] * z[i + 1];
                }
                for i in 0..k {
                    m[i + 1][c] = z[i];
                }
            }
        }
        Ok(Self { s, y, m })
    }

    /// The range of the knots.
    pub fn range(&self) -> (f64, f64) {
        (self.s[0], self.s[self.s.len() - 1])
    }

    /// Value and the first three derivatives at s (outside the knots the end
    /// cubic is extended), written into `out[0..4]` (each of length d).
    pub fn eval(&self, s: f64, out: &mut [Vec<f64>; 4]) {
        let n = self.s.len();
        let i = match self.s.partition_point(|v| *v <= s) {
            0 => 0,
            p if p >= n => n - 2,
            p => p - 1,
        };
        let h = self.s[i + 1] - self.s[i];
        let a = (self.s[i + 1] - s) / h;
        let b = (s - self.s[i]) / h;
        let (y0, y1, m0, m1) = (&self.y[i], &self.y[i + 1], &self.m[i], &self.m[i + 1]);
        for c in 0..y0.len() {
            out[0][c] = a * y0[c]
                + b * y1[c]
                + ((a * a * a - a) * m0[c] + (b * b * b - b) * m1[c]) * h * h / 6.0;
            out[1][c] = (y1[c] - y0[c]) / h
                + ((3.0 * b * b - 1.0) * m1[c] - (3.0 * a * a - 1.0) * m0[c]) * h / 6.0;
            out[2][c] = a * m0[c] + b * m1[c];
            out[3][c] = (m1[c] - m0[c]) / h;
        }
    }

    /// A work array for [`eval`](Self::eval).
    pub fn work(&self) -> [Vec<f64>; 4] {
        let d = self.y[0].len();
        [vec![0.0; d], vec![0.0; d], vec![0.0; d], vec![0.0; d]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
