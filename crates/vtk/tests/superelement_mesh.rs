//! Superelements drawn as their FE mesh (issue 21), read back with meshio:
//! the mesh at the reference configuration where the scene places it (also
//! on nodes that start rotated), a static deflection at the positions
//! `MeshRecovery` gives, a rigid motion of it moving the mesh rigidly, a mode
//! series recovered at its extreme frame, and the VTK cell types and node
//! orders of every solid kind checked against VTK's own conventions.

mod common;

use flexmb_dynamics::{Dynamics, StaticOptions};
use flexmb_element::{FeCell, FeMesh, LinearSuperelement, Material};
use flexmb_model::{Mechanism, Scene};
use flexmb_rotation::EulerParameters;
use flexmb_superelement::geometry::{element_moments, SolidKind};
use flexmb_superelement::recovery::MeshRecovery;
use flexmb_superelement::{build, parts, spec::write_ron, BuildSettings, FeModel, SolidElements};
use flexmb_vtk::{Drawing, Superelements};
use nalgebra::{Unit, Vector3};
use std::path::{Path, PathBuf};
use std::sync::Arc;

const L: f64 = 0.2;

/// A 200 mm steel bar, 10 × 10 mm, of 4 × 1 × 1 twenty-node hexahedra, with
/// two fixed-interface normal modes: built along global x from the origin,
/// so R0 = I and the FE node coordinates are the element-frame ones.
fn bar() -> (FeModel, BuildSettings) {
    let steel = Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    };
    let part = parts::prismatic_bar(L, 0.01, 0.01, [4, 1, 1], steel).unwrap();
    let model = part.mesh.assemble("bar").unwrap();
    let mut s = part.settings.clone();
    s.normal_modes = 2;
    (model, s)
}

fn temp(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-vtk-se-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The initial orientations of P and Q in the rotated scene.
const TURN_P: ([f64; 3], f64) = ([1.0, 1.0, 0.5], 0.8);
const TURN_Q: ([f64; 3], f64) = ([0.0, 1.0, -0.3], -0.6);

fn euler(turn: ([f64; 3], f64)) -> EulerParameters {
    EulerParameters::from_axis_angle(&Unit::new_normalize(Vector3::from(turn.0)), turn.1)
}

/// Writes `data` as DIR/bar.se.ron and builds the scene: the bar from P at
/// `c` to Q = c + (L, 0, 0), P and Q turned initially (`TURN_P`, `TURN_Q`)
/// when `rotated`, P clamped, a force and a moment at Q.
fn mechanism(dir: &Path, data: &LinearSuperelement, c: [f64; 3], rotated: bool) -> Mechanism {
    write_ron(&dir.join("bar.se.ron"), data).unwrap();
    let turn = |t: ([f64; 3], f64)| {
        if rotated {
            format!(
                ", orientation: Some(AxisAngle(axis: {:?}, angle: {:?}))",
                t.0, t.1
            )
        } else {
            String::new()
        }
    };
    let q = [c[0] + L, c[1], c[2]];
    let text = format!(
        r#"(
    dimension: Spatial,
    nodes: [
        (id: "P", at: {c:?}{}),
        (id: "Q", at: {q:?}{}),
    ],
    elements: [ (id: "bar", type: Superelement(nodes: ("P", "Q"), file: "bar.se.ron")) ],
    fixed: [ Node("P") ],
    loads: [ (node: "Q", force: Some([-50.0, 30.0, -20.0]), moment: Some([0.5, 0.2, -0.3])) ],
)"#,
        turn(TURN_P),
        turn(TURN_Q)
    );
    Scene::from_ron_str(&text)
        .unwrap()
        .build(Some(dir))
        .unwrap()
}

