//! A run that cannot go on says why: the integrator's step-size underflow
//! comes with the last evaluation that failed (the coordinates and equations
//! the position solve could not satisfy), for every integrator.

use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions};
use flexmb_model::Scene;
use std::sync::Arc;

#[test]
fn a_mechanism_driven_out_of_reach_names_the_failing_equations() {
    // two bars of 1 m that keep their length, the free end driven in x from 1.6 m to 2.5 m:
    // out of reach once x > 2 m (at t = 0.44 s)
    let scene = Scene::from_ron_str(
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
    .unwrap();
    let mech = Arc::new(scene.build(None).unwrap());

    for integrator in [
        Integrator::Dopri5,
        Integrator::Adams,
        Integrator::GeneralizedAlpha,
    ] {
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
            msg.contains("the last evaluation that failed"),
            "{integrator:?}: the cause is missing: {msg}"
        );
        assert!(
            msg.contains("ab.") || msg.contains("bc.") || msg.contains("B.") || msg.contains("C."),
            "{integrator:?}: no element or node named: {msg}"
        );
    }
}
