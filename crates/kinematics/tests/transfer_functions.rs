//! Transfer-function derivatives against differences of F along q + t q̇, and
//! the geometric-stiffness contraction against differences of F,qᵀw + E,qᵀσ.

use flexmb_kinematics::{Kinematics, KinematicsError, NewtonOptions};
use flexmb_model::{DofChoice, Scene};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::path::Path;
use std::sync::Arc;

fn scene(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap()
}

fn kinematics(name: &str, dofs: DofChoice) -> Kinematics {
    let mut s = scene(name);
    s.dofs = dofs;
    Kinematics::new(Arc::new(s.build(None).unwrap()))
}

/// The same with the sparse factorization of the Jacobian (small mechanisms
/// get the dense one by default).
fn sparse_kinematics(name: &str, dofs: DofChoice) -> Kinematics {
    let mut s = scene(name);
    s.dofs = dofs;
    Kinematics::with_dense_limit(Arc::new(s.build(None).unwrap()), 0)
}

/// A deflected configuration: q0 plus a random perturbation of a few percent
/// of the flexure length in deformation terms.
fn deflected(k: &Kinematics, rng: &mut StdRng, scale: f64) -> Vec<f64> {
    let q0 = k.mechanism().q0();
    q0.iter()
        .map(|v| v + scale * rng.random_range(-1.0..1.0))
        .collect()
}

fn x_at(k: &mut Kinematics, q: &[f64]) -> Vec<f64> {
    k.solve(q, 0.0).unwrap();
    k.x().to_vec()
}

fn check_first_and_second_order(name: &str, dofs: DofChoice, scale: f64) {
    check_derivatives(
        kinematics(name, dofs.clone()),
        &format!("{name} dense"),
        scale,
    );
    check_derivatives(
        sparse_kinematics(name, dofs),
        &format!("{name} sparse"),
        scale,
    );
}

fn check_derivatives(mut k: Kinematics, name: &str, scale: f64) {
    let mut rng = StdRng::seed_from_u64(3);
    // second differences amplify the solve tolerance by 1/h²: solve to rounding level
    k.set_newton_options(NewtonOptions {
        tol: 1e-17,
        max_iterations: 30,
    });
    let nq = k.n_q();
    for _ in 0..3 {
        let q = deflected(&k, &mut rng, scale);
        let qd: Vec<f64> = (0..nq).map(|_| rng.random_range(-0.01..0.01)).collect();
        k.solve(&q, 0.0).unwrap();
        k.first_order();
        k.velocities(&qd);
        k.accelerations();
        let xd = k.xd().to_vec();
        let conv = k.xdd0().to_vec();
        let x0 = k.x().to_vec();
        // central differences with step h and h/2, Richardson-extrapolated
        // (eliminates the h² truncation term)
        let along = |t: f64| -> Vec<f64> { q.iter().zip(&qd).map(|(a, b)| a + t * b).collect() };
        let h = 2e-3;
        let (xp, xm) = (x_at(&mut k, &along(h)), x_at(&mut k, &along(-h)));
        let (xp2, xm2) = (
            x_at(&mut k, &along(h / 2.0)),
            x_at(&mut k, &along(-h / 2.0)),
        );
        let scale_v = xd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scale_a = conv
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-3 * scale_v);
        for i in 0..x0.len() {
            let d1 = |p: f64, m: f64, h: f64| (p - m) / (2.0 * h);
            let d2 = |p: f64, m: f64, h: f64| (p - 2.0 * x0[i] + m) / (h * h);
            let fd1 = (4.0 * d1(xp2[i], xm2[i], h / 2.0) - d1(xp[i], xm[i], h)) / 3.0;
            let fd2 = (4.0 * d2(xp2[i], xm2[i], h / 2.0) - d2(xp[i], xm[i], h)) / 3.0;
            assert!(
                (fd1 - xd[i]).abs() < 1e-7 * scale_v,
                "{name}: F,q q̇ at {i}: {} vs {fd1}",
                xd[i]
            );
            assert!(
                (fd2 - conv[i]).abs() < 1e-7 * scale_a,
                "{name}: (F,qq q̇)q̇ at {i}: {} vs {fd2}",
                conv[i]
            );
        }
    }
}

