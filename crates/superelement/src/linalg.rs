//! Linear algebra on top of faer: one supernodal sparse Cholesky factorization
//! (AMD ordering) used for the static solves and, as a shift-invert operator,
//! for the lowest eigenpairs of K φ = λ M φ through faer's Krylov–Schur
//! `partial_self_adjoint_eigen`; and the dense symmetric-definite generalized
//! eigensolver (Cholesky of M, transformation, `self_adjoint_eigen`) used for
//! small problems and as a check.

use crate::Error;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltParams;
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::linalg::triangular_solve;
use faer::matrix_free::eigen::{
    partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch, PartialEigenParams,
};
use faer::matrix_free::LinOp;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLltRef, CholeskySymbolicParams,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SparseColMatRef;
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

/// A supernodal Cholesky factorization P A Pᵀ = L Lᵀ of a sparse symmetric
/// positive-definite matrix given by its upper triangle.
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    n: usize,
}

/// Why a factorization failed.
#[derive(Debug)]
pub enum FactorError {
    /// A pivot was not positive; the index is in the original (unpermuted) numbering.
    NonPositivePivot(usize),
    /// Anything else (out of memory, index overflow).
    Other(String),
}

impl SparseCholesky {
    /// Factorizes `a` (upper triangle) with an AMD ordering.
    pub fn factor(a: SparseColMatRef<'_, usize, f64>) -> Result<Self, FactorError> {
        let n = a.nrows();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_cholesky(a.symbolic(), Side::Upper, SymmetricOrdering::Amd, params)
                .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        let mut values = vec![0.0f64; symbolic.len_val()];
        let par = Par::Seq;
        let req = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut buf = MemBuffer::try_new(req).map_err(|e| FactorError::Other(format!("{e:?}")))?;
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
                return Err(FactorError::NonPositivePivot(orig));
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

/// The shift-invert operator y ↦ L⁻¹ P M Pᵀ L⁻ᵀ y of the pencil (K, M) with
/// K = Pᵀ L Lᵀ P; its largest eigenvalues are 1/λ for the smallest λ.
struct ShiftInvert<'a, F: Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync> {
    llt: &'a SparseCholesky,
    apply_m: F,
}

impl<F: Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync> std::fmt::Debug for ShiftInvert<'_, F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShiftInvert(n = {})", self.llt.n)
    }
}

impl<F: Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync> LinOp<f64> for ShiftInvert<'_, F> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.llt.n
    }
    fn ncols(&self) -> usize {
        self.llt.n
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let k = rhs.ncols();
        let n = self.llt.n;
        let l = self.llt.supernodal();
        let mut buf = self.llt.scratch(k);
        let mut z = rhs.to_owned();
        l.l_transpose_solve_with_conj(Conj::No, z.as_mut(), Par::Seq, MemStack::new(&mut buf));
        let mut w = Mat::<f64>::zeros(n, k);
        self.llt.permute_out(z.as_ref(), w.as_mut());
        let mut mw = Mat::<f64>::zeros(n, k);
        (self.apply_m)(w.as_ref(), mw.as_mut());
        let mut out = out;
        self.llt.permute_in(mw.as_ref(), out.as_mut());
        l.l_solve_with_conj(Conj::No, out.as_mut(), Par::Seq, MemStack::new(&mut buf));
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

/// The `nev` lowest eigenpairs of K φ = λ M φ with K factorized in `llt` and M
/// applied by `apply_m` (out = M x). Returns λ ascending and M-orthonormal φ.
pub fn lowest_eigenpairs(
    llt: &SparseCholesky,
    apply_m: impl Fn(MatRef<'_, f64>, MatMut<'_, f64>) + Sync,
    nev: usize,
) -> Result<(Vec<f64>, Mat<f64>), Error> {
    let n = llt.n;
    if nev == 0 {
        return Ok((Vec::new(), Mat::zeros(n, 0)));
    }
    if nev > n {
        return Err(Error::Spec(format!(
            "{nev} normal modes requested but the interior has only {n} DOFs"
        )));
    }
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
        return Err(Error::Solver(format!(
            "the Krylov–Schur eigensolver converged {} of {nev} eigenpairs",
            info.n_converged_eigen
        )));
    }
    // back-transform: φ = Pᵀ L⁻ᵀ y, λ = 1/μ; M-normalize (φᵀMφ = μ for unit y).
    let l = llt.supernodal();
    let mut buf = llt.scratch(nev);
    let mut z = vecs.clone();
    l.l_transpose_solve_with_conj(Conj::No, z.as_mut(), Par::Seq, MemStack::new(&mut buf));
    let mut phi = Mat::<f64>::zeros(n, nev);
    llt.permute_out(z.as_ref(), phi.as_mut());
    let mut pairs: Vec<(f64, usize)> = vals
        .iter()
        .enumerate()
        .map(|(i, &mu)| (1.0 / mu, i))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = Mat::<f64>::zeros(n, nev);
    let mut lam: Vec<f64> = Vec::with_capacity(nev);
    for (c, &(l, i)) in pairs.iter().enumerate() {
        if !(l.is_finite() && l > 0.0) {
            return Err(Error::Solver(format!(
                "eigenvalue {l} of a positive-definite pencil"
            )));
        }
        let s = (1.0 / vals[i]).sqrt() / vecs.col(i).norm_l2();
        for r in 0..n {
            out[(r, c)] = phi[(r, i)] * s;
        }
        lam.push(l);
    }
    // Two steps of shift-invert subspace iteration with Rayleigh–Ritz polish the
    // Krylov–Schur pairs: Y = K⁻¹ M Φ, K_r = Yᵀ K Y = Yᵀ M Φ, M_r = Yᵀ M Y.
    let mut phi = out;
    for _ in 0..2 {
        let mut mphi = Mat::<f64>::zeros(n, nev);
        apply(&op.apply_m, phi.as_ref(), mphi.as_mut());
        let mut y = mphi.clone();
        llt.solve_in_place(y.as_mut());
        let kr = y.transpose() * &mphi;
        let mut my = Mat::<f64>::zeros(n, nev);
        apply(&op.apply_m, y.as_ref(), my.as_mut());
        let mr = y.transpose() * &my;
        let kr = Mat::<f64>::from_fn(nev, nev, |i, j| 0.5 * (kr[(i, j)] + kr[(j, i)]));
        let mr = Mat::<f64>::from_fn(nev, nev, |i, j| 0.5 * (mr[(i, j)] + mr[(j, i)]));
        let (l2, q) = dense_generalized_eigen(kr.as_ref(), mr.as_ref())?;
        phi = &y * &q;
        lam = l2;
    }
    Ok((lam, phi))
}

