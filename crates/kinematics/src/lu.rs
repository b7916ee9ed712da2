//! A dense LU factorization (faer, partial pivoting, in place in memory
//! kept between factorizations) that reports singularity instead of
//! producing infinities.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
use faer::linalg::triangular_solve as tri;
use faer::{Mat, MatMut, MatRef, Par};

/// A factorized square matrix: PA = LU with L (unit diagonal) and U stored
/// in one column-major matrix, and the row permutation P.
pub struct DenseLu {
    lu: Mat<f64>,
    /// (PA)ᵢ = A\[fwd\[i\]\].
    fwd: Vec<usize>,
    bwd: Vec<usize>,
    /// One column of work for the row permutation of multi-column solves.
    col: Vec<f64>,
    mem: Option<MemBuffer>,
    factored: bool,
    /// Smallest |Uᵢᵢ| / largest |Uᵢᵢ| of the last factorization.
    pub pivot_ratio: f64,
}

impl Default for DenseLu {
    fn default() -> Self {
        Self {
            lu: Mat::new(),
            fwd: vec![],
            bwd: vec![],
            col: vec![],
            mem: None,
            factored: false,
            pivot_ratio: 0.0,
        }
    }
}

impl std::fmt::Debug for DenseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLu")
            .field("n", &self.lu.nrows())
            .field("factored", &self.factored)
            .field("pivot_ratio", &self.pivot_ratio)
            .finish()
    }
}

/// Pivot ratio below which a matrix is treated as singular.
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-13;

impl DenseLu {
    /// Factorizes `a`; returns false if it is (numerically) singular or not
    /// finite. Memory is allocated on the first call for a size only.
    pub fn factor(&mut self, a: MatRef<'_, f64>) -> bool {
        let n = a.nrows();
        if self.lu.nrows() != n || self.mem.is_none() {
            self.lu = Mat::zeros(n, n);
            self.fwd = vec![0; n];
            self.bwd = vec![0; n];
            self.col = vec![0.0; n];
            self.mem = Some(MemBuffer::new(lu_in_place_scratch::<usize, f64>(
                n,
                n,
                Par::Seq,
                Default::default(),
            )));
        }
        self.factored = false;
        if n == 0 {
            self.pivot_ratio = 1.0;
            self.factored = true;
            return true;
        }
        self.lu.copy_from(a);
        let mem = self.mem.as_mut().expect("allocated above");
        lu_in_place(
            self.lu.as_mut(),
            &mut self.fwd,
            &mut self.bwd,
            Par::Seq,
            MemStack::new(mem),
            Default::default(),
        );
        let (mut mn, mut mx) = (f64::INFINITY, 0.0f64);
        for i in 0..n {
            let v = self.lu[(i, i)].abs();
            mn = mn.min(v);
            mx = mx.max(v);
        }
        self.pivot_ratio = if mx > 0.0 && mx.is_finite() {
            mn / mx
        } else {
            0.0
        };
        // a non-finite entry leaves a non-finite pivot somewhere, or NaN ratio
        self.factored = self.pivot_ratio > SINGULAR_PIVOT_RATIO;
        self.factored
    }

    /// False (and B set to NaN) when there is nothing to solve with.
    fn ready(&self, mut b: MatMut<'_, f64>) -> bool {
        if b.nrows() == 0 || b.ncols() == 0 {
            return false;
        }
        if !self.factored {
            b.fill(f64::NAN);
        }
        self.factored
    }

    /// B ← P B (`forward`) or B ← Pᵀ B, column by column.
    fn permute_rows(&mut self, mut b: MatMut<'_, f64>, forward: bool) {
        let col = &mut self.col;
        for j in 0..b.ncols() {
            for (i, &p) in self.fwd.iter().enumerate() {
                if forward {
                    col[i] = b[(p, j)];
                } else {
                    col[p] = b[(i, j)];
                }
            }
            for (i, c) in col.iter().enumerate() {
                b[(i, j)] = *c;
            }
        }
    }

    /// Solves A X = B in place (NaN without a successful factorization).
    pub fn solve_in_place(&mut self, mut b: MatMut<'_, f64>) {
        if !self.ready(b.as_mut()) {
            return;
        }
        self.permute_rows(b.as_mut(), true);
        tri::solve_unit_lower_triangular_in_place(self.lu.as_ref(), b.as_mut(), Par::Seq);
        tri::solve_upper_triangular_in_place(self.lu.as_ref(), b, Par::Seq);
    }

    /// Solves Aᵀ X = B in place: Aᵀ = Uᵀ Lᵀ P.
    pub fn solve_transpose_in_place(&mut self, mut b: MatMut<'_, f64>) {
        if !self.ready(b.as_mut()) {
            return;
        }
        tri::solve_lower_triangular_in_place(self.lu.transpose(), b.as_mut(), Par::Seq);
        tri::solve_unit_upper_triangular_in_place(self.lu.transpose(), b.as_mut(), Par::Seq);
        self.permute_rows(b, false);
    }

