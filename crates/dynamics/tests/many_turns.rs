//! Rotations without limits for dependent positions: the spin-up beam
//! (thesis §2.4.1) with absolute nodal coordinates as DOFs. The DOF choice
//! at the reference makes the x positions of the beam's nodes dependent,
//! solved from the rigid elongations; once the beam has turned by 90°
//! (t ≈ 5.6 s) the elongations no longer determine them, and a node's
//! scalar Euler parameter, solved from the normalization, is no longer
//! determined at 180°. A run re-chooses the dependent set where J of the
//! old one gets ill-conditioned (`Dynamics::switch_partition`,
//! docs/ARCHITECTURE.md "Re-partitioning of nodal DOFs"), so it follows the
//! beam through any number of turns.

use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions, Trajectory};
use flexmb_model::{DofChoice, Mechanism, Scene};
use std::path::Path;
use std::sync::Arc;

fn spin_up(dofs: DofChoice) -> Arc<Mechanism> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/spin_up_spatial_planar.ron");
    let mut scene = Scene::load(&p).unwrap();
    scene.dofs = dofs;
    Arc::new(scene.build(None).unwrap())
}

fn run(mech: &Arc<Mechanism>, integrator: Integrator, t_end: f64, n: usize) -> Trajectory {
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = dy.initial_qd(0.0, &q0).unwrap();
    let mut opts = SimulationOptions::new(integrator, 0.0, t_end, n);
    opts.rtol = 1e-10;
    opts.atol = 1e-12;
    dy.simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .unwrap_or_else(|e| panic!("{integrator:?}: {e}"))
}

/// The position of node `id` at each output of `traj`.
fn positions(mech: &Mechanism, traj: &Trajectory, id: &str) -> Vec<[f64; 2]> {
    let p = &mech.node(id).unwrap().position;
    traj.x.iter().map(|x| [x[p[0]], x[p[1]]]).collect()
}

/// 0–20 s, about eight turns: the nodal-DOF run re-chooses its dependent
/// coordinates on the way and has the tip positions of the run with
/// deformations as DOFs (a hinge angle and bending deformations, whose
/// dependent set never changes).
#[test]
fn spin_up_with_nodal_dofs_follows_the_deformation_model_through_20_s() {
    let nodal = spin_up(DofChoice::NodalCoordinates);
    assert!(!nodal.partition_eligible().is_empty());
    let deformation = spin_up(DofChoice::Deformations);
    assert!(deformation.partition_eligible().is_empty());
    let a = run(&nodal, Integrator::Adams, 20.0, 201);
    let b = run(&deformation, Integrator::Adams, 20.0, 201);
    assert_eq!(a.t.len(), 201);
    assert!(b.partition_switches.is_empty());
    // at least the x ↔ y exchange at every quarter turn
    assert!(
        a.partition_switches.len() >= 16,
        "{:?}",
        a.partition_switches
    );
    let (ta, tb) = (positions(&nodal, &a, "T"), positions(&deformation, &b, "T"));
    let mut worst = 0.0f64;
    for (pa, pb) in ta.iter().zip(&tb) {
        worst = worst.max((pa[0] - pb[0]).hypot(pa[1] - pb[1]));
    }
    // measured: 6.1e-8 m (rtol 1e-10; 31 switches)
    assert!(worst < 2e-7, "tip positions differ by {worst:e} m");
}