#[test]
fn spatial_guidance_deformation_dofs_first_and_second_order() {
    check_first_and_second_order(
        "straight_guidance_spatial.ron",
        DofChoice::Deformations,
        2e-3,
    );
}

#[test]
fn spatial_guidance_nodal_dofs_first_and_second_order() {
    check_first_and_second_order(
        "straight_guidance_spatial.ron",
        DofChoice::NodalCoordinates,
        2e-3,
    );
}

#[test]
fn planar_guidance_first_and_second_order() {
    check_first_and_second_order(
        "straight_guidance_planar.ron",
        DofChoice::Deformations,
        1e-3,
    );
}

#[test]
fn geometric_contraction_matches_differences() {
    // G = ∂/∂q (F,qᵀ w + E,qᵀ σ) with w, σ frozen.
    let mut rng = StdRng::seed_from_u64(4);
    for dofs in [DofChoice::Deformations, DofChoice::NodalCoordinates] {
        let mut k = kinematics("straight_guidance_spatial.ron", dofs.clone());
        let q = deflected(&k, &mut rng, 2e-3);
        let (nx, ne, nq) = (k.x().len(), k.eps().len(), k.n_q());
        let w: Vec<f64> = (0..nx).map(|_| rng.random_range(-1.0..1.0)).collect();
        let sigma: Vec<f64> = (0..ne).map(|_| rng.random_range(-1.0..1.0)).collect();
        let gen = |k: &mut Kinematics, q: &[f64]| -> Vec<f64> {
            k.solve(q, 0.0).unwrap();
            k.first_order();
            let v = k.first_order_view();
            let (f, e) = (v.f, v.e);
            (0..nq)
                .map(|c| {
                    (0..nx).map(|i| f[(i, c)] * w[i]).sum::<f64>()
                        + (0..ne).map(|j| e[(j, c)] * sigma[j]).sum::<f64>()
                })
                .collect()
        };
        k.solve(&q, 0.0).unwrap();
        k.first_order();
        let g = k.second_order_contraction(&w, &sigma);
        let h = 1e-6;
        let mut maxg = 0.0f64;
        let mut maxd = 0.0f64;
        for c in 0..nq {
            let mut qp = q.clone();
            qp[c] += h;
            let mut qm = q.clone();
            qm[c] -= h;
            let (a, b) = (gen(&mut k, &qp), gen(&mut k, &qm));
            for r in 0..nq {
                let fd = (a[r] - b[r]) / (2.0 * h);
                maxg = maxg.max(fd.abs());
                maxd = maxd.max((fd - g[(r, c)]).abs());
            }
        }
        assert!(
            maxd < 1e-6 * maxg,
            "contraction error {maxd:e} relative to {maxg:e}"
        );
        for r in 0..nq {
            for c in 0..nq {
                assert!((g[(r, c)] - g[(c, r)]).abs() <= 1e-9 * maxg);
            }
        }
    }
}

#[test]
fn unreachable_configuration_reports_the_equations_that_fail() {
    // a pendulum with its tip prescribed out of reach
    let s = Scene::from_ron_str(
        r#"(
        dimension: Planar,
        materials: { "al": (e: 7.0e10, rho: 2700.0) },
        sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.6, 0.8]) ],
        elements: [ (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))) ],
        fixed: [ Coord("A", Position) ],
        rigid: [ Def("arm", "*") ],
        prescribed: [ (what: Coord("B", X), function: Ramp(t0: 0.0, t1: 1.0, v0: 0.6, v1: 3.0)) ],
    )"#,
    )
    .unwrap();
    let mech = s.build(None).unwrap();
    let mut k = Kinematics::new(Arc::new(mech));
    k.solve(&[], 0.0).unwrap();
    let e = k.solve(&[], 1.0).unwrap_err();
    match &e {
        KinematicsError::NotConverged { equations, .. }
        | KinematicsError::Singular {
            coordinates: equations,
            ..
        } => {
            assert!(!equations.is_empty(), "{e}")
        }
        other => panic!("unexpected {other}"),
    }
    let msg = e.to_string();
    assert!(
        msg.contains("arm.") || msg.contains("B.") || msg.contains("A."),
        "{msg}"
    );
    assert!(k.solve(&[f64::NAN], 0.0).is_err());
}

