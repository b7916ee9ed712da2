//! Issue 14 item 2 through the command line: `flexmb build-superelement`
//! refuses K and M files that do not belong together with exit code 2 (an
//! input error; build errors used to give 1) and names the file at fault.
//! The files are Matrix Market exports of a small built-in hex20 bar.

mod common;

use flexmb_element::Material;
use flexmb_superelement::parts;
use flexmb_superelement::readers::{write_matrix_market, write_nodes};
use std::path::{Path, PathBuf};
use std::process::Command;

const L: f64 = 0.05;
const BY: f64 = 0.01;
const BZ: f64 = 0.006;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("sefiles", name)
}

/// Writes K, M (Matrix Market) and the node file of a steel bar with `n`
/// elements along x, y, z as `{tag}_k.mtx`, `{tag}_m.mtx`, `{tag}_nodes.txt`.
fn export_bar(dir: &Path, tag: &str, n: [usize; 3]) {
    let steel = Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    };
    let model = parts::prismatic_bar(L, BY, BZ, n, steel)
        .unwrap()
        .mesh
        .assemble(tag)
        .unwrap();
    write_matrix_market(&dir.join(format!("{tag}_k.mtx")), model.k()).unwrap();
    write_matrix_market(&dir.join(format!("{tag}_m.mtx")), model.m()).unwrap();
    write_nodes(
        &dir.join(format!("{tag}_nodes.txt")),
        model.node_ids(),
        model.coords(),
    )
    .unwrap();
}

/// Writes a spec `name.spec.ron` building from the Matrix Market files `k`,
/// `m`, `nodes`, with `extra` fields of `MatrixMarket(..)` (volume, density).
fn spec(dir: &Path, name: &str, k: &str, m: &str, nodes: &str, extra: &str) -> String {
    let plane = |x: f64| {
        format!("NearPlane(point: ({x:?}, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-9)")
    };
    let text = format!(
        "(\n    name: \"{name}\",\n    model: MatrixMarket(k: \"{k}\", m: \"{m}\", nodes: \"{nodes}\"{extra}),\n    \
         settings: (\n        p: (0.0, 0.0, 0.0),\n        q: ({L:?}, 0.0, 0.0),\n        \
         interface_p: {},\n        interface_q: {},\n        normal_modes: 2,\n    ),\n    \
         output: \"{name}.se.ron\",\n)\n",
        plane(0.0),
        plane(L)
    );
    let p = dir.join(format!("{name}.spec.ron"));
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// Runs `flexmb build-superelement SPEC`, requires exit code `code` and
/// every one of `words` in stderr; returns stderr.
fn build(spec: &str, code: i32, words: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(["build-superelement", spec])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(
        o.status.code(),
        Some(code),
        "flexmb build-superelement {spec}: {}\n{err}",
        String::from_utf8_lossy(&o.stdout)
    );
    for w in words {
        assert!(err.contains(w), "stderr should mention '{w}': {err}");
    }
    println!("{err}");
    err
}

#[test]
fn mismatched_superelement_files_are_input_errors_naming_the_file() {
    let dir = temp_dir("mm");
    export_bar(&dir, "bar", [4, 2, 1]);
    export_bar(&dir, "fine", [8, 2, 1]);
    let volume = format!(", volume: Some({:?})", L * BY * BZ);
    // the consistent files build (exit 0), with the density check too
    let ok = spec(
        &dir,
        "ok",
        "bar_k.mtx",
        "bar_m.mtx",
        "bar_nodes.txt",
        &format!("{volume}, density: Some(7800.0)"),
    );
    build(&ok, 0, &[]);
    assert!(dir.join("ok.se.ron").exists());
    // swapped: was "units look wrong" with exit code 1
    let swapped = spec(
        &dir,
        "swapped",
        "bar_m.mtx",
        "bar_k.mtx",
        "bar_nodes.txt",
        &volume,
    );
    let err = build(
        &swapped,
        2,
        &["K and M look swapped", "bar_m.mtx", "bar_k.mtx"],
    );
    assert!(!err.contains("units"), "{err}");
    // a truncated K: was a parse error with exit code 1
    let k = std::fs::read_to_string(dir.join("bar_k.mtx")).unwrap();
    let n = k.lines().count();
    let cut: String = k.lines().take(n - 3).map(|l| format!("{l}\n")).collect();
    std::fs::write(dir.join("cut_k.mtx"), cut).unwrap();
    let truncated = spec(
        &dir,
        "truncated",
        "cut_k.mtx",
        "bar_m.mtx",
        "bar_nodes.txt",
        "",
    );
    build(
        &truncated,
        2,
        &[&format!("cut_k.mtx:{}: truncated or incomplete", n - 3)],
    );
    // M of a finer mesh of the same bar
    let other = spec(
        &dir,
        "other",
        "bar_k.mtx",
        "fine_m.mtx",
        "bar_nodes.txt",
        "",
    );
    build(&other, 2, &["fine_m.mtx", "is from another model"]);
    // steel matrices with the density of aluminium
    let light = spec(
        &dir,
        "light",
        "bar_k.mtx",
        "bar_m.mtx",
        "bar_nodes.txt",
        &format!("{volume}, density: Some(2700.0)"),
    );
    build(&light, 2, &["bar_m.mtx", "rigid-body mass", "density 2700"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The worked example of docs/superelement.md: the rotor exported by Abaqus
/// and by ANSYS (`fixtures/fe-exports/`) built by `flexmb build-superelement`
/// from the two specs there, giving the same superelement and a readable
/// report.
#[test]
fn the_abaqus_and_ansys_rotor_specs_build_the_same_superelement() {
    let fx = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fe-exports");
    let mut built = vec![];
    for name in ["rotor_abaqus", "rotor_ansys"] {
        let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
            .arg("build-superelement")
            .arg(fx.join(format!("{name}.spec.ron")))
            .output()
            .unwrap();
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "{name}: {}\n{out}",
            String::from_utf8_lossy(&o.stderr)
        );
        for part in [
            "l0 = 0.500000 m",
            "345 equations",
            "fixed-interface normal modes:",
            "clamped at p, free at q:",
        ] {
            assert!(out.contains(part), "{name}: no '{part}' in\n{out}");
        }
        assert!(!out.contains("BuildReport {"), "a struct dump:\n{out}");
        let file = fx.join(format!("../../target/fe-exports/{name}.se.ron"));
        built.push(flexmb_superelement::spec::read_ron(&file).unwrap());
    }
    let (a, b) = (&built[0], &built[1]);
    let max = a.s_bar.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..6 {
        for j in 0..6 {
            let d = (a.s_bar[i][j] - b.s_bar[i][j]).abs() / max;
            assert!(
                d < 1e-6,
                "S̄[{i}][{j}]: {} against {}",
                a.s_bar[i][j],
                b.s_bar[i][j]
            );
        }
    }
}
