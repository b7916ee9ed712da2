//! Starting at rest under a force that begins smoothly (f(t0) = 0, as for a
//! mechanism in equilibrium hit by the raised-cosine pulse of thesis (6.27)):
//! the first step must not jump over the pulse.

use flexmb_ode::{Adams, AdamsOptions, Dopri5, Dopri5Options, OdeSystem, Output, RhsError};

/// y'' = F(t) with F the raised-cosine pulse of duration 0.1 s.
struct Pulse;

impl OdeSystem for Pulse {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let f = if t <= 0.1 {
            0.5 * (1.0 - (20.0 * std::f64::consts::PI * t).cos())
        } else {
            0.0
        };
        dy[0] = y[1];
        dy[1] = f;
        Ok(())
    }
}

#[test]
fn the_first_step_resolves_a_pulse_that_starts_from_rest() {
    // exact: velocity after the pulse 0.05, position at 0.3 s = 0.05·0.3 − ∫₀^0.1 t F dt = 0.015 − 0.0025
    let exact = 0.05 * 0.3 - 0.0025;
    let times: Vec<f64> = (0..=30).map(|i| 0.01 * i as f64).collect();
    let a = Adams::new(AdamsOptions::default())
        .solve(
            &mut Pulse,
            0.0,
            &[0.0, 0.0],
            0.3,
            &Output::Times(times.clone()),
        )
        .unwrap();
    let y = a.last().unwrap().1.to_vec();
    assert!(
        (y[0] / exact - 1.0).abs() < 1e-3,
        "Adams: {} vs {exact} ({} evaluations)",
        y[0],
        a.stats.rhs_evals
    );
    let d = Dopri5::new(Dopri5Options::default())
        .solve(&mut Pulse, 0.0, &[0.0, 0.0], 0.3, &Output::Times(times))
        .unwrap();
    let y = d.last().unwrap().1.to_vec();
    assert!(
        (y[0] / exact - 1.0).abs() < 1e-3,
        "DOPRI5: {} vs {exact}",
        y[0]
    );
}
