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

/// A parse error: (line, column, message).
fn parse_err(text: &str) -> (usize, usize, String) {
    match Scene::from_ron_str(text) {
        Ok(_) => panic!("expected a parse error"),
        Err(e) => match &e {
            ModelError::Parse { line, column, .. } => (*line, *column, e.to_string()),
            other => panic!("expected a parse error, got {other}"),
        },
    }
}

/// Issue 14.1: a misspelt field used to be ignored (`gravityy` dropped
/// gravity, `timoshenkoo` kept Timoshenko bending, `fixd` gave a free-free
/// model). Each is an error with line, column and the nearest valid name, at
/// every level: the scene, a struct inside a newtype variant (`BeamSpec`), a
/// struct variant of an enum (`Truss`, `Ramp`), a struct in a tuple variant
/// (`User` section) and a map value (a material).
#[test]
fn unknown_fields_are_rejected_with_line_column_and_the_nearest_name() {
    let (line, column, e) = parse_err(&variant(
        "    fixed: [ Node(\"A\") ],",
        "    gravityy: Some([0.0, -9.81]),\n    fixed: [ Node(\"A\") ],",
    ));
    assert_eq!((line, column), (10, 5), "{e}");
    assert!(
        e.contains("`gravityy`") && e.contains("did you mean `gravity`?"),
        "{e}"
    );
    let (line, _, e) = parse_err(&variant("fixed: [", "fixd: ["));
    assert_eq!(line, 10, "{e}");
    assert!(e.contains("did you mean `fixed`?"), "{e}");
    let (line, _, e) = parse_err(&variant(
        r#"section: "bar"))),
        (id: "bc""#,
        r#"section: "bar", timoshenkoo: false))),
        (id: "bc""#,
    ));
    assert_eq!(line, 7, "{e}");
    assert!(e.contains("did you mean `timoshenko`?"), "{e}");
    let (_, _, e) = parse_err(&variant("(e: 7.0e10,", "(e: 7.0e10, nuu: 0.33,"));
    assert!(e.contains("did you mean `nu`?"), "{e}");
    let (_, _, e) = parse_err(&variant(
        "Rectangle(by: 0.01, bz: 0.02)",
        "User((area: 2e-4, iy: 6.7e-9, iz: 1.7e-9, j: 4.6e-9, ky: 0.85, kz: 0.85, kzz: 1.0))",
    ));
    assert!(
        e.contains("`kzz`") && e.contains("did you mean `kz`?"),
        "{e}"
    );
    let (_, _, e) = parse_err(&variant(
        r#"(id: "bc", type: Beam((nodes: ("B", "C"), material: "al", section: "bar"))),"#,
        r#"(id: "bc", type: Truss(nodes: ("B", "C"), ea: 1e6, mass_per_lenght: 1.0)),"#,
    ));
    assert!(e.contains("did you mean `mass_per_length`?"), "{e}");
    let (_, _, e) = parse_err(&variant(
        "    fixed: [ Node(\"A\") ],",
        "    fixed: [ Node(\"A\") ],\n    prescribed: [ (what: Coord(\"B\", Y), function: Ramp(t0: 0.0, t1: 1.0, v0: 0.0, v: 1.0)) ],",
    ));
    assert!(e.contains("`v`") && e.contains("in `Ramp`"), "{e}");
    // a misspelt variant gets a suggestion too
    let (_, _, e) = parse_err(&variant("Rectangle(", "Rectangel("));
    assert!(e.contains("did you mean `Rectangle`?"), "{e}");
}

/// Issue 14.1: a repeated material or section id used to keep the last entry
/// silently; it is an error naming the id, with its line.
#[test]
fn duplicate_material_and_section_ids_are_rejected() {
    let (line, _, e) = parse_err(&variant(
        r#"materials: { "al": (e: 7.0e10, rho: 2700.0) },"#,
        "materials: {\n        \"al\": (e: 7.0e10, rho: 2700.0),\n        \"al\": (e: 7.0e7, rho: 2700.0),\n    },",
    ));
    assert_eq!(line, 5, "{e}");
    assert!(e.contains("duplicate material id 'al'"), "{e}");
    let (_, _, e) = parse_err(&variant(
        r#"sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },"#,
        r#"sections: { "bar": Rectangle(by: 0.01, bz: 0.02), "bar": Circle(d: 0.1) },"#,
    ));
    assert!(e.contains("duplicate section id 'bar'"), "{e}");
}

/// Issue 13.8: material data must be physical. ν = 2 used to be accepted.
/// Each error names the material and the field.
#[test]
fn unphysical_materials_are_rejected_naming_the_material_and_field() {
    let with = |m: &str| err(&variant("(e: 7.0e10, rho: 2700.0)", m));
    for (m, field) in [
        (
            "(e: 7.0e10, nu: 2.0, rho: 2700.0)",
            "nu (Poisson's ratio) = 2",
        ),
        (
            "(e: 7.0e10, nu: 0.5, rho: 2700.0)",
            "nu (Poisson's ratio) = 0.5",
        ),
        (
            "(e: 7.0e10, nu: -1.0, rho: 2700.0)",
            "nu (Poisson's ratio) = -1",
        ),
        (
            "(e: 7.0e10, nu: NaN, rho: 2700.0)",
            "nu (Poisson's ratio) = NaN",
        ),
        ("(e: 0.0, rho: 2700.0)", "e (Young's modulus) = 0"),
        ("(e: inf, rho: 2700.0)", "e (Young's modulus) = inf"),
        ("(e: 7.0e10, rho: -1.0)", "rho (density) = -1"),
        ("(e: 7.0e10, g: 0.0, rho: 2700.0)", "g (shear modulus) = 0"),
        // G below E/3 means ν > 0.5
        (
            "(e: 7.0e10, g: 2.0e10, rho: 2700.0)",
            "implies Poisson's ratio",
        ),
        // both given and inconsistent
        (
            "(e: 7.0e10, g: 2.6e10, nu: 0.2, rho: 2700.0)",
            "disagrees with nu",
        ),
    ] {
        let e = with(m);
        assert!(e.contains("material 'al'") && e.contains(field), "{m}: {e}");
    }
    // consistent G and ν together are fine
    let ok = variant(
        "(e: 7.0e10, rho: 2700.0)",
        "(e: 7.0e10, g: 2.5e10, nu: 0.4, rho: 2700.0)",
    );
    Scene::from_ron_str(&ok).unwrap().build(None).unwrap();
}

/// Issue 13.8: sections must be physical: positive finite dimensions, a tube
/// wall between zero and half the outer diameter, positive properties of a
/// `User` section with J ≤ Iy + Iz and shear factors in (0, 1] or inf.
#[test]
fn unphysical_sections_are_rejected_naming_the_section_and_field() {
    let with = |s: &str| err(&variant("Rectangle(by: 0.01, bz: 0.02)", s));
    for (s, field) in [
        ("Rectangle(by: -0.01, bz: 0.02)", "`by`"),
        ("Rectangle(by: 0.01, bz: inf)", "`bz`"),
        ("Circle(d: 0.0)", "`d`"),
        ("Tube(d_outer: 0.02, d_inner: 0.02)", "`d_inner`"),
        ("Tube(d_outer: 0.02, d_inner: -0.001)", "`d_inner`"),
        (
            "User((area: 0.0, iy: 1e-9, iz: 1e-9, j: 1e-9, ky: inf, kz: inf))",
            "`area`",
        ),
        (
            "User((area: 2e-4, iy: 1e-9, iz: 1e-9, j: 5e-9, ky: inf, kz: inf))",
            "`j`",
        ),
        (
            "User((area: 2e-4, iy: 1e-9, iz: 1e-9, j: 1e-9, ky: 0.0, kz: inf))",
            "`ky`",
        ),
        (
            "User((area: 2e-4, iy: 1e-9, iz: 1e-9, j: 1e-9, ky: inf, kz: 1.5))",
            "`kz`",
        ),
    ] {
        let e = with(s);
        assert!(e.contains("section 'bar'") && e.contains(field), "{s}: {e}");
    }
}

/// Issue 14.1: a superelement file with an unknown field is rejected when a
/// scene loads it, naming the file, line and field.
#[test]
fn superelement_files_with_unknown_fields_are_rejected() {
    use flexmb_element::LinearSuperelement;
    let dir = std::env::temp_dir().join(format!("flexmb-bad-se-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = nalgebra::DMatrix::<f64>::identity(6, 6);
    s *= 1.0e6;
    let m = nalgebra::DMatrix::<f64>::identity(12, 12);
    let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let se = LinearSuperelement::from_matrices(1.0, eye, &s, &m, vec![]);
    let text = ron::ser::to_string_pretty(&se, ron::ser::PrettyConfig::default()).unwrap();
    let scene = |file: &str| {
        format!(
            r#"(
    materials: {{}},
    nodes: [ (id: "P", at: [0.0, 0.0, 0.0]), (id: "Q", at: [1.0, 0.0, 0.0]) ],
    elements: [ (id: "se", type: Superelement(nodes: ("P", "Q"), file: "{file}")) ],
    fixed: [ Node("P") ],
)"#
        )
    };
    std::fs::write(dir.join("good.se.ron"), &text).unwrap();
    Scene::from_ron_str(&scene("good.se.ron"))
        .unwrap()
        .build(Some(&dir))
        .unwrap();
    let bad = text.replacen("modes:", "mode: [],\n    modes:", 1);
    assert_ne!(bad, text);
    std::fs::write(dir.join("bad.se.ron"), &bad).unwrap();
    let e = Scene::from_ron_str(&scene("bad.se.ron"))
        .unwrap()
        .build(Some(&dir))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad.se.ron") && e.contains("`mode`") && e.contains("did you mean `modes`?"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An inertia tensor whose principal moments break the triangle inequality
/// (no mass distribution has it: e.g. an inertia about the node instead of
/// the centre of mass, or a typo) is refused naming the element; a flat
/// plate, on the bound, is accepted.
#[test]
fn a_rigid_body_inertia_no_body_can_have_is_refused() {
    let scene = |j: &str| {
        format!(
            r#"(
        dimension: Spatial,
        nodes: [ (id: "C", at: [0.0, 0.0, 0.0]) ],
        elements: [ (id: "plate", type: RigidBody(node: "C", mass: 0.05, inertia: {j})) ],
    )"#
        )
    };
    let e = err(&scene(
        "[[1.0e-3, 0.0, 0.0], [0.0, 1.0e-3, 0.0], [0.0, 0.0, 3.0e-3]]",
    ));
    assert!(
        e.contains("plate") && e.contains("triangle inequality"),
        "{e}"
    );
    let flat = "[[1.0e-3, 0.0, 0.0], [0.0, 0.6e-3, 0.0], [0.0, 0.0, 1.6e-3]]";
    Scene::from_ron_str(&scene(flat))
        .unwrap()
        .build(None)
        .unwrap();
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
    // large but allowed (its assembly time is in benches/build.rs)
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
}

#[test]
fn a_position_of_cycle_is_reported_as_a_cycle_naming_its_nodes() {
    // B shares the position of C and C that of B: neither has a position
    let e = err(&variant(
        r#"(id: "B", at: [1.0, 0.0]), (id: "C", at: [1.0, 1.0])"#,
        r#"(id: "B", position_of: Some("C")), (id: "C", position_of: Some("B"))"#,
    ));
    assert!(e.contains("position_of cycle: B → C → B"), "{e}");
    // a longer cycle, entered from a node that is not on it
    let e = err(&variant(
        r#"(id: "B", at: [1.0, 0.0]), (id: "C", at: [1.0, 1.0])"#,
        r#"(id: "B", position_of: Some("D")), (id: "C", position_of: Some("E")),
           (id: "D", position_of: Some("E")), (id: "E", position_of: Some("C"))"#,
    ));
    assert!(e.contains("position_of cycle: C → E → C"), "{e}");
    // a node that names itself
    let e = err(&variant(
        r#"(id: "C", at: [1.0, 1.0])"#,
        r#"(id: "C", position_of: Some("C"))"#,
    ));
    assert!(e.contains("position_of cycle: C → C"), "{e}");
    // no cycle, but a node declared later: said so, not "unknown node"
    let e = err(&variant(
        r#"(id: "B", at: [1.0, 0.0]), (id: "C", at: [1.0, 1.0])"#,
        r#"(id: "B", position_of: Some("C")), (id: "C", at: [1.0, 1.0])"#,
    ));
    assert!(
        e.contains("'C' is declared after 'B'") && !e.contains("unknown node"),
        "{e}"
    );
}

#[test]
fn outputs_that_name_what_the_mechanism_lacks_are_refused_when_building() {
    let with = |outputs: &str| variant("fixed:", &format!("outputs: [ {outputs} ],\n    fixed:"));
    // the valid ones build
    Scene::from_ron_str(&with(
        r#"Position("C"), Rotation("C"), Deformation("bc", "*"), Stress("ab", "elongation"), Energies, Dofs"#,
    ))
    .unwrap()
    .build(None)
    .unwrap();
    let e = err(&with(r#"Position("CC")"#));
    assert!(
        e.contains(r#"output Position("CC")"#)
            && e.contains("unknown node 'CC'")
            && e.contains("did you mean 'C'"),
        "{e}"
    );
    let e = err(&with(r#"Deformation("bd", "*")"#));
    assert!(
        e.contains(r#"output Deformation("bd", "*")"#) && e.contains("unknown element 'bd'"),
        "{e}"
    );
    let e = err(&with(r#"Stress("bc", "torsion")"#));
    assert!(
        e.contains(r#"output Stress("bc", "torsion")"#) && e.contains("no deformation 'torsion'"),
        "{e}"
    );
}

#[test]
fn a_rotation_output_of_a_node_without_rotation_is_refused() {
    // trusses use only the positions of their nodes
    let text = r#"(
        dimension: Planar,
        materials: { "al": (e: 7.0e10, rho: 2700.0) },
        sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [ (id: "ab", type: Truss(nodes: ("A", "B"), ea: 1.0e6, mass_per_length: 1.0)) ],
        fixed: [ Node("A"), Coord("B", Y) ],
        outputs: [ Rotation("B") ],
    )"#;
    let e = err(text);
    assert!(
        e.contains(r#"output Rotation("B")"#) && e.contains("node 'B' has no rotation"),
        "{e}"
    );
}
