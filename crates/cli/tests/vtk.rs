//! `--vtk DIR` on `static` and `simulate`: a PVD collection with one VTU
//! file per configuration, the configuration the command computed, and an
//! unwritable directory refused before any computation.

mod common;
use common::{fixture, flexmb, temp_dir};

/// The `NumberOfPoints` and the first point of a VTU text.
fn points(vtu: &str) -> (usize, [f64; 3]) {
    let n = vtu
        .split("NumberOfPoints=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    let after = vtu.split("Name=\"Points\"").nth(1).unwrap();
    let data = after.split('>').nth(1).unwrap();
    let v: Vec<f64> = data
        .split_whitespace()
        .take(3)
        .map(|s| s.parse().unwrap())
        .collect();
    (n, [v[0], v[1], v[2]])
}

#[test]
fn static_and_simulate_write_a_pvd_series() {
    let dir = temp_dir("vtk", "series");
    let scene = fixture("flexible_pendulum.ron");
    let o = flexmb()
        .arg("simulate")
        .arg(&scene)
        .args(["--t-end", "0.2", "--outputs", "5"])
        .arg("--out")
        .arg(dir.join("sim"))
        .arg("--vtk")
        .arg(dir.join("vtk"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pvd = std::fs::read_to_string(dir.join("vtk/simulate.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 5, "{pvd}");
    assert!(pvd.contains("timestep=\"2e-1\""), "{pvd}");
    let first = std::fs::read_to_string(dir.join("vtk/simulate_0000.vtu")).unwrap();
    let last = std::fs::read_to_string(dir.join("vtk/simulate_0004.vtu")).unwrap();
    let (n, _) = points(&first);
    assert!(n >= 2, "{n} points");
    assert_ne!(first, last, "the pendulum moved");
    // static: one configuration (the pendulum has no static equilibrium
    // where it starts; the guidance has)
    let o = flexmb()
        .arg("static")
        .arg(fixture("straight_guidance_planar.ron"))
        .arg("--out")
        .arg(dir.join("st"))
        .arg("--vtk")
        .arg(dir.join("vtk"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pvd = std::fs::read_to_string(dir.join("vtk/static.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 1, "{pvd}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_unwritable_vtk_directory_is_refused_first() {
    let dir = temp_dir("vtk", "bad");
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let o = flexmb()
        .arg("simulate")
        .arg(fixture("flexible_pendulum.ron"))
        .args(["--t-end", "100"])
        .arg("--out")
        .arg(dir.join("sim"))
        .arg("--vtk")
        .arg(&file)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--vtk"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
