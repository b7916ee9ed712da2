//! Dense generalized symmetric-definite eigenproblems `K v = λ M v`.
//!
//! These give the undamped modes of a linearized mechanism, `(K + G) v = ω² M v`
//! (`flexmb-linearize`, thesis (4.2)), the normal modes of a small or reduced
//! finite-element model and the Rayleigh–Ritz step of the sparse eigensolver
//! (`flexmb-superelement`, [`crate::sparse_cholesky`]), and the buckling load
//! factors, `−G v = (1/μ) K v`.
//!
//! The pencil is reduced to a standard symmetric problem by the Cholesky
//! factor of a positive-definite member: with `B = L Lᵀ`, `A v = λ B v` becomes
//! `(L⁻¹ A L⁻ᵀ) y = λ y`, `v = L⁻ᵀ y`, solved by faer's `self_adjoint_eigen`.
//! [`generalized_eigen`] transforms with the factor of K when K is positive
//! definite: `L_K⁻¹ M L_K⁻ᵀ` has the eigenvalues 1/λ, so the lowest modes (the
//! ones of interest) are its dominant ones and keep their relative accuracy
//! even when λ spans many decades (with the factor of M, faer's
//! `self_adjoint_eigen` lost ~6 digits of the lowest eigenvalue of a small
//! solid model: its error is relative to the largest λ). Otherwise (K
//! indefinite, e.g. buckled, or singular) it uses the factor of M. The
//! eigenvalues are finally computed as Rayleigh quotients `vᵀKv / vᵀMv` and
//! the vectors M-normalized, `VᵀMV = I`.
//!
//! When only a few of the lowest pairs of a large pencil are asked for
//! (n ≥ [`PARTIAL_MIN_DIM`], at most n/[`PARTIAL_MAX_FRACTION`] pairs) and
//! K is positive definite, the O(n³) transformation and full
//! eigendecomposition are replaced by Krylov–Schur on the shift-invert
//! operator `L_K⁻¹ M L_K⁻ᵀ` (the same operator, its dominant eigenvalues
//! only: `shift_invert.rs` of this crate), polished by subspace iteration and
//! Rayleigh–Ritz; only the Cholesky factorizations remain O(n³). Should it
//! not converge, the full method is used.
//!
//! Both matrices are symmetrized, `½(A + Aᵀ)`, before use.

use crate::abandon::{abandonable, Outcome};
use crate::shift_invert::{check_stop, lowest_pairs, CholeskyFactor};
use faer::linalg::triangular_solve as tri;
use faer::{Mat, MatMut, MatRef, Par, Side};
use std::sync::atomic::AtomicBool;

/// The smallest dimension for which [`generalized_eigen`] computes only the
/// pairs asked for (Krylov–Schur) rather than all of them. (The 1440-DOF
/// flexure chain: 2 modes in 0.1 s instead of 0.95 s.)
pub const PARTIAL_MIN_DIM: usize = 200;

/// [`generalized_eigen`] computes only the pairs asked for when they are at
/// most 1/`PARTIAL_MAX_FRACTION` of the dimension.
pub const PARTIAL_MAX_FRACTION: usize = 8;

/// The smallest dimension for which [`generalized_eigen_until`] solves on a
/// thread of its own that a stop request leaves at once. Below, a dense
/// solution takes a few milliseconds at most, less than the cost of
/// the thread is worth in a sweep of many small configurations.
pub const ABANDON_MIN_DIM: usize = 200;

/// Which member of the pencil (K, M) must be positive definite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Definite {
    /// M must be positive definite (the modes of a mechanism: a DOF without
    /// inertia is an error, whatever K is).
    Mass,
    /// K or M must be positive definite (a finite-element pencil, either of
    /// whose members may be only semi-definite).
    Either,
}

/// Which matrix of a pencil an error refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Member {
    /// The left-hand (stiffness) matrix K, or A of `A v = λ B v`.
    K,
    /// The right-hand (mass) matrix M, or B of `A v = λ B v`.
    M,
}

