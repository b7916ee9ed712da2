//! One evaluation of the equations of motion of the thesis's straight
//! guidances (44-DOF spatial, 17-DOF planar), and of the static tangent.
//!
//! "at one state" repeats the evaluation at a fixed (q, q̇): the position
//! solve converges at once and the kinematic factorization is of that very
//! configuration. "along a trajectory" evaluates, in their order, the states
//! a DOPRI5 run (ode45 tolerances) of the first 2 ms of the response asked
//! for, so chord Newton steps, a factorization of an earlier configuration
//! and its refinement, and refactorizations happen as in a simulation.

mod common;

use common::{load, one_state, trajectory};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn eom(c: &mut Criterion) {
    for (name, file) in [
        ("spatial guidance 44 DOF", "straight_guidance_spatial.ron"),
        ("planar guidance 17 DOF", "straight_guidance_planar.ron"),
    ] {
        let mut dy = load(file);
        let n = dy.n_q();
        let (q, qd) = one_state(&dy);
        let mut qdd = vec![0.0; n];
        dy.accelerations(0.05, &q, &qd, &mut qdd).unwrap();
        let mut g = c.benchmark_group(name);
        g.bench_function("equations of motion (q̈ from q, q̇) at one state", |b| {
            b.iter(|| {
                dy.accelerations(0.05, black_box(&q), &qd, &mut qdd)
                    .unwrap()
            })
        });
        g.bench_function(
            "equations of motion by the projection (D.10) at one state",
            |b| {
                b.iter(|| {
                    dy.accelerations_by_projection(0.05, black_box(&q), &qd, &mut qdd)
                        .unwrap()
                })
            },
        );
        let states = trajectory(file);
        let mut dy = load(file);
        let mut k = 0;
        let (f0, r0) = (
            dy.kinematics().factorizations(),
            dy.kinematics().refinements(),
        );
        let e0 = dy.evaluations();
        g.bench_function("equations of motion along a trajectory", |b| {
            b.iter(|| {
                let (t, y) = &states[k % states.len()];
                k += 1;
                dy.accelerations(*t, black_box(&y[..n]), &y[n..], &mut qdd)
                    .unwrap()
            })
        });
        let evals = (dy.evaluations() - e0).max(1) as f64;
        println!(
            "{name}: {} recorded states; per evaluation along them {:.3} factorizations and {:.2} refinement steps of the kinematic Jacobian",
            states.len(),
            (dy.kinematics().factorizations() - f0) as f64 / evals,
            (dy.kinematics().refinements() - r0) as f64 / evals
        );
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
