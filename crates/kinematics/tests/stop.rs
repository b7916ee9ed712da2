//! A position solve reads the stop request of `Kinematics::set_stop` at each
//! Newton iteration.

use flexmb_kinematics::{Kinematics, KinematicsError};
use flexmb_model::{DofChoice, Scene};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

#[test]
fn a_set_stop_request_ends_the_position_solve_and_a_cleared_one_lets_it_converge() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_spatial.ron");
    let mut scene = Scene::load(&p).unwrap();
    scene.dofs = DofChoice::NodalCoordinates;
    let mut kin = Kinematics::new(Arc::new(scene.build(None).unwrap()));
    let q0 = kin.mechanism().q0();
    // a configuration some Newton iterations away from the reference
    let q: Vec<f64> = q0
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * ((i % 5) as f64 - 2.0))
        .collect();
    let stop = Arc::new(AtomicBool::new(true));
    kin.set_stop(Some(stop.clone()));
    assert_eq!(kin.solve(&q, 0.0), Err(KinematicsError::Interrupted));
    stop.store(false, Ordering::Relaxed);
    kin.solve(&q, 0.0)
        .expect("converges once the request is cleared");
    assert!(kin.iterations() > 0);
    let x = kin.x().to_vec();
    // the same configuration as a solve that was never interrupted
    let mut fresh = Kinematics::new(kin.mechanism().clone());
    fresh.solve(&q, 0.0).unwrap();
    let d = x
        .iter()
        .zip(fresh.x())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-12, "differs by {d:e}");
    // no request: never stops
    kin.set_stop(None);
    kin.solve(&q0, 0.0).unwrap();
}
