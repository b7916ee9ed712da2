//! A request to stop from outside (a signal handler in the CLI) ends a
//! simulation at the next integrator step and a static solve at the next
//! Newton iteration ([`SimulationOptions::stop`], [`StaticOptions::stop`]).

use flexmb_dynamics::{
    Control, Dynamics, DynamicsError, Integrator, SimulationOptions, StaticOptions,
};
use flexmb_model::Scene;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The planar straight guidance (17 DOF).
fn guidance() -> Dynamics {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_planar.ron");
    Dynamics::new(Arc::new(Scene::load(&p).unwrap().build(None).unwrap()))
}

/// Outputs at 0, 10 and 20 ms; the stop is requested while the output at
/// 10 ms is recorded (the observer goes on): the run ends at the next
/// accepted step, long before 20 ms (every integrator takes many steps per
/// 10 ms here), and its last row is the state at that step.
#[test]
fn a_stop_request_ends_a_simulation_at_the_next_step_with_that_state() {
    for integrator in [
        Integrator::Dopri5,
        Integrator::Adams,
        Integrator::GeneralizedAlpha,
    ] {
        let mut dy = guidance();
        let q0 = dy.mechanism().q0();
        let qd0 = vec![0.0; q0.len()];
        let stop = Arc::new(AtomicBool::new(false));
        let mut opts = SimulationOptions::new(integrator, 0.0, 0.02, 3);
        opts.stop = Some(stop.clone());
        let traj = dy
            .simulate(0.0, &q0, &qd0, &opts, |t, _, _| {
                if t == 0.01 {
                    stop.store(true, Ordering::Relaxed);
                }
                Control::Continue
            })
            .unwrap();
        assert!(traj.stopped, "{integrator:?}");
        assert_eq!(traj.t.len(), 3, "{integrator:?}: {:?}", traj.t);
        let t_stop = traj.t[2];
        assert!(
            t_stop > 0.01 && t_stop < 0.015,
            "{integrator:?} stopped at t = {t_stop}"
        );
        // the last row is the state the integrator had there
        assert_eq!(traj.q.len(), 3);
        assert!(traj.q[2].iter().all(|v| v.is_finite()));
        assert_ne!(traj.q[2], traj.q[1], "{integrator:?}");
        // without a request the same run reaches its end
        let mut opts = SimulationOptions::new(integrator, 0.0, 0.02, 3);
        opts.stop = Some(Arc::new(AtomicBool::new(false)));
        let traj = dy
            .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
            .unwrap();
        assert!(
            !traj.stopped && traj.t == vec![0.0, 0.01, 0.02],
            "{integrator:?}"
        );
    }
}

/// A static solve with the request already set ends before its first
/// Newton iteration with `Interrupted`; without it, it converges.
#[test]
fn a_stop_request_ends_a_static_solve() {
    let mut dy = guidance();
    let q0 = dy.mechanism().q0();
    let opts = StaticOptions {
        stop: Some(Arc::new(AtomicBool::new(true))),
        ..Default::default()
    };
    let e = dy.static_equilibrium(0.05, &q0, &opts).unwrap_err();
    assert_eq!(e, DynamicsError::Interrupted);
    let opts = StaticOptions {
        stop: Some(Arc::new(AtomicBool::new(false))),
        ..Default::default()
    };
    let sol = dy.static_equilibrium(0.05, &q0, &opts).unwrap();
    assert!(sol.iterations > 0);
}
