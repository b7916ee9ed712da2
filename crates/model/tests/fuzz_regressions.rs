//! Inputs found by `cargo xtask fuzz` that broke the model layer's contract:
//! a valid scene builds, an invalid one is an error naming the culprit, and
//! nothing panics. Each test failed before its fix.

use flexmb_model::Scene;

const SEED: &str = include_str!("../../../fixtures/fuzz/spatial_truss_rigid_body.ron");

/// The DOF names of a scene, sorted (independent of the node order).
fn dof_names(text: &str) -> Vec<String> {
    let mech = Scene::from_ron_str(text).unwrap().build(None).unwrap();
    let mut names: Vec<String> = mech
        .dofs
        .iter()
        .map(|c| mech.coordinate_name(*c).to_string())
        .collect();
    names.sort();
    names
}

/// Case 0x9ee0d2e82b774409 (CI, stop 25): the spatial truss and rigid-body
/// seed with its nodes listed as A, B, D, E, C. The DOF choice's SVD of a
/// 26 × 26 well-conditioned constraint Jacobian (singular values 0.108 to
/// 2.98) panicked with faer's `NoConvergence`; `flexmb_linalg::svd` falls
/// back to the transpose. The node order must not change the model.
#[test]
fn reordered_nodes_build_the_same_degrees_of_freedom() {
    let c = "        (id: \"C\", at: [0.5, 0.3, 0.0]),\n";
    let e = "        (id: \"E\", at: [0.8, 0.0, 0.0]),\n";
    assert!(
        SEED.contains(c) && SEED.contains(e),
        "the seed scene changed"
    );
    let reordered = SEED.replace(c, "").replace(e, &format!("{e}{c}"));
    assert_ne!(reordered, SEED);
    let original = dof_names(SEED);
    assert!(!original.is_empty());
    assert_eq!(dof_names(&reordered), original);
}
