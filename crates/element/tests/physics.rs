//! Physical properties of the elements: rigid-motion invariance, exact rigid
//! kinetic energy, beam = superelement with the beam's matrices, the linear
//! cantilever against Timoshenko beam theory, continuous hinge angles.

mod common;
use common::*;
use flexmb_element::*;
use flexmb_rotation::EulerParameters;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::Rng;

/// Applies a rigid motion to an element configuration: spatial (rotation q,
/// translation t) or planar (rotation by q's angle about z is not used; a
/// planar angle `th` and translation `t`).
fn rigid_motion(e: &Element, x: &[f64], q: &EulerParameters, t: &[f64; 3], th: f64) -> Vec<f64> {
    let r = q.rotation_matrix();
    let (s, c) = th.sin_cos();
    let mut y = x.to_vec();
    let mut i = 0;
    for sl in e.slots() {
        match sl {
            Slot::Position3 => {
                let v = r * Vector3::new(x[i], x[i + 1], x[i + 2]);
                for k in 0..3 {
                    y[i + k] = v[k] + t[k];
                }
            }
            Slot::Orientation => {
                let l = q.compose(&EulerParameters([x[i], x[i + 1], x[i + 2], x[i + 3]]));
                y[i..i + 4].copy_from_slice(&l.0);
            }
            Slot::Position2 => {
                y[i] = c * x[i] - s * x[i + 1] + t[0];
                y[i + 1] = s * x[i] + c * x[i + 1] + t[1];
            }
            Slot::Angle => y[i] = x[i] + th,
            Slot::Modes(_) => {}
        }
        i += sl.len();
    }
    y
}

#[test]
fn deformations_are_invariant_under_rigid_motion_including_beyond_two_pi() {
    let mut r = rng(21);
    for (name, e) in catalogue(&mut r) {
        if e.n_eps() == 0 {
            continue;
        }
        for trial in 0..20 {
            let x = random_x(&mut r, &e);
            // rotation angles up to 5π (beyond 2π), planar angles up to ±20 rad
            let q = random_rotation(&mut r, 5.0 * std::f64::consts::PI);
            let t = [
                r.random_range(-3.0..3.0),
                r.random_range(-3.0..3.0),
                r.random_range(-3.0..3.0),
            ];
            let th = if trial == 0 {
                7.5
            } else {
                r.random_range(-20.0..20.0)
            };
            let y = rigid_motion(&e, &x, &q, &t, th);
            let mut a = vec![0.0; e.n_eps()];
            let mut b = vec![0.0; e.n_eps()];
            e.deformations(&x, None, &mut a);
            e.deformations(&y, Some(&a), &mut b);
            let d = a
                .iter()
                .zip(&b)
                .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
            assert!(
                d < 1e-12,
                "{name}: deformation changed by {d:e} under a rigid motion"
            );
        }
    }
}

fn beam_reference_x(p: [f64; 3], q: [f64; 3], l: &EulerParameters) -> [f64; 14] {
    let mut x = [0.0; 14];
    x[..3].copy_from_slice(&p);
    x[3..7].copy_from_slice(&l.0);
    x[7..10].copy_from_slice(&q);
    x[10..14].copy_from_slice(&l.0);
    x
}

