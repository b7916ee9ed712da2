//! Frames whose nodes start rotated (`orientation:` on scene nodes, issue
//! 15 item 2): a node's initial orientation changes the coordinates the
//! mechanism is described in, not the mechanism. A frame with rotated nodes
//! starts in balance, and it has the same equilibrium under gravity and the
//! same eigenfrequencies as the frame without them (a rigid body's `com` and
//! `inertia` then given turned into global axes).

use flexmb_dynamics::{Dynamics, StaticOptions};
use flexmb_linearize::undamped_modes;
use flexmb_model::Scene;
use flexmb_rotation::EulerParameters;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

fn row(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|c| format!("{c:e}")).collect();
    format!("[{}]", s.join(", "))
}

/// A clamped spatial L-frame (two chains of beams) with a rigid body at
/// the tip C, under gravity. `rotated`: B starts turned by π about x
/// (λ0 ≈ (0, 1, 0, 0), so λ0 cannot be its dependent parameter) and C by
/// a general rotation vector; the body's centre and inertia are given in
/// C's axes. Otherwise the same body in global axes.
fn spatial_frame(rotated: bool) -> Scene {
    let rc = EulerParameters::from_rotation_vector(&Vector3::new(0.3, -1.2, 0.5));
    let com = Vector3::new(0.01, 0.02, -0.005);
    let j = Matrix3::new(2e-4, 1e-5, 0.0, 1e-5, 3e-4, 2e-5, 0.0, 2e-5, 4e-4);
    let (orient_b, orient_c, com, j) = if rotated {
        (
            "orientation: Some(AxisAngle(axis: [2.0, 0.0, 0.0], angle: 3.141592653589793))"
                .to_string(),
            format!("orientation: Some(EulerParameters({}))", row(&rc.0)),
            com,
            j,
        )
    } else {
        let r = rc.rotation_matrix();
        (String::new(), String::new(), r * com, r * j * r.transpose())
    };
    Scene::from_ron_str(&format!(
        r#"(
        dimension: Spatial,
        gravity: Some([0.0, -4.0, -9.81]),
        materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) }},
        sections: {{ "bar": Rectangle(by: 0.01, bz: 0.004) }},
        nodes: [
            (id: "A", at: [0.0, 0.0, 0.0]),
            (id: "B", at: [0.2, 0.0, 0.0], {orient_b}),
            (id: "C", at: [0.2, 0.15, 0.0], {orient_c}),
        ],
        elements: [
            (id: "ab", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", up: Some([0.0, 1.0, 0.0]), n: 3))),
            (id: "bc", type: Beam((nodes: ("B", "C"), material: "steel", section: "bar", up: Some([1.0, 0.0, 0.0]), n: 3))),
            (id: "tip", type: RigidBody(node: "C", mass: 0.3, com: Some({}),
                inertia: [{}, {}, {}])),
        ],
        fixed: [Node("A")],
    )"#,
        row(com.as_slice()),
        row(&[j[(0, 0)], j[(0, 1)], j[(0, 2)]]),
        row(&[j[(1, 0)], j[(1, 1)], j[(1, 2)]]),
        row(&[j[(2, 0)], j[(2, 1)], j[(2, 2)]]),
    ))
    .unwrap()
}

/// The same in a plane: B and C start at angles 2.5 and −1.0 rad; C
/// carries a mass with rotary inertia.
fn planar_frame(rotated: bool) -> Scene {
    let (ob, oc) = if rotated {
        (
            "orientation: Some(Angle(2.5))",
            "orientation: Some(Angle(-1.0))",
        )
    } else {
        ("", "")
    };
    Scene::from_ron_str(&format!(
        r#"(
        dimension: Planar,
        gravity: Some([1.0, -9.81]),
        materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) }},
        sections: {{ "bar": Rectangle(by: 0.004, bz: 0.01) }},
        nodes: [
            (id: "A", at: [0.0, 0.0]),
            (id: "B", at: [0.2, 0.0], {ob}),
            (id: "C", at: [0.2, 0.15], {oc}),
        ],
        elements: [
            (id: "ab", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", n: 3))),
            (id: "bc", type: Beam((nodes: ("B", "C"), material: "steel", section: "bar", n: 3))),
            (id: "tip", type: PointMass(node: "C", mass: 0.3, inertia: Some(1e-3))),
        ],
        fixed: [Node("A")],
    )"#
    ))
    .unwrap()
}

/// Positions of all nodes at rest without loads and under gravity, and the
/// first `k` eigenfrequencies at the loaded equilibrium.
struct Study {
    unloaded_residual: f64,
    positions: Vec<f64>,
    frequencies: Vec<f64>,
}

fn study(scene: Scene, k: usize) -> Study {
    let mech = Arc::new(scene.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    // at t = 0 with the loads scaled to zero the frame is in balance
    let mut unloaded = Dynamics::new(Arc::new({
        let mut m = (*mech).clone();
        m.gravity = None;
        m
    }));
    let r = unloaded.static_residual(0.0, &q0).unwrap();
    let unloaded_residual = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let eq = dy
        .static_equilibrium(0.0, &q0, &StaticOptions::default())
        .unwrap();
    let positions = mech
        .nodes
        .iter()
        .flat_map(|n| n.position.iter().map(|&i| eq.x[i]))
        .collect();
    let lin = dy.linearize_at_rest(0.0, &eq.q).unwrap();
    let frequencies = undamped_modes(&lin, k).unwrap().frequencies_hz();
    Study {
        unloaded_residual,
        positions,
        frequencies,
    }
}

fn compare(rotated: Study, plain: Study, what: &str) {
    assert!(
        rotated.unloaded_residual < 1e-9,
        "{what}: the rotated frame is not in balance at the start: residual {:e}",
        rotated.unloaded_residual
    );
    let moved = plain
        .positions
        .iter()
        .zip(&rotated.positions)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        moved < 1e-12,
        "{what}: equilibrium positions differ by {moved:e} m"
    );
    for (a, b) in rotated.frequencies.iter().zip(&plain.frequencies) {
        assert!((a / b - 1.0).abs() < 1e-8, "{what}: {a} Hz against {b} Hz");
    }
}

