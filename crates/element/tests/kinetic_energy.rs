//! Custom elements with a configuration-dependent mass from a kinetic-energy
//! kernel ([`KineticEnergyKernel`], [`Element::with_kinetic_energy`]):
//! the mass matrix, the inertia force and its derivatives, the gravity force
//! and its derivative against central differences of T alone (Lagrange's
//! equations); a constant mass written as an energy equals
//! `with_mass_matrix`; placed in a mechanism, a body carried by a node gives
//! the equilibrium and eigenfrequencies of the same body built from built-in
//! elements; bad input is an error.

use flexmb_dual::Real;
use flexmb_dynamics::Dynamics;
use flexmb_element::{DeformationKernel, Element, KineticEnergyKernel, Slot};
use flexmb_model::{CodeElement, Mechanism, Scene};
use nalgebra::DMatrix;
use std::sync::Arc;

/// No deformation: a body carried by one planar node (x, y, φ).
struct Carried;
impl DeformationKernel<3, 0> for Carried {
    fn eval<T: Real>(&self, _x: &[T; 3]) -> [T; 0] {
        []
    }
}

/// A point mass `m` with rotary inertia `j` at the offset `c` (in the node's
/// frame) from a planar node (x, y, φ), carried rigidly by the node.
struct Bob {
    m: f64,
    j: f64,
    c: [f64; 2],
}
impl KineticEnergyKernel<3> for Bob {
    fn kinetic_energy<T: Real>(&self, x: &[T; 3], v: &[T; 3]) -> T {
        let (s, c) = (x[2].sin(), x[2].cos());
        let vx = v[0] - v[2] * (s * self.c[0] + c * self.c[1]);
        let vy = v[1] + v[2] * (c * self.c[0] - s * self.c[1]);
        (vx * vx + vy * vy) * (0.5 * self.m) + v[2] * v[2] * (0.5 * self.j)
    }
}

