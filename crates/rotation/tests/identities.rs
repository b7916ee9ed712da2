//! Euler-parameter identities, checked against independent computations
//! (central differences, orthogonality, round trips).

use flexmb_rotation::EulerParameters;
use nalgebra::{Matrix3, Unit, Vector3, Vector4};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn random_lambda(rng: &mut StdRng) -> EulerParameters {
    loop {
        let v: [f64; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        if let Some(e) = EulerParameters(v).normalized() {
            return e;
        }
    }
}

fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0)
}

#[test]
fn rotation_matrix_is_orthonormal_with_unit_determinant() {
    let mut rng = StdRng::seed_from_u64(1);
    for _ in 0..200 {
        let r = random_lambda(&mut rng).rotation_matrix();
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14);
        assert!((r.determinant() - 1.0).abs() < 1e-14);
    }
}

#[test]
fn lambda_bar_equals_rt_lambda_and_identities_hold() {
    let mut rng = StdRng::seed_from_u64(2);
    for _ in 0..100 {
        let l = random_lambda(&mut rng);
        let (r, lam, lamb) = (l.rotation_matrix(), l.lambda(), l.lambda_bar());
        assert!((r.transpose() * lam - lamb).norm() < 1e-14);
        assert!((lam * l.as_vector()).norm() < 1e-15); // Λλ = 0
        assert!((lam * lam.transpose() - Matrix3::identity()).norm() < 1e-14);
        assert!((lam * lamb.transpose() - r).norm() < 1e-14); // R = ΛΛ̄ᵀ
    }
}

#[test]
fn omega_matches_differences_of_r() {
    // Ṙ Rᵀ = [ω×] (inertial), Rᵀ Ṙ = [ω̄×] (body); Ṙ by central differences of
    // R(λ(t)) along the normalized path λ(t) = (λ + t λ̇)/|λ + t λ̇|.
    let mut rng = StdRng::seed_from_u64(3);
    for _ in 0..50 {
        let l = random_lambda(&mut rng);
        let w = Vector3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            0.7,
        );
        let ld = l.lambda_dot_from_omega(&w);
        let h = 1e-6;
        let at = |t: f64| {
            let v = l.as_vector() + Vector4::from(ld) * t;
            EulerParameters([v[0], v[1], v[2], v[3]])
                .normalized()
                .unwrap()
                .rotation_matrix()
        };
        let rdot = (at(h) - at(-h)) / (2.0 * h);
        let r = l.rotation_matrix();
        let w_fd = rdot * r.transpose();
        assert!((w_fd - skew(&l.omega(&ld))).norm() < 1e-8);
        assert!((l.omega(&ld) - w).norm() < 1e-13);
        let wb_fd = r.transpose() * rdot;
        assert!((wb_fd - skew(&l.omega_body(&ld))).norm() < 1e-8);
        assert!((l.omega_body(&ld) - r.transpose() * w).norm() < 1e-13);
    }
}

#[test]
fn d_rotation_matches_central_differences_and_second_derivatives_are_constant() {
    let mut rng = StdRng::seed_from_u64(4);
    let d2 = EulerParameters::d2_rotation();
    for _ in 0..50 {
        let l = random_lambda(&mut rng);
        let d = l.d_rotation();
        for i in 0..4 {
            let h = 1e-6;
            let mut p = l.0;
            p[i] += h;
            let mut m = l.0;
            m[i] -= h;
            let fd = (EulerParameters(p).rotation_matrix() - EulerParameters(m).rotation_matrix())
                / (2.0 * h);
            assert!((fd - d[i]).norm() < 1e-9, "∂R/∂λ{i}");
            for (j, d2ij) in d2[i].iter().enumerate() {
                let mut p = l.0;
                p[j] += h;
                let mut m = l.0;
                m[j] -= h;
                let fd2 = (EulerParameters(p).d_rotation()[i] - EulerParameters(m).d_rotation()[i])
                    / (2.0 * h);
                assert!((fd2 - d2ij).norm() < 1e-9, "∂²R/∂λ{i}∂λ{j}");
            }
        }
    }
}

