//! Beams with warping in a scene (`warping: Some((p: .., q: ..))`): the
//! one-coordinate mode groups `ID.w0` … `ID.wN` of a chain, restrained and
//! shared ends, and bad input that names the element.

mod common;

use common::build;
use flexmb_model::{Mechanism, Scene, XRole};
use std::path::Path;

/// Two collinear sheet chains A → B (n = 3) and B → C (n = 2); `w1`, `w2`
/// are their `warping:` fields (RON), `dim` the scene's dimension.
fn scene(w1: &str, w2: &str, section: &str) -> String {
    format!(
        r#"(
    dimension: Spatial,
    materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7600.0) }},
    sections: {{ "sheet": {section} }},
    nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [0.0, 0.2, 0.0]), (id: "C", at: [0.0, 0.3, 0.0]) ],
    elements: [
        (id: "s1", type: Beam((nodes: ("A", "B"), material: "steel", section: "sheet", up: Some([0.0, 0.0, 1.0]), n: 3{w1}))),
        (id: "s2", type: Beam((nodes: ("B", "C"), material: "steel", section: "sheet", up: Some([0.0, 0.0, 1.0]), n: 2{w2}))),
    ],
    fixed: [Node("A")],
)"#
    )
}

const SHEET: &str = "Rectangle(by: 0.03, bz: 0.001)";

fn group<'a>(m: &'a Mechanism, g: &str) -> &'a [usize] {
    &m.mode_groups
        .iter()
        .find(|(n, _)| n == g)
        .unwrap_or_else(|| panic!("no group '{g}' in {:?}", m.mode_groups))
        .1
}

#[test]
fn a_chain_gets_one_warping_group_per_node_and_restrained_ends_are_fixed() {
    let plain = build(&scene("", "", SHEET)).unwrap();
    assert!(plain.mode_groups.is_empty());
    let m = build(&scene(
        ", warping: Some((p: Restrained, q: Shared(\"join\")))",
        ", warping: Some((p: Shared(\"join\"), q: Free))",
        SHEET,
    ))
    .unwrap();
    let names: Vec<&str> = m.mode_groups.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["s1.w0", "s1.w1", "s1.w2", "join", "s2.w1", "s2.w2"],
        "3 + 1 and 2 + 1 nodes, the joint shared"
    );
    assert!(m.mode_groups.iter().all(|(_, idx)| idx.len() == 1));
    assert_eq!(m.n_x(), plain.n_x() + 6);
    // the restrained end is fixed, the others are not
    assert_eq!(m.x_roles[group(&m, "s1.w0")[0]], XRole::Fixed);
    for g in ["s1.w1", "join", "s2.w2"] {
        assert_ne!(m.x_roles[group(&m, g)[0]], XRole::Fixed, "{g}");
    }
    // neighbours share the group of their common node
    let x_of = |id: &str| &m.elements.iter().find(|e| e.id == id).unwrap().x_index;
    assert_eq!(x_of("s1.1")[15], x_of("s1.2")[14]);
    assert_eq!(x_of("s1.3")[15], group(&m, "join")[0]);
    assert_eq!(x_of("s2.1")[14], group(&m, "join")[0]);
    // the warping deformations are named per element
    assert!(m.eps_names.iter().any(|n| n == "s2.2.warping_q"));
}

#[test]
fn restrained_by_name_is_the_same_as_restrained() {
    let by_option = build(&scene(
        ", warping: Some((p: Restrained, q: Free))",
        "",
        SHEET,
    ))
    .unwrap();
    let text = scene(", warping: Some((p: Free, q: Free))", "", SHEET).replace(
        r#"fixed: [Node("A")]"#,
        r#"fixed: [Node("A"), Modes("s1.w0")]"#,
    );
    let by_name = build(&text).unwrap();
    assert_eq!(by_option.x_roles, by_name.x_roles);
    assert_eq!(by_option.n_dof(), by_name.n_dof());
}

#[test]
fn bad_warping_input_names_the_element() {
    // a planar beam has no torsion
    let planar = r#"(
    dimension: Planar,
    materials: { "steel": (e: 2.1e11, nu: 0.3, rho: 7600.0) },
    sections: { "sheet": Rectangle(by: 0.001, bz: 0.03) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.0, 0.2]) ],
    elements: [ (id: "flat", type: Beam((nodes: ("A", "B"), material: "steel", section: "sheet", warping: Some((p: Restrained, q: Free))))) ],
    fixed: [Node("A")],
)"#;
    let e = build(planar).unwrap_err();
    assert!(e.contains("element 'flat'") && e.contains("spatial"), "{e}");
    // a section without a warping constant
    let user = "User((area: 3.0e-5, iy: 2.5e-12, iz: 2.25e-9, j: 9.8e-12, ky: 0.83, kz: 0.83))";
    let e = build(&scene(
        ", warping: Some((p: Restrained, q: Free))",
        "",
        user,
    ))
    .unwrap_err();
    assert!(
        e.contains("'s1")
            && e.contains("missing section warping constant `iw`")
            && !e.contains("NaN"),
        "{e}"
    );
    // ... which it may give
    let with_iw = user.replace("kz: 0.83", "kz: 0.83, iw: 1.875e-16");
    assert!(build(&scene(
        ", warping: Some((p: Restrained, q: Free))",
        "",
        &with_iw
    ))
    .is_ok());
    // unknown fields and ends are errors
    let e = build(&scene(
        ", warping: Some((p: Restrained, q: Free, r: Free))",
        "",
        SHEET,
    ))
    .unwrap_err();
    assert!(e.contains("r"), "{e}");
    let e = build(&scene(", warping: Some((p: Clamped, q: Free))", "", SHEET)).unwrap_err();
    assert!(e.contains("Clamped"), "{e}");
}

#[test]
fn sharing_a_group_of_another_size_names_the_element_and_the_group() {
    // a superelement whose normal-mode group `se.f` holds 2 modes
    let text = r#"(
    dimension: Spatial,
    materials: { "steel": (e: 2.1e11, nu: 0.3, rho: 7600.0) },
    sections: { "sheet": Rectangle(by: 0.03, bz: 0.001) },
    nodes: [ (id: "P", at: [0.0, 0.0, 0.0]), (id: "Q", at: [0.1, 0.0, 0.0]), (id: "R", at: [0.3, 0.0, 0.0]) ],
    elements: [
        (id: "se", type: Superelement(nodes: ("P", "Q"), file: "bar.se.ron")),
        (id: "sheet", type: Beam((nodes: ("Q", "R"), material: "steel", section: "sheet", up: Some([0.0, 0.0, 1.0]), warping: Some((p: Shared("se.f"), q: Free))))),
    ],
    fixed: [Node("P")],
)"#;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fuzz");
    let e = Scene::from_ron_str(text)
        .and_then(|s| s.build(Some(&dir)))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("element 'sheet'") && e.contains("'se.f'") && e.contains("2 modes"),
        "{e}"
    );
}
