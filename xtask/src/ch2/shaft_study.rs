//! The runs of the unbalanced shaft (thesis §2.4.3, [`super::shaft`]) that
//! `cargo xtask reproduce ch2` reports: the static reference (2.43) over
//! three meshes, the six spin-ups (B1, B2, B3 × joined at q and at p) and
//! the integration checks.

use super::segments::ShaftMesh;
use super::shaft::{self, Drive, Joined, ShaftResponse};
use super::spin_up::{integrator_name, Integration};
use flexmb_dynamics::Integrator;
use flexmb_element::VelocityTransform::{self, B1, B2, B3};
use flexmb_superelement::RigidBodyProperties;
use rayon::prelude::*;
use std::path::Path;

/// Simulated time (s): the spin-up (T = 15 s) and 5 s at Ω.
pub const T_END: f64 = 20.0;
/// Output points per second (the drive's work is integrated over them).
pub const OUTPUTS_PER_SECOND: f64 = 200.0;
/// The steady state is averaged over t ≥ this (s).
pub const STEADY_FROM: f64 = 17.0;
/// Generalized-α's relative tolerance (absolute: rtol/1000, m and rad).
pub const RTOL: f64 = 1e-6;
/// The meshes of the static convergence study: the rod divided 8, 16 and
/// 32 times along (4 × 4 across the cylinder), then the default
/// [`shaft::MESH`] and a finer cylinder section.
pub const MESHES: [ShaftMesh; 5] = [
    mesh(4, 8, 4),
    mesh(4, 16, 4),
    mesh(4, 32, 4),
    shaft::MESH,
    mesh(12, 32, 8),
];

const fn mesh(section: usize, rod: usize, cylinder: usize) -> ShaftMesh {
    ShaftMesh {
        section,
        rod,
        cylinder,
    }
}

/// The thesis's drive.
const SPIN_UP: Drive = Drive::SpinUp {
    omega: shaft::OMEGA,
};

/// One spin-up.
#[derive(Clone, Debug)]
pub struct SpinRun {
    /// Velocity transformation.
    pub transform: VelocityTransform,
    /// How the halves are joined.
    pub joined: Joined,
    /// Integrator and relative tolerance.
    pub integrator: Integrator,
    /// Relative tolerance.
    pub rtol: f64,
    /// The response.
    pub response: ShaftResponse,
}

impl SpinRun {
    /// The steady-state Δr: the mean over t ≥ [`STEADY_FROM`] (m).
    pub fn steady(&self) -> f64 {
        self.response.mean_after(STEADY_FROM)
    }
}

/// The static reference with one mesh.
#[derive(Clone, Debug)]
pub struct StaticRow {
    /// The mesh.
    pub mesh: ShaftMesh,
    /// Its description (elements, nodes, equations) and build time.
    pub description: String,
    /// The half's mass from M̄ (kg).
    pub half_mass: f64,
    /// Δr of (2.43) (m).
    pub dr: f64,
    /// Fixed-point iterations.
    pub iterations: usize,
}

/// Everything the shaft section reports.
#[derive(Clone, Debug)]
pub struct ShaftResults {
    /// The static reference per mesh ([`MESHES`]).
    pub statics: Vec<StaticRow>,
    /// The six spin-ups with generalized-α at [`RTOL`], then the checks:
    /// B3 at RTOL/10, Adams (explicit, no numerical damping) for B1 joined
    /// at q.
    pub runs: Vec<SpinRun>,
}

impl ShaftResults {
    /// The static reference with the default mesh (m).
    pub fn reference(&self) -> f64 {
        self.statics
            .iter()
            .find(|s| s.mesh == shaft::MESH)
            .map_or(f64::NAN, |s| s.dr)
    }

    /// The run of a transformation, joining, integrator and tolerance.
    pub fn run(
        &self,
        t: VelocityTransform,
        joined: Joined,
        integrator: Integrator,
        rtol: f64,
    ) -> Option<&SpinRun> {
        self.runs.iter().find(|r| {
            r.transform == t && r.joined == joined && r.integrator == integrator && r.rtol == rtol
        })
    }

    /// The main run (generalized-α at [`RTOL`]).
    pub fn main(&self, t: VelocityTransform, joined: Joined) -> Option<&SpinRun> {
        self.run(t, joined, Integrator::GeneralizedAlpha, RTOL)
    }
}

/// The analytic mass of a half: the rod and half the cylinder (kg).
pub fn half_mass_analytic() -> f64 {
    let rho = super::segments::steel().rho;
    rho * std::f64::consts::PI / 4.0
        * (shaft::D1 * shaft::D1 * shaft::L + shaft::D2 * shaft::D2 * 0.5 * shaft::L)
}

