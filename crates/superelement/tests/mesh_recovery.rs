//! The FE mesh section of the superelement data and the recovery of the FE
//! node positions from the superelement's coordinates (issue 21): against the
//! full FE static solution of a tip load, under a large rigid motion, and the
//! files written before the section existed.

use flexmb_element::{LinearSuperelement, Material};
use flexmb_superelement::recovery::MeshRecovery;
use flexmb_superelement::spec::{read_ron, write_ron};
use flexmb_superelement::{build, parts, prescribed_rigid_solve, BuildResult, RigidMotion};
use std::path::Path;

fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    }
}

/// A 200 mm bar of 10 × 2 × 2 twenty-node hexahedra with two normal modes.
fn bar() -> (parts::Part, flexmb_superelement::FeModel, BuildResult) {
    let part = parts::prismatic_bar(0.2, 0.01, 0.01, [10, 2, 2], steel()).unwrap();
    let model = part.mesh.assemble("bar").unwrap();
    let mut s = part.settings.clone();
    s.normal_modes = 2;
    let se = build(&model, &s).unwrap();
    (part, model, se)
}

/// Euler parameters of the rotation by the vector `v`.
fn quat(v: [f64; 3]) -> [f64; 4] {
    let t = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if t == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let s = (0.5 * t).sin() / t;
    [(0.5 * t).cos(), s * v[0], s * v[1], s * v[2]]
}

/// Rodrigues: the rotation matrix of the vector `v`.
fn rot(v: [f64; 3]) -> [[f64; 3]; 3] {
    let t = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let n = v.map(|x| x / t);
    let (c, s) = (t.cos(), t.sin());
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
            (if i == j { c } else { 0.0 }) + s * k[i][j] + (1.0 - c) * n[i] * n[j]
        })
    })
}

fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|j| r[i][j] * v[j]).sum())
}

/// The element coordinates (r_p, λp, r_q, λq, η̄).
fn coords(rp: [f64; 3], lp: [f64; 4], rq: [f64; 3], lq: [f64; 4], eta: &[f64]) -> Vec<f64> {
    rp.iter()
        .chain(&lp)
        .chain(&rq)
        .chain(&lq)
        .chain(eta)
        .copied()
        .collect()
}

fn positions(rec: &mut MeshRecovery<'_>, x: &[f64]) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]; rec.mesh().nodes.len()];
    rec.positions(x, &mut out).unwrap();
    out
}

/// Node p clamped, a transverse and axial force and a torque at q: the linear
/// superelement's static solution (from [V W]ᵀ K [V W]) placed as a
/// configuration of the non-linear element. The recovered displacement of the
/// q-interface nodes is q's rigid motion, and at every node it is the full FE
/// solution with the same motion of interface q (static condensation is exact
/// for the constraint modes). The co-rotated recovery differs from the linear
/// FE solution by second-order terms only: at rotations ~2e-5 the difference
/// is ~4e-6 of the displacement, and it falls with the load (100× smaller
/// load, 100× smaller relative difference), which a first-order error would not.
#[test]
fn tip_load_recovers_the_fe_static_solution() {
    let (part, model, se) = bar();
    let big = tip_load_errors(&part, &model, &se, 1.0);
    let small = tip_load_errors(&part, &model, &se, 0.01);
    println!("relative errors (all nodes vs FE, q interface vs rigid): load 1 {big:?}, load 0.01 {small:?}");
    for c in 0..2 {
        assert!(
            small[c] < 1e-6,
            "recovered vs FE / rigid q motion: {small:?}"
        );
        assert!(
            small[c] < 0.03 * big[c],
            "the difference is not second order: {big:?} → {small:?}"
        );
    }
}

