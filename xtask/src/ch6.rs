//! Thesis chapter 6, §6.4: the spatial compliant straight guidance (Table 6.1,
//! (6.27), gravity, 44 DOF), reduced with the fixed basis method (MODAL-2,
//! SVD-7, SVD-13; deformation coordinates as DOFs) and the interpolated basis
//! method (MSI-2, MSI-7, MSI-7g, MAC-7; absolute nodal coordinates as DOFs),
//! integrated with the Adams (Shampine–Gordon style) integrator.

use crate::curves::StoredCurve;
use crate::models::{quasi_static_curve, CurvePoint, Model, ModelKind};
use crate::progress::Progress;
use flexmb_linearize::{sweep, SweepOptions, SweepParameter, SweepPoint};
use flexmb_model::{Component, DofChoice, Mechanism, Scene, Select};
use flexmb_reduction::{
    interpolated_basis_from_sweep, modal_basis, per_mode_svd_basis, PerModeSvd,
    SubspaceInterpolation, SVD_THRESHOLD,
};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The scene file, relative to the workspace root.
pub const SCENE: &str = "fixtures/scenes/straight_guidance_spatial.ron";
/// The node whose x- and z-displacements are reported ("coordinate s").
pub const NODE: &str = "S";
/// Time at which the force pulse (6.27) is at its maximum (100 N): the
/// quasi-static curves scale the loads at this time.
pub const T_LOAD: f64 = 0.05;

/// The selection rule of the last SVD of §6.3.2 (step 9); the reasoning is at
/// [`flexmb_reduction::FINAL_SVD_THRESHOLD`].
pub const FINAL_THRESHOLD: f64 = flexmb_reduction::FINAL_SVD_THRESHOLD;

/// Settings of the chapter 6 benchmark.
#[derive(Clone, Debug)]
pub struct Ch6Options {
    /// Reference configurations for the reduced bases (thesis: 300).
    pub n_ref: usize,
    /// Points of the quasi-static eigenfrequency curves.
    pub n_curve: usize,
    /// Largest x-displacement of the reference configurations (m): the
    /// thesis's maximal deflection 0.0834 m.
    pub x_max: f64,
    /// Simulated time (s).
    pub t_end: f64,
    /// Output points of the time responses.
    pub outputs: usize,
    /// Relative and absolute tolerances of the integrators.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

impl Default for Ch6Options {
    fn default() -> Self {
        Self {
            n_ref: 300,
            n_curve: 61,
            x_max: 0.0834,
            t_end: 0.3,
            outputs: 601,
            rtol: 1e-3,
            atol: 1e-6,
        }
    }
}

/// The four mechanisms of the chapter: deformation or nodal DOFs, with and
/// without gravity (the bases are built without gravity, §6.4.1).
pub struct Setup {
    /// Deformation DOFs, gravity (FBM and the unreduced reference).
    pub def: Arc<Mechanism>,
    /// Deformation DOFs, no gravity.
    pub def_nog: Arc<Mechanism>,
    /// Absolute nodal DOFs with the x of node S first, gravity (IBM).
    pub nod: Arc<Mechanism>,
    /// Absolute nodal DOFs, no gravity.
    pub nod_nog: Arc<Mechanism>,
    /// Index of x of node S among the nodal DOFs (the IBM's s).
    pub s_dof: usize,
    /// Load scale (at `T_LOAD`) of the static force that holds S at x_max
    /// without gravity.
    pub lambda_max: f64,
}

fn build(
    scene: &Scene,
    dofs: DofChoice,
    first: Vec<Select>,
    gravity: bool,
) -> Result<Arc<Mechanism>, String> {
    let mut s = scene.clone();
    s.dofs = dofs;
    s.dofs_first = first;
    if !gravity {
        s.gravity = None;
    }
    Ok(Arc::new(s.build(None).map_err(|e| e.to_string())?))
}

/// Loads the scene and builds the mechanisms.
pub fn setup(root: &Path, opts: &Ch6Options) -> Result<Setup, String> {
    let scene = Scene::load(&root.join(SCENE)).map_err(|e| e.to_string())?;
    let sx = vec![Select::Coord(NODE.into(), Component::X)];
    let def = build(&scene, DofChoice::Deformations, vec![], true)?;
    let def_nog = build(&scene, DofChoice::Deformations, vec![], false)?;
    let nod = build(&scene, DofChoice::NodalCoordinates, sx.clone(), true)?;
    let nod_nog = build(&scene, DofChoice::NodalCoordinates, sx, false)?;
    let xs = nod.node(NODE).ok_or("no node S")?.position[0];
    let s_dof = nod
        .dofs
        .iter()
        .position(|c| *c == flexmb_model::Coordinate::Node(xs))
        .ok_or("x of S is not a degree of freedom")?;
    // the force that holds S at x_max (no gravity), as a load scale at T_LOAD
    let mut dy = flexmb_dynamics::Dynamics::new(nod_nog.clone());
    let o = flexmb_dynamics::StaticOptions {
        held: vec![(s_dof, opts.x_max)],
        load_steps: 4,
        ..Default::default()
    };
    let x0 = nod_nog.q0()[s_dof];
    let o = flexmb_dynamics::StaticOptions {
        held: vec![(s_dof, x0 + opts.x_max)],
        ..o
    };
    let sol = dy
        .static_equilibrium(0.0, &nod_nog.q0(), &o)
        .map_err(|e| format!("equilibrium at x = x_max: {e}"))?;
    let unit = load_at(&nod_nog, T_LOAD);
    Ok(Setup {
        lambda_max: (sol.reactions[0] / unit).abs(),
        def,
        def_nog,
        nod,
        nod_nog,
        s_dof,
    })
}

/// The x-component of the scene's force at t (the pulse (6.27)).
fn load_at(mech: &Mechanism, t: f64) -> f64 {
    mech.loads
        .iter()
        .map(|l| match l {
            flexmb_model::Load::Force { f, function, .. } => f[0] * function.value(t),
            _ => 0.0,
        })
        .sum()
}

/// The reference data the bases are built from.
pub struct References {
    /// FBM: equilibria under a static x-force, no gravity, deformation DOFs.
    pub fbm: Vec<SweepPoint>,
    /// IBM: equilibria with x of S held, no gravity, nodal DOFs.
    pub ibm: Vec<SweepPoint>,
    /// IBM with gravity (MSI-7g).
    pub ibm_g: Vec<SweepPoint>,
    /// Wall time of the three sweeps (s).
    pub wall_time: f64,
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| a + (b - a) * k as f64 / (n.max(2) - 1) as f64)
        .collect()
}

