//! Dense LU factorization with partial pivoting, `P A = L U`, in memory kept
//! between factorizations.
//!
//! This is the factorization of every small square system matrix that is
//! refactorized inside a loop: the mass matrix and the Newton iteration matrix
//! `M + γh C + βh² K` of the time integrators (`flexmb-ode`), the kinematic
//! Jacobian of small mechanisms (`flexmb-kinematics`) and the static tangent
//! (`flexmb-dynamics`). Hence its shape:
//!
//! - [`DenseLu::new`] allocates the factor, the permutation, faer's scratch
//!   memory and one column of work once; [`DenseLu::factor_in_place`],
//!   [`DenseLu::factor`] (for a matrix of the same size) and all solves then
//!   do not allocate;
//! - the matrix can be assembled directly in the factor's storage
//!   ([`DenseLu::matrix_mut`]), so that a per-step refactorization does not
//!   copy it;
//! - a factorization reports its *pivot ratio* min |Uᵢᵢ| / max |Uᵢᵢ| and fails
//!   with a typed [`LuError`] when a pivot is not finite or the ratio is at or
//!   below a threshold ([`SINGULAR_PIVOT_RATIO`] by default, settable with
//!   [`DenseLu::with_singular_pivot_ratio`]), instead of producing infinities;
//! - a solve without a successful factorization sets its right-hand side to
//!   NaN, so that it can never pass for a result.
//!
//! The factorization itself is a plain elimination with partial pivoting
//! for small matrices ([`UNBLOCKED_UP_TO`]) and faer's `lu_in_place` above;
//! the solves are triangular solves on the factors.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
use faer::linalg::triangular_solve as tri;
use faer::{Mat, MatMut, MatRef, Par};

/// Matrices up to this order are factorized by a plain right-looking
/// elimination (`DenseLu::factor_unblocked`), larger ones by faer's
/// recursive blocked LU. For the small Jacobians and mass matrices that are
/// refactorized in every few evaluations faer's blocking and dispatch cost
/// more than the arithmetic: the 33 × 33 kinematic Jacobian of the spatial
/// guidance in nodal DOFs took 57 000 instructions with faer (callgrind),
/// TODO with the plain loop.
pub const UNBLOCKED_UP_TO: usize = 48;

/// Default pivot ratio min |Uᵢᵢ| / max |Uᵢᵢ| at or below which a matrix is
/// treated as (numerically) singular.
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-13;

/// Why an LU factorization is unusable.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum LuError {
    /// The matrix to factor is not square.
    #[error("cannot LU-factorize a {rows} × {cols} matrix: it is not square")]
    NotSquare {
        /// Rows of the matrix.
        rows: usize,
        /// Its columns.
        cols: usize,
    },
    /// A pivot is NaN or infinite (the matrix has a non-finite entry, or
    /// elimination overflowed).
    #[error("the {n} × {n} matrix is not finite: LU pivot {index} is {value}")]
    NonFinite {
        /// Dimension.
        n: usize,
        /// Index of the first non-finite pivot.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The smallest pivot is zero or too small relative to the largest.
    #[error(
        "the {n} × {n} matrix is singular: its smallest LU pivot (at {index}) is \
         {pivot_ratio:.1e} times its largest (threshold {threshold:.0e})"
    )]
    Singular {
        /// Dimension.
        n: usize,
        /// Index of the smallest pivot (in the pivoted order).
        index: usize,
        /// min |Uᵢᵢ| / max |Uᵢᵢ| (0 when a pivot is exactly zero).
        pivot_ratio: f64,
        /// The ratio at or below which a matrix counts as singular.
        threshold: f64,
    },
}

/// A reusable dense LU factorization `P A = L U` of an n × n matrix: L (unit
/// diagonal) and U in one column-major matrix, and the row permutation P.
/// See the [module documentation](self).
pub struct DenseLu {
    n: usize,
    lu: Mat<f64>,
    /// (PA)ᵢ = A\[fwd\[i\]\].
    fwd: Vec<usize>,
    bwd: Vec<usize>,
    /// One column of work (row permutations, vector solves).
    work: Vec<f64>,
    mem: MemBuffer,
    factored: bool,
    pivot_ratio: f64,
    singular_below: f64,
}

impl Default for DenseLu {
    /// An empty (0 × 0) workspace; [`DenseLu::factor`] sizes it.
    fn default() -> Self {
        Self::new(0)
    }
}

impl std::fmt::Debug for DenseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLu")
            .field("n", &self.n)
            .field("factored", &self.factored)
            .field("pivot_ratio", &self.pivot_ratio)
            .field("singular_below", &self.singular_below)
            .finish()
    }
}

