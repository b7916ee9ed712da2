//! The reduced linearization (F.5) against central differences of the
//! reduced residual (F.1) at states with velocities and accelerations, for an
//! interpolated basis (where G,zz and G,zzz contribute) and a fixed basis; and
//! its rest form against (F.7). Also the path eigenvectors of chapter 7
//! (7.3)–(7.11).

use faer::Mat;
use flexmb_linearize::{sweep, SweepOptions, SweepParameter};
use flexmb_model::{Component, DofChoice, Scene, Select};
use flexmb_reduction::*;
use std::path::Path;
use std::sync::Arc;

fn nodal_guidance() -> Arc<flexmb_model::Mechanism> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_planar.ron");
    let mut s = Scene::load(&p).unwrap();
    s.dofs = DofChoice::NodalCoordinates;
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    Arc::new(s.build(None).unwrap())
}

fn ibm(mech: &Arc<flexmb_model::Mechanism>) -> InterpolatedBasis {
    let x0 = mech.q0()[0];
    let values: Vec<f64> = (0..9).map(|k| x0 - 0.06 + 0.015 * k as f64).collect();
    let pts = sweep(
        mech,
        &SweepParameter::Dof(0),
        &SweepOptions {
            values,
            modes: 4,
            t: 0.0,
            keep_vectors: true,
        },
        &|_, _| {},
    )
    .unwrap();
    interpolated_basis_from_sweep(mech.q0(), 0, &pts, 1..3, SubspaceInterpolation::Msi, true)
        .unwrap()
}

/// Compares (M, D + C, K + G + N) with differences of g_z in z̈, ż and z.
fn check(model: &mut ReducedModel, t: f64, z: &[f64], zd: &[f64], zdd: &[f64]) {
    model
        .dynamics_mut()
        .kinematics_mut()
        .set_newton_options(flexmb_kinematics::NewtonOptions {
            tol: 1e-16,
            max_iterations: 40,
        });
    let lin = model.linearize(t, z, zd, zdd).unwrap();
    let n = z.len();
    let fd = |model: &mut ReducedModel, which: usize, h: f64| -> Mat<f64> {
        let mut cols = vec![];
        for k in 0..n {
            let mut s = [z.to_vec(), zd.to_vec(), zdd.to_vec()];
            let mut m = s.clone();
            s[which][k] += h;
            m[which][k] -= h;
            let gp = model.residual(t, &s[0], &s[1], &s[2]).unwrap();
            let gm = model.residual(t, &m[0], &m[1], &m[2]).unwrap();
            cols.push(
                gp.iter()
                    .zip(&gm)
                    .map(|(a, b)| (a - b) / (2.0 * h))
                    .collect::<Vec<f64>>(),
            );
        }
        Mat::from_fn(n, n, |i, k| cols[k][i])
    };
    for (which, name, exact, h) in [
        (2, "Mz", &lin.m, 1e-3),
        (1, "Dz + Cz", &lin.damping, 1e-3), // g is quadratic in ż: central differences are exact up to rounding
        (0, "Kz + Gz + Nz", &lin.stiffness, 1e-7),
    ] {
        let d = fd(model, which, h);
        let scale = (0..n)
            .flat_map(|i| (0..n).map(move |k| (i, k)))
            .fold(0.0f64, |m, (i, k)| m.max(exact[(i, k)].abs()));
        for i in 0..n {
            for k in 0..n {
                assert!(
                    (d[(i, k)] - exact[(i, k)]).abs() <= 1e-6 * scale,
                    "{name}[{i},{k}]: {} against differences {} (scale {scale:e})",
                    exact[(i, k)],
                    d[(i, k)]
                );
            }
        }
    }
}

#[test]
fn interpolated_basis_linearization_matches_differences_of_the_reduced_residual() {
    let mech = nodal_guidance();
    let b = ibm(&mech);
    let s0 = mech.q0()[0] + 0.021;
    let mut model = ReducedModel::new(mech, Box::new(b)).unwrap();
    check(
        &mut model,
        0.05,
        &[s0, 2e-4, -1e-4],
        &[0.4, 0.05, -0.03],
        &[3.0, -2.0, 5.0],
    );
}

#[test]
fn fixed_basis_linearization_matches_differences_of_the_reduced_residual() {
    let mech = nodal_guidance();
    let b = modal_basis(&mech, 0.0, &mech.q0(), 3, None).unwrap();
    let mut model = ReducedModel::new(mech, Box::new(b)).unwrap();
    check(
        &mut model,
        0.05,
        &[0.01, -0.002, 0.001],
        &[0.3, 0.02, -0.05],
        &[1.0, 4.0, -3.0],
    );
}

#[test]
fn at_rest_in_equilibrium_the_linearization_is_the_rest_form() {
    let mech = nodal_guidance();
    let b = ibm(&mech);
    let mut model = ReducedModel::new(mech.clone(), Box::new(b)).unwrap();
    let z0 = model.basis().z_reference();
    let z = model
        .newton_equilibrium(0.0, &[z0[0] + 0.02, 0.0, 0.0], &[0])
        .unwrap();
    let lin = model.linearize(0.0, &z, &[0.0; 3], &[0.0; 3]).unwrap();
    let (mz, kz) = model.linearize_at_rest(0.0, &z).unwrap();
    let diff = |a: &Mat<f64>, b: &Mat<f64>| {
        let mut m = 0.0f64;
        let mut s = 0.0f64;
        for i in 0..a.nrows() {
            for j in 0..a.ncols() {
                m = m.max((a[(i, j)] - b[(i, j)]).abs());
                s = s.max(b[(i, j)].abs());
            }
        }
        m / s
    };
    assert!(diff(&lin.m, &mz) < 1e-12);
    // with s held the reduced equilibrium carries a reaction on s: the rest
    // form (F.7e) keeps the same G,zzᵀ g term as (F.5e)
    assert!(
        diff(&lin.stiffness, &kz) < 1e-9,
        "{}",
        diff(&lin.stiffness, &kz)
    );
}