#[test]
fn conversions_round_trip_near_zero_pi_and_two_pi() {
    let axis = Unit::new_normalize(Vector3::new(0.3, -0.8, 0.5));
    let pi = std::f64::consts::PI;
    for &angle in &[
        0.0,
        1e-9,
        1e-5,
        0.3,
        pi - 1e-9,
        pi,
        pi + 1e-9,
        2.0 * pi - 1e-9,
        2.0 * pi,
        2.0 * pi + 1e-7,
        5.0 * pi + 0.2,
    ] {
        let l = EulerParameters::from_axis_angle(&axis, angle);
        let r = l.rotation_matrix();
        // matrix → λ → matrix
        let back = EulerParameters::from_rotation_matrix(&r);
        assert!((back.rotation_matrix() - r).norm() < 1e-14, "angle {angle}");
        // λ equal up to sign
        let d = (back.as_vector() - l.as_vector())
            .norm()
            .min((back.as_vector() + l.as_vector()).norm());
        assert!(d < 1e-14, "angle {angle}: {d}");
        // rotation vector → λ → rotation vector gives the same rotation
        let rv = l.to_rotation_vector();
        assert!(rv.norm() <= pi + 1e-12);
        let l2 = EulerParameters::from_rotation_vector(&rv);
        assert!((l2.rotation_matrix() - r).norm() < 1e-13, "angle {angle}");
        // axis–angle
        let (a, th) = l.to_axis_angle();
        let l3 = EulerParameters::from_axis_angle(&a, th);
        assert!((l3.rotation_matrix() - r).norm() < 1e-13);
        // ZYX angles
        let (y, p, ro) = l.to_zyx();
        assert!((EulerParameters::from_zyx(y, p, ro).rotation_matrix() - r).norm() < 1e-12);
    }
}

#[test]
fn rotation_vector_is_exact_near_zero() {
    let rv = Vector3::new(1e-10, -2e-10, 3e-10);
    let l = EulerParameters::from_rotation_vector(&rv);
    assert!((l.to_rotation_vector() - rv).norm() < 1e-24);
    assert!((l.norm() - 1.0).abs() < 1e-16);
}

#[test]
fn zyx_at_gimbal_lock_reproduces_rotation() {
    for &pitch in &[std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2] {
        let l = EulerParameters::from_zyx(0.4, pitch, -0.3);
        let (y, p, r) = l.to_zyx();
        assert!((p - pitch).abs() < 1e-7);
        let back = EulerParameters::from_zyx(y, p, r).rotation_matrix();
        assert!((back - l.rotation_matrix()).norm() < 1e-7);
    }
}

#[test]
fn composition_matches_matrix_product() {
    let mut rng = StdRng::seed_from_u64(5);
    for _ in 0..50 {
        let (a, b) = (random_lambda(&mut rng), random_lambda(&mut rng));
        let c = a.compose(&b);
        assert!((c.rotation_matrix() - a.rotation_matrix() * b.rotation_matrix()).norm() < 1e-14);
        let i = a.compose(&a.conjugate());
        assert!((i.rotation_matrix() - Matrix3::identity()).norm() < 1e-14);
    }
}

#[test]
fn average_of_equal_frames_is_that_frame_whatever_the_sign() {
    let mut rng = StdRng::seed_from_u64(6);
    for _ in 0..50 {
        let l = random_lambda(&mut rng);
        let r = EulerParameters::average(&l, &l);
        assert!((r.as_vector() - l.as_vector()).norm() < 1e-15);
        let neg = EulerParameters(l.0.map(|v| -v));
        let r2 = EulerParameters::average(&l, &neg);
        assert!((r2.rotation_matrix() - l.rotation_matrix()).norm() < 1e-14);
    }
}

#[test]
fn average_is_halfway_for_a_relative_rotation_about_one_axis() {
    let axis = Vector3::y_axis();
    let p = EulerParameters::from_axis_angle(&axis, 0.2);
    let q = EulerParameters::from_axis_angle(&axis, 0.6);
    let r = EulerParameters::average(&p, &q);
    let mid = EulerParameters::from_axis_angle(&axis, 0.4);
    assert!((r.as_vector() - mid.as_vector()).norm() < 1e-15);
}

#[test]
fn d_average_matches_central_differences() {
    let mut rng = StdRng::seed_from_u64(7);
    for _ in 0..30 {
        let p = random_lambda(&mut rng);
        let dq: [f64; 4] = std::array::from_fn(|_| rng.random_range(-0.2..0.2));
        let q = EulerParameters(std::array::from_fn(|i| p.0[i] + dq[i]))
            .normalized()
            .unwrap();
        let (dp, dqm) = EulerParameters::d_average(&p, &q);
        let h = 1e-6;
        for j in 0..4 {
            let pert = |l: &EulerParameters, s: f64| {
                let mut v = l.0;
                v[j] += s;
                EulerParameters(v)
            };
            let fd_p = (EulerParameters::average(&pert(&p, h), &q).as_vector()
                - EulerParameters::average(&pert(&p, -h), &q).as_vector())
                / (2.0 * h);
            let fd_q = (EulerParameters::average(&p, &pert(&q, h)).as_vector()
                - EulerParameters::average(&p, &pert(&q, -h)).as_vector())
                / (2.0 * h);
            assert!((fd_p - dp.column(j)).norm() < 1e-9);
            assert!((fd_q - dqm.column(j)).norm() < 1e-9);
        }
    }
}

#[test]
fn normalization_rejects_zero_and_nan() {
    assert!(EulerParameters([0.0; 4]).normalized().is_none());
    assert!(EulerParameters([f64::NAN, 1.0, 0.0, 0.0])
        .normalized()
        .is_none());
}
