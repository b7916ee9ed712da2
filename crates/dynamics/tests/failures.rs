//! A run that cannot go on says why: the integrator's step-size underflow
//! comes with the last evaluation that failed (the coordinates and equations
//! the position solve could not satisfy), for every integrator.

use flexmb_dynamics::{Control, Dynamics, DynamicsError, Integrator, SimulationOptions};
use flexmb_model::Scene;
use std::sync::Arc;

/// Two bars of 1 m that keep their length, the free end driven in x from
/// 1.6 m to 2.5 m: out of reach once x > 2 m (at t = 0.44 s).
fn out_of_reach() -> Arc<flexmb_model::Mechanism> {
    Arc::new(out_of_reach_scene().build(None).unwrap())
}

fn out_of_reach_scene() -> Scene {
    Scene::from_ron_str(
        r#"(
        dimension: Planar,
        materials: { "al": (e: 7.0e10, rho: 2700.0) },
        sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.8, 0.6]), (id: "C", at: [1.6, 0.0]) ],
        elements: [
            (id: "ab", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))),
            (id: "bc", type: Beam((nodes: ("B", "C"), material: "al", section: "bar"))),
            (id: "mb", type: PointMass(node: "B", mass: 1.0)),
            (id: "mc", type: PointMass(node: "C", mass: 1.0)),
        ],
        fixed: [ Coord("A", Position) ],
        rigid: [ Def("ab", "elongation"), Def("bc", "elongation") ],
        prescribed: [ (what: Coord("C", X), function: Ramp(t0: 0.0, t1: 1.0, v0: 1.6, v1: 2.5)) ],
    )"#,
    )
    .unwrap()
}

#[test]
fn an_evaluation_that_fails_keeps_its_typed_error_for_the_integrator() {
    // with a fixed step nothing is retried: the integrator ends with the
    // evaluation's failure, the kinematics error kept as its cause
    let mech = out_of_reach();
    let mut dy = Dynamics::new(mech.clone());
    let mut y0 = mech.q0();
    y0.extend(vec![0.0; mech.n_dof()]);
    let method = flexmb_ode::Dopri5::new(flexmb_ode::Dopri5Options::default().fixed_step(0.05));
    let err = method
        .solve(
            &mut dy.first_order_system(),
            0.0,
            &y0,
            1.0,
            &flexmb_ode::Output::Final,
        )
        .expect_err("the end is driven out of reach");
    let flexmb_ode::OdeError::Rhs { t, source } = &err else {
        panic!("not an evaluation failure: {err:?}");
    };
    assert!(*t > 0.0 && *t < 1.0, "failed at t = {t}");
    assert!(source.is_recoverable());
    let cause = source.downcast_cause::<DynamicsError>();
    assert!(
        matches!(cause, Some(DynamicsError::Kinematics { .. })),
        "{cause:?}"
    );
    assert_eq!(source.message(), cause.unwrap().to_string());
    // and through a DynamicsError::Integration
    let wrapped = DynamicsError::Integration {
        source: err.clone(),
        message: err.to_string(),
    };
    assert_eq!(wrapped.failed_evaluation(), cause);
    assert_eq!(DynamicsError::Interrupted.failed_evaluation(), None);
}

#[test]
fn a_mechanism_driven_out_of_reach_names_the_failing_equations() {
    // two bars of 1 m that keep their length, the free end driven in x from 1.6 m to 2.5 m:
    // out of reach once x > 2 m (at t = 0.44 s)
    out_of_reach_names_the_failing_equations(
        out_of_reach(),
        &[
            Integrator::Dopri5,
            Integrator::Adams,
            Integrator::GeneralizedAlpha,
        ],
    );
}

/// The same with nodal coordinates as DOFs: where J of the dependent
/// coordinates degrades the run looks for another dependent set
/// (`Dynamics::switch_partition`), but near the stretched position every
/// set degrades alike (at it no square block of D_c,x is regular: both
/// elongations depend on B.x alone), so none that restores the
/// conditioning exists and the run ends as with deformation DOFs, naming
/// what failed (or, where no evaluation failed, the near-singular state
/// of the last step).
#[test]
fn with_nodal_dofs_a_mechanism_driven_out_of_reach_still_names_the_failing_equations() {
    let mut scene = out_of_reach_scene();
    scene.dofs = flexmb_model::DofChoice::NodalCoordinates;
    let mech = Arc::new(scene.build(None).unwrap());
    assert!(!mech.partition_eligible().is_empty());
    out_of_reach_names_the_failing_equations(
        mech,
        &[
            Integrator::Dopri5,
            Integrator::Adams,
            Integrator::GeneralizedAlpha,
        ],
    );
}

