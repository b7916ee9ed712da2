//! What the reduced-model benches share: the recorded states of a run and
//! the benchmarks of one model on them.

use criterion::Criterion;
use flexmb_dynamics::{integrate_explicit, Control, Integrator, SimulationOptions};
use flexmb_model::Scene;
use flexmb_ode::{OdeSystem, RhsError};
use flexmb_reduction::ReducedModel;
use std::hint::black_box;
use std::path::Path;

/// A scene of `fixtures/scenes`.
pub fn scene(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap()
}

/// The first-order system of a reduced model, recording every state it is
/// evaluated at.
struct Recorder<'a> {
    model: &'a mut ReducedModel,
    states: Vec<(f64, Vec<f64>)>,
}

impl OdeSystem for Recorder<'_> {
    fn dim(&self) -> usize {
        self.model.dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), RhsError> {
        self.states.push((t, y.to_vec()));
        self.model.rhs(t, y, out)
    }
}

/// The states (t, (z, ż)) a run of `model` from (z0, 0) over [t0, t_end]
/// with `outputs` equidistant outputs evaluates.
pub fn trajectory(
    model: &mut ReducedModel,
    integrator: Integrator,
    (t0, t_end, outputs): (f64, f64, usize),
    z0: &[f64],
) -> Vec<(f64, Vec<f64>)> {
    let mut y0 = z0.to_vec();
    y0.extend(vec![0.0; z0.len()]);
    let mut rec = Recorder {
        model,
        states: vec![],
    };
    let opts = SimulationOptions::new(integrator, t0, t_end, outputs);
    integrate_explicit(&mut rec, &opts, t0, &y0, |_, _, _| Control::Continue).unwrap();
    rec.states
}

/// z̈ of `model` at (t, y = (z, ż)): by the projected evaluation, or by
/// the projection of the unreduced Mq if `full_mass`.
fn evaluate(model: &mut ReducedModel, full_mass: bool, t: f64, y: &[f64], zdd: &mut [f64]) {
    let n = model.n_z();
    if full_mass {
        model.accelerations_from_full_mass(t, &y[..n], &y[n..], zdd)
    } else {
        model.accelerations(t, &y[..n], &y[n..], zdd)
    }
    .unwrap()
}

/// The kinematic work per evaluation along `states` with each path (not
/// timed): Newton iterations of the position solve, factorizations and
/// refinement steps of J.
// (not inlined: a profile can be split after each call with callgrind's
// --dump-after)
#[inline(never)]
fn kinematic_work(model: &mut ReducedModel, states: &[(f64, Vec<f64>)], full_mass: bool) -> String {
    let n = model.n_z();
    let mut zdd = vec![0.0; n];
    let k = model.dynamics().kinematics();
    let (f0, r0) = (k.factorizations(), k.refinements());
    let mut iterations = 0;
    for (t, y) in states {
        evaluate(model, full_mass, *t, y, &mut zdd);
        iterations += model.dynamics().kinematics().iterations();
    }
    let k = model.dynamics().kinematics();
    let per = |a: u64, b: u64| (a - b) as f64 / states.len() as f64;
    format!(
        "{:.2} Newton iterations, {:.3} factorizations and {:.2} refinement steps of J per evaluation",
        per(iterations as u64, 0),
        per(k.factorizations(), f0),
        per(k.refinements(), r0)
    )
}

/// Benchmarks z̈ of one model at one state (the middle one) and along the
/// recorded states, by the projected evaluation and, if `full_mass`, by the
/// projection of the unreduced Mq (the reference path).
pub fn bench_model(
    c: &mut Criterion,
    group: &str,
    model: &mut ReducedModel,
    states: &[(f64, Vec<f64>)],
    full_mass: bool,
) {
    println!(
        "{group}: {} states; projected: {}",
        states.len(),
        kinematic_work(model, states, false)
    );
    if full_mass {
        println!(
            "{group}: full mass: {}",
            kinematic_work(model, states, true)
        );
    }
    let mut zdd = vec![0.0; model.n_z()];
    let (t, y) = states[states.len() / 2].clone();
    let mut g = c.benchmark_group(group);
    let paths: &[(&str, bool)] = if full_mass {
        &[("", false), ("by the full mass ", true)]
    } else {
        &[("", false)]
    };
    for &(label, full) in paths {
        g.bench_function(format!("z̈ {label}at one state"), |b| {
            b.iter(|| evaluate(model, full, t, black_box(&y), &mut zdd))
        });
        let mut k = 0;
        g.bench_function(format!("z̈ {label}along a trajectory"), |b| {
            b.iter(|| {
                let (t, y) = &states[k % states.len()];
                k += 1;
                evaluate(model, full, *t, black_box(y), &mut zdd)
            })
        });
    }
    g.finish();
}
