//! The lowest eigenpairs of a symmetric pencil `K φ = λ M φ` by Krylov–Schur
//! on the shift-invert operator of a Cholesky factor of K, sparse
//! ([`crate::SparseCholesky`], the Craig–Bampton reduction of solid models) or
//! dense ([`crate::generalized_eigen`] when a few modes of a large model are
//! asked for): with K = Pᵀ L Lᵀ P, faer's `partial_self_adjoint_eigen` finds
//! the largest eigenvalues μ = 1/λ of `y ↦ L⁻¹ P M Pᵀ L⁻ᵀ y`, the smallest λ;
//! two steps of shift-invert subspace iteration with a Rayleigh–Ritz
//! projection ([`crate::eigen::generalized_eigen`] of the small pencil) then
//! polish the pairs. Only matrix–vector products with M and triangular solves
//! with L: O(n²) per Krylov step for a dense K instead of the O(n³)
//! transformation and full eigendecomposition.

use crate::eigen::{generalized_eigen, Definite, EigenError};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::eigen::{
    partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch, PartialEigenParams,
};
use faer::matrix_free::LinOp;
use faer::{Mat, MatMut, MatRef, Par};
use std::sync::atomic::{AtomicBool, Ordering};

/// A factorization K = Pᵀ L Lᵀ P (P a permutation, possibly the identity).
pub(crate) trait CholeskyFactor: Sync {
    /// The dimension.
    fn n(&self) -> usize;
    /// out = L⁻¹ P b.
    fn forward(&self, b: MatRef<'_, f64>, out: MatMut<'_, f64>);
    /// out = Pᵀ L⁻ᵀ y.
    fn backward(&self, y: MatRef<'_, f64>, out: MatMut<'_, f64>);
}

/// The shift-invert operator y ↦ L⁻¹ P M Pᵀ L⁻ᵀ y of the pencil (K, M); its
/// largest eigenvalues are 1/λ for the smallest λ.
struct ShiftInvert<'a, C: CholeskyFactor, F: Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync> {
    llt: &'a C,
    apply_m: F,
}

impl<C: CholeskyFactor, F: Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync> std::fmt::Debug
    for ShiftInvert<'_, C, F>
{
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShiftInvert(n = {})", self.llt.n())
    }
}

impl<C: CholeskyFactor, F: Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync> LinOp<f64>
    for ShiftInvert<'_, C, F>
{
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.llt.n()
    }
    fn ncols(&self) -> usize {
        self.llt.n()
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let (n, k) = (self.llt.n(), rhs.ncols());
        let mut w = Mat::<f64>::zeros(n, k);
        self.llt.backward(rhs, w.as_mut());
        let mut mw = Mat::<f64>::zeros(n, k);
        (self.apply_m)(w.as_ref(), mw.as_mut());
        self.llt.forward(mw.as_ref(), out);
    }
    fn conj_apply(
        &self,
        out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        par: Par,
        stack: &mut MemStack,
    ) {
        self.apply(out, rhs, par, stack)
    }
}

/// [`EigenError::Interrupted`] if `stop` is given and set.
pub(crate) fn check_stop(stop: Option<&AtomicBool>) -> Result<(), EigenError> {
    match stop {
        Some(s) if s.load(Ordering::Relaxed) => Err(EigenError::Interrupted),
        _ => Ok(()),
    }
}

/// The `nev` lowest eigenpairs of K φ = λ M φ with K factorized in `llt` and
/// M applied by `apply_m` (out = M x): λ ascending and M-orthonormal φ. A
/// set `stop` ends it with [`EigenError::Interrupted`] before the Krylov–Schur
/// iteration, after it and between the polishing steps.
pub(crate) fn lowest_pairs<C: CholeskyFactor>(
    llt: &C,
    apply_m: impl Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync,
    nev: usize,
    stop: Option<&AtomicBool>,
) -> Result<(Vec<f64>, Mat<f64>), EigenError> {
    let n = llt.n();
    if nev == 0 {
        return Ok((Vec::new(), Mat::zeros(n, 0)));
    }
    if nev > n {
        return Err(EigenError::TooMany { requested: nev, n });
    }
    check_stop(stop)?;
    let op = ShiftInvert { llt, apply_m };
    let params = PartialEigenParams::default();
    let mut vecs = Mat::<f64>::zeros(n, nev);
    let mut vals = vec![0.0f64; nev];
    // a deterministic, generic start vector
    let v0 = faer::Col::<f64>::from_fn(n, |i| {
        1.0 + 0.37 * ((i as f64 * 0.618_033_988_75).fract() - 0.5)
    });
    let v0n = v0.norm_l2();
    let v0 = v0 / v0n;
    let req = partial_self_adjoint_eigen_scratch::<f64>(&op, nev, Par::Seq, params);
    let mut buf = MemBuffer::new(req);
    let info = partial_self_adjoint_eigen(
        vecs.as_mut(),
        &mut vals,
        &op,
        v0.as_ref(),
        f64::EPSILON * 128.0,
        Par::Seq,
        MemStack::new(&mut buf),
        params,
    );
    if info.n_converged_eigen < nev {
        return Err(EigenError::PartialConvergence {
            converged: info.n_converged_eigen,
            requested: nev,
        });
    }
    check_stop(stop)?;
    // back-transform: φ = Pᵀ L⁻ᵀ y, λ = 1/μ; M-normalize (φᵀMφ = μ for unit y).
    let mut phi = Mat::<f64>::zeros(n, nev);
    llt.backward(vecs.as_ref(), phi.as_mut());
    let mut pairs: Vec<(f64, usize)> = vals
        .iter()
        .enumerate()
        .map(|(i, &mu)| (1.0 / mu, i))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = Mat::<f64>::zeros(n, nev);
    for (c, &(l, i)) in pairs.iter().enumerate() {
        if !(l.is_finite() && l > 0.0) {
            return Err(EigenError::InvalidEigenvalue { value: l });
        }
        let s = (1.0 / vals[i]).sqrt() / vecs.col(i).norm_l2();
        for r in 0..n {
            out[(r, c)] = phi[(r, i)] * s;
        }
    }
    // Two steps of shift-invert subspace iteration with Rayleigh–Ritz polish the
    // Krylov–Schur pairs: Y = K⁻¹ M Φ, K_r = Yᵀ K Y = Yᵀ M Φ, M_r = Yᵀ M Y.
    let mut phi = out;
    let mut lam = vec![];
    for _ in 0..2 {
        check_stop(stop)?;
        let mut mphi = Mat::<f64>::zeros(n, nev);
        (op.apply_m)(phi.as_ref(), mphi.as_mut());
        let mut z = Mat::<f64>::zeros(n, nev);
        llt.forward(mphi.as_ref(), z.as_mut());
        let mut y = Mat::<f64>::zeros(n, nev);
        llt.backward(z.as_ref(), y.as_mut());
        let kr = y.transpose() * &mphi;
        let mut my = Mat::<f64>::zeros(n, nev);
        (op.apply_m)(y.as_ref(), my.as_mut());
        let mr = y.transpose() * &my;
        let kr = Mat::<f64>::from_fn(nev, nev, |i, j| 0.5 * (kr[(i, j)] + kr[(j, i)]));
        let mr = Mat::<f64>::from_fn(nev, nev, |i, j| 0.5 * (mr[(i, j)] + mr[(j, i)]));
        let e = generalized_eigen(kr.as_ref(), mr.as_ref(), nev, Definite::Either)?;
        phi = &y * &e.vectors;
        lam = e.values;
    }
    Ok((lam, phi))
}
