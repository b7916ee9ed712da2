//! User-defined elements through the public interface only
//! ([`DeformationKernel`], [`Element::custom`], `Scene::build_with_elements`):
//! reimplementations of the planar truss and the planar beam (5.3) give the
//! built-ins' deformations, exact derivatives (also against central
//! differences), inertia, and, placed in a mechanism, the same kinematics,
//! static equilibrium and eigenfrequencies. Rigid-motion invariance; an
//! element too large for the buffers is an error, not a panic.

use flexmb_dual::Real;
use flexmb_dynamics::Dynamics;
use flexmb_element::{
    BeamOptions, DeformationKernel, Element, ElementError, Material, SectionShape, Slot,
    MAX_ELEMENT_COORDS,
};
use flexmb_kinematics::Kinematics;
use flexmb_model::{CodeElement, Mechanism, Scene};
use nalgebra::DMatrix;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::sync::Arc;

/// A planar rod on x = (x_p, y_p, x_q, y_q): ε = l − l0.
struct Rod {
    l0: f64,
}

impl DeformationKernel<4, 1> for Rod {
    fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
        let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
        [(dx * dx + dy * dy).sqrt() - self.l0]
    }
}

/// The planar beam of thesis (5.3) on x = (x_p, y_p, φ_p, x_q, y_q, φ_q),
/// written as l0 × the sines of the angles between the chord and the node
/// frames (β0 the initial chord angle), with the shortening term of (5.3a).
struct Beam {
    l0: f64,
    beta0: f64,
}

impl DeformationKernel<6, 3> for Beam {
    fn eval<T: Real>(&self, x: &[T; 6]) -> [T; 3] {
        let (dx, dy) = (x[3] - x[0], x[4] - x[1]);
        let l = (dx * dx + dy * dy).sqrt();
        // sin(φ + β0 − γ) = (Δx sin(φ + β0) − Δy cos(φ + β0)) / l
        let sine = |phi: T| {
            let a = phi + self.beta0;
            (dx * a.sin() - dy * a.cos()) / l
        };
        let e2 = sine(x[2]) * self.l0;
        let e3 = -(sine(x[5]) * self.l0);
        let e1 = l - self.l0 + (e2 * e2 * 2.0 + e2 * e3 + e3 * e3 * 2.0) / (30.0 * self.l0);
        [e1, e2, e3]
    }
}

fn planar_truss_pair(p: [f64; 2], q: [f64; 2], ea: f64, rho_a: f64) -> (Element, Element) {
    let builtin = Element::planar_truss(p, q, ea, rho_a).unwrap();
    let l0 = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
    let m = rho_a * l0;
    // the consistent mass of a rod: m/6 [[2, 1], [1, 2]] per direction
    let mass = DMatrix::from_fn(4, 4, |r, c| {
        if r % 2 != c % 2 {
            0.0
        } else if r == c {
            m / 3.0
        } else {
            m / 6.0
        }
    });
    let custom = Element::custom(
        "my rod",
        Rod { l0 },
        &[Slot::Position2, Slot::Position2],
        &["elongation"],
        DMatrix::from_element(1, 1, ea / l0),
    )
    .unwrap()
    .with_mass_matrix(mass)
    .unwrap();
    (builtin, custom)
}

fn planar_beam_pair(p: [f64; 2], q: [f64; 2]) -> (Element, Element) {
    let mat = Material::from_poisson(2.1e11, 0.3, 7800.0);
    let shape = SectionShape::Rectangle { by: 0.02, bz: 0.01 };
    let opts = BeamOptions {
        inertia: false,
        ..BeamOptions::default()
    };
    let builtin = Element::planar_beam(p, q, &mat, &shape, &opts).unwrap();
    let beam = Beam {
        l0: ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt(),
        beta0: (q[1] - p[1]).atan2(q[0] - p[0]),
    };
    let slots = [Slot::Position2, Slot::Angle, Slot::Position2, Slot::Angle];
    let names = ["elongation", "bending_p", "bending_q"];
    let custom =
        Element::custom("my beam", beam, &slots, &names, builtin.stiffness().clone()).unwrap();
    (builtin, custom)
}

