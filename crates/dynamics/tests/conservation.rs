//! Conservation of energy of free and conservative mechanisms at tight
//! tolerances, and robustness to reversing the element directions (thesis
//! Fig. 2.12).

use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions};
use flexmb_kinematics::Kinematics;
use flexmb_model::{ElementSpec, Scene};
use std::path::Path;
use std::sync::Arc;

fn scene(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap()
}

fn energy_drift(name: &str, t_end: f64) -> (f64, f64) {
    let mech = Arc::new(scene(name).build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = dy.initial_qd(0.0, &q0).unwrap();
    let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, t_end, 101);
    opts.rtol = 1e-11;
    opts.atol = 1e-13;
    let tr = dy
        .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .unwrap();
    let mut e0 = None;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for (t, (q, qd)) in tr.t.iter().zip(tr.q.iter().zip(&tr.qd)) {
        let en = dy.energies(*t, q, qd).unwrap();
        assert!(en.gravity_exact);
        let e = en.kinetic + en.elastic + en.gravitational;
        scale = scale
            .max(en.kinetic.abs())
            .max(en.elastic.abs())
            .max(en.gravitational.abs());
        let e0 = *e0.get_or_insert(e);
        worst = worst.max((e - e0).abs());
    }
    (worst / scale, scale)
}

#[test]
fn tumbling_flexible_beam_conserves_energy() {
    let (rel, scale) = energy_drift("tumbling_beam.ron", 10.0);
    assert!(scale > 1e-3, "the body should move: energy scale {scale}");
    assert!(rel < 1e-6, "relative energy drift {rel:e} over 10 s");
}

#[test]
fn flexible_pendulum_under_gravity_conserves_energy() {
    let (rel, scale) = energy_drift("flexible_pendulum.ron", 10.0);
    assert!(scale > 1.0, "energy scale {scale}");
    assert!(rel < 1e-6, "relative energy drift {rel:e} over 10 s");
}

/// Tip position history of the universal-joint spin-up model, optionally
/// with every beam element reversed (q to p).
fn tip_history(reverse: bool) -> (Vec<[f64; 3]>, f64) {
    let mut s = scene("spin_up_universal_joint.ron");
    if reverse {
        // describe the beam from T to O: same chain, opposite element directions
        for e in &mut s.elements {
            if let ElementSpec::Beam(b) = &mut e.kind {
                b.nodes = (b.nodes.1.clone(), b.nodes.0.clone());
            }
        }
    }
    let mech = Arc::new(s.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 4.0, 81);
    opts.rtol = 1e-11;
    opts.atol = 1e-13;
    let tr = dy
        .simulate(0.0, &q0, &vec![0.0; q0.len()], &opts, |_, _, _| {
            Control::Continue
        })
        .unwrap();
    let tip = mech.node("T").unwrap().position.clone();
    let mut kin = Kinematics::new(mech.clone());
    let mut out = vec![];
    for (t, q) in tr.t.iter().zip(&tr.q) {
        kin.solve(q, *t).unwrap();
        out.push([kin.x()[tip[0]], kin.x()[tip[1]], kin.x()[tip[2]]]);
    }
    (out, tr.wall_time)
}

#[test]
fn reversing_the_elements_gives_the_same_spatial_spin_up_response() {
    let (a, _) = tip_history(false);
    let (b, _) = tip_history(true);
    let mut diff = 0.0f64;
    for (p, q) in a.iter().zip(&b) {
        for k in 0..3 {
            diff = diff.max((p[k] - q[k]).abs());
        }
    }
    // relative to the beam length (tip positions are O(8 m); deflections O(0.5 m))
    assert!(
        diff < 1e-6 * 0.5,
        "tip positions differ by {diff} m after reversing the elements"
    );
}

/// Kinetic + elastic − external work along a simulation of `name` (the
/// external work includes gravity's): its largest deviation and the largest
/// |work|, and the change of the gravitational energy.
fn work_balance(name: &str, t_end: f64) -> (f64, f64, f64) {
    let mech = Arc::new(scene(name).build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = dy.initial_qd(0.0, &q0).unwrap();
    let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, t_end, 2001);
    opts.rtol = 1e-8;
    opts.atol = 1e-11;
    let tr = dy
        .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .unwrap();
    let mut s = scene(name);
    s.outputs = vec![flexmb_model::OutputSpec::Energies];
    let table = flexmb_dynamics::OutputTable::new(&Dynamics::new(Arc::new(s.build(None).unwrap())))
        .unwrap();
    let col = |n: &str| table.header.iter().position(|h| h == n).unwrap();
    let (k, e, g, w) = (
        col("kinetic"),
        col("elastic"),
        col("gravitational"),
        col("external_work"),
    );
    let rows: Vec<Vec<f64>> =
        tr.t.iter()
            .zip(tr.q.iter().zip(&tr.qd).zip(&tr.x))
            .map(|(t, ((q, qd), x))| table.row(&mut dy, *t, q, qd, x).unwrap())
            .collect();
    let balance = |r: &Vec<f64>| r[k] + r[e] - r[w];
    let b0 = balance(&rows[0]);
    let work = rows.iter().fold(0.0f64, |m, r| m.max(r[w].abs()));
    let worst = rows
        .iter()
        .fold(0.0f64, |m, r| m.max((balance(r) - b0).abs()));
    let dg = rows
        .iter()
        .fold(0.0f64, |m, r| m.max((r[g] - rows[0][g]).abs()));
    (worst, work, dg)
}

/// The external-work output balances the energy: of the planar straight
/// guidance driven by the force pulse (5.24), and of the flexible pendulum
/// falling under gravity, whose external work is the drop of its
/// gravitational energy. The tolerance is the trapezoidal rule's over 2000
/// output intervals.
#[test]
fn external_work_balances_the_energy() {
    let (worst, work, _) = work_balance("straight_guidance_planar.ron", 0.15);
    assert!(work > 1.0, "the pulse does work: {work} J");
    assert!(
        worst < 1e-4 * work,
        "guidance: balance off by {worst:e} J of {work} J"
    );
    let (worst, work, dg) = work_balance("flexible_pendulum.ron", 0.3);
    assert!(
        (work - dg).abs() < 1e-3 * dg,
        "gravity's work {work} J against the drop {dg} J"
    );
    assert!(
        worst < 1e-4 * work,
        "pendulum: balance off by {worst:e} J of {work} J"
    );
}