/// The adjoint product F,ξᵀy (one solve with Jᵀ) equals the product with the
/// explicit F,ξ, and D,xᵀs with E,ξᵀs = F,ξᵀD,xᵀs, for deformation and nodal
/// DOFs of the spatial guidance (a closed loop) at a deflected configuration.
#[test]
fn adjoint_transfer_matches_the_explicit_product() {
    for (dofs, sparse) in [
        (DofChoice::Deformations, false),
        (DofChoice::NodalCoordinates, false),
        (DofChoice::Deformations, true),
        (DofChoice::NodalCoordinates, true),
    ] {
        let mut rng = StdRng::seed_from_u64(11);
        let name = "straight_guidance_spatial.ron";
        let mut k = if sparse {
            sparse_kinematics(name, dofs.clone())
        } else {
            kinematics(name, dofs.clone())
        };
        let q = deflected(&k, &mut rng, 2e-3);
        k.solve(&q, 0.0).unwrap();
        let mech = k.mechanism().clone();
        let y: Vec<f64> = (0..mech.n_x())
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let s: Vec<f64> = (0..mech.n_eps())
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let n_xi = k.n_q() + k.n_u();
        let mut adj = vec![0.0; n_xi];
        k.transfer_transpose_times(&y, &mut adj);
        let mut ys = vec![0.0; mech.n_x()];
        k.add_deformation_forces(&s, &mut ys);
        let mut adj_s = vec![0.0; n_xi];
        k.transfer_transpose_times(&ys, &mut adj_s);
        k.first_order();
        let v = k.first_order_view();
        let (f, e) = (v.f, v.e);
        for c in 0..n_xi {
            let fy: f64 = (0..mech.n_x()).map(|i| f[(i, c)] * y[i]).sum();
            let es: f64 = (0..mech.n_eps()).map(|j| e[(j, c)] * s[j]).sum();
            let scale = 1.0 + fy.abs();
            assert!(
                (adj[c] - fy).abs() < 1e-10 * scale,
                "{dofs:?} F,ξᵀy[{c}]: {} vs {fy}",
                adj[c]
            );
            assert!(
                (adj_s[c] - es).abs() < 1e-10 * (1.0 + es.abs()),
                "{dofs:?} E,ξᵀs[{c}]: {} vs {es}",
                adj_s[c]
            );
        }
    }
}

