//! Every element derivative against central differences at random
//! configurations (relative error ≤ 1e-7, normalized by the largest entry).
//!
//! Step choice: h = 1e-6 for first differences of functions of O(1) coordinates
//! (truncation ~h² ≈ 1e-12, rounding ~1e-16/h ≈ 1e-10); h = 1e-5 where a
//! difference of an already differenced quantity is taken.

mod common;
use common::*;
use flexmb_element::Element;

const H: f64 = 1e-6;
const TOL: f64 = 1e-7;

fn eps_of(e: &Element, x: &[f64], prev: Option<&[f64]>) -> Vec<f64> {
    let mut out = vec![0.0; e.n_eps()];
    e.deformations(x, prev, &mut out);
    out
}

fn jac_of(e: &Element, x: &[f64]) -> Vec<f64> {
    let mut eps = vec![0.0; e.n_eps()];
    let mut j = vec![0.0; e.n_eps() * e.n_x()];
    e.deformations_and_jacobian(x, None, &mut eps, &mut j);
    j
}

fn shifted(x: &[f64], d: &[f64], h: f64) -> Vec<f64> {
    x.iter().zip(d).map(|(a, b)| a + h * b).collect()
}

fn unit(n: usize, i: usize) -> Vec<f64> {
    let mut v = vec![0.0; n];
    v[i] = 1.0;
    v
}

#[test]
fn deformation_jacobian_matches_central_differences() {
    let mut r = rng(11);
    for (name, e) in catalogue(&mut r) {
        if e.n_eps() == 0 {
            continue;
        }
        for _ in 0..5 {
            let x = random_x(&mut r, &e);
            let (nx, ne) = (e.n_x(), e.n_eps());
            let mut eps = vec![0.0; ne];
            let mut j = vec![0.0; ne * nx];
            e.deformations_and_jacobian(&x, None, &mut eps, &mut j);
            let plain = eps_of(&e, &x, None);
            // bit for bit: the position solve takes trial steps with the
            // plain ε and the converged point's with D,x
            assert_eq!(eps, plain, "{name}: ε differs between the two entry points");
            let mut fd = vec![0.0; ne * nx];
            for c in 0..nx {
                let u = unit(nx, c);
                let prev = eps_of(&e, &x, None);
                let p = eps_of(&e, &shifted(&x, &u, H), Some(&prev));
                let m = eps_of(&e, &shifted(&x, &u, -H), Some(&prev));
                for rr in 0..ne {
                    fd[rr * nx + c] = (p[rr] - m[rr]) / (2.0 * H);
                }
            }
            let err = rel_err(&j, &fd);
            assert!(err < TOL, "{name}: D,x relative error {err:e}");
        }
    }
}

#[test]
fn directional_second_derivative_matches_differences_of_the_jacobian() {
    let mut r = rng(12);
    let h = 1e-5;
    for (name, e) in catalogue(&mut r) {
        if e.n_eps() == 0 {
            continue;
        }
        for _ in 0..5 {
            let x = random_x(&mut r, &e);
            let a = random_x(&mut r, &e);
            let b = random_xd(&mut r, &e, &x);
            let (nx, ne) = (e.n_x(), e.n_eps());
            let mut d2 = vec![0.0; ne];
            e.deformation_second_derivative(&x, &a, &b, &mut d2);
            let jp = jac_of(&e, &shifted(&x, &a, h));
            let jm = jac_of(&e, &shifted(&x, &a, -h));
            let fd: Vec<f64> = (0..ne)
                .map(|rr| {
                    (0..nx)
                        .map(|c| (jp[rr * nx + c] - jm[rr * nx + c]) / (2.0 * h) * b[c])
                        .sum()
                })
                .collect();
            let err = rel_err(&d2, &fd);
            assert!(err < TOL, "{name}: D,xx[a,b] relative error {err:e}");
        }
    }
}