impl std::fmt::Display for Member {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Member::K => "K",
            Member::M => "M",
        })
    }
}

/// Why an eigenproblem could not be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EigenError {
    /// The matrices are not square or not of the same size.
    #[error("eigenproblem: K is {k_rows} × {k_cols}, M is {m_rows} × {m_cols}")]
    Dimension {
        /// Rows of K.
        k_rows: usize,
        /// Columns of K.
        k_cols: usize,
        /// Rows of M.
        m_rows: usize,
        /// Columns of M.
        m_cols: usize,
    },
    /// An entry is NaN or infinite.
    #[error("eigenproblem: {matrix} has a non-finite entry {value} at row {row}, column {col}")]
    NonFinite {
        /// The matrix.
        matrix: Member,
        /// Row of the first non-finite entry.
        row: usize,
        /// Its column.
        col: usize,
        /// Its value.
        value: f64,
    },
    /// The Cholesky factorization of a matrix that must be positive definite
    /// failed (for [`Definite::Either`]: of both).
    #[error("eigenproblem: {} positive definite", match .matrix {
        Some(m) => format!("{m} is not"),
        None => "neither K nor M is".to_string(),
    })]
    NotPositiveDefinite {
        /// The matrix; `None` when neither K nor M is.
        matrix: Option<Member>,
    },
    /// More eigenpairs were requested than the problem has.
    #[error("{requested} eigenpairs requested of a problem of dimension {n}")]
    TooMany {
        /// Pairs requested.
        requested: usize,
        /// Dimension.
        n: usize,
    },
    /// The symmetric eigensolver did not converge.
    #[error("the symmetric eigensolver did not converge on the {n} × {n} transformed problem")]
    NoConvergence {
        /// Dimension.
        n: usize,
    },
    /// The iterative (Krylov–Schur) eigensolver found fewer pairs than requested.
    #[error("the Krylov–Schur eigensolver converged {converged} of {requested} eigenpairs")]
    PartialConvergence {
        /// Pairs converged.
        converged: usize,
        /// Pairs requested.
        requested: usize,
    },
    /// An eigenvalue that a positive-definite pencil cannot have.
    #[error("eigenvalue {value} of a positive-definite pencil")]
    InvalidEigenvalue {
        /// The eigenvalue.
        value: f64,
    },
    /// The stop request of [`generalized_eigen_until`] was set.
    #[error("the eigen analysis was stopped on request")]
    Interrupted,
}

/// Eigenvalues, ascending, and M-normalized eigenvectors as columns.
#[derive(Debug, Clone)]
pub struct GeneralizedEigen {
    /// λ, ascending (Rayleigh quotients).
    pub values: Vec<f64>,
    /// v as columns, in the order of `values`, with `VᵀMV = I` (for a
    /// semi-definite M: vᵀMv = ±1 where it is not zero).
    pub vectors: Mat<f64>,
}

/// ½(A + Aᵀ).
fn sym(a: MatRef<'_, f64>) -> Mat<f64> {
    let n = a.nrows();
    Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// The first non-finite entry, as an error about `matrix`.
fn check_finite(a: MatRef<'_, f64>, matrix: Member) -> Result<(), EigenError> {
    for col in 0..a.ncols() {
        for row in 0..a.nrows() {
            let value = a[(row, col)];
            if !value.is_finite() {
                return Err(EigenError::NonFinite {
                    matrix,
                    row,
                    col,
                    value,
                });
            }
        }
    }
    Ok(())
}

fn check_dims(k: MatRef<'_, f64>, m: MatRef<'_, f64>) -> Result<usize, EigenError> {
    let n = k.nrows();
    if k.ncols() != n || m.nrows() != n || m.ncols() != n {
        return Err(EigenError::Dimension {
            k_rows: k.nrows(),
            k_cols: k.ncols(),
            m_rows: m.nrows(),
            m_cols: m.ncols(),
        });
    }
    Ok(n)
}

/// The lower Cholesky factor of a symmetric matrix, if it is positive definite.
fn cholesky(a: &Mat<f64>) -> Option<Mat<f64>> {
    a.llt(Side::Lower).ok().map(|llt| llt.L().to_owned())
}

/// L⁻¹ A L⁻ᵀ, symmetrized, for a lower-triangular L.
fn congruence(l: &Mat<f64>, a: &Mat<f64>) -> Mat<f64> {
    let mut b = a.clone();
    tri::solve_lower_triangular_in_place(l.as_ref(), b.as_mut(), Par::Seq);
    let mut bt = b.transpose().to_owned();
    tri::solve_lower_triangular_in_place(l.as_ref(), bt.as_mut(), Par::Seq);
    sym(bt.as_ref())
}

/// A dense lower Cholesky factor as the shift-invert operator of
/// [`crate::shift_invert`] (no permutation).
struct DenseFactor<'a>(&'a Mat<f64>);

