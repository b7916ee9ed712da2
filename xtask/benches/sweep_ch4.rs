//! One step of the chapter-4 sweep (thesis §4.4, `cargo xtask reproduce
//! ch4`): the 664-DOF mechanism (`fixtures/scenes/two_dof_mechanism.ron`)
//! with the end-effector held on the path (4.1), the equilibrium at the
//! next of the 50 equally spaced arc lengths and the rest linearization's
//! first 12 modes there. Issue 17's target is the whole 50-point sweep in
//! ≤ 30 s, so ≤ 0.6 s per step.
//!
//! Each iteration runs the first two points of the sweep (s = 0, where the
//! equilibrium is the reference, and s = L/49), so it times two eigen
//! solutions and one equilibrium step; the sweep's own points each cost
//! one of both.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use xtask::ch4::sweep;
use xtask::reproduce4::{fixture_scene, Ch4Options};

fn bench(c: &mut Criterion) {
    let root = xtask::workspace_root();
    let (mech, dofs) = sweep::mechanism(&fixture_scene(&root)).unwrap();
    let o = Ch4Options::default();
    let values: Vec<f64> = sweep::path_values(o.n).into_iter().take(2).collect();
    let mut g = c.benchmark_group("ch4 sweep (664 DOF)");
    g.sample_size(10);
    g.bench_function(
        "first two points: 2 eigen solutions, 1 equilibrium step",
        |b| {
            b.iter(|| {
                let points =
                    sweep::run(&mech, dofs, black_box(&values), o.modes, &|_, _| {}).unwrap();
                assert_eq!(points.len(), 2);
                points
            })
        },
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
