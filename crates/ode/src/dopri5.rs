//! Dormand–Prince 5(4) with the step-size control of MATLAB's `ode45`.
//!
//! # Method
//!
//! The explicit Runge–Kutta pair of Dormand & Prince (J. Comput. Appl. Math.
//! 6, 1980), 7 stages, FSAL ("first same as last": the last stage of an
//! accepted step is the first stage of the next one), propagating the
//! 5th-order solution (local extrapolation). Dense output uses the
//! 4th-order continuous extension of Shampine ("Some practical Runge–Kutta
//! formulas", Math. Comp. 46, 1986), the one used by `ode45` (`ntrp45`); it
//! needs no extra evaluation.
//!
//! # Control rules (as described for `ode45` in Shampine & Reichelt, "The
//! MATLAB ODE Suite", SIAM J. Sci. Comput. 18, 1997, and in the `ode45`
//! documentation)
//!
//! With `rtol` (default `1e-3`, raised to `100·eps` if smaller), `atol`
//! (default `1e-6`, scalar or per component), `threshold_i = atol_i / rtol`,
//! `eps(t)` the floating-point spacing at `|t|` and `T = |t_end − t0|`:
//!
//! 1. `hmax = min(T, MaxStep)` with `MaxStep` defaulting to `0.1·T`.
//! 2. Initial step (unless given as `h0`, then `min(hmax, max(hmin, h0))`):
//!    `rh = ‖f0_i / max(|y0_i|, threshold_i)‖∞ / (0.8·rtol^(1/5))`,
//!    `h = min(hmax, T)`, and `h = 1/rh` if `h·rh > 1`; finally
//!    `h = max(h, hmin)`.
//! 3. At the start of every step `hmin = 16·eps(t)` and
//!    `h = min(hmax, max(hmin, h))`; if `1.1·h ≥ |t_end − t|` the step is
//!    stretched to end exactly at `t_end`.
//! 4. Error test: `err = h·‖(Σ_j e_j k_j)_i / max(|y_i|, |ynew_i|, threshold_i)‖∞`
//!    (`e` = difference of the 5th- and 4th-order weights); the step is
//!    accepted if `err ≤ rtol`.
//! 5. Rejected step: if `h ≤ hmin` the integration fails
//!    ([`OdeError::StepSizeTooSmall`]). On the first failure of the step
//!    `h = max(hmin, h·max(0.1, 0.8·(rtol/err)^(1/5)))`, on later failures
//!    `h = max(hmin, h/2)`.
//! 6. Accepted step without failure: `h = h / (1.25·(err/rtol)^(1/5))`, with
//!    growth limited to a factor 5. After an accepted step that had failures
//!    the step size is not increased (it stays as in rule 5).
//!
//! Every attempted step costs 6 evaluations of `f` (stages 2–7; stage 7 is
//! needed for the error estimate), and the integration starts with one
//! evaluation of `f(t0, y0)`, so
//! `rhs_evals = 1 + 6·(steps_accepted + steps_rejected)`, the count that
//! `ode45` reports.
//!
//! Not reproduced from `ode45`: the `Refine` option (extra interpolated
//! output points per step; use [`Output::Times`] instead), the
//! `NormControl`, `NonNegative`, `Events` and `Mass` options.
//!
//! A fixed-step mode ([`Dopri5Options::fixed_step`]) switches off the error
//! control, for convergence studies.

use crate::common::{
    check_interval, check_optional_positive, check_positive, check_state, check_vector, eval_rhs,
    spacing, Control, FirstOrderSink, Output, Solution, Stats, Status, Tolerance,
};
use crate::error::OdeError;
use crate::system::OdeSystem;
use crate::FirstOrderIntegrator;

/// Nodes `c_i`.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

/// Coupling coefficients `a_ij` (rows 2 to 7; row 7 holds the 5th-order
/// weights `b`).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Error weights `e = b(5th) − b(4th)`.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Continuous extension: `b_j(s) = Σ_m BI[j](m)·s^(m+1)`.
const BI: [[f64; 4]; 7] = [
    [1.0, -183.0 / 64.0, 37.0 / 12.0, -145.0 / 128.0],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 1500.0 / 371.0, -1000.0 / 159.0, 1000.0 / 371.0],
    [0.0, -125.0 / 32.0, 125.0 / 12.0, -375.0 / 64.0],
    [0.0, 9477.0 / 3392.0, -729.0 / 106.0, 25515.0 / 6784.0],
    [0.0, -11.0 / 7.0, 11.0 / 3.0, -55.0 / 28.0],
    [0.0, 3.0 / 2.0, -4.0, 5.0 / 2.0],
];

