//! The rate, momentum and reaction outputs of a scene (issue 15 item 3):
//! `Velocity`, `AngularVelocity`, `Momentum` and `Reaction`, checked against
//! the initial velocity field they must reproduce and against Newton's law
//! for the whole mechanism, L̇ = R + W (the supports' force plus the weight).

use flexmb_dynamics::{Control, Dynamics, Integrator, OutputTable, SimulationOptions};
use flexmb_model::Scene;
use std::sync::Arc;

fn fixture_text(name: &str) -> String {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    std::fs::read_to_string(p).unwrap()
}

/// The rows of `outputs` over a run of `t_end` with `n` outputs.
fn run(text: &str, t_end: f64, n: usize) -> (Vec<String>, Vec<Vec<f64>>) {
    let mech = Arc::new(Scene::from_ron_str(text).unwrap().build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = dy.initial_qd(0.0, &q0).unwrap();
    let table = OutputTable::new(&dy).unwrap();
    let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, t_end, n);
    opts.rtol = 1e-11;
    opts.atol = 1e-13;
    let mut rows = vec![];
    dy.simulate_with(0.0, &q0, &qd0, &opts, |p| {
        let x = p.dynamics.kinematics().x().to_vec();
        let mut row = vec![p.t];
        row.extend(
            table
                .row(p.dynamics, p.t, p.q_chart, p.qd_chart, &x)
                .unwrap(),
        );
        rows.push(row);
        Control::Continue
    })
    .unwrap();
    let mut header = vec!["t".to_string()];
    header.extend(table.header.clone());
    (header, rows)
}

fn col(header: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let k = header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    rows.iter().map(|r| r[k]).collect()
}

#[test]
fn the_pivot_reaction_of_a_swinging_pendulum_is_the_rate_of_its_momentum_minus_its_weight() {
    let text = fixture_text("flexible_pendulum.ron").replace(
        "fixed: [Node(\"G\")],",
        "fixed: [Node(\"G\")],\n    outputs: [Position(\"T\"), Velocity(\"T\"), AngularVelocity(\"E1\"), Momentum([0.0, 0.0]), Reaction(\"G\")],",
    );
    assert!(text.contains("Reaction(\"G\")"));
    let dt = 1e-3;
    let (h, rows) = run(&text, 0.3, 301);
    let (lx, ly) = (col(&h, &rows, "L_x"), col(&h, &rows, "L_y"));
    let (rx, ry) = (col(&h, &rows, "G.R_x"), col(&h, &rows, "G.R_y"));
    // every point mass of the scene (the rods have none): 2.1 kg
    let weight = 2.1 * 9.81;
    let mut worst = 0.0f64;
    for i in 1..rows.len() - 1 {
        let ldx = (lx[i + 1] - lx[i - 1]) / (2.0 * dt);
        let ldy = (ly[i + 1] - ly[i - 1]) / (2.0 * dt);
        worst = worst
            .max((ldx - rx[i]).abs())
            .max((ldy - (ry[i] - weight)).abs());
    }
    // central differences over 1 ms: O(Δt²) of L⃛
    assert!(worst < 1e-3 * weight, "L̇ − R − W off by {worst:e} N");
    // at rest at t = 0 (released horizontally) the pivot carries less than
    // the weight: the masses start to fall
    assert!(ry[0] < weight && ry[0] > 0.0, "{}", ry[0]);
    // the velocity output is the rate of the position output
    let (x, vx) = (col(&h, &rows, "T.x"), col(&h, &rows, "T.vx"));
    for i in [50, 150, 250] {
        let fd = (x[i + 1] - x[i - 1]) / (2.0 * dt);
        assert!(
            (fd - vx[i]).abs() < 1e-5 * (1.0 + vx[i].abs()),
            "{fd} against {}",
            vx[i]
        );
    }
    let (y, vy) = (col(&h, &rows, "T.y"), col(&h, &rows, "T.vy"));
    let fd = (y[201] - y[199]) / (2.0 * dt);
    assert!((fd - vy[200]).abs() < 1e-5 * (1.0 + vy[200].abs()));
    assert!(h.iter().any(|c| c == "E1.omega_z"));
}

#[test]
fn a_tumbling_beam_reports_its_initial_rigid_velocity_field_and_constant_momentum() {
    let text = fixture_text("tumbling_beam.ron").replace(
        "initial_velocity:",
        "outputs: [Velocity(\"B\"), AngularVelocity(\"A\"), AngularVelocity(\"B\"), Momentum([0.3, 0.0, 0.0])],\n    initial_velocity:",
    );
    let (h, rows) = run(&text, 0.5, 11);
    let omega = [0.05, 0.1, 0.15];
    for (k, c) in ["x", "y", "z"].iter().enumerate() {
        for node in ["A", "B"] {
            let w = col(&h, &rows, &format!("{node}.omega_{c}"))[0];
            assert!((w - omega[k]).abs() < 1e-12, "{node}.omega_{c} = {w}");
        }
    }
    // v_B = v + ω × (B − about) = (0.1, 0, 0.2) + ω × (0.3, 0, 0)
    let vb = [0.1, 0.3 * omega[2], 0.2 - 0.3 * omega[1]];
    for (k, c) in ["x", "y", "z"].iter().enumerate() {
        let v = col(&h, &rows, &format!("B.v{c}"))[0];
        assert!(
            (v - vb[k]).abs() < 1e-12,
            "B.v{c} = {v}, expected {}",
            vb[k]
        );
    }
    // no force acts, so L and H about the fixed point (0.3, 0, 0) are
    // constant, and L = m v_G with the centre of mass at (0.3, 0, 0):
    // 0.144 kg × (0.1, 0, 0.2)
    let m = 1200.0 * 0.02 * 0.005 * 0.6;
    for (k, c) in ["x", "y", "z"].iter().enumerate() {
        let l = col(&h, &rows, &format!("L_{c}"));
        let expected = m * [0.1, 0.0, 0.2][k];
        assert!(
            (l[0] - expected).abs() < 1e-12,
            "L_{c} = {} against {expected}",
            l[0]
        );
        let hc = col(&h, &rows, &format!("H_{c}"));
        for r in 1..rows.len() {
            assert!((l[r] - l[0]).abs() < 1e-10, "L_{c} drifts");
            assert!(
                (hc[r] - hc[0]).abs() < 1e-9,
                "H_{c} drifts: {} against {}",
                hc[r],
                hc[0]
            );
        }
    }
}

#[test]
fn bad_rate_and_reaction_outputs_are_refused_with_the_culprit() {
    let base = fixture_text("flexible_pendulum.ron");
    for (output, expect) in [
        ("Reaction(\"T\")", "no fixed or prescribed coordinate"),
        ("Reaction(\"TT\")", "unknown node 'TT'"),
        ("Momentum([0.0, 0.0, 0.0])", "needs 2 finite coordinates"),
        ("Velocity(\"X\")", "unknown node 'X'"),
    ] {
        let text = base.replace(
            "fixed: [Node(\"G\")],",
            &format!("fixed: [Node(\"G\")],\n    outputs: [{output}],"),
        );
        let err = Scene::from_ron_str(&text)
            .unwrap()
            .build(None)
            .err()
            .unwrap_or_else(|| panic!("{output} accepted"))
            .to_string();
        assert!(err.contains(expect), "{output}: {err}");
    }
}
