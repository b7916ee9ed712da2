//! A supernodal sparse Cholesky factorization `P A Pᵀ = L Lᵀ` (AMD ordering)
//! and, with it as a shift-invert operator, the lowest eigenpairs of a large
//! sparse pencil `K φ = λ M φ`.
//!
//! `flexmb-superelement` uses these for the Craig–Bampton reduction of a
//! solid finite-element model: [`SparseCholesky`] factorizes the interior
//! stiffness once for all static solves (constraint modes) and
//! [`lowest_eigenpairs`] finds the fixed-interface normal modes through faer's
//! Krylov–Schur `partial_self_adjoint_eigen` on the operator
//! `y ↦ L⁻¹ P M Pᵀ L⁻ᵀ y`, whose largest eigenvalues are 1/λ of the smallest
//! λ; two steps of shift-invert subspace iteration with a Rayleigh–Ritz
//! projection ([`crate::eigen::generalized_eigen`]) then polish the pairs
//! (`shift_invert.rs`, which the dense solver uses too).
//!
//! The factorization is on faer's sparse supernodal Cholesky; errors are typed
//! ([`CholeskyError`], [`EigenError`]).

use crate::eigen::EigenError;
use crate::shift_invert::{lowest_pairs, CholeskyFactor};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltParams;
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLltRef, CholeskySymbolicParams,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{FaerError, SparseColMatRef};
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

/// A supernodal Cholesky factorization P A Pᵀ = L Lᵀ of a sparse symmetric
/// positive-definite matrix given by its upper triangle.
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    n: usize,
}

/// Why a sparse Cholesky factorization failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum CholeskyError {
    /// A pivot was not positive: the matrix is not positive definite.
    #[error(
        "the sparse Cholesky factorization broke down at row {index} (a zero or negative pivot)"
    )]
    NonPositivePivot {
        /// The row, in the original (unpermuted) numbering.
        index: usize,
    },
    /// faer could not set the factorization up (out of memory, index overflow).
    #[error("sparse Cholesky: {0}")]
    Faer(#[from] FaerError),
}