#[test]
fn rigid_superelement_has_the_rigid_body_kinetic_energy_for_b1_b2_b3() {
    let mut r = rng(22);
    let mat = steel();
    let shape = SectionShape::Rectangle { by: 0.02, bz: 0.04 };
    let sec = shape.properties(mat.poisson()).unwrap();
    let l0 = 0.5;
    let r0 = frame_from_axis(&[1.0, 2.0, -0.5], &[0.0, 0.0, 1.0]).unwrap();
    let r0m = Matrix3::from_fn(|i, j| r0[i][j]);
    let mbar = DMatrix::from_iterator(12, 12, spatial_beam_m_bar(&mat, &sec, l0).iter().copied());
    let sbar = DMatrix::from_iterator(6, 6, spatial_beam_s_bar(&mat, &sec, l0).iter().copied());
    let data = LinearSuperelement::from_matrices(l0, r0, &sbar, &mbar, vec![]);
    let m = mat.rho * sec.area * l0;
    let j_local = Matrix3::from_diagonal(&Vector3::new(
        mat.rho * sec.polar() * l0,
        mat.rho * (sec.area * l0.powi(3) / 12.0 + sec.iy * l0),
        mat.rho * (sec.area * l0.powi(3) / 12.0 + sec.iz * l0),
    ));
    for tr in [
        VelocityTransform::B1,
        VelocityTransform::B2,
        VelocityTransform::B3,
    ] {
        let e = Element::superelement(&data, tr).unwrap();
        for _ in 0..20 {
            let lam = random_rotation(&mut r, 7.0);
            let rot = lam.rotation_matrix() * r0m;
            let p = Vector3::new(
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
            );
            let axis = rot * Vector3::new(l0, 0.0, 0.0);
            let q = p + axis;
            let x = beam_reference_x(p.into(), q.into(), &lam);
            let v = Vector3::new(
                r.random_range(-2.0..2.0),
                r.random_range(-2.0..2.0),
                r.random_range(-2.0..2.0),
            );
            let w = Vector3::new(
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
            );
            let ld = lam.lambda_dot_from_omega(&w);
            let vq = v + w.cross(&axis);
            let mut xd = [0.0; 14];
            xd[..3].copy_from_slice(v.as_slice());
            xd[3..7].copy_from_slice(&ld);
            xd[7..10].copy_from_slice(vq.as_slice());
            xd[10..14].copy_from_slice(&ld);
            let vc = v + w.cross(&(axis * 0.5));
            let j = rot * j_local * rot.transpose();
            let t_ref = 0.5 * m * vc.norm_squared() + 0.5 * w.dot(&(j * w));
            let t = e.kinetic_energy(&x, &xd);
            assert!(
                (t - t_ref).abs() < 1e-12 * t_ref,
                "{tr:?}: T = {t}, rigid body {t_ref}"
            );
        }
    }
}

#[test]
fn beam_and_superelement_with_the_beams_matrices_agree() {
    let mut r = rng(23);
    let mat = steel();
    let shape = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.002,
    };
    let sec = shape.properties(mat.poisson()).unwrap();
    let (p, q, up) = ([0.1, 0.0, 0.2], [0.1, 0.25, 0.2], [1.0, 0.0, 1.0]);
    let opts = BeamOptions {
        shortening: false,
        ..Default::default()
    };
    let beam = Element::beam(p, q, up, &mat, &shape, &opts).unwrap();
    let l0 = 0.25;
    let r0 = frame_from_axis(&[0.0, 0.25, 0.0], &up).unwrap();
    let sbar = DMatrix::from_iterator(6, 6, spatial_beam_s_bar(&mat, &sec, l0).iter().copied());
    let mbar = DMatrix::from_iterator(12, 12, spatial_beam_m_bar(&mat, &sec, l0).iter().copied());
    let se = Element::superelement(
        &LinearSuperelement::from_matrices(l0, r0, &sbar, &mbar, vec![]),
        VelocityTransform::B3,
    )
    .unwrap();
    assert_eq!(beam.stiffness(), se.stiffness());
    for _ in 0..10 {
        let x = random_x(&mut r, &beam);
        let xd = random_xd(&mut r, &beam, &x);
        let (mut e1, mut e2) = ([0.0; 6], [0.0; 6]);
        let (mut j1, mut j2) = ([0.0; 84], [0.0; 84]);
        beam.deformations_and_jacobian(&x, None, &mut e1, &mut j1);
        se.deformations_and_jacobian(&x, None, &mut e2, &mut j2);
        assert!(rel_err(&e1, &e2) < 1e-15 && rel_err(&j1, &j2) < 1e-15);
        let (mut s1, mut s2) = ([0.0; 6], [0.0; 6]);
        beam.stress(&e1, None, &mut s1);
        se.stress(&e2, None, &mut s2);
        assert!(rel_err(&s1, &s2) < 1e-14);
        let (mut m1, mut m2) = ([0.0; 196], [0.0; 196]);
        beam.mass_matrix(&x, &mut m1);
        se.mass_matrix(&x, &mut m2);
        assert!(rel_err(&m1, &m2) < 1e-14);
        let (mut h1, mut h2) = ([0.0; 14], [0.0; 14]);
        beam.inertia_h(&x, &xd, &mut h1);
        se.inertia_h(&x, &xd, &mut h2);
        assert!(rel_err(&h1, &h2) < 1e-14);
    }
}

