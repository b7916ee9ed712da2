//! The spin-up beam of thesis §2.4.1: maximum tip deflection in the rotating
//! frame against the thesis's 0.5388 m (Table 2.1, SPACAR non-linear beams).

use flexmb_dynamics::{Control, Dynamics, Integrator, OutputTable, SimulationOptions};
use flexmb_model::{Mechanism, Scene};
use std::path::Path;
use std::sync::Arc;

fn mechanism(name: &str) -> Mechanism {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap().build(None).unwrap()
}

/// Simulates 0–20 s and returns the tip deflection Δy' in the frame rotating
/// with the prescribed spin-up angle, at 4001 output times (atol = rtol/1000).
fn tip_deflection(name: &str, integrator: Integrator, rtol: f64) -> (Vec<f64>, u64) {
    tip_deflection_of(mechanism(name), integrator, rtol, rtol * 1e-3)
}

/// [`tip_deflection`] of a given mechanism and tolerances.
fn tip_deflection_of(
    mech: Mechanism,
    integrator: Integrator,
    rtol: f64,
    atol: f64,
) -> (Vec<f64>, u64) {
    let mech = Arc::new(mech);
    let tip = mech.node("T").unwrap().position.clone();
    let spin = mech.inputs[0].function.clone();
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    let mut opts = SimulationOptions::new(integrator, 0.0, 20.0, 4001);
    opts.rtol = rtol;
    opts.atol = atol;
    let traj = dy
        .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .unwrap();
    let mut out = vec![];
    for (t, x) in traj.t.iter().zip(&traj.x) {
        let e = spin.value(*t);
        out.push(-e.sin() * x[tip[0]] + e.cos() * x[tip[1]]);
    }
    (out, traj.stats.rhs_evals as u64)
}

#[test]
fn planar_spin_up_maximum_tip_deflection_matches_the_thesis() {
    let (d, _) = tip_deflection("spin_up_planar.ron", Integrator::Dopri5, 1e-7);
    let max = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // thesis Table 2.1: 0.5388 m (SPACAR, 4 non-linear beams)
    assert!(
        (max / 0.5388 - 1.0).abs() < 0.01,
        "max tip deflection {max} m vs 0.5388 m"
    );
    // the same table's superelement models with B2/B3 (the formulation of our
    // beam inertia and elongation in this scene): 0.53754 m
    assert!(
        (max / 0.53754 - 1.0).abs() < 1e-3,
        "max tip deflection {max} m vs 0.53754 m"
    );
}

#[test]
fn spatial_beams_in_the_plane_give_the_planar_result() {
    let (a, _) = tip_deflection("spin_up_planar.ron", Integrator::Dopri5, 1e-8);
    let (b, _) = tip_deflection("spin_up_spatial_planar.ron", Integrator::Dopri5, 1e-8);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a
        .iter()
        .zip(&b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(
        diff < 1e-4 * scale,
        "planar vs spatial tip response differ by {diff} (max {scale})"
    );
}

/// Issue 13, item 5: generalized-α on the spin-up beam with 32 elements
/// (the fixture with `n: 32`, 64 DOF) at rtol 1e-7, atol 1e-9 reaches the
/// model's converged maximum deflection to 0.02 %. Converged value 0.53411 m
/// (generalized-α at rtol 1e-9/atol 1e-11: 0.534112 m; with the position
/// error estimate alone, before, 0.534118 m); measured 0.534182 m
/// (+0.013 %) with 1 844 evaluations in 0.8 s. With the position error
/// estimate alone the same tolerances gave 0.534284 m (+0.033 %).
#[test]
fn generalized_alpha_spin_up_with_32_beams_to_0_02_percent() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenes/spin_up_planar.ron");
    let text = std::fs::read_to_string(p)
        .unwrap()
        .replace("n: 4,", "n: 32,");
    let mech = Scene::from_ron_str(&text).unwrap().build(None).unwrap();
    assert_eq!(mech.n_dof(), 64);
    let (d, evals) = tip_deflection_of(mech, Integrator::GeneralizedAlpha, 1e-7, 1e-9);
    let max = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    eprintln!("32 beams, generalized-α: max {max} m, {evals} evaluations");
    assert!(
        (max / 0.53411 - 1.0).abs() < 2e-4,
        "max tip deflection {max} m vs the converged 0.53411 m"
    );
}

/// The output table (`Position("T")`) of the planar spin-up beam from 0 to
/// `t_end` with `n` outputs, rows (t, T.x, T.y), written after the run as the
/// CLI does.
fn tip_rows(integrator: Integrator, t_end: f64, n: usize) -> Vec<Vec<f64>> {
    let mech = Arc::new(mechanism("spin_up_planar.ron"));
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    let mut opts = SimulationOptions::new(integrator, 0.0, t_end, n);
    opts.rtol = 1e-6;
    opts.atol = 1e-9;
    let traj = dy
        .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .unwrap();
    assert_eq!(traj.x.len(), traj.t.len(), "one configuration per output");
    let table = OutputTable::new(&dy).unwrap();
    let mut rows = vec![];
    for k in 0..traj.t.len() {
        let mut r = vec![traj.t[k]];
        r.extend(
            table
                .row(&mut dy, traj.t[k], &traj.q[k], &traj.qd[k], &traj.x[k])
                .unwrap(),
        );
        rows.push(r);
    }
    rows
}

/// Issue 13 item 2: an output must not depend on the length of the run.
/// The outputs used to be solved after the run from its final configuration;
/// for 20 s the solve at t = 0 landed on the mirrored branch, tip at
/// x = −8 m. At t = 0 the beam is at rest in its reference configuration
/// (spin-up angle 0): the tip is at (8, 0) m, the scene's node T. Every
/// integrator; the rows at t ≤ 5 s of a 5 s and a 20 s run (same output
/// times, every 0.04 s; rtol 1e-6, atol 1e-9) agree far inside the
/// integration error: the runs differ only in step sizes chosen with the end
/// time in view (measured: DOPRI5 8.4e-11 m, Adams 2.0e-12 m, generalized-α,
/// whose step sequence depends on the end time from its first step,
/// 1.6e-7 m).
#[test]
fn outputs_do_not_depend_on_the_length_of_the_run() {
    for integrator in [
        Integrator::Dopri5,
        Integrator::Adams,
        Integrator::GeneralizedAlpha,
    ] {
        let long = tip_rows(integrator, 20.0, 501);
        let short = tip_rows(integrator, 5.0, 126);
        for rows in [&long, &short] {
            assert!(
                (rows[0][1] - 8.0).abs() < 1e-9 && rows[0][2].abs() < 1e-9,
                "{integrator:?}: tip at t = 0 at ({}, {}), not (8, 0)",
                rows[0][1],
                rows[0][2]
            );
        }
        let mut worst = 0.0f64;
        for (a, b) in short.iter().zip(&long) {
            assert!((a[0] - b[0]).abs() < 1e-12, "output times differ");
            worst = worst.max((a[1] - b[1]).abs()).max((a[2] - b[2]).abs());
        }
        let tol = if integrator == Integrator::GeneralizedAlpha {
            1e-6
        } else {
            1e-9
        };
        assert!(
            worst < tol,
            "{integrator:?}: rows at t ≤ 5 s differ by {worst:.3e} m between a 5 s and a 20 s run"
        );
    }
}