#[test]
fn weighted_hessian_matches_differences_of_the_weighted_gradient() {
    let mut r = rng(13);
    let h = 1e-5;
    for (name, e) in catalogue(&mut r) {
        if e.n_eps() == 0 {
            continue;
        }
        let x = random_x(&mut r, &e);
        let (nx, ne) = (e.n_x(), e.n_eps());
        let w: Vec<f64> = (0..ne)
            .map(|i| 1.0 + 0.5 * i as f64 * if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let mut hs = vec![0.0; nx * nx];
        e.deformation_weighted_hessian(&x, &w, &mut hs);
        let grad = |x: &[f64]| -> Vec<f64> {
            let j = jac_of(&e, x);
            (0..nx)
                .map(|c| (0..ne).map(|rr| w[rr] * j[rr * nx + c]).sum())
                .collect()
        };
        let mut fd = vec![0.0; nx * nx];
        for c in 0..nx {
            let u = unit(nx, c);
            let gp = grad(&shifted(&x, &u, h));
            let gm = grad(&shifted(&x, &u, -h));
            for rr in 0..nx {
                fd[rr * nx + c] = (gp[rr] - gm[rr]) / (2.0 * h);
            }
        }
        let err = rel_err(&hs, &fd);
        assert!(err < TOL, "{name}: Σ wᵢ Dᵢ,xx relative error {err:e}");
        // symmetric
        for i in 0..nx {
            for j in 0..nx {
                assert!(
                    (hs[i * nx + j] - hs[j * nx + i]).abs() <= 1e-12 * max_abs(&hs).max(1e-300)
                );
            }
        }
    }
}

/// ∂T/∂ẋ by central differences: exact (up to rounding) because T is quadratic in ẋ.
fn dt_dxd(e: &Element, x: &[f64], xd: &[f64]) -> Vec<f64> {
    let n = e.n_x();
    (0..n)
        .map(|c| {
            let u = unit(n, c);
            (e.kinetic_energy(x, &shifted(xd, &u, 1.0))
                - e.kinetic_energy(x, &shifted(xd, &u, -1.0)))
                / 2.0
        })
        .collect()
}

#[test]
fn mass_matrix_is_the_hessian_of_the_kinetic_energy() {
    let mut r = rng(14);
    for (name, e) in catalogue(&mut r) {
        if !e.has_inertia() {
            continue;
        }
        for _ in 0..5 {
            let x = random_x(&mut r, &e);
            let xd = random_xd(&mut r, &e, &x);
            let n = e.n_x();
            let mut m = vec![0.0; n * n];
            e.mass_matrix(&x, &mut m);
            let mxd: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| m[i * n + j] * xd[j]).sum())
                .collect();
            let err = rel_err(&mxd, &dt_dxd(&e, &x, &xd));
            assert!(err < 1e-12, "{name}: M ẋ vs ∂T/∂ẋ {err:e}");
            let t2: f64 = (0..n).map(|i| xd[i] * mxd[i]).sum();
            assert!(
                (t2 - 2.0 * e.kinetic_energy(&x, &xd)).abs() < 1e-12 * t2.abs().max(1e-30),
                "{name}"
            );
        }
    }
}

#[test]
fn inertia_force_satisfies_lagranges_equations() {
    // M ẍ + h = d/dt ∂T/∂ẋ − ∂T/∂x along x(t) = x + t ẋ + ½t² ẍ, with ∂T/∂ẋ
    // from exact differences of T, its time derivative and ∂T/∂x by central
    // differences. Independent of the force code: it only uses T.
    let mut r = rng(15);
    let ht = 1e-5;
    for (name, e) in catalogue(&mut r) {
        if !e.has_inertia() {
            continue;
        }
        for _ in 0..5 {
            let n = e.n_x();
            let x = random_x(&mut r, &e);
            let xd = random_xd(&mut r, &e, &x);
            let xdd = random_x(&mut r, &e);
            let at = |t: f64| {
                let xt: Vec<f64> = (0..n)
                    .map(|i| x[i] + t * xd[i] + 0.5 * t * t * xdd[i])
                    .collect();
                let vt: Vec<f64> = (0..n).map(|i| xd[i] + t * xdd[i]).collect();
                dt_dxd(&e, &xt, &vt)
            };
            let (pp, pm) = (at(ht), at(-ht));
            let mut lag = vec![0.0; n];
            for i in 0..n {
                let u = unit(n, i);
                let dtdx = (e.kinetic_energy(&shifted(&x, &u, H), &xd)
                    - e.kinetic_energy(&shifted(&x, &u, -H), &xd))
                    / (2.0 * H);
                lag[i] = (pp[i] - pm[i]) / (2.0 * ht) - dtdx;
            }
            let mut f = vec![0.0; n];
            e.inertia_force(&x, &xd, &xdd, &mut f);
            let err = rel_err(&f, &lag);
            assert!(err < TOL, "{name}: M ẍ + h vs Lagrange {err:e}");
        }
    }
}

