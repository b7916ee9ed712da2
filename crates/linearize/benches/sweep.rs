//! Eigenfrequency sweeps: 300 equilibria plus eigen analyses of the 44-DOF
//! spatial straight guidance along its stroke (target ≤ 5 s on 2 cores).
//! The 720-DOF flexure chain (target ≤ 20 s for 50 configurations) is timed by
//! `flexmb sweep fixtures/scenes/flexure_chain_720.ron --over load --from 0 --to 1 --n 50`
//! (a criterion loop of it would take minutes).
//!
//! `held_sweep_gravity`: issue 14 item 7, the sweep over S.x with 10 beams
//! per flexure, with and without gravity, rigid and free elongation (target:
//! with gravity at most 2× the time without).

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

/// The spatial guidance with `n` beams per flexure, S.x the first DOF.
fn guidance(n: usize, gravity: bool, free_elongation: bool) -> Arc<flexmb_model::Mechanism> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_spatial.ron");
    let mut text = std::fs::read_to_string(p)
        .unwrap()
        .replace("n: 5", &format!("n: {n}"));
    if free_elongation {
        text = text.replace(
            r#"Def("flexure1", "elongation"), Def("flexure2", "elongation"), "#,
            "",
        );
    }
    let mut s = Scene::from_ron_str(&text).unwrap();
    if !gravity {
        s.gravity = None;
    }
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    Arc::new(s.build(None).unwrap())
}

fn held_sweep_gravity(c: &mut Criterion) {
    let mut g = c.benchmark_group("held_sweep_gravity");
    g.sample_size(10);
    for free in [false, true] {
        for gravity in [false, true] {
            let mech = guidance(10, gravity, free);
            let x0 = mech.q0()[0];
            let values: Vec<f64> = (0..20).map(|i| x0 + 0.08 * i as f64 / 19.0).collect();
            let opts = SweepOptions {
                values,
                modes: 6,
                t: 0.0,
                keep_vectors: false,
            };
            let name = format!(
                "10 beams per flexure, elongation {}, gravity {}",
                if free { "free" } else { "rigid" },
                if gravity { "on" } else { "off" }
            );
            g.bench_function(name, |b| {
                b.iter(|| sweep(&mech, &SweepParameter::Dof(0), &opts, &|_, _| {}).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group!(benches, guidance_sweep, held_sweep_gravity);
criterion_main!(benches);
