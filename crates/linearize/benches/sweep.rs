//! Eigenfrequency sweeps: 300 equilibria plus eigen analyses of the 44-DOF
//! spatial straight guidance along its stroke (target ≤ 5 s on 2 cores).
//! The 720-DOF flexure chain (target ≤ 20 s for 50 configurations) is timed by
//! `flexmb sweep fixtures/scenes/flexure_chain_720.ron --over load --from 0 --to 1 --n 50`
//! (a criterion loop of it would take minutes).

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_linearize::{sweep, SweepOptions, SweepParameter};
use flexmb_model::{Component, Scene, Select};
use std::path::Path;
use std::sync::Arc;

fn guidance_sweep(c: &mut Criterion) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_spatial.ron");
    let mut s = Scene::load(&p).unwrap();
    s.gravity = None;
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    let mech = Arc::new(s.build(None).unwrap());
    let x0 = mech.q0()[0];
    let values: Vec<f64> = (0..300).map(|i| x0 + 0.083 * i as f64 / 299.0).collect();
    let opts = SweepOptions {
        values,
        modes: 4,
        t: 0.0,
        keep_vectors: false,
    };
    let mut g = c.benchmark_group("sweep");
    g.sample_size(10);
    g.bench_function("spatial guidance, 300 configurations, 4 modes", |b| {
        b.iter(|| sweep(&mech, &SweepParameter::Dof(0), &opts, &|_, _| {}).unwrap())
    });
    g.finish();
}

criterion_group!(benches, guidance_sweep);
criterion_main!(benches);