/// A configuration near the reference x0, with deformations of order `amp`.
fn near(rng: &mut StdRng, x0: &[f64], amp: f64) -> Vec<f64> {
    x0.iter().map(|v| v + rng.random_range(-amp..amp)).collect()
}

fn rand_vec(rng: &mut StdRng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn eps(e: &Element, x: &[f64]) -> Vec<f64> {
    let mut o = vec![0.0; e.n_eps()];
    e.deformations(x, None, &mut o);
    o
}

fn jac(e: &Element, x: &[f64]) -> Vec<f64> {
    let (ne, nx) = (e.n_eps(), e.n_x());
    let (mut o, mut j) = (vec![0.0; ne], vec![0.0; ne * nx]);
    e.deformations_and_jacobian(x, None, &mut o, &mut j);
    assert!(max_diff(&o, &eps(e, x)) < 1e-14);
    j
}

fn second(e: &Element, x: &[f64], a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut o = vec![0.0; e.n_eps()];
    e.deformation_second_derivative(x, a, b, &mut o);
    o
}

fn third(e: &Element, x: &[f64], a: &[f64], b: &[f64], c: &[f64]) -> Vec<f64> {
    let mut o = vec![0.0; e.n_eps()];
    e.deformation_third_derivative(x, a, b, c, &mut o);
    o
}

fn hess(e: &Element, x: &[f64], w: &[f64]) -> Vec<f64> {
    let mut o = vec![0.0; e.n_x() * e.n_x()];
    e.deformation_weighted_hessian(x, w, &mut o);
    o
}

fn plus(x: &[f64], s: f64, d: &[f64]) -> Vec<f64> {
    x.iter().zip(d).map(|(a, b)| a + s * b).collect()
}

/// The custom element agrees with the built-in to rounding in every
/// derivative, and its derivatives agree with central differences of the
/// next lower one.
fn check_against_builtin(builtin: &Element, custom: &Element, x0: &[f64], seed: u64) {
    let mut rng = StdRng::seed_from_u64(seed);
    assert_eq!(builtin.n_x(), custom.n_x());
    assert_eq!(builtin.n_eps(), custom.n_eps());
    assert_eq!(builtin.deformation_names(), custom.deformation_names());
    let (nx, ne) = (custom.n_x(), custom.n_eps());
    for _ in 0..20 {
        let x = near(&mut rng, x0, 0.05);
        let (a, b, c) = (
            rand_vec(&mut rng, nx),
            rand_vec(&mut rng, nx),
            rand_vec(&mut rng, nx),
        );
        let w = rand_vec(&mut rng, ne);
        // identical to the built-in (to rounding: the same function, written differently)
        let tol = 1e-12;
        assert!(max_diff(&eps(custom, &x), &eps(builtin, &x)) < tol);
        assert!(max_diff(&jac(custom, &x), &jac(builtin, &x)) < tol);
        assert!(max_diff(&second(custom, &x, &a, &b), &second(builtin, &x, &a, &b)) < tol);
        assert!(
            max_diff(
                &third(custom, &x, &a, &b, &c),
                &third(builtin, &x, &a, &b, &c)
            ) < 1e-10
        );
        assert!(max_diff(&hess(custom, &x, &w), &hess(builtin, &x, &w)) < 1e-10);
        // central differences, step h: errors O(h²)
        let h = 1e-5;
        let fd_tol = 1e-6;
        let j = jac(custom, &x);
        for col in 0..nx {
            let mut e = vec![0.0; nx];
            e[col] = 1.0;
            let d = plus(
                &eps(custom, &plus(&x, h, &e)),
                -1.0,
                &eps(custom, &plus(&x, -h, &e)),
            );
            for r in 0..ne {
                assert!((d[r] / (2.0 * h) - j[r * nx + col]).abs() < fd_tol, "D,x");
            }
        }
        // D,xx[a, b] = d/ds (D,x(x + s a) b)
        let jb = |y: &[f64]| -> Vec<f64> {
            let j = jac(custom, y);
            (0..ne)
                .map(|r| (0..nx).map(|k| j[r * nx + k] * b[k]).sum())
                .collect()
        };
        let d = plus(&jb(&plus(&x, h, &a)), -1.0, &jb(&plus(&x, -h, &a)));
        let s2 = second(custom, &x, &a, &b);
        for r in 0..ne {
            assert!((d[r] / (2.0 * h) - s2[r]).abs() < fd_tol, "D,xx[a, b]");
        }
        // D,xxx[a, b, c] = d/ds D,xx(x + s c)[a, b]
        let d = plus(
            &second(custom, &plus(&x, h, &c), &a, &b),
            -1.0,
            &second(custom, &plus(&x, -h, &c), &a, &b),
        );
        let s3 = third(custom, &x, &a, &b, &c);
        for r in 0..ne {
            assert!((d[r] / (2.0 * h) - s3[r]).abs() < 1e-5, "D,xxx");
        }
        // Σ wᵢ Dᵢ,xx: column k = d/ds (wᵀ D,x(x + s e_k))
        let wj = |y: &[f64]| -> Vec<f64> {
            let j = jac(custom, y);
            (0..nx)
                .map(|k| (0..ne).map(|r| w[r] * j[r * nx + k]).sum())
                .collect()
        };
        let hw = hess(custom, &x, &w);
        for col in 0..nx {
            let mut e = vec![0.0; nx];
            e[col] = 1.0;
            let d = plus(&wj(&plus(&x, h, &e)), -1.0, &wj(&plus(&x, -h, &e)));
            for r in 0..nx {
                assert!(
                    (d[r] / (2.0 * h) - hw[r * nx + col]).abs() < fd_tol,
                    "Σ wᵢ Dᵢ,xx"
                );
            }
        }
    }
}

#[test]
fn custom_rod_matches_the_builtin_planar_truss() {
    let (p, q) = ([0.1, -0.2], [0.9, 0.4]);
    let (builtin, custom) = planar_truss_pair(p, q, 3.0e6, 0.7);
    check_against_builtin(&builtin, &custom, &[p[0], p[1], q[0], q[1]], 1);
    assert_eq!(custom.type_name(), "my rod");
    assert_eq!(builtin.stiffness(), custom.stiffness());
    // the constant mass matrix: M, M ẍ, T, the gravity force
    let mut rng = StdRng::seed_from_u64(2);
    let x = near(&mut rng, &[p[0], p[1], q[0], q[1]], 0.1);
    let (xd, xdd) = (rand_vec(&mut rng, 4), rand_vec(&mut rng, 4));
    let run = |e: &Element| {
        let (mut m, mut f, mut g) = (vec![0.0; 16], vec![0.0; 4], vec![0.0; 4]);
        e.mass_matrix(&x, &mut m);
        e.inertia_force(&x, &xd, &xdd, &mut f);
        e.gravity_force(&x, &[0.3, -9.81, 0.0], &mut g);
        (m, f, g, e.kinetic_energy(&x, &xd), e.has_inertia())
    };
    let (a, b) = (run(&builtin), run(&custom));
    assert!(max_diff(&a.0, &b.0) < 1e-15);
    assert!(max_diff(&a.1, &b.1) < 1e-14);
    assert!(max_diff(&a.2, &b.2) < 1e-14);
    assert!((a.3 - b.3).abs() < 1e-14);
    assert!(a.4 && b.4);
    let mut r = vec![0.0; 16];
    assert_eq!(custom.mass_factor(&x, &mut r), Some(4));
}

#[test]
fn custom_beam_matches_the_builtin_planar_beam() {
    let (p, q) = ([0.2, 0.1], [0.5, 0.7]);
    let (builtin, custom) = planar_beam_pair(p, q);
    check_against_builtin(&builtin, &custom, &[p[0], p[1], 0.0, q[0], q[1], 0.0], 3);
    assert!(!custom.has_inertia());
}

#[test]
fn custom_beam_deformations_are_invariant_under_rigid_motion() {
    let (p, q) = ([0.2, 0.1], [0.5, 0.7]);
    let (_, custom) = planar_beam_pair(p, q);
    let mut rng = StdRng::seed_from_u64(4);
    let x0 = [p[0], p[1], 0.0, q[0], q[1], 0.0];
    assert!(eps(&custom, &x0).iter().all(|e| e.abs() < 1e-15));
    for _ in 0..50 {
        let x = near(&mut rng, &x0, 0.05);
        let th = rng.random_range(-7.0..7.0);
        let (tx, ty) = (rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
        let (c, s) = (f64::cos(th), f64::sin(th));
        let mv = |px: f64, py: f64| (c * px - s * py + tx, s * px + c * py + ty);
        let (xp, yp) = mv(x[0], x[1]);
        let (xq, yq) = mv(x[3], x[4]);
        let y = [xp, yp, x[2] + th, xq, yq, x[5] + th];
        let d = max_diff(&eps(&custom, &x), &eps(&custom, &y));
        assert!(d < 1e-13, "rigid motion changed ε by {d}");
    }
    // and a deformation does change them
    let mut y = x0;
    y[5] += 0.01;
    assert!(eps(&custom, &y)[2].abs() > 1e-4);
}

/// A kernel with more coordinates than the element buffers hold.
struct TooBig;
impl DeformationKernel<{ MAX_ELEMENT_COORDS + 2 }, 1> for TooBig {
    fn eval<T: Real>(&self, x: &[T; MAX_ELEMENT_COORDS + 2]) -> [T; 1] {
        [x.iter().fold(T::zero(), |s, v| s + *v)]
    }
}

#[test]
fn a_custom_element_too_large_for_the_buffers_is_an_error() {
    let slots = vec![Slot::Position2; (MAX_ELEMENT_COORDS + 2) / 2];
    let err = Element::custom("big", TooBig, &slots, &["sum"], DMatrix::zeros(1, 1)).unwrap_err();
    assert!(matches!(
        err,
        ElementError::TooLarge {
            n,
            max: MAX_ELEMENT_COORDS,
            ..
        } if n == MAX_ELEMENT_COORDS + 2
    ));
    let msg = err.to_string();
    assert!(
        msg.contains("'big'") && msg.contains("MAX_ELEMENT_COORDS"),
        "{msg}"
    );
}

#[test]
fn a_custom_element_with_inconsistent_sizes_is_an_error() {
    let rod = || Rod { l0: 1.0 };
    let s = DMatrix::from_element(1, 1, 1.0);
    // slots of 3 coordinates for a kernel of 4
    let e = Element::custom(
        "r",
        rod(),
        &[Slot::Position2, Slot::Angle],
        &["e"],
        s.clone(),
    );
    assert!(e.unwrap_err().to_string().contains("NX = 4"));
    // two names for one deformation
    let e = Element::custom("r", rod(), &[Slot::Position2; 2], &["a", "b"], s.clone());
    assert!(e.unwrap_err().to_string().contains("NE = 1"));
    // a 2 × 2 stiffness
    let e = Element::custom(
        "r",
        rod(),
        &[Slot::Position2; 2],
        &["a"],
        DMatrix::zeros(2, 2),
    );
    assert!(e.is_err());
    // an indefinite mass matrix
    let e = Element::custom("r", rod(), &[Slot::Position2; 2], &["a"], s.clone()).unwrap();
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 1.0, -1.0, 1.0]));
    assert!(e.with_mass_matrix(m).is_err());
    // a mass matrix on a built-in element
    let t = Element::planar_hinge(1.0).unwrap();
    assert!(t.with_mass_matrix(DMatrix::zeros(2, 2)).is_err());
}

