//! What the `eom` bench and the `eom_instructions` example share: a scene of
//! `fixtures/scenes`, the state they evaluate at and the states of a run.

use flexmb_dynamics::{integrate_explicit, Control, Dynamics, Integrator, SimulationOptions};
use flexmb_model::Scene;
use flexmb_ode::{OdeSystem, RhsError};
use std::path::Path;
use std::sync::Arc;

/// The dynamics of a scene of `fixtures/scenes`.
pub fn load(name: &str) -> Dynamics {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Dynamics::new(Arc::new(Scene::load(&p).unwrap().build(None).unwrap()))
}

/// The fixed state (q, q̇) "at one state" is evaluated at: q0 perturbed by
/// up to 3e-4, q̇ up to 2e-2 per DOF.
pub fn one_state(dy: &Dynamics) -> (Vec<f64>, Vec<f64>) {
    let q = dy
        .mechanism()
        .q0()
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-4 * ((i % 7) as f64 - 3.0))
        .collect();
    let qd = (0..dy.n_q())
        .map(|i| 1e-2 * ((i % 5) as f64 - 2.0))
        .collect();
    (q, qd)
}

/// The first-order system of `dy`, recording every state it is evaluated at.
struct Recorder<'a> {
    dy: &'a mut Dynamics,
    states: Vec<(f64, Vec<f64>)>,
    qdd: Vec<f64>,
}

impl OdeSystem for Recorder<'_> {
    fn dim(&self) -> usize {
        2 * self.dy.n_q()
    }
    fn rhs(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), RhsError> {
        let n = self.dy.n_q();
        self.states.push((t, y.to_vec()));
        self.dy
            .accelerations(t, &y[..n], &y[n..], &mut self.qdd)
            .map_err(|e| RhsError::new(e.to_string()))?;
        out[..n].copy_from_slice(&y[n..]);
        out[n..].copy_from_slice(&self.qdd);
        Ok(())
    }
}

/// The states (t, (q, q̇)) a DOPRI5 run (ode45 tolerances) of the first 2 ms
/// of the response of scene `name` from rest at q0 evaluates, in order.
pub fn trajectory(name: &str) -> Vec<(f64, Vec<f64>)> {
    let mut dy = load(name);
    let n = dy.n_q();
    let mut y0 = dy.mechanism().q0();
    y0.extend(vec![0.0; n]);
    let mut rec = Recorder {
        dy: &mut dy,
        states: vec![],
        qdd: vec![0.0; n],
    };
    let opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 2e-3, 4);
    integrate_explicit(&mut rec, &opts, 0.0, &y0, |_, _, _| Control::Continue).unwrap();
    rec.states
}