/// The 3 × n_ref reference sweeps.
pub fn references(s: &Setup, opts: &Ch6Options, pg: &Progress) -> Result<References, String> {
    let start = std::time::Instant::now();
    let run = |mech: &Arc<Mechanism>,
               p: SweepParameter,
               values: Vec<f64>,
               t: f64,
               modes: usize,
               label: &str| {
        let bar = pg.bar(label, 2 * values.len() as u64);
        let o = SweepOptions {
            values,
            modes,
            t,
            keep_vectors: true,
        };
        let r = sweep(mech, &p, &o, &|d, _| bar.set(d as u64)).map_err(|e| format!("{label}: {e}"));
        bar.finish();
        r
    };
    let lam = linspace(-s.lambda_max, s.lambda_max, opts.n_ref);
    let x0 = s.nod.q0()[s.s_dof];
    let xs = linspace(x0 - opts.x_max, x0 + opts.x_max, opts.n_ref);
    let fbm = run(
        &s.def_nog,
        SweepParameter::LoadScale,
        lam,
        T_LOAD,
        4,
        "FBM reference configurations",
    )?;
    let ibm = run(
        &s.nod_nog,
        SweepParameter::Dof(s.s_dof),
        xs.clone(),
        0.0,
        7,
        "IBM reference configurations",
    )?;
    let ibm_g = run(
        &s.nod,
        SweepParameter::Dof(s.s_dof),
        xs,
        0.0,
        7,
        "IBM reference configurations (gravity)",
    )?;
    Ok(References {
        fbm,
        ibm,
        ibm_g,
        wall_time: start.elapsed().as_secs_f64(),
    })
}

/// The models of Tables 6.2 and 6.3, with the SVD data of Figs 6.7 and 6.8.
pub struct Models {
    /// Unreduced first, then MODAL-2, SVD-7, SVD-13, MSI-2, MSI-7, MSI-7g, MAC-7.
    pub models: Vec<Model>,
    /// Per-mode SVD of SVD-7.
    pub svd7: PerModeSvd,
    /// Per-mode SVD of SVD-13.
    pub svd13: PerModeSvd,
}

/// The eigenfrequencies each model is meant to capture (2 or 4, §6.4.1).
pub fn retained(name: &str) -> usize {
    match name {
        "MODAL-2" | "SVD-7" | "MSI-2" => 2,
        _ => 4,
    }
}