fn apply<F: Fn(MatRef<'_, f64>, MatMut<'_, f64>)>(f: &F, x: MatRef<'_, f64>, y: MatMut<'_, f64>) {
    f(x, y)
}

/// All eigenpairs of the dense symmetric-definite pencil (K, M), λ ascending,
/// M-orthonormal φ.
///
/// When K is positive definite the pencil is transformed with the Cholesky
/// factor of K: C = L_K⁻¹ M L_K⁻ᵀ has eigenvalues 1/λ, so the lowest modes
/// (the ones of interest) are the dominant ones and keep their relative
/// accuracy (with the factor of M, faer's `self_adjoint_eigen` lost ~6 digits
/// of the lowest eigenvalue of a small solid model: its error is relative to
/// ‖C‖ = λ_max). Otherwise (K singular) the factor of M is used. Eigenvalues
/// are returned as Rayleigh quotients.
pub fn dense_generalized_eigen(
    k: MatRef<'_, f64>,
    m: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>), Error> {
    let n = k.nrows();
    if k.ncols() != n || m.nrows() != n || m.ncols() != n {
        return Err(Error::SizeMismatch(format!(
            "dense eigenproblem: K is {}×{}, M is {}×{}",
            k.nrows(),
            k.ncols(),
            m.nrows(),
            m.ncols()
        )));
    }
    let (a, b, inverted) = match k.llt(Side::Lower) {
        Ok(_) => (k, m, true),
        Err(_) => (m, k, false),
    };
    let llt = a.llt(Side::Lower).map_err(|e| {
        Error::Solver(format!(
            "neither K nor M is positive definite ({e:?}); the dense eigensolver needs one of them"
        ))
    })?;
    let l = llt.L();
    let mut c = b.to_owned();
    triangular_solve::solve_lower_triangular_in_place(l, c.as_mut(), Par::Seq);
    let mut ct = c.transpose().to_owned();
    triangular_solve::solve_lower_triangular_in_place(l, ct.as_mut(), Par::Seq);
    let cs = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (ct[(i, j)] + ct[(j, i)]));
    let evd = cs
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::Solver(format!("dense eigensolver failed ({e:?})")))?;
    let s = evd.S();
    let mut y = evd.U().to_owned();
    triangular_solve::solve_upper_triangular_in_place(l.transpose(), y.as_mut(), Par::Seq);
    let mut idx: Vec<usize> = (0..n).collect();
    if inverted {
        // μ = 1/λ descending ↔ λ ascending
        idx.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    } else {
        idx.sort_by(|&a, &b| s[a].total_cmp(&s[b]));
    }
    let mut phi = Mat::<f64>::from_fn(n, n, |r, c| y[(r, idx[c])]);
    let kp = k * &phi;
    let mp = m * &phi;
    let mut lam = Vec::with_capacity(n);
    for c in 0..n {
        let num: f64 = (0..n).map(|r| phi[(r, c)] * kp[(r, c)]).sum();
        let den: f64 = (0..n).map(|r| phi[(r, c)] * mp[(r, c)]).sum();
        lam.push(num / den);
        let sc = 1.0 / den.abs().sqrt();
        for r in 0..n {
            phi[(r, c)] *= sc;
        }
    }
    Ok((lam, phi))
}

/// Frequencies (Hz) from eigenvalues ω².
pub fn to_hz(lam: &[f64]) -> Vec<f64> {
    lam.iter()
        .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect()
}
