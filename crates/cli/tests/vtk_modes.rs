//! `--vtk DIR` on `eig` and `sweep` (also `--reduced`), read back with
//! meshio: the configuration, the modes as animated series and as point
//! data, against the closed-form cantilever with a tip mass.

mod common;
use common::{flexmb, meshio_check, temp_dir};
use std::path::Path;

/// A massless cantilever (EI = 200 N m², L = 1 m, axially rigid) with a
/// 2 kg tip mass and a tip force of 2 N in y: one bending mode
/// ω² = 3EI/(m L³), tip deflection F L³/(3EI) = 3.33 mm.
const CANTILEVER: &str = r#"(
    dimension: Planar,
    materials: { "s": (e: 2.0e11, rho: 1.0) },
    sections: { "b": User((area: 1e-4, iy: 1e-9, iz: 1e-9, j: 1e-9, ky: inf, kz: inf)) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
    elements: [
        (id: "beam", type: Beam((nodes: ("A", "B"), material: "s", section: "b", mass: false))),
        (id: "m", type: PointMass(node: "B", mass: 2.0, inertia: Some(1e-6))),
    ],
    fixed: [ Node("A") ],
    rigid: [ Def("beam", "elongation") ],
    loads: [ (node: "B", force: Some([0.0, 2.0])) ],
)"#;

fn run(args: &[&str], dirs: &[&Path]) {
    let mut c = flexmb();
    c.args(args);
    for d in dirs {
        c.arg(d);
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn eig_writes_the_configuration_and_each_mode_as_an_animated_series() {
    let dir = temp_dir("vtk", "eig");
    let scene = dir.join("cantilever.ron");
    std::fs::write(&scene, CANTILEVER).unwrap();
    let s = scene.to_str().unwrap();
    run(&["eig", s, "--modes", "2", "--vtk"], &[&dir.join("v")]);
    let check = format!(
        r#"
import meshio, numpy as np, xml.etree.ElementTree as ET
d = "{d}/v"
f1 = np.sqrt(3 * 200.0 / 2.0) / (2 * np.pi)
e = meshio.read(d + "/eig_0000.vtu")
assert np.allclose(e.points, [[0, 0, 0], [1, 0, 0]], atol=1e-12), e.points
assert [c.data.tolist() for c in e.cells if c.type == "line"] == [[[0, 1]]], e.cells
# the bending mode moves B across the beam; drawn at a tenth of the length
m1 = e.point_data["mode_1"]
assert np.allclose(m1[0], 0, atol=1e-12), m1
assert np.allclose(np.abs(m1[1]), [0, 0.1, 0], atol=1e-9), m1
assert "mode_2" in e.point_data
for k in (1, 2):
    t = [float(x.get("timestep")) for x in ET.parse(f"{{d}}/mode_{{k}}.pvd").getroot().iter("DataSet")]
    assert t == [j / 24 for j in range(24)], t
q = meshio.read(d + "/mode_1_0006.vtu")  # a quarter period: the full mode
assert abs(q.field_data["frequency_hz"][0] / f1 - 1) < 1e-3, (q.field_data, f1)
shape = q.point_data["mode_shape"]
assert np.allclose(shape, m1, atol=1e-12), (shape, m1)
assert np.allclose(q.points, e.points + shape, atol=1e-12), q.points
h = meshio.read(d + "/mode_1_0012.vtu")  # half a period: back at rest
assert np.allclose(h.points, e.points, atol=1e-12), h.points
f2 = meshio.read(d + "/mode_2_0000.vtu").field_data["frequency_hz"][0]
assert f2 > 10 * f1, (f1, f2)
print("ok")
"#,
        d = dir.display()
    );
    meshio_check(&check);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_writes_the_equilibria_as_a_series_with_the_modes_as_point_data() {
    let dir = temp_dir("vtk", "sweep");
    let scene = dir.join("cantilever.ron");
    std::fs::write(&scene, CANTILEVER).unwrap();
    let s = scene.to_str().unwrap();
    let sweep = [
        "sweep", s, "--over", "load", "--from", "0", "--to", "1", "--n", "5", "--modes", "2",
    ];
    let (out, v) = (dir.join("out"), dir.join("v"));
    run(
        &[&sweep[..], &["--vtk"]].concat(),
        &[&v, Path::new("--out"), &out],
    );
    // the same sweep with a modal model that keeps both DOFs: the same
    // equilibria and modes, through q = G(z) and q̇ = G,z ż
    let model = dir.join("modal2.ron");
    run(
        &["reduce", s, "--method", "modal", "--modes", "2", "--out"],
        &[&model],
    );
    let m = model.to_str().unwrap();
    let reduced = [&sweep[..], &["--reduced", m, "--vtk"]].concat();
    run(
        &reduced,
        &[&dir.join("rv"), Path::new("--out"), &dir.join("rout")],
    );
    let check = format!(
        r#"
import meshio, numpy as np, xml.etree.ElementTree as ET
for d in ("{d}/v", "{d}/rv"):
    t = [float(x.get("timestep")) for x in ET.parse(d + "/sweep.pvd").getroot().iter("DataSet")]
    assert t == [0, 0.25, 0.5, 0.75, 1.0], t
    for k, lam in enumerate(t):
        m = meshio.read(f"{{d}}/sweep_{{k:04d}}.vtu")
        # the tip deflection of the linear theory, to its geometric nonlinearity
        tip = m.points[1] - [1, 0, 0]
        assert abs(tip[1] - lam * 2.0 / 600.0) < 1e-3 * 2.0 / 600.0 + 1e-15, (d, lam, tip)
        assert np.allclose(m.point_data["displacement"][1], tip, atol=1e-15)
        m1 = m.point_data["mode_1"]
        assert abs(np.linalg.norm(m1[1]) - 0.1) < 1e-12, m1
        assert abs(m1[1][1]) > 0.99 * 0.1, m1
    print(d, "checked")
for k in range(5):
    a = meshio.read(f"{d}/v/sweep_{{k:04d}}.vtu")
    b = meshio.read(f"{d}/rv/sweep_{{k:04d}}.vtu")
    assert np.allclose(a.points, b.points, atol=1e-9), (a.points, b.points)
    for n in ("mode_1", "mode_2"):
        assert np.allclose(a.point_data[n], b.point_data[n], atol=1e-6), (n, a.point_data[n], b.point_data[n])
print("ok")
"#,
        d = dir.display()
    );
    meshio_check(&check);
    std::fs::remove_dir_all(&dir).ok();
}