/// Options of [`Dopri5`]. The defaults are those of `ode45`.
#[derive(Clone, Debug, PartialEq)]
pub struct Dopri5Options {
    /// Relative tolerance (`RelTol`), default `1e-3`.
    pub rtol: f64,
    /// Absolute tolerance (`AbsTol`), default `1e-6`.
    pub atol: Tolerance,
    /// Initial step size (`InitialStep`); `None` selects the `ode45`
    /// heuristic.
    pub h0: Option<f64>,
    /// Maximum step size (`MaxStep`); `None` means `0.1·|t_end − t0|`.
    pub hmax: Option<f64>,
    /// Maximum number of accepted steps, default 1 000 000.
    pub max_steps: usize,
    /// If set, integrate with this constant step size (the last step is
    /// shortened to hit `t_end`) and no error control.
    pub fixed_step: Option<f64>,
}

impl Default for Dopri5Options {
    fn default() -> Self {
        Self {
            rtol: 1e-3,
            atol: Tolerance::Scalar(1e-6),
            h0: None,
            hmax: None,
            max_steps: 1_000_000,
            fixed_step: None,
        }
    }
}

impl Dopri5Options {
    /// Sets the relative tolerance.
    pub fn rtol(mut self, rtol: f64) -> Self {
        self.rtol = rtol;
        self
    }
    /// Sets the absolute tolerance (scalar or per component).
    pub fn atol(mut self, atol: impl Into<Tolerance>) -> Self {
        self.atol = atol.into();
        self
    }
    /// Sets the initial step size.
    pub fn h0(mut self, h0: f64) -> Self {
        self.h0 = Some(h0);
        self
    }
    /// Sets the maximum step size.
    pub fn hmax(mut self, hmax: f64) -> Self {
        self.hmax = Some(hmax);
        self
    }
    /// Sets the maximum number of accepted steps.
    pub fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps;
        self
    }
    /// Selects fixed-step mode with step `h`.
    pub fn fixed_step(mut self, h: f64) -> Self {
        self.fixed_step = Some(h);
        self
    }
}

/// Dormand–Prince 5(4) integrator behaving like MATLAB's `ode45`; see the
/// [module documentation](self) for the exact rules.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dopri5 {
    /// The options.
    pub options: Dopri5Options,
}

/// Work arrays of one integration.
struct Work {
    /// Stage derivatives `k_1 … k_7`.
    k: [Vec<f64>; 7],
    y: Vec<f64>,
    y_new: Vec<f64>,
    y_stage: Vec<f64>,
}

impl Dopri5 {
    /// Creates the integrator with the given options.
    pub fn new(options: Dopri5Options) -> Self {
        Self { options }
    }

    /// Integrates from `(t0, y0)` to `t_end` (which may be smaller than `t0`)
    /// and stores the points selected by `output`.
    pub fn solve<S: OdeSystem + ?Sized>(
        &self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        output: &Output,
    ) -> Result<Solution, OdeError> {
        self.solve_with(sys, t0, y0, t_end, output, |_, _| Control::Continue)
    }

