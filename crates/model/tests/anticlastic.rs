//! Sheets with the anticlastic curl in a scene (`anticlastic: Some((p: ..,
//! q: ..))`): the two-coordinate groups `ID.a0` … `ID.aN`, the overlay
//! elements in their own group, restrained ends, the curl amplitudes as DOFs,
//! and bad input that names the element.

mod common;

use common::build;
use flexmb_model::XRole;

fn scene(opts: &str, section: &str, dimension: &str) -> String {
    let (at_b, up) = if dimension == "Spatial" {
        ("[0.0, 0.2, 0.0]", ", up: Some([0.0, 0.0, 1.0])")
    } else {
        ("[0.0, 0.2]", "")
    };
    let at_a = if dimension == "Spatial" {
        "[0.0, 0.0, 0.0]"
    } else {
        "[0.0, 0.0]"
    };
    format!(
        r#"(
    dimension: {dimension},
    materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7600.0) }},
    sections: {{ "sheet": {section} }},
    nodes: [ (id: "A", at: {at_a}), (id: "B", at: {at_b}) ],
    elements: [ (id: "s", type: Beam((nodes: ("A", "B"), material: "steel", section: "sheet"{up}, n: 4{opts}))) ],
    fixed: [Node("A")],
    rigid: [Def("s", "elongation")],
)"#
    )
}

const SHEET: &str = "Rectangle(by: 0.03, bz: 0.001)";

#[test]
fn a_sheet_chain_gets_two_curl_amplitudes_per_node_as_dofs() {
    let m = build(&scene(
        ", anticlastic: Some((p: Restrained, q: Free))",
        SHEET,
        "Spatial",
    ))
    .unwrap();
    let names: Vec<&str> = m.mode_groups.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["s.a0", "s.a1", "s.a2", "s.a3", "s.a4"]);
    for (g, idx) in &m.mode_groups {
        assert_eq!(idx.len(), 2, "{g}");
        for &i in idx {
            // the clamped end's curl is fixed, the others are DOFs
            match (g.as_str(), m.x_roles[i]) {
                ("s.a0", XRole::Fixed) => {}
                (_, XRole::Dof(_)) if g != "s.a0" => {}
                (g, r) => panic!("{g}: {r:?}"),
            }
        }
    }
    // an overlay per beam; `Def("s", "elongation")` still names the beams
    let plain = build(&scene("", SHEET, "Spatial")).unwrap();
    assert_eq!(m.elements.len(), plain.elements.len() + 4);
    assert_eq!(m.dofs.len(), plain.dofs.len() + 2 * 4);
}

#[test]
fn the_curl_on_what_is_not_a_spatial_sheet_is_an_error_naming_the_element() {
    let planar = scene(
        ", anticlastic: Some((p: Restrained, q: Free))",
        "Rectangle(by: 0.001, bz: 0.03)",
        "Planar",
    );
    let e = build(&planar).unwrap_err();
    assert!(e.contains("'s'") && e.contains("spatial"), "{e}");
    let e = build(&scene(
        ", anticlastic: Some((p: Restrained, q: Free))",
        "Circle(d: 0.01)",
        "Spatial",
    ))
    .unwrap_err();
    assert!(
        e.contains("'s'") && e.contains("Rectangle") && !e.contains("NaN"),
        "{e}"
    );
    let e = build(&scene(
        ", anticlastic: Some((p: Restrained, q: Loose))",
        SHEET,
        "Spatial",
    ))
    .unwrap_err();
    assert!(e.contains("Loose"), "{e}");
}
