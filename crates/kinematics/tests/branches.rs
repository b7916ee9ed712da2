//! The position solve stays on the branch of the last solution (of the
//! reference configuration for the first solve): a two-link arm whose tip is
//! the DOF has two configurations for most tip positions (the elbow on
//! either side of the line from the shoulder to the tip). A solve far from
//! the last one used to fold the elbow the other way without a word.

use flexmb_kinematics::{Kinematics, KinematicsError};
use flexmb_model::{Mechanism, Scene};
use std::sync::Arc;

/// Shoulder A fixed, elbow B, tip C (the DOFs), links of length 1 as rigid
/// trusses, the elbow to the left of A → C at the reference.
const ARM: &str = r#"(
    dimension: Planar,
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.6, 0.8]), (id: "C", at: [1.2, 0.0]) ],
    elements: [
        (id: "upper", type: Truss(nodes: ("A", "B"), ea: 1.0e6, mass_per_length: 1.0)),
        (id: "lower", type: Truss(nodes: ("B", "C"), ea: 1.0e6, mass_per_length: 1.0)),
    ],
    fixed: [ Coord("A", Position) ],
    rigid: [ Def("upper", "*"), Def("lower", "*") ],
    dofs: Explicit([ Coord("C", Position) ]),
)"#;

fn arm() -> Arc<Mechanism> {
    Arc::new(Scene::from_ron_str(ARM).unwrap().build(None).unwrap())
}

/// The elbow's side: the sign of (C − A) × (B − A), positive to the left.
fn elbow_side(k: &Kinematics) -> f64 {
    let m = k.mechanism();
    let (b, c) = (
        &m.node("B").unwrap().position,
        &m.node("C").unwrap().position,
    );
    let x = k.x();
    x[c[0]] * x[b[1]] - x[c[1]] * x[b[0]]
}

/// Tip positions all around the shoulder, off the line through A and the
/// reference tip (the fold at the shoulder is not crossed on the way).
const TARGETS: [[f64; 2]; 6] = [
    [0.3, 0.0],
    [0.0, 1.2],
    [-1.0, 0.3],
    [-1.5, 1.0],
    [0.2, -1.5],
    [1.0, -1.0],
];

#[test]
fn a_large_step_keeps_the_elbow_on_the_side_of_the_last_solution() {
    let mech = arm();
    for target in TARGETS {
        // one step from a solution with F,ξ at hand
        let mut k = Kinematics::new(mech.clone());
        k.solve(&[1.2, 0.0], 0.0).unwrap();
        k.first_order();
        k.solve(&target, 0.0).unwrap();
        assert!(
            elbow_side(&k) > 0.0,
            "the elbow folded over going to {target:?}"
        );
        // the same as 400 small steps
        let mut c = Kinematics::new(mech.clone());
        for j in 1..=400 {
            let s = j as f64 / 400.0;
            c.solve(&[1.2 + s * (target[0] - 1.2), s * target[1]], 0.0)
                .unwrap();
        }
        let d = k
            .x()
            .iter()
            .zip(c.x())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(d < 1e-10, "{target:?}: {d:e} from the continued solution");
    }
}

#[test]
fn the_first_solve_stays_on_the_branch_of_the_reference() {
    let mech = arm();
    for target in TARGETS {
        let mut k = Kinematics::new(mech.clone());
        k.solve(&target, 0.0).unwrap();
        assert!(
            elbow_side(&k) > 0.0,
            "the elbow folded over going to {target:?}"
        );
    }
}

#[test]
fn a_guess_on_the_other_branch_is_kept() {
    let mech = arm();
    let mut k = Kinematics::new(mech.clone());
    // the mirror image of the reference: elbow below A → C
    let b = &mech.node("B").unwrap().position;
    let mut guess = k.x().to_vec();
    guess[b[1]] = -0.8;
    k.set_guess(&guess);
    k.solve(&[1.2, 0.0], 0.0).unwrap();
    assert!(elbow_side(&k) < 0.0);
    // and later solves continue from it
    k.solve(&[-1.0, 0.3], 0.0).unwrap();
    assert!(elbow_side(&k) < 0.0);
}

#[test]
fn a_step_through_the_fold_at_the_shoulder_is_an_error_not_an_answer() {
    // the straight path from (1.2, 0) to (-1.2, 0) passes the tip through
    // the shoulder, where the elbow is anywhere on a circle
    let mut k = Kinematics::new(arm());
    let e = k.solve(&[-1.2, 0.0], 0.0).unwrap_err();
    assert!(
        matches!(
            e,
            KinematicsError::BranchJump { .. } | KinematicsError::Singular { .. }
        ),
        "{e}"
    );
    // back at the last solution, the reference
    assert!((k.x()[k.mechanism().node("C").unwrap().position[0]] - 1.2).abs() < 1e-15);
    assert!(elbow_side(&k) > 0.0);
}
