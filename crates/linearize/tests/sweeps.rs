//! Sweeps along a path of several held coordinates (thesis (4.1)) with MAC
//! tracking of the modes, and mode shapes in nodal coordinates.

use flexmb_dynamics::Dynamics;
use flexmb_linearize::*;
use flexmb_model::{Component, Scene, Select};
use std::path::Path;
use std::sync::Arc;

fn guidance(first: Vec<Select>) -> Arc<flexmb_model::Mechanism> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_spatial.ron");
    let mut s = Scene::load(&p).unwrap();
    s.dofs_first = first;
    Arc::new(s.build(None).unwrap())
}

#[test]
fn path_sweep_holds_every_path_coordinate_and_tracks_modes() {
    // hold the body's x and z on a path P(s) = (x0 + s, z0 − 0.01 s): the
    // equilibrium carries gravity and the reactions of both held coordinates
    let mech = guidance(vec![
        Select::Coord("S".into(), Component::X),
        Select::Coord("S".into(), Component::Z),
    ]);
    let q0 = mech.q0();
    let (x0, z0) = (q0[0], q0[1]);
    let param = SweepParameter::Path {
        dofs: vec![0, 1],
        path: Box::new(move |s| vec![x0 + s, z0 - 0.01 * s]),
    };
    let values: Vec<f64> = (0..11).map(|i| 0.008 * i as f64).collect();
    let pts = sweep(
        &mech,
        &param,
        &SweepOptions {
            values: values.clone(),
            modes: 4,
            t: 0.0,
            keep_vectors: true,
        },
        &|_, _| {},
    )
    .unwrap();
    for (p, s) in pts.iter().zip(&values) {
        assert!((p.q[0] - (x0 + s)).abs() < 1e-12 && (p.q[1] - (z0 - 0.01 * s)).abs() < 1e-12);
        assert!(
            p.frequencies_hz.iter().all(|f| f.is_finite() && *f > 0.0),
            "{:?}",
            p.frequencies_hz
        );
    }
    let sets: Vec<faer::Mat<f64>> = pts.iter().map(|p| p.modes.clone().unwrap()).collect();
    let masses: Vec<faer::Mat<f64>> = pts.iter().map(|p| p.mass.clone().unwrap()).collect();
    let tr = track_modes(&sets, Some(&masses));
    for t in 0..4 {
        let w = tr.confidence.iter().map(|c| c[t]).fold(1.0f64, f64::min);
        eprintln!("track {t}: lowest MAC with the previous configuration {w:.3}");
    }
    // the lowest constrained mode (an in-plane flexure mode) is followed with
    // a high MAC between neighbouring configurations
    let w0 = tr.confidence.iter().map(|c| c[0]).fold(1.0f64, f64::min);
    assert!(w0 > 0.9, "tracking confidence of the first mode {w0}");
}

#[test]
fn mode_shapes_in_nodal_coordinates_move_the_body_in_x_for_the_first_mode() {
    let mut s = Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/scenes/straight_guidance_spatial.ron"),
    )
    .unwrap();
    s.gravity = None;
    let mech = Arc::new(s.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let lin = dy.linearize_at_rest(0.0, &q0).unwrap();
    let modes = undamped_modes(&lin, 2).unwrap();
    let shapes = nodal_mode_shapes(&mut dy, &modes.vectors);
    let sx = mech.node("S").unwrap().position.clone();
    // mode 1: translation of the body along x; mode 2: out-of-plane (z)
    let (ux, uy, uz) = (
        shapes[(sx[0], 0)].abs(),
        shapes[(sx[1], 0)].abs(),
        shapes[(sx[2], 0)].abs(),
    );
    assert!(ux > 100.0 * uy.max(uz), "mode 1 at S: ({ux}, {uy}, {uz})");
    let (vx, vz) = (shapes[(sx[0], 1)].abs(), shapes[(sx[2], 1)].abs());
    assert!(vz > 100.0 * vx, "mode 2 at S: x {vx}, z {vz}");
}

/// A sweep stopped from outside ([`sweep_until`]): requested after two
/// equilibria it has no modes and says how many equilibria it found;
/// requested after the first eigen analysis it returns the configurations
/// done (the parallel workers stop before their next one); never requested,
/// it is the whole sweep.
#[test]
fn a_stopped_sweep_returns_what_is_done() {
    use std::sync::atomic::{AtomicBool, Ordering};
    let mech = guidance(vec![Select::Coord("S".into(), Component::X)]);
    let x0 = mech.q0()[0];
    let n = 12;
    let opts = SweepOptions {
        values: (0..n).map(|i| x0 + 0.005 * i as f64).collect(),
        modes: 2,
        t: 0.0,
        keep_vectors: false,
    };
    let run = |stop_after: usize| {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let progress = move |done: usize, _: usize| {
            if done == stop_after {
                flag.store(true, Ordering::Relaxed);
            }
        };
        sweep_until(
            &mech,
            &SweepParameter::Dof(0),
            &opts,
            &progress,
            Some(&stop),
        )
        .unwrap()
    };
    let o = run(2);
    assert!(
        o.stopped && o.points.is_empty() && o.equilibria == 2,
        "{o:?}"
    );
    let o = run(n + 1);
    assert!(o.stopped && o.equilibria == n, "{o:?}");
    // each worker finishes the configuration it is at (with a thread per
    // configuration all of them would be done)
    let threads = rayon::current_num_threads();
    assert!(!o.points.is_empty() && o.points.len() <= threads.min(n));
    if threads < n {
        assert!(o.points.len() < n, "{} points", o.points.len());
    }
    // the points done are in the order of the values, each at its value
    for w in o.points.windows(2) {
        assert!(w[0].s < w[1].s);
    }
    let o = run(usize::MAX);
    assert!(!o.stopped && o.points.len() == n && o.equilibria == n);
}

