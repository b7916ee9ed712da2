//! A pendulum from a scene string: a point mass on a massless rigid rod,
//! released at rest from 1 rad. Its period, from the upward zero crossings
//! of the angle in the simulated response, must match the exact
//! large-amplitude period T = 2π √(l/g) / AGM(1, cos(θ0/2)) (and it differs
//! from the small-amplitude 2π √(l/g) by 6.6 %).
//!
//! `cargo run --release -p flexmb --example pendulum`

use flexmb::prelude::*;
use std::process::ExitCode;
use std::sync::Arc;

/// A 1 m rod of 2 kg bob in the plane, gravity along −y; its degree of
/// freedom is the rod's angle from the x axis.
const SCENE: &str = r#"(
    dimension: Planar,
    gravity: Some([0.0, -9.81]),
    materials: { "m": (e: 1.0e9, rho: 0.0) },
    sections: { "s": Circle(d: 0.01) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
    elements: [
        (id: "rod", type: Beam((nodes: ("A", "B"), material: "m", section: "s", mass: false))),
        (id: "bob", type: PointMass(node: "B", mass: 2.0)),
    ],
    fixed: [ Coord("A", Position) ],
    rigid: [ Def("rod", "*") ],
)"#;

/// The arithmetic-geometric mean.
fn agm(mut a: f64, mut b: f64) -> f64 {
    while (a - b).abs() > 1e-15 * a {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    a
}

fn main() -> ExitCode {
    let (l, g, theta0) = (1.0_f64, 9.81_f64, 1.0_f64);
    let scene = Scene::from_ron_str(SCENE).expect("the scene parses");
    let mech = Arc::new(scene.build(None).expect("the scene builds"));
    let mut model = Dynamics::new(mech);
    // hanging is φ = −π/2; start θ0 away from it, at rest
    let down = -std::f64::consts::FRAC_PI_2;
    let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 4.5, 9001);
    (opts.rtol, opts.atol) = (1e-10, 1e-12);
    let run = MechanicalModel::simulate(
        &mut model,
        0.0,
        &[down + theta0],
        &[0.0],
        &opts,
        &mut |_, _, _| Control::Continue,
    )
    .expect("the pendulum simulates");
    // upward zero crossings of θ = φ + π/2, linearly interpolated
    let theta: Vec<f64> = run.coordinates.iter().map(|q| q[0] - down).collect();
    let t = &run.full.t;
    let crossings: Vec<f64> = (1..t.len())
        .filter(|&i| theta[i - 1] < 0.0 && theta[i] >= 0.0)
        .map(|i| t[i - 1] + (t[i] - t[i - 1]) * theta[i - 1] / (theta[i - 1] - theta[i]))
        .collect();
    let [first, second, ..] = crossings[..] else {
        eprintln!("fewer than two upward crossings in 4.5 s: {crossings:?}");
        return ExitCode::FAILURE;
    };
    let period = second - first;
    let small = 2.0 * std::f64::consts::PI * (l / g).sqrt();
    let exact = small / agm(1.0, (theta0 / 2.0).cos());
    let error = (period / exact - 1.0).abs();
    println!(
        "period {period:.6} s, exact {exact:.6} s (small-amplitude {small:.6} s), relative error {error:.1e}, {} evaluations",
        run.full.stats.rhs_evals
    );
    if error > 1e-6 {
        eprintln!("the period is off by {error:.1e} (more than 1e-6)");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
