//! `--vtk DIR` on `static` and `simulate`: a PVD collection with one VTU
//! file per configuration, the configuration the command computed, an
//! unwritable directory refused before any computation, and a superelement
//! drawn as its FE mesh (or, with `--vtk-chords`, as its chord) by `eig`
//! and `static`.

mod common;
use common::{fixture, flexmb, meshio_check, temp_dir};

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
    // with --vtk-boxes the guidance's beams are hexahedra, 4 each, their
    // section in the cell data (crates/vtk/tests/meshio.rs checks the
    // geometry); without --vtk it is refused
    let o = flexmb()
        .arg("static")
        .arg(fixture("straight_guidance_planar.ron"))
        .arg("--out")
        .arg(dir.join("st"))
        .arg("--vtk")
        .arg(dir.join("boxes"))
        .arg("--vtk-boxes")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let vtu = std::fs::read_to_string(dir.join("boxes/static_0000.vtu")).unwrap();
    let lines = std::fs::read_to_string(dir.join("vtk/static_0000.vtu")).unwrap();
    for f in [&vtu, &lines] {
        assert!(f.contains("Name=\"section_dimensions\""), "no section data");
    }
    let types = |f: &str| -> Vec<u8> {
        let a = f.split("Name=\"types\"").nth(1).unwrap();
        let a = &a[a.find('>').unwrap() + 1..a.find("</DataArray>").unwrap()];
        a.split_whitespace().map(|t| t.parse().unwrap()).collect()
    };
    let beams = types(&lines).iter().filter(|&&t| t == 3).count();
    assert!(beams > 0);
    assert_eq!(types(&vtu).iter().filter(|&&t| t == 12).count(), 4 * beams);
    let o = flexmb()
        .arg("static")
        .arg(fixture("straight_guidance_planar.ron"))
        .arg("--out")
        .arg(dir.join("st"))
        .arg("--vtk-boxes")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "--vtk-boxes without --vtk");
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

/// A 200 mm steel bar superelement (4 × 1 × 1 twenty-node hexahedra, two
/// normal modes) written to `dir/bar.se.ron`, and a scene `dir/bar.ron`
/// with it clamped at P and loaded at Q; returns its FE node count.
fn bar_scene(dir: &std::path::Path) -> usize {
    let steel = flexmb_element::Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    };
    let part =
        flexmb_superelement::parts::prismatic_bar(0.2, 0.01, 0.01, [4, 1, 1], steel).unwrap();
    let model = part.mesh.assemble("bar").unwrap();
    let mut s = part.settings.clone();
    s.normal_modes = 2;
    let data = flexmb_superelement::build(&model, &s).unwrap().data;
    flexmb_superelement::spec::write_ron(&dir.join("bar.se.ron"), &data).unwrap();
    std::fs::write(
        dir.join("bar.ron"),
        r#"(
    dimension: Spatial,
    nodes: [ (id: "P", at: [0.0, 0.0, 0.0]), (id: "Q", at: [0.2, 0.0, 0.0]) ],
    elements: [ (id: "bar", type: Superelement(nodes: ("P", "Q"), file: "bar.se.ron")) ],
    fixed: [ Node("P") ],
    loads: [ (node: "Q", force: Some([0.0, 30.0, -20.0])) ],
)"#,
    )
    .unwrap();
    model.n_nodes()
}

#[test]
fn a_superelement_is_drawn_as_its_mesh_or_with_vtk_chords_as_its_chord() {
    let dir = temp_dir("vtk", "superelement");
    let n_fe = bar_scene(&dir);
    let run = |args: &[&str]| {
        let o = flexmb()
            .args(args)
            .arg(dir.join("bar.ron"))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    run(&[
        "static",
        "--out",
        out,
        "--vtk",
        dir.join("mesh").to_str().unwrap(),
    ]);
    run(&[
        "static",
        "--out",
        out,
        "--vtk-chords",
        "--vtk",
        dir.join("chord").to_str().unwrap(),
    ]);
    run(&[
        "eig",
        "--modes",
        "2",
        "--vtk",
        dir.join("eig").to_str().unwrap(),
    ]);
    meshio_check(&format!(
        r#"
import meshio, numpy as np
d = "{d}"
m = meshio.read(d + "/mesh/static_0000.vtu")
assert m.points.shape == ({n} + 2, 3), m.points.shape
assert [b.type for b in m.cells] == ["hexahedron20"] and len(m.cells[0].data) == 4, m.cells
# the load bends the bar: the FE nodes at q move with Q
disp = m.point_data["displacement"]
assert np.linalg.norm(disp[2:], axis=1).max() > 1e-4, disp
c = meshio.read(d + "/chord/static_0000.vtu")
assert c.points.shape == (2, 3) and [b.type for b in c.cells] == ["line"], c.cells
assert np.abs(c.points - m.points[:2]).max() == 0
e = meshio.read(d + "/eig/eig_0000.vtu")
for k in (1, 2):
    f = e.point_data["mode_%d" % k]
    assert f.shape == ({n} + 2, 3) and np.linalg.norm(f[2:], axis=1).max() > 0, f
    s = meshio.read(d + "/eig/mode_%d_0006.vtu" % k)
    assert s.points.shape == ({n} + 2, 3)
    assert np.abs(s.point_data["displacement"] - s.point_data["mode_shape"]).max() < 1e-12
print("ok")
"#,
        d = dir.display(),
        n = n_fe
    ));
    std::fs::remove_dir_all(&dir).ok();
}