/// Along a path of nearby configurations (as an integrator visits them),
/// the chord solve with the factorization of earlier configurations and the
/// refined velocities give the configuration and ẋ = F,ξ ξ̇ of a solve that
/// factorizes J at every point; F,ξ after a chord solve (factorized on
/// demand) equals F,ξ after a full solve. Deformation and nodal DOFs, dense
/// and sparse factorizations.
#[test]
fn chord_solve_and_refined_velocities_match_the_full_solve() {
    for dofs in [DofChoice::Deformations, DofChoice::NodalCoordinates] {
        for sparse in [false, true] {
            let make = |d: DofChoice| {
                if sparse {
                    sparse_kinematics("straight_guidance_spatial.ron", d)
                } else {
                    kinematics("straight_guidance_spatial.ron", d)
                }
            };
            let (mut chord, mut full) = (make(dofs.clone()), make(dofs.clone()));
            let nq = chord.n_q();
            let mut rng = StdRng::seed_from_u64(11);
            let start = deflected(&chord, &mut rng, 2e-3);
            let dir: Vec<f64> = (0..nq).map(|_| rng.random_range(-1.0..1.0)).collect();
            let qd: Vec<f64> = (0..nq).map(|_| rng.random_range(-0.05..0.05)).collect();
            let mut refinements_seen = false;
            for step in 0..40 {
                // steps from 1e-7 (refinement converges at once) to 1e-3 (refreshes)
                let h = 1e-7 * 10f64.powf(step as f64 / 10.0);
                let q: Vec<f64> = start.iter().zip(&dir).map(|(a, d)| a + h * d).collect();
                chord.solve_chord(&q, 0.0).unwrap();
                chord.velocities_refined(&qd).unwrap();
                full.solve(&q, 0.0).unwrap();
                full.first_order();
                full.velocities(&qd);
                let tag = format!("{dofs:?} sparse={sparse} step {step}");
                let xs = full.x().iter().fold(1.0f64, |m, v| m.max(v.abs()));
                for (a, b) in chord.x().iter().zip(full.x()) {
                    assert!((a - b).abs() <= 1e-11 * xs, "{tag}: x {a} vs {b}");
                }
                let vs = full.xd().iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (a, b) in chord.xd().iter().zip(full.xd()) {
                    assert!((a - b).abs() <= 1e-9 * vs, "{tag}: ẋ {a} vs {b}");
                }
                for (a, b) in chord.epsd().iter().zip(full.epsd()) {
                    assert!((a - b).abs() <= 1e-9 * vs.max(1.0), "{tag}: ε̇ {a} vs {b}");
                }
                refinements_seen |= chord.refinements() > 0;
            }
            assert!(refinements_seen, "the path never exercised the refinement");
            // F,ξ on demand after a chord solve
            chord.first_order();
            let (fc, ff) = (chord.f_xi(), full.f_xi());
            let fs = (0..ff.ncols())
                .flat_map(|c| ff.col_as_slice(c).to_vec())
                .fold(0.0f64, |m, v| m.max(v.abs()));
            for c in 0..ff.ncols() {
                for (a, b) in fc.col_as_slice(c).iter().zip(ff.col_as_slice(c)) {
                    assert!((a - b).abs() <= 1e-9 * fs, "F,ξ {a} vs {b}");
                }
            }
        }
    }
}

