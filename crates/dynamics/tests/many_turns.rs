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
    // measured: 4.6e-9 m (31 switches; rtol 1e-10)
    assert!(worst < 5e-8, "tip positions differ by {worst:e} m");
}