    /// Like [`Dopri5::solve`], calling `observer(t, y)` at every output point
    /// (in order, including the initial one when selected); the integration
    /// stops cleanly when the observer returns [`Control::Stop`].
    pub fn solve_with<S, F>(
        &self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        output: &Output,
        observer: F,
    ) -> Result<Solution, OdeError>
    where
        S: OdeSystem + ?Sized,
        F: FnMut(f64, &[f64]) -> Control,
    {
        let o = &self.options;
        let n = sys.dim();
        check_interval(t0, t_end)?;
        check_vector("y0", y0, n)?;
        check_positive("rtol", o.rtol)?;
        let atol = o.atol.expand("atol", n)?;
        check_optional_positive("h0", o.h0)?;
        check_optional_positive("hmax", o.hmax)?;
        check_optional_positive("fixed_step", o.fixed_step)?;
        if o.max_steps == 0 {
            return Err(OdeError::InvalidOption {
                name: "max_steps",
                reason: "must be at least 1".into(),
            });
        }
        output.validate(t0, t_end)?;

        let rtol = o.rtol.max(100.0 * f64::EPSILON);
        let threshold: Vec<f64> = atol.iter().map(|a| a / rtol).collect();
        let tdir = (t_end - t0).signum();
        let span = (t_end - t0).abs();
        let hmax = o.hmax.unwrap_or(0.1 * span).min(span);
        let pow = 1.0 / 5.0;

        let mut w = Work {
            k: std::array::from_fn(|_| vec![0.0; n]),
            y: y0.to_vec(),
            y_new: vec![0.0; n],
            y_stage: vec![0.0; n],
        };
        let mut stats = Stats::default();
        let mut sink = FirstOrderSink::new(output, n, tdir, observer);
        let mut t = t0;

        eval_rhs(sys, t, &w.y, &mut w.k[0], &mut stats)?;
        if sink.initial(t, &w.y) == Control::Stop {
            return Ok(finish(sink.solution, stats));
        }

        // Initial step size.
        let mut absh = if let Some(hf) = o.fixed_step {
            hf
        } else {
            let hmin = 16.0 * spacing(t);
            match o.h0 {
                Some(h0) => hmax.min(hmin.max(h0)),
                None => {
                    let mut absh = hmax.min(span);
                    let rh = (0..n)
                        .map(|i| w.k[0][i].abs() / w.y[i].abs().max(threshold[i]))
                        .fold(0.0, f64::max)
                        / (0.8 * rtol.powf(pow));
                    if absh * rh > 1.0 {
                        absh = 1.0 / rh;
                    }
                    absh.max(hmin)
                }
            }
        };

        loop {
            if stats.steps_accepted >= o.max_steps {
                return Err(OdeError::MaxStepsExceeded {
                    t,
                    max_steps: o.max_steps,
                });
            }
            let hmin = 16.0 * spacing(t);
            let remaining = (t_end - t).abs();
            let mut done;
            let mut h;
            if o.fixed_step.is_some() {
                done = remaining <= absh * (1.0 + 1e-9);
                h = if done { t_end - t } else { tdir * absh };
            } else {
                absh = hmax.min(hmin.max(absh));
                h = tdir * absh;
                done = false;
                if 1.1 * absh >= remaining {
                    h = t_end - t;
                    absh = h.abs();
                    done = true;
                }
            }

            // Attempt the step until the error test passes.
            let mut no_failure = true;
            let err = loop {
                let t_new = if done { t_end } else { t + h };
                h = t_new - t;
                match attempt(sys, t, h, t_new, &mut w, &mut stats) {
                    Ok(()) => {}
                    Err(e) if e.is_recoverable_rhs() && o.fixed_step.is_none() => {
                        // the system could not be evaluated at a stage: reject
                        // the step and retry with a quarter of it
                        stats.steps_rejected += 1;
                        if absh <= hmin {
                            return Err(e);
                        }
                        no_failure = false;
                        absh = hmin.max(0.25 * absh);
                        h = tdir * absh;
                        done = false;
                        continue;
                    }
                    Err(e) => return Err(e),
                }
                if o.fixed_step.is_some() {
                    break 0.0;
                }
                let mut err: f64 = 0.0;
                for i in 0..n {
                    let mut e = 0.0;
                    for (j, kj) in w.k.iter().enumerate() {
                        e += E[j] * kj[i];
                    }
                    let scale = w.y[i].abs().max(w.y_new[i].abs()).max(threshold[i]);
                    err = err.max(e.abs() / scale);
                }
                let err = absh * err;
                if err <= rtol {
                    break err;
                }
                stats.steps_rejected += 1;
                if absh <= hmin {
                    return Err(OdeError::StepSizeTooSmall {
                        t,
                        h: absh,
                        h_min: hmin,
                    });
                }
                absh = if no_failure {
                    no_failure = false;
                    hmin.max(absh * (0.8 * (rtol / err).powf(pow)).max(0.1))
                } else {
                    hmin.max(0.5 * absh)
                };
                h = tdir * absh;
                done = false;
            };

            let t_new = t + h;
            let t_new = if done { t_end } else { t_new };
            stats.record_accepted(h);
            let control = {
                let (y, k) = (&w.y, &w.k);
                sink.step(t_new, &w.y_new, done, |tau, out| {
                    interpolate(t, h, y, k, tau, out)
                })
            };
            if done {
                break;
            }
            if control == Control::Stop {
                return Ok(finish(sink.solution, stats));
            }
            if sys.step_accepted(t_new, &w.y_new) == Control::Stop {
                sink.solution.status = Status::Stopped { t: t_new };
                return Ok(finish(sink.solution, stats));
            }
            if no_failure && o.fixed_step.is_none() {
                let temp = 1.25 * (err / rtol).powf(pow);
                absh = if temp > 0.2 { absh / temp } else { 5.0 * absh };
            }
            t = t_new;
            std::mem::swap(&mut w.y, &mut w.y_new);
            w.k.swap(0, 6);
        }
        Ok(finish(sink.solution, stats))
    }
}

fn finish(mut solution: Solution, stats: Stats) -> Solution {
    solution.stats = stats;
    solution
}

