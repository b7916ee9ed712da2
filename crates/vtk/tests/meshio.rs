//! VTU and PVD files read back by an independent reader, meshio (Python;
//! `.ci/run` installs the Debian package python3-meshio): coordinates,
//! connectivity and fields.

mod common;

use flexmb_model::Scene;

const SCENE: &str = r#"(
    dimension: Spatial,
    materials: { "steel": (e: 2.1e11, g: 8.1e10, rho: 7850.0) },
    sections: { "rod": Circle(d: 0.01) },
    nodes: [
        (id: "A", at: [0.0, 0.0, 0.0]),
        (id: "B", at: [0.5, 0.0, 0.0]),
        (id: "C", at: [0.5, 0.3, 0.0]),
    ],
    elements: [
        (id: "arm", type: Beam((nodes: ("A", "B"), material: "steel", section: "rod", up: Some([0.0, 0.0, 1.0])))),
        (id: "tie", type: Truss(nodes: ("B", "C"), ea: 1.0e6, mass_per_length: 0.2)),
        (id: "bob", type: PointMass(node: "C", mass: 0.1)),
    ],
    fixed: [Node("A")],
)"#;

#[test]
fn a_configuration_and_a_mode_series_read_back_with_meshio() {
    let mech = Scene::from_ron_str(SCENE).unwrap().build(None).unwrap();
    let mut x = vec![0.0; mech.n_x()];
    for n in &mech.nodes {
        for (d, &i) in n.position.iter().enumerate() {
            x[i] = n.at[d];
        }
        if let Some(o) = &n.orientation {
            x[o[0]] = 1.0;
        }
    }
    // C moved by (0.01, −0.02, 0.03)
    let c = mech.node("C").unwrap().position.clone();
    let dx: Vec<f64> = (0..mech.n_x())
        .map(|i| match c.iter().position(|&k| k == i) {
            Some(0) => 0.01,
            Some(1) => -0.02,
            Some(2) => 0.03,
            _ => 0.0,
        })
        .collect();
    let moved: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + b).collect();
    let speed = vec![[1.0, 2.0, 3.0]; mech.nodes.len()];
    let dir = std::env::temp_dir().join(format!("flexmb-vtk-{}", std::process::id()));
    let one = flexmb_vtk::configuration(&mech, &moved, &[("velocity", speed)]).unwrap();
    let frames =
        flexmb_vtk::mode_frames(&mech, &x, &dx, 0.05, 8, &[("frequency_hz", 12.5)]).unwrap();
    flexmb_vtk::write_series(&dir, "static", &[(0.0, one)]).unwrap();
    let files = flexmb_vtk::write_series(&dir, "mode1", &frames).unwrap();
    assert_eq!(files.len(), 9);
    let check = format!(
        r#"
import meshio, numpy as np, xml.etree.ElementTree as ET
m = meshio.read("{d}/static_0000.vtu")
p = m.points
assert p.shape == (3, 3), p.shape
assert np.allclose(p[2], [0.51, 0.28, 0.03]), p[2]
assert np.allclose(p[1], [0.5, 0.0, 0.0]), p[1]
lines = [c.data for c in m.cells if c.type == "line"][0]
assert lines.tolist() == [[0, 1], [1, 2]], lines
verts = [c.data for c in m.cells if c.type == "vertex"][0]
assert verts.tolist() == [[2]], verts
assert np.allclose(m.point_data["displacement"][2], [0.01, -0.02, 0.03])
assert np.allclose(m.point_data["velocity"][0], [1, 2, 3])
kinds = np.concatenate(m.cell_data["kind"]).ravel().tolist()
assert kinds == [1, 2, 5], kinds
ea = np.concatenate(m.cell_data["axial_stiffness"]).ravel()
assert abs(ea[0] / (2.1e11 * np.pi * 0.01**2 / 4) - 1) < 1e-9, ea
assert abs(ea[1] / 1e6 - 1) < 1e-9, ea
# the mode series: a quarter period has the full 0.05 m at C
q = meshio.read("{d}/mode1_0002.vtu")
assert abs(np.linalg.norm(q.point_data["displacement"][2]) - 0.05) < 1e-12
# every frame has the mode's node displacements, the largest 0.05 m, and its frequency
for k in (0, 3):
    f = meshio.read("{d}/mode1_%04d.vtu" % k)
    assert np.allclose(f.point_data["mode_shape"][2], 0.05 * np.array([0.01, -0.02, 0.03]) / np.linalg.norm([0.01, -0.02, 0.03]), atol=1e-15), f.point_data
    assert np.allclose(f.point_data["mode_shape"][0], 0), f.point_data
    assert f.field_data["frequency_hz"].tolist() == [12.5], f.field_data
t = [float(e.get("timestep")) for e in ET.parse("{d}/mode1.pvd").getroot().iter("DataSet")]
assert t == [k / 8 for k in range(8)], t
print("ok")
"#,
        d = dir.display()
    );
    common::check_with_python(&check);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn coordinates_of_another_mechanism_are_refused() {
    let mech = Scene::from_ron_str(SCENE).unwrap().build(None).unwrap();
    let e = flexmb_vtk::configuration(&mech, &[0.0; 3], &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("x has 3 entries"), "{e}");
}