/// A cantilever beam A–B with a mass at B hung from C by a rod, under gravity.
/// `builtin` decides whether the beam and the rod are the built-in elements
/// or the custom ones (placed with `build_with_elements`).
fn mechanism(builtin: bool) -> Mechanism {
    let elements = if builtin {
        r#"
        (id: "beam", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", mass: false))),
        (id: "rod", type: Truss(nodes: ("B", "C"), ea: 2.0e4, mass_per_length: 0.5)),"#
    } else {
        ""
    };
    let text = format!(
        r#"(
        dimension: Planar,
        gravity: Some([0.0, -9.81]),
        materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) }},
        sections: {{ "bar": Rectangle(by: 0.02, bz: 0.01) }},
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [1.6, 0.8]) ],
        elements: [
            (id: "m", type: PointMass(node: "B", mass: 2.0, inertia: Some(1e-3))),{elements}
        ],
        fixed: [ Node("A"), Node("C") ],
        rigid: [ Def("beam", "elongation") ],
    )"#
    );
    let scene = Scene::from_ron_str(&text).unwrap();
    if builtin {
        return scene.build(None).unwrap();
    }
    let (_, beam) = planar_beam_pair([0.0, 0.0], [1.0, 0.0]);
    let (_, rod) = planar_truss_pair([1.0, 0.0], [1.6, 0.8], 2.0e4, 0.5);
    let on = |id: &str, element: Element, nodes: &[&str]| CodeElement {
        id: id.into(),
        element,
        nodes: nodes.iter().map(|s| s.to_string()).collect(),
    };
    scene
        .build_with_elements(
            None,
            &[
                on("beam", beam, &["A", "A", "B", "B"]),
                on("rod", rod, &["B", "C"]),
            ],
        )
        .unwrap()
}

