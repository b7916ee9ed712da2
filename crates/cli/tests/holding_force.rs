//! `flexmb sweep --over S.x` writes the force that holds S.x along the
//! stroke (`hold:S.x`), the actuation force users need (issue 15 item 3).
//! Checked against beam theory at small stroke and against `flexmb static`
//! under that force, which must move S by the swept amount.

mod common;
use common::fixture;

use std::path::{Path, PathBuf};
use std::process::Command;

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-hold-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "flexmb {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The (parameter, holding force) rows of a sweep's CSV.
fn holding(csv: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == "hold:S.x")
        .expect("a hold:S.x column");
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[k])
        })
        .collect()
}

#[test]
fn the_holding_force_of_a_sweep_is_the_force_that_holds_the_stroke() {
    let scene = fixture("straight_guidance_spatial.ron");
    let out = temp("sweep");
    run(&[
        "sweep",
        scene.to_str().unwrap(),
        "--over",
        "S.x",
        "--from",
        "0",
        "--to",
        "0.04",
        "--n",
        "21",
        "--out",
        out.to_str().unwrap(),
    ]);
    let rows = holding(&out.join("eigenfrequencies.csv"));
    assert!(out.join("holding_force.svg").exists());
    // small stroke: two guided sheets, 2 × 12 EI / L³ (E = 2.1e11, 30 × 1 mm,
    // L = 0.2 m); the body's weight acts along z, normal to the stroke
    let ei = 2.1e11 * 0.03 * 1e-9 / 12.0;
    let k = 2.0 * 12.0 * ei / 0.2f64.powi(3);
    let (s1, f1) = rows[1];
    assert!(
        (f1 / (k * s1) - 1.0).abs() < 2e-3,
        "{f1} N at {s1} m, linear {}",
        k * s1
    );
    // and the force grows faster than linearly (the sheets stiffen)
    let (s, f) = rows[20];
    assert!(f > 1.001 * k * s, "{f} N at {s} m");
    // `static` under that force moves S by the stroke
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "function: Some(RaisedCosinePulse(amplitude: 100.0, duration: 0.1))",
        &format!("function: Some(Constant({f:e}))"),
    );
    assert!(text.contains("Constant("));
    let dir = temp("static");
    let loaded = dir.join("loaded.ron");
    std::fs::write(&loaded, text).unwrap();
    let stdout = run(&[
        "static",
        loaded.to_str().unwrap(),
        "--steps",
        "4",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let line = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("S "))
        .unwrap_or_else(|| panic!("no displacement of S in {stdout}"));
    let dx: f64 = line
        .split('[')
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert!(
        (dx - s).abs() < 1e-7,
        "S moved {dx} m under {f} N, the sweep held it at {s} m"
    );
}
