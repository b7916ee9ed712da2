//! `flexmb sweep` through Euler-chart switches (issue 15 item 1): the
//! spatial roll-up of a cantilever by the end moment M = 2πEI/L, swept over
//! the load scale 0 … 1 (the tip turns by 2πs). With absolute nodal
//! coordinates as DOFs the nodes' charts must switch on the way (the start
//! chart of the tip is singular at s = ½); the frequencies equal those of
//! the same sweep with deformations as DOFs, which have no charts.

mod common;

use common::{flexmb, temp_dir};
use std::f64::consts::PI;
use std::path::Path;

const E: f64 = 2.0e11;
/// Side of the square section (m).
const B: f64 = 0.01;

/// The roll-up scene (8 steel beams over 1 m) with the given `dofs:`.
fn roll_up_scene(dofs: &str) -> String {
    let m = 2.0 * PI * E * B.powi(4) / 12.0;
    format!(
        r#"(
    name: "roll-up",
    dimension: Spatial,
    dofs: {dofs},
    materials: {{ "steel": (e: {E:?}, nu: 0.3, rho: 7800.0) }},
    sections: {{ "s": Rectangle(by: {B:?}, bz: {B:?}) }},
    nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [1.0, 0.0, 0.0]) ],
    elements: [ (id: "b", type: Beam((nodes: ("A", "B"), material: "steel", section: "s", n: 8, timoshenko: false, up: Some([0.0, 1.0, 0.0])))) ],
    fixed: [ Node("A") ],
    loads: [ (node: "B", moment: Some([0.0, 0.0, {m:?}])) ],
)"#
    )
}

/// Runs the load sweep s = 0, ⅛, …, 1 with six modes on the scene with
/// `dofs`; returns stdout and the rows of eigenfrequencies.csv.
fn sweep(dir: &Path, dofs: &str) -> (String, Vec<Vec<f64>>) {
    let scene = dir.join(format!("{dofs}.ron"));
    std::fs::write(&scene, roll_up_scene(dofs)).unwrap();
    let out = dir.join(dofs);
    let o = flexmb()
        .args(["sweep", scene.to_str().unwrap(), "--over", "load"])
        .args(["--from", "0", "--to", "1", "--n", "9", "--modes", "6"])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{dofs}: {stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let csv = std::fs::read_to_string(out.join("eigenfrequencies.csv")).unwrap();
    let rows = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect())
        .collect();
    (stdout, rows)
}

#[test]
fn a_load_sweep_with_nodal_dofs_switches_charts_and_has_the_deformation_sweeps_frequencies() {
    let dir = temp_dir("chart-sweep", "rollup");
    let (said_nodal, nodal) = sweep(&dir, "NodalCoordinates");
    let (said_def, def) = sweep(&dir, "Deformations");
    // the nodal run says how many charts it switched, the other none
    assert!(
        said_nodal.contains("chart switches of free orientations"),
        "{said_nodal}"
    );
    assert!(!said_def.contains("chart switches"), "{said_def}");
    assert_eq!(nodal.len(), 9);
    assert_eq!(def.len(), 9);
    for (a, b) in nodal.iter().zip(&def) {
        // load scale, then six frequencies
        assert_eq!(a.len(), 7, "{a:?}");
        assert_eq!(a[0], b[0]);
        for (fa, fb) in a[1..].iter().zip(&b[1..]) {
            // the library's sweep measured 3.5e-10 relative at most
            // (crates/linearize/tests/chart_sweep.rs); the CSV has 13 digits
            assert!(
                (fa - fb).abs() <= 1e-8 * fb.abs(),
                "s = {}: {a:?} against {b:?}",
                a[0]
            );
        }
    }
}