/// The solves along directions that a reduced model uses, without F,ξ,
/// against the products with F,ξ of a solve that factorizes J at every
/// point, along a path of nearby configurations reached by chord solves:
/// F,q V by `transfer_matrix` (a strided V too), the velocities from a known
/// F,q q̇ by `velocities_from` (with moving inputs on the universal joint),
/// and ẍ = F,q q̈ + ẍ0 by `accelerations_refined`. Deformation and nodal
/// DOFs, dense and sparse factorizations; slices of the wrong size are
/// errors.
#[test]
fn solves_along_directions_match_the_products_with_the_transfer_matrix() {
    let cases = [
        (
            "straight_guidance_spatial.ron",
            DofChoice::Deformations,
            false,
        ),
        (
            "straight_guidance_spatial.ron",
            DofChoice::NodalCoordinates,
            false,
        ),
        (
            "straight_guidance_spatial.ron",
            DofChoice::Deformations,
            true,
        ),
        (
            "straight_guidance_spatial.ron",
            DofChoice::NodalCoordinates,
            true,
        ),
        (
            "spin_up_universal_joint.ron",
            DofChoice::Deformations,
            false,
        ),
    ];
    for (name, dofs, sparse) in cases {
        let make = || {
            if sparse {
                sparse_kinematics(name, dofs.clone())
            } else {
                kinematics(name, dofs.clone())
            }
        };
        let (mut k, mut full) = (make(), make());
        let (nq, nx) = (k.n_q(), k.mechanism().n_x());
        let mut rng = StdRng::seed_from_u64(5);
        let start = deflected(&k, &mut rng, 2e-3);
        let dir: Vec<f64> = (0..nq).map(|_| rng.random_range(-1.0..1.0)).collect();
        // three directions, stored transposed (V strided) for the second pass
        let v = faer::Mat::from_fn(nq, 3, |_, _| rng.random_range(-1.0..1.0));
        let vt = v.transpose().to_owned();
        let zd = [0.3, -0.2, 0.5];
        let qd: Vec<f64> = (0..nq)
            .map(|i| (0..3).map(|c| v[(i, c)] * zd[c]).sum())
            .collect();
        let qdd: Vec<f64> = (0..nq).map(|_| rng.random_range(-1.0..1.0)).collect();
        let tag = format!("{name} {dofs:?} sparse={sparse}");
        for step in 0..12 {
            let (h, t) = (1e-6 * 2f64.powi(step), 0.7 + 0.1 * step as f64);
            let q: Vec<f64> = start.iter().zip(&dir).map(|(a, d)| a + h * d).collect();
            k.solve_chord(&q, t).unwrap();
            full.solve(&q, t).unwrap();
            full.first_order();
            full.velocities(&qd);
            full.accelerations();
            let f = full.f_xi().subcols(0, nq).to_owned();
            let fv = &f * &v;
            let scale = |m: &faer::Mat<f64>| {
                (0..m.ncols())
                    .flat_map(|c| m.col_as_slice(c).to_vec())
                    .fold(0.0f64, |a, b| a.max(b.abs()))
            };
            let mut out = faer::Mat::zeros(nx, 3);
            let v_in = if step % 2 == 0 {
                v.as_ref()
            } else {
                vt.transpose()
            };
            if step % 3 == 0 {
                // a strided destination
                let mut out_t = faer::Mat::zeros(3, nx);
                k.transfer_matrix(v_in, out_t.as_mut().transpose_mut())
                    .unwrap();
                out.copy_from(out_t.transpose());
            } else {
                k.transfer_matrix(v_in, out.as_mut()).unwrap();
            }
            let fs = scale(&fv);
            for c in 0..3 {
                for i in 0..nx {
                    let (a, b) = (out[(i, c)], fv[(i, c)]);
                    assert!(
                        (a - b).abs() <= 1e-11 * fs,
                        "{tag} step {step}: F,q V {a} vs {b}"
                    );
                }
            }
            let fq_qd: Vec<f64> = (0..nx)
                .map(|i| (0..3).map(|c| out[(i, c)] * zd[c]).sum())
                .collect();
            k.velocities_from(&qd, &fq_qd).unwrap();
            let vs = full.xd().iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in k.xd().iter().zip(full.xd()) {
                assert!(
                    (a - b).abs() <= 1e-11 * vs,
                    "{tag} step {step}: ẋ {a} vs {b}"
                );
            }
            for (a, b) in k.epsd().iter().zip(full.epsd()) {
                assert!((a - b).abs() <= 1e-11 * vs.max(1.0), "{tag}: ε̇ {a} vs {b}");
            }
            let mut xdd = vec![0.0; nx];
            k.accelerations_refined(&qdd, &mut xdd).unwrap();
            let expected: Vec<f64> = (0..nx)
                .map(|i| full.xdd0()[i] + (0..nq).map(|c| f[(i, c)] * qdd[c]).sum::<f64>())
                .collect();
            let xs = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in xdd.iter().zip(&expected) {
                assert!(
                    (a - b).abs() <= 1e-10 * xs,
                    "{tag} step {step}: ẍ {a} vs {b}"
                );
            }
        }
        // caller errors: the sizes of V, F,q V, q̇, F,q q̇, q̈ and ẍ
        let mut out = faer::Mat::zeros(nx, 3);
        let short = faer::Mat::<f64>::zeros(nq - 1, 3);
        assert!(matches!(
            k.transfer_matrix(short.as_ref(), out.as_mut()),
            Err(KinematicsError::Length { .. })
        ));
        let mut narrow = faer::Mat::zeros(nx, 2);
        assert!(matches!(
            k.transfer_matrix(v.as_ref(), narrow.as_mut()),
            Err(KinematicsError::Length { .. })
        ));
        assert!(k.velocities_from(&qd, &vec![0.0; nx + 1]).is_err());
        assert!(k
            .accelerations_refined(&qdd[1..], &mut vec![0.0; nx])
            .is_err());
    }
}