impl DenseLu {
    /// A workspace for n × n matrices, with all memory allocated.
    pub fn new(n: usize) -> Self {
        let req = lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default());
        Self {
            n,
            lu: Mat::zeros(n, n),
            fwd: vec![0; n],
            bwd: vec![0; n],
            work: vec![0.0; n],
            mem: MemBuffer::new(req),
            factored: false,
            pivot_ratio: 0.0,
            singular_below: SINGULAR_PIVOT_RATIO,
        }
    }

    /// Sets the pivot ratio at or below which a factorization fails as
    /// singular. `0.0` refuses only exactly zero pivots (the integrators use
    /// this: a badly scaled mass matrix is still invertible).
    pub fn with_singular_pivot_ratio(mut self, ratio: f64) -> Self {
        self.singular_below = ratio;
        self
    }

    /// The dimension n.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// min |Uᵢᵢ| / max |Uᵢᵢ| of the last factorization (0 before one, or
    /// when it failed on a zero or non-finite pivot; 1 for n = 0). A small
    /// ratio means an ill-conditioned matrix.
    pub fn pivot_ratio(&self) -> f64 {
        self.pivot_ratio
    }

    /// Whether the last factorization succeeded (and the matrix has not been
    /// touched through [`matrix_mut`](Self::matrix_mut) since).
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// The storage of the matrix to be factored: fill it, then call
    /// [`factor_in_place`](Self::factor_in_place). This invalidates the
    /// current factorization; the storage holds the factors afterwards.
    pub fn matrix_mut(&mut self) -> MatMut<'_, f64> {
        self.factored = false;
        self.lu.as_mut()
    }

    /// Factorizes `a`, a copy of which is kept. Memory is allocated only when
    /// the size differs from the last one. Returns the pivot ratio.
    pub fn factor(&mut self, a: MatRef<'_, f64>) -> Result<f64, LuError> {
        if a.nrows() != a.ncols() {
            self.factored = false;
            self.pivot_ratio = 0.0;
            return Err(LuError::NotSquare {
                rows: a.nrows(),
                cols: a.ncols(),
            });
        }
        if a.nrows() != self.n {
            *self = Self::new(a.nrows()).with_singular_pivot_ratio(self.singular_below);
        }
        self.lu.copy_from(a);
        self.factor_in_place()
    }

    /// Factorizes the matrix filled in through [`matrix_mut`](Self::matrix_mut),
    /// without allocating. Returns the pivot ratio.
    pub fn factor_in_place(&mut self) -> Result<f64, LuError> {
        let n = self.n;
        self.factored = false;
        self.pivot_ratio = 0.0;
        if n == 0 {
            self.pivot_ratio = 1.0;
            self.factored = true;
            return Ok(1.0);
        }
        if n <= UNBLOCKED_UP_TO {
            self.factor_unblocked();
        } else {
            lu_in_place(
                self.lu.as_mut(),
                &mut self.fwd,
                &mut self.bwd,
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            );
        }
        let (mut mn, mut imn, mut mx) = (f64::INFINITY, 0, 0.0f64);
        for i in 0..n {
            let d = self.lu[(i, i)];
            if !d.is_finite() {
                return Err(LuError::NonFinite {
                    n,
                    index: i,
                    value: d,
                });
            }
            let d = d.abs();
            if d < mn {
                (mn, imn) = (d, i);
            }
            mx = mx.max(d);
        }
        let ratio = if mx > 0.0 { mn / mx } else { 0.0 };
        if mn == 0.0 || mn <= self.singular_below * mx {
            return Err(LuError::Singular {
                n,
                index: imn,
                pivot_ratio: ratio,
                threshold: self.singular_below,
            });
        }
        self.pivot_ratio = ratio;
        self.factored = true;
        Ok(ratio)
    }

    /// Right-looking elimination with partial pivoting in place, column by
    /// column (each update a contiguous axpy), with the row exchanges in
    /// `fwd` and `bwd` as faer's `lu_in_place` gives them. A zero pivot
    /// column is left as it is (the pivot check then refuses the factor).
    fn factor_unblocked(&mut self) {
        let n = self.n;
        for (i, (f, b)) in self.fwd.iter_mut().zip(&mut self.bwd).enumerate() {
            (*f, *b) = (i, i);
        }
        for k in 0..n {
            let col = self.lu.col_as_slice(k);
            let mut p = k;
            let mut best = col[k].abs();
            for (i, v) in col.iter().enumerate().skip(k + 1) {
                if v.abs() > best {
                    (p, best) = (i, v.abs());
                }
            }
            if p != k {
                self.fwd.swap(k, p);
                for j in 0..n {
                    let c = self.lu.col_as_slice_mut(j);
                    c.swap(k, p);
                }
            }
            let pivot = self.lu[(k, k)];
            if pivot == 0.0 {
                continue;
            }
            let inv = 1.0 / pivot;
            for l in &mut self.lu.col_as_slice_mut(k)[k + 1..] {
                *l *= inv;
            }
            // the trailing columns minus the multipliers times row k
            let (left, right) = self.lu.as_mut().split_at_col_mut(k + 1);
            let l = &left
                .col_mut(k)
                .try_as_col_major_mut()
                .expect("column-major")
                .as_slice_mut()[k + 1..];
            for col in right.col_iter_mut() {
                let c = col
                    .try_as_col_major_mut()
                    .expect("column-major")
                    .as_slice_mut();
                let ukj = c[k];
                if ukj != 0.0 {
                    for (d, li) in c[k + 1..].iter_mut().zip(l) {
                        *d -= li * ukj;
                    }
                }
            }
        }
        for (i, f) in self.fwd.iter().enumerate() {
            self.bwd[*f] = i;
        }
    }

    /// False (and B set to NaN) when there is nothing to solve with.
    fn ready(&self, mut b: MatMut<'_, f64>) -> bool {
        assert_eq!(b.nrows(), self.n, "right-hand side of the wrong size");
        if b.nrows() == 0 || b.ncols() == 0 {
            return false;
        }
        if !self.factored {
            b.fill(f64::NAN);
        }
        self.factored
    }

    /// B ← P B (`forward`) or B ← Pᵀ B, column by column through `work`.
    fn permute_rows(&mut self, mut b: MatMut<'_, f64>, forward: bool) {
        let work = &mut self.work;
        for j in 0..b.ncols() {
            for (i, &p) in self.fwd.iter().enumerate() {
                if forward {
                    work[i] = b[(p, j)];
                } else {
                    work[p] = b[(i, j)];
                }
            }
            for (i, w) in work.iter().enumerate() {
                b[(i, j)] = *w;
            }
        }
    }

    /// Solves A X = B in place (B: n × k; NaN without a successful
    /// factorization).
    pub fn solve_in_place(&mut self, mut b: MatMut<'_, f64>) {
        if !self.ready(b.as_mut()) {
            return;
        }
        self.permute_rows(b.as_mut(), true);
        tri::solve_unit_lower_triangular_in_place(self.lu.as_ref(), b.as_mut(), Par::Seq);
        tri::solve_upper_triangular_in_place(self.lu.as_ref(), b, Par::Seq);
    }

    /// Solves Aᵀ X = B in place (Aᵀ = Uᵀ Lᵀ P; NaN without a successful
    /// factorization).
    pub fn solve_transpose_in_place(&mut self, mut b: MatMut<'_, f64>) {
        if !self.ready(b.as_mut()) {
            return;
        }
        tri::solve_lower_triangular_in_place(self.lu.transpose(), b.as_mut(), Par::Seq);
        tri::solve_unit_upper_triangular_in_place(self.lu.transpose(), b.as_mut(), Par::Seq);
        self.permute_rows(b, false);
    }

    /// Solves A x = b for one vector in place (NaN without a successful
    /// factorization). Works by columns of the factors, each update one
    /// contiguous axpy: for the sizes of flexmb's systems this is faster than
    /// a general triangular solve.
    pub fn solve_vec(&mut self, b: &mut [f64]) {
        // moving the buffer out and back does not allocate
        let mut work = std::mem::take(&mut self.work);
        self.solve_vec_with(b, &mut work);
        self.work = work;
    }

    /// As [`solve_vec`](Self::solve_vec) with caller-provided work space of
    /// at least n entries, for solves through a shared reference.
    pub fn solve_vec_with(&self, b: &mut [f64], work: &mut [f64]) {
        let n = self.n;
        assert_eq!(b.len(), n, "right-hand side of the wrong size");
        assert!(work.len() >= n, "work space smaller than the matrix");
        if n == 0 {
            return;
        }
        if !self.factored {
            b.fill(f64::NAN);
            return;
        }
        let y = &mut work[..n];
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

    /// Solves Aᵀ x = b for one vector in place (NaN without a successful
    /// factorization).
    pub fn solve_transpose_vec(&mut self, b: &mut [f64]) {
        let n = b.len();
        self.solve_transpose_in_place(MatMut::from_column_major_slice_mut(b, n, 1));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fill(lu: &mut DenseLu, a: &Mat<f64>) {
        lu.matrix_mut().copy_from(a);
    }

    /// A known solution, with a zero leading entry that needs a row exchange,
    /// assembled in place.
    #[test]
    fn solves_a_known_system() {
        let a = Mat::from_fn(3, 3, |i, j| {
            [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]][i][j]
        });
        let mut lu = DenseLu::new(3);
        fill(&mut lu, &a);
        let ratio = lu.factor_in_place().unwrap();
        assert!(ratio > 0.1 && ratio <= 1.0 && lu.is_factored());
        // x = (1, 2, 3): A x = (7, 3, 6), Aᵀ x = (11, 4, 4)
        let mut x = [7.0, 3.0, 6.0];
        lu.solve_vec(&mut x);
        let mut xt = [11.0, 4.0, 4.0];
        lu.solve_transpose_vec(&mut xt);
        for ((xi, ti), ei) in x.iter().zip(&xt).zip([1.0, 2.0, 3.0]) {
            assert!((xi - ei).abs() < 1e-14, "{x:?}");
            assert!((ti - ei).abs() < 1e-14, "{xt:?}");
        }
    }

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
            lu.factor(a.as_ref()).unwrap();
            assert_eq!(lu.dim(), n);
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.2).collect();
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
            lu.solve_vec(&mut x);
            check(&x, false, "solve_vec");
            let mut x = b.clone();
            lu.solve_transpose_vec(&mut x);
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
        // both sides of UNBLOCKED_UP_TO
        for n in [2usize, 8, 31, 48, 49, 77, 80] {
            let a = Mat::from_fn(n, n, |i, j| if i == j { 1e-3 * rnd() } else { rnd() });
            lu.factor(a.as_ref()).unwrap();
            let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let mut x = b.clone();
            lu.solve_vec(&mut x);
            let mut xt = b.clone();
            lu.solve_transpose_vec(&mut xt);
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

    /// Singular, nearly singular and non-finite matrices give typed errors,
    /// no panic, and solves with them give NaN.
    #[test]
    fn singular_and_non_finite_matrices_are_refused_and_solve_to_nan() {
        let mut lu = DenseLu::default();
        let singular = Mat::from_fn(3, 3, |i, j| (i + j) as f64);
        let err = lu.factor(singular.as_ref()).unwrap_err();
        assert!(
            matches!(err, LuError::Singular { n: 3, pivot_ratio, .. } if pivot_ratio < SINGULAR_PIVOT_RATIO),
            "{err}"
        );
        assert!(err.to_string().contains("singular"), "{err}");
        assert!(!lu.is_factored() && lu.pivot_ratio() == 0.0);
        let mut x = vec![1.0; 3];
        lu.solve_vec(&mut x);
        assert!(x.iter().all(|v| v.is_nan()));
        let mut m = Mat::<f64>::ones(3, 2);
        lu.solve_transpose_in_place(m.as_mut());
        assert!(m.col_as_slice(1).iter().all(|v| v.is_nan()));

        // exactly singular: rank one
        let rank_one = Mat::from_fn(2, 2, |i, j| [[1.0, 2.0], [2.0, 4.0]][i][j]);
        assert!(matches!(
            lu.factor(rank_one.as_ref()),
            Err(LuError::Singular { pivot_ratio, .. }) if pivot_ratio == 0.0
        ));

        // one NaN pivot among finite ones is caught
        let nan = Mat::from_fn(3, 3, |i, j| if i == j { (i + 1) as f64 } else { 0.0 });
        let mut nan = nan;
        nan[(1, 1)] = f64::NAN;
        assert!(matches!(
            lu.factor(nan.as_ref()),
            Err(LuError::NonFinite { n: 3, .. })
        ));
        assert!(matches!(
            lu.factor(Mat::<f64>::zeros(2, 3).as_ref()),
            Err(LuError::NotSquare { rows: 2, cols: 3 })
        ));
    }

    /// The threshold decides about ill-conditioned matrices: refused by
    /// default, accepted when only zero pivots are refused.
    #[test]
    fn singular_pivot_ratio_threshold() {
        let a = Mat::from_fn(2, 2, |i, j| if i == j { [1.0, 1e-15][i] } else { 0.0 });
        let mut lu = DenseLu::new(2);
        assert!(lu.factor(a.as_ref()).is_err());
        let mut lu = DenseLu::new(2).with_singular_pivot_ratio(0.0);
        let ratio = lu.factor(a.as_ref()).unwrap();
        assert!((ratio - 1e-15).abs() < 1e-30);
        let mut x = [1.0, 1e-15];
        lu.solve_vec(&mut x);
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        // a matrix edited after factoring is no longer factored
        lu.matrix_mut()[(0, 1)] = 1.0;
        assert!(!lu.is_factored());
    }

    #[test]
    fn empty_matrix_factors() {
        let mut lu = DenseLu::new(0);
        assert_eq!(lu.factor_in_place(), Ok(1.0));
        lu.solve_vec(&mut []);
    }
}
