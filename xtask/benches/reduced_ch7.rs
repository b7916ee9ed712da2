//! One evaluation of the reduced equations of motion (6.15), z̈ from (z, ż),
//! of the 8-DOF IBM-u of the chapter 7 mechanism (thesis §7.2,
//! `fixtures/scenes/two_dof_mechanism_actuated.ron`, n_q = 664) in closed
//! loop: gravity and the PD controllers (7.12) following the angle
//! references, as `cargo xtask reproduce ch7` simulates it. Target ≤ 1 ms.
//!
//! Setup (about a minute, not timed) as in `xtask::reproduce7::compute`:
//! the reference configurations along the path without gravity, IBM-u from
//! them, the angle references from IBM-u's kinematics with η ≡ 0, the
//! closed-loop mechanism with gravity.
//!
//! The states follow the reference motion s(t) (7.13) every millisecond,
//! z = (s(t), η), ż = (ṡ(t), η̇) with small η = 1e-4 and η̇ = 1e-3
//! (the closed loop's deflections are of that order), and are evaluated in
//! the order of t so that each position solve starts from the previous one
//! and stays on the mechanism's branch (from s = 0 the solves beyond
//! s ≈ 0.19 m may converge to another). "at one state" repeats the state
//! where s first passes 0.1 m; "along the path" cycles through all states,
//! restarting the position solve from the undeflected configuration at the
//! wrap. "by the full mass" is the reference path, which forms the unreduced
//! Mq = F,qᵀ Mx F,q (664 × 664) and projects it: at one state only.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_reduction::ReducedModel;
use std::hint::black_box;
use xtask::ch4::sweep;
use xtask::ch7::{self, Variant};

/// (t, z, ż) of one evaluation.
type State = (f64, Vec<f64>, Vec<f64>);

/// The closed-loop IBM-u with gravity and the states (t, z, ż) along the
/// reference motion, every millisecond over the 1.5 s.
fn closed_loop() -> (ReducedModel, Vec<State>) {
    let root = xtask::workspace_root();
    let (mech, dofs) = ch7::mechanism(&root, false, None).unwrap();
    let values = ch7::reference_values(ch7::N_REFERENCE);
    let points = sweep::run(&mech, dofs, &values, ch7::R, &|_, _| {}).unwrap();
    let ibm_u = &ch7::basis(&mech, dofs, &points, Variant::Unconstrained, ch7::R).unwrap();
    let refs = ch7::angle_references(
        &mut ch7::reduced(&mech, ibm_u).unwrap(),
        4 * ch7::N_REFERENCE,
    )
    .unwrap();
    let (cmech, _) = ch7::mechanism(&root, true, Some(&refs)).unwrap();
    let model = ch7::reduced(&cmech, ibm_u).unwrap();
    let n = model.n_z();
    let motion = ch7::reference_motion();
    let steps = (ch7::T_END * 1000.0).round() as usize;
    let states = (0..=steps)
        .map(|i| {
            let t = ch7::T_END * i as f64 / steps as f64;
            let (s, sd, _) = motion.eval(t);
            let mut z = vec![1e-4; n];
            let mut zd = vec![1e-3; n];
            z[0] = s;
            zd[0] = sd;
            (t, z, zd)
        })
        .collect();
    (model, states)
}

/// z̈ at (t, z, ż): by the projected evaluation, or by the projection of
/// the unreduced Mq if `full_mass`.
fn evaluate(model: &mut ReducedModel, full_mass: bool, state: &State, zdd: &mut [f64]) {
    let (t, z, zd) = state;
    if full_mass {
        model.accelerations_from_full_mass(*t, z, zd, zdd)
    } else {
        model.accelerations(*t, z, zd, zdd)
    }
    .unwrap()
}

/// Evaluates `states` in order by one path and reports the position
/// solve's work per evaluation (not timed). Not inlined: a callgrind profile
/// can be split after each call (`--dump-after`, docs/reduction.md).
#[inline(never)]
fn kinematic_work(model: &mut ReducedModel, states: &[State], full_mass: bool) -> String {
    let mut zdd = vec![0.0; model.n_z()];
    let k = model.dynamics().kinematics();
    let (f0, r0) = (k.factorizations(), k.refinements());
    let mut iterations = 0;
    for st in states {
        evaluate(model, full_mass, st, &mut zdd);
        iterations += model.dynamics().kinematics().iterations();
    }
    let k = model.dynamics().kinematics();
    let per = |a: u64| a as f64 / states.len() as f64;
    format!(
        "{} states: {:.2} Newton iterations, {:.3} factorizations and {:.2} refinement steps of J per evaluation",
        states.len(),
        per(iterations as u64),
        per(k.factorizations() - f0),
        per(k.refinements() - r0)
    )
}

fn mechanism(c: &mut Criterion) {
    let (mut m, states) = closed_loop();
    println!("IBM-u closed loop: set up");
    let mut zdd = vec![0.0; m.n_z()];
    // along the path once, in order, keeping the undeflected configuration
    // and the one where s first passes 0.1 m
    evaluate(&mut m, false, &states[0], &mut zdd);
    let x0 = m.dynamics().kinematics().x().to_vec();
    let at = states
        .iter()
        .position(|(_, z, _)| z[0] >= 0.1)
        .expect("the path passes s = 0.1 m");
    for st in &states[..=at] {
        evaluate(&mut m, false, st, &mut zdd);
    }
    let x_at = m.dynamics().kinematics().x().to_vec();
    let one = states[at].clone();
    println!(
        "IBM-u closed loop: one state at t = {:.3} s, s = {:.4} m",
        one.0, one.1[0]
    );
    m.dynamics_mut().kinematics_mut().set_guess(&x0);
    println!("along the path: {}", kinematic_work(&mut m, &states, false));
    let near = &states[at..at + 10];
    for (label, full) in [("projected", false), ("full mass", true)] {
        m.dynamics_mut().kinematics_mut().set_guess(&x_at);
        println!(
            "from s = 0.1 m, {label}: {}",
            kinematic_work(&mut m, near, full)
        );
    }
    m.dynamics_mut().kinematics_mut().set_guess(&x_at);
    let mut g = c.benchmark_group("IBM-u, ch7 mechanism in closed loop (n_q = 664, n_z = 8)");
    g.bench_function("z̈ at one state", |b| {
        b.iter(|| evaluate(&mut m, false, black_box(&one), &mut zdd))
    });
    g.bench_function("z̈ by the full mass at one state", |b| {
        b.iter(|| evaluate(&mut m, true, black_box(&one), &mut zdd))
    });
    // from the start of the path again
    m.dynamics_mut().kinematics_mut().set_guess(&x0);
    let mut k = 0;
    g.bench_function("z̈ along the path", |b| {
        b.iter(|| {
            let i = k % states.len();
            if i == 0 {
                m.dynamics_mut().kinematics_mut().set_guess(&x0);
            }
            k += 1;
            evaluate(&mut m, false, black_box(&states[i]), &mut zdd)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(3)).warm_up_time(std::time::Duration::from_millis(500));
    targets = mechanism
}
criterion_main!(benches);
