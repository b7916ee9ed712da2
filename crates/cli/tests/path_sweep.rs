//! `flexmb sweep --over path --path FILE.csv`: eigenfrequencies along a path
//! of several coordinates (thesis (4.1)).

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-path-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn flexmb(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(args)
        .output()
        .unwrap()
}

/// The eigenfrequency rows (without the sweep parameter) of a sweep's CSV.
/// The f*_hz columns of a sweep's CSV (not the parameter or the `hold:`
/// columns of the forces that hold the path's coordinates).
fn frequencies(dir: &Path) -> Vec<Vec<f64>> {
    let (h, rows) = flexmb_plot::read_csv(&dir.join("eigenfrequencies.csv")).unwrap();
    let cols: Vec<usize> = (0..h.len()).filter(|k| h[*k].ends_with("_hz")).collect();
    rows.into_iter()
        .map(|r| cols.iter().map(|k| r[*k]).collect())
        .collect()
}

#[test]
fn a_one_coordinate_path_equals_the_sweep_over_that_coordinate() {
    let d = tmp("one");
    let scene = root().join("fixtures/scenes/straight_guidance_planar.ron");
    let file = d.join("path.csv");
    std::fs::write(&file, "s,S.x\n0,0\n0.5,0.02\n1,0.04\n").unwrap();
    let (a, b) = (d.join("path"), d.join("coord"));
    let s = scene.to_str().unwrap();
    let o = flexmb(&[
        "sweep",
        s,
        "--over",
        "path",
        "--path",
        file.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--n",
        "5",
        "--modes",
        "3",
        "--out",
        a.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = flexmb(&[
        "sweep",
        s,
        "--over",
        "S.x",
        "--from",
        "0",
        "--to",
        "0.04",
        "--n",
        "5",
        "--modes",
        "3",
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (fa, fb) = (frequencies(&a), frequencies(&b));
    assert_eq!(fa.len(), 5);
    for (ra, rb) in fa.iter().zip(&fb) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-8 * y.abs(), "{x} against {y}");
        }
    }
    // the stiffening along the stroke shows: ω1 rises
    assert!(fa[4][0] > fa[0][0]);
}

#[test]
fn a_two_coordinate_path_moves_both_joints_of_the_manipulator() {
    let d = tmp("two");
    let scene = root().join("fixtures/scenes/manipulator_planar.ron");
    let file = d.join("path.csv");
    // both joints turn; the second half of the path bends back
    std::fs::write(
        &file,
        "s,joint1.rotation,joint2.rotation\n0,0,0\n1,0.4,-0.3\n2,0.6,0.2\n",
    )
    .unwrap();
    let out = d.join("out");
    let o = flexmb(&[
        "sweep",
        scene.to_str().unwrap(),
        "--over",
        "path",
        "--path",
        file.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "2",
        "--n",
        "9",
        "--modes",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = frequencies(&out);
    assert_eq!(f.len(), 9);
    assert!(f.iter().flatten().all(|v| v.is_finite() && *v > 0.0));
    // the configuration changes the frequencies along the path
    let spread = f.iter().map(|r| r[0]).fold(f64::MIN, f64::max)
        - f.iter().map(|r| r[0]).fold(f64::MAX, f64::min);
    assert!(spread > 1e-3 * f[0][0], "ω1 along the path: {f:?}");
}

#[test]
fn bad_path_files_are_named_with_exit_code_2() {
    let d = tmp("bad");
    let scene = root().join("fixtures/scenes/straight_guidance_planar.ron");
    let s = scene.to_str().unwrap();
    for (text, from, to, words) in [
        ("t,S.x\n0,0\n1,0.01\n", "0", "1", "header"),
        ("s,Q.x\n0,0\n1,0.01\n", "0", "1", "Q.x"),
        ("s,S.x\n0,0\n0,0.01\n", "0", "1", "increase"),
        ("s,S.x\n0,0\n1,0.01\n", "0", "2", "range"),
        ("s,S.x\n0,0\n", "0", "1", "two rows"),
    ] {
        let file = d.join("p.csv");
        std::fs::write(&file, text).unwrap();
        let o = flexmb(&[
            "sweep",
            s,
            "--over",
            "path",
            "--path",
            file.to_str().unwrap(),
            "--from",
            from,
            "--to",
            to,
            "--n",
            "3",
            "--out",
            d.join("o").to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(words), "{text}: expected '{words}' in: {err}");
    }
    let o = flexmb(&["sweep", s, "--over", "path", "--from", "0", "--to", "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--path"));
}