/// A run whose steps shrink near the stretched position (issue 15 item 4:
/// before, the run ended with "step size underflow" alone): Adams with
/// deformation DOFs. The message explains the end: the evaluation that
/// failed (since the position solve's branch guard, a solve near the fold
/// is refused rather than converged on a step too large for the branch's
/// curvature), or, where none failed, the state of the last accepted step
/// with the kinematic Jacobian near singular there and the dependent
/// coordinates it determines least (that explanation is tested on its own
/// in `culprit::tests`).
#[test]
fn a_stall_near_the_stretched_position_is_explained() {
    let mech = out_of_reach();
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let opts = SimulationOptions::new(Integrator::Adams, 0.0, 1.0, 11);
    let err = dy
        .simulate(0.0, &q0, &vec![0.0; q0.len()], &opts, |_, _, _| {
            Control::Continue
        })
        .expect_err("the end is driven out of reach");
    let msg = err.to_string();
    assert!(
        matches!(&err, DynamicsError::Integration { .. }),
        "not an integration error: {err:?}"
    );
    assert!(explains_the_end(&msg), "unexplained: {msg}");
    assert!(
        msg.contains("C.y") || msg.contains("bc."),
        "the culprit is not named: {msg}"
    );
}

/// Whether the end of a run is explained: by the evaluation that failed,
/// or, when none failed, by the near-singular state of the last step.
fn explains_the_end(msg: &str) -> bool {
    msg.contains("the last evaluation that failed")
        || (msg.contains("no evaluation failed") && msg.contains("near a singular configuration"))
}

fn out_of_reach_names_the_failing_equations(
    mech: Arc<flexmb_model::Mechanism>,
    integrators: &[Integrator],
) {
    for &integrator in integrators {
        let mut dy = Dynamics::new(mech.clone());
        let q0 = mech.q0();
        let opts = SimulationOptions::new(integrator, 0.0, 1.0, 11);
        let err = dy
            .simulate(0.0, &q0, &vec![0.0; q0.len()], &opts, |_, _, _| {
                Control::Continue
            })
            .expect_err("the end is driven out of reach");
        let msg = err.to_string();
        assert!(
            explains_the_end(&msg),
            "{integrator:?}: the cause is missing: {msg}"
        );
        // the integrator's own error is kept, to match on
        match &err {
            DynamicsError::Integration { source, .. } => {
                let inner = std::error::Error::source(&err).map(|e| e.to_string());
                assert_eq!(inner, Some(source.to_string()), "{integrator:?}");
                assert!(
                    matches!(
                        source,
                        flexmb_ode::OdeError::StepSizeTooSmall { .. }
                            | flexmb_ode::OdeError::NewtonFailed { .. }
                            | flexmb_ode::OdeError::Rhs { .. }
                    ),
                    "{integrator:?}: {source:?}"
                );
            }
            other => panic!("{integrator:?}: not an integration error: {other:?}"),
        }
        assert!(
            msg.contains("ab.") || msg.contains("bc.") || msg.contains("B.") || msg.contains("C."),
            "{integrator:?}: no element or node named: {msg}"
        );
    }
}

/// A free node S with a point mass: DOFs q0 = S.x, q1 = S.y.
fn free_mass(mass: f64, force: f64) -> Arc<flexmb_model::Mechanism> {
    let scene = Scene::from_ron_str(&format!(
        r#"(
        dimension: Planar,
        nodes: [ (id: "S", at: [0.0, 0.0]) ],
        elements: [ (id: "m", type: PointMass(node: "S", mass: {mass:e})) ],
        loads: [ (node: "S", force: Some([0.0, {force:e}])) ],
    )"#
    ))
    .unwrap();
    let mech = Arc::new(scene.build(None).unwrap());
    let names: Vec<&str> = mech.dofs.iter().map(|c| mech.coordinate_name(*c)).collect();
    assert_eq!(names, ["S.x", "S.y"]);
    mech
}

