//! Eigen-analyses of linearized equations: undamped modes (K + G) v = ω² M v
//! (thesis (4.2)), damped/gyroscopic/controlled modes from the state-space
//! matrix, and buckling load factors.

use crate::LinearizeError;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use flexmb_dynamics::Linearization;

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

/// L⁻¹ A L⁻ᵀ (symmetrized) for a lower-triangular Cholesky factor L.
fn congruence(l: &Mat<f64>, a: &Mat<f64>) -> Mat<f64> {
    let mut b = a.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        l.as_ref(),
        b.as_mut(),
        faer::Par::Seq,
    );
    let mut bt = b.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        l.as_ref(),
        bt.as_mut(),
        faer::Par::Seq,
    );
    sym(&bt)
}

/// v = L⁻ᵀ y.
fn back_substitute(l: &Mat<f64>, mut y: Mat<f64>) -> Mat<f64> {
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        y.as_mut(),
        faer::Par::Seq,
    );
    y
}

/// Solves the generalized symmetric-definite problem K v = λ M v for the `k`
/// lowest λ (all when `k` ≥ n). M must be positive definite. The problem is
/// transformed with the Cholesky factor of K when K is positive definite (which
/// keeps the low eigenvalues accurate when λ spans many decades), else with
/// that of M; the eigenvalues are then refined by Rayleigh quotients.
pub fn generalized_symmetric(
    k: &Mat<f64>,
    m: &Mat<f64>,
    count: usize,
) -> Result<Modes, LinearizeError> {
    let n = k.nrows();
    if n == 0 {
        return Ok(Modes {
            omega2: vec![],
            vectors: Mat::zeros(0, 0),
        });
    }
    if k.ncols() != n || m.nrows() != n || m.ncols() != n {
        return Err(LinearizeError::Dimension(format!(
            "K is {}×{}, M is {}×{}",
            k.nrows(),
            k.ncols(),
            m.nrows(),
            m.ncols()
        )));
    }
    if k.col_iter()
        .flat_map(|c| c.iter().copied().collect::<Vec<_>>())
        .any(|v| !v.is_finite())
    {
        return Err(LinearizeError::NonFinite("stiffness matrix"));
    }
    let (ks, ms) = (sym(k), sym(m));
    let mllt = ms
        .llt(Side::Lower)
        .map_err(|_| LinearizeError::MassNotPositive { dofs: vec![] })?;
    let count = count.min(n);
    let vectors: Mat<f64> = match ks.llt(Side::Lower) {
        Ok(kllt) => {
            // K = Lk Lkᵀ: Lk⁻¹ M Lk⁻ᵀ y = (1/λ) y, v = Lk⁻ᵀ y; largest 1/λ first
            let l = kllt.L().to_owned();
            let evd = congruence(&l, &ms)
                .self_adjoint_eigen(Side::Lower)
                .map_err(|_| LinearizeError::NoConvergence { at: String::new() })?;
            let u = evd.U();
            back_substitute(&l, Mat::from_fn(n, count, |i, j| u[(i, n - 1 - j)]))
        }
        Err(_) => {
            // M = Lm Lmᵀ: Lm⁻¹ K Lm⁻ᵀ y = λ y, v = Lm⁻ᵀ y; smallest λ first
            let l = mllt.L().to_owned();
            let evd = congruence(&l, &ks)
                .self_adjoint_eigen(Side::Lower)
                .map_err(|_| LinearizeError::NoConvergence { at: String::new() })?;
            let u = evd.U();
            back_substitute(&l, Mat::from_fn(n, count, |i, j| u[(i, j)]))
        }
    };
    // mass-normalize and Rayleigh quotients
    let kv = &ks * &vectors;
    let mv = &ms * &vectors;
    let mut pairs: Vec<(f64, Vec<f64>)> = (0..count)
        .map(|j| {
            let vm: f64 = (0..n).map(|i| vectors[(i, j)] * mv[(i, j)]).sum();
            let vk: f64 = (0..n).map(|i| vectors[(i, j)] * kv[(i, j)]).sum();
            let s = 1.0 / vm.sqrt();
            (vk / vm, (0..n).map(|i| vectors[(i, j)] * s).collect())
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let omega2 = pairs.iter().map(|p| p.0).collect();
    let vectors = Mat::from_fn(n, count, |i, j| pairs[j].1[i]);
    Ok(Modes { omega2, vectors })
}

/// Undamped modes of a linearization: (K + G + N) v = ω² M v with the
/// symmetric part of the stiffness (at rest with conservative loads the
/// tangent is symmetric; its asymmetry is reported by [`asymmetry`]).
pub fn undamped_modes(lin: &Linearization, count: usize) -> Result<Modes, LinearizeError> {
    generalized_symmetric(&lin.stiffness_total(), &lin.m, count).map_err(|e| named(lin, e))
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
    let n = lin.m.nrows();
    if n == 0 {
        return Ok(vec![]);
    }
    let llt = sym(&lin.m)
        .llt(Side::Lower)
        .map_err(|_| LinearizeError::MassNotPositive { dofs: vec![] })?;
    let mut mk = lin.stiffness_total();
    let mut mc = lin.damping_total();
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
    let kllt = sym(&lin.k)
        .llt(Side::Lower)
        .map_err(|_| LinearizeError::StiffnessNotPositive { dofs: vec![] })?;
    let l = kllt.L().to_owned();
    let mut g = sym(&lin.g);
    g += &sym(&lin.n);
    for v in g.col_iter_mut() {
        for e in v.iter_mut() {
            *e = -*e;
        }
    }
    let vals = congruence(&l, &g)
        .self_adjoint_eigenvalues(Side::Lower)
        .map_err(|_| LinearizeError::NoConvergence { at: String::new() })?;
    // eigenvalues ν of Lk⁻¹(−G)Lk⁻ᵀ: μ = 1/ν for ν > 0
    let mut mu: Vec<f64> = vals
        .iter()
        .filter(|v| **v > 1e-14 * vals.iter().fold(0.0f64, |m, x| m.max(x.abs())))
        .map(|v| 1.0 / v)
        .collect();
    mu.sort_by(|a, b| a.total_cmp(b));
    mu.truncate(count.min(n));
    Ok(mu)
}