/// The bar's element coordinates (r_p, λp, r_q, λq, η̄) at `x`, gathered by
/// name (the scene without initial orientations).
fn element_coords(mech: &Mechanism, x: &[f64]) -> Vec<f64> {
    let mut v = vec![];
    for id in ["P", "Q"] {
        let n = mech.node(id).unwrap();
        v.extend(n.position.iter().map(|&i| x[i]));
        v.extend(n.orientation.as_ref().unwrap().iter().map(|&i| x[i]));
    }
    for g in ["bar.p", "bar.q", "bar.f"] {
        let (_, idx) = mech.mode_groups.iter().find(|(n, _)| n == g).unwrap();
        v.extend(idx.iter().map(|&i| x[i]));
    }
    v
}

fn recovered(data: &LinearSuperelement, coords: &[f64]) -> Vec<[f64; 3]> {
    let mut rec = MeshRecovery::new(data).unwrap();
    let mut out = vec![[0.0; 3]; rec.mesh().nodes.len()];
    rec.positions(coords, &mut out).unwrap();
    out
}

/// Writes the configurations `frames` of `mech` as DIR/NAME.pvd.
fn write(dir: &Path, name: &str, mech: &Mechanism, x: &[f64], style: Superelements) {
    let mut d = Drawing::new(mech, style).unwrap();
    let text = d.configuration(x, &[], &[]).unwrap();
    flexmb_vtk::write_series(dir, name, &[(0.0, text)]).unwrap();
}

/// A Python list of lists.
fn py<T: std::fmt::Debug>(v: &[T]) -> String {
    format!("{v:?}")
}

#[test]
fn the_mesh_at_the_reference_is_the_fe_mesh_where_the_scene_puts_it() {
    let (model, s) = bar();
    let data = build(&model, &s).unwrap().data;
    let mesh = data.fe_mesh.clone().unwrap();
    let c = [0.3, -0.1, 0.25];
    let dir = temp("reference");
    for (name, rotated) in [("plain", false), ("rotated", true)] {
        let mech = mechanism(&dir, &data, c, rotated);
        write(&dir, name, &mech, &mech.x0, Superelements::Mesh);
        if !rotated {
            write(&dir, "chord", &mech, &mech.x0, Superelements::Chord);
        }
    }
    // the builder's FE node coordinates, moved to the scene's p (R0 = I)
    let placed: Vec<[f64; 3]> = model
        .coords()
        .iter()
        .map(|x| std::array::from_fn(|d| x[d] + c[d]))
        .collect();
    let conn: Vec<Vec<usize>> = mesh
        .cells
        .iter()
        .map(|cell| cell.nodes.iter().map(|i| i + 2).collect())
        .collect();
    let script = format!(
        r#"
import meshio, numpy as np
placed = np.array({placed}); conn = np.array({conn}); c = np.array({c:?})
for name in ("plain", "rotated"):
    m = meshio.read("{d}/%s_0000.vtu" % name)
    assert m.points.shape == (2 + len(placed), 3), (name, m.points.shape)
    assert np.allclose(m.points[0], c, rtol=0, atol=1e-15), m.points[0]
    assert np.allclose(m.points[1], c + [{L}, 0, 0], rtol=0, atol=1e-15), m.points[1]
    err = np.abs(m.points[2:] - placed).max()
    assert err < 1e-14, (name, err)
    print(name, "mesh at the reference vs the placed FE mesh:", err, "m")
    assert [b.type for b in m.cells] == ["hexahedron20"], [b.type for b in m.cells]
    assert (m.cells[0].data == conn).all(), name
    assert np.abs(m.point_data["displacement"]).max() < 1e-14, name
    assert (np.concatenate(m.cell_data["kind"]) == 4).all()
    assert (np.concatenate(m.cell_data["element"]) == 0).all()
m = meshio.read("{d}/chord_0000.vtu")
assert m.points.shape == (2, 3), m.points.shape
assert [(b.type, b.data.tolist()) for b in m.cells] == [("line", [[0, 1]])], m.cells
import os
size = [os.path.getsize("{d}/%s_0000.vtu" % n) for n in ("plain", "chord")]
print("file size: mesh", size[0], "bytes, chord", size[1], "bytes:", (size[0] - size[1]) / len(placed), "bytes a FE node")
print("ok")
"#,
        placed = py(&placed),
        conn = py(&conn),
        d = dir.display()
    );
    common::check_with_python(&script);
    std::fs::remove_dir_all(&dir).ok();
}