#[test]
fn inertia_force_derivatives_match_central_differences() {
    let mut r = rng(16);
    for (name, e) in catalogue(&mut r) {
        if !e.has_inertia() {
            continue;
        }
        for _ in 0..3 {
            let n = e.n_x();
            let x = random_x(&mut r, &e);
            let xd = random_xd(&mut r, &e, &x);
            let xdd = random_x(&mut r, &e);
            let mut dx = vec![0.0; n * n];
            let mut dxd = vec![0.0; n * n];
            e.inertia_force_derivatives(&x, &xd, &xdd, &mut dx, &mut dxd);
            let f = |x: &[f64], xd: &[f64]| {
                let mut o = vec![0.0; n];
                e.inertia_force(x, xd, &xdd, &mut o);
                o
            };
            let mut fx = vec![0.0; n * n];
            let mut fxd = vec![0.0; n * n];
            for c in 0..n {
                let u = unit(n, c);
                let (a, b) = (f(&shifted(&x, &u, H), &xd), f(&shifted(&x, &u, -H), &xd));
                let (ad, bd) = (f(&x, &shifted(&xd, &u, H)), f(&x, &shifted(&xd, &u, -H)));
                for rr in 0..n {
                    fx[rr * n + c] = (a[rr] - b[rr]) / (2.0 * H);
                    fxd[rr * n + c] = (ad[rr] - bd[rr]) / (2.0 * H);
                }
            }
            let e1 = rel_err(&dx, &fx);
            let e2 = rel_err(&dxd, &fxd);
            assert!(e1 < TOL, "{name}: ∂F/∂x {e1:e}");
            assert!(e2 < TOL, "{name}: ∂F/∂ẋ {e2:e}");
        }
    }
}

#[test]
fn gravity_force_derivative_matches_central_differences_and_equals_potential_gradient() {
    let mut r = rng(17);
    let g = [0.3, -1.2, -9.81];
    for (name, e) in catalogue(&mut r) {
        if !e.has_inertia() {
            continue;
        }
        let n = e.n_x();
        let x = random_x(&mut r, &e);
        let mut d = vec![0.0; n * n];
        e.gravity_force_derivative(&x, &g, &mut d);
        let f = |x: &[f64]| {
            let mut o = vec![0.0; n];
            e.gravity_force(x, &g, &mut o);
            o
        };
        let mut fd = vec![0.0; n * n];
        for c in 0..n {
            let u = unit(n, c);
            let (a, b) = (f(&shifted(&x, &u, H)), f(&shifted(&x, &u, -H)));
            for rr in 0..n {
                fd[rr * n + c] = (a[rr] - b[rr]) / (2.0 * H);
            }
        }
        let err = rel_err(&d, &fd);
        assert!(err < TOL, "{name}: ∂f_g/∂x {err:e}");
    }
}

#[test]
fn third_directional_derivative_matches_differences_of_the_second() {
    let mut r = rng(18);
    let h = 1e-5;
    for (name, e) in catalogue(&mut r) {
        if e.n_eps() == 0 {
            continue;
        }
        let x = random_x(&mut r, &e);
        let a = random_x(&mut r, &e);
        let b = random_xd(&mut r, &e, &x);
        let c = random_xd(&mut r, &e, &x);
        let ne = e.n_eps();
        let mut d3 = vec![0.0; ne];
        e.deformation_third_derivative(&x, &a, &b, &c, &mut d3);
        let d2 = |x: &[f64]| {
            let mut o = vec![0.0; ne];
            e.deformation_second_derivative(x, &b, &c, &mut o);
            o
        };
        let (p, m) = (d2(&shifted(&x, &a, h)), d2(&shifted(&x, &a, -h)));
        let fd: Vec<f64> = (0..ne).map(|k| (p[k] - m[k]) / (2.0 * h)).collect();
        let err = rel_err(&d3, &fd);
        assert!(err < TOL, "{name}: D,xxx[a,b,c] relative error {err:e}");
    }
}
