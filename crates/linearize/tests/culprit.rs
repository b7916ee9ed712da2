//! Failed analyses name their culprit: the DOFs without inertia (as
//! `Dynamics::accelerations` does), the unrestrained motion, the
//! configuration where the eigenvalue solver failed, the sweep configuration.

use faer::Mat;
use flexmb_dynamics::{Dynamics, DynamicsError};
use flexmb_linearize::*;
use flexmb_model::Scene;
use std::sync::Arc;

/// A point mass on a massless cantilever A–B; `extra` adds scene fields.
fn cantilever(inertia: &str, extra: &str) -> Dynamics {
    let text = format!(
        r#"(
        dimension: Planar,
        materials: {{ "s": (e: 2.0e11, rho: 1.0) }},
        sections: {{ "b": User((area: 1e-4, iy: 1e-9, iz: 1e-9, j: 1e-9, ky: inf, kz: inf)) }},
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [
            (id: "beam", type: Beam((nodes: ("A", "B"), material: "s", section: "b", mass: false))),
            (id: "m", type: PointMass(node: "B", mass: 2.0{inertia})),
        ],
        fixed: [ Node("A") ],
        rigid: [ Def("beam", "elongation") ],
        {extra}
    )"#
    );
    Dynamics::new(Arc::new(
        Scene::from_ron_str(&text).unwrap().build(None).unwrap(),
    ))
}

fn rest(dy: &mut Dynamics) -> flexmb_dynamics::Linearization {
    let q0 = dy.mechanism().q0();
    dy.linearize_at_rest(0.0, &q0).unwrap()
}

#[test]
fn no_inertia_names_the_dofs_and_nodes_as_the_equations_of_motion_do() {
    // the angle of B has no inertia: as a DOF it is named with its node, as
    // a deformation with its element and nodes
    for (extra, expect) in [
        (r#"dofs_first: [ Coord("B", Angle) ],"#, "B.angle (node B)"),
        ("", "(element beam, nodes A, B)"),
    ] {
        let mut dy = cantilever("", extra);
        let lin = rest(&mut dy);
        let eig = undamped_modes(&lin, 1)
            .expect_err("a massless DOF")
            .to_string();
        assert!(
            eig.contains("no inertia: DOF q") && eig.contains(expect),
            "{eig}"
        );
        // the same DOFs as the equations of motion name
        let n = dy.n_q();
        let q0 = dy.mechanism().q0();
        let sim = dy.accelerations(0.0, &q0, &vec![0.0; n], &mut vec![0.0; n]);
        let Err(DynamicsError::SingularMass { dofs }) = sim else {
            panic!("expected SingularMass, got {sim:?}");
        };
        assert!(!dofs.is_empty());
        assert!(eig.ends_with(&dofs.join(", ")), "{eig} / {dofs:?}");
        let damped = damped_modes(&lin).expect_err("a massless DOF").to_string();
        assert!(damped.contains(expect), "{damped}");
    }
}

#[test]
fn a_stiffness_without_a_restraint_in_buckling_names_the_unrestrained_motion() {
    let mut dy = cantilever(", inertia: Some(1e-6)", "");
    let mut lin = rest(&mut dy);
    // remove the stiffness of DOF 0: nothing restrains it
    for j in 0..lin.k.ncols() {
        lin.k[(0, j)] = 0.0;
        lin.k[(j, 0)] = 0.0;
    }
    let e = buckling_factors(&lin, 1)
        .expect_err("K is singular")
        .to_string();
    let first = lin.at.mechanism.dof_label(0);
    assert!(
        e.contains("unrestrained motion") && e.contains(&format!("it involves {first}")),
        "{e}"
    );
}

#[test]
fn an_eigenvalue_solver_that_fails_gives_the_configuration() {
    let mut dy = cantilever(", inertia: Some(1e-6)", "");
    let mut lin = rest(&mut dy);
    // a state-space matrix that overflows: the eigenvalue solver cannot converge
    let n = lin.m.nrows();
    lin.d = Mat::from_fn(n, n, |i, j| if i == j { f64::MAX } else { 0.0 });
    lin.k = Mat::from_fn(n, n, |i, j| if i == j { f64::MAX } else { f64::MAX / 2.0 });
    let e = damped_modes(&lin).expect_err("no convergence").to_string();
    assert!(
        e.contains("did not converge at t = 0 s, the reference configuration"),
        "{e}"
    );
    // elsewhere: the DOFs furthest from their reference values
    let mut q = dy.mechanism().q0();
    q[1] += 1e-3;
    let mut lin2 = dy.linearize_at_rest(0.0, &q).unwrap();
    lin2.d = lin.d.clone();
    lin2.k = lin.k.clone();
    let e = damped_modes(&lin2).expect_err("no convergence").to_string();
    let label = dy.mechanism().dof_label(1);
    assert!(
        e.contains(&format!(
            "did not converge at t = 0 s, where {label} is 0.001 (reference 0)"
        )),
        "{e}"
    );
}

#[test]
fn a_sweep_configuration_that_fails_is_named_with_its_held_value() {
    // B.angle has no inertia: every configuration fails, the first is named
    let dy = cantilever("", r#"dofs_first: [ Coord("B", Angle) ],"#);
    let mech = dy.mechanism().clone();
    assert_eq!(mech.coordinate_name(mech.dofs[0]), "B.angle");
    let opts = SweepOptions {
        values: vec![0.0, 1e-3],
        modes: 1,
        t: 0.0,
        keep_vectors: false,
    };
    let e = sweep(&mech, &SweepParameter::Dof(0), &opts, &|_, _| {})
        .expect_err("no inertia")
        .to_string();
    assert!(
        e.starts_with("sweep configuration 1 of 2 (DOF q0 = B.angle (node B) held at 0)")
            && e.contains("no inertia"),
        "{e}"
    );
}
