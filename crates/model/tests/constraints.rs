//! The constraint diagnosis (`Scene::diagnose_constraints`): counts from the
//! Grübler–Kutzbach formula, loops named with the right elements, releases
//! that make a mechanism exactly constrained, an under-constrained scene, the
//! fixture scenes, and a long chain.

use flexmb_model::constraints::{Direction, OverConstraint};
use flexmb_model::{ModelError, Scene};
use std::collections::BTreeSet;

const HEAD: &str = r#"
    dimension: Spatial,
    materials: { "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
"#;

/// A link (beam) `id` from node `p` to node `q`, with `up` = global z.
fn beam(id: &str, p: &str, q: &str) -> String {
    format!(
        r#"(id: "{id}", type: Beam((nodes: ("{p}", "{q}"), material: "steel", section: "bar", up: Some([0.0, 0.0, 1.0])))),"#
    )
}

/// A revolute joint `id` about global z between the orientations of `p` and `q`.
fn hinge(id: &str, p: &str, q: &str) -> String {
    format!(r#"(id: "{id}", type: Hinge(nodes: ("{p}", "{q}"), axis: Some([0.0, 0.0, 1.0]))),"#)
}

/// Every deformation of the beams rigid, the hinges ideal (bending rigid).
fn rigid(beams: &[&str], hinges: &[&str], released: &[(&str, &str)]) -> String {
    let mut s = String::new();
    for b in beams {
        for d in [
            "elongation",
            "torsion",
            "bending_y_p",
            "bending_y_q",
            "bending_z_p",
            "bending_z_q",
        ] {
            if !released.contains(&(b, d)) {
                s += &format!(r#"Def("{b}", "{d}"), "#);
            }
        }
    }
    for h in hinges {
        s += &format!(r#"Def("{h}", "bending_y"), Def("{h}", "bending_z"), "#);
    }
    s
}

/// A mechanism's part in RON pieces: (nodes, elements, fixed, beams, hinges).
type Part = (String, String, String, Vec<String>, Vec<String>);

/// A planar four-bar in the xy-plane built spatially, with ground pivots
/// `{t}GA` at (x0, 0) and `{t}GD` at (x0 + 2, 0): crank `{t}crank`,
/// coupler `{t}coupler`, rocker `{t}rocker`, hinges `{t}hA` … `{t}hD`.
/// Returns (nodes, elements, fixed, beams, hinges).
fn four_bar(t: &str, x0: f64) -> Part {
    let n = |s: &str| format!("{t}{s}");
    let nodes = format!(
        r#"(id: "{ga}", at: [{x0}, 0.0, 0.0]), (id: "{a}", position_of: Some("{ga}")),
           (id: "{b}", at: [{xb}, 1.0, 0.0]), (id: "{b2}", position_of: Some("{b}")),
           (id: "{c}", at: [{xc}, 1.5, 0.0]), (id: "{c2}", position_of: Some("{c}")),
           (id: "{gd}", at: [{xd}, 0.0, 0.0]), (id: "{d}", position_of: Some("{gd}")),"#,
        ga = n("GA"),
        a = n("A"),
        b = n("B"),
        b2 = n("B2"),
        c = n("C"),
        c2 = n("C2"),
        gd = n("GD"),
        d = n("D"),
        xb = x0 + 0.2,
        xc = x0 + 1.7,
        xd = x0 + 2.0,
    );
    let elements = [
        beam(&n("crank"), &n("A"), &n("B")),
        beam(&n("coupler"), &n("B2"), &n("C")),
        beam(&n("rocker"), &n("C2"), &n("D")),
        hinge(&n("hA"), &n("GA"), &n("A")),
        hinge(&n("hB"), &n("B"), &n("B2")),
        hinge(&n("hC"), &n("C"), &n("C2")),
        hinge(&n("hD"), &n("D"), &n("GD")),
    ]
    .join("\n");
    let fixed = format!(r#"Node("{}"), Node("{}"), "#, n("GA"), n("GD"));
    let beams = ["crank", "coupler", "rocker"].map(n).to_vec();
    let hinges = ["hA", "hB", "hC", "hD"].map(n).to_vec();
    (nodes, elements, fixed, beams, hinges)
}

fn scene_of(parts: &[Part], released: &[(&str, &str)]) -> Scene {
    let (mut nodes, mut elements, mut fixed, mut rig) =
        (String::new(), String::new(), String::new(), String::new());
    for (n, e, f, b, h) in parts {
        nodes += n;
        elements += e;
        fixed += f;
        let b: Vec<&str> = b.iter().map(|s| s.as_str()).collect();
        let h: Vec<&str> = h.iter().map(|s| s.as_str()).collect();
        rig += &rigid(&b, &h, released);
    }
    let text = format!(
        "({HEAD} nodes: [{nodes}], elements: [{elements}], fixed: [{fixed}], rigid: [{rig}])"
    );
    Scene::from_ron_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn loop_set(o: &OverConstraint) -> BTreeSet<String> {
    o.loop_elements.iter().cloned().collect()
}

fn set(v: &[&str]) -> BTreeSet<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// Sorts the loops of `d` into the two `sides` (each loop within one side
/// and containing its `core`), and checks that each side has 3 and that
/// their union is the whole side.
fn assert_two_sides(
    d: &flexmb_model::ConstraintDiagnosis,
    sides: [(&BTreeSet<String>, &BTreeSet<String>); 2],
) {
    let mut count = [0, 0];
    let mut union = [BTreeSet::new(), BTreeSet::new()];
    for o in &d.over {
        let s = loop_set(o);
        let k = sides
            .iter()
            .position(|(all, core)| s.is_subset(all) && s.is_superset(core))
            .unwrap_or_else(|| panic!("a loop in neither side: {s:?}\n{d}"));
        count[k] += 1;
        union[k].extend(s);
        assert_out_of_plane(o);
    }
    assert_eq!(count, [3, 3], "{d}");
    assert_eq!(&union[0], sides[0].0, "{d}");
    assert_eq!(&union[1], sides[1].0, "{d}");
}

fn assert_out_of_plane(o: &OverConstraint) {
    match &o.direction {
        Direction::Plane {
            normal,
            out_of_plane,
            ..
        } => {
            assert!((normal[2].abs() - 1.0).abs() < 1e-9, "{normal:?}");
            assert!(*out_of_plane > 1.0 - 1e-9, "{}", o.direction);
        }
        d => panic!("not a planar loop: {d}"),
    }
}

#[test]
fn a_spatial_four_bar_is_three_times_over_constrained_out_of_plane() {
    // Grübler–Kutzbach, spatial: 4 bodies with the ground, 4 revolute joints
    // of 5 constraints each: M = 6 (4 − 1) − 5 · 4 = −2; the planar four-bar
    // moves with 1 DOF, so 1 − (−2) = 3 over-constraints.
    let scene = scene_of(&[four_bar("", 0.0)], &[]);
    let d = scene.diagnose_constraints(None).unwrap();
    assert_eq!(d.over.len(), 3, "{d}");
    assert_eq!(d.mobility, 1, "{d}");
    assert!(d.under.is_empty() && !d.under_checked);
    // one loop: every self-stress runs through the ground and the three
    // links (cutting one leaves an open chain, which carries none); a
    // joint at a ground pivot carries moments only, so one self-stress may
    // pass it by (its force goes to the ground through the shared, fixed
    // position), but together they use every joint
    let all = set(&[
        "ground", "crank", "coupler", "rocker", "hA", "hB", "hC", "hD",
    ]);
    let links = set(&["ground", "crank", "coupler", "rocker"]);
    let mut union = BTreeSet::new();
    for o in &d.over {
        let s = loop_set(o);
        assert!(s.is_subset(&all) && s.is_superset(&links), "{s:?}\n{d}");
        union.extend(s);
        assert_eq!(o.loop_elements[0], "ground");
        assert_out_of_plane(o);
        // weights normalized, sorted
        assert!((o.equations[0].weight.abs() - 1.0).abs() < 1e-12);
        assert!(o
            .equations
            .windows(2)
            .all(|w| w[0].weight.abs() >= w[1].weight.abs()));
    }
    assert_eq!(union, all, "{d}");
    // the build refuses the scene; the diagnosis is what explains it
    match scene.build(None) {
        Err(ModelError::OverConstrained { .. }) => {}
        other => panic!("expected an over-constrained build, got {other:?}"),
    }
    let text = d.to_string();
    assert!(
        text.contains("3 over-constraint(s), 0 under-constraint(s)"),
        "{text}"
    );
    assert!(text.contains("over-constraint 3: loop ground – "), "{text}");
}

#[test]
fn the_same_four_bar_as_a_planar_scene_is_exactly_constrained() {
    // planar Grübler: 3 (4 − 1) − 2 · 4 = 1, no over-constraint
    let text = r#"(
        dimension: Planar,
        materials: { "steel": (e: 2.1e11, rho: 7800.0) },
        sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.2, 1.0]), (id: "B2", position_of: Some("B")),
                 (id: "C", at: [1.7, 1.5]), (id: "C2", position_of: Some("C")), (id: "D", at: [2.0, 0.0]) ],
        elements: [
            (id: "crank", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar"))),
            (id: "coupler", type: Beam((nodes: ("B2", "C"), material: "steel", section: "bar"))),
            (id: "rocker", type: Beam((nodes: ("C2", "D"), material: "steel", section: "bar"))),
            (id: "hB", type: Hinge(nodes: ("B", "B2"))),
            (id: "hC", type: Hinge(nodes: ("C", "C2"))),
        ],
        fixed: [ Coord("A", Position), Coord("D", Position) ],
        rigid: [ Def("crank", "*"), Def("coupler", "*"), Def("rocker", "*") ],
    )"#;
    let scene = Scene::from_ron_str(text).unwrap();
    let d = scene.diagnose_constraints(None).unwrap();
    assert!(d.is_exact(), "{d}");
    assert_eq!(d.mobility, 1);
    assert_eq!(scene.build(None).unwrap().n_dof(), 1);
    assert!(d.to_string().contains("no over- or under-constraints"));
}

#[test]
fn two_separate_four_bars_give_two_separate_loops() {
    let scene = scene_of(&[four_bar("L", 0.0), four_bar("R", 5.0)], &[]);
    let d = scene.diagnose_constraints(None).unwrap();
    assert_eq!(d.over.len(), 6, "{d}");
    assert_eq!(d.mobility, 2);
    let side = |t: &str| {
        let n = |s: &str| format!("{t}{s}");
        let all: BTreeSet<String> = ["crank", "coupler", "rocker", "hA", "hB", "hC", "hD"]
            .iter()
            .map(|s| n(s))
            .chain(["ground".to_string()])
            .collect();
        let core: BTreeSet<String> = ["crank", "coupler", "rocker"]
            .iter()
            .map(|s| n(s))
            .chain(["ground".to_string()])
            .collect();
        (all, core)
    };
    let (l, r) = (side("L"), side("R"));
    assert_two_sides(&d, [(&l.0, &l.1), (&r.0, &r.1)]);
}

#[test]
fn two_loops_that_share_a_link_come_out_separately() {
    // two parallelograms side by side sharing the vertical V2 and its
    // ground pivot: ground pivots G1, G2, G3 at x = 0, 1, 2; verticals V1,
    // V2, V3 to height 1; horizontals H1 (V1–V2) and H2 (V2–V3). Spatial
    // Grübler: 6 bodies with the ground, 7 revolute joints:
    // 6 · 5 − 5 · 7 = −5; planar 3 · 5 − 2 · 7 = 1; so 6 over-constraints,
    // 3 per loop.
    let text = format!(
        r#"({HEAD}
        nodes: [
            (id: "G1", at: [0.0, 0.0, 0.0]), (id: "P1", position_of: Some("G1")),
            (id: "G2", at: [1.0, 0.0, 0.0]), (id: "P2", position_of: Some("G2")),
            (id: "G3", at: [2.0, 0.0, 0.0]), (id: "P3", position_of: Some("G3")),
            (id: "T1", at: [0.0, 1.0, 0.0]), (id: "T1h", position_of: Some("T1")),
            (id: "T2", at: [1.0, 1.0, 0.0]), (id: "T2a", position_of: Some("T2")), (id: "T2b", position_of: Some("T2")),
            (id: "T3", at: [2.0, 1.0, 0.0]), (id: "T3h", position_of: Some("T3")),
        ],
        elements: [
            {} {} {} {} {}
            {} {} {} {} {} {} {}
        ],
        fixed: [Node("G1"), Node("G2"), Node("G3")],
        rigid: [{}],
    )"#,
        beam("V1", "P1", "T1"),
        beam("V2", "P2", "T2"),
        beam("V3", "P3", "T3"),
        beam("H1", "T1h", "T2a"),
        beam("H2", "T2b", "T3h"),
        hinge("g1", "G1", "P1"),
        hinge("g2", "G2", "P2"),
        hinge("g3", "G3", "P3"),
        hinge("t1", "T1", "T1h"),
        hinge("t2a", "T2", "T2a"),
        hinge("t2b", "T2", "T2b"),
        hinge("t3", "T3", "T3h"),
        rigid(
            &["V1", "V2", "V3", "H1", "H2"],
            &["g1", "g2", "g3", "t1", "t2a", "t2b", "t3"],
            &[]
        ),
    );
    let scene = Scene::from_ron_str(&text).unwrap();
    let d = scene.diagnose_constraints(None).unwrap();
    assert_eq!(d.over.len(), 6, "{d}");
    assert_eq!(d.mobility, 1, "{d}");
    let left = set(&["ground", "g1", "V1", "t1", "H1", "t2a", "V2", "g2"]);
    let right = set(&["ground", "g2", "V2", "t2b", "H2", "t3", "V3", "g3"]);
    // the links are in every self-stress of their cell; joints carry
    // moments only and may be passed by
    let left_core = set(&["ground", "V1", "H1", "V2"]);
    let right_core = set(&["ground", "V2", "H2", "V3"]);
    assert_two_sides(&d, [(&left, &left_core), (&right, &right_core)]);
}

#[test]
fn releasing_the_couplers_out_of_plane_deformations_makes_the_four_bar_exact() {
    // the three out-of-plane self-stresses (force along z, moments about x
    // and y) all pass through the coupler: freeing its torsion and its two
    // bending deformations about the in-plane axis (local z, since local y
    // is `up` = global z) removes them, as the thesis's torsion and notch
    // releases do (§4.1.3). The mobility stays 1: the released equations
    // were the redundant ones.
    let released = [
        ("coupler", "torsion"),
        ("coupler", "bending_z_p"),
        ("coupler", "bending_z_q"),
    ];
    let scene = scene_of(&[four_bar("", 0.0)], &released);
    let d = scene.diagnose_constraints(None).unwrap();
    assert!(d.is_exact(), "{d}");
    assert_eq!(d.mobility, 1);
    assert!(
        d.to_string().contains("no over- or under-constraints"),
        "{d}"
    );
    // the builder, by its own SVD, agrees: it builds, with the one DOF of
    // the four-bar (the released deformations follow from the motion)
    assert_eq!(scene.build(None).unwrap().n_dof(), 1);
    // releasing in-plane bending instead leaves the out-of-plane loop
    // over-constrained (and adds an in-plane mobility per release)
    let wrong = [
        ("coupler", "torsion"),
        ("coupler", "bending_y_p"),
        ("coupler", "bending_y_q"),
    ];
    let d = scene_of(&[four_bar("", 0.0)], &wrong)
        .diagnose_constraints(None)
        .unwrap();
    // torsion is one of the three: two remain
    assert_eq!(d.over.len(), 2, "{d}");
    assert_eq!(d.mobility, 3, "{d}");
}

#[test]
fn an_undetermined_coordinate_is_named() {
    // a planar double pendulum of two rigid trusses, A fixed, B = (1, 0),
    // C = (2, 0), with only B.y as a degree of freedom: the swing of the
    // second link about B (C.y to first order) is determined by nothing
    let text = r#"(
        dimension: Planar,
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [2.0, 0.0]) ],
        elements: [
            (id: "ab", type: Truss(nodes: ("A", "B"), ea: 1.0e6)),
            (id: "bc", type: Truss(nodes: ("B", "C"), ea: 1.0e6)),
        ],
        fixed: [ Node("A") ],
        rigid: [ Def("ab", "elongation"), Def("bc", "elongation") ],
        dofs: Explicit([ Coord("B", Y) ]),
    )"#;
    let scene = Scene::from_ron_str(text).unwrap();
    let d = scene.diagnose_constraints(None).unwrap();
    assert!(d.over.is_empty(), "{d}");
    assert!(d.under_checked);
    assert_eq!(d.mobility, 2);
    assert_eq!(d.under.len(), 1, "{d}");
    let c = &d.under[0].coordinates;
    assert_eq!(c.len(), 1, "{d}");
    assert_eq!(c[0].name, "C.y");
    assert!((c[0].weight - 1.0).abs() < 1e-12);
    assert!(matches!(
        scene.build(None),
        Err(ModelError::UnderConstrained { .. })
    ));
    let text = d.to_string();
    assert!(
        text.contains("under-constraint 1: a motion of 1 coordinates"),
        "{text}"
    );
    // with both swings as DOFs it is exact
    let both = text_with_dofs(r#"Coord("B", Y), Coord("C", Y)"#);
    let d = Scene::from_ron_str(&both)
        .unwrap()
        .diagnose_constraints(None)
        .unwrap();
    assert!(d.is_exact(), "{d}");
}