/// Builds all models from the references.
pub fn models(s: &Setup, r: &References) -> Result<Models, String> {
    let e = |x: flexmb_reduction::ReductionError| x.to_string();
    let q0d = s.def.q0();
    let q0n = s.nod.q0();
    let modal2 = modal_basis(&s.def_nog, 0.0, &q0d, 2, None).map_err(e)?;
    let svd7 =
        per_mode_svd_basis(&q0d, &r.fbm, &[0, 1], SVD_THRESHOLD, FINAL_THRESHOLD).map_err(e)?;
    let svd13 = per_mode_svd_basis(&q0d, &r.fbm, &[0, 1, 2, 3], SVD_THRESHOLD, FINAL_THRESHOLD)
        .map_err(e)?;
    let ibm = |pts: &[SweepPoint], r: usize, m: SubspaceInterpolation| {
        interpolated_basis_from_sweep(q0n.clone(), s.s_dof, pts, 1..1 + r, m, true).map_err(e)
    };
    use SubspaceInterpolation::{MacSorted, Msi};
    let name = |b: &flexmb_reduction::FixedBasis, base: &str| format!("{base}-{}", b.v.ncols());
    let models = vec![
        Model::new("Unreduced", &s.def, ModelKind::Unreduced),
        Model::new("MODAL-2", &s.def, ModelKind::Fixed(modal2)),
        Model::new(
            &name(&svd7.basis, "SVD"),
            &s.def,
            ModelKind::Fixed(svd7.basis.clone()),
        ),
        Model::new(
            &name(&svd13.basis, "SVD"),
            &s.def,
            ModelKind::Fixed(svd13.basis.clone()),
        ),
        Model::new(
            "MSI-2",
            &s.nod,
            ModelKind::Interpolated(Box::new(ibm(&r.ibm, 1, Msi)?)),
        ),
        Model::new(
            "MSI-7",
            &s.nod,
            ModelKind::Interpolated(Box::new(ibm(&r.ibm, 6, Msi)?)),
        ),
        Model::new(
            "MSI-7g",
            &s.nod,
            ModelKind::Interpolated(Box::new(ibm(&r.ibm_g, 6, Msi)?)),
        ),
        Model::new(
            "MAC-7",
            &s.nod,
            ModelKind::Interpolated(Box::new(ibm(&r.ibm, 6, MacSorted)?)),
        ),
    ];
    Ok(Models {
        models,
        svd7,
        svd13,
    })
}

/// The quasi-static curves of all models (in parallel): load scales
/// λ ∈ [−λmax, λmax] at `T_LOAD`, gravity on.
pub fn curves(
    s: &Setup,
    m: &Models,
    n: usize,
    pg: &Progress,
) -> Result<Vec<(String, Vec<CurvePoint>)>, String> {
    let lam = linspace(-s.lambda_max, s.lambda_max, n);
    let bar = pg.bar("eigenfrequency curves", m.models.len() as u64);
    let out: Result<Vec<_>, String> = m
        .models
        .par_iter()
        .map(|model| {
            let c = quasi_static_curve(model, T_LOAD, &lam, NODE, 4)?;
            bar.inc();
            Ok((model.name.clone(), c))
        })
        .collect();
    bar.finish();
    out
}

/// The stored form of the curves (x in m, up to four eigenfrequencies).
pub fn stored_curves(curves: &[(String, Vec<CurvePoint>)]) -> Vec<StoredCurve> {
    curves
        .iter()
        .map(|(n, c)| StoredCurve::from_points(n, c, 0, 4))
        .collect()
}

/// Where the chapter's fixtures live.
pub fn fixture_dir(root: &Path) -> PathBuf {
    root.join("fixtures/curves/ch6")
}

/// How the stored curves were produced (their CSV header).
pub fn provenance(opts: &Ch6Options, s: &Setup) -> Vec<String> {
    vec![
        format!("produced by `cargo xtask regress --update` (flexmb {}) from {SCENE}", env!("CARGO_PKG_VERSION")),
        format!(
            "quasi-static curve: static equilibrium under the x-force of (6.27) at t = {T_LOAD} s scaled by lambda in [-{:.6}, {:.6}] ({} points), gravity on, continuation from lambda = 0",
            s.lambda_max, s.lambda_max, opts.n_curve
        ),
        format!(
            "bases: {} reference configurations without gravity (MSI-7g: with), x_max = {} m; x = x-displacement of node S (m); f_k = undamped eigenfrequencies of the rest linearization (E.6)/(F.7) in Hz",
            opts.n_ref, opts.x_max
        ),
    ]
}
