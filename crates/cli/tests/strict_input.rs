//! Typos and unphysical data through the command line (issues 14.1 and 13.8):
//! each is refused with the culprit named, and a result that is not finite is
//! an error (exit code 1), never NaN printed with exit code 0.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("strict", name)
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(args)
        .output()
        .unwrap()
}

/// Runs flexmb, requires `code` and returns (stdout, stderr).
fn run_code(args: &[&str], code: i32) -> (String, String) {
    let o = run(args);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    );
    assert_eq!(o.status.code(), Some(code), "flexmb {args:?}: {out}\n{err}");
    (out, err)
}

/// A pinned planar arm of 4 beams; `material` replaces its material entry.
fn arm(dir: &Path, name: &str, material: &str, extra: &str) -> String {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            r#"(
    dimension: Planar,
    materials: {{ "al": {material} }},
    sections: {{ "bar": Rectangle(by: 0.01, bz: 0.02) }},
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
    elements: [ (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar", n: 4))) ],
    fixed: [ Node("A") ],
{extra})
"#
        ),
    )
    .unwrap();
    p.display().to_string()
}

/// Issue 13.8: E = 1e-308 used to print NaN for every eigenfrequency with
/// exit code 0. Now exit code 1, the mode named, no NaN on stdout.
#[test]
fn eig_with_a_non_finite_result_fails_naming_the_mode() {
    let dir = temp_dir("eig");
    let scene = arm(&dir, "tiny_e.ron", "(e: 1.0e-308, rho: 2700.0)", "");
    let (out, err) = run_code(&["eig", &scene], 1);
    assert!(
        err.contains("eigenfrequency of mode 1 is NaN") && err.contains("not a finite number"),
        "{err}"
    );
    assert!(!out.contains("NaN"), "{out}");
    // the same arm with a real modulus still works
    let scene = arm(&dir, "al.ron", "(e: 7.0e10, rho: 2700.0)", "");
    let (out, _) = run_code(&["eig", &scene, "--modes", "3"], 0);
    assert!(out.contains("undamped eigenfrequencies"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 13.8: ν = 2 used to be accepted; it is invalid input (exit code 2)
/// naming the material and the field.
#[test]
fn poisson_ratio_out_of_range_is_refused() {
    let dir = temp_dir("nu");
    let scene = arm(&dir, "nu2.ron", "(e: 7.0e10, nu: 2.0, rho: 2700.0)", "");
    let (_, err) = run_code(&["info", &scene], 2);
    assert!(
        err.contains("material 'al'") && err.contains("nu (Poisson's ratio) = 2"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 14.1: `gravityy` used to drop gravity silently; a repeated material
/// id kept the last one.
#[test]
fn scene_typos_and_repeated_ids_are_refused_with_line_and_column() {
    let dir = temp_dir("scene");
    let scene = arm(
        &dir,
        "gravityy.ron",
        "(e: 7.0e10, rho: 2700.0)",
        "    gravityy: Some([0.0, -9.81]),\n",
    );
    let (_, err) = run_code(&["info", &scene], 2);
    assert!(
        err.contains("line 8, column 5")
            && err.contains("`gravityy`")
            && err.contains("did you mean `gravity`?"),
        "{err}"
    );
    let scene = arm(
        &dir,
        "twice.ron",
        "(e: 7.0e10, rho: 2700.0), \"al\": (e: 7.0e7, rho: 2700.0)",
        "",
    );
    let (_, err) = run_code(&["info", &scene], 2);
    assert!(err.contains("duplicate material id 'al'"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 14.1: `normal_mode: 6` in a superelement spec used to build 0
/// normal modes. It is refused before any file is read.
#[test]
fn superelement_spec_typos_are_refused() {
    let dir = temp_dir("spec");
    let spec = dir.join("spec.ron");
    std::fs::write(
        &spec,
        r#"(
    name: "flexure",
    model: CalculiX(job: "flexure"),
    settings: (
        p: (0.0, 0.0, 0.0),
        q: (0.04, 0.0, 0.0),
        interface_p: NearPlane(point: (0.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-7),
        interface_q: NearPlane(point: (0.04, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-7),
        normal_mode: 6,
    ),
    output: "flexure.se.ron",
)
"#,
    )
    .unwrap();
    let (_, err) = run_code(&["build-superelement", &spec.display().to_string()], 2);
    assert!(
        err.contains("spec.ron:9")
            && err.contains("`normal_mode`")
            && err.contains("did you mean `normal_modes`?"),
        "{err}"
    );
    // an unknown field of a struct variant (a node selection) too
    let text = std::fs::read_to_string(&spec)
        .unwrap()
        .replace("normal_mode: 6", "normal_modes: 6")
        .replacen("tolerance: 1e-7", "tolerence: 1e-7", 1);
    std::fs::write(&spec, text).unwrap();
    let (_, err) = run_code(&["build-superelement", &spec.display().to_string()], 2);
    assert!(err.contains("did you mean `tolerance`?"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 14.1: a saved reduced model with an unknown field is refused when
/// it is loaded, with line, column and the nearest field.
#[test]
fn saved_model_typos_are_refused() {
    let dir = temp_dir("saved");
    let scene = arm(&dir, "al.ron", "(e: 7.0e10, rho: 2700.0)", "");
    let model = dir.join("model.ron");
    std::fs::write(
        &model,
        "(\n    format: 1,\n    description: \"\",\n    scene: \"\",\n    dofs: [],\n    basis: Fixed(q0: [], vector: []),\n)\n",
    )
    .unwrap();
    let m = model.display().to_string();
    let (_, err) = run_code(&["simulate", &scene, "--reduced", &m], 2);
    assert!(
        err.contains("model.ron:6:")
            && err.contains("`vector`")
            && err.contains("did you mean `vectors`?"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