/// The worst differences, relative to the largest FE displacement, of the
/// recovered displacement from the FE solution (all nodes) and from q's rigid
/// motion (q interface nodes), at `factor` × the tip load.
fn tip_load_errors(
    part: &parts::Part,
    model: &flexmb_superelement::FeModel,
    se: &BuildResult,
    factor: f64,
) -> [f64; 2] {
    let data = &se.data;
    let k = data.n_modes();
    let n = 12 + k;
    // free coordinates: µ̄q and η̄
    let free: Vec<usize> = (6..n).collect();
    let kff =
        nalgebra::DMatrix::from_fn(free.len(), free.len(), |i, j| se.k_full[(free[i], free[j])]);
    let mut f = nalgebra::DVector::zeros(free.len());
    f[0] = 20.0; // axial force (N)
    f[1] = 0.2; // y force (N)
    f[2] = -0.1; // z force (N)
    f[3] = 0.01; // torque about x (N m)
    let u = kff.lu().solve(&(f * factor)).unwrap();
    let (uq, phq) = ([u[0], u[1], u[2]], [u[3], u[4], u[5]]);
    let eta: Vec<f64> = (0..k).map(|i| u[6 + i]).collect();
    let r0 = data.r0;
    let g = |v: [f64; 3]| apply(&r0, v);
    let (p, q) = (part.settings.p, part.settings.q);
    let (uq_g, phq_g) = (g(uq), g(phq));
    let rq: [f64; 3] = std::array::from_fn(|i| q[i] + uq_g[i]);
    let x = coords(p, quat([0.0; 3]), rq, quat(phq_g), &eta);
    let x0 = coords(p, quat([0.0; 3]), q, quat([0.0; 3]), &vec![0.0; k]);
    let mut rec = MeshRecovery::new(data).unwrap();
    let pos = positions(&mut rec, &x);
    let pos0 = positions(&mut rec, &x0);
    // the reference configuration is the mesh itself
    for (a, b) in pos0.iter().zip(model.coords()) {
        for d in 0..3 {
            assert!((a[d] - b[d]).abs() < 1e-15, "reference {a:?} vs {b:?}");
        }
    }
    let disp: Vec<[f64; 3]> = pos
        .iter()
        .zip(&pos0)
        .map(|(a, b)| std::array::from_fn(|d| a[d] - b[d]))
        .collect();
    let motion = RigidMotion {
        translation: uq_g,
        rotation: phq_g,
        about: q,
    };
    let (fe, _) = prescribed_rigid_solve(
        model,
        &part.settings.interface_p,
        &part.settings.interface_q,
        &motion,
    )
    .unwrap();
    let scale = fe.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(scale > 1e-9, "the load moves the bar: {scale:e}");
    let q_nodes = part.settings.interface_q.resolve(model, "q").unwrap();
    let rq_m = rot(phq_g);
    let mut worst = [0.0f64; 2];
    for (i, di) in disp.iter().enumerate() {
        let eqs = model.dofs().node_eqs(i);
        let fe_i: [f64; 3] = std::array::from_fn(|d| eqs[d].map_or(0.0, |e| fe[e]));
        let err = (0..3).map(|d| (di[d] - fe_i[d]).abs()).fold(0.0, f64::max);
        worst[0] = worst[0].max(err / scale);
        if q_nodes.contains(&i) {
            let xi = model.coords()[i];
            let r = apply(&rq_m, std::array::from_fn(|d| xi[d] - q[d]));
            let rigid: [f64; 3] = std::array::from_fn(|d| rq[d] + r[d] - xi[d]);
            let e = (0..3).map(|d| (di[d] - rigid[d]).abs()).fold(0.0, f64::max);
            worst[1] = worst[1].max(e / scale);
        }
    }
    worst
}

