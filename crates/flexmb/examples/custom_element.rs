//! A user-defined element, written outside the element library with its
//! public interface only: a planar rod whose deformation ε = l − l0 is
//! written once over a generic scalar; its derivatives come from dual numbers.
//!
//! The example checks the element against the built-in planar truss, places
//! two of them in a mechanism built from a scene plus elements built in code
//! (`Scene::build_with_elements`), solves the static equilibrium of a mass
//! hanging from the two rods and compares the vertical eigenfrequency with
//! the analytic one. Exits non-zero if a check fails.
//!
//! Run with `cargo run --release -p flexmb --example custom_element`.

use flexmb::dual::Real;
use flexmb::dynamics::Dynamics;
use flexmb::element::{DeformationKernel, Element, Slot};
use flexmb::model::{CodeElement, Scene};
use flexmb::nalgebra::DMatrix;
use std::process::ExitCode;
use std::sync::Arc;

/// A planar rod between two points, x = (x_p, y_p, x_q, y_q): ε = l − l0
/// (rigid-motion invariant: a length).
struct Rod {
    l0: f64,
}

impl DeformationKernel<4, 1> for Rod {
    fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
        let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
        [(dx * dx + dy * dy).sqrt() - self.l0]
    }
}

/// The rod from p to q with axial stiffness EA (N), massless.
fn rod(p: [f64; 2], q: [f64; 2], ea: f64) -> Result<Element, Box<dyn std::error::Error>> {
    let l0 = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
    Ok(Element::custom(
        "rod",
        Rod { l0 },
        &[Slot::Position2, Slot::Position2],
        &["elongation"],
        DMatrix::from_element(1, 1, ea / l0),
    )?)
}

fn check(what: &str, ok: bool, failures: &mut u32) {
    println!("{} {what}", if ok { "ok  " } else { "FAIL" });
    if !ok {
        *failures += 1;
    }
}

fn run() -> Result<u32, Box<dyn std::error::Error>> {
    let mut failures = 0;
    // 1. the element against the built-in planar truss, at a deformed state
    let (p, q, ea) = ([0.0, 1.0], [1.0, 0.0], 1.0e4);
    let custom = rod(p, q, ea)?;
    let builtin = Element::planar_truss(p, q, ea, 0.0)?;
    let x = [0.01, 1.02, 0.97, -0.03];
    let (mut e1, mut j1, mut e2, mut j2) = ([0.0; 1], [0.0; 4], [0.0; 1], [0.0; 4]);
    custom.deformations_and_jacobian(&x, None, &mut e1, &mut j1);
    builtin.deformations_and_jacobian(&x, None, &mut e2, &mut j2);
    let (mut h1, mut h2) = ([0.0; 16], [0.0; 16]);
    custom.deformation_weighted_hessian(&x, &[1.0], &mut h1);
    builtin.deformation_weighted_hessian(&x, &[1.0], &mut h2);
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(u, v)| (u - v).abs() < 1e-12);
    check(
        "ε, D,x and D,xx equal the built-in truss's",
        close(&e1, &e2) && close(&j1, &j2) && close(&h1, &h2),
        &mut failures,
    );

    // 2. a mass m hanging from two rods at ±45° (a V), under gravity
    let (m, g, a) = (2.0, 9.81, 1.0);
    let scene = Scene::from_ron_str(&format!(
        r#"(
        dimension: Planar,
        gravity: Some([0.0, -{g}]),
        nodes: [ (id: "L", at: [-{a}, {a}]), (id: "R", at: [{a}, {a}]), (id: "M", at: [0.0, 0.0]) ],
        elements: [ (id: "mass", type: PointMass(node: "M", mass: {m})) ],
        fixed: [ Node("L"), Node("R") ],
    )"#
    ))?;
    let place = |id: &str, element: Element, nodes: [&str; 2]| CodeElement {
        id: id.to_string(),
        element,
        nodes: nodes.map(String::from).to_vec(),
    };
    let mech = scene.build_with_elements(
        None,
        &[
            place("left", rod([-a, a], [0.0, 0.0], ea)?, ["L", "M"]),
            place("right", rod([a, a], [0.0, 0.0], ea)?, ["R", "M"]),
        ],
    )?;
    println!("{}", mech.summary());
    let mut dy = Dynamics::new(Arc::new(mech));
    let q0 = dy.mechanism().q0();
    let st = dy.static_equilibrium(0.0, &q0, &Default::default())?;
    // each rod carries m g / √2 and stretches by that / (EA/l0)
    let l0 = a * 2f64.sqrt();
    let k_rod = ea / l0;
    let stretch = m * g / 2f64.sqrt() / k_rod;
    let sag = -st.x[dy.mechanism().node("M").ok_or("no node M")?.position[1]];
    let sag_expected = stretch * 2f64.sqrt();
    println!("sag {sag:.6e} m, small-deflection estimate {sag_expected:.6e} m");
    check(
        "the static sag matches m g / (2 k cos²45°) within 1 %",
        (sag / sag_expected - 1.0).abs() < 1e-2,
        &mut failures,
    );
    // eigenfrequencies at the equilibrium: vertical and horizontal both
    // √(2 k cos²45° / m) = √(k/m), plus the small geometric-stiffness term
    let lin = dy.linearize_at_rest(0.0, &st.q)?;
    let f = flexmb::linearize::undamped_modes(&lin, 2)?.frequencies_hz();
    let f_expected = (k_rod / m).sqrt() / (2.0 * std::f64::consts::PI);
    println!("eigenfrequencies {f:?} Hz, analytic {f_expected:.6} Hz");
    check(
        "both eigenfrequencies match √(k/m) / 2π within 1 %",
        f.len() == 2 && f.iter().all(|v| (v / f_expected - 1.0).abs() < 1e-2),
        &mut failures,
    );
    Ok(failures)
}

fn main() -> ExitCode {
    match run() {
        Ok(0) => ExitCode::SUCCESS,
        Ok(n) => {
            eprintln!("{n} check(s) failed");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