/// R(λ) as a row-major array.
fn matrix(l: &EulerParameters) -> [[f64; 3]; 3] {
    let r = l.rotation_matrix();
    std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]))
}

#[test]
fn a_static_deflection_is_drawn_where_the_recovery_puts_it_and_moves_rigidly() {
    let (model, s) = bar();
    let data = build(&model, &s).unwrap().data;
    let c = [0.3, -0.1, 0.25];
    let dir = temp("static");
    let mech = mechanism(&dir, &data, c, false);
    let sol = Dynamics::new(Arc::new(mech.clone()))
        .static_equilibrium(0.0, &mech.q0(), &StaticOptions::default())
        .unwrap();
    let x = sol.x.clone();
    write(&dir, "static", &mech, &x, Superelements::Mesh);
    let expected = recovered(&data, &element_coords(&mech, &x));
    let reference = recovered(&data, &element_coords(&mech, &mech.x0));
    // the same configuration of the scene whose nodes start rotated: each
    // node's Euler parameters λ ∘ λ0 (the element sees λ again)
    let turned = mechanism(&dir, &data, c, true);
    let mut xt = x.clone();
    for (id, turn) in [("P", TURN_P), ("Q", TURN_Q)] {
        let o = mech.node(id).unwrap().orientation.clone().unwrap();
        let ot = turned.node(id).unwrap().orientation.clone().unwrap();
        let l = EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]).compose(&euler(turn));
        for k in 0..4 {
            xt[ot[k]] = l.0[k];
        }
    }
    assert_eq!(turned.n_x(), mech.n_x());
    write(&dir, "turned", &turned, &xt, Superelements::Mesh);
    // a rigid motion of the deflected mechanism: r → R r + t, λ → λR ∘ λ
    let lr = euler(([0.3, -1.0, 2.0], 2.1));
    let t = [1.5, -0.7, 0.4];
    let rm = matrix(&lr);
    let mut xm = x.clone();
    for n in &mech.nodes {
        let r: [f64; 3] = std::array::from_fn(|d| x[n.position[d]]);
        for i in 0..3 {
            xm[n.position[i]] = (0..3).map(|j| rm[i][j] * r[j]).sum::<f64>() + t[i];
        }
        if let Some(o) = &n.orientation {
            let l = lr.compose(&EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]));
            for k in 0..4 {
                xm[o[k]] = l.0[k];
            }
        }
    }
    write(&dir, "moved", &mech, &xm, Superelements::Mesh);
    let script = format!(
        r#"
import meshio, numpy as np
expected = np.array({expected}); reference = np.array({reference})
R = np.array({rm:?}); t = np.array({t:?})
s = meshio.read("{d}/static_0000.vtu")
fe = s.points[2:]
err = np.abs(fe - expected).max()
assert err < 1e-14, ("the writer's mesh is not the recovery's", err)
print("static: writer vs MeshRecovery", err, "m")
disp = s.point_data["displacement"][2:]
assert np.abs(disp - (expected - reference)).max() < 1e-14
big = np.linalg.norm(disp, axis=1).max()
assert big > 2e-4, ("the load deflects the bar", big)
# the nodes start rotated: the same mesh
tu = meshio.read("{d}/turned_0000.vtu")
err = np.abs(tu.points - s.points).max()
assert err < 1e-14, ("rotated nodes draw another mesh", err)
print("static on rotated nodes vs unrotated", err, "m")
# the rigid motion moves every point rigidly
m = meshio.read("{d}/moved_0000.vtu")
err = np.abs(m.points - (s.points @ R.T + t)).max()
assert err < 1e-13, ("not rigid", err)
print("rigid motion: worst", err, "m; largest deflection", big, "m")
import os
print("file size of the deflected bar:", os.path.getsize("{d}/static_0000.vtu"), "bytes for", len(expected), "FE nodes")
print("ok")
"#,
        expected = py(&expected),
        reference = py(&reference),
        d = dir.display()
    );
    common::check_with_python(&script);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_mode_series_recovers_the_mesh_at_every_frame() {
    let (model, s) = bar();
    let data = build(&model, &s).unwrap().data;
    let dir = temp("mode");
    let mech = mechanism(&dir, &data, [0.0; 3], false);
    // Q moved along y by 1 and the first normal mode by 1 (a nodal vector)
    let mut dx = vec![0.0; mech.n_x()];
    dx[mech.node("Q").unwrap().position[1]] = 1.0;
    let (_, f) = mech.mode_groups.iter().find(|(n, _)| n == "bar.f").unwrap();
    dx[f[0]] = 1.0;
    let size = 0.02;
    let frames = flexmb_vtk::mode_frames(&mech, &mech.x0, &dx, size, 8, &[]).unwrap();
    flexmb_vtk::write_series(&dir, "mode", &frames).unwrap();
    // the extreme frame (phase 1/4) is x0 + a Δx with a = size (Q's move is 1)
    let extreme: Vec<f64> = mech.x0.iter().zip(&dx).map(|(x, d)| x + size * d).collect();
    let expected = recovered(&data, &element_coords(&mech, &extreme));
    let script = format!(
        r#"
import meshio, numpy as np
expected = np.array({expected}); placed = np.array({placed})
f0 = meshio.read("{d}/mode_0000.vtu")
assert np.abs(f0.points[2:] - placed).max() < 1e-14
f2 = meshio.read("{d}/mode_0002.vtu")
err = np.abs(f2.points[2:] - expected).max()
assert err < 1e-14, ("the extreme frame is not the recovered mesh", err)
print("mode extreme frame vs MeshRecovery", err, "m")
for f in (f0, f2):
    err = np.abs(f.point_data["mode_shape"] - f2.point_data["displacement"]).max()
    assert err < 1e-14, ("mode_shape is not the extreme displacement", err)
fe = np.linalg.norm(f2.point_data["mode_shape"][2:], axis=1).max()
assert fe > 0.01, fe
print("ok")
"#,
        expected = py(&expected),
        placed = py(model.coords()),
        d = dir.display()
    );
    common::check_with_python(&script);
    std::fs::remove_dir_all(&dir).ok();
}