#[test]
fn a_mechanism_with_custom_elements_solves_as_with_the_builtins() {
    let (mb, mc) = (mechanism(true), mechanism(false));
    assert_eq!(mb.x_names, mc.x_names);
    assert_eq!(mb.eps_names, mc.eps_names);
    assert_eq!(mb.dofs, mc.dofs);
    assert_eq!(
        mc.element_by_id("rod").unwrap().element.type_name(),
        "my rod"
    );
    let (mb, mc) = (Arc::new(mb), Arc::new(mc));
    // kinematics at a deformed q
    let q: Vec<f64> = mb
        .q0()
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * (i + 1) as f64)
        .collect();
    let mut kb = Kinematics::new(mb.clone());
    let mut kc = Kinematics::new(mc.clone());
    kb.solve(&q, 0.0).unwrap();
    kc.solve(&q, 0.0).unwrap();
    assert!(max_diff(kb.x(), kc.x()) < 1e-12);
    assert!(max_diff(kb.eps(), kc.eps()) < 1e-12);
    // static equilibrium under gravity
    let (mut db, mut dc) = (Dynamics::new(mb.clone()), Dynamics::new(mc.clone()));
    let sb = db
        .static_equilibrium(0.0, &mb.q0(), &Default::default())
        .unwrap();
    let sc = dc
        .static_equilibrium(0.0, &mc.q0(), &Default::default())
        .unwrap();
    let sag = sb.x[4] - mb.x0[4];
    assert!(sag < -1e-4, "B sags under gravity: {sag}");
    assert!(max_diff(&sb.x, &sc.x) < 1e-12 * (1.0 + sag.abs()));
    // eigenfrequencies at the equilibrium (with the geometric stiffness)
    let lb = db.linearize_at_rest(0.0, &sb.q).unwrap();
    let lc = dc.linearize_at_rest(0.0, &sc.q).unwrap();
    let n = mb.n_dof();
    let fb = flexmb_linearize::undamped_modes(&lb, n)
        .unwrap()
        .frequencies_hz();
    let fc = flexmb_linearize::undamped_modes(&lc, n)
        .unwrap()
        .frequencies_hz();
    assert_eq!(fb.len(), n);
    for (a, b) in fb.iter().zip(&fc) {
        assert!(a.is_finite() && *a > 0.0);
        assert!(
            (a / b - 1.0).abs() < 1e-9,
            "built-in {fb:?} vs custom {fc:?}"
        );
    }
}

