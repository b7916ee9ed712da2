//! Eigen-analyses of linearized equations: undamped modes (K + G) v = ω² M v
//! (thesis (4.2)), damped/gyroscopic/controlled modes from the state-space
//! matrix, and buckling load factors.

use crate::LinearizeError;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use flexmb_dynamics::Linearization;
use flexmb_linalg::{
    generalized_eigen_until, generalized_eigenvalues, Definite, EigenError, Member,
};
use std::sync::atomic::AtomicBool;

/// Undamped modes, sorted by increasing ω².
#[derive(Clone, Debug)]
pub struct Modes {
    /// ω² (rad²/s²); negative values mean an unstable (buckled) direction.
    pub omega2: Vec<f64>,
    /// Mass-normalized eigenvectors in q (n × k, vᵀ M v = 1).
    pub vectors: Mat<f64>,
}

impl Modes {
    /// Frequencies in Hz, signed: −√|ω²|/2π for negative ω².
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.omega2
            .iter()
            .map(|w2| w2.signum() * w2.abs().sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }
    /// Number of modes.
    pub fn len(&self) -> usize {
        self.omega2.len()
    }
    /// Whether there are no modes.
    pub fn is_empty(&self) -> bool {
        self.omega2.is_empty()
    }
}

fn sym(a: &Mat<f64>) -> Mat<f64> {
    let n = a.nrows();
    Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// The analysis error of a failed eigenproblem: `names` says what K and M of
/// the pencil are, `not_positive` is the error when the member that must be
/// positive definite is not (its culprit is named later, by [`named`]).
fn eigen_error(
    e: EigenError,
    names: [&'static str; 2],
    not_positive: LinearizeError,
) -> LinearizeError {
    match e {
        EigenError::Dimension { .. } | EigenError::TooMany { .. } => {
            LinearizeError::Dimension(e.to_string())
        }
        EigenError::NonFinite { matrix, .. } => LinearizeError::NonFinite(match matrix {
            Member::K => names[0],
            Member::M => names[1],
        }),
        EigenError::NotPositiveDefinite { .. } => not_positive,
        EigenError::Interrupted => LinearizeError::Interrupted,
        _ => LinearizeError::NoConvergence { at: String::new() },
    }
}

/// Solves the generalized symmetric-definite problem K v = λ M v for the `k`
/// lowest λ (all when `k` ≥ n). M must be positive definite. The problem is
/// transformed with the Cholesky factor of K when K is positive definite (which
/// keeps the low eigenvalues accurate when λ spans many decades), else with
/// that of M; the eigenvalues are then refined by Rayleigh quotients
/// ([`flexmb_linalg::generalized_eigen`]).
pub fn generalized_symmetric(
    k: &Mat<f64>,
    m: &Mat<f64>,
    count: usize,
) -> Result<Modes, LinearizeError> {
    generalized_symmetric_until(k, m, count, None)
}

/// [`generalized_symmetric`] that ends with [`LinearizeError::Interrupted`]
/// when `stop` is set ([`flexmb_linalg::generalized_eigen_until`]).
fn generalized_symmetric_until(
    k: &Mat<f64>,
    m: &Mat<f64>,
    count: usize,
    stop: Option<&AtomicBool>,
) -> Result<Modes, LinearizeError> {
    let e = generalized_eigen_until(k.as_ref(), m.as_ref(), count, Definite::Mass, stop).map_err(
        |e| {
            eigen_error(
                e,
                ["stiffness matrix", "mass matrix"],
                LinearizeError::MassNotPositive { dofs: vec![] },
            )
        },
    )?;
    Ok(Modes {
        omega2: e.values,
        vectors: e.vectors,
    })
}

/// Undamped modes of a linearization: (K + G + N) v = ω² M v with the
/// symmetric part of the stiffness (at rest with conservative loads the
/// tangent is symmetric; its asymmetry is reported by [`asymmetry`]). A few
/// modes of a large model are found by Krylov–Schur, not by a full
/// eigendecomposition ([`flexmb_linalg::eigen`]).
pub fn undamped_modes(lin: &Linearization, count: usize) -> Result<Modes, LinearizeError> {
    undamped_modes_until(lin, count, None)
}

/// [`undamped_modes`] that ends with [`LinearizeError::Interrupted`] when
/// `stop` is set: it is read between the factorizations and the steps of the
/// eigensolver ([`flexmb_linalg::generalized_eigen_until`]).
pub fn undamped_modes_until(
    lin: &Linearization,
    count: usize,
    stop: Option<&AtomicBool>,
) -> Result<Modes, LinearizeError> {
    generalized_symmetric_until(&lin.stiffness_total(), &lin.m, count, stop)
        .map_err(|e| named(lin, e))
}

/// An analysis error of `lin`'s matrices with its culprit named from the
/// mechanism and configuration of `lin`: the DOFs without inertia, the DOFs
/// of an unrestrained motion, the configuration where the eigenvalue solver
/// failed.
fn named(lin: &Linearization, e: LinearizeError) -> LinearizeError {
    let mech = &lin.at.mechanism;
    match e {
        LinearizeError::MassNotPositive { dofs } if dofs.is_empty() => {
            LinearizeError::MassNotPositive {
                dofs: flexmb_dynamics::massless_dofs(mech, sym(&lin.m).as_ref()),
            }
        }
        LinearizeError::StiffnessNotPositive { dofs } if dofs.is_empty() => {
            let all: Vec<usize> = (0..lin.k.nrows()).collect();
            LinearizeError::StiffnessNotPositive {
                dofs: flexmb_dynamics::null_space_dofs(mech, sym(&lin.k).as_ref(), &all),
            }
        }
        LinearizeError::NoConvergence { at } if at.is_empty() => LinearizeError::NoConvergence {
            at: lin.at.describe(),
        },
        e => e,
    }
}

/// ‖A − Aᵀ‖ / ‖A‖ (max norms).
pub fn asymmetry(a: &Mat<f64>) -> f64 {
    let n = a.nrows();
    let (mut d, mut m) = (0.0f64, 0.0f64);
    for i in 0..n {
        for j in 0..n {
            d = d.max((a[(i, j)] - a[(j, i)]).abs());
            m = m.max(a[(i, j)].abs());
        }
    }
    if m > 0.0 {
        d / m
    } else {
        0.0
    }
}

/// A damped mode: frequency and damping ratio of a complex eigenvalue pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DampedMode {
    /// Eigenvalue real part (1/s).
    pub re: f64,
    /// Eigenvalue imaginary part (rad/s), ≥ 0.
    pub im: f64,
    /// Undamped natural frequency |λ|/2π (Hz).
    pub frequency_hz: f64,
    /// Damping ratio −Re λ / |λ|.
    pub damping_ratio: f64,
}

/// Modes of M δq̈ + (D + C) δq̇ + (K + G + N) δq = 0 from the eigenvalues of the
/// state-space matrix [[0, I], [−M⁻¹(K+G+N), −M⁻¹(D+C)]]; one entry per
/// oscillating pair (Im λ > 0) or real eigenvalue, sorted by |λ|. For
/// gyroscopic, damped and controlled states (thesis Table 7.2).
pub fn damped_modes(lin: &Linearization) -> Result<Vec<DampedMode>, LinearizeError> {
    state_space_modes(lin).map_err(|e| named(lin, e))
}

/// [`damped_modes`] without naming the culprit of a failure.
fn state_space_modes(lin: &Linearization) -> Result<Vec<DampedMode>, LinearizeError> {
    damped_modes_of(&lin.m, &lin.damping_total(), &lin.stiffness_total())
}

/// [`damped_modes`] of the matrices of M δq̈ + D δq̇ + K δq = 0 (`damping`
/// D + C, `stiffness` K + G + N): e.g. a reduced linearization (F.5), whose
/// closed-loop poles thesis Table 7.2 gives.
pub fn damped_modes_of(
    mass: &Mat<f64>,
    damping: &Mat<f64>,
    stiffness: &Mat<f64>,
) -> Result<Vec<DampedMode>, LinearizeError> {
    let n = mass.nrows();
    if damping.nrows() != n || stiffness.nrows() != n {
        return Err(LinearizeError::Dimension(format!(
            "mass of order {n}, damping {}, stiffness {}",
            damping.nrows(),
            stiffness.nrows()
        )));
    }
    if n == 0 {
        return Ok(vec![]);
    }
    let llt = sym(mass)
        .llt(Side::Lower)
        .map_err(|_| LinearizeError::MassNotPositive { dofs: vec![] })?;
    let mut mk = stiffness.clone();
    let mut mc = damping.clone();
    llt.solve_in_place(mk.as_mut());
    llt.solve_in_place(mc.as_mut());
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| {
        if i < n {
            if j == n + i {
                1.0
            } else {
                0.0
            }
        } else if j < n {
            -mk[(i - n, j)]
        } else {
            -mc[(i - n, j - n)]
        }
    });
    let ev = a
        .eigenvalues()
        .map_err(|_| LinearizeError::NoConvergence { at: String::new() })?;
    let mut out: Vec<DampedMode> = ev
        .iter()
        .filter(|z| z.im >= -1e-12 * z.re.abs().max(z.im.abs()).max(1e-300))
        .map(|z| {
            let mag = (z.re * z.re + z.im * z.im).sqrt();
            DampedMode {
                re: z.re,
                im: z.im.abs(),
                frequency_hz: mag / (2.0 * std::f64::consts::PI),
                damping_ratio: if mag > 0.0 { -z.re / mag } else { 0.0 },
            }
        })
        .collect();
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    Ok(out)
}