/// One straight-edged cell of each kind in the Abaqus/CalculiX node order:
/// natural coordinates of the corners (tetrahedron: the unit one; wedge: the
/// unit triangle × [−1, 1]; hexahedron: [−1, 1]³), the midside nodes at
/// the middle of the edges the order puts them on.
fn abaqus_cell(kind: SolidKind) -> Vec<[f64; 3]> {
    // the edges of a ring of n corners from `first`, and those from each
    // corner of one ring to the one above it
    let ring = |first: usize, n: usize| (0..n).map(move |i| (first + i, first + (i + 1) % n));
    let up = |n: usize| (0..n).map(move |i| (i, i + n));
    let (corners, edges): (Vec<[f64; 3]>, Vec<(usize, usize)>) = match kind {
        SolidKind::Tet4 | SolidKind::Tet10 => (
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            ring(0, 3).chain((0..3).map(|i| (i, 3))).collect(),
        ),
        SolidKind::Wedge6 | SolidKind::Wedge15 => {
            let tri = [[0., 0.], [1., 0.], [0., 1.]];
            (
                [-1.0, 1.0]
                    .iter()
                    .flat_map(|&z| tri.map(|[a, b]| [a, b, z]))
                    .collect(),
                ring(0, 3).chain(ring(3, 3)).chain(up(3)).collect(),
            )
        }
        SolidKind::Hex8 | SolidKind::Hex20 => {
            let quad = [[-1., -1.], [1., -1.], [1., 1.], [-1., 1.]];
            (
                [-1.0, 1.0]
                    .iter()
                    .flat_map(|&z| quad.map(|[a, b]| [a, b, z]))
                    .collect(),
                ring(0, 4).chain(ring(4, 4)).chain(up(4)).collect(),
            )
        }
    };
    let mut nodes = corners.clone();
    if kind.n_nodes() > corners.len() {
        for (a, b) in edges {
            nodes.push(std::array::from_fn(|d| {
                0.5 * (corners[a][d] + corners[b][d])
            }));
        }
    }
    assert_eq!(nodes.len(), kind.n_nodes());
    nodes
}