impl CholeskyFactor for DenseFactor<'_> {
    fn n(&self) -> usize {
        self.0.nrows()
    }
    fn forward(&self, b: MatRef<'_, f64>, mut out: MatMut<'_, f64>) {
        out.copy_from(b);
        tri::solve_lower_triangular_in_place(self.0.as_ref(), out, Par::Seq);
    }
    fn backward(&self, y: MatRef<'_, f64>, mut out: MatMut<'_, f64>) {
        out.copy_from(y);
        tri::solve_upper_triangular_in_place(self.0.transpose(), out, Par::Seq);
    }
}

/// The `count` lowest eigenpairs (all when `count` ≥ n) of the symmetric
/// pencil `K v = λ M v`, λ ascending, `VᵀMV = I`; `definite` says which
/// member must be positive definite. See the [module documentation](self)
/// for the method.
pub fn generalized_eigen(
    k: MatRef<'_, f64>,
    m: MatRef<'_, f64>,
    count: usize,
    definite: Definite,
) -> Result<GeneralizedEigen, EigenError> {
    generalized_eigen_until(k, m, count, definite, None)
}

/// [`generalized_eigen`] that ends with [`EigenError::Interrupted`] when
/// `stop` is set. From [`ABANDON_MIN_DIM`] on, the solution runs on a thread
/// of its own and a stop request returns within about a millisecond, even
/// inside a factorization or the full eigendecomposition, which have no
/// check inside (the thread is told to stop and finishes its current
/// factorization in the background: `abandon.rs`). Below, `stop` is read
/// between the factorizations and the steps of the partial method, and
/// before and after the full method's eigendecomposition (a few
/// milliseconds at most).
pub fn generalized_eigen_until(
    k: MatRef<'_, f64>,
    m: MatRef<'_, f64>,
    count: usize,
    definite: Definite,
    stop: Option<&AtomicBool>,
) -> Result<GeneralizedEigen, EigenError> {
    match stop {
        Some(stop) if k.nrows() >= ABANDON_MIN_DIM => {
            let (k, m) = (k.to_owned(), m.to_owned());
            let work = move |abandoned: &AtomicBool| {
                eigen_checked(k.as_ref(), m.as_ref(), count, definite, Some(abandoned))
            };
            match abandonable(stop, work) {
                Outcome::Done(result) => result,
                Outcome::Stopped => Err(EigenError::Interrupted),
            }
        }
        _ => eigen_checked(k, m, count, definite, stop),
    }
}

