//! Reduce and simulate: the planar straight guidance (17 degrees of freedom,
//! thesis §5.4.1) pushed by its force pulse, unreduced and with an SVD-modal
//! basis (thesis (5.22)–(5.23)) built from the modes at static equilibria
//! along the load. Both run through the same function, written once over
//! [`MechanicalModel`]; the reduced response of the node S must follow the
//! unreduced one within 1 % of the stroke, with fewer evaluations.
//!
//! `cargo run --release -p flexmb --example reduce_and_simulate`

use flexmb::linearize::sweep;
use flexmb::prelude::*;
use flexmb::reduction::SVD_THRESHOLD;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

/// The x-displacement of the node at nodal coordinate `xs` (reference
/// `x_ref`) over 0.3 s from the reference configuration at rest, and the
/// evaluations it took: the same study for any model.
fn response(
    model: &mut dyn MechanicalModel,
    xs: usize,
    x_ref: f64,
) -> Result<(Vec<f64>, usize), ReductionError> {
    let c0 = model.reference_coordinates();
    let cd0 = model.initial_velocities(0.0, &c0)?;
    let opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 0.3, 301);
    let run = model.simulate(0.0, &c0, &cd0, &opts, &mut |_, _, _| Control::Continue)?;
    let x = run.full.x.iter().map(|x| x[xs] - x_ref).collect();
    Ok((x, run.full.stats.rhs_evals))
}

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene = Scene::load(&root.join("fixtures/scenes/straight_guidance_planar.ron"))
        .expect("the guidance scene loads");
    let mech = Arc::new(scene.build(None).expect("the guidance builds"));
    let s = mech.node("S").expect("node S");
    let (xs, x_ref) = (s.position[0], s.at[0]);

    // the three lowest modes at ten static equilibria under ±120 % of the
    // pulse's peak force, compressed by an SVD (a = 0: modes not weighted)
    let values: Vec<f64> = (0..10).map(|k| -1.2 + 2.4 * k as f64 / 9.0).collect();
    let opts = SweepOptions {
        values,
        modes: 3,
        t: 0.05,
        keep_vectors: true,
    };
    let points = sweep(&mech, &SweepParameter::LoadScale, &opts, &|_, _| {}).expect("the sweep");
    let svd = svd_modal_basis(&mech.q0(), &points, 3, 0.0, SVD_THRESHOLD).expect("the SVD basis");
    let n_z = svd.basis.v.ncols();

    let (full, full_evals) =
        response(&mut Dynamics::new(mech.clone()), xs, x_ref).expect("unreduced run");
    let mut reduced =
        ReducedModel::new(mech.clone(), Box::new(svd.basis)).expect("the reduced model");
    let (red, red_evals) = response(&mut reduced, xs, x_ref).expect("reduced run");

    let stroke = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let error = full
        .iter()
        .zip(&red)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "unreduced: {} DOFs, {full_evals} evaluations; SVD-modal: {n_z} coordinates, {red_evals} evaluations",
        mech.n_dof()
    );
    println!(
        "stroke of S {stroke:.4e} m, largest difference {error:.3e} m ({:.3} % of the stroke)",
        100.0 * error / stroke
    );
    if error > 0.01 * stroke || red_evals >= full_evals {
        eprintln!("the reduced response is off by more than 1 % of the stroke, or not cheaper");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
