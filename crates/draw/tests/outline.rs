//! `Style::Outline` (the default of `flexmb draw`), checked in model
//! coordinates: beams as thin boxes of their section along their deformed
//! centre line, superelements as the outline of their recovered FE mesh.

use flexmb_draw::{styled_geometry, Configuration, Item, ItemKind, Style, View, BEAM_STATIONS};
use flexmb_model::{Mechanism, Scene};
use flexmb_rotation::generic::rotation;
use std::sync::Arc;

fn items<'a>(g: &'a flexmb_draw::Geometry, kind: ItemKind, id: &str) -> Vec<&'a Item> {
    g.items
        .iter()
        .filter(|i| i.kind == kind && i.id == id)
        .collect()
}

fn node(mech: &Mechanism, x: &[f64], id: &str) -> ([f64; 3], [f64; 4]) {
    let n = mech.node(id).unwrap();
    let p = std::array::from_fn(|d| x[n.position[d]]);
    let o = n.orientation.as_ref().unwrap();
    (p, std::array::from_fn(|d| x[o[d]]))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|d| a[d] - b[d])
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn mean(p: &[[f64; 3]]) -> [f64; 3] {
    std::array::from_fn(|d| p.iter().map(|q| q[d]).sum::<f64>() / p.len() as f64)
}

/// A steel strip cantilever (0.2 m along x, section 0.02 × 0.002 m with y
/// up, so it bends about its weak axis under a tip force along z), in
/// static equilibrium: its box's end sections are by × bz rectangles
/// centred on the nodes and turned with their Euler parameters, its four
/// long edges run between them, and the projection is the view's.
#[test]
fn a_beam_is_a_thin_box_along_its_deformed_centre_line() {
    let scene = r#"(
    dimension: Spatial,
    materials: { "steel": (e: 2.1e11, g: 8.1e10, rho: 7850.0) },
    sections: { "strip": Rectangle(by: 0.02, bz: 0.002) },
    nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [0.2, 0.0, 0.0]) ],
    elements: [ (id: "strip", type: Beam((nodes: ("A", "B"), material: "steel", section: "strip", up: Some([0.0, 1.0, 0.0])))) ],
    fixed: [Node("A")],
    loads: [ (node: "B", force: Some([0.0, 0.0, -20.0])) ],
)"#;
    let mech = Arc::new(Scene::from_ron_str(scene).unwrap().build(None).unwrap());
    let at = Configuration::static_equilibrium(&mech).unwrap();
    let (rb, lb) = node(&mech, &at.x, "B");
    assert!(rb[2] < -0.01, "the tip went down: {rb:?}");
    let g = styled_geometry(&mech, &at.x, View::Iso, Style::Outline);
    let lines = items(&g, ItemKind::Beam, "strip");
    assert_eq!(lines.len(), 6, "4 long edges and 2 end sections");
    for edge in &lines[..4] {
        assert_eq!(edge.model.len(), BEAM_STATIONS + 1);
    }
    let r = rotation(&lb).0;
    for (k, (centre, turn)) in [
        (
            [0.0; 3],
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        ),
        (rb, r),
    ]
    .into_iter()
    .enumerate()
    {
        let sec = &lines[4 + k].model;
        assert_eq!(sec.len(), 5);
        assert_eq!(sec[0], sec[4], "closed");
        assert!(norm(sub(mean(&sec[..4]), centre)) < 1e-15);
        // the corner (+y, −z) at + by/2 y − bz/2 z of the node's frame
        let (y, z) = (
            [turn[0][1], turn[1][1], turn[2][1]],
            [turn[0][2], turn[1][2], turn[2][2]],
        );
        let want: [f64; 3] = std::array::from_fn(|d| centre[d] + 0.01 * y[d] - 0.001 * z[d]);
        assert!(
            norm(sub(sec[1], want)) < 1e-12,
            "end {k}: {:?} against {want:?}",
            sec[1]
        );
        // the long edges start and end at these corners
        for c in 0..4 {
            let e = &lines[c].model;
            assert_eq!(if k == 0 { e[0] } else { e[BEAM_STATIONS] }, sec[c]);
        }
    }
    for it in &g.items {
        for (m, p) in it.model.iter().zip(&it.projected) {
            assert_eq!(*p, View::Iso.project(*m));
        }
    }
    // Style::Lines keeps the line between the nodes
    let lines = styled_geometry(&mech, &at.x, View::Iso, Style::Lines);
    assert_eq!(
        items(&lines, ItemKind::Beam, "strip")[0].model,
        vec![[0.0; 3], rb]
    );
}