/// Constrained eigenvectors (7.3)–(7.5) with the path along a DOF equal the
/// modes with that DOF clamped; unconstrained path eigenvectors (7.6)–(7.11)
/// of a one-DOF mechanism are the orthonormalized modes 2..r: perpendicular to
/// the first (along the path), spanning the rest of the modes' subspace.
#[test]
fn path_eigenvectors_on_the_guidance() {
    let mech = nodal_guidance();
    let mut dy = flexmb_dynamics::Dynamics::new(mech.clone());
    let x0 = mech.q0()[0];
    let o = flexmb_dynamics::StaticOptions {
        held: vec![(0, x0 + 0.04)],
        ..Default::default()
    };
    let q = dy.static_equilibrium(0.0, &mech.q0(), &o).unwrap().q;
    let lin = dy.linearize_at_rest(0.0, &q).unwrap();
    let (k, m) = (lin.stiffness_total(), lin.m.clone());
    let n = k.nrows();
    let mut qs = vec![0.0; n];
    qs[0] = 1.0;
    let (v, f) = constrained_eigenvectors(&k, &m, &qs, 3).unwrap();
    let kc = Mat::from_fn(n - 1, n - 1, |i, j| k[(i + 1, j + 1)]);
    let mc = Mat::from_fn(n - 1, n - 1, |i, j| m[(i + 1, j + 1)]);
    let clamped = flexmb_linearize::generalized_symmetric(&kc, &mc, 3)
        .unwrap()
        .frequencies_hz();
    for j in 0..3 {
        assert!(
            (f[j] - clamped[j]).abs() < 1e-8 * clamped[j],
            "{} against {}",
            f[j],
            clamped[j]
        );
        assert!(v[(0, j)].abs() < 1e-12, "no motion along the path");
    }
    // unconstrained: Vu = first 4 modes; path row = the S.x row of F,q (a DOF: e_0)
    let modes = flexmb_linearize::undamped_modes(&lin, 4).unwrap();
    let f_p = Mat::from_fn(1, n, |_, j| if j == 0 { 1.0 } else { 0.0 });
    let vpath = unconstrained_path_eigenvectors(&modes.vectors, &f_p, &[1.0]).unwrap();
    assert_eq!(vpath.ncols(), 3);
    let v1: Vec<f64> = (0..n).map(|i| modes.vectors[(i, 0)]).collect();
    for j in 0..3 {
        let d: f64 = (0..n).map(|i| vpath[(i, j)] * v1[i]).sum();
        assert!(
            d.abs() < 1e-12,
            "column {j} is not perpendicular to the first mode: {d:e}"
        );
    }
    let all = Mat::from_fn(n, 4, |i, j| if j == 0 { v1[i] } else { vpath[(i, j - 1)] });
    let angle = largest_principal_angle(&all, &modes.vectors).unwrap();
    assert!(
        angle < 1e-10,
        "span differs from modes 1–4 by {angle:e} rad"
    );
}

/// With two path coordinates, V_b of (7.6) is perpendicular to the motion
/// along the path (7.7) and [V_b, V_a] has r − 1 columns spanning the
/// complement of V_p η_p within the eigenvectors' span.
#[test]
fn unconstrained_path_eigenvectors_remove_the_path_direction() {
    let k = 6;
    let vu = Mat::from_fn(k, 4, |i, j| {
        ((1 + i) as f64 * 0.37 + (j * j) as f64 * 0.91).sin()
    });
    let f_p = Mat::from_fn(2, k, |i, j| {
        if j == 2 * i {
            1.0
        } else {
            0.1 * (i + j) as f64
        }
    });
    let p_s = [0.6, -0.8];
    let v = unconstrained_path_eigenvectors(&vu, &f_p, &p_s).unwrap();
    assert_eq!((v.nrows(), v.ncols()), (k, 3));
    // the direction V_p η_p: solve [f_p V_p] η = p_s with V_p the first two orthonormalized vectors
    let vo = orthonormalize(&vu);
    let vp = Mat::from_fn(k, 2, |i, j| vo[(i, j)]);
    let a = &f_p * &vp;
    let det = a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)];
    let eta = [
        (a[(1, 1)] * p_s[0] - a[(0, 1)] * p_s[1]) / det,
        (a[(0, 0)] * p_s[1] - a[(1, 0)] * p_s[0]) / det,
    ];
    let dir: Vec<f64> = (0..k)
        .map(|i| vp[(i, 0)] * eta[0] + vp[(i, 1)] * eta[1])
        .collect();
    let d: f64 = (0..k).map(|i| v[(i, 0)] * dir[i]).sum();
    assert!(d.abs() < 1e-13, "V_bᵀ V_p η_p = {d:e} (7.7)");
    // the path direction reproduces P,s through the path rows
    for (r, ps) in p_s.iter().enumerate() {
        let fp: f64 = (0..k).map(|j| f_p[(r, j)] * dir[j]).sum();
        assert!((fp - ps).abs() < 1e-12);
    }
    // [dir, V] spans the same space as Vu
    let mut all = Mat::zeros(k, 4);
    for i in 0..k {
        all[(i, 0)] = dir[i];
        for j in 0..3 {
            all[(i, j + 1)] = v[(i, j)];
        }
    }
    assert!(largest_principal_angle(&all, &vu).unwrap() < 1e-10);
    assert!(unconstrained_path_eigenvectors(&vu, &f_p, &[0.0, 0.0]).is_err());
}