/// Computes stages 2–7 of a step of size `h` from `(t, y)`; `k[0]` must
/// hold `f(t, y)`. Leaves the 5th-order solution in `y_new` and
/// `f(t_new, y_new)` in `k[6]`.
fn attempt<S: OdeSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    t_new: f64,
    w: &mut Work,
    stats: &mut Stats,
) -> Result<(), OdeError> {
    let n = w.y.len();
    for s in 1..7 {
        let (done, rest) = w.k.split_at_mut(s);
        let target = if s == 6 { &mut w.y_new } else { &mut w.y_stage };
        let a = &A[s];
        for i in 0..n {
            let mut acc = 0.0;
            for (j, kj) in done.iter().enumerate() {
                acc += a[j] * kj[i];
            }
            target[i] = w.y[i] + h * acc;
        }
        if s == 6 {
            check_state(t_new, &w.y_new)?;
            eval_rhs(sys, t_new, &w.y_new, &mut rest[0], stats)?;
        } else {
            eval_rhs(sys, t + C[s] * h, &w.y_stage, &mut rest[0], stats)?;
        }
    }
    Ok(())
}

/// Evaluates the continuous extension of the step `(t, y) → t + h` at `tau`.
fn interpolate(t: f64, h: f64, y: &[f64], k: &[Vec<f64>; 7], tau: f64, out: &mut [f64]) {
    let s = (tau - t) / h;
    let mut b = [0.0; 7];
    for (bj, c) in b.iter_mut().zip(BI.iter()) {
        *bj = h * s * (c[0] + s * (c[1] + s * (c[2] + s * c[3])));
    }
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = 0.0;
        for (bj, kj) in b.iter().zip(k.iter()) {
            acc += bj * kj[i];
        }
        *o = y[i] + acc;
    }
}

impl FirstOrderIntegrator for Dopri5 {
    fn name(&self) -> &'static str {
        "DOPRI5 (ode45-like)"
    }

    fn integrate(
        &self,
        sys: &mut dyn OdeSystem,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        output: &Output,
        observer: &mut dyn FnMut(f64, &[f64]) -> Control,
    ) -> Result<Solution, OdeError> {
        self.solve_with(sys, t0, y0, t_end, output, observer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Weights of the continuous extension at `s`.
    fn b_of(s: f64) -> [f64; 7] {
        let mut b = [0.0; 7];
        for (bj, c) in b.iter_mut().zip(BI.iter()) {
            *bj = s * (c[0] + s * (c[1] + s * (c[2] + s * c[3])));
        }
        b
    }

    #[test]
    fn tableau_is_consistent() {
        for s in 1..7 {
            let row: f64 = A[s].iter().sum();
            assert!((row - C[s]).abs() < 1e-14, "row {s}");
        }
        let e: f64 = E.iter().sum();
        assert!(e.abs() < 1e-15);
    }

    #[test]
    fn continuous_extension_order_conditions() {
        // Order conditions of a 4th-order continuous extension (Hairer,
        // Nørsett & Wanner, Solving ODEs I, sect. II.6), checked at several
        // points s of the step.
        let a = |i: usize, j: usize| if j < 6 { A[i][j] } else { 0.0 };
        for &s in &[0.1, 0.3, 0.5, 0.77, 1.0] {
            let b = b_of(s);
            let sum = |f: &dyn Fn(usize) -> f64| (0..7).map(|i| b[i] * f(i)).sum::<f64>();
            let ac = |i: usize| (0..7).map(|j| a(i, j) * C[j]).sum::<f64>();
            let ac2 = |i: usize| (0..7).map(|j| a(i, j) * C[j] * C[j]).sum::<f64>();
            let aac = |i: usize| (0..7).map(|j| a(i, j) * ac(j)).sum::<f64>();
            let checks = [
                (sum(&|_| 1.0), s),
                (sum(&|i| C[i]), s * s / 2.0),
                (sum(&|i| C[i] * C[i]), s.powi(3) / 3.0),
                (sum(&ac), s.powi(3) / 6.0),
                (sum(&|i| C[i].powi(3)), s.powi(4) / 4.0),
                (sum(&|i| C[i] * ac(i)), s.powi(4) / 8.0),
                (sum(&ac2), s.powi(4) / 12.0),
                (sum(&aac), s.powi(4) / 24.0),
            ];
            for (m, (got, want)) in checks.iter().enumerate() {
                assert!(
                    (got - want).abs() < 1e-13,
                    "s = {s}, condition {m}: {got} vs {want}"
                );
            }
        }
        // At s = 1 the extension reproduces the 5th-order step.
        let b = b_of(1.0);
        for j in 0..6 {
            assert!((b[j] - A[6][j]).abs() < 1e-14);
        }
        assert!(b[6].abs() < 1e-14);
    }
}