/// A jump the first Newton solve cannot make (it falls back to continuation
/// from the last solution, restored with its own deformations and element
/// Jacobians) ends with the configuration and F,ξ of a path of small steps,
/// whether the chord or the full solve made it, and chord velocities right
/// after it are exact.
#[test]
fn a_far_jump_by_continuation_gives_the_configuration_and_derivatives_of_small_steps() {
    let mut rng = StdRng::seed_from_u64(5);
    let reference_k = kinematics("straight_guidance_spatial.ron", DofChoice::Deformations);
    let nq = reference_k.n_q();
    let far = deflected(&reference_k, &mut rng, 4e-3);
    let qd: Vec<f64> = (0..nq).map(|_| rng.random_range(-0.05..0.05)).collect();
    let mut reference = reference_k;
    for j in 1..=40 {
        let q: Vec<f64> = far.iter().map(|v| v * j as f64 / 40.0).collect();
        reference.solve(&q, 0.0).unwrap();
        reference.first_order();
    }
    reference.velocities(&qd);
    for chord in [false, true] {
        // the iterations the jump takes at once, less one: the solve then
        // continues from the last solution in smaller steps
        let mut once = kinematics("straight_guidance_spatial.ron", DofChoice::Deformations);
        once.solve(&vec![0.0; nq], 0.0).unwrap();
        once.solve(&far, 0.0).unwrap();
        let mut k = kinematics("straight_guidance_spatial.ron", DofChoice::Deformations);
        k.solve(&vec![0.0; nq], 0.0).unwrap();
        k.set_newton_options(NewtonOptions {
            tol: 1e-12,
            max_iterations: once.iterations() - 1,
        });
        if chord {
            k.solve_chord(&far, 0.0).unwrap();
            k.velocities_refined(&qd).unwrap();
        } else {
            k.solve(&far, 0.0).unwrap();
            k.first_order();
            k.velocities(&qd);
        }
        assert_eq!(k.continuations(), 1, "the jump is made by continuation");
        let xs = reference.x().iter().fold(1.0f64, |m, v| m.max(v.abs()));
        for (a, b) in k.x().iter().zip(reference.x()) {
            assert!((a - b).abs() <= 1e-10 * xs, "chord {chord}: x {a} vs {b}");
        }
        let vs = reference.xd().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in k.xd().iter().zip(reference.xd()) {
            assert!((a - b).abs() <= 1e-8 * vs, "chord {chord}: ẋ {a} vs {b}");
        }
        k.first_order();
        let (f, fr) = (k.f_xi(), reference.f_xi());
        for c in 0..fr.ncols() {
            for (a, b) in f.col_as_slice(c).iter().zip(fr.col_as_slice(c)) {
                assert!((a - b).abs() <= 1e-8 * xs, "chord {chord}: F,ξ {a} vs {b}");
            }
        }
    }
}

/// F,ξ, E,ξ and the velocities read after a solve that did not compute them
/// (a chord solve, as one evaluation of the equations of motion does, or a
/// new guess) are of the new configuration, never of the one before. Before
/// this was enforced, `nodal_mode_shapes` after `Dynamics::accelerations`
/// read F,q of an older configuration.
#[test]
fn derivatives_are_never_of_an_older_configuration() {
    for mut k in [
        kinematics("straight_guidance_spatial.ron", DofChoice::Deformations),
        sparse_kinematics("straight_guidance_spatial.ron", DofChoice::Deformations),
    ] {
        let mut rng = StdRng::seed_from_u64(11);
        let q1 = deflected(&k, &mut rng, 2e-3);
        let q2 = deflected(&k, &mut rng, 2e-3);
        let n_q = q1.len();
        // the reference at q2, from a fresh solve with first order
        let mut fresh = kinematics("straight_guidance_spatial.ron", DofChoice::Deformations);
        fresh.solve(&q2, 0.0).unwrap();
        fresh.first_order();
        let (f_ref, e_ref) = (fresh.f_xi().to_owned(), fresh.e_xi().to_owned());
        let qd = vec![0.3; n_q];
        fresh.velocities(&qd);
        let xd_ref = fresh.xd().to_vec();
        // first order at q1, then only a chord solve at q2
        k.solve(&q1, 0.0).unwrap();
        k.first_order();
        let f_old = k.f_xi().to_owned();
        k.solve_chord(&q2, 0.0).unwrap();
        assert!(!k.first_order_is_current(), "a solve must invalidate F,ξ");
        let scale = f_ref.norm_max();
        let diff_old = (&f_old - &f_ref).norm_max();
        assert!(
            diff_old > 1e-6 * scale,
            "the test needs configurations with other F,ξ ({diff_old:e})"
        );
        let df = (k.f_xi() - &f_ref).norm_max();
        let de = (k.e_xi() - &e_ref).norm_max();
        assert!(
            df <= 1e-9 * scale,
            "F,ξ after a chord solve differs by {df:e} from the one at its configuration"
        );
        assert!(
            de <= 1e-9 * e_ref.norm_max().max(1.0),
            "E,ξ differs by {de:e}"
        );
        // velocities after a solve without first order
        k.solve_chord(&q1, 0.0).unwrap();
        k.solve_chord(&q2, 0.0).unwrap();
        k.velocities(&qd);
        let dv = k
            .xd()
            .iter()
            .zip(&xd_ref)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let sv = xd_ref.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(dv <= 1e-9 * sv, "ẋ differs by {dv:e} of {sv:e}");
        // a new guess invalidates too
        k.set_guess(&x_at(&mut fresh, &q1));
        assert!(!k.first_order_is_current());
    }
}

