//! The tangent-free static out-of balance (one adjoint solve) against the one
//! of the static tangent, and chord-Newton equilibria against the balance
//! they claim, on mechanisms with loads, gravity, controllers, inputs and
//! both kinds of DOFs.

use flexmb_dynamics::{Dynamics, StaticOptions};
use flexmb_model::{DofChoice, Scene};
use std::path::Path;
use std::sync::Arc;

fn dynamics(name: &str, dofs: DofChoice) -> Dynamics {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    let mut s = Scene::load(&p).unwrap();
    s.dofs = dofs;
    Dynamics::new(Arc::new(s.build(None).unwrap()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn static_residual_equals_the_out_of_balance_of_the_tangent() {
    for (name, dofs, t) in [
        (
            "straight_guidance_spatial.ron",
            DofChoice::Deformations,
            0.05,
        ),
        (
            "straight_guidance_spatial.ron",
            DofChoice::NodalCoordinates,
            0.05,
        ),
        (
            "straight_guidance_planar.ron",
            DofChoice::Deformations,
            0.05,
        ),
        ("manipulator_planar.ron", DofChoice::Deformations, 0.3),
        ("spin_up_spatial_planar.ron", DofChoice::Deformations, 3.0),
    ] {
        let mut dy = dynamics(name, dofs.clone());
        let q: Vec<f64> = dy
            .mechanism()
            .q0()
            .iter()
            .enumerate()
            .map(|(i, v)| v + 1e-3 * ((i as f64) * 0.7).sin())
            .collect();
        let (g_tangent, _) = dy.static_tangent(t, &q).unwrap();
        let g = dy.static_residual(t, &q).unwrap();
        let scale = g_tangent.iter().fold(1e-12, |m: f64, v| m.max(v.abs()));
        let d = max_diff(&g, &g_tangent);
        assert!(
            d <= 1e-11 * scale,
            "{name} {dofs:?}: residuals differ by {d:.3e} (scale {scale:.3e})"
        );
    }
}

/// Equilibria by chord Newton are balanced to the tolerance, along a
/// continuation that reuses the factorized tangent between calls.
#[test]
fn chord_newton_equilibria_are_balanced() {
    let mut dy = dynamics("straight_guidance_spatial.ron", DofChoice::Deformations);
    let mut q = dy.mechanism().q0();
    let opts = StaticOptions {
        load_steps: 2,
        ..Default::default()
    };
    for (k, s) in [0.2, 0.4, 0.6, 0.8, 1.0].into_iter().enumerate() {
        dy.set_load_scale(s);
        let so = StaticOptions {
            ramp_loads: k == 0,
            ..opts.clone()
        };
        // the pulse is at its maximum (100 N) at t = 0.05
        let sol = dy.static_equilibrium(0.05, &q, &so).unwrap();
        let (g, kt) = dy.static_tangent(0.05, &sol.q).unwrap();
        // out-of-balance against the size of the stiffness terms
        let scale = (0..kt.nrows()).fold(0.0f64, |m, i| m.max(kt[(i, i)].abs()));
        let gmax = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            gmax <= 1e-9 * scale * 1e-3,
            "load scale {s}: out-of-balance {gmax:.3e} (stiffness scale {scale:.3e})"
        );
        q = sol.q;
    }
}

/// The planar cantilever of 64 beams rolled up by the end moment M = 2πEI/L
/// (fixtures/scenes/rollup_planar.ron, L = 1 m) in `steps` load increments.
fn rollup(steps: usize) -> (Dynamics, flexmb_dynamics::StaticSolution) {
    let mut dy = dynamics("rollup_planar.ron", DofChoice::Deformations);
    let q0 = dy.mechanism().q0();
    let opts = StaticOptions {
        load_steps: steps,
        ..Default::default()
    };
    let sol = dy.static_equilibrium(0.0, &q0, &opts).unwrap();
    (dy, sol)
}

/// Issue 13 item 4: `load_steps` N means N equal load increments (it used
/// to set only the first, 1/N, which then doubled: 64 gave 7 increments).
/// With the 64 equal increments the roll-up reaches the closed form of
/// Bernoulli–Euler theory: under a constant moment M = 2πEI/L the beam
/// curls into a full circle and the tip returns to the root (0, 0) with its
/// angle turned by 2π. The discretization leaves a tip error ∝ 1/n²:
/// measured with 64 equal increments, tip x = 2.68e-2, 6.50e-3, 1.61e-3,
/// 4.02e-4 m for n = 16, 32, 64, 128 beams (y ≤ 2.3e-3 m, 8.2e-6 m at n = 64).
#[test]
fn load_steps_are_equal_increments_and_the_rollup_closes_the_circle() {
    let (dy, sol) = rollup(64);
    assert_eq!(sol.increments, 64, "64 equal load increments");
    let mech = dy.mechanism().clone();
    let b = &mech.node("B").unwrap().position;
    let (x, y) = (sol.x[b[0]], sol.x[b[1]]);
    assert!(
        x.hypot(y) < 2e-3,
        "tip at ({x:.3e}, {y:.3e}), the closed form puts it at the root"
    );
}

/// Issue 13 item 4: the solution carries the configuration the solver
/// converged to: x solves x = F(q) (a position solve started there stays
/// there) and ε = D(x) are the solution's deformations. Before, callers
/// solved x = F(q) again from the reference configuration, which for the
/// roll-up failed or landed on another branch.
#[test]
fn the_equilibrium_carries_its_configuration() {
    for steps in [1, 4, 64] {
        let (dy, sol) = rollup(steps);
        let mech = dy.mechanism().clone();
        let mut k = flexmb_kinematics::Kinematics::new(mech.clone());
        k.set_guess(&sol.x);
        k.solve(&sol.q, 0.0).unwrap();
        let dx = max_diff(k.x(), &sol.x);
        let de = max_diff(k.eps(), &sol.eps);
        assert!(
            dx < 1e-12 && de < 1e-12,
            "steps {steps}: x, ε of the solution are off F(q) by {dx:.3e}, {de:.3e}"
        );
        assert_eq!(sol.x.len(), mech.n_x());
        assert_eq!(sol.eps.len(), mech.n_eps());
    }
}
