//! `flexmb info --constraints`: the diagnosis printed for an over-constrained
//! scene (that `flexmb info` refuses), for an exact one, and bad input.

mod common;
use common::{fixture, flexmb, temp_dir};

/// A planar four-bar built spatially with ideal hinges and rigid links:
/// 3 over-constraints by Grübler–Kutzbach (6 · 3 − 5 · 4 = −2 against a
/// mobility of 1), all out of the xy-plane. `released` makes the coupler's
/// torsion and out-of-plane bending free.
fn four_bar(released: bool) -> String {
    let coupler = if released {
        r#"Def("coupler", "elongation"), Def("coupler", "bending_y_p"), Def("coupler", "bending_y_q"),"#
    } else {
        r#"Def("coupler", "*"),"#
    };
    let mut s = String::from(
        r#"(
    name: "spatial four-bar",
    materials: { "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [
        (id: "GA", at: [0.0, 0.0, 0.0]), (id: "A", position_of: Some("GA")),
        (id: "B", at: [0.2, 1.0, 0.0]), (id: "B2", position_of: Some("B")),
        (id: "C", at: [1.7, 1.5, 0.0]), (id: "C2", position_of: Some("C")),
        (id: "GD", at: [2.0, 0.0, 0.0]), (id: "D", position_of: Some("GD")),
    ],
    elements: [
"#,
    );
    for (id, p, q) in [
        ("crank", "A", "B"),
        ("coupler", "B2", "C"),
        ("rocker", "C2", "D"),
    ] {
        s += &format!(
            "        (id: \"{id}\", type: Beam((nodes: (\"{p}\", \"{q}\"), material: \"steel\", section: \"bar\", up: Some([0.0, 0.0, 1.0])))),\n"
        );
    }
    for (id, p, q) in [
        ("hA", "GA", "A"),
        ("hB", "B", "B2"),
        ("hC", "C", "C2"),
        ("hD", "D", "GD"),
    ] {
        s += &format!(
            "        (id: \"{id}\", type: Hinge(nodes: (\"{p}\", \"{q}\"), axis: Some([0.0, 0.0, 1.0]))),\n"
        );
    }
    s += "    ],\n    fixed: [Node(\"GA\"), Node(\"GD\")],\n    rigid: [\n";
    s += &format!("        Def(\"crank\", \"*\"), {coupler} Def(\"rocker\", \"*\"),\n");
    for h in ["hA", "hB", "hC", "hD"] {
        s += &format!("        Def(\"{h}\", \"bending_y\"), Def(\"{h}\", \"bending_z\"),\n");
    }
    s += "    ],\n)\n";
    s
}

#[test]
fn the_over_constrained_four_bar_is_diagnosed_and_its_build_refused() {
    let dir = temp_dir("constraints", "four-bar");
    let p = dir.join("four_bar.ron");
    std::fs::write(&p, four_bar(false)).unwrap();
    let o = flexmb().arg("info").arg(&p).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("over-constrained mechanism"), "{err}");
    assert!(err.contains("flexmb info --constraints"), "{err}");
    let o = flexmb()
        .args(["info", "--constraints"])
        .arg(&p)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("mobility 1"), "{out}");
    assert!(
        out.contains("3 over-constraint(s), 0 under-constraint(s)"),
        "{out}"
    );
    for k in 1..=3 {
        assert!(
            out.contains(&format!("over-constraint {k}: loop ground – ")),
            "{out}"
        );
    }
    assert!(!out.contains("over-constraint 4"), "{out}");
    assert_eq!(
        out.matches("direction: out of plane (loop plane normal [0.000, 0.000, 1.000]")
            .count(),
        3,
        "{out}"
    );
    assert!(
        out.contains("crank.torsion") && out.contains("(fixed)"),
        "{out}"
    );
    // the released coupler: exact, and the build goes through
    std::fs::write(&p, four_bar(true)).unwrap();
    let o = flexmb()
        .args(["info", "--constraints"])
        .arg(&p)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("no over- or under-constraints"), "{out}");
    let o = flexmb().arg("info").arg(&p).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("1 degrees of freedom"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_fixture_is_exactly_constrained() {
    let o = flexmb()
        .args(["info", "--constraints"])
        .arg(fixture("straight_guidance_spatial.ron"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("no over- or under-constraints"), "{out}");
    // the same mobility as the degrees of freedom plain `info` reports
    let info = flexmb()
        .arg("info")
        .arg(fixture("straight_guidance_spatial.ron"))
        .output()
        .unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    let dofs = info
        .split(", ")
        .find_map(|s| s.strip_suffix(" degrees of freedom"))
        .unwrap();
    assert!(out.contains(&format!("mobility {dofs}\n")), "{out}\n{info}");
}

#[test]
fn bad_input_to_the_diagnosis_is_named() {
    let o = flexmb()
        .args(["info", "--constraints", "/no/such/scene.ron"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("cannot read /no/such/scene.ron"), "{err}");
    let dir = temp_dir("constraints", "bad");
    let p = dir.join("bad.ron");
    std::fs::write(
        &p,
        "(\n  nodes: [ (id: \"A\", at: [0.0, 0.0, 0.0]) ],\n  elements: [ oops ],\n)\n",
    )
    .unwrap();
    let o = flexmb()
        .args(["info", "--constraints"])
        .arg(&p)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.ron: line 3"), "{err}");
    // an unknown node in `fixed`: named, as by the build
    std::fs::write(
        &p,
        four_bar(false).replace("Node(\"GD\")]", "Node(\"GX\")]"),
    )
    .unwrap();
    let o = flexmb()
        .args(["info", "--constraints"])
        .arg(&p)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("unknown node 'GX'"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
