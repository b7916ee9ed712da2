//! The interpolated basis method: modal subspace interpolation through a
//! synthetic veering, and the derivatives of G against differences.

use faer::Mat;
use flexmb_linearize::generalized_symmetric;
use flexmb_reduction::*;

/// K(s) = diag(0.5, 2 + s, 2 − s) with coupling c between DOFs 2 and 3, M = I:
/// modes 2 and 3 veer at s = 0 (gap 2c).
fn veering_modes(c: f64, s: &[f64]) -> Vec<Mat<f64>> {
    s.iter()
        .map(|&x| {
            let k = Mat::from_fn(3, 3, |i, j| match (i, j) {
                (0, 0) => 0.5,
                (1, 1) => 2.0 + x,
                (2, 2) => 2.0 - x,
                (1, 2) | (2, 1) => c,
                _ => 0.0,
            });
            let m = generalized_symmetric(&k, &Mat::identity(3, 3), 3).unwrap();
            Mat::from_fn(3, 2, |i, j| m.vectors[(i, 1 + j)])
        })
        .collect()
}

#[test]
fn msi_spans_the_eigenvector_subspaces_and_stays_smooth_through_a_veering() {
    let s: Vec<f64> = (0..41).map(|i| -1.0 + 0.05 * i as f64).collect();
    let v = veering_modes(0.01, &s);
    let w = modal_subspace_interpolation(&v, None);
    // the same subspace at every node
    for (vi, wi) in v.iter().zip(&w) {
        let a = largest_principal_angle(vi, wi).unwrap();
        assert!(a < 1e-10, "largest principal angle {a:e}");
    }
    // derivatives of the interpolated bases
    let q0 = vec![0.0; 3];
    let qs: Vec<Vec<f64>> = s.iter().map(|_| vec![0.0; 3]).collect();
    let msi = InterpolatedBasis::new(
        q0.clone(),
        s.clone(),
        &qs,
        &v,
        None,
        SubspaceInterpolation::Msi,
    )
    .unwrap();
    let mac = InterpolatedBasis::new(
        q0,
        s.clone(),
        &qs,
        &v,
        None,
        SubspaceInterpolation::MacSorted,
    )
    .unwrap();
    let max_derivative = |b: &InterpolatedBasis| {
        (0..401)
            .map(|k| -1.0 + 0.005 * k as f64)
            .map(|x| {
                let d = &b.v_and_derivatives(x)[1];
                (0..3)
                    .flat_map(|i| (0..2).map(move |j| (i, j)))
                    .fold(0.0f64, |m, (i, j)| m.max(d[(i, j)].abs()))
            })
            .fold(0.0f64, f64::max)
    };
    let (dw, dv) = (max_derivative(&msi), max_derivative(&mac));
    eprintln!("max |V'(s)|: MSI {dw:.3e}, MAC-sorted eigenvectors {dv:.3e}");
    assert!(
        dw < 1e-8,
        "MSI base vectors stay constant in this veering: |W'| = {dw:e}"
    );
    assert!(
        dv > 10.0,
        "MAC-sorted eigenvectors rotate quickly through the veering: |V'| = {dv:e}"
    );
}

/// A smooth interpolated basis from analytic data.
fn smooth_basis() -> InterpolatedBasis {
    let n = 5;
    let s: Vec<f64> = (0..9).map(|i| 0.1 * i as f64).collect();
    let qs: Vec<Vec<f64>> = s
        .iter()
        .map(|x| (0..n).map(|i| (x * (i + 1) as f64).sin()).collect())
        .collect();
    let v: Vec<Mat<f64>> = s
        .iter()
        .map(|x| {
            Mat::from_fn(n, 2, |i, j| {
                ((i + 2 * j) as f64 * 0.7 + x * (1.0 + j as f64)).cos()
            })
        })
        .collect();
    InterpolatedBasis::new(vec![0.3; n], s, &qs, &v, None, SubspaceInterpolation::Msi).unwrap()
}