#[test]
fn build_with_elements_checks_its_elements() {
    let scene = Scene::from_ron_str(
        r#"(dimension: Planar, nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
            elements: [ (id: "m", type: PointMass(node: "B", mass: 1.0)) ], fixed: [ Node("A") ])"#,
    )
    .unwrap();
    let (_, rod) = planar_truss_pair([0.0, 0.0], [1.0, 0.0], 1.0, 0.0);
    let place = |id: &str, nodes: &[&str]| {
        scene.build_with_elements(
            None,
            &[CodeElement {
                id: id.into(),
                element: rod.clone(),
                nodes: nodes.iter().map(|s| s.to_string()).collect(),
            }],
        )
    };
    assert!(place("r", &["A", "B"]).is_ok());
    let e = place("r", &["A"]).unwrap_err().to_string();
    assert!(e.contains("one node per slot"), "{e}");
    let e = place("r", &["A", "Bx"]).unwrap_err().to_string();
    assert!(e.contains("Bx"), "{e}");
    let e = place("m", &["A", "B"]).unwrap_err().to_string();
    assert!(e.contains("'m'"), "{e}");
}

/// A chain of planar points as large as the buffers allow: ε = its length − l0.
struct Chain {
    l0: f64,
}
impl DeformationKernel<MAX_ELEMENT_COORDS, 1> for Chain {
    fn eval<T: Real>(&self, x: &[T; MAX_ELEMENT_COORDS]) -> [T; 1] {
        let mut l = T::zero();
        for i in 0..MAX_ELEMENT_COORDS / 2 - 1 {
            let (dx, dy) = (x[2 * i + 2] - x[2 * i], x[2 * i + 3] - x[2 * i + 1]);
            l += (dx * dx + dy * dy).sqrt();
        }
        [l - self.l0]
    }
}