impl SparseCholesky {
    /// Factorizes `a` (upper triangle) with an AMD ordering.
    pub fn factor(a: SparseColMatRef<'_, usize, f64>) -> Result<Self, CholeskyError> {
        let n = a.nrows();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_cholesky(a.symbolic(), Side::Upper, SymmetricOrdering::Amd, params)?;
        let mut values = vec![0.0f64; symbolic.len_val()];
        let par = Par::Seq;
        let req = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut buf = MemBuffer::try_new(req).map_err(FaerError::from)?;
        let res = symbolic.factorize_numeric_llt::<f64>(
            &mut values,
            a,
            Side::Upper,
            LltRegularization::default(),
            par,
            MemStack::new(&mut buf),
            faer::Spec::<LltParams, f64>::default(),
        );
        match res {
            Ok(_) => {}
            Err(LltError::NonPositivePivot { index }) => {
                let orig = match symbolic.perm() {
                    Some(p) => p.arrays().0[index.min(n.saturating_sub(1))],
                    None => index,
                };
                return Err(CholeskyError::NonPositivePivot { index: orig });
            }
        }
        Ok(Self {
            symbolic,
            values,
            n,
        })
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of stored values of L.
    pub fn factor_nnz(&self) -> usize {
        self.values.len()
    }

    fn supernodal(&self) -> SupernodalLltRef<'_, usize, f64> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => SupernodalLltRef::new(s, &self.values),
            SymbolicCholeskyRaw::Simplicial(_) => {
                unreachable!("supernodal factorization was forced")
            }
        }
    }

    fn scratch(&self, k: usize) -> MemBuffer {
        let req = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => s.solve_in_place_scratch::<f64>(k, Par::Seq),
            SymbolicCholeskyRaw::Simplicial(_) => StackReq::EMPTY,
        };
        MemBuffer::new(req)
    }

    fn fwd(&self) -> Option<&[usize]> {
        self.symbolic.perm().map(|p| p.arrays().0)
    }

    /// Solves A X = B in place.
    pub fn solve_in_place(&self, mut rhs: MatMut<'_, f64>) {
        let k = rhs.ncols();
        let mut x = Mat::<f64>::zeros(self.n, k);
        self.permute_in(rhs.as_ref(), x.as_mut());
        let l = self.supernodal();
        let mut buf = self.scratch(k);
        l.l_solve_with_conj(Conj::No, x.as_mut(), Par::Seq, MemStack::new(&mut buf));
        l.l_transpose_solve_with_conj(Conj::No, x.as_mut(), Par::Seq, MemStack::new(&mut buf));
        self.permute_out(x.as_ref(), rhs.as_mut());
    }

    /// x_perm[i] = x[fwd[i]]
    fn permute_in(&self, src: MatRef<'_, f64>, mut dst: MatMut<'_, f64>) {
        match self.fwd() {
            Some(fwd) => {
                for c in 0..src.ncols() {
                    for (i, &f) in fwd.iter().enumerate() {
                        dst[(i, c)] = src[(f, c)];
                    }
                }
            }
            None => dst.copy_from(src),
        }
    }

    fn permute_out(&self, src: MatRef<'_, f64>, mut dst: MatMut<'_, f64>) {
        match self.fwd() {
            Some(fwd) => {
                for c in 0..src.ncols() {
                    for (i, &f) in fwd.iter().enumerate() {
                        dst[(f, c)] = src[(i, c)];
                    }
                }
            }
            None => dst.copy_from(src),
        }
    }

    /// The smallest ratio L_ii² / A_ii over the pivots and the original index
    /// where it occurs: a tiny ratio means a (nearly) singular matrix.
    pub fn min_pivot_ratio(&self, a: SparseColMatRef<'_, usize, f64>) -> (f64, usize) {
        let mut diag = vec![0.0; self.n];
        for (j, d) in diag.iter_mut().enumerate() {
            for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                if i == j {
                    *d = v;
                }
            }
        }
        let l = self.supernodal();
        let s = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => s,
            SymbolicCholeskyRaw::Simplicial(_) => unreachable!(),
        };
        let fwd = self.fwd();
        let mut best = (f64::INFINITY, 0);
        for sn in 0..s.n_supernodes() {
            let node = l.supernode(sn);
            let m = node.val();
            let start = node.start();
            for c in 0..m.ncols() {
                let p = start + c;
                let orig = fwd.map_or(p, |f| f[p]);
                let r = m[(c, c)] * m[(c, c)] / diag[orig];
                if r < best.0 {
                    best = (r, orig);
                }
            }
        }
        best
    }
}

impl CholeskyFactor for SparseCholesky {
    fn n(&self) -> usize {
        self.n
    }
    fn forward(&self, b: MatRef<'_, f64>, mut out: MatMut<'_, f64>) {
        self.permute_in(b, out.as_mut());
        let mut buf = self.scratch(b.ncols());
        self.supernodal()
            .l_solve_with_conj(Conj::No, out, Par::Seq, MemStack::new(&mut buf));
    }
    fn backward(&self, y: MatRef<'_, f64>, out: MatMut<'_, f64>) {
        let mut z = y.to_owned();
        let mut buf = self.scratch(y.ncols());
        self.supernodal().l_transpose_solve_with_conj(
            Conj::No,
            z.as_mut(),
            Par::Seq,
            MemStack::new(&mut buf),
        );
        self.permute_out(z.as_ref(), out);
    }
}