/// A steel bar superelement (0.1 × 0.01 × 0.01 m, 4 × 2 × 2 twenty-node
/// hexahedra) clamped at P with a tip load at Q: drawn as its outline, the
/// 12 edges of the bar in 32 element edges (4 × 4 along it, 2 × 8 around
/// its ends), each through its midside node; no edge inside the bar or in
/// the grid of its flat faces; at the static equilibrium the q end's
/// points are centred on Q where the solver put it.
#[test]
fn a_superelement_is_the_outline_of_its_recovered_mesh() {
    let dir = std::env::temp_dir().join(format!("flexmb-draw-outline-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let steel = flexmb_element::Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    };
    let part =
        flexmb_superelement::parts::prismatic_bar(0.1, 0.01, 0.01, [4, 2, 2], steel).unwrap();
    let model = part.mesh.assemble("bar").unwrap();
    let data = flexmb_superelement::build(&model, &part.settings)
        .unwrap()
        .data;
    flexmb_superelement::spec::write_ron(&dir.join("bar.se.ron"), &data).unwrap();
    let scene = r#"(
    dimension: Spatial,
    nodes: [ (id: "P", at: [0.0, 0.0, 0.0]), (id: "Q", at: [0.1, 0.0, 0.0]) ],
    elements: [ (id: "bar", type: Superelement(nodes: ("P", "Q"), file: "bar.se.ron")) ],
    fixed: [Node("P")],
    loads: [ (node: "Q", force: Some([0.0, 2000.0, -1000.0]), moment: Some([5.0, 0.0, 0.0])) ],
)"#;
    let mech = Arc::new(
        Scene::from_ron_str(scene)
            .unwrap()
            .build(Some(&dir))
            .unwrap(),
    );
    let g = styled_geometry(&mech, &mech.x0, View::Iso, Style::Outline);
    let edges = items(&g, ItemKind::SuperelementOutline, "bar");
    assert_eq!(edges.len(), 32);
    for e in &edges {
        assert_eq!(e.model.len(), 3, "corner, midside, corner");
        for p in &e.model {
            // on an edge of the bar: two of x ∈ {0, L}, |y| = b/2, |z| = b/2
            let on = [
                p[0].abs() < 1e-15 || (p[0] - 0.1).abs() < 1e-15,
                (p[1].abs() - 0.005).abs() < 1e-15,
                (p[2].abs() - 0.005).abs() < 1e-15,
            ];
            assert!(
                on.iter().filter(|b| **b).count() >= 2,
                "{p:?} is not on an edge of the bar"
            );
        }
    }
    assert_eq!(items(&g, ItemKind::InterfaceNode, "bar").len(), 2);
    assert!(items(&g, ItemKind::SuperelementChord, "bar").is_empty());
    let at = Configuration::static_equilibrium(&mech).unwrap();
    let (q, _) = node(&mech, &at.x, "Q");
    assert!(q[1] > 1e-4, "Q moved: {q:?}");
    let g = styled_geometry(&mech, &at.x, View::Xy, Style::Outline);
    let ref_g = styled_geometry(&mech, &mech.x0, View::Xy, Style::Outline);
    // the points of the edges that lie in the q end face at the reference
    let mut end = vec![];
    for (e, r) in items(&g, ItemKind::SuperelementOutline, "bar")
        .iter()
        .zip(items(&ref_g, ItemKind::SuperelementOutline, "bar"))
    {
        for (p, p0) in e.model.iter().zip(&r.model) {
            if (p0[0] - 0.1).abs() < 1e-15 {
                end.push(*p);
            }
        }
    }
    assert!(end.len() > 10);
    let c = mean(&end);
    println!("q face centre {c:?}, Q {q:?}");
    assert!(
        norm(sub(c, q)) < 1e-6 * 0.1,
        "the q face is centred at {c:?}, Q at {q:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
