//! A dense LU factorization (faer, partial pivoting) that reports singularity
//! instead of producing infinities.

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut, MatRef};

/// A factorized square matrix.
#[derive(Debug)]
pub struct DenseLu {
    lu: Option<PartialPivLu<f64>>,
    /// Smallest |Uᵢᵢ| / largest |Uᵢᵢ| of the last factorization.
    pub pivot_ratio: f64,
}

impl Default for DenseLu {
    fn default() -> Self {
        Self {
            lu: None,
            pivot_ratio: 0.0,
        }
    }
}

/// Pivot ratio below which a matrix is treated as singular.
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-13;

impl DenseLu {
    /// Factorizes `a`; returns false if it is (numerically) singular or not finite.
    pub fn factor(&mut self, a: MatRef<'_, f64>) -> bool {
        let n = a.nrows();
        if n == 0 {
            self.lu = Some(PartialPivLu::new(a));
            self.pivot_ratio = 1.0;
            return true;
        }
        let lu = PartialPivLu::new(a);
        let u = lu.U();
        let (mut mn, mut mx) = (f64::INFINITY, 0.0f64);
        for i in 0..n {
            let v = u[(i, i)].abs();
            mn = mn.min(v);
            mx = mx.max(v);
        }
        self.pivot_ratio = if mx > 0.0 && mx.is_finite() {
            mn / mx
        } else {
            0.0
        };
        self.lu = Some(lu);
        self.pivot_ratio > SINGULAR_PIVOT_RATIO
    }
    /// Solves A X = B in place.
    pub fn solve_in_place(&self, b: MatMut<'_, f64>) {
        if let Some(lu) = &self.lu {
            if b.nrows() > 0 {
                lu.solve_in_place(b);
            }
        }
    }
    /// Solves Aᵀ X = B in place.
    pub fn solve_transpose_in_place(&self, b: MatMut<'_, f64>) {
        if let Some(lu) = &self.lu {
            if b.nrows() > 0 {
                lu.solve_transpose_in_place(b);
            }
        }
    }
    /// Solves A x = b for a vector, using `buf` (n × 1) as work space.
    pub fn solve_vec(&self, b: &mut [f64], buf: &mut Mat<f64>) {
        let n = b.len();
        buf.col_as_slice_mut(0)[..n].copy_from_slice(b);
        self.solve_in_place(buf.as_mut().subrows_mut(0, n));
        b.copy_from_slice(&buf.col_as_slice(0)[..n]);
    }
    /// Solves Aᵀ x = b for a vector, using `buf` (n × 1) as work space.
    pub fn solve_transpose_vec(&self, b: &mut [f64], buf: &mut Mat<f64>) {
        let n = b.len();
        buf.col_as_slice_mut(0)[..n].copy_from_slice(b);
        self.solve_transpose_in_place(buf.as_mut().subrows_mut(0, n));
        b.copy_from_slice(&buf.col_as_slice(0)[..n]);
    }
}