#[test]
fn a_spatial_frame_with_rotated_nodes_is_the_same_frame() {
    let (r, p) = (
        study(spatial_frame(true), 8),
        study(spatial_frame(false), 8),
    );
    // the frame does sag under gravity (so the comparison means something)
    let sag = p.positions.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(sag > 0.0);
    compare(r, p, "spatial");
}

#[test]
fn a_planar_frame_with_rotated_nodes_is_the_same_frame() {
    compare(
        study(planar_frame(true), 6),
        study(planar_frame(false), 6),
        "planar",
    );
}

#[test]
fn node_orientations_are_checked_and_name_the_node() {
    let err = |text: &str| {
        Scene::from_ron_str(text)
            .and_then(|s| s.build(None))
            .unwrap_err()
            .to_string()
    };
    let spatial = |orient: &str| {
        format!(
            r#"(nodes: [(id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [1.0, 0.0, 0.0], orientation: Some({orient}))],
            elements: [(id: "h", type: Hinge(nodes: ("A", "B"), axis: Some([0.0, 0.0, 1.0]))),
                       (id: "t", type: Truss(nodes: ("A", "B"), ea: 1.0))],
            fixed: [Node("A")])"#
        )
    };
    for (orient, want) in [
        (
            "AxisAngle(axis: [0.0, 0.0, 0.0], angle: 1.0)",
            "zero length",
        ),
        ("AxisAngle(axis: [0.0, 1.0], angle: 1.0)", "2 components"),
        ("RotationVector([0.0, NaN, 1.0])", "non-finite"),
        ("EulerParameters([1.0, 0.1, 0.0, 0.0])", "not 1"),
        ("EulerParameters([1.0, 0.0, 0.0])", "4 components"),
        ("Angle(0.3)", "planar scenes"),
    ] {
        let m = err(&spatial(orient));
        assert!(
            m.contains("node 'B' orientation") && m.contains(want),
            "{orient}: {m}"
        );
    }
    // a misspelt form is a parse error naming the valid ones
    let m = err(&spatial("AxisAngel(axis: [0.0, 0.0, 1.0], angle: 1.0)"));
    assert!(m.contains("AxisAngel"), "{m}");
    // planar scenes take an angle only
    let m = err(
        r#"(dimension: Planar, nodes: [(id: "A", at: [0.0, 0.0], orientation: Some(RotationVector([0.0, 0.0, 1.0]))), (id: "B", at: [1.0, 0.0])],
        elements: [(id: "h", type: Hinge(nodes: ("A", "B")))])"#,
    );
    assert!(
        m.contains("node 'A' orientation") && m.contains("Angle(φ)"),
        "{m}"
    );
    // an orientation that no element uses is a mistake
    let m = err(
        r#"(nodes: [(id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [1.0, 0.0, 0.0], orientation: Some(RotationVector([0.0, 0.0, 1.0])))],
        elements: [(id: "t", type: Truss(nodes: ("A", "B"), ea: 1.0))], fixed: [Node("A")])"#,
    );
    assert!(
        m.contains("node 'B' orientation") && m.contains("no element uses"),
        "{m}"
    );
}

/// Released from rest under gravity, the rotated and the unrotated spatial
/// frame swing the same (the mass of the beams on rotated nodes through the
/// mapped angular-velocity bases of the nodal equations of motion).
#[test]
fn a_spatial_frame_with_rotated_nodes_swings_as_the_same_frame() {
    use flexmb_dynamics::{Control, Integrator, SimulationOptions};
    let swing = |scene: Scene| -> Vec<Vec<f64>> {
        let mech = Arc::new(scene.build(None).unwrap());
        let mut dy = Dynamics::new(mech.clone());
        let q0 = mech.q0();
        let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 2e-3, 11);
        opts.rtol = 1e-9;
        opts.atol = 1e-12;
        let tr = dy
            .simulate(0.0, &q0, &vec![0.0; q0.len()], &opts, |_, _, _| {
                Control::Continue
            })
            .unwrap();
        tr.x.iter()
            .map(|x| {
                mech.nodes
                    .iter()
                    .flat_map(|n| n.position.iter().map(|&i| x[i]))
                    .collect()
            })
            .collect()
    };
    let (a, b) = (swing(spatial_frame(true)), swing(spatial_frame(false)));
    let mut moved = 0.0f64;
    let mut diff = 0.0f64;
    for (pa, pb) in a.iter().zip(&b) {
        for (u, v) in pa.iter().zip(pb) {
            diff = diff.max((u - v).abs());
        }
        for (u, v) in pb.iter().zip(&b[0]) {
            moved = moved.max((u - v).abs());
        }
    }
    assert!(moved > 1e-6, "the frame swings ({moved:e} m)");
    // measured: 2.2e-14 m of 2.3e-5 m
    assert!(
        diff < 1e-8 * moved,
        "positions differ by {diff:e} m of {moved:e} m"
    );
}