/// [`generalized_eigen_until`] on the caller's thread: `stop` is read
/// between the steps.
fn eigen_checked(
    k: MatRef<'_, f64>,
    m: MatRef<'_, f64>,
    count: usize,
    definite: Definite,
    stop: Option<&AtomicBool>,
) -> Result<GeneralizedEigen, EigenError> {
    let n = check_dims(k, m)?;
    check_finite(k, Member::K)?;
    check_finite(m, Member::M)?;
    let count = count.min(n);
    if n == 0 {
        return Ok(GeneralizedEigen {
            values: vec![],
            vectors: Mat::zeros(0, 0),
        });
    }
    check_stop(stop)?;
    let (ks, ms) = (sym(k), sym(m));
    let mut lm = None;
    if definite == Definite::Mass {
        lm = Some(cholesky(&ms).ok_or(EigenError::NotPositiveDefinite {
            matrix: Some(Member::M),
        })?);
    }
    check_stop(stop)?;
    let lk = cholesky(&ks);
    check_stop(stop)?;
    if let Some(l) = &lk {
        if n >= PARTIAL_MIN_DIM && count * PARTIAL_MAX_FRACTION <= n {
            let apply_m = |x: MatRef<'_, f64>, mut out: MatMut<'_, f64>| {
                faer::linalg::matmul::matmul(
                    out.as_mut(),
                    faer::Accum::Replace,
                    ms.as_ref(),
                    x,
                    1.0,
                    Par::Seq,
                )
            };
            match lowest_pairs(&DenseFactor(l), apply_m, count, stop) {
                Ok((values, vectors)) => return Ok(GeneralizedEigen { values, vectors }),
                Err(EigenError::Interrupted) => return Err(EigenError::Interrupted),
                // not converged: the full method
                Err(_) => {}
            }
        }
    }
    let y = match lk {
        Some(l) => {
            // K = Lk Lkᵀ: Lk⁻¹ M Lk⁻ᵀ y = (1/λ) y, v = Lk⁻ᵀ y; largest 1/λ first
            let (s, u) = standard_eigen(congruence(&l, &ms))?;
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
            back_substitute(&l, Mat::from_fn(n, count, |i, j| u[(i, order[j])]))
        }
        None => {
            // M = Lm Lmᵀ: Lm⁻¹ K Lm⁻ᵀ y = λ y, v = Lm⁻ᵀ y; smallest λ first
            let l = match lm.take() {
                Some(l) => l,
                None => cholesky(&ms).ok_or(EigenError::NotPositiveDefinite { matrix: None })?,
            };
            let (s, u) = standard_eigen(congruence(&l, &ks))?;
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| s[a].total_cmp(&s[b]));
            back_substitute(&l, Mat::from_fn(n, count, |i, j| u[(i, order[j])]))
        }
    };
    check_stop(stop)?;
    // Rayleigh quotients and M-normalization
    let kv = &ks * &y;
    let mv = &ms * &y;
    let mut pairs: Vec<(f64, usize, f64)> = (0..count)
        .map(|j| {
            let vm: f64 = (0..n).map(|i| y[(i, j)] * mv[(i, j)]).sum();
            let vk: f64 = (0..n).map(|i| y[(i, j)] * kv[(i, j)]).sum();
            (vk / vm, j, 1.0 / vm.abs().sqrt())
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let values = pairs.iter().map(|p| p.0).collect();
    let vectors = Mat::from_fn(n, count, |i, c| y[(i, pairs[c].1)] * pairs[c].2);
    Ok(GeneralizedEigen { values, vectors })
}

/// All eigenvalues ν, ascending, of the symmetric pencil `A v = ν B v` with B
/// positive definite (by B's Cholesky factor; no eigenvectors). The buckling
/// load factors μ of `K v = −μ G v` are 1/ν of `−G v = ν K v`.
pub fn generalized_eigenvalues(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
) -> Result<Vec<f64>, EigenError> {
    let n = check_dims(a, b)?;
    check_finite(a, Member::K)?;
    check_finite(b, Member::M)?;
    if n == 0 {
        return Ok(vec![]);
    }
    let l = cholesky(&sym(b)).ok_or(EigenError::NotPositiveDefinite {
        matrix: Some(Member::M),
    })?;
    let c = congruence(&l, &sym(a));
    let mut vals: Vec<f64> = c
        .self_adjoint_eigenvalues(Side::Lower)
        .map_err(|_| EigenError::NoConvergence { n })?;
    vals.sort_by(|x, y| x.total_cmp(y));
    Ok(vals)
}

/// Eigenvalues and eigenvectors (columns) of a dense symmetric matrix.
fn standard_eigen(c: Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), EigenError> {
    let n = c.nrows();
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| EigenError::NoConvergence { n })?;
    let s = evd.S();
    Ok(((0..n).map(|i| s[i]).collect(), evd.U().to_owned()))
}