/// A rigid motion of 90° about an oblique axis plus a translation moves the
/// mesh rigidly, undeformed and deformed (a finite bending, twist and modes).
#[test]
fn rigid_motion_moves_the_mesh_rigidly() {
    let (part, model, se) = bar();
    let data = &se.data;
    let k = data.n_modes();
    let (p, q) = (part.settings.p, part.settings.q);
    let axis: [f64; 3] = [1.0, -2.0, 0.5];
    let na = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let v = axis.map(|a| a * std::f64::consts::FRAC_PI_2 / na);
    let (qm, t) = (rot(v), [0.3, -1.2, 2.0]);
    let mv = |x: [f64; 3]| -> [f64; 3] {
        let r = apply(&qm, x);
        std::array::from_fn(|i| r[i] + t[i])
    };
    let mut rec = MeshRecovery::new(data).unwrap();
    let size = 0.2;
    // undeformed: the mesh itself, moved
    let x = coords(mv(p), quat(v), mv(q), quat(v), &vec![0.0; k]);
    let pos = positions(&mut rec, &x);
    let mut worst = 0.0f64;
    for (a, b) in pos.iter().zip(model.coords()) {
        let e = mv(*b);
        worst = (0..3).fold(worst, |w, d| w.max((a[d] - e[d]).abs()));
    }
    // deformed: q moved and turned, the modes excited, then the same rigid motion
    let dq = [q[0] + 0.002, q[1] + 0.003, q[2] - 0.001];
    let lq = quat([0.05, 0.02, -0.03]);
    let lp = quat([0.01, -0.02, 0.04]);
    let eta: Vec<f64> = (0..k).map(|i| 1e-3 * (i as f64 + 1.0)).collect();
    let xd = coords(p, lp, dq, lq, &eta);
    let pd = positions(&mut rec, &xd);
    let qv = quat(v);
    let comp = |a: [f64; 4], b: [f64; 4]| -> [f64; 4] {
        [
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
        ]
    };
    let xm = coords(mv(p), comp(qv, lp), mv(dq), comp(qv, lq), &eta);
    let pm = positions(&mut rec, &xm);
    let mut moved = 0.0f64;
    for ((a, b), c) in pm.iter().zip(&pd).zip(model.coords()) {
        let e = mv(*b);
        worst = (0..3).fold(worst, |w, d| w.max((a[d] - e[d]).abs()));
        moved = (0..3).fold(moved, |w, d| w.max((b[d] - c[d]).abs()));
    }
    println!(
        "rigid motion: worst {worst:.2e} m on a {size} m part; deformation up to {moved:.2e} m"
    );
    assert!(moved > 1e-3, "the deformed case deforms: {moved:e}");
    assert!(worst < 1e-13, "not rigid: {worst:e}");
}

/// The section round-trips through the RON file, is left out with
/// `fe_mesh: false`, and a file written before it existed still loads (and
/// the recovery says what is missing).
#[test]
fn files_with_and_without_the_mesh_section() {
    let (part, model, se) = bar();
    let mesh = se.data.fe_mesh.as_ref().unwrap();
    assert_eq!(mesh.nodes.len(), model.n_nodes());
    assert_eq!(mesh.cells.len(), 40);
    assert!(mesh
        .cells
        .iter()
        .all(|c| c.vtk_type == 25 && c.nodes.len() == 20));
    assert_eq!(mesh.recovery[0].len(), 3 * (6 + se.data.n_modes()));
    let dir = std::env::temp_dir().join(format!("flexmb-semesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bar.se.ron");
    write_ron(&path, &se.data).unwrap();
    assert_eq!(read_ron(&path).unwrap(), se.data);
    // an unknown field in the section is an error naming it
    let text = std::fs::read_to_string(&path).unwrap();
    let bad = text.replacen("recovery:", "recover:", 1);
    std::fs::write(&path, bad).unwrap();
    let e = read_ron(&path).unwrap_err().to_string();
    assert!(e.contains("recover"), "{e}");
    // fe_mesh: false leaves it out
    let mut s = part.settings.clone();
    s.fe_mesh = false;
    let plain = build(&model, &s).unwrap();
    assert!(plain.data.fe_mesh.is_none());
    write_ron(&path, &plain.data).unwrap();
    assert!(!std::fs::read_to_string(&path).unwrap().contains("fe_mesh"));
    std::fs::remove_dir_all(&dir).unwrap();
    // the fixture written before the section
    let old: LinearSuperelement =
        read_ron(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fuzz/bar.se.ron"))
            .unwrap();
    assert!(old.fe_mesh.is_none());
    old.validate().unwrap();
    let e = MeshRecovery::new(&old).err().unwrap().to_string();
    assert!(e.contains("fe_mesh"), "{e}");
}

/// A mesh section with a cell of an unknown VTK type, or with the wrong
/// number of nodes for its type, is refused naming the cell.
#[test]
fn a_mesh_cell_of_another_type_or_size_is_refused_naming_it() {
    let (_, _, se) = bar();
    let mut data = se.data.clone();
    data.validate().unwrap();
    data.fe_mesh.as_mut().unwrap().cells[0].vtk_type = 99;
    let e = data.validate().unwrap_err().to_string();
    assert!(e.contains("cell 0 has VTK type 99"), "{e}");
    let mut data = se.data.clone();
    data.fe_mesh.as_mut().unwrap().cells[3].nodes.pop();
    let e = data.validate().unwrap_err().to_string();
    assert!(
        e.contains("cell 3 (VTK type 25) has 19 nodes, the type has 20"),
        "{e}"
    );
}
