//! Dense output at requested times: accuracy and no extra evaluations.

mod common;

use common::{sdof_exact, Forced, Linear2};
use flexmb_ode::{
    Adams, AdamsOptions, Dopri5, Dopri5Options, FirstOrderIntegrator, GeneralizedAlpha,
    GeneralizedAlphaOptions, Output,
};

fn grid(t_end: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|i| t_end * i as f64 / n as f64).collect()
}

/// Interpolated values at 1001 times on [0, 10] for y' = −y + sin t agree
/// with the exact solution within 10·tol (reference: closed-form solution;
/// measured at most 1.01·tol for DOPRI5 and 5.3·tol for Adams), and cost no
/// evaluation beyond those of the same run with only the final point.
#[test]
fn first_order_dense_output_accuracy() {
    let times = grid(10.0, 1000);
    for tol in [1e-4, 1e-6, 1e-8] {
        let methods: [Box<dyn FirstOrderIntegrator>; 2] = [
            Box::new(Dopri5::new(Dopri5Options::default().rtol(tol).atol(tol))),
            Box::new(Adams::new(AdamsOptions::default().rtol(tol).atol(tol))),
        ];
        for m in &methods {
            let dense = m
                .integrate(
                    &mut Forced,
                    0.0,
                    &[1.0],
                    10.0,
                    &Output::Times(times.clone()),
                    &mut |_, _| flexmb_ode::Control::Continue,
                )
                .unwrap();
            assert_eq!(dense.len(), times.len());
            assert_eq!(dense.t(), &times[..]);
            let err = dense
                .iter()
                .map(|(t, y)| (y[0] - Forced::exact(t)).abs())
                .fold(0.0, f64::max);
            assert!(
                err <= 10.0 * tol,
                "{} tol {tol}: dense error {err}",
                m.name()
            );
            let last_only = m
                .integrate(
                    &mut Forced,
                    0.0,
                    &[1.0],
                    10.0,
                    &Output::Final,
                    &mut |_, _| flexmb_ode::Control::Continue,
                )
                .unwrap();
            assert_eq!(dense.stats, last_only.stats, "{}", m.name());
            assert_eq!(last_only.len(), 1);
            assert_eq!(last_only.t()[0], 10.0);
        }
    }
}

/// The DOPRI5 continuous extension is 4th order (Shampine 1986): its local
/// error is O(h⁵), so with fixed steps the maximum error at 400 points of
/// [0, 2] must fall at least by 2⁴·0.8 = 12.8 when h halves (measured 33–35,
/// i.e. O(h⁵) like the step values), and stay within 8× the largest error
/// at the step points (measured 5.4×).
#[test]
fn dopri5_dense_output_order_fixed_step() {
    let times = grid(2.0, 400);
    let mut prev = None;
    for h in [0.2, 0.1, 0.05, 0.025] {
        let solver = Dopri5::new(Dopri5Options::default().fixed_step(h));
        let dense = solver
            .solve(&mut Forced, 0.0, &[1.0], 2.0, &Output::Times(times.clone()))
            .unwrap();
        let steps = solver
            .solve(&mut Forced, 0.0, &[1.0], 2.0, &Output::Steps)
            .unwrap();
        let e_dense = dense
            .iter()
            .map(|(t, y)| (y[0] - Forced::exact(t)).abs())
            .fold(0.0, f64::max);
        let e_steps = steps
            .iter()
            .map(|(t, y)| (y[0] - Forced::exact(t)).abs())
            .fold(0.0, f64::max);
        assert!(
            e_dense <= 8.0 * e_steps,
            "h {h}: dense {e_dense} steps {e_steps}"
        );
        if let Some(p) = prev {
            let ratio: f64 = p / e_dense;
            assert!(ratio >= 12.8, "h {h}: ratio {ratio}");
        }
        prev = Some(e_dense);
    }
}

/// Generalized-α dense output (cubic Hermite) at 501 times: its error with
/// respect to the exact solution of q̈ + 0.1 q̇ + 4 q = sin t is at most
/// 1.2× the largest error at the step points (interpolation adds O(h⁴) to
/// the O(h²) global error) plus 1e-7 (measured: 5.507e-4 at the output
/// times, 5.507e-4 at the steps), and no evaluation is added.
#[test]
fn generalized_alpha_dense_output() {
    let (c, k) = (0.1, 4.0);
    let times = grid(5.0, 500);
    let solver = GeneralizedAlpha::new(GeneralizedAlphaOptions::default().rtol(1e-6).atol(1e-6));
    let dense = solver
        .solve(
            &mut Linear2::sdof(c, k),
            0.0,
            &[1.0],
            &[0.0],
            5.0,
            &Output::Times(times.clone()),
        )
        .unwrap();
    let steps = solver
        .solve(
            &mut Linear2::sdof(c, k),
            0.0,
            &[1.0],
            &[0.0],
            5.0,
            &Output::Steps,
        )
        .unwrap();
    assert_eq!(dense.stats, steps.stats);
    let err = |sol: &flexmb_ode::SecondOrderSolution| {
        (0..sol.len())
            .map(|i| {
                let (q, qd) = sdof_exact(c, k, 1.0, 0.0, sol.t()[i]);
                ((sol.q(i)[0] - q).abs(), (sol.qd(i)[0] - qd).abs())
            })
            .fold((0.0f64, 0.0f64), |a, b| (a.0.max(b.0), a.1.max(b.1)))
    };
    let (dq, dv) = err(&dense);
    let (sq, sv) = err(&steps);
    assert!(dq <= 1.2 * sq + 1e-7, "q: dense {dq} steps {sq}");
    assert!(dv <= 1.2 * sv + 1e-6, "q̇: dense {dv} steps {sv}");
    assert_eq!(dense.t(), &times[..]);
}