#[test]
fn derivatives_of_g_match_differences() {
    let b = smooth_basis();
    let n = b.n_q();
    let z = [0.33, 0.4, -0.7];
    let zd = [0.8, -0.5, 1.3];
    let g = |z: &[f64]| {
        let mut q = vec![0.0; n];
        let mut gz = Mat::zeros(n, 3);
        let mut c = vec![0.0; n];
        b.eval(z, &[0.0; 3], &mut q, &mut gz, &mut c);
        (q, gz)
    };
    let (q, gz) = g(&z);
    let h = 1e-6;
    // G,z by columns
    for k in 0..3 {
        let mut zp = z;
        zp[k] += h;
        let mut zm = z;
        zm[k] -= h;
        let (qp, qm) = (g(&zp).0, g(&zm).0);
        for i in 0..n {
            let fd = (qp[i] - qm[i]) / (2.0 * h);
            assert!(
                (fd - gz[(i, k)]).abs() < 1e-7,
                "G,z[{i},{k}]: {} vs {fd}",
                gz[(i, k)]
            );
        }
    }
    // (G,zz ż)ż = d²/dt² G(z + t ż) at t = 0
    let mut q_ = vec![0.0; n];
    let mut gz_ = Mat::zeros(n, 3);
    let mut conv = vec![0.0; n];
    b.eval(&z, &zd, &mut q_, &mut gz_, &mut conv);
    let along =
        |t: f64| -> Vec<f64> { g(&[z[0] + t * zd[0], z[1] + t * zd[1], z[2] + t * zd[2]]).0 };
    let hh = 1e-4;
    let (p, m) = (along(hh), along(-hh));
    for i in 0..n {
        let fd = (p[i] - 2.0 * q[i] + m[i]) / (hh * hh);
        assert!(
            (fd - conv[i]).abs() < 1e-5 * (1.0 + conv[i].abs()),
            "(G,zz ż)ż[{i}]: {} vs {fd}",
            conv[i]
        );
    }
    // third derivative along ż: d³/dt³ G(z + t ż)
    let mut third = vec![0.0; n];
    b.third_derivative(&z, &zd, &mut third);
    let h3 = 1e-3;
    let (p2, p1, m1, m2) = (along(2.0 * h3), along(h3), along(-h3), along(-2.0 * h3));
    for i in 0..n {
        let fd = (p2[i] - 2.0 * p1[i] + 2.0 * m1[i] - m2[i]) / (2.0 * h3 * h3 * h3);
        assert!(
            (fd - third[i]).abs() < 1e-4 * (1.0 + third[i].abs()),
            "third derivative[{i}]: {} vs {fd}",
            third[i]
        );
    }
}

#[test]
fn ibm_from_unconstrained_eigenvectors_reproduces_the_frequencies_at_its_nodes() {
    // planar straight guidance with the body's x as a DOF, equilibria under
    // the scaled force (t = 0.05 s, peak of the pulse): at each node the IBM's
    // span {Q'(s), V(s)} contains the first r eigenvectors, so its reduced rest
    // linearization (F.7) has the unreduced first r eigenfrequencies
    use flexmb_dynamics::Dynamics;
    use flexmb_linearize::{sweep, undamped_modes, SweepOptions, SweepParameter};
    use flexmb_model::{Component, Scene, Select};
    use std::sync::Arc;
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_planar.ron");
    let mut sc = Scene::load(&p).unwrap();
    sc.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    let mech = Arc::new(sc.build(None).unwrap());
    let r = 3;
    let values: Vec<f64> = (0..8).map(|i| 0.1 * i as f64).collect();
    let pts = sweep(
        &mech,
        &SweepParameter::LoadScale,
        &SweepOptions {
            values,
            modes: r,
            t: 0.05,
            keep_vectors: true,
        },
        &|_, _| {},
    )
    .unwrap();
    let q0 = mech.q0();
    let s: Vec<f64> = pts.iter().map(|p| p.q[0] - q0[0]).collect();
    let qs: Vec<Vec<f64>> = pts.iter().map(|p| p.q.clone()).collect();
    let vecs: Vec<Mat<f64>> = pts.iter().map(|p| p.modes.clone().unwrap()).collect();
    let basis = InterpolatedBasis::new(
        q0.clone(),
        s.clone(),
        &qs,
        &vecs,
        None,
        SubspaceInterpolation::Msi,
    )
    .unwrap();
    let mut red = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
    for (k, pt) in pts.iter().enumerate() {
        let mut dy = Dynamics::new(mech.clone());
        dy.set_load_scale(0.1 * k as f64);
        let lin = dy.linearize_at_rest(0.05, &pt.q).unwrap();
        let full = undamped_modes(&lin, r).unwrap().frequencies_hz();
        let mut z = vec![0.0; 1 + r];
        z[0] = s[k];
        // the reduced model sees the same load scale
        let (mz, kz) = {
            let dyn_scale = 0.1 * k as f64;
            red.set_load_scale(dyn_scale);
            red.linearize_at_rest(0.05, &z).unwrap()
        };
        let f_red = generalized_symmetric(&kz, &mz, r).unwrap().frequencies_hz();
        for (a, b) in full.iter().zip(&f_red) {
            assert!(
                (a / b - 1.0).abs() < 1e-8,
                "node {k}: unreduced {a} Hz vs IBM {b} Hz"
            );
        }
    }
}