fn text_with_dofs(dofs: &str) -> String {
    format!(
        r#"(
        dimension: Planar,
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [2.0, 0.0]) ],
        elements: [
            (id: "ab", type: Truss(nodes: ("A", "B"), ea: 1.0e6)),
            (id: "bc", type: Truss(nodes: ("B", "C"), ea: 1.0e6)),
        ],
        fixed: [ Node("A") ],
        rigid: [ Def("ab", "elongation"), Def("bc", "elongation") ],
        dofs: Explicit([ {dofs} ]),
    )"#
    )
}

#[test]
fn every_fixture_scene_that_builds_is_exactly_constrained() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenes");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let scene = Scene::load(&path).unwrap();
        let Ok(mech) = scene.build(path.parent()) else {
            continue;
        };
        let d = scene.diagnose_constraints(path.parent()).unwrap();
        assert!(d.is_exact(), "{}: {d}", path.display());
        // the builder's own SVD-based choice took as many DOFs as the
        // diagnosis finds motions (automatic choice) or the scene lists
        if !d.under_checked {
            assert_eq!(d.mobility, mech.n_dof(), "{}", path.display());
        }
        checked += 1;
    }
    assert!(checked >= 8, "only {checked} fixture scenes checked");
}

/// A straight spatial chain of `n` beams along x, clamped at both ends, with
/// the deformations `rigid` (a RON list) rigid.
fn clamped_chain(n: usize, rigid: &str) -> Scene {
    let text = format!(
        r#"({HEAD}
        nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [{l}, 0.0, 0.0]) ],
        elements: [ (id: "chain", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", up: Some([0.0, 0.0, 1.0]), n: {n}))) ],
        fixed: [ Node("A"), Node("B") ],
        rigid: [ {rigid} ],
    )"#,
        l = 0.01 * n as f64
    );
    Scene::from_ron_str(&text).unwrap()
}

