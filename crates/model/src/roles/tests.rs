//! The choice of DOFs by every method compared on the fixtures, the test
//! scenes and random mechanisms: the same DOFs, roles and diagnostics.

use super::*;
use std::path::{Path, PathBuf};

/// Builds with the given method: the DOF names and the roles, or the error.
fn build_with(scene: &Scene, dir: Option<&Path>, m: Method) -> Result<String, String> {
    METHOD.with(|c| c.set(m));
    let r = scene.build(dir);
    METHOD.with(|c| c.set(Method::Auto));
    r.map(|mech| {
        let names: Vec<&str> = mech.dofs.iter().map(|c| mech.coordinate_name(*c)).collect();
        format!(
            "dofs {names:?}\nx roles {:?}\ne roles {:?}\ndependent {:?}\nrows {:?}",
            mech.x_roles, mech.e_roles, mech.dependent, mech.constraint_rows
        )
    })
    .map_err(|e| e.to_string())
}

fn same(scene: &Scene, dir: Option<&Path>, what: &str) -> bool {
    let d = build_with(scene, dir, Method::Dense);
    let s = build_with(scene, dir, Method::Sparse);
    assert_eq!(d, s, "{what}: the sparse choice differs from the dense one");
    let b = build_with(scene, dir, Method::Blocks);
    assert_eq!(
        d, b,
        "{what}: the blocks' choice differs from the dense one"
    );
    d.is_ok()
}

fn fallbacks() -> usize {
    BLOCK_FALLBACKS.with(|c| c.get())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn sparse_choice_equals_dense_on_every_fixture() {
    let dir = root().join("fixtures/scenes");
    let mut n = 0;
    for f in std::fs::read_dir(&dir).unwrap() {
        let path = f.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let scene = Scene::load(&path).unwrap();
            assert!(same(&scene, Some(&dir), &path.display().to_string()));
            n += 1;
        }
    }
    assert!(n >= 9, "{n} fixtures");
    // the over-constrained chapter-4 skeleton: every method refuses it alike
    let refused = dir.join("refused/two_dof_skeleton_no_releases.ron");
    let scene = Scene::load(&refused).unwrap();
    assert!(!same(&scene, Some(&dir), &refused.display().to_string()));
}

/// Every literal scene in the tests and doc examples of the workspace
/// (raw strings that parse as a scene; those built with `format!` are skipped).
#[test]
fn sparse_choice_equals_dense_on_the_literal_test_scenes() {
    let files = [
        "crates/model/tests/bad_input.rs",
        "crates/model/src/lib.rs",
        "crates/kinematics/tests/transfer_functions.rs",
        "crates/kinematics/src/lib.rs",
        "crates/linearize/tests/analytic.rs",
        "crates/linearize/src/lib.rs",
        "crates/dynamics/src/eom.rs",
        "crates/dynamics/src/nodal_eom.rs",
        "crates/dynamics/src/lib.rs",
    ];
    let (mut parsed, mut built) = (0, 0);
    for f in files {
        let Ok(text) = std::fs::read_to_string(root().join(f)) else {
            continue;
        };
        // doc examples: without their comment markers
        let text: String = text
            .lines()
            .map(|l| {
                let t = l.trim_start();
                t.strip_prefix("//! ")
                    .or_else(|| t.strip_prefix("/// "))
                    .unwrap_or(l)
            })
            .collect::<Vec<_>>()
            .join("\n");
        let mut rest = text.as_str();
        while let Some(a) = rest.find("r#\"(") {
            let body = &rest[a + 3..];
            let Some(b) = body.find("\"#") else { break };
            let lit = &body[..b];
            // a format! template without arguments in the scene itself
            let unescaped = lit.replace("{{", "{").replace("}}", "}");
            if let Ok(scene) = Scene::from_ron_str(lit).or_else(|_| Scene::from_ron_str(&unescaped))
            {
                parsed += 1;
                if same(&scene, None, f) {
                    built += 1;
                }
            }
            rest = &body[b..];
        }
    }
    assert!(parsed >= 8 && built >= 8, "{parsed} scenes, {built} valid");
}