fn bob() -> Element {
    Element::custom(
        "bob",
        Carried,
        &[Slot::Position2, Slot::Angle],
        &[],
        DMatrix::zeros(0, 0),
    )
    .unwrap()
    .with_kinetic_energy(Bob {
        m: 1.5,
        j: 2e-3,
        c: [0.3, -0.2],
    })
    .unwrap()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn plus(x: &[f64], s: f64, d: &[f64]) -> Vec<f64> {
    x.iter().zip(d).map(|(a, b)| a + s * b).collect()
}

fn unit(n: usize, j: usize) -> Vec<f64> {
    (0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect()
}

fn force(e: &Element, x: &[f64], xd: &[f64], xdd: &[f64]) -> Vec<f64> {
    let mut o = vec![0.0; e.n_x()];
    e.inertia_force(x, xd, xdd, &mut o);
    o
}

#[test]
fn mass_force_and_derivatives_follow_lagranges_equations_of_the_energy() {
    let e = bob();
    let n = 3;
    let x = [0.1, -0.2, 0.7];
    let xd = [0.3, 0.5, -1.1];
    let xdd = [-0.4, 0.2, 0.9];
    let t = |x: &[f64], v: &[f64]| e.kinetic_energy(x, v);
    let h = 1e-5;
    // M = ∂²T/∂ẋ² by central differences of T
    let mut m = vec![0.0; n * n];
    e.mass_matrix(&x, &mut m);
    for i in 0..n {
        for j in 0..n {
            let (ei, ej) = (unit(n, i), unit(n, j));
            let d2 = (t(&x, &plus(&plus(&xd, h, &ei), h, &ej))
                - t(&x, &plus(&plus(&xd, h, &ei), -h, &ej))
                - t(&x, &plus(&plus(&xd, -h, &ei), h, &ej))
                + t(&x, &plus(&plus(&xd, -h, &ei), -h, &ej)))
                / (4.0 * h * h);
            assert!(
                (m[i * n + j] - d2).abs() < 1e-5,
                "M[{i}][{j}] {} vs {d2}",
                m[i * n + j]
            );
        }
    }
    assert!(m[2] != 0.0, "the offset couples translation and rotation");
    // F = d/dt ∂T/∂ẋ − ∂T/∂x with the time derivative along the motion
    // x(τ) = x + τẋ + ½τ²ẍ, all by central differences of T
    let p = |x: &[f64], v: &[f64], i: usize| {
        let ei = unit(n, i);
        (t(x, &plus(v, h, &ei)) - t(x, &plus(v, -h, &ei))) / (2.0 * h)
    };
    let f = force(&e, &x, &xd, &xdd);
    let tau = 1e-4;
    let at = |s: f64| -> (Vec<f64>, Vec<f64>) {
        let xs: Vec<f64> = (0..n)
            .map(|k| x[k] + s * xd[k] + 0.5 * s * s * xdd[k])
            .collect();
        let vs: Vec<f64> = (0..n).map(|k| xd[k] + s * xdd[k]).collect();
        (xs, vs)
    };
    for i in 0..n {
        let ((xp, vp), (xm, vm)) = (at(tau), at(-tau));
        let dpdt = (p(&xp, &vp, i) - p(&xm, &vm, i)) / (2.0 * tau);
        let ei = unit(n, i);
        let dtdx = (t(&plus(&x, h, &ei), &xd) - t(&plus(&x, -h, &ei), &xd)) / (2.0 * h);
        let lagrange = dpdt - dtdx;
        assert!(
            (f[i] - lagrange).abs() < 1e-6 * (1.0 + f[i].abs()),
            "F[{i}] {} vs {lagrange}",
            f[i]
        );
    }
    // M ẍ + h: F is affine in ẍ with slope M
    let f0 = force(&e, &x, &xd, &[0.0; 3]);
    for i in 0..n {
        let mx: f64 = (0..n).map(|j| m[i * n + j] * xdd[j]).sum();
        assert!((f[i] - f0[i] - mx).abs() < 1e-12);
    }
    // ∂F/∂x and ∂F/∂ẋ against central differences of F
    let (mut dfdx, mut dfdxd) = (vec![0.0; n * n], vec![0.0; n * n]);
    e.inertia_force_derivatives(&x, &xd, &xdd, &mut dfdx, &mut dfdxd);
    for j in 0..n {
        let ej = unit(n, j);
        let cx: Vec<f64> = force(&e, &plus(&x, h, &ej), &xd, &xdd)
            .iter()
            .zip(force(&e, &plus(&x, -h, &ej), &xd, &xdd))
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        let cv: Vec<f64> = force(&e, &x, &plus(&xd, h, &ej), &xdd)
            .iter()
            .zip(force(&e, &x, &plus(&xd, -h, &ej), &xdd))
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        for i in 0..n {
            assert!((dfdx[i * n + j] - cx[i]).abs() < 1e-7, "∂F{i}/∂x{j}");
            assert!((dfdxd[i * n + j] - cv[i]).abs() < 1e-7, "∂F{i}/∂ẋ{j}");
        }
    }
    // gravity f = M ẋ_g and its derivative
    let g = [0.0, -9.81, 0.0];
    let mut fg = vec![0.0; n];
    e.gravity_force(&x, &g, &mut fg);
    let xg = [0.0, -9.81, 0.0];
    for i in 0..n {
        let mg: f64 = (0..n).map(|j| m[i * n + j] * xg[j]).sum();
        assert!((fg[i] - mg).abs() < 1e-12);
    }
    // the moment of gravity about the node: −m g × (R c)
    let (s, c) = (x[2].sin(), x[2].cos());
    let rcx = c * 0.3 + s * 0.2;
    assert!(
        (fg[2] - 1.5 * -9.81 * rcx).abs() < 1e-12,
        "{} vs {}",
        fg[2],
        1.5 * -9.81 * rcx
    );
    let mut dg = vec![0.0; n * n];
    e.gravity_force_derivative(&x, &g, &mut dg);
    for j in 0..n {
        let ej = unit(n, j);
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        e.gravity_force(&plus(&x, h, &ej), &g, &mut a);
        e.gravity_force(&plus(&x, -h, &ej), &g, &mut b);
        for i in 0..n {
            assert!((dg[i * n + j] - (a[i] - b[i]) / (2.0 * h)).abs() < 1e-7);
        }
    }
    // M has a factor M = RᵀR
    let mut r = vec![0.0; n * n];
    let k = e.mass_factor(&x, &mut r).expect("M is positive definite");
    for i in 0..n {
        for j in 0..n {
            let rtr: f64 = (0..k).map(|l| r[l * n + i] * r[l * n + j]).sum();
            assert!((rtr - m[i * n + j]).abs() < 1e-12);
        }
    }
}

/// The planar rod's constant consistent mass written as a kinetic energy.
struct RodEnergy {
    m: f64,
}
impl KineticEnergyKernel<4> for RodEnergy {
    fn kinetic_energy<T: Real>(&self, _x: &[T; 4], v: &[T; 4]) -> T {
        // ½ ẋᵀ (m/6)[[2, 1], [1, 2]] ẋ per direction
        let per = |a: T, b: T| (a * a * 2.0 + a * b * 2.0 + b * b * 2.0) * (self.m / 12.0);
        per(v[0], v[2]) + per(v[1], v[3])
    }
}

struct Rod {
    l0: f64,
}
impl DeformationKernel<4, 1> for Rod {
    fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
        let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
        [(dx * dx + dy * dy).sqrt() - self.l0]
    }
}

#[test]
fn a_constant_mass_written_as_an_energy_equals_the_mass_matrix() {
    let m = 0.8;
    let rod = || {
        Element::custom(
            "rod",
            Rod { l0: 1.0 },
            &[Slot::Position2, Slot::Position2],
            &["elongation"],
            DMatrix::from_element(1, 1, 10.0),
        )
        .unwrap()
    };
    let by_energy = rod().with_kinetic_energy(RodEnergy { m }).unwrap();
    let mass = DMatrix::from_fn(4, 4, |r, c| match (r % 2 == c % 2, r == c) {
        (false, _) => 0.0,
        (true, true) => m / 3.0,
        (true, false) => m / 6.0,
    });
    let by_matrix = rod().with_mass_matrix(mass).unwrap();
    let x = [0.1, 0.0, 1.05, 0.2];
    let xd = [0.3, -0.1, 0.2, 0.4];
    let xdd = [1.0, 2.0, -0.5, 0.25];
    let (mut a, mut b) = (vec![0.0; 16], vec![0.0; 16]);
    by_energy.mass_matrix(&x, &mut a);
    by_matrix.mass_matrix(&x, &mut b);
    assert!(max_diff(&a, &b) < 1e-15);
    assert!(
        max_diff(
            &force(&by_energy, &x, &xd, &xdd),
            &force(&by_matrix, &x, &xd, &xdd)
        ) < 1e-14
    );
    let (mut ga, mut gb) = (vec![0.0; 4], vec![0.0; 4]);
    by_energy.gravity_force(&x, &[0.0, -9.81, 0.0], &mut ga);
    by_matrix.gravity_force(&x, &[0.0, -9.81, 0.0], &mut gb);
    assert!(max_diff(&ga, &gb) < 1e-14);
    assert!((by_energy.kinetic_energy(&x, &xd) - by_matrix.kinetic_energy(&x, &xd)).abs() < 1e-15);
    let (mut dx, mut dv) = (vec![1.0; 16], vec![1.0; 16]);
    by_energy.inertia_force_derivatives(&x, &xd, &xdd, &mut dx, &mut dv);
    assert!(
        dx.iter().chain(&dv).all(|v| *v == 0.0),
        "a constant mass has h = 0"
    );
}

#[test]
fn a_kinetic_energy_of_the_wrong_size_or_on_a_builtin_is_an_error() {
    let e = Element::custom(
        "bob",
        Carried,
        &[Slot::Position2, Slot::Angle],
        &[],
        DMatrix::zeros(0, 0),
    )
    .unwrap();
    let msg = e
        .with_kinetic_energy(RodEnergy { m: 1.0 })
        .expect_err("NX = 4 on a 3-coordinate element")
        .to_string();
    assert!(msg.contains("NX = 4") && msg.contains("n_x = 3"), "{msg}");
    let truss = Element::planar_truss([0.0, 0.0], [1.0, 0.0], 1.0, 1.0).unwrap();
    let msg = truss
        .with_kinetic_energy(RodEnergy { m: 1.0 })
        .expect_err("a built-in element")
        .to_string();
    assert!(msg.contains("only a custom element"), "{msg}");
}

/// The two-bar frame of `custom.rs` with a body hung off node B: either the
/// custom bob on B, or a massless rigid beam from B to the body's centre D
/// with a built-in point mass (and rotary inertia) at D.
fn frame(builtin: bool) -> Mechanism {
    let body = if builtin {
        r#"
        (id: "arm", type: Beam((nodes: ("B", "D"), material: "steel", section: "bar", mass: false))),
        (id: "body", type: PointMass(node: "D", mass: 1.5, inertia: Some(2e-3))),"#
    } else {
        ""
    };
    let rigid = if builtin {
        r#", Def("arm", "elongation"), Def("arm", "bending_p"), Def("arm", "bending_q")"#
    } else {
        ""
    };
    let text = format!(
        r#"(
        dimension: Planar,
        gravity: Some([0.0, -9.81]),
        materials: {{ "steel": (e: 2.1e11, nu: 0.3, rho: 7800.0) }},
        sections: {{ "bar": Rectangle(by: 0.02, bz: 0.01) }},
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [1.6, 0.8]),
                 (id: "D", at: [1.3, -0.2]) ],
        elements: [
            (id: "beam", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", mass: false))),
            (id: "rod", type: Truss(nodes: ("B", "C"), ea: 2.0e4, mass_per_length: 0.5)),{body}
        ],
        fixed: [ Node("A"), Node("C") ],
        rigid: [ Def("beam", "elongation"){rigid} ],
    )"#
    );
    let mut scene = Scene::from_ron_str(&text).unwrap();
    if builtin {
        return scene.build(None).unwrap();
    }
    scene.nodes.retain(|n| n.id != "D");
    scene
        .build_with_elements(
            None,
            &[CodeElement {
                id: "bob".into(),
                element: bob(),
                nodes: vec!["B".into(), "B".into()],
            }],
        )
        .unwrap()
}

