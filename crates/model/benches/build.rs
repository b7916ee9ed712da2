//! Assembly of a clamped spatial beam chain (the chain helper, `n` beams,
//! 7(n+1) nodal coordinates, 6n DOFs) and of the tumbling beam of
//! `fixtures/scenes/tumbling_beam.ron` split into `n` beams (no support,
//! rigid elongation and torsion, 4n + 6 DOFs): parsing, elements, the sparse
//! choice of DOFs. This is all `flexmb info` does besides printing. Targets
//! (issue 14): ≤ 2 s at n = 1000, ≤ 30 s at n = 20000.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_model::Scene;
use std::hint::black_box;
use std::time::Duration;

fn chain(n: usize) -> String {
    format!(
        r#"(
    name: "chain {n}",
    dimension: Spatial,
    materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) }},
    sections: {{ "strip": Rectangle(by: 0.02, bz: 0.002) }},
    nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [1.0, 0.0, 0.0]) ],
    elements: [ (id: "c", type: Beam((nodes: ("A", "B"), material: "steel", section: "strip", up: Some([0.0, 0.0, 1.0]), n: {n}))) ],
    fixed: [Node("A")],
    loads: [ (node: "B", force: Some([0.0, 20.0, 0.0])) ],
)"#
    )
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("build chain");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    for n in [1000, 20000] {
        let text = chain(n);
        g.bench_function(format!("n = {n}"), |b| {
            b.iter(|| {
                let m = Scene::from_ron_str(black_box(&text))
                    .unwrap()
                    .build(None)
                    .unwrap();
                assert_eq!(m.n_dof(), 6 * n);
                m
            })
        });
    }
    let tumbling = include_str!("../../../fixtures/scenes/tumbling_beam.ron");
    for n in [1000, 20000] {
        let text = tumbling.replace("n: 2)", &format!("n: {n})"));
        g.bench_function(format!("free, n = {n}"), |b| {
            b.iter(|| {
                let m = Scene::from_ron_str(black_box(&text))
                    .unwrap()
                    .build(None)
                    .unwrap();
                assert_eq!(m.n_dof(), 4 * n + 6);
                m
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
