//! Every linearized matrix of (E.5) against central differences of the
//! residual g(q, q̇, q̈, t) of (E.1) at random states with velocities and
//! accelerations (relative 1e-6), on mechanisms with constraints, gravity,
//! prescribed inputs, controllers and both kinds of DOFs.

use flexmb_dynamics::Dynamics;
use flexmb_model::{DofChoice, Scene};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::path::Path;
use std::sync::Arc;

fn dynamics(name: &str, dofs: Option<DofChoice>) -> Dynamics {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    let mut s = Scene::load(&p).unwrap();
    if let Some(d) = dofs {
        s.dofs = d;
    }
    Dynamics::new(Arc::new(s.build(None).unwrap()))
}

fn check(name: &str, dofs: Option<DofChoice>, t: f64, q_scale: f64, v_scale: f64) {
    let mut rng = StdRng::seed_from_u64(7);
    let mut dy = dynamics(name, dofs);
    // differences of g amplify the position-solve tolerance by S/h: solve to rounding level
    dy.kinematics_mut()
        .set_newton_options(flexmb_kinematics::NewtonOptions {
            tol: 1e-16,
            max_iterations: 40,
        });
    let n = dy.n_q();
    let q: Vec<f64> = dy
        .mechanism()
        .q0()
        .iter()
        .map(|v| v + q_scale * rng.random_range(-1.0..1.0))
        .collect();
    let qd: Vec<f64> = (0..n)
        .map(|_| v_scale * rng.random_range(-1.0..1.0))
        .collect();
    let qdd: Vec<f64> = (0..n)
        .map(|_| v_scale * rng.random_range(-10.0..10.0))
        .collect();
    let lin = dy.linearize(t, &q, &qd, &qdd).unwrap();
    let g = |dy: &mut Dynamics, q: &[f64], qd: &[f64], qdd: &[f64]| {
        let mut r = vec![0.0; n];
        dy.residual(t, q, qd, qdd, &mut r).unwrap();
        r
    };
    // g is linear in q̈ and quadratic in q̇: central differences in those are
    // exact for any step, so a large one keeps rounding out; in q a small one
    let (h, hv) = (1e-6, 0.1);
    let mut fd_q = faer::Mat::<f64>::zeros(n, n);
    let mut fd_qd = faer::Mat::<f64>::zeros(n, n);
    let mut fd_qdd = faer::Mat::<f64>::zeros(n, n);
    for k in 0..n {
        let pert = |v: &[f64], s: f64| -> Vec<f64> {
            let mut w = v.to_vec();
            w[k] += s;
            w
        };
        let (a, b) = (
            g(&mut dy, &pert(&q, h), &qd, &qdd),
            g(&mut dy, &pert(&q, -h), &qd, &qdd),
        );
        let (c, d) = (
            g(&mut dy, &q, &pert(&qd, hv), &qdd),
            g(&mut dy, &q, &pert(&qd, -hv), &qdd),
        );
        let (e, f) = (
            g(&mut dy, &q, &qd, &pert(&qdd, hv)),
            g(&mut dy, &q, &qd, &pert(&qdd, -hv)),
        );
        for r in 0..n {
            fd_q[(r, k)] = (a[r] - b[r]) / (2.0 * h);
            fd_qd[(r, k)] = (c[r] - d[r]) / (2.0 * hv);
            fd_qdd[(r, k)] = (e[r] - f[r]) / (2.0 * hv);
        }
    }
    let cmp = |what: &str, got: &faer::Mat<f64>, fd: &faer::Mat<f64>| {
        let mut mx = 0.0f64;
        let mut err = 0.0f64;
        for r in 0..n {
            for c in 0..n {
                mx = mx.max(fd[(r, c)].abs());
                err = err.max((got[(r, c)] - fd[(r, c)]).abs());
            }
        }
        assert!(
            err <= 1e-6 * mx,
            "{name}: {what} error {err:e} relative to {mx:e}"
        );
    };
    cmp("M = g,q̈", &lin.m, &fd_qdd);
    cmp("D + C = g,q̇", &lin.damping_total(), &fd_qd);
    cmp("K + G + N = g,q", &lin.stiffness_total(), &fd_q);
}

#[test]
fn spatial_guidance_with_gravity_deformation_dofs() {
    check("straight_guidance_spatial.ron", None, 0.05, 2e-3, 0.3);
}

#[test]
fn spatial_guidance_with_gravity_nodal_dofs() {
    check(
        "straight_guidance_spatial.ron",
        Some(DofChoice::NodalCoordinates),
        0.05,
        2e-3,
        0.3,
    );
}

#[test]
fn universal_joint_with_prescribed_inputs() {
    check("spin_up_universal_joint.ron", None, 7.0, 1e-2, 0.5);
}

#[test]
fn pd_controlled_manipulator() {
    check("manipulator_planar.ron", None, 0.2, 1e-2, 1.0);
}

