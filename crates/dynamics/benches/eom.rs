//! One evaluation of the equations of motion of the thesis's straight
//! guidances (44-DOF spatial, 17-DOF planar), and of the static tangent.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_dynamics::Dynamics;
use flexmb_model::Scene;
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;

fn load(name: &str) -> Dynamics {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Dynamics::new(Arc::new(Scene::load(&p).unwrap().build(None).unwrap()))
}

fn eom(c: &mut Criterion) {
    for (name, file) in [
        ("spatial guidance 44 DOF", "straight_guidance_spatial.ron"),
        ("planar guidance 17 DOF", "straight_guidance_planar.ron"),
    ] {
        let mut dy = load(file);
        let n = dy.n_q();
        let q: Vec<f64> = dy
            .mechanism()
            .q0()
            .iter()
            .enumerate()
            .map(|(i, v)| v + 1e-4 * ((i % 7) as f64 - 3.0))
            .collect();
        let qd: Vec<f64> = (0..n).map(|i| 1e-2 * ((i % 5) as f64 - 2.0)).collect();
        let mut qdd = vec![0.0; n];
        dy.accelerations(0.05, &q, &qd, &mut qdd).unwrap();
        let mut g = c.benchmark_group(name);
        g.bench_function("equations of motion (q̈ from q, q̇)", |b| {
            b.iter(|| {
                dy.accelerations(0.05, black_box(&q), &qd, &mut qdd)
                    .unwrap()
            })
        });
        g.bench_function("static tangent Kq + Gq", |b| {
            b.iter(|| dy.static_tangent(0.05, black_box(&q)).unwrap())
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(300));
    targets = eom
}
criterion_main!(benches);
