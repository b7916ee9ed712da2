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

/// A beam's section in the cell data, and with `Beams::Boxes` the beam as
/// boxes of its section along its centre line, read back by meshio: a
/// steel strip 0.5 m along x (section 0.02 × 0.004 m, `up` y) and a truss,
/// with the strip's tip moved to (0.48, 0.1, 0) and turned by θ = 0.4 rad
/// about z. The box's end sections are the section at the nodes, turned
/// with them (the corners r ± by/2 y ± bz/2 z from the node's Euler
/// parameters, computed in Python); its middle section sits on the cubic
/// Hermite curve; at the reference the hexahedra fill by × bz × L.
#[test]
fn beams_carry_their_section_and_draw_as_boxes() {
    let scene = r#"(
    dimension: Spatial,
    materials: { "steel": (e: 2.1e11, g: 8.1e10, rho: 7850.0) },
    sections: { "strip": Rectangle(by: 0.02, bz: 0.004) },
    nodes: [
        (id: "A", at: [0.0, 0.0, 0.0]),
        (id: "B", at: [0.5, 0.0, 0.0]),
        (id: "C", at: [0.5, 0.3, 0.0]),
    ],
    elements: [
        (id: "strip", type: Beam((nodes: ("A", "B"), material: "steel", section: "strip", up: Some([0.0, 1.0, 0.0])))),
        (id: "tie", type: Truss(nodes: ("B", "C"), ea: 1.0e6, mass_per_length: 0.2)),
    ],
    fixed: [Node("A")],
)"#;
    let mech = Scene::from_ron_str(scene).unwrap().build(None).unwrap();
    let theta = 0.4f64;
    let mut x = mech.x0.clone();
    let b = mech.node("B").unwrap();
    x[b.position[0]] = 0.48;
    x[b.position[1]] = 0.1;
    let o = b.orientation.clone().unwrap();
    x[o[0]] = (0.5 * theta).cos();
    x[o[3]] = (0.5 * theta).sin();
    let dir = std::env::temp_dir().join(format!("flexmb-vtk-boxes-{}", std::process::id()));
    let mut lines = flexmb_vtk::Drawing::new(&mech, flexmb_vtk::Superelements::Mesh).unwrap();
    let mut boxes = flexmb_vtk::Drawing::with_beams(
        &mech,
        flexmb_vtk::Superelements::Mesh,
        flexmb_vtk::Beams::Boxes,
    )
    .unwrap();
    assert_eq!(boxes.n_points(), 3 + 4 * (flexmb_vtk::BOX_SEGMENTS + 1));
    let frames = |d: &mut flexmb_vtk::Drawing| {
        vec![
            (0.0, d.configuration(&mech.x0, &[], &[]).unwrap()),
            (1.0, d.configuration(&x, &[], &[]).unwrap()),
        ]
    };
    flexmb_vtk::write_series(&dir, "lines", &frames(&mut lines)).unwrap();
    flexmb_vtk::write_series(&dir, "boxes", &frames(&mut boxes)).unwrap();
    let check = format!(
        r#"
import meshio, numpy as np
L, by, bz, th = 0.5, 0.02, 0.004, {theta}
m = meshio.read("{d}/lines_0001.vtu")
cd = {{k: np.concatenate(v) for k, v in m.cell_data.items()}}
assert cd["section_shape"].ravel().tolist() == [1, 0], cd["section_shape"]
assert np.allclose(cd["section_dimensions"], [[by, bz, 0], [0, 0, 0]]), cd["section_dimensions"]
assert np.allclose(cd["section_area"].ravel(), [by * bz, 0]), cd["section_area"]
def hexes(path):
    m = meshio.read(path)
    h = [c.data for c in m.cells if c.type == "hexahedron"][0]
    return m, h
def volume(p):
    # a hexahedron as six tetrahedra around its diagonal 0–6
    t = [(0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6), (0, 5, 1, 6)]
    return sum(np.dot(np.cross(p[b] - p[a], p[c] - p[a]), p[d] - p[a]) / 6 for a, b, c, d in t)
m, h = hexes("{d}/boxes_0000.vtu")
assert h.shape == (4, 8), h.shape
vols = [volume(m.points[c]) for c in h]
assert all(v > 0 for v in vols), vols
assert abs(sum(vols) - by * bz * L) < 1e-15, (sum(vols), by * bz * L)
cd = {{k: np.concatenate(v) for k, v in m.cell_data.items()}}
assert cd["section_shape"].ravel().tolist() == [1, 1, 1, 1, 0], cd["section_shape"]
assert cd["element"].ravel().tolist() == [0, 0, 0, 0, 1], cd["element"]
m, h = hexes("{d}/boxes_0001.vtu")
p = m.points
R = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
y0, z0 = np.array([0, 1.0, 0]), np.array([0, 0, 1.0])
def section(c, Rm):
    y, z = Rm @ y0, Rm @ z0
    return np.array([c + a * by / 2 * y + b * bz / 2 * z for a, b in [(-1, -1), (1, -1), (1, 1), (-1, 1)]])
rq = np.array([0.48, 0.1, 0.0])
assert np.allclose(p[h[0][:4]], section(np.zeros(3), np.eye(3)), atol=1e-15), p[h[0][:4]]
assert np.allclose(p[h[3][4:]], section(rq, R), atol=1e-15), (p[h[3][4:]], section(rq, R))
# the middle station on the Hermite curve with end tangents L' (1, 0, 0), L' (cos θ, sin θ, 0)
l = np.linalg.norm(rq)
mid = 0.5 * rq + 0.125 * l * (np.array([1, 0, 0]) - np.array([np.cos(th), np.sin(th), 0]))
assert np.allclose(p[h[2][:4]].mean(axis=0), mid, atol=1e-15), (p[h[2][:4]].mean(axis=0), mid)
assert all(volume(p[c]) > 0 for c in h)
print("ok")
"#,
        d = dir.display()
    );
    common::check_with_python(&check);
    std::fs::remove_dir_all(&dir).ok();
}