const KINDS: [SolidKind; 6] = [
    SolidKind::Tet4,
    SolidKind::Tet10,
    SolidKind::Hex8,
    SolidKind::Hex20,
    SolidKind::Wedge6,
    SolidKind::Wedge15,
];

/// VTK's conventions, from its cell classes (vtkTetra, vtkHexahedron,
/// vtkWedge and their quadratic forms): the faces, each wound so that its
/// right-hand normal points out of the cell, and the edges of the
/// midside nodes in order. A cell passes when every face points away from
/// the cell's centroid and every midside node is at its edge's middle.
const VTK_CONVENTIONS: &str = r#"
import numpy as np, xml.etree.ElementTree as ET
FACES = {
    10: [(0, 1, 3), (1, 2, 3), (2, 0, 3), (0, 2, 1)],
    12: [(0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2), (0, 3, 2, 1), (4, 5, 6, 7)],
    13: [(0, 1, 2), (3, 5, 4), (0, 3, 4, 1), (1, 4, 5, 2), (2, 5, 3, 0)],
}
FACES[24] = FACES[10]; FACES[25] = FACES[12]; FACES[26] = FACES[13]
CORNERS = {10: 4, 24: 4, 12: 8, 25: 8, 13: 6, 26: 6}
EDGES = {
    24: [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
    25: [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)],
    26: [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)],
}
def raw(path):
    """points and cells (type, node list) as written, without meshio's reordering"""
    arrays = {a.get("Name"): np.array(a.text.split(), dtype=float) for a in ET.parse(path).iter("DataArray")}
    pts = arrays["Points"].reshape(-1, 3)
    conn = arrays["connectivity"].astype(int); off = arrays["offsets"].astype(int); ty = arrays["types"].astype(int)
    starts = np.concatenate([[0], off[:-1]])
    return pts, [(t, conn[s:e].tolist()) for t, s, e in zip(ty, starts, off)]
def follows_vtk(t, x):
    """x: the cell's node positions in the written order"""
    centre = x[:CORNERS[t]].mean(axis=0)
    for f in FACES[t]:
        p = x[list(f)]
        n = sum(np.cross(p[i], p[(i + 1) % len(p)]) for i in range(len(p)))  # Newell
        if np.dot(n, p.mean(axis=0) - centre) <= 0:
            return "face %s points inwards" % (f,)
    for k, (a, b) in enumerate(EDGES.get(t, [])):
        m = x[CORNERS[t] + k]
        if np.abs(m - 0.5 * (x[a] + x[b])).max() > 1e-12:
            return "midside node %d is not on edge %s" % (CORNERS[t] + k, (a, b))
    return None
"#;