#[test]
fn the_largest_custom_element_evaluates_on_a_default_thread_stack() {
    let n = MAX_ELEMENT_COORDS;
    let k = n / 2 - 1;
    let e = Element::custom(
        "chain",
        Chain { l0: k as f64 },
        &vec![Slot::Position2; n / 2],
        &["elongation"],
        DMatrix::from_element(1, 1, 1.0),
    )
    .unwrap();
    // a worker thread with Rust's default 2 MiB stack (as rayon's)
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(move || {
            let x: Vec<f64> = (0..n)
                .map(|i| if i % 2 == 0 { (i / 2) as f64 } else { 0.0 })
                .collect();
            let a = vec![0.1; n];
            assert!(eps(&e, &x)[0].abs() < 1e-12);
            let j = jac(&e, &x);
            assert!((j[0] + 1.0).abs() < 1e-12 && (j[n - 2] - 1.0).abs() < 1e-12);
            assert!(second(&e, &x, &a, &a)[0].abs() < 1e-12);
            assert!(third(&e, &x, &a, &a, &a)[0].is_finite());
            let h = hess(&e, &x, &[1.0]);
            // a straight chain: only transverse (y) second derivatives
            assert!(h[n + 1] > 0.5 && h[0].abs() < 1e-12);
        })
        .unwrap()
        .join()
        .unwrap();
}

/// The direction of a planar bar against its initial one, from an atan2:
/// ε = atan2(Δy, Δx) − β0, in (−π − β0, π − β0].
struct Direction {
    beta0: f64,
}

impl DeformationKernel<4, 1> for Direction {
    fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
        let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
        [dy.atan2(dx) - self.beta0]
    }
}

fn direction(periodic: bool) -> Element {
    let e = Element::custom(
        "direction",
        Direction { beta0: 0.0 },
        &[Slot::Position2, Slot::Position2],
        &["angle"],
        DMatrix::from_element(1, 1, 1.0),
    )
    .unwrap();
    if periodic {
        e.with_periodic_deformation(0, 2.0 * std::f64::consts::PI)
            .unwrap()
    } else {
        e
    }
}

