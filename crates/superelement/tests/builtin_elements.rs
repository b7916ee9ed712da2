//! The built-in solid elements against CalculiX (`ccx` 2.20, an independent
//! code): one distorted element of each kind (4- and 10-node tetrahedra, 8-
//! and 20-node hexahedra, 6- and 15-node wedges) through
//! `SolidMesh::assemble` and through `run_calculix` (the deck the builder
//! writes, `*FREQUENCY, SOLVER=MATRIXSTORAGE`). K must agree to rounding
//! (CalculiX prints 14 digits); M too, except on the 4-node tetrahedron
//! and the 6-node wedge, whose CalculiX mass is integrated at one point of
//! the triangle and loses the rigid-body inertia even of an undistorted
//! element (the built-in one takes more points). M applied to rigid motions
//! gives each element's volume moments × ρ where the rules are exact for
//! them: on affine images (rotated, sheared) of the reference elements.
//!
//! Needs `ccx` (Debian package `calculix-ccx`); fails, never skips, without it.

use flexmb_superelement::geometry::{element_moments, SolidKind};
use flexmb_superelement::mesh_file::{run_calculix, MeshFile, MeshMaterial};
use flexmb_superelement::FeModel;

const MATERIAL: MeshMaterial = MeshMaterial {
    e: 1000.0,
    nu: 0.3,
    rho: 2.0,
};

/// Corners and midside edges (Abaqus order) of the reference elements.
fn reference(kind: SolidKind) -> Vec<[f64; 3]> {
    let tet = vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let hex = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    let wedge = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [0., 1., 1.],
    ];
    let corners = match kind {
        SolidKind::Tet4 | SolidKind::Tet10 => tet,
        SolidKind::Hex8 | SolidKind::Hex20 => hex,
        SolidKind::Wedge6 | SolidKind::Wedge15 => wedge,
    };
    let mut x = corners.clone();
    for &(a, b) in kind.midside_edges() {
        x.push(std::array::from_fn(|d| {
            0.5 * (corners[a][d] + corners[b][d])
        }));
    }
    x
}

/// One element of `kind`: an affine image (stretched, sheared, turned) of
/// the reference element, distorted by a deterministic perturbation of
/// `distortion` × its size (curved edges on the quadratic ones).
fn one_element(kind: SolidKind, distortion: f64) -> MeshFile {
    let a = [[1.2, 0.3, -0.1], [-0.2, 0.9, 0.25], [0.1, -0.15, 1.1]];
    let coords: Vec<[f64; 3]> = reference(kind)
        .iter()
        .enumerate()
        .map(|(i, p)| {
            std::array::from_fn(|d| {
                (0..3).map(|k| a[d][k] * p[k]).sum::<f64>()
                    + distortion * ((7 * i + 3 * d) as f64).sin()
            })
        })
        .collect();
    let n = coords.len();
    MeshFile {
        ids: (1..=n as u64).collect(),
        coords,
        kinds: vec![kind],
        elements: vec![(0..n).collect()],
        element_ids: vec![1],
        groups: vec![],
        files: vec![],
    }
}

/// A model's matrix as a dense array over (node label order, direction).
fn dense(model: &FeModel, m: bool) -> Vec<Vec<f64>> {
    let a = if m { model.m() } else { model.k() };
    let n = model.n_eq();
    let mut out = vec![vec![0.0; n]; n];
    let slot = |e: usize| {
        let (node, d) = model.dofs().dof(e);
        3 * (model.node_ids()[node] as usize - 1) + d as usize
    };
    for j in 0..n {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            out[slot(i)][slot(j)] = v;
            out[slot(j)][slot(i)] = v;
        }
    }
    out
}

fn largest_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut d = 0.0f64;
    for (ra, rb) in a.iter().zip(b) {
        for (x, y) in ra.iter().zip(rb) {
            d = d.max((x - y).abs());
        }
    }
    d / scale
}

#[test]
fn every_builtin_element_equals_calculix() {
    let dir = std::env::temp_dir().join(format!("flexmb-builtin-elements-{}", std::process::id()));
    for kind in SolidKind::ALL {
        let mesh = one_element(kind, 0.03);
        let own = mesh
            .solid_mesh(MATERIAL.material().unwrap())
            .assemble("own", "test")
            .unwrap();
        let job = dir.join(format!("{kind:?}")).join("element");
        let (ccx, _) = run_calculix(&mesh, &MATERIAL, &job, "one element")
            .unwrap_or_else(|e| panic!("{kind:?}: {e} (install calculix-ccx)"));
        assert_eq!(own.n_eq(), ccx.n_eq());
        let dk = largest_difference(&dense(&ccx, false), &dense(&own, false));
        let dm = largest_difference(&dense(&ccx, true), &dense(&own, true));
        println!("{kind:?}: K {dk:.1e}, M {dm:.1e}");
        assert!(dk < 5e-12, "{kind:?}: K differs from CalculiX's by {dk:e}");
        if !matches!(kind, SolidKind::Tet4 | SolidKind::Wedge6) {
            assert!(dm < 5e-12, "{kind:?}: M differs from CalculiX's by {dm:e}");
        }
        // M applied to rigid motions: the element's volume moments × ρ
        let affine = one_element(kind, 0.0);
        let own = affine
            .solid_mesh(MATERIAL.material().unwrap())
            .assemble("own", "test")
            .unwrap();
        let c = own.compare_rigid_body().expect("densities known");
        assert!(c.worst() < 1e-12, "{kind:?}: rigid body {:?}", c.difference);
        let m = element_moments(kind, &affine.coords, [0.0; 3]).unwrap();
        assert!((c.from_m.mass / (MATERIAL.rho * m.volume) - 1.0).abs() < 1e-12);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
