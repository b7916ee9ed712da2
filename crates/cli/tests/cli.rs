//! The command line end to end: a real scene run, exit codes and messages.

use std::path::Path;
use std::process::Command;

fn flexmb() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexmb"))
}

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn simulate_writes_csv_and_plot() {
    let out = std::env::temp_dir().join(format!("flexmb-cli-sim-{}", std::process::id()));
    let o = flexmb()
        .args([
            "simulate",
            &fixture("spin_up_planar.ron"),
            "--t-end",
            "2",
            "--outputs",
            "21",
            "--rtol",
            "1e-6",
            "--atol",
            "1e-9",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("function evaluations"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("outputs.csv")).unwrap();
    assert_eq!(
        csv.lines().filter(|l| !l.starts_with('#')).count(),
        22,
        "header + 21 rows"
    );
    assert!(std::fs::read_to_string(out.join("outputs.svg"))
        .unwrap()
        .contains("<polyline"));
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn static_reports_displacements() {
    let out = std::env::temp_dir().join(format!("flexmb-cli-static-{}", std::process::id()));
    let o = flexmb()
        .args(["static", &fixture("straight_guidance_spatial.ron"), "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("equilibrium found"));
    assert!(out.join("node_positions.csv").exists());
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn bad_input_gives_exit_code_2_and_names_the_problem() {
    let o = flexmb()
        .args(["info", "/no/such/scene.ron"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read /no/such/scene.ron"));
    let dir = std::env::temp_dir().join(format!("flexmb-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.ron");
    std::fs::write(
        &p,
        "(\n  nodes: [ (id: \"A\", at: [0.0, 0.0, 0.0]) ],\n  elements: [ oops ],\n)\n",
    )
    .unwrap();
    let o = flexmb().arg("info").arg(&p).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 3"), "{err}");
    let o = flexmb()
        .args([
            "simulate",
            &fixture("spin_up_planar.ron"),
            "--integrator",
            "euler",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown integrator 'euler'"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn eig_and_sweep_report_frequencies() {
    let o = flexmb()
        .args([
            "eig",
            &fixture("straight_guidance_spatial.ron"),
            "--modes",
            "3",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(s.contains("undamped eigenfrequencies"), "{s}");
    let out = std::env::temp_dir().join(format!("flexmb-cli-sweep-{}", std::process::id()));
    let o = flexmb()
        .args([
            "sweep",
            &fixture("straight_guidance_spatial.ron"),
            "--over",
            "S.x",
            "--from",
            "0",
            "--to",
            "0.08",
            "--n",
            "9",
            "--modes",
            "2",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (h, rows) = flexmb_plot_read(&out.join("eigenfrequencies.csv"));
    assert_eq!(h, vec!["S.x change", "f1_hz", "f2_hz"]);
    assert_eq!(rows.len(), 9);
    // the out-of-plane mode drops sharply over the stroke (thesis Fig. 6.9b)
    assert!(
        rows[8][2] < 0.5 * rows[0][2],
        "ω2 {} → {}",
        rows[0][2],
        rows[8][2]
    );
    assert!(std::fs::read_to_string(out.join("eigenfrequencies.svg"))
        .unwrap()
        .contains("<polyline"));
    let o = flexmb()
        .args([
            "sweep",
            &fixture("straight_guidance_spatial.ron"),
            "--over",
            "Q.x",
            "--from",
            "0",
            "--to",
            "1",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("'Q.x' is neither"));
    std::fs::remove_dir_all(&out).ok();
}

fn flexmb_plot_read(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let h = lines
        .next()
        .unwrap()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (h, rows)
}