/// A small random mechanism: beams (some split), trusses and hinges between
/// random nodes, a fixed node, random rigid deformations, either DOF choice.
fn random_scene(seed: u64) -> String {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move |n: u64| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 33) % n
    };
    let spatial = next(2) == 1;
    let nn = 3 + next(4) as usize;
    let mut nodes = String::new();
    let mut used = vec![];
    for k in 0..nn {
        let mut p;
        loop {
            p = if spatial {
                vec![next(4), next(4), next(3)]
            } else {
                vec![next(4), next(4)]
            };
            if !used.contains(&p) {
                break;
            }
        }
        used.push(p.clone());
        let at: Vec<String> = p.iter().map(|v| format!("{}.0", v)).collect();
        nodes += &format!("(id: \"N{k}\", at: [{}]), ", at.join(", "));
    }
    let mut elements = String::new();
    let mut rigid = vec![];
    let ne = 2 + next(6) as usize;
    for k in 0..ne {
        let a = next(nn as u64) as usize;
        let mut b = next(nn as u64) as usize;
        if b == a {
            b = (a + 1) % nn;
        }
        let kind = next(6);
        let id = format!("e{k}");
        match kind {
            0..=2 => {
                let n = 1 + next(3);
                elements += &format!("(id: \"{id}\", type: Beam((nodes: (\"N{a}\", \"N{b}\"), material: \"m\", section: \"s\", n: {n}))), ");
                match next(4) {
                    0 => rigid.push(format!("Def(\"{id}\", \"elongation\")")),
                    1 => rigid.push(format!("Def(\"{id}\", \"*\")")),
                    _ => {}
                }
            }
            3 | 4 => {
                let n = 1 + next(2);
                elements += &format!("(id: \"{id}\", type: Truss(nodes: (\"N{a}\", \"N{b}\"), ea: 1.0e6, mass_per_length: 1.0, n: {n})), ");
                if next(2) == 0 {
                    rigid.push(format!("Def(\"{id}\", \"*\")"));
                }
            }
            _ => {
                let axis = if spatial {
                    ", axis: Some([0.0, 0.0, 1.0])"
                } else {
                    ""
                };
                elements +=
                    &format!("(id: \"{id}\", type: Hinge(nodes: (\"N{a}\", \"N{b}\"){axis})), ");
                if next(2) == 0 {
                    rigid.push(format!("Def(\"{id}\", \"*\")"));
                }
            }
        }
    }
    let f = next(nn as u64);
    let mut fixed = format!("Node(\"N{f}\")");
    if next(3) == 0 {
        fixed += &format!(", Coord(\"N{}\", Position)", (f + 1) % nn as u64);
    }
    let dofs = if next(3) == 0 {
        "NodalCoordinates"
    } else {
        "Deformations"
    };
    format!(
            "(dimension: {}, materials: {{ \"m\": (e: 2.0e11, rho: 7800.0) }}, sections: {{ \"s\": Rectangle(by: 0.02, bz: 0.01) }}, nodes: [{nodes}], elements: [{elements}], fixed: [{fixed}], rigid: [{}], dofs: {dofs})",
            if spatial { "Spatial" } else { "Planar" },
            rigid.join(", ")
        )
}

#[test]
fn sparse_choice_equals_dense_on_random_mechanisms() {
    let (mut ok, mut err) = (0, 0);
    for seed in 0..400 {
        let text = random_scene(seed);
        let scene = Scene::from_ron_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        if same(&scene, None, &text) {
            ok += 1;
        } else {
            err += 1;
        }
    }
    assert!(ok >= 80 && err >= 40, "{ok} valid, {err} rejected");
}

/// The over- and under-constrained cases of tests/bad_input.rs, and a
/// zero equation: the sparse method names the same culprits.
#[test]
fn sparse_diagnostics_name_the_same_culprits() {
    let base = r#"(
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
    let cases = [
            ("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\"), Coord(\"C\", Position) ],\n    dofs: Explicit([Def(\"ab\", \"bending_p\"), Def(\"ab\", \"bending_q\"), Def(\"bc\", \"bending_p\"), Def(\"bc\", \"bending_q\"), Coord(\"B\", X)]),", "redundant"),
            ("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\") ],\n    dofs: Explicit([Def(\"ab\", \"bending_p\")]),", "C.x"),
            ("rigid: [ Def(\"ab\", \"elongation\"), Def(\"bc\", \"elongation\") ],", "rigid: [ Def(\"ab\", \"*\"), Def(\"bc\", \"*\") ],\n    dofs: Explicit([Def(\"ab\", \"elongation\")]),", "ab.elongation"),
            ("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\"), Node(\"B\") ],", "ab.elongation"),
        ];
    for (from, to, named) in cases {
        let scene = Scene::from_ron_str(&base.replacen(from, to, 1)).unwrap();
        assert!(!same(&scene, None, to), "{to}");
        let e = build_with(&scene, None, Method::Sparse).unwrap_err();
        assert!(e.contains(named), "{e}");
    }
}

/// Chains without supports (the tumbling beam, spatial and planar, with
/// either choice of DOFs): the same choice as the dense SVD, decided by
/// the local bounds alone (no fallback to the blocks, which grow with
/// the cube of n), except where a DOF candidate is determined only
/// through the whole chain (nodal coordinates as DOFs with rigid
/// elongations: the end node's x follows from all the elongations).
#[test]
fn free_chains_are_chosen_locally_as_the_dense_svd_chooses() {
    let tumbling =
        std::fs::read_to_string(root().join("fixtures/scenes/tumbling_beam.ron")).unwrap();
    let planar = r#"(
    dimension: Planar,
    materials: { "al": (e: 7.0e10, rho: 2700.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.5]) ],
    elements: [ (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar", n: 2))) ],
    rigid: [ Def("arm", "elongation") ],
)"#;
    let rigid = "rigid: [ Def(\"beam\", \"elongation\"), Def(\"beam\", \"torsion\") ],";
    let nodal = |t: &str| t.replace(")),\n    ],", ")),\n    ],\n    dofs: NodalCoordinates,");
    let mut cases = vec![];
    for n in [3, 12, 45] {
        let t = tumbling.replace("n: 2)", &format!("n: {n})"));
        cases.push((t.clone(), true));
        cases.push((t.replace(rigid, ""), true));
        cases.push((nodal(&t.replace(rigid, "")), true));
        cases.push((nodal(&t), n < 20));
        let pl = planar.replace("n: 2)", &format!("n: {n})"));
        cases.push((pl.clone(), true));
        cases.push((
            pl.replace(
                "rigid: [ Def(\"arm\", \"elongation\") ],",
                "dofs: NodalCoordinates,",
            ),
            true,
        ));
    }
    for (text, local) in &cases {
        let scene = Scene::from_ron_str(text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let before = fallbacks();
        assert!(same(&scene, None, text), "{text}");
        assert_eq!(fallbacks() == before, *local, "local bounds:\n{text}");
    }
    assert_eq!(
        cases
            .iter()
            .filter(|c| c.0.contains("NodalCoordinates"))
            .count(),
        9
    );
}
