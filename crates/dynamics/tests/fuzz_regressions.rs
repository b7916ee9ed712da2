//! Inputs found by `cargo xtask fuzz` (issue 14 item 8) that broke the
//! contract of the dynamics layer: a result is finite or an error that names
//! the culprit. Each test failed before its fix.

use flexmb_dynamics::{Dynamics, DynamicsError};
use flexmb_model::Scene;
use std::sync::Arc;

/// Case 0x37ab83c1f0171e7b (seed 0x1f, from `fixtures/fuzz/planar_explicit_dofs.ron`
/// with an initial angular velocity of −1e308 rad/s about the origin),
/// reduced: a free point mass 0.7 m from the origin gets ẋ = −7e307 m/s,
/// finite, and ½mv² overflows. `energies` returned Ok with T = inf.
#[test]
fn an_overflowing_kinetic_energy_is_an_error_naming_the_element() {
    let scene = Scene::from_ron_str(
        r#"(
        dimension: Planar,
        nodes: [ (id: "C", at: [-0.1, -0.7]) ],
        elements: [ (id: "mc", type: PointMass(node: "C", mass: 0.2)) ],
        initial_velocity: [ (nodes: ["C"], omega: Some([0.0, 0.0, -1e308])) ],
    )"#,
    )
    .unwrap();
    let mech = Arc::new(scene.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = dy.initial_qd(0.0, &q0).unwrap();
    assert!(
        qd0.iter().all(|v| v.is_finite()) && qd0[0].abs() > 1e307,
        "{qd0:?}"
    );
    let e = dy.energies(0.0, &q0, &qd0);
    match &e {
        Err(DynamicsError::NonFinite { what, name, .. }) => {
            assert_eq!(*what, "kinetic energy");
            assert!(name.contains("element 'mc'"), "{name}");
        }
        other => panic!("expected a non-finite kinetic energy, got {other:?}"),
    }
    let msg = e.unwrap_err().to_string();
    assert!(
        msg.contains("non-finite kinetic energy of element 'mc'"),
        "{msg}"
    );
    // a finite one is still computed
    let slow = vec![1.0; qd0.len()];
    let t = dy.energies(0.0, &q0, &slow).unwrap();
    assert!((t.kinetic - 0.5 * 0.2 * 2.0).abs() < 1e-12, "{t:?}");
}

/// A planar arm A–B whose rotation at A is prescribed by `function`, with a
/// point mass at B.
fn driven_arm(function: &str) -> Arc<flexmb_model::Mechanism> {
    let scene = Scene::from_ron_str(&format!(
        r#"(
        dimension: Planar,
        materials: {{ "al": (e: 7.0e10, rho: 2700.0) }},
        sections: {{ "bar": Rectangle(by: 0.01, bz: 0.02) }},
        nodes: [ (id: "G", at: [0.0, 0.0]), (id: "A", position_of: Some("G")), (id: "B", at: [1.0, 0.0]) ],
        elements: [
            (id: "joint", type: Hinge(nodes: ("G", "A"))),
            (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))),
            (id: "m", type: PointMass(node: "B", mass: 1.0)),
        ],
        fixed: [ Node("G") ],
        rigid: [ Def("arm", "elongation") ],
        prescribed: [ (what: Def("joint", "rotation"), function: {function}) ],
    )"#
    ))
    .unwrap();
    Arc::new(scene.build(None).unwrap())
}

/// Case 0x3ba297352708be4c of the dynamics target (seed 0x4d, from
/// `fixtures/scenes/spin_up_universal_joint.ron` with the second hinge's
/// input −1e308 sin(15 t)), reduced: the input's rate at t = 0 is
/// −1.5e309 = −inf. `initial_qd` returned Ok with q̇ = NaN, and q̈ was
/// reported non-finite for DOFs that are not the cause.
#[test]
fn a_non_finite_input_rate_is_an_error_naming_the_input() {
    let mech = driven_arm("Sine(amplitude: -1e308, omega: 15.0, phase: 0.0)");
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let msg = dy
        .initial_qd(0.0, &q0)
        .expect_err("the input rate is -inf")
        .to_string();
    assert!(
        msg.contains("non-finite prescribed input of joint.rotation") && msg.contains("rate -inf"),
        "{msg}"
    );
    let n = mech.n_dof();
    let mut qdd = vec![0.0; n];
    let msg = dy
        .accelerations(0.0, &q0, &vec![0.0; n], &mut qdd)
        .expect_err("the input rate is -inf")
        .to_string();
    assert!(
        msg.contains("non-finite prescribed input of joint.rotation"),
        "{msg}"
    );
    // a finite input gives finite velocities and accelerations
    let mech = driven_arm("Sine(amplitude: 0.1, omega: 15.0, phase: 0.0)");
    let mut dy = Dynamics::new(mech.clone());
    let qd = dy.initial_qd(0.0, &q0).unwrap();
    assert!(qd.iter().all(|v| v.is_finite()), "{qd:?}");
    dy.accelerations(0.0, &q0, &qd, &mut qdd).unwrap();
}