/// The `nev` lowest eigenpairs of K φ = λ M φ with K factorized in `llt` and M
/// applied by `apply_m` (out = M x). Returns λ ascending and M-orthonormal φ
/// (Krylov–Schur on the shift-invert operator, then two steps of subspace
/// iteration: `shift_invert.rs`).
pub fn lowest_eigenpairs(
    llt: &SparseCholesky,
    apply_m: impl Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync,
    nev: usize,
) -> Result<(Vec<f64>, Mat<f64>), EigenError> {
    lowest_pairs(llt, apply_m, nev, None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// The upper triangle of the 1-D Laplacian tridiag(−1, 2, −1) of order n
    /// (fixed ends), scaled by `k`, and its dense form.
    fn laplacian(n: usize, k: f64) -> (SparseColMat<usize, f64>, Mat<f64>) {
        let mut t = vec![];
        for i in 0..n {
            t.push(Triplet::new(i, i, 2.0 * k));
            if i + 1 < n {
                t.push(Triplet::new(i, i + 1, -k));
            }
        }
        let a = SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
        let d = Mat::from_fn(n, n, |i, j| {
            if i == j {
                2.0 * k
            } else if i.abs_diff(j) == 1 {
                -k
            } else {
                0.0
            }
        });
        (a, d)
    }

    /// A x = b with the known solution of the Laplacian: b = e_n gives
    /// xᵢ = (i + 1)/(n + 1) (a linear ramp).
    #[test]
    fn solves_a_known_system() {
        let n = 30;
        let (a, d) = laplacian(n, 1.0);
        let llt = SparseCholesky::factor(a.as_ref()).unwrap();
        assert_eq!(llt.n(), n);
        assert!(llt.factor_nnz() >= 2 * n - 1);
        let mut x = Mat::<f64>::zeros(n, 2);
        x[(n - 1, 0)] = 1.0;
        x[(n - 1, 1)] = 2.0;
        llt.solve_in_place(x.as_mut());
        for i in 0..n {
            let expect = (i + 1) as f64 / (n + 1) as f64;
            assert!((x[(i, 0)] - expect).abs() < 1e-13, "x[{i}] = {}", x[(i, 0)]);
            assert!((x[(i, 1)] - 2.0 * expect).abs() < 1e-13);
        }
        let r =
            &d * x.col(0) - Mat::from_fn(n, 1, |i, _| if i == n - 1 { 1.0 } else { 0.0 }).col(0);
        assert!(r.norm_max() < 1e-13);
        // every pivot of a well-conditioned matrix is far from zero
        let (ratio, _) = llt.min_pivot_ratio(a.as_ref());
        assert!(ratio > 0.1 && ratio <= 1.0, "{ratio}");
    }

    /// An indefinite matrix fails with a typed error naming a row; no panic.
    /// (faer 0.24 reports the failing pivot of this diagonal matrix, row 4, as
    /// 5: the index can lie just past the bad pivot within its supernode.)
    #[test]
    fn indefinite_matrix_is_refused() {
        let n = 6;
        let mut t = vec![];
        for i in 0..n {
            t.push(Triplet::new(i, i, if i == 4 { -1.0 } else { 2.0 }));
        }
        let a = SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
        let err = SparseCholesky::factor(a.as_ref()).err().unwrap();
        let CholeskyError::NonPositivePivot { index } = err else {
            panic!("{err}");
        };
        assert!((4..n).contains(&index), "{err}");
        assert!(err.to_string().contains("broke down at row"), "{err}");
    }

    /// The lowest eigenpairs of a fixed–fixed string, K = tridiag(−1, 2, −1) ·
    /// 1e4 and M = 0.5·I: λⱼ = (4·1e4/0.5) sin²(jπ/(2(n + 1))), with
    /// ΦᵀMΦ = I and small residuals K φ − λ M φ.
    #[test]
    fn lowest_eigenpairs_of_a_string() {
        let n = 200;
        let (k, kd) = laplacian(n, 1e4);
        let llt = SparseCholesky::factor(k.as_ref()).unwrap();
        let mass = 0.5;
        let apply_m = |x: MatRef<'_, f64>, mut out: MatMut<'_, f64>| {
            out.copy_from(x);
            for j in 0..out.ncols() {
                for i in 0..out.nrows() {
                    out[(i, j)] *= mass;
                }
            }
        };
        let nev = 5;
        let (lam, phi) = lowest_eigenpairs(&llt, apply_m, nev).unwrap();
        for (j, l) in lam.iter().enumerate() {
            let s = ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin();
            let expect = 4.0 * 1e4 / mass * s * s;
            assert!(
                (l / expect - 1.0).abs() < 1e-10,
                "λ{j} = {l}, expected {expect}"
            );
        }
        let vmv = phi.transpose() * &phi * mass;
        assert!((vmv - Mat::<f64>::identity(nev, nev)).norm_max() < 1e-10);
        let kv = &kd * &phi;
        for j in 0..nev {
            let r = (0..n)
                .map(|i| (kv[(i, j)] - lam[j] * mass * phi[(i, j)]).abs())
                .fold(0.0, f64::max);
            assert!(r < 1e-8 * lam[j], "residual {r} of pair {j}");
        }
        assert_eq!(
            lowest_eigenpairs(&llt, apply_m, n + 1).unwrap_err(),
            EigenError::TooMany {
                requested: n + 1,
                n
            }
        );
        assert_eq!(lowest_eigenpairs(&llt, apply_m, 0).unwrap().0.len(), 0);
    }
}