#[test]
fn a_long_clamped_chain_with_rigid_elongation_has_one_axial_over_constraint() {
    // 500 beams: 3507 nodal coordinates. Clamped at both ends with every
    // elongation rigid, the chain's length is fixed twice: one
    // over-constraint, an axial self-stress through the whole chain and the
    // ground. The normalizations peel away; the elongations stay in the loop.
    let d = clamped_chain(500, r#"Def("chain", "elongation")"#)
        .diagnose_constraints(None)
        .unwrap();
    assert_eq!(d.n_coordinates, 501 * 7);
    assert_eq!(d.over.len(), 1, "{d}");
    let o = &d.over[0];
    assert_eq!(o.loop_elements, vec!["ground", "chain"]);
    assert_eq!(o.dominant.0, "beam elongation");
    // every elongation takes part with the same weight
    let elong: Vec<f64> = o
        .equations
        .iter()
        .filter(|w| w.name.ends_with(".elongation"))
        .map(|w| w.weight)
        .collect();
    assert_eq!(elong.len(), 500);
    assert!(elong
        .iter()
        .all(|w| (w.abs() - elong[0].abs()).abs() < 1e-9));
    match &o.direction {
        Direction::Spatial { force: Some(f), .. } => {
            assert!((f[0].abs() - 1.0).abs() < 1e-9, "{f:?}")
        }
        other => panic!("{other}"),
    }
    assert!(d.largest_block < 600, "{d}");
    // flexible (no rigid deformation): exact, everything peels
    let d = clamped_chain(500, "").diagnose_constraints(None).unwrap();
    assert!(d.is_exact(), "{d}");
    assert_eq!(d.core_equations, 0);
    assert_eq!(d.mobility, 499 * 6);
}

#[test]
fn a_clamped_rigid_chain_is_six_times_over_constrained() {
    // every deformation rigid: the clamped-clamped chain is one rigid body
    // held by two clamps, 6 over-constraints
    let d = clamped_chain(20, r#"Def("chain", "*")"#)
        .diagnose_constraints(None)
        .unwrap();
    assert_eq!(d.over.len(), 6, "{d}");
    assert_eq!(d.mobility, 0);
    for o in &d.over {
        assert_eq!(o.loop_elements, vec!["ground", "chain"]);
    }
}

#[test]
fn errors_of_the_scene_are_reported_as_by_the_build() {
    let text = r#"(
        dimension: Planar,
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [ (id: "ab", type: Truss(nodes: ("A", "B"), ea: 1.0e6)) ],
        fixed: [ Node("Q") ],
    )"#;
    let scene = Scene::from_ron_str(text).unwrap();
    let e = scene.diagnose_constraints(None).unwrap_err();
    assert!(e.to_string().contains("unknown node 'Q'"), "{e}");
    assert_eq!(e.to_string(), scene.build(None).unwrap_err().to_string());
}