/// The spin-up beam with its hinge free, started at 4 rad/s: no torque
/// about the hinge axis, so energy and the angular momentum about it stay
/// constant. With nodal DOFs the dependent set changes at every quarter
/// turn; the run conserves both over 1.6 turns (2.5 s) and follows the
/// deformation-DOF run.
#[test]
fn a_free_spinning_beam_with_nodal_dofs_conserves_energy_and_momentum_through_switches() {
    let (nodal, deformation) = (
        free_spinning("NodalCoordinates"),
        free_spinning("Deformations"),
    );
    let mut worst_tip = 0.0f64;
    let runs: Vec<Trajectory> = [&nodal, &deformation]
        .iter()
        .map(|mech| {
            // energy and H_z at each output, in the chart the run has there
            let mut seen: Vec<(f64, f64)> = vec![];
            let mut dy = Dynamics::new((*mech).clone());
            let q0 = mech.q0();
            let qd0 = dy.initial_qd(0.0, &q0).unwrap();
            let mut opts = SimulationOptions::new(Integrator::Adams, 0.0, 2.5, 26);
            opts.rtol = 1e-10;
            opts.atol = 1e-12;
            let traj = dy
                .simulate_with(0.0, &q0, &qd0, &opts, |p| {
                    let en = p.dynamics.energies(p.t, p.q_chart, p.qd_chart).unwrap();
                    let h = p.dynamics.momentum(p.t, p.q_chart, p.qd_chart, [0.0; 3]);
                    seen.push((en.kinetic + en.elastic, h.unwrap().angular[2]));
                    Control::Continue
                })
                .unwrap();
            assert_eq!(seen.len(), 26);
            let (e0, h0) = seen[0];
            let de = seen
                .iter()
                .fold(0.0f64, |m, s| m.max((s.0 - e0).abs() / e0));
            let dh = seen
                .iter()
                .fold(0.0f64, |m, s| m.max((s.1 - h0).abs() / h0.abs()));
            // measured: 1.2e-8 and 5.8e-9 with nodal DOFs (6 switches),
            // 6.7e-13 with deformation DOFs
            assert!(
                de < 1e-7 && dh < 1e-7,
                "{}: energy {de:e}, momentum {dh:e}",
                mech.name
            );
            traj
        })
        .collect();
    assert!(
        runs[0].partition_switches.len() >= 5,
        "{:?}",
        runs[0].partition_switches
    );
    for (pa, pb) in
        positions(&nodal, &runs[0], "T")
            .iter()
            .zip(&positions(&deformation, &runs[1], "T"))
    {
        worst_tip = worst_tip.max((pa[0] - pb[0]).hypot(pa[1] - pb[1]));
    }
    // measured: 2.8e-7 m
    assert!(worst_tip < 1e-6, "tip positions differ by {worst_tip:e} m");
}

/// The spin-up beam with its hinge free, started at 4 rad/s about it.
fn free_spinning(dofs: &str) -> Arc<Mechanism> {
    let mut s = Scene::from_ron_str(&format!(
        r#"(
dimension: Spatial,
dofs: {dofs},
materials: {{ "aluminium": (e: 6.895e10, nu: 0.3, rho: 2766.67) }},
sections: {{ "beam": Rectangle(by: 0.03675, bz: 0.001986) }},
nodes: [ (id: "G", at: [0.0, 0.0, 0.0]), (id: "O", at: [0.0, 0.0, 0.0]), (id: "T", at: [8.0, 0.0, 0.0]) ],
elements: [
    (id: "drive", type: Hinge(nodes: ("G", "O"), axis: Some([0.0, 0.0, 1.0]))),
    (id: "beam", type: Beam((nodes: ("O", "T"), material: "aluminium", section: "beam", up: Some([0.0, 1.0, 0.0]), n: 4, timoshenko: false, shortening: false))),
],
fixed: [Node("G"), Coord("O", Position)],
rigid: [
    Def("drive", "bending_y"), Def("drive", "bending_z"),
    Def("beam", "elongation"), Def("beam", "torsion"),
    Def("beam", "bending_y_p"), Def("beam", "bending_y_q"),
],
initial_velocity: [ (omega: Some([0.0, 0.0, 4.0]), about: Some([0.0, 0.0, 0.0])) ],
)"#
    ))
    .unwrap();
    s.name = dofs.into();
    Arc::new(s.build(None).unwrap())
}

/// The re-partitioning restarts DOPRI5 and generalized-α too: the free
/// spinning beam with nodal DOFs through 286° (three changes of the
/// dependent set) ends where the Adams run with deformation DOFs does.
#[test]
fn dopri5_and_generalized_alpha_pass_the_changes_of_the_dependent_set() {
    let nodal = free_spinning("NodalCoordinates");
    let deformation = free_spinning("Deformations");
    let reference = run(&deformation, Integrator::Adams, 1.25, 6);
    let tip_ref = positions(&deformation, &reference, "T");
    // measured: 4.1e-8 m (DOPRI5) and 6.9e-5 m (generalized-α, a
    // second-order method at rtol 1e-7), 3 changes each
    for (integrator, rtol, tol) in [
        (Integrator::Dopri5, 1e-10, 2e-7),
        (Integrator::GeneralizedAlpha, 1e-7, 3e-4),
    ] {
        let mut dy = Dynamics::new(nodal.clone());
        let q0 = nodal.q0();
        let qd0 = dy.initial_qd(0.0, &q0).unwrap();
        let mut opts = SimulationOptions::new(integrator, 0.0, 1.25, 6);
        opts.rtol = rtol;
        opts.atol = rtol * 1e-2;
        let traj = dy
            .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
            .unwrap_or_else(|e| panic!("{integrator:?}: {e}"));
        assert!(
            traj.partition_switches.len() >= 3,
            "{integrator:?}: {:?}",
            traj.partition_switches
        );
        let tip = positions(&nodal, &traj, "T");
        let d = tip
            .iter()
            .zip(&tip_ref)
            .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).hypot(a[1] - b[1])));
        assert!(
            d < tol,
            "{integrator:?}: tip {d:e} m from the deformation run"
        );
    }
}
