//! Where rotations still meet a limit: the spin-up beam (thesis §2.4.1) with
//! absolute nodal coordinates as DOFs. The DOF choice at the reference makes
//! the x positions of the beam's nodes dependent, solved from the rigid
//! elongations; once the beam has turned by 90° (t ≈ 5.6 s) the elongations
//! no longer determine them. Euler-parameter charts switch (see
//! `rigid_body.rs`), dependent positions do not yet: the run must stop with a
//! message that names the coordinates and the reason, not a bare step-size
//! underflow.

use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions};
use flexmb_model::{DofChoice, Scene};
use std::path::Path;
use std::sync::Arc;

#[test]
fn spin_up_with_nodal_dofs_stops_at_90_degrees_naming_the_coordinates() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/spin_up_spatial_planar.ron");
    let mut scene = Scene::load(&p).unwrap();
    scene.dofs = DofChoice::NodalCoordinates;
    let mech = Arc::new(scene.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    let mut opts = SimulationOptions::new(Integrator::Adams, 0.0, 20.0, 201);
    opts.rtol = 1e-8;
    opts.atol = 1e-11;
    let err = dy
        .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .expect_err("dependent positions cannot follow a 90° turn");
    let msg = err.to_string();
    // the cause is a singular Jacobian or a position solve that no longer
    // converges; either names the tip's dependent x
    for part in ["the last evaluation that failed", "T.x"] {
        assert!(msg.contains(part), "`{part}` missing from: {msg}");
    }
}
