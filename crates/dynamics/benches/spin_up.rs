//! End to end: the spin-up beam of thesis §2.4.1 with 32 planar beams
//! (64 DOF) over 0–20 s with generalized-α at rtol 1e-7, atol 1e-9, the
//! tolerances at which its maximum tip deflection is within 0.02 % of the
//! converged 0.53411 m (`tests/spin_up.rs`). Issue 13, item 5: target ≤ 1 s.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions};
use flexmb_model::Scene;
use std::path::Path;
use std::sync::Arc;

fn spin_up_32(c: &mut Criterion) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenes/spin_up_planar.ron");
    let text = std::fs::read_to_string(p)
        .unwrap()
        .replace("n: 4,", "n: 32,");
    let mech = Arc::new(Scene::from_ron_str(&text).unwrap().build(None).unwrap());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    let mut opts = SimulationOptions::new(Integrator::GeneralizedAlpha, 0.0, 20.0, 401);
    opts.rtol = 1e-7;
    opts.atol = 1e-9;
    let mut g = c.benchmark_group("spin_up_32_beams");
    g.sample_size(10);
    g.bench_function("generalized-α 0–20 s, rtol 1e-7", |b| {
        b.iter(|| {
            let mut dy = Dynamics::new(mech.clone());
            dy.simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
                .unwrap()
                .stats
                .rhs_evals
        })
    });
    g.finish();
}

criterion_group!(benches, spin_up_32);
criterion_main!(benches);
