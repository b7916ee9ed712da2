//! The bad-input catalogue: one case per error class; each message names the
//! culprit and nothing panics.

use flexmb_model::{ModelError, Scene};

const BASE: &str = r#"(
    dimension: Planar,
    materials: { "al": (e: 7.0e10, rho: 2700.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [1.0, 1.0]) ],
    elements: [
        (id: "ab", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))),
        (id: "bc", type: Beam((nodes: ("B", "C"), material: "al", section: "bar"))),
    ],
    fixed: [ Node("A") ],
    rigid: [ Def("ab", "elongation"), Def("bc", "elongation") ],
)"#;

fn err(text: &str) -> String {
    match Scene::from_ron_str(text).and_then(|s| s.build(None)) {
        Ok(m) => panic!("expected an error, got {}", m.summary()),
        Err(e) => e.to_string(),
    }
}

fn variant(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "{from}");
    BASE.replacen(from, to, 1)
}

#[test]
fn the_base_scene_is_valid() {
    let m = Scene::from_ron_str(BASE).unwrap().build(None).unwrap();
    assert_eq!(m.n_dof(), 4);
}

#[test]
fn unknown_ids_are_named_with_a_suggestion() {
    let e = err(&variant(r#"nodes: ("B", "C")"#, r#"nodes: ("B", "CC")"#));
    assert!(
        e.contains("unknown node 'CC'")
            && e.contains("element 'bc'")
            && e.contains("did you mean 'C'"),
        "{e}"
    );
    let e = err(&variant(
        r#"material: "al", section: "bar"))),
        (id: "bc""#,
        r#"material: "steel", section: "bar"))),
        (id: "bc""#,
    ));
    assert!(e.contains("unknown material 'steel'"), "{e}");
    let e = err(&variant(
        r#"Def("bc", "elongation")"#,
        r#"Def("cd", "elongation")"#,
    ));
    assert!(e.contains("unknown element 'cd'"), "{e}");
    let e = err(&variant(
        r#"Def("bc", "elongation")"#,
        r#"Def("bc", "torsion")"#,
    ));
    assert!(e.contains("no deformation 'torsion'"), "{e}");
}

#[test]
fn duplicate_ids_are_rejected() {
    let e = err(&variant(
        r#"(id: "C", at: [1.0, 1.0])"#,
        r#"(id: "B", at: [1.0, 1.0])"#,
    ));
    assert!(e.contains("duplicate node id 'B'"), "{e}");
    let e = err(&variant(r#"(id: "bc", type"#, r#"(id: "ab", type"#));
    assert!(e.contains("duplicate element id 'ab'"), "{e}");
}

#[test]
fn zero_length_elements_and_bad_properties_are_named() {
    let e = err(&variant(
        r#"(id: "C", at: [1.0, 1.0])"#,
        r#"(id: "C", at: [1.0, 0.0])"#,
    ));
    assert!(e.contains("element 'bc'") && e.contains("length"), "{e}");
    let e = err(&variant(
        "(e: 7.0e10, rho: 2700.0)",
        "(e: -7.0e10, rho: 2700.0)",
    ));
    assert!(e.contains("material 'al'") && e.contains("Young"), "{e}");
    let e = err(&variant(
        "Rectangle(by: 0.01, bz: 0.02)",
        "Rectangle(by: 0.0, bz: 0.02)",
    ));
    assert!(e.contains("section 'bar'"), "{e}");
}

#[test]
fn non_finite_values_are_rejected() {
    let e = err(&variant(
        "(id: \"B\", at: [1.0, 0.0])",
        "(id: \"B\", at: [NaN, 0.0])",
    ));
    assert!(e.contains("node 'B'") && e.contains("non-finite"), "{e}");
    let e = err(&variant(
        "(e: 7.0e10, rho: 2700.0)",
        "(e: inf, rho: 2700.0)",
    ));
    assert!(e.contains("material 'al'"), "{e}");
}

#[test]
fn prescribed_coordinates_need_a_function_and_one_role() {
    // a prescribed entry without its function is a parse error naming the field
    let e = err(&variant(
        "fixed: [ Node(\"A\") ],",
        "fixed: [ Node(\"A\") ],\n    prescribed: [ (what: Coord(\"C\", X)) ],",
    ));
    assert!(e.contains("function"), "{e}");
    // fixed and prescribed at once
    let e = err(&variant(
        "fixed: [ Node(\"A\") ],",
        "fixed: [ Node(\"A\") ],\n    prescribed: [ (what: Coord(\"A\", X), function: Constant(0.0)) ],",
    ));
    assert!(e.contains("A.x") && e.contains("two roles"), "{e}");
    // an invalid time function
    let e = err(&variant(
        "fixed: [ Node(\"A\") ],",
        "fixed: [ Node(\"A\") ],\n    prescribed: [ (what: Coord(\"C\", X), function: Ramp(t0: 1.0, t1: 0.0, v0: 0.0, v1: 1.0)) ],",
    ));
    assert!(e.contains("t1 > t0"), "{e}");
}

#[test]
fn inconsistent_roles_are_reported() {
    let e = err(&variant("rigid: [", "rigid: [ Node(\"B\"), "));
    assert!(e.contains("B.x") && e.contains("cannot be rigid"), "{e}");
    let e = err(&variant(
        "fixed: [ Node(\"A\") ],",
        "fixed: [ Node(\"A\"), Def(\"ab\", \"bending_p\") ],",
    ));
    assert!(
        e.contains("ab.bending_p") && e.contains("cannot be fixed"),
        "{e}"
    );
}

#[test]
fn over_and_under_constrained_mechanisms_name_the_culprits() {
    // C fixed as well: the two rigid elongations and the fixed ends leave a
    // redundant equation
    let e = err(&variant("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\"), Coord(\"C\", Position) ],\n    dofs: Explicit([Def(\"ab\", \"bending_p\"), Def(\"ab\", \"bending_q\"), Def(\"bc\", \"bending_p\"), Def(\"bc\", \"bending_q\"), Coord(\"B\", X)]),"));
    assert!(
        e.contains("over-constrained") || e.contains("redundant"),
        "{e}"
    );
    // too few explicit DOFs: the mechanism is under-constrained
    let e = err(&variant(
        "fixed: [ Node(\"A\") ],",
        "fixed: [ Node(\"A\") ],\n    dofs: Explicit([Def(\"ab\", \"bending_p\")]),",
    ));
    assert!(
        e.contains("under-constrained") && e.contains("3 motion") && e.contains("C.x"),
        "{e}"
    );
    // a free body with every deformation rigid and an explicit deformation DOF: redundant
    let e = err(&variant(
        "rigid: [ Def(\"ab\", \"elongation\"), Def(\"bc\", \"elongation\") ],",
        "rigid: [ Def(\"ab\", \"*\"), Def(\"bc\", \"*\") ],\n    dofs: Explicit([Def(\"ab\", \"elongation\")]),",
    ));
    assert!(e.contains("ab.elongation"), "{e}");
}

#[test]
fn malformed_ron_reports_line_and_column() {
    let e = Scene::from_ron_str(
        "(\n  nodes: [\n    (id: \"A\" at: [0.0, 0.0]),\n  ],\n  elements: [],\n)",
    )
    .unwrap_err();
    match &e {
        ModelError::Parse { line, column, .. } => {
            assert_eq!(*line, 3, "{e}");
            assert!(*column > 1, "{e}");
        }
        other => panic!("expected a parse error, got {other}"),
    }
    assert!(e.to_string().contains("line 3, column"), "{e}");
}

#[test]
fn a_chain_too_long_is_refused_before_anything_is_allocated() {
    let e = err(&variant(
        r#"section: "bar"))),
        (id: "bc""#,
        r#"section: "bar", n: 2000000))),
        (id: "bc""#,
    ));
    assert!(
        e.contains("element 'ab'") && e.contains("n = 2000000") && e.contains("1000000"),
        "{e}"
    );
    // 1e9 is not an integer: a parse error with its place, not an allocation
    let e = err(&variant(
        r#"section: "bar"))),
        (id: "bc""#,
        r#"section: "bar", n: 1e9))),
        (id: "bc""#,
    ));
    assert!(e.contains("line 7") && e.contains("integer"), "{e}");
    // large but allowed: assembled in well under a second
    let t = std::time::Instant::now();
    let m = Scene::from_ron_str(&variant(
        r#"section: "bar"))),
        (id: "bc""#,
        r#"section: "bar", n: 2000))),
        (id: "bc""#,
    ))
    .unwrap()
    .build(None)
    .unwrap();
    // two bending deformations per beam of the chain, two of bc
    assert_eq!(m.n_dof(), 2 * 2000 + 2);
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
}