/// The static reference (2.43) with `mesh` (files in `dir`, named after
/// the mesh so that they do not overwrite the default ones).
fn static_row(dir: &Path, mesh: ShaftMesh) -> Result<StaticRow, String> {
    let sub = dir.join(format!(
        "shaft_mesh_{}_{}_{}",
        mesh.section, mesh.rod, mesh.cylinder
    ));
    let b = shaft::build_halves(&sub, Joined::AtQ, mesh)?;
    let rb = RigidBodyProperties::from_m_bar(&b.data.m_bar_matrix(), b.data.l0);
    let scene = shaft::scene(B3, Joined::AtQ, Drive::StaticForce);
    let (dr, iterations) = shaft::static_reference(&scene, &sub, shaft::M_U_THESIS, shaft::OMEGA)?;
    Ok(StaticRow {
        mesh,
        description: format!("{} ({:.1} s)", b.mesh, b.seconds),
        half_mass: rb.mass,
        dr,
        iterations,
    })
}

/// One spin-up of the shaft (files in `dir`).
pub fn spin(
    dir: &Path,
    t: VelocityTransform,
    joined: Joined,
    integrator: Integrator,
    rtol: f64,
) -> Result<SpinRun, String> {
    let scene = shaft::scene(t, joined, SPIN_UP);
    let how = Integration {
        integrator,
        rtol,
        atol: 1e-3 * rtol,
    };
    let response = shaft::run(
        &scene,
        dir,
        how,
        T_END,
        (T_END * OUTPUTS_PER_SECOND) as usize + 1,
    )?;
    Ok(SpinRun {
        transform: t,
        joined,
        integrator,
        rtol,
        response,
    })
}

/// The spin-ups of [`compute`], longest first: the Adams check, B3 at
/// RTOL/10, then the six runs with generalized-α at [`RTOL`].
fn spin_jobs() -> Vec<(VelocityTransform, Joined, Integrator, f64)> {
    let ga = Integrator::GeneralizedAlpha;
    let mut jobs = vec![
        (B1, Joined::AtQ, Integrator::Adams, RTOL),
        (B3, Joined::AtQ, ga, 0.1 * RTOL),
    ];
    for joined in [Joined::AtQ, Joined::AtP] {
        for t in [B1, B2, B3] {
            jobs.push((t, joined, ga, RTOL));
        }
    }
    jobs
}

/// The number of items [`compute`] reports as done: the static references
/// and the spin-ups.
pub fn job_count() -> usize {
    MESHES.len() + spin_jobs().len()
}

/// Builds the halves into `dir`, writes every scene there (so that
/// `flexmb simulate --integrator genalpha` repeats each run), and runs the
/// static references and the spin-ups in parallel; `done` is called with a
/// line per finished run.
pub fn compute(dir: &Path, done: &(dyn Fn(String) + Sync)) -> Result<ShaftResults, String> {
    for joined in [Joined::AtQ, Joined::AtP] {
        shaft::build_halves(dir, joined, shaft::MESH)?;
        for t in [B1, B2, B3] {
            let name = format!("shaft_{t:?}_joined_{}.ron", joined.label());
            std::fs::write(dir.join(&name), shaft::scene(t, joined, SPIN_UP))
                .map_err(|e| format!("{name}: {e}"))?;
        }
    }
    let name = "shaft_static_reference.ron";
    std::fs::write(
        dir.join(name),
        shaft::scene(B3, Joined::AtQ, Drive::StaticForce),
    )
    .map_err(|e| format!("{name}: {e}"))?;
    let statics: Vec<Result<StaticRow, String>> = MESHES
        .par_iter()
        .map(|&m| {
            let r = static_row(dir, m);
            if let Ok(s) = &r {
                done(format!(
                    "shaft static reference, mesh {}/{}/{}: Δr {:.4e} m",
                    m.section, m.rod, m.cylinder, s.dr
                ));
            }
            r
        })
        .collect();
    let runs: Vec<Result<SpinRun, String>> = spin_jobs()
        .par_iter()
        .map(|&(t, joined, integrator, rtol)| {
            let r = spin(dir, t, joined, integrator, rtol);
            done(match &r {
                Ok(r) => format!(
                    "shaft {t:?} joined at {}, {} rtol {rtol:.0e}: steady Δr {:.4e} m, {} evaluations in {:.1} s",
                    joined.label(),
                    integrator_name(integrator),
                    r.steady(),
                    r.response.evaluations,
                    r.response.wall_time
                ),
                Err(e) => format!("shaft {t:?} joined at {}: failed: {e}", joined.label()),
            });
            r
        })
        .collect();
    Ok(ShaftResults {
        statics: statics.into_iter().collect::<Result<_, _>>()?,
        runs: runs.into_iter().collect::<Result<_, _>>()?,
    })
}