#[test]
fn linearization_at_rest_equals_the_general_one_without_motion() {
    let mut dy = dynamics("straight_guidance_spatial.ron", None);
    let n = dy.n_q();
    let q: Vec<f64> = dy
        .mechanism()
        .q0()
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-4 * ((i % 5) as f64 - 2.0))
        .collect();
    let z = vec![0.0; n];
    let a = dy.linearize(0.5, &q, &z, &z).unwrap();
    let b = dy.linearize_at_rest(0.5, &q).unwrap();
    let diff = |x: &faer::Mat<f64>, y: &faer::Mat<f64>| {
        let mut d = 0.0f64;
        let mut m = 0.0f64;
        for r in 0..n {
            for c in 0..n {
                d = d.max((x[(r, c)] - y[(r, c)]).abs());
                m = m.max(x[(r, c)].abs());
            }
        }
        d / m.max(1e-300)
    };
    assert!(diff(&a.m, &b.m) < 1e-12);
    assert!(diff(&a.k, &b.k) < 1e-12);
    assert!(diff(&a.g, &b.g) < 1e-9, "{}", diff(&a.g, &b.g));
    assert!(diff(&a.stiffness_total(), &b.stiffness_total()) < 1e-9);
}

/// A load sweep scales the nodal loads, not gravity: the static
/// out-of-balance at load scale 0 still carries gravity (and equals the one at
/// scale 1 while the force pulse is zero), and the static tangent matches
/// differences of the out-of-balance at a scale ≠ 1 with gravity on.
#[test]
fn load_scale_scales_the_loads_but_not_gravity() {
    let mut dy = dynamics("straight_guidance_spatial.ron", None);
    let q: Vec<f64> = dy
        .mechanism()
        .q0()
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * ((i as f64) * 0.7).sin())
        .collect();
    dy.set_load_scale(0.0);
    let (g0, _) = dy.static_tangent(0.0, &q).unwrap();
    dy.set_load_scale(1.0);
    let (g1, _) = dy.static_tangent(0.0, &q).unwrap();
    let gravity_free = {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/scenes/straight_guidance_spatial.ron");
        let mut s = Scene::load(&p).unwrap();
        s.gravity = None;
        let mut d = Dynamics::new(Arc::new(s.build(None).unwrap()));
        d.static_tangent(0.0, &q).unwrap().0
    };
    let diff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        diff(&g0, &g1) < 1e-12,
        "gravity must not follow the load scale"
    );
    assert!(
        diff(&g0, &gravity_free) > 1e-3,
        "gravity acts at load scale 0"
    );
    // tangent against central differences at scale 0.4 while the pulse acts
    let t = 0.05;
    dy.set_load_scale(0.4);
    let (_, k) = dy.static_tangent(t, &q).unwrap();
    let h = 1e-7;
    for j in [0, 7, 21, 40] {
        let mut qp = q.clone();
        qp[j] += h;
        let mut qm = q.clone();
        qm[j] -= h;
        let gp = dy.static_tangent(t, &qp).unwrap().0;
        let gm = dy.static_tangent(t, &qm).unwrap().0;
        for i in 0..q.len() {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            assert!(
                (fd - k[(i, j)]).abs() < 1e-5 * (1.0 + k[(i, j)].abs()),
                "K[{i},{j}] = {} against {fd}",
                k[(i, j)]
            );
        }
    }
}

/// The residual is formed through the nodal accelerations ẍ0 + F,q q̈
/// without Mq: it equals Mq q̈ − F,qᵀ(f − Mx ẍ0 − h) + E,qᵀσ from the mass
/// matrix and force of (D.10), at random states of a chain whose F,q is
/// dense (the flexure chain, every node depends on the DOFs upstream) and of
/// the guidance with nodal DOFs.
#[test]
fn the_residual_equals_the_mass_matrix_times_the_accelerations_minus_the_force() {
    for (name, dofs) in [
        ("flexure_chain_720.ron", None),
        (
            "straight_guidance_spatial.ron",
            Some(DofChoice::NodalCoordinates),
        ),
    ] {
        let mut rng = StdRng::seed_from_u64(3);
        let mut dy = dynamics(name, dofs);
        let n = dy.n_q();
        let q: Vec<f64> = dy
            .mechanism()
            .q0()
            .iter()
            .map(|v| v + 1e-3 * rng.random_range(-1.0..1.0))
            .collect();
        let qd: Vec<f64> = (0..n).map(|_| rng.random_range(-0.1..0.1)).collect();
        let qdd: Vec<f64> = (0..n).map(|_| rng.random_range(-10.0..10.0)).collect();
        let mut g = vec![0.0; n];
        dy.residual(0.1, &q, &qd, &qdd, &mut g).unwrap();
        let (mq, rhs) = dy.mass_and_force(0.1, &q, &qd).unwrap();
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for r in 0..n {
            let mut want = -rhs[r];
            for c in 0..n {
                want += mq[(r, c)] * qdd[c];
            }
            worst = worst.max((g[r] - want).abs());
            scale = scale.max(want.abs());
        }
        assert!(scale > 0.0);
        assert!(
            worst <= 1e-11 * scale,
            "{name}: residual off by {worst:e} of {scale:e}"
        );
    }
}