/// Buckling load factors μ with K v = −μ G v (K the structural stiffness, G the
/// geometric stiffness of the current loads): the loads times μ make K + μG
/// singular. Returns the `count` smallest positive μ. K must be positive definite.
pub fn buckling_factors(lin: &Linearization, count: usize) -> Result<Vec<f64>, LinearizeError> {
    buckling_eigenvalues(lin, count).map_err(|e| named(lin, e))
}

/// [`buckling_factors`] without naming the culprit of a failure.
fn buckling_eigenvalues(lin: &Linearization, count: usize) -> Result<Vec<f64>, LinearizeError> {
    let n = lin.k.nrows();
    let mut g = sym(&lin.g);
    g += &sym(&lin.n);
    for v in g.col_iter_mut() {
        for e in v.iter_mut() {
            *e = -*e;
        }
    }
    // −G v = ν K v
    let vals = generalized_eigenvalues(g.as_ref(), lin.k.as_ref()).map_err(|e| {
        eigen_error(
            e,
            ["geometric stiffness", "stiffness matrix"],
            LinearizeError::StiffnessNotPositive { dofs: vec![] },
        )
    })?;
    // μ = 1/ν for ν > 0
    let mut mu: Vec<f64> = vals
        .iter()
        .filter(|v| **v > 1e-14 * vals.iter().fold(0.0f64, |m, x| m.max(x.abs())))
        .map(|v| 1.0 / v)
        .collect();
    mu.sort_by(|a, b| a.total_cmp(b));
    mu.truncate(count.min(n));
    Ok(mu)
}