/// A periodic deformation of a custom element is continued from the
/// previous deformations (issue 19: custom elements ignored `prev`): a bar
/// turned through three revolutions in steps of 0.3 rad has ε equal to the
/// angle turned, in `deformations` and in `deformations_and_jacobian`; the
/// same kernel without the declaration jumps back by 2π at every half turn.
#[test]
fn a_periodic_custom_deformation_turns_through_many_revolutions() {
    let (periodic, plain) = (direction(true), direction(false));
    let mut prev = [0.0];
    let mut jumps = 0;
    for k in 1..=63 {
        let a = 0.3 * k as f64;
        let x = [0.2, -0.1, 0.2 + 1.5 * a.cos(), -0.1 + 1.5 * a.sin()];
        let mut e = [0.0];
        periodic.deformations(&x, Some(&prev), &mut e);
        assert!((e[0] - a).abs() < 1e-12, "turned {a}: ε = {}", e[0]);
        let (mut ej, mut j) = ([0.0], [0.0; 4]);
        periodic.deformations_and_jacobian(&x, Some(&prev), &mut ej, &mut j);
        assert_eq!(ej, e);
        // the derivative of the angle: (−Δy, Δx)/l² at q
        let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
        let l2 = dx * dx + dy * dy;
        assert!((j[2] + dy / l2).abs() < 1e-12 && (j[3] - dx / l2).abs() < 1e-12);
        let mut e_plain = [0.0];
        plain.deformations(&x, Some(&prev), &mut e_plain);
        if (e_plain[0] - a).abs() > 1.0 {
            jumps += 1;
        }
        prev = e;
    }
    assert!(jumps > 30, "the plain kernel stayed continuous: {jumps}");
    // a bad declaration is an error naming it
    let err = |r: Result<Element, ElementError>| r.unwrap_err().to_string();
    assert!(err(direction(false).with_periodic_deformation(1, 1.0)).contains("1 deformations"));
    assert!(err(direction(false).with_periodic_deformation(0, 0.0)).contains("positive"));
    assert!(err(Element::planar_hinge(1.0)
        .unwrap()
        .with_periodic_deformation(0, 1.0))
    .contains("only a custom element"));
}

/// In a mechanism the kinematics passes the last solution as `prev`: a bar
/// whose custom direction is its DOF turns to 5π (two and a half turns) in
/// steps, its tip where the angle puts it; without the declaration the
/// solve cannot reach an angle beyond π.
#[test]
fn a_custom_hinge_angle_as_a_dof_turns_through_many_revolutions() {
    let build = |periodic: bool| {
        let scene = Scene::from_ron_str(
            r#"(
        dimension: Planar,
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [ (id: "rod", type: Truss(nodes: ("A", "B"), ea: 1.0e6, mass_per_length: 1.0)) ],
        fixed: [ Node("A") ],
        rigid: [ Def("rod", "*") ],
        dofs: Explicit([Def("dir", "angle")]),
    )"#,
        )
        .unwrap();
        let dir = CodeElement {
            id: "dir".into(),
            element: direction(periodic),
            nodes: vec!["A".into(), "B".into()],
        };
        Arc::new(scene.build_with_elements(None, &[dir]).unwrap())
    };
    let mech = build(true);
    let mut k = Kinematics::new(mech.clone());
    let b = mech.node("B").unwrap().position.clone();
    for step in 1..=50 {
        let a = 0.1 * std::f64::consts::PI * step as f64;
        k.solve(&[a], 0.0).unwrap();
        let (x, y) = (k.x()[b[0]], k.x()[b[1]]);
        assert!(
            (x - a.cos()).abs() < 1e-10 && (y - a.sin()).abs() < 1e-10,
            "at {a}: B = ({x}, {y})"
        );
    }
    let mech = build(false);
    let mut k = Kinematics::new(mech);
    let reached = (1..=50).take_while(|s| {
        k.solve(&[0.1 * std::f64::consts::PI * *s as f64], 0.0)
            .is_ok()
    });
    assert!(reached.count() <= 10, "an angle beyond π was reached");
}