#[test]
fn a_non_finite_acceleration_or_velocity_names_its_dof_and_node() {
    // q̈ = f/m = 1e10 / 1e-300 overflows
    let mut dy = Dynamics::new(free_mass(1e-300, 1e10));
    let mut qdd = [0.0; 2];
    let msg = dy
        .accelerations(0.0, &[0.0, 0.0], &[0.0, 0.0], &mut qdd)
        .expect_err("q̈ overflows")
        .to_string();
    // (the overflow spreads to S.x in the solve; both are named)
    assert!(
        msg.contains("non-finite q̈ of DOF q") && msg.contains("DOF q1 = S.y (node S)"),
        "{msg}"
    );
    let mut dy = Dynamics::new(free_mass(1.0, 1.0));
    let msg = dy
        .accelerations(0.0, &[0.0, 0.0], &[0.0, f64::NAN], &mut qdd)
        .expect_err("q̇ is NaN")
        .to_string();
    assert!(
        msg.contains("non-finite q̇ of DOF q1 = S.y (node S)"),
        "{msg}"
    );
    let msg = dy
        .accelerations(0.0, &[f64::INFINITY, 0.0], &[0.0, 0.0], &mut qdd)
        .expect_err("q is infinite")
        .to_string();
    assert!(msg.contains("DOF q0 = S.x (node S)"), "{msg}");
}

#[test]
fn a_non_finite_initial_velocity_names_its_dof_and_node_for_every_integrator() {
    let mech = free_mass(1.0, 1.0);
    for integrator in [
        Integrator::Dopri5,
        Integrator::Adams,
        Integrator::GeneralizedAlpha,
    ] {
        let mut dy = Dynamics::new(mech.clone());
        let opts = SimulationOptions::new(integrator, 0.0, 0.1, 3);
        let msg = dy
            .simulate(0.0, &[0.0, 0.0], &[0.0, f64::NAN], &opts, |_, _, _| {
                Control::Continue
            })
            .expect_err("q̇0 is NaN")
            .to_string();
        assert!(
            msg.contains("non-finite component")
                && msg.contains("the rate of DOF q1 = S.y (node S)"),
            "{integrator:?}: {msg}"
        );
    }
}

#[test]
fn a_singular_static_tangent_names_the_unrestrained_coordinates() {
    // a clamped beam A–B and a truss B–S along x with a mass at S: nothing
    // resists S moving in y (the truss turning about B)
    let scene = Scene::from_ron_str(
        r#"(
        dimension: Planar,
        gravity: Some([0.0, -9.81]),
        materials: { "al": (e: 7.0e10, rho: 2700.0) },
        sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.5, 0.0]), (id: "S", at: [1.0, 0.0]) ],
        elements: [
            (id: "ab", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))),
            (id: "bs", type: Truss(nodes: ("B", "S"), ea: 1.0e6)),
            (id: "m", type: PointMass(node: "S", mass: 1.0)),
        ],
        fixed: [ Node("A") ],
    )"#,
    )
    .unwrap();
    let mech = Arc::new(scene.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let msg = dy
        .static_equilibrium(0.0, &mech.q0(), &Default::default())
        .expect_err("S.y is unrestrained")
        .to_string();
    assert!(
        msg.contains("singular static tangent") && msg.contains("the motion involves DOF q"),
        "{msg}"
    );
    // S.y, and only the coordinates of that motion
    let named = msg.split("the motion involves ").nth(1).unwrap_or("");
    assert!(named.contains("S.y (node S)"), "{msg}");
    assert!(!named.contains("ab.") && !named.contains("bs."), "{msg}");
}