/// The spatial guidance with `n` beams per flexure, with or without gravity
/// and with rigid or free elongation, S.x made the first DOF.
fn guidance_with(n: usize, gravity: bool, free_elongation: bool) -> Arc<flexmb_model::Mechanism> {
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

/// Issue 14 item 7: the held sweep over S.x of the spatial guidance (10
/// beams per flexure, 20 configurations to 0.08 m, the bench
/// `held_sweep_gravity`) under gravity costs at most 2× the Newton
/// iterations of the same sweep without. Each equilibrium starts from the
/// quadratic extrapolation of the last three: 108 against 65 iterations
/// (1.66×) with rigid elongation; from the last equilibrium alone (and the
/// tangent predictor of `static_equilibrium`) it was 183 against 89
/// (2.06×). The equilibria are the ones an independent solve from the
/// reference configuration finds.
#[test]
fn a_held_sweep_with_gravity_costs_at_most_twice_the_iterations_without() {
    let opts = |mech: &flexmb_model::Mechanism| SweepOptions {
        values: (0..20)
            .map(|i| mech.q0()[0] + 0.08 * i as f64 / 19.0)
            .collect(),
        modes: 2,
        t: 0.0,
        keep_vectors: false,
    };
    // (free elongation, bound on the ratio of the iterations)
    for (free, bound) in [(false, 1.85), (true, 1.5)] {
        let with = guidance_with(10, true, free);
        let without = guidance_with(10, false, free);
        let run = |mech: &Arc<flexmb_model::Mechanism>| {
            sweep_until(mech, &SweepParameter::Dof(0), &opts(mech), &|_, _| {}, None).unwrap()
        };
        let (a, b) = (run(&with), run(&without));
        let ratio = a.iterations as f64 / b.iterations as f64;
        println!(
            "free elongation {free}: {} Newton iterations with gravity, {} without ({ratio:.2}×)",
            a.iterations, b.iterations
        );
        assert!(ratio <= bound, "{ratio:.2}× the iterations with gravity");
        assert_eq!(a.points.len(), 20);
        if free {
            continue;
        }
        // an independent solve of two points: fresh dynamics, from the
        // reference configuration, the held value ramped in 8 increments
        for k in [9, 19] {
            let mut fresh = Dynamics::new(with.clone());
            let q0 = with.q0();
            let so = flexmb_dynamics::StaticOptions {
                held: vec![(0, a.points[k].s)],
                load_steps: 8,
                ..Default::default()
            };
            let sol = fresh.static_equilibrium(0.0, &q0, &so).unwrap();
            let dq = sol
                .q
                .iter()
                .zip(&a.points[k].q)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(dq < 1e-8, "point {k}: the equilibria differ by {dq:e}");
            let df = (sol.reactions[0] - a.points[k].holding[0]).abs();
            assert!(df < 1e-6 * sol.reactions[0].abs(), "point {k}: {df} N");
        }
    }
}

/// A load sweep continues each equilibrium from the last one with the loads
/// applied fully (they are not ramped from the last scale). On the 720-DOF
/// flexure chain from load scale 0 to 1 in one step the first Newton step
/// went where the position solve does not converge, and since the loads were
/// not ramped, the halved increments were the same problem: "static
/// equilibrium not found beyond load factor 0" (the 1440-DOF chain failed so
/// at 0.5 of `--from 0 --to 1 --n 3`). The sweep now steps the load scale in
/// between, and finds the equilibrium a solve from the reference
/// configuration finds.
#[test]
fn a_load_sweep_in_one_large_step_steps_the_load_scale_in_between() {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenes/flexure_chain_720.ron");
    let mech = Arc::new(Scene::load(&p).unwrap().build(None).unwrap());
    assert_eq!(mech.n_dof(), 720);
    let opts = |values: Vec<f64>| SweepOptions {
        values,
        modes: 2,
        t: 0.0,
        keep_vectors: false,
    };
    let run = |values: Vec<f64>| {
        sweep_until(
            &mech,
            &SweepParameter::LoadScale,
            &opts(values),
            &|_, _| {},
            None,
        )
    };
    let stepped = run(vec![0.0, 1.0]).unwrap_or_else(|e| panic!("{e}"));
    // the equilibrium at scale 1 ramped from the reference configuration
    let direct = run(vec![1.0]).unwrap_or_else(|e| panic!("{e}"));
    let (a, b) = (&stepped.points[1], &direct.points[0]);
    let dq =
        a.q.iter()
            .zip(&b.q)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(dq < 1e-8, "the equilibria differ by {dq:e}");
    for (fa, fb) in a.frequencies_hz.iter().zip(&b.frequencies_hz) {
        assert!((fa / fb - 1.0).abs() < 1e-8, "{fa} Hz against {fb} Hz");
    }
    // the loads move the chain: the equilibrium is not the unloaded one
    let d0 =
        a.q.iter()
            .zip(&stepped.points[0].q)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(d0 > 1e-4, "{d0}");
}
