//! The reduced equations of motion (6.15) evaluated with the reduced
//! transfer matrix F,z = F,q G,z (`ReducedModel::accelerations`: n_z solves
//! with the kinematic Jacobian, Mz by element blocks) against the projection
//! of the unreduced Mq (`ReducedModel::accelerations_from_full_mass`), on
//! every kind of reduced model: modal (with kept large coordinates too),
//! SVD-modal, per-mode SVD, interpolated with MSI and with MAC-sorted
//! eigenvectors; deformation and absolute nodal DOFs; with and without
//! gravity; prescribed nodal coordinates and prescribed deformations; PD
//! controllers; a 720-DOF model whose kinematic Jacobian is factorized
//! sparsely. With the identity basis it is also checked against the
//! unreduced nodal solve with multipliers (`Dynamics::accelerations`), a
//! third, independent way to the same accelerations.
//!
//! The states are off the reference configuration, moving, and loaded, and
//! follow each other as in a simulation: the new path solves with the
//! factorization of the previous state's J and refines; the reference
//! factorizes at every state.

use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_linearize::{sweep, SweepOptions, SweepParameter, SweepPoint};
use flexmb_model::{Component, DofChoice, Mechanism, Scene, Select};
use flexmb_reduction::*;
use std::path::Path;
use std::sync::Arc;

/// Relative agreement asked of the two evaluations: the largest difference
/// of z̈ over the largest |z̈|.
const RTOL: f64 = 1e-10;

fn scene(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap()
}

fn build(s: &Scene) -> Arc<Mechanism> {
    Arc::new(s.clone().build(None).unwrap())
}

/// A scene in absolute nodal coordinates with the x of node `node` first.
fn nodal(mut s: Scene, node: &str) -> Scene {
    s.dofs = DofChoice::NodalCoordinates;
    s.dofs_first = vec![Select::Coord(node.into(), Component::X)];
    s
}

fn without_gravity(mut s: Scene) -> Scene {
    s.gravity = None;
    s
}

fn held_sweep(mech: &Arc<Mechanism>, values: Vec<f64>, modes: usize) -> Vec<SweepPoint> {
    let o = SweepOptions {
        values,
        modes,
        t: 0.0,
        keep_vectors: true,
    };
    sweep(mech, &SweepParameter::Dof(0), &o, &|_, _| {}).unwrap()
}

fn load_sweep(mech: &Arc<Mechanism>, values: Vec<f64>, t: f64, modes: usize) -> Vec<SweepPoint> {
    let o = SweepOptions {
        values,
        modes,
        t,
        keep_vectors: true,
    };
    sweep(mech, &SweepParameter::LoadScale, &o, &|_, _| {}).unwrap()
}

fn around(x0: f64, half: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| x0 - half + 2.0 * half * i as f64 / (n - 1) as f64)
        .collect()
}

/// Three successive moving states near the basis's reference: z offset by
/// `dz` (per coordinate, scaled by 1, −0.6, 0.3), ż = `dzd` likewise.
fn states(
    basis: &dyn Basis,
    dz: &[f64],
    dzd: &[f64],
    t: &[f64; 3],
) -> Vec<(f64, Vec<f64>, Vec<f64>)> {
    let z0 = basis.z_reference();
    [1.0, -0.6, 0.3]
        .iter()
        .zip(t)
        .map(|(a, t)| {
            let z = z0.iter().zip(dz).map(|(z, d)| z + a * d).collect();
            let zd = dzd.iter().map(|d| a * d).collect();
            (*t, z, zd)
        })
        .collect()
}

/// Checks that the two evaluations agree within [`RTOL`] over the states,
/// evaluated in their order on one model (new path first), and prints the
/// largest relative difference.
fn check(
    name: &str,
    mech: &Arc<Mechanism>,
    basis: Box<dyn Basis>,
    dz: &[f64],
    dzd: &[f64],
    t: &[f64; 3],
) {
    let st = states(basis.as_ref(), dz, dzd, t);
    let mut model = ReducedModel::new(mech.clone(), basis).unwrap();
    let n = model.n_z();
    let mut worst = 0.0f64;
    for (t, z, zd) in &st {
        let (mut fast, mut reference) = (vec![0.0; n], vec![0.0; n]);
        model.accelerations(*t, z, zd, &mut fast).unwrap();
        model
            .accelerations_from_full_mass(*t, z, zd, &mut reference)
            .unwrap();
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            scale > 0.0 && scale.is_finite(),
            "{name}: z̈ = {reference:?}"
        );
        let d = fast
            .iter()
            .zip(&reference)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale;
        worst = worst.max(d);
    }
    eprintln!(
        "{name}: n_q = {}, n_z = {n}, largest relative difference {worst:.2e}",
        mech.n_dof()
    );
    assert!(worst <= RTOL, "{name}: z̈ differs by {worst:.2e} of max |z̈|");
}