#[test]
fn every_cell_kind_is_written_in_vtk_order() {
    let (model, s) = bar();
    let mut data = build(&model, &s).unwrap().data;
    let n_coords = 6 + data.n_modes();
    // one cell of each kind, turned and stretched (a positive determinant)
    // and set apart along y; in the Abaqus order each has a positive volume
    let turn =
        EulerParameters::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)), 0.7)
            .rotation_matrix();
    let mut nodes = vec![];
    let mut cells = vec![];
    for (c, kind) in KINDS.iter().enumerate() {
        let x: Vec<[f64; 3]> = abaqus_cell(*kind)
            .iter()
            .map(|n| {
                let v = turn * Vector3::new(0.01 * n[0], 0.006 * n[1], 0.004 * n[2]);
                [0.05 + v[0], 0.03 * c as f64 + v[1], v[2]]
            })
            .collect();
        let vol = element_moments(*kind, &x, [0.0; 3]).unwrap().volume;
        assert!(vol > 0.0, "{kind:?} in the Abaqus order has volume {vol}");
        let first = nodes.len();
        nodes.extend(&x);
        let ids: Vec<usize> = (first..first + x.len()).collect();
        cells.push(FeCell {
            vtk_type: kind.vtk_type(),
            nodes: kind.vtk_order().iter().map(|&i| ids[i]).collect(),
        });
    }
    let n = nodes.len();
    data.fe_mesh = Some(FeMesh {
        nodes,
        cells,
        recovery: vec![vec![0.0; 3 * n_coords]; n],
    });
    let dir = temp("cells");
    let mech = mechanism(&dir, &data, [0.0; 3], false);
    write(&dir, "cells", &mech, &mech.x0, Superelements::Mesh);
    // the builder's cells: the bar's FE model with the corners of each
    // hexahedron described as two six-node wedges, built again (the same
    // volume: the rigid-body check of M passes; a coupling named so that
    // M's sparsity is checked against K, not against the wedges, which
    // leave out the midside nodes)
    let mut wedged = model.clone();
    let sol = wedged.solid.clone().unwrap();
    let mut split = SolidElements {
        kinds: vec![],
        nodes: vec![],
        density: vec![],
        couplings: vec!["the test's wedges leave out the midside nodes".into()],
        ..sol.clone()
    };
    for (h, d) in sol.nodes.iter().zip(&sol.density) {
        for w in [[0, 1, 2, 4, 5, 6], [0, 2, 3, 4, 6, 7]] {
            split.kinds.push(SolidKind::Wedge6);
            split.nodes.push(w.iter().map(|&i| h[i]).collect());
            split.density.push(*d);
        }
    }
    let wedge_nodes = split.nodes.clone();
    wedged.solid = Some(split);
    let built = build(&wedged, &s).unwrap().data;
    let mech_w = mechanism(&dir, &built, [0.0; 3], false);
    write(&dir, "wedges", &mech_w, &mech_w.x0, Superelements::Mesh);
    let wedge_nodes: Vec<Vec<usize>> = wedge_nodes
        .iter()
        .map(|w| w.iter().map(|i| i + 2).collect())
        .collect();
    let script = format!(
        r#"{VTK_CONVENTIONS}
import meshio
for name, want in (("cells", [10, 24, 12, 25, 13, 26]), ("wedges", None)):
    pts, cells = raw("{d}/%s_0000.vtu" % name)
    types = [t for t, _ in cells]
    if want is not None:
        assert types == want, types
    else:
        assert set(types) == {{13}} and len(types) == {nw}, types
    for k, (t, c) in enumerate(cells):
        why = follows_vtk(t, pts[c])
        assert why is None, (name, k, t, why)
# meshio turns a VTK wedge back to its own (gmsh's, Abaqus's) order (meshio
# 5.0 cannot read the quadratic wedge: the file with all kinds is read raw)
w = meshio.read("{d}/wedges_0000.vtu")
assert w.cells[0].type == "wedge" and w.cells[0].data.tolist() == {wedge_nodes}
print("ok")
"#,
        d = dir.display(),
        nw = wedge_nodes.len(),
        wedge_nodes = py(&wedge_nodes),
    );
    common::check_with_python(&script);
    std::fs::remove_dir_all(&dir).ok();
}