    /// Solves A x = b for a vector, by columns of the factors (each update
    /// one contiguous axpy), using `buf` (n × 1) as work space.
    pub fn solve_vec(&self, b: &mut [f64], buf: &mut Mat<f64>) {
        let n = b.len();
        if n == 0 {
            return;
        }
        if !self.factored {
            b.fill(f64::NAN);
            return;
        }
        let y = &mut buf.col_as_slice_mut(0)[..n];
        for i in 0..n {
            y[i] = b[self.fwd[i]];
        }
        // L y = P b
        for j in 0..n {
            let yj = y[j];
            if yj != 0.0 {
                let col = &self.lu.col_as_slice(j)[j + 1..n];
                for (yi, l) in y[j + 1..].iter_mut().zip(col) {
                    *yi -= l * yj;
                }
            }
        }
        // U x = y
        for j in (0..n).rev() {
            let col = self.lu.col_as_slice(j);
            let xj = y[j] / col[j];
            y[j] = xj;
            if xj != 0.0 {
                for (yi, u) in y[..j].iter_mut().zip(&col[..j]) {
                    *yi -= u * xj;
                }
            }
        }
        b.copy_from_slice(y);
    }

    /// Solves Aᵀ x = b for a vector, using `buf` (n × 1) as work space.
    pub fn solve_transpose_vec(&mut self, b: &mut [f64], buf: &mut Mat<f64>) {
        let n = b.len();
        buf.col_as_slice_mut(0)[..n].copy_from_slice(b);
        self.solve_transpose_in_place(buf.as_mut().subrows_mut(0, n));
        b.copy_from_slice(&buf.col_as_slice(0)[..n]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every solve against the residual with the original matrix, on
    /// matrices that need row exchanges; refactorizing reuses the memory.
    #[test]
    fn solves_have_small_residuals() {
        let mut lu = DenseLu::default();
        for (n, shift) in [(1usize, 0.0), (5, 0.3), (23, 0.1), (23, -0.7)] {
            let a = Mat::from_fn(n, n, |i, j| {
                let v = ((i * 7 + j * 13) % 11) as f64 - 5.0;
                if i == j {
                    0.1 * v + shift
                } else {
                    v + 0.3 * (i as f64 - j as f64)
                }
            });
            assert!(lu.factor(a.as_ref()));
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.2).collect();
            let mut buf = Mat::zeros(n, 1);
            let check = |x: &[f64], transpose: bool, what: &str| {
                let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                for i in 0..n {
                    let r: f64 = (0..n)
                        .map(|j| if transpose { a[(j, i)] } else { a[(i, j)] } * x[j])
                        .sum::<f64>()
                        - b[i];
                    assert!(r.abs() <= 1e-11 * scale, "{what}, n = {n}: residual {r}");
                }
            };
            let mut x = b.clone();
            lu.solve_vec(&mut x, &mut buf);
            check(&x, false, "solve_vec");
            let mut x = b.clone();
            lu.solve_transpose_vec(&mut x, &mut buf);
            check(&x, true, "solve_transpose_vec");
            let mut m = Mat::from_fn(n, 2, |i, _| b[i]);
            lu.solve_in_place(m.as_mut());
            check(m.col_as_slice(1), false, "solve_in_place");
            let mut m = Mat::from_fn(n, 2, |i, _| b[i]);
            lu.solve_transpose_in_place(m.as_mut());
            check(m.col_as_slice(0), true, "solve_transpose_in_place");
        }
    }

    /// Pseudo-random matrices up to the size of the guidance's Jacobian with
    /// small diagonals, so that partial pivoting exchanges many rows.
    #[test]
    fn random_matrices_with_heavy_pivoting() {
        let mut state = 17u64;
        let mut rnd = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut lu = DenseLu::default();
        for n in [2usize, 8, 31, 77, 80] {
            let a = Mat::from_fn(n, n, |i, j| if i == j { 1e-3 * rnd() } else { rnd() });
            assert!(lu.factor(a.as_ref()));
            let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let mut x = b.clone();
            lu.solve_vec(&mut x, &mut Mat::zeros(n, 1));
            let mut xt = b.clone();
            lu.solve_transpose_vec(&mut xt, &mut Mat::zeros(n, 1));
            let scale = x.iter().chain(&xt).fold(1.0f64, |m, v| m.max(v.abs()));
            for i in 0..n {
                let r: f64 = (0..n).map(|j| a[(i, j)] * x[j]).sum::<f64>() - b[i];
                let rt: f64 = (0..n).map(|j| a[(j, i)] * xt[j]).sum::<f64>() - b[i];
                assert!(r.abs() <= 1e-10 * scale, "n = {n}: residual {r}");
                assert!(
                    rt.abs() <= 1e-10 * scale,
                    "n = {n}: transposed residual {rt}"
                );
            }
        }
    }

    #[test]
    fn singular_and_non_finite_matrices_are_refused_and_solve_to_nan() {
        let mut lu = DenseLu::default();
        let singular = Mat::from_fn(3, 3, |i, j| (i + j) as f64);
        assert!(!lu.factor(singular.as_ref()));
        let mut x = vec![1.0; 3];
        lu.solve_vec(&mut x, &mut Mat::zeros(3, 1));
        assert!(x.iter().all(|v| v.is_nan()));
        let nan = Mat::from_fn(3, 3, |i, j| if i == j { f64::NAN } else { 0.0 });
        assert!(!lu.factor(nan.as_ref()));
    }
}