/// The planar straight guidance (thesis §5.4.1, deformation DOFs, the force
/// pulse): MODAL-3, SVDm-5-a1 and the identity basis.
#[test]
fn fixed_bases_of_the_planar_guidance() {
    let s = scene("straight_guidance_planar.ron");
    let mech = build(&s);
    let t = [0.03, 0.05, 0.07];
    let modal = modal_basis(&mech, 0.0, &mech.q0(), 3, None).unwrap();
    check(
        "planar guidance MODAL-3",
        &mech,
        Box::new(modal),
        &[2e-3, -1e-3, 5e-4],
        &[0.4, 0.3, -0.2],
        &t,
    );
    // SVD-modal from ten configurations along the stroke (S.x first, held)
    let mut sd = s.clone();
    sd.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    let swept_def = build(&sd);
    let x0 = swept_def.q0()[0];
    let pts = held_sweep(&swept_def, around(x0 + 0.04, 0.04, 10), 4);
    let svd = svd_modal_basis(&swept_def.q0(), &pts, 3, 1.0, SVD_THRESHOLD).unwrap();
    let r = svd.basis.v.ncols();
    let dz: Vec<f64> = (0..r).map(|k| 1e-3 / (1 + k) as f64).collect();
    let dzd: Vec<f64> = (0..r).map(|k| 0.3 / (1 + k) as f64).collect();
    check(
        "planar guidance SVDm-a1",
        &swept_def,
        Box::new(svd.basis),
        &dz,
        &dzd,
        &t,
    );
}

/// V = I: the reduced evaluation is the unreduced equations of motion, so
/// it must give the q̈ of the nodal solve with multipliers.
#[test]
fn the_identity_basis_gives_the_unreduced_accelerations() {
    for (name, s) in [
        ("planar guidance", scene("straight_guidance_planar.ron")),
        ("spatial guidance", scene("straight_guidance_spatial.ron")),
        (
            "spatial guidance, nodal DOFs",
            nodal(scene("straight_guidance_spatial.ron"), "S"),
        ),
        ("universal joint", scene("spin_up_universal_joint.ron")),
    ] {
        let mech = build(&s);
        let n = mech.n_dof();
        let basis = FixedBasis {
            q0: mech.q0(),
            v: Mat::identity(n, n),
        };
        let mut model = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
        let mut dy = Dynamics::new(mech.clone());
        let q: Vec<f64> = mech
            .q0()
            .iter()
            .enumerate()
            .map(|(i, v)| v + 1e-4 * ((i % 7) as f64 - 3.0))
            .collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.05 * ((i % 5) as f64 - 2.0)).collect();
        let z: Vec<f64> = q.iter().zip(mech.q0()).map(|(a, b)| a - b).collect();
        let (mut zdd, mut qdd) = (vec![0.0; n], vec![0.0; n]);
        model.accelerations(0.05, &z, &qd, &mut zdd).unwrap();
        dy.accelerations(0.05, &q, &qd, &mut qdd).unwrap();
        let scale = qdd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = zdd
            .iter()
            .zip(&qdd)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale;
        eprintln!("{name}: identity basis against the nodal solve {d:.2e}");
        assert!(scale > 0.0 && d <= 1e-8, "{name}: {d:.2e}");
    }
}

/// The spatial guidance of thesis §6.4 (44 DOF, gravity): MODAL-2 and the
/// per-mode SVD basis of modes 1–2 (SVD-7's procedure) in deformation DOFs,
/// as in chapter 6, and MODAL-2 without gravity.
#[test]
fn fixed_bases_of_the_spatial_guidance() {
    let s = scene("straight_guidance_spatial.ron");
    let (mech, nog) = (build(&s), build(&without_gravity(s)));
    let t = [0.03, 0.05, 0.07];
    let modal = modal_basis(&nog, 0.0, &nog.q0(), 2, None).unwrap();
    check(
        "spatial guidance MODAL-2, gravity",
        &mech,
        Box::new(modal.clone()),
        &[2e-3, -1e-3],
        &[0.4, -0.2],
        &t,
    );
    check(
        "spatial guidance MODAL-2, no gravity",
        &nog,
        Box::new(modal),
        &[2e-3, -1e-3],
        &[0.4, -0.2],
        &t,
    );
    // equilibria under the static x-force (the pulse's value at 0.05 s, 100 N)
    let pts = load_sweep(&nog, around(0.0, 0.3, 7), 0.05, 2);
    let svd =
        per_mode_svd_basis(&nog.q0(), &pts, &[0, 1], SVD_THRESHOLD, FINAL_SVD_THRESHOLD).unwrap();
    let r = svd.basis.v.ncols();
    let dz: Vec<f64> = (0..r).map(|k| 1e-3 / (1 + k) as f64).collect();
    let dzd: Vec<f64> = (0..r).map(|k| 0.3 / (1 + k) as f64).collect();
    check(
        &format!("spatial guidance per-mode SVD ({r} vectors), gravity"),
        &mech,
        Box::new(svd.basis),
        &dz,
        &dzd,
        &t,
    );
}