/// Linear stiffness of the free node q of a beam clamped at p, over
/// (u_x, u_y, u_z, θ_x, θ_y, θ_z) with δλ = ½ Λᵀ δθ, from K = Gᵀ D,xᵀ S D,x G.
fn clamped_free_stiffness(e: &Element, x: &[f64]) -> DMatrix<f64> {
    let (ne, nx) = (e.n_eps(), e.n_x());
    let mut eps = vec![0.0; ne];
    let mut j = vec![0.0; ne * nx];
    e.deformations_and_jacobian(x, None, &mut eps, &mut j);
    let dx = DMatrix::from_row_slice(ne, nx, &j);
    let lq = EulerParameters([x[10], x[11], x[12], x[13]]);
    let mut g = DMatrix::zeros(nx, 6);
    for k in 0..3 {
        g[(7 + k, k)] = 1.0;
    }
    let lt = lq.lambda().transpose() * 0.5;
    for a in 0..4 {
        for b in 0..3 {
            g[(10 + a, 3 + b)] = lt[(a, b)];
        }
    }
    let b = dx * g;
    b.transpose() * e.stiffness() * b
}

#[test]
fn linear_cantilever_matches_timoshenko_beam_theory() {
    // One spatial beam along x, clamped at p, loaded at q; the element's linear
    // stiffness reproduces the Timoshenko cantilever exactly (the two-node
    // Timoshenko stiffness is exact for end loads).
    let mat = Material::from_poisson(2.1e11, 0.3, 7800.0);
    let shape = SectionShape::Rectangle { by: 0.03, bz: 0.01 };
    let sec = shape.properties(mat.poisson()).unwrap();
    let l = 0.2;
    let beam = Element::beam(
        [0.0; 3],
        [l, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        &mat,
        &shape,
        &BeamOptions::default(),
    )
    .unwrap();
    let x = beam_reference_x([0.0; 3], [l, 0.0, 0.0], &EulerParameters::identity());
    let k = clamped_free_stiffness(&beam, &x);
    let solve = |f: [f64; 6]| k.clone().lu().solve(&DVector::from_row_slice(&f)).unwrap();
    let (e, g, a) = (mat.e, mat.g, sec.area);
    let close = |got: f64, want: f64, what: &str| {
        assert!(
            (got / want - 1.0).abs() < 1e-10,
            "{what}: {got} vs Timoshenko {want}"
        );
    };
    let p = 10.0;
    // transverse force in y: bending about z, shear in y
    let u = solve([0.0, p, 0.0, 0.0, 0.0, 0.0]);
    close(
        u[1],
        p * l.powi(3) / (3.0 * e * sec.iz) + p * l / (sec.ky * g * a),
        "tip deflection y",
    );
    close(u[5], p * l * l / (2.0 * e * sec.iz), "tip rotation θz");
    // transverse force in z: bending about y, shear in z
    let u = solve([0.0, 0.0, p, 0.0, 0.0, 0.0]);
    close(
        u[2],
        p * l.powi(3) / (3.0 * e * sec.iy) + p * l / (sec.kz * g * a),
        "tip deflection z",
    );
    close(u[4], -p * l * l / (2.0 * e * sec.iy), "tip rotation θy");
    // torque and axial force
    let u = solve([0.0, 0.0, 0.0, p, 0.0, 0.0]);
    close(u[3], p * l / (g * sec.j), "twist");
    let u = solve([p, 0.0, 0.0, 0.0, 0.0, 0.0]);
    close(u[0], p * l / (e * a), "elongation");
    // end moment about z
    let u = solve([0.0, 0.0, 0.0, 0.0, 0.0, p]);
    close(u[5], p * l / (e * sec.iz), "rotation under end moment");
    close(
        u[1],
        p * l * l / (2.0 * e * sec.iz),
        "deflection under end moment",
    );
}

#[test]
fn linear_planar_cantilever_matches_timoshenko_beam_theory() {
    let mat = Material::from_poisson(7.3e10, 0.33, 2700.0);
    let shape = SectionShape::Rectangle {
        by: 0.02,
        bz: 0.005,
    };
    let sec = shape.properties(mat.poisson()).unwrap();
    let l = 0.5;
    // an inclined beam: β0 = 30°
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let beam = Element::planar_beam(
        [0.0, 0.0],
        [l * c, l * s],
        &mat,
        &shape,
        &BeamOptions::default(),
    )
    .unwrap();
    let x = [0.0, 0.0, 0.0, l * c, l * s, 0.0];
    let mut eps = [0.0; 3];
    let mut j = [0.0; 18];
    beam.deformations_and_jacobian(&x, None, &mut eps, &mut j);
    let b = DMatrix::from_row_slice(3, 6, &j).columns(3, 3).into_owned();
    let k = b.transpose() * beam.stiffness() * &b;
    let p = 5.0;
    // force perpendicular to the beam
    let f = DVector::from_row_slice(&[-p * s, p * c, 0.0]);
    let u = k.clone().lu().solve(&f).unwrap();
    let v = -u[0] * s + u[1] * c;
    let want = p * l.powi(3) / (3.0 * mat.e * sec.iz) + p * l / (sec.ky * mat.g * sec.area);
    assert!((v / want - 1.0).abs() < 1e-10, "deflection {v} vs {want}");
    assert!((u[2] / (p * l * l / (2.0 * mat.e * sec.iz)) - 1.0).abs() < 1e-10);
    let f = DVector::from_row_slice(&[p * c, p * s, 0.0]);
    let u = k.lu().solve(&f).unwrap();
    assert!(((u[0] * c + u[1] * s) / (p * l / (mat.e * sec.area)) - 1.0).abs() < 1e-10);
}

#[test]
fn spatial_hinge_angle_is_continuous_over_many_turns() {
    let axis = [0.3, -0.2, 0.9];
    let hinge = Element::hinge(axis, 0.0, 0.0).unwrap();
    let n = nalgebra::Unit::new_normalize(Vector3::from(axis));
    let lp = EulerParameters::from_axis_angle(&Vector3::x_axis(), 0.4);
    let mut prev = [0.0; 3];
    let steps = 400;
    let total = 12.0 * std::f64::consts::PI + 0.3; // six turns and a bit
    for k in 0..=steps {
        let th = total * k as f64 / steps as f64;
        // q rotated relative to p about the hinge axis (axis given in the initial
        // frame, so the relative rotation is applied before p's rotation)
        let lq = lp.compose(&EulerParameters::from_axis_angle(&n, th));
        let mut x = [0.0; 8];
        x[..4].copy_from_slice(&lp.0);
        x[4..].copy_from_slice(&lq.0);
        let mut e = [0.0; 3];
        hinge.deformations(&x, Some(&prev), &mut e);
        assert!((e[0] - th).abs() < 1e-12, "angle {} vs {th}", e[0]);
        assert!(e[1].abs() < 1e-14 && e[2].abs() < 1e-14);
        prev = e;
    }
}

#[test]
fn gravity_on_an_undeformed_beam_is_its_weight_and_on_a_rigid_body_the_potential_gradient() {
    let mut r = rng(24);
    let mat = steel();
    let shape = SectionShape::Circle { d: 0.01 };
    let sec = shape.properties(0.3).unwrap();
    let l0 = 0.3;
    let beam = Element::beam(
        [0.0; 3],
        [0.0, 0.0, l0],
        [1.0, 0.0, 0.0],
        &mat,
        &shape,
        &BeamOptions::default(),
    )
    .unwrap();
    let g = [0.0, 0.0, -9.81];
    let lam = random_rotation(&mut r, 3.0);
    let r0 = frame_from_axis(&[0.0, 0.0, 1.0], &[1.0, 0.0, 0.0]).unwrap();
    let axis =
        lam.rotation_matrix() * Matrix3::from_fn(|i, j| r0[i][j]) * Vector3::new(l0, 0.0, 0.0);
    let x = beam_reference_x([0.0; 3], axis.into(), &lam);
    let mut f = [0.0; 14];
    beam.gravity_force(&x, &g, &mut f);
    let m = mat.rho * sec.area * l0;
    for k in 0..3 {
        assert!(
            (f[k] + f[7 + k] - m * g[k]).abs() < 1e-12 * m * 9.81,
            "resultant"
        );
    }
    // rigid body: f = −∂V/∂x with V = −m g·(r + R R0 c)
    let r0 = frame_from_axis(&[1.0, 0.2, 0.0], &[0.0, 0.0, 1.0]).unwrap();
    let c = [0.1, -0.2, 0.05];
    let body = Element::rigid_body(
        3.0,
        c,
        [[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]],
        r0,
    )
    .unwrap();
    let v = |x: &[f64]| {
        let l = EulerParameters([x[3], x[4], x[5], x[6]]);
        let rc = l.rotation_matrix() * Matrix3::from_fn(|i, j| r0[i][j]) * Vector3::from(c);
        -3.0 * (0..3).map(|k| g[k] * (x[k] + rc[k])).sum::<f64>()
    };
    // Compared on the tangent space of the unit sphere (δλ = ½Λᵀδθ): off the
    // sphere the homogeneous R(λ) of V and the co-rotational force are different
    // (equally valid) extensions, so only tangent components are meaningful.
    let x = random_x(&mut r, &body);
    let mut f = [0.0; 7];
    body.gravity_force(&x, &g, &mut f);
    let lam = EulerParameters([x[3], x[4], x[5], x[6]]);
    let lt = lam.lambda().transpose() * 0.5;
    let h = 1e-6;
    let grad: Vec<f64> = (0..7)
        .map(|i| {
            let mut a = x.clone();
            a[i] += h;
            let mut b = x.clone();
            b[i] -= h;
            (v(&a) - v(&b)) / (2.0 * h)
        })
        .collect();
    for k in 0..6 {
        let (fk, gk) = if k < 3 {
            (f[k], grad[k])
        } else {
            let col = lt.column(k - 3);
            (
                (0..4).map(|a| col[a] * f[3 + a]).sum::<f64>(),
                (0..4).map(|a| col[a] * grad[3 + a]).sum::<f64>(),
            )
        };
        assert!(
            (fk + gk).abs() < 1e-7 * 30.0,
            "component {k}: {fk} vs {}",
            -gk
        );
    }
}

#[test]
fn bad_input_gives_errors_that_name_the_culprit() {
    let mat = steel();
    let shape = SectionShape::Circle { d: 0.01 };
    let o = BeamOptions::default();
    let e = Element::beam([0.0; 3], [0.0; 3], [0.0, 1.0, 0.0], &mat, &shape, &o).unwrap_err();
    assert!(e.to_string().contains("beam length"), "{e}");
    let e =
        Element::beam([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], &mat, &shape, &o).unwrap_err();
    assert!(e.to_string().contains("parallel"), "{e}");
    let bad = Material { e: -1.0, ..mat };
    let e = Element::planar_beam([0.0; 2], [1.0, 0.0], &bad, &shape, &o).unwrap_err();
    assert!(e.to_string().contains("Young"), "{e}");
    let e = Element::point_mass(f64::NAN).unwrap_err();
    assert!(e.to_string().contains("point mass"), "{e}");
    let mut r = rng(25);
    let (_, mut data) = random_superelement(&mut r, 2, VelocityTransform::B3);
    data.s_bar[0][1] += 1.0;
    let e = Element::superelement(&data, VelocityTransform::B3).unwrap_err();
    assert!(e.to_string().contains("not symmetric"), "{e}");
    let (_, mut data) = random_superelement(&mut r, 2, VelocityTransform::B3);
    data.m_bar.pop();
    let e = Element::superelement(&data, VelocityTransform::B3).unwrap_err();
    assert!(e.to_string().contains("M̄ must be 14 × 14"), "{e}");
    let e = Element::rigid_body(
        1.0,
        [0.0; 3],
        [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    )
    .unwrap_err();
    assert!(e.to_string().contains("inertia tensor"), "{e}");
    let beam = Element::beam([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], &mat, &shape, &o).unwrap();
    assert!(beam.clone().with_damping(DMatrix::zeros(3, 3)).is_err());
    assert!(beam.with_initial_stress(vec![f64::INFINITY; 6]).is_err());
}