#[test]
fn a_body_carried_by_a_node_equals_the_same_body_built_from_builtins() {
    let (mb, mc) = (Arc::new(frame(true)), Arc::new(frame(false)));
    assert_eq!(mb.n_dof(), mc.n_dof());
    let (mut db, mut dc) = (Dynamics::new(mb.clone()), Dynamics::new(mc.clone()));
    let sb = db
        .static_equilibrium(0.0, &mb.q0(), &Default::default())
        .unwrap();
    let sc = dc
        .static_equilibrium(0.0, &mc.q0(), &Default::default())
        .unwrap();
    // B's coordinates in both (the built-in model has D's after them)
    let b = |m: &Mechanism, x: &[f64]| -> Vec<f64> {
        ["B.x", "B.y", "B.angle"]
            .iter()
            .map(|name| {
                let k = m
                    .x_names
                    .iter()
                    .position(|s| s == name)
                    .unwrap_or_else(|| panic!("{name} in {:?}", m.x_names));
                x[k]
            })
            .collect()
    };
    let (xb, xc) = (b(&mb, &sb.x), b(&mc, &sc.x));
    assert!(xb[1] < -1e-4, "B sags under the body's weight: {xb:?}");
    assert!(xb[2].abs() > 1e-4, "the offset body turns B: {xb:?}");
    assert!(
        max_diff(&xb, &xc) < 1e-9 * (1.0 + xb[1].abs()),
        "{xb:?} vs {xc:?}"
    );
    // eigenfrequencies at the equilibrium (geometric and inertia terms)
    let n = mb.n_dof();
    let fb = flexmb_linearize::undamped_modes(&db.linearize_at_rest(0.0, &sb.q).unwrap(), n)
        .unwrap()
        .frequencies_hz();
    let fc = flexmb_linearize::undamped_modes(&dc.linearize_at_rest(0.0, &sc.q).unwrap(), n)
        .unwrap()
        .frequencies_hz();
    for (a, c) in fb.iter().zip(&fc) {
        assert!(a.is_finite() && *a > 0.0);
        assert!(
            (a / c - 1.0).abs() < 1e-7,
            "built-in {fb:?} vs custom {fc:?}"
        );
    }
}
