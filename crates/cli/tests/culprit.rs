//! Errors that name the culprit, through the command line (issue 14.5):
//! `info` checks the outputs, and the failures of `static` and `eig` name
//! the coordinates and nodes involved.

mod common;

use std::path::PathBuf;
use std::process::Command;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("culprit", name)
}

/// Writes a planar scene: a clamped beam A–B, a truss B–S along x and a
/// point mass at S, with `extra` scene fields.
fn scene(name: &str, extra: &str) -> String {
    let p = temp_dir(name).join("scene.ron");
    std::fs::write(
        &p,
        format!(
            r#"(
    dimension: Planar,
    materials: {{ "al": (e: 7.0e10, rho: 2700.0) }},
    sections: {{ "bar": Rectangle(by: 0.01, bz: 0.02) }},
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.5, 0.0]), (id: "S", at: [1.0, 0.0]) ],
    elements: [
        (id: "ab", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))),
        (id: "bs", type: Truss(nodes: ("B", "S"), ea: 1.0e6)),
        (id: "m", type: PointMass(node: "S", mass: 1.0)),
    ],
    fixed: [ Node("A") ],
{extra})
"#
        ),
    )
    .unwrap();
    p.display().to_string()
}

/// Runs flexmb, requires exit code `code` and returns stderr.
fn stderr_of(args: &[&str], code: i32) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(
        o.status.code(),
        Some(code),
        "flexmb {args:?}: {}\n{err}",
        String::from_utf8_lossy(&o.stdout)
    );
    err
}

#[test]
fn info_refuses_outputs_naming_what_the_scene_lacks() {
    let ok = scene(
        "info-ok",
        r#"    outputs: [ Position("S"), Deformation("ab", "*") ],"#,
    );
    stderr_of(&["info", &ok], 0);
    for (outputs, culprit) in [
        (r#"Position("SS")"#, "unknown node 'SS'"),
        (r#"Rotation("S")"#, "node 'S' has no rotation"),
        (r#"Deformation("bd", "*")"#, "unknown element 'bd'"),
        (r#"Stress("bs", "torsion")"#, "no deformation 'torsion'"),
    ] {
        let p = scene("info-bad", &format!("    outputs: [ {outputs} ],"));
        let err = stderr_of(&["info", &p], 2);
        assert!(
            err.contains(&format!("output {outputs}")) && err.contains(culprit),
            "{outputs}: {err}"
        );
    }
}

#[test]
fn static_names_the_unrestrained_coordinate_and_eig_the_one_without_inertia() {
    // nothing resists S moving in y
    let p = scene("static", "    gravity: Some([0.0, -9.81]),");
    let out = temp_dir("static-out").display().to_string();
    let err = stderr_of(&["static", &p, "--out", &out], 1);
    assert!(
        err.contains("singular static tangent") && err.contains("S.y (node S)"),
        "{err}"
    );
    // B turns without inertia: the beam is massless and the truss has none
    let p = scene(
        "eig",
        r#"    rigid: [ Def("bs", "elongation") ],
    dofs_first: [ Coord("B", Angle) ],"#,
    );
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replace("rho: 2700.0", "rho: 0.0")).unwrap();
    let err = stderr_of(&["eig", &p], 1);
    assert!(
        err.contains("no inertia") && err.contains("B.angle (node B)"),
        "{err}"
    );
}