/// `SimulationOptions::new` with fewer than two outputs is what was asked:
/// one output is the final state, none is an error (both used to become two
/// outputs silently).
#[test]
fn one_output_is_the_final_state_and_none_is_an_error() {
    let scene = Scene::from_ron_str(
        r#"(
        dimension: Planar,
        gravity: Some([0.0, -9.81]),
        materials: { "m": (e: 1.0e9, rho: 0.0) },
        sections: { "s": Circle(d: 0.01) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [
            (id: "rod", type: Beam((nodes: ("A", "B"), material: "m", section: "s", mass: false))),
            (id: "bob", type: PointMass(node: "B", mass: 2.0)),
        ],
        fixed: [ Coord("A", Position) ],
        rigid: [ Def("rod", "*") ],
    )"#,
    )
    .unwrap();
    let mech = Arc::new(scene.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    let three = SimulationOptions::new(Integrator::Dopri5, 0.0, 0.5, 3);
    let one = SimulationOptions::new(Integrator::Dopri5, 0.0, 0.5, 1);
    assert_eq!(one.output_times, vec![0.5]);
    let a = dy
        .simulate(0.0, &q0, &qd0, &three, |_, _, _| Control::Continue)
        .unwrap();
    let b = dy
        .simulate(0.0, &q0, &qd0, &one, |_, _, _| Control::Continue)
        .unwrap();
    assert_eq!(b.t, vec![0.5]);
    let (qa, qb) = (a.q.last().unwrap(), &b.q[0]);
    assert!(
        (qa[0] - qb[0]).abs() < 1e-3 && qa[0] < -0.5,
        "{qa:?} {qb:?}"
    );
    let none = SimulationOptions::new(Integrator::Dopri5, 0.0, 0.5, 0);
    let e = dy
        .simulate(0.0, &q0, &qd0, &none, |_, _, _| Control::Continue)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no output times"), "{e}");
}

/// A degree of freedom without inertia is named by every integrator
/// (generalized-α used to say only "singular mass matrix at t = 0").
#[test]
fn a_massless_degree_of_freedom_is_named_by_every_integrator() {
    let scene = Scene::from_ron_str(
        r#"(
        dimension: Planar,
        materials: { "m": (e: 1.0e9, rho: 0.0) },
        sections: { "s": Circle(d: 0.01) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [
            (id: "rod", type: Beam((nodes: ("A", "B"), material: "m", section: "s", mass: false))),
            (id: "bob", type: PointMass(node: "B", mass: 2.0)),
        ],
        fixed: [ Coord("A", Position) ],
    )"#,
    )
    .unwrap();
    let mech = Arc::new(scene.build(None).unwrap());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    for integrator in [
        Integrator::Dopri5,
        Integrator::Adams,
        Integrator::GeneralizedAlpha,
    ] {
        let mut dy = Dynamics::new(mech.clone());
        let opts = SimulationOptions::new(integrator, 0.0, 0.1, 3);
        let e = dy
            .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("degrees of freedom without inertia: DOF q2 = rod.bending_q"),
            "{integrator:?}: {e}"
        );
    }
}

#[test]
fn slices_of_the_wrong_length_are_errors_naming_the_argument() {
    // the length rule of the public API (docs/ARCHITECTURE.md): no panic,
    // no silent truncation
    let mut dy = Dynamics::new(free_mass(1.0, 1.0));
    let mut qdd = [0.0; 2];
    let cases: [(&str, Result<(), DynamicsError>); 4] = [
        (
            "q has 3 entries",
            dy.accelerations(0.0, &[0.0; 3], &[0.0; 2], &mut qdd),
        ),
        (
            "q̇ has 1 entries",
            dy.accelerations(0.0, &[0.0; 2], &[0.0; 1], &mut qdd),
        ),
        (
            "q̈ has 3 entries",
            dy.accelerations(0.0, &[0.0; 2], &[0.0; 2], &mut [0.0; 3]),
        ),
        (
            "q̇ has 4 entries",
            dy.energies(0.0, &[0.0; 2], &[0.0; 4]).map(|_| ()),
        ),
    ];
    for (expected, r) in cases {
        let msg = r.expect_err(expected).to_string();
        assert!(
            msg.contains(expected) && msg.contains(" 2"),
            "{expected}: {msg}"
        );
    }
    // the right lengths still work
    dy.accelerations(0.0, &[0.0; 2], &[0.0; 2], &mut qdd)
        .unwrap();
    assert_eq!(qdd, [0.0, 1.0]);
}