/// Interpolated bases (thesis (6.23), absolute nodal DOFs, S.x = s): MSI-2
/// and a MAC-sorted MAC-3 over S.x ± 0.06 m, built without gravity and run
/// with and without it, on the spatial and the planar guidance. G,zz ≠ 0
/// here, so the convective term of the basis, (G,zz ż)ż, enters.
#[test]
fn interpolated_bases_with_nodal_dofs() {
    let t = [0.03, 0.05, 0.07];
    for (name, file) in [
        ("spatial guidance", "straight_guidance_spatial.ron"),
        ("planar guidance", "straight_guidance_planar.ron"),
    ] {
        let s = nodal(scene(file), "S");
        let (mech, nog) = (build(&s), build(&without_gravity(s)));
        let x0 = nog.q0()[0];
        let pts = held_sweep(&nog, around(x0, 0.06, 9), 4);
        for (label, r, method) in [
            ("MSI-2", 1, SubspaceInterpolation::Msi),
            ("MAC-3", 2, SubspaceInterpolation::MacSorted),
        ] {
            let basis =
                interpolated_basis_from_sweep(nog.q0(), 0, &pts, 1..1 + r, method, true).unwrap();
            let mut dz = vec![0.021];
            dz.extend((0..r).map(|k| 2e-3 / (1 + k) as f64));
            let mut dzd = vec![0.35];
            dzd.extend((0..r).map(|k| 0.2 / (1 + k) as f64));
            // (the planar guidance has no gravity)
            let runs = match mech.gravity {
                Some(_) => vec![("gravity", &mech), ("no gravity", &nog)],
                None => vec![("no gravity", &nog)],
            };
            for (g, m) in runs {
                check(
                    &format!("{name} {label}, {g}"),
                    m,
                    Box::new(basis.clone()),
                    &dz,
                    &dzd,
                    &t,
                );
            }
        }
    }
}

/// Prescribed coordinates: the spin-up beam (a prescribed nodal angle, thesis
/// §2.4.1) and the universal joint (two prescribed hinge rotations, §2.4.2)
/// with modal bases, during the spin-up (u̇, ü ≠ 0); the transfer matrix
/// F,z leaves the inputs out, ẍ_c carries their accelerations.
#[test]
fn modal_bases_with_prescribed_coordinates() {
    let t = [2.0, 5.5, 9.0];
    for (name, file, r) in [
        ("spin-up beam MODAL-3", "spin_up_planar.ron", 3),
        ("universal joint MODAL-4", "spin_up_universal_joint.ron", 4),
    ] {
        let mech = build(&scene(file));
        let basis = modal_basis(&mech, 0.0, &mech.q0(), r, None).unwrap();
        let dz: Vec<f64> = (0..r).map(|k| 2e-2 / (1 + k) as f64).collect();
        let dzd: Vec<f64> = (0..r).map(|k| 0.5 / (1 + k) as f64).collect();
        check(name, &mech, Box::new(basis), &dz, &dzd, &t);
    }
}

/// The planar manipulator of §5.4.2 (PD controllers on the joints):
/// MODAL-2 with the joint rotations kept (5.20)–(5.21).
#[test]
fn a_modal_basis_with_kept_coordinates_and_controllers() {
    let mech = build(&scene("manipulator_planar.ron"));
    let large: Vec<usize> = mech
        .dofs
        .iter()
        .enumerate()
        .filter(|(_, c)| mech.coordinate_name(**c).starts_with("joint"))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(large.len(), 2);
    let basis = modal_basis(&mech, 0.0, &mech.q0(), 2, Some(&large)).unwrap();
    check(
        "manipulator MODAL-2 (joints kept)",
        &mech,
        Box::new(basis),
        &[0.3, -0.2, 1e-3, -5e-4],
        &[2.0, -1.5, 0.1, 0.05],
        &[0.1, 0.2, 0.3],
    );
}

/// A model much larger than the thesis's: the 720-DOF flexure chain
/// (840 × 840 kinematic Jacobian, factorized sparsely) with 8 modes.
#[test]
fn a_large_model_with_a_sparse_kinematic_jacobian() {
    let mech = build(&scene("flexure_chain_720.ron"));
    let basis = modal_basis(&mech, 0.0, &mech.q0(), 8, None).unwrap();
    let dz: Vec<f64> = (0..8).map(|k| 1e-3 / (1 + k) as f64).collect();
    let dzd: Vec<f64> = (0..8).map(|k| 0.1 / (1 + k) as f64).collect();
    check(
        "flexure chain MODAL-8",
        &mech,
        Box::new(basis),
        &dz,
        &dzd,
        &[0.0, 0.01, 0.02],
    );
}