/// v = L⁻ᵀ y.
fn back_substitute(l: &Mat<f64>, mut y: Mat<f64>) -> Mat<f64> {
    tri::solve_upper_triangular_in_place(l.transpose(), y.as_mut(), Par::Seq);
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    /// max |VᵀMV − I| and max over the pairs of ‖K v − λ M v‖ / (‖K‖ ‖v‖).
    fn residuals(k: &Mat<f64>, m: &Mat<f64>, e: &GeneralizedEigen) -> (f64, f64) {
        let v = &e.vectors;
        let p = v.nrows();
        let c = v.ncols();
        let vmv = v.transpose() * m * v;
        let orth = (vmv - Mat::<f64>::identity(c, c)).norm_max();
        let kv = k * v;
        let mv = m * v;
        let knorm = k.norm_max() * p as f64;
        let res = (0..c)
            .map(|j| {
                let r: f64 = (0..p)
                    .map(|i| (kv[(i, j)] - e.values[j] * mv[(i, j)]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let vn: f64 = (0..p).map(|i| v[(i, j)].powi(2)).sum::<f64>().sqrt();
                r / (knorm * vn)
            })
            .fold(0.0, f64::max);
        (orth, res)
    }

    /// A spring–mass chain: K = k·tridiag(−1, 2, −1) (fixed at both ends),
    /// M = m·I has the known eigenvalues λⱼ = (4k/m) sin²(jπ / (2(n + 1))).
    #[test]
    fn spring_mass_chain_has_its_known_eigenvalues() {
        let n = 12;
        let (kk, mm) = (3.0e4, 0.2);
        let k = Mat::from_fn(n, n, |i, j| {
            if i == j {
                2.0 * kk
            } else if i.abs_diff(j) == 1 {
                -kk
            } else {
                0.0
            }
        });
        let m = Mat::from_fn(n, n, |i, j| if i == j { mm } else { 0.0 });
        for definite in [Definite::Mass, Definite::Either] {
            let e = generalized_eigen(k.as_ref(), m.as_ref(), n, definite).unwrap();
            for (j, l) in e.values.iter().enumerate() {
                let s = ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin();
                let expect = 4.0 * kk / mm * s * s;
                assert!(
                    (l / expect - 1.0).abs() < 1e-12,
                    "λ{j} = {l}, expected {expect}"
                );
            }
            let (orth, res) = residuals(&k, &m, &e);
            assert!(
                orth < 1e-12 && res < 1e-13,
                "VᵀMV − I: {orth}, residual {res}"
            );
        }
    }

    /// A dense random pencil with an indefinite K (so M's factor is used)
    /// and a positive definite one (K's factor), the lowest three pairs.
    #[test]
    fn random_pencils_satisfy_the_eigen_equations() {
        let mut state = 5u64;
        let mut rnd = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let n = 15;
        let g = Mat::from_fn(n, n, |_, _| rnd());
        let h = Mat::from_fn(n, n, |_, _| rnd());
        let m = &g * g.transpose() + Mat::<f64>::identity(n, n) * 0.1;
        let spd = &h * h.transpose() + Mat::<f64>::identity(n, n) * 0.5;
        let indefinite = &spd - Mat::<f64>::identity(n, n) * 2.0;
        for k in [spd, indefinite] {
            let e = generalized_eigen(k.as_ref(), m.as_ref(), 3, Definite::Mass).unwrap();
            assert_eq!((e.values.len(), e.vectors.ncols()), (3, 3));
            assert!(e.values.windows(2).all(|w| w[0] <= w[1]));
            let (orth, res) = residuals(&k, &m, &e);
            assert!(
                orth < 1e-10 && res < 1e-12,
                "VᵀMV − I: {orth}, residual {res}"
            );
            // the lowest three of all
            let all = generalized_eigen(k.as_ref(), m.as_ref(), n, Definite::Either).unwrap();
            for (a, b) in e.values.iter().zip(&all.values) {
                assert!((a - b).abs() <= 1e-10 * b.abs().max(1.0), "{a} vs {b}");
            }
        }
    }

    /// K positive definite and M singular is solvable with `Either` (the
    /// finite eigenvalues first), an error with `Mass`; neither definite is
    /// an error; non-finite entries and mismatched sizes are refused.
    #[test]
    fn singular_and_invalid_pencils_give_errors() {
        let k = Mat::from_fn(2, 2, |i, j| [[2.0, -1.0], [-1.0, 2.0]][i][j]);
        let m = Mat::from_fn(2, 2, |i, j| if i == j && i == 0 { 1.0 } else { 0.0 });
        assert_eq!(
            generalized_eigen(k.as_ref(), m.as_ref(), 2, Definite::Mass).unwrap_err(),
            EigenError::NotPositiveDefinite {
                matrix: Some(Member::M)
            }
        );
        let e = generalized_eigen(k.as_ref(), m.as_ref(), 1, Definite::Either).unwrap();
        // K v = λ M v with M = diag(1, 0): λ = det K / K₂₂ = 3/2
        assert!((e.values[0] - 1.5).abs() < 1e-14, "{:?}", e.values);
        let indefinite = Mat::from_fn(2, 2, |i, j| if i == j { [1.0, -1.0][i] } else { 0.0 });
        let err =
            generalized_eigen(indefinite.as_ref(), m.as_ref(), 2, Definite::Either).unwrap_err();
        assert_eq!(err, EigenError::NotPositiveDefinite { matrix: None });
        assert!(err.to_string().contains("neither K nor M"), "{err}");
        let mut nan = k.clone();
        nan[(1, 0)] = f64::NAN;
        assert!(matches!(
            generalized_eigen(k.as_ref(), nan.as_ref(), 2, Definite::Mass),
            Err(EigenError::NonFinite {
                matrix: Member::M,
                row: 1,
                col: 0,
                ..
            })
        ));
        assert!(matches!(
            generalized_eigen(
                k.as_ref(),
                Mat::<f64>::zeros(3, 3).as_ref(),
                2,
                Definite::Mass
            ),
            Err(EigenError::Dimension { m_rows: 3, .. })
        ));
        assert!(generalized_eigen(
            Mat::<f64>::zeros(0, 0).as_ref(),
            Mat::<f64>::zeros(0, 0).as_ref(),
            3,
            Definite::Mass
        )
        .unwrap()
        .values
        .is_empty());
    }

    /// A ν = B with B = diag(1, 4), A = diag(2, −4): ν = (−1, 2); B not
    /// positive definite is an error.
    #[test]
    fn eigenvalues_of_a_pencil() {
        let a = Mat::from_fn(2, 2, |i, j| if i == j { [2.0, -4.0][i] } else { 0.0 });
        let b = Mat::from_fn(2, 2, |i, j| if i == j { [1.0, 4.0][i] } else { 0.0 });
        let v = generalized_eigenvalues(a.as_ref(), b.as_ref()).unwrap();
        assert!(
            (v[0] + 1.0).abs() < 1e-15 && (v[1] - 2.0).abs() < 1e-15,
            "{v:?}"
        );
        assert_eq!(
            generalized_eigenvalues(b.as_ref(), a.as_ref()).unwrap_err(),
            EigenError::NotPositiveDefinite {
                matrix: Some(Member::M)
            }
        );
    }

    /// A few pairs of a large pencil come from the partial method: a
    /// spring–mass chain of order 400 with varying masses (a dense pencil in
    /// effect: M is diagonal but not a multiple of I), K positive definite.
    /// The 4 lowest pairs agree with the full method (all 400 pairs) to
    /// 1e-11 relative, satisfy K v = λ M v and VᵀMV = I; for the uniform chain
    /// they are the known λⱼ = (4k/m) sin²(jπ/(2(n + 1))). A set stop flag
    /// ends it with `Interrupted`.
    #[test]
    fn a_few_pairs_of_a_large_pencil_come_from_the_partial_method() {
        // large enough for the partial method, 4 pairs few enough
        let n = 2 * PARTIAL_MIN_DIM;
        let kk = 2.0e4;
        let k = Mat::from_fn(n, n, |i, j| {
            if i == j {
                2.0 * kk
            } else if i.abs_diff(j) == 1 {
                -kk
            } else {
                0.0
            }
        });
        for uniform in [true, false] {
            let mass = |i: usize| {
                if uniform {
                    0.3
                } else {
                    0.3 + 0.2 * (0.37 * i as f64).sin()
                }
            };
            let m = Mat::from_fn(n, n, |i, j| if i == j { mass(i) } else { 0.0 });
            let few = generalized_eigen(k.as_ref(), m.as_ref(), 4, Definite::Mass).unwrap();
            let all = generalized_eigen(k.as_ref(), m.as_ref(), n, Definite::Mass).unwrap();
            assert_eq!(few.values.len(), 4);
            for j in 0..4 {
                let r = few.values[j] / all.values[j] - 1.0;
                assert!(
                    r.abs() < 1e-11,
                    "λ{j}: {} against {}",
                    few.values[j],
                    all.values[j]
                );
                if uniform {
                    let s = ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin();
                    let exact = 4.0 * kk / 0.3 * s * s;
                    assert!((few.values[j] / exact - 1.0).abs() < 1e-10, "λ{j}");
                }
            }
            let (orth, res) = residuals(&k, &m, &few);
            assert!(orth < 1e-10 && res < 1e-12, "{orth:e} {res:e}");
        }
        let m = Mat::<f64>::identity(n, n);
        let stop = AtomicBool::new(true);
        assert_eq!(
            generalized_eigen_until(k.as_ref(), m.as_ref(), 4, Definite::Mass, Some(&stop))
                .unwrap_err(),
            EigenError::Interrupted
        );
        stop.store(false, std::sync::atomic::Ordering::Relaxed);
        assert!(
            generalized_eigen_until(k.as_ref(), m.as_ref(), 4, Definite::Mass, Some(&stop)).is_ok()
        );
    }

    /// The full method on a large pencil (all pairs of order 900: seconds of
    /// factorization and decomposition without a check inside) is left on a
    /// stop request 20 ms after the start, in less than a third of the time
    /// the uninterrupted solution takes, and the same call without a stop
    /// request gives the same pairs as the one without a flag.
    #[test]
    fn a_stop_request_leaves_the_full_method_of_a_large_pencil_at_once() {
        use std::sync::atomic::Ordering;
        use std::time::{Duration, Instant};
        let n = 900;
        assert!(n >= ABANDON_MIN_DIM);
        let k = Mat::from_fn(n, n, |i, j| {
            let d = i.abs_diff(j) as f64;
            if i == j {
                4.0 + (0.1 * i as f64).sin()
            } else {
                0.5 / (1.0 + d * d)
            }
        });
        let m = Mat::from_fn(
            n,
            n,
            |i, j| if i == j { 1.0 + 0.001 * i as f64 } else { 0.0 },
        );
        let start = Instant::now();
        let plain = generalized_eigen(k.as_ref(), m.as_ref(), n, Definite::Mass).unwrap();
        let full = start.elapsed();
        let stop = AtomicBool::new(false);
        let flagged =
            generalized_eigen_until(k.as_ref(), m.as_ref(), n, Definite::Mass, Some(&stop))
                .unwrap();
        assert_eq!(plain.values, flagged.values);
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let setter = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            s.store(true, Ordering::SeqCst);
        });
        let start = Instant::now();
        let r = generalized_eigen_until(k.as_ref(), m.as_ref(), n, Definite::Mass, Some(&stop));
        let stopped = start.elapsed();
        setter.join().unwrap();
        assert_eq!(r.unwrap_err(), EigenError::Interrupted);
        assert!(
            stopped < full / 3,
            "stopped after {stopped:?}; the uninterrupted solution took {full:?}"
        );
    }
}