/// Issue 13 item 4: the position solve's convergence test was relative to
/// the element length L only (residual ≤ 1e-12 L, or ≤ 1e-9 L once Newton
/// stalls). Residuals of lengths computed from coordinates of size |x|
/// cannot go below a few ε|x|, so a small mechanism far from the origin
/// (here 4 beams of 0.25 mm at x = 1e5 m: ε|x| = 2.2e-11 m against
/// 1e-9 L = 2.5e-13 m) "did not converge in 30 iterations (residual
/// 2.6e-13)" at its Newton stall. The same solve near the origin gives the
/// same shape: the displacements agree to the rounding of the far
/// coordinates (1e3 ε |x|).
#[test]
fn the_position_solve_converges_at_the_rounding_of_the_coordinates() {
    let at = |x0: f64| {
        let text = format!(
            r#"(
    name: "small cantilever at x = {x0}",
    dimension: Planar,
    materials: {{ "m": (e: 1.2e10, nu: 0.3, rho: 1000.0) }},
    sections: {{ "square": Rectangle(by: 0.0001, bz: 0.0001) }},
    nodes: [ (id: "A", at: [{x0:?}, 0.0]), (id: "B", at: [{:?}, 0.0]) ],
    elements: [ (id: "beam", type: Beam((nodes: ("A", "B"), material: "m", section: "square", n: 4))) ],
    fixed: [Node("A")],
)"#,
            x0 + 1e-3
        );
        let mech = Arc::new(Scene::from_ron_str(&text).unwrap().build(None).unwrap());
        let mut k = Kinematics::new(mech.clone());
        // bent by about 0.1 rad at each beam end (deformation DOFs: ε of each beam)
        let q: Vec<f64> = mech
            .q0()
            .iter()
            .enumerate()
            .map(|(i, v)| v + if i % 3 == 0 { 1e-7 } else { 2.5e-5 })
            .collect();
        k.solve(&q, 0.0)
            .unwrap_or_else(|e| panic!("cantilever at x = {x0}: {e}"));
        let b = &mech.node("B").unwrap().position;
        (k.x()[b[0]] - mech.node("B").unwrap().at[0], k.x()[b[1]])
    };
    let (near, far) = (at(0.0), at(1e5));
    let tol = 1e3 * f64::EPSILON * 1e5;
    assert!(
        (near.0 - far.0).abs() < tol && (near.1 - far.1).abs() < tol,
        "tip displacement near the origin {near:?}, far {far:?}"
    );
    assert!(near.1.abs() > 1e-5, "the cantilever is bent: {near:?}");
}

/// A q with several non-finite entries names each of them (up to three and a
/// count), not only the first.
#[test]
fn every_non_finite_entry_of_q_is_named() {
    let mut k = kinematics("straight_guidance_spatial.ron", DofChoice::Deformations);
    let mut q = k.mechanism().q0();
    assert!(q.len() > 8);
    for i in [2, 4, 5, 7, 8] {
        q[i] = f64::NAN;
    }
    let e = k.solve(&q, 0.0).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, KinematicsError::NonFinite { index: 2, .. }),
        "{msg}"
    );
    for i in [2, 4, 5] {
        assert!(msg.contains(&format!("q{i} ")), "q{i} not named: {msg}");
    }
    assert!(msg.contains("2 more"), "{msg}");
}
