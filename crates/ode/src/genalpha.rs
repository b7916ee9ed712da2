//! Generalized-α method (Chung & Hulbert) for second-order systems in
//! residual form, with Newton iterations and local error control.
//!
//! # Formulation
//!
//! The system is `g(t, q, q̇, q̈) = 0` ([`SecondOrderSystem`]). Following
//! Chung & Hulbert (J. Appl. Mech. 60, 1993) in the form of Arnold & Brüls
//! (Multibody Syst. Dyn. 18, 2007), the equations are satisfied at the end
//! of each step and an auxiliary acceleration-like variable `a` carries the
//! α-weighting:
//!
//! ```text
//! g(t_{n+1}, q_{n+1}, q̇_{n+1}, q̈_{n+1}) = 0
//! (1 − α_m)·a_{n+1} + α_m·a_n = (1 − α_f)·q̈_{n+1} + α_f·q̈_n
//! q_{n+1} = q_n + h·q̇_n + h²·((1/2 − β)·a_n + β·a_{n+1})
//! q̇_{n+1} = q̇_n + h·((1 − γ)·a_n + γ·a_{n+1})
//! ```
//!
//! with, for the spectral radius at infinity `ρ∞ ∈ [0, 1]` (default 0.8),
//! `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = 1/2 + α_f − α_m`,
//! `β = (γ + 1/2)²/4`: second order, unconditionally stable for linear
//! problems, and high frequencies damped to `ρ∞` per step. `a_0 = q̈_0`.
//!
//! # Newton iteration
//!
//! The unknown is `q_{n+1}`; `q̇` and `q̈` follow with `∂q̇/∂q = γ'` and
//! `∂q̈/∂q = β'`, `β' = (1 − α_m)/(β h² (1 − α_f))`, `γ' = γ/(β h)`. The
//! iteration matrix is `S = β'·M + γ'·C + K` with `M = ∂g/∂q̈`,
//! `C = ∂g/∂q̇`, `K = ∂g/∂q` from [`SecondOrderSystem::tangent`]. The
//! predictor keeps the acceleration (`q̈_{n+1} = q̈_n`).
//!
//! Modified Newton: the tangent matrices are evaluated at the start of a
//! step and kept across iterations and steps; `S` is refactored (dense LU
//! with partial pivoting) when `h` changes or the tangent is re-evaluated.
//! The tangent is re-evaluated after a step whose contraction rate
//! `θ = ‖Δ_k‖/‖Δ_{k−1}‖` exceeded
//! [`GeneralizedAlphaOptions::jacobian_refresh`], and after a convergence
//! failure with an old tangent; a failure with a fresh tangent halves `h`.
//! Convergence (as in Hairer & Wanner's RADAU5) is declared when
//! `η·‖Δ_k‖ ≤ newton_tol` with `η = θ/(1 − θ)` (on the first iteration `η`
//! is carried over from the previous step), the norm being the larger of
//! the weighted RMS norms of the position increment (weights
//! `atol_i + rtol·|q_i|`) and of the velocity increment it makes,
//! `γ/(βh)·Δq` (weights `atol_i + rtol·|q̇_i|`). With small steps on stiff
//! problems a position increment within tolerance can leave a velocity
//! error that the position error estimate never sees; on the 44-DOF spatial
//! guidance at rtol 1e-3 such errors grew until no step could be taken.
//! An iterate the system cannot evaluate (a recoverable error, e.g. a
//! configuration a mechanism cannot reach) fails the Newton solve like a
//! diverging iteration.
//!
//! # Error estimate and step-size control
//!
//! Both the position and the velocity local errors are estimated, from the
//! accelerations of the last steps, by the leading term of the local
//! truncation error. Following Arnold & Brüls (2007, sect. 3), along a
//! smooth solution the auxiliary variable is
//! `a_n = q̈(t_n + Δ·h) + O(h²)` with `Δ = α_m − α_f`; writing
//! `a_n = q̈ + Δ·h·q⃛ + c₂·h²·q⁗ + O(h³)` and matching the recursion for `a`
//! gives `c₂ = (1 − α_f)/2 − (1 − α_m)(1/2 + Δ)`. Expanding the update
//! formulas then gives the local errors (the differences from the Taylor
//! series of the exact solution)
//!
//! ```text
//! position: C_q·h³·q⃛,  C_q = β − γ/2 + 1/12        (= β + Δ/2 − 1/6)
//! velocity: C_v·h³·q⁗,  C_v = c₂ + γ·(1/2 + Δ) − 1/6
//! ```
//!
//! (for `ρ∞ = 1`, the trapezoidal rule, `C_q = C_v = 1/12`). The
//! position estimate is the one of Zienkiewicz & Xie (Earthquake Eng.
//! Struct. Dyn. 20, 1991) for Newmark's method, with generalized-α's
//! constant: `q⃛` is replaced by the divided difference of the
//! accelerations. The velocity estimate replaces `q⁗` by the second divided
//! difference over the current and the previous step (`h_p`):
//!
//! ```text
//! e_q = C_q·h²·(q̈_{n+1} − q̈_n)
//! e_v = C_v·2h²/(h + h_p)·((q̈_{n+1} − q̈_n) − (h/h_p)·(q̈_n − q̈_{n−1}))
//! ```
//!
//! (`e_v = 0` on the first step, which has no previous one). Both are
//! filtered as in the stiff codes, `e ← S⁻¹·β'·M·e` with the iteration
//! matrix `S` (Hairer & Wanner, *Solving ODEs II*, IV.8, eq. 8.20, after
//! Shampine): a component with `h·ω ≪ 1` passes unchanged to `O(h²ω²)`,
//! a stiff one, which the method damps rather than resolves, is scaled by
//! about `β'/ω²`. Without the filter the velocity estimate, which sees the
//! accelerations of the highest modes with the factor `1/h`, drove the step
//! of a 32-element spin-up beam at rtol 1e-8 down to the period of its
//! highest modes (600 000 steps instead of 1 700). The step is accepted if
//! `err ≤ 1`, with the usual weighted RMS norm over all `2n` components of
//! `y = (q, q̇)` (Hairer, Nørsett & Wanner, *Solving ODEs I*, II.4,
//! eq. 4.11):
//!
//! ```text
//! err = sqrt( (Σ_i (e_q,i/sc_q,i)² + Σ_i (e_v,i/sc_v,i)²) / 2n ),
//! sc_i = atol_i + rtol·max(|y_n,i|, |y_{n+1},i|)
//! ```
//!
//! with the same `atol` for positions and velocities. Both tolerances act
//! on the step: `rtol` whenever `rtol·|y_i|` is not small against `atol_i`
//! for the components that dominate the error. The new step is
//! `h·min(5, max(0.2, 0.9·err^(−1/3)))` (both estimates are `O(h³)`; no
//! increase right after a rejection); increases by less than 20% are not
//! made, so that the factorization can be reused. As in `ode45`, a step
//! within 10% of the remaining interval is stretched to end exactly at
//! `t_end`. The control is per step: the global error is typically a few
//! times to a few hundred times the tolerance, growing as `tol^(−1/3)`
//! (27× at 1e-3 and 540× at 1e-7 in `tests/convergence.rs`).
//!
//! The initial acceleration solves `M q̈_0 = −g(t_0, q_0, q̇_0, 0)` (exact
//! when `g` is affine in `q̈`), unless given.
//!
//! Dense output: cubic Hermite interpolation of `q` (from `q`, `q̇` at both
//! ends of the step) and of `q̇` (from `q̇`, `q̈`); `q̈` is interpolated
//! linearly. No extra evaluation.

use faer::Mat;

use crate::common::{
    check_interval, check_optional_positive, check_positive, check_vector, first_non_finite,
    spacing, wrap_rhs_error, Control, Output, Stats, Status, Tolerance,
};
use crate::error::OdeError;
use crate::system::SecondOrderSystem;
use flexmb_linalg::{DenseLu, LuError};

/// Options of [`GeneralizedAlpha`].
#[derive(Clone, Debug, PartialEq)]
pub struct GeneralizedAlphaOptions {
    /// Spectral radius at infinity `ρ∞ ∈ [0, 1]`, default 0.8.
    pub rho_inf: f64,
    /// Relative tolerance on positions and velocities, default `1e-3`.
    pub rtol: f64,
    /// Absolute tolerance on positions and velocities, default `1e-6`.
    pub atol: Tolerance,
    /// Initial step size; `None` means `min(hmax, |t_end − t0|/100)`.
    pub h0: Option<f64>,
    /// Maximum step size; `None` means `|t_end − t0|`.
    pub hmax: Option<f64>,
    /// Maximum number of accepted steps, default 1 000 000.
    pub max_steps: usize,
    /// If set, integrate with this constant step (last step shortened to hit
    /// `t_end`) and no error control; Newton still uses `rtol`/`atol`.
    pub fixed_step: Option<f64>,
    /// Maximum Newton iterations per attempt, default 8.
    pub max_newton_iterations: usize,
    /// Newton stopping tolerance in the weighted norm (1 = the local error
    /// tolerance), default 0.01.
    pub newton_tol: f64,
    /// Contraction rate above which the tangent is re-evaluated for the next
    /// step, default 0.25.
    pub jacobian_refresh: f64,
    /// Initial acceleration; `None` computes the consistent one.
    pub initial_acceleration: Option<Vec<f64>>,
}

impl Default for GeneralizedAlphaOptions {
    fn default() -> Self {
        Self {
            rho_inf: 0.8,
            rtol: 1e-3,
            atol: Tolerance::Scalar(1e-6),
            h0: None,
            hmax: None,
            max_steps: 1_000_000,
            fixed_step: None,
            max_newton_iterations: 8,
            newton_tol: 0.01,
            jacobian_refresh: 0.25,
            initial_acceleration: None,
        }
    }
}

impl GeneralizedAlphaOptions {
    /// Sets `ρ∞`.
    pub fn rho_inf(mut self, rho_inf: f64) -> Self {
        self.rho_inf = rho_inf;
        self
    }
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

/// The four parameters of the method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlphaParameters {
    /// `α_m`.
    pub alpha_m: f64,
    /// `α_f`.
    pub alpha_f: f64,
    /// `β`.
    pub beta: f64,
    /// `γ`.
    pub gamma: f64,
}

impl AlphaParameters {
    /// Chung–Hulbert parameters for the spectral radius at infinity `rho_inf`.
    pub fn from_rho_inf(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        Self {
            alpha_m,
            alpha_f,
            beta,
            gamma,
        }
    }

    /// Constant `C_q` of the local position error `C_q·h³·q⃛` (module
    /// documentation, "Error estimate").
    pub fn error_constant(&self) -> f64 {
        self.beta - 0.5 * self.gamma + 1.0 / 12.0
    }

    /// Constant `C_v` of the local velocity error `C_v·h³·q⁗`:
    /// `c₂ + γ(1/2 + Δ) − 1/6` with `Δ = α_m − α_f` and
    /// `c₂ = (1 − α_f)/2 − (1 − α_m)(1/2 + Δ)` (module documentation).
    pub fn velocity_error_constant(&self) -> f64 {
        let delta = self.alpha_m - self.alpha_f;
        let c2 = 0.5 * (1.0 - self.alpha_f) - (1.0 - self.alpha_m) * (0.5 + delta);
        c2 + self.gamma * (0.5 + delta) - 1.0 / 6.0
    }
}

/// Solution of a second-order problem.
#[derive(Clone, Debug, PartialEq)]
pub struct SecondOrderSolution {
    t: Vec<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    dim: usize,
    /// Work statistics.
    pub stats: Stats,
    /// Whether `t_end` was reached or the observer stopped the integration.
    pub status: Status,
}

impl SecondOrderSolution {
    fn with_capacity(dim: usize, points: usize) -> Self {
        Self {
            t: Vec::with_capacity(points),
            q: Vec::with_capacity(points * dim),
            qd: Vec::with_capacity(points * dim),
            qdd: Vec::with_capacity(points * dim),
            dim,
            stats: Stats::default(),
            status: Status::Completed,
        }
    }
    /// Number of coordinates.
    pub fn dim(&self) -> usize {
        self.dim
    }
    /// Number of stored points.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// Whether no point is stored.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// The stored times.
    pub fn t(&self) -> &[f64] {
        &self.t
    }
    /// Positions at the `i`-th point (panics if out of range).
    pub fn q(&self, i: usize) -> &[f64] {
        &self.q[i * self.dim..(i + 1) * self.dim]
    }
    /// Velocities at the `i`-th point (panics if out of range).
    pub fn qd(&self, i: usize) -> &[f64] {
        &self.qd[i * self.dim..(i + 1) * self.dim]
    }
    /// Accelerations at the `i`-th point (panics if out of range).
    pub fn qdd(&self, i: usize) -> &[f64] {
        &self.qdd[i * self.dim..(i + 1) * self.dim]
    }
}

/// Kinematic state at one time.
struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    /// Auxiliary acceleration `a`.
    a: Vec<f64>,
}

impl State {
    fn zeros(n: usize) -> Self {
        Self {
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            a: vec![0.0; n],
        }
    }
}

/// Output collection for second-order solutions.
struct Sink<'o, F> {
    output: &'o Output,
    next_time: usize,
    solution: SecondOrderSolution,
    observer: F,
    buf: State,
}

impl<F: FnMut(f64, &[f64], &[f64], &[f64]) -> Control> Sink<'_, F> {
    fn emit(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> Control {
        let s = &mut self.solution;
        s.t.push(t);
        s.q.extend_from_slice(q);
        s.qd.extend_from_slice(qd);
        s.qdd.extend_from_slice(qdd);
        let c = (self.observer)(t, q, qd, qdd);
        if c == Control::Stop {
            s.status = Status::Stopped { t };
        }
        c
    }

    fn initial(&mut self, t0: f64, x: &State) -> Control {
        match self.output {
            Output::Steps => self.emit(t0, &x.q, &x.qd, &x.qdd),
            Output::Times(times) => {
                while self.next_time < times.len() && times[self.next_time] == t0 {
                    self.next_time += 1;
                    if self.emit(t0, &x.q, &x.qd, &x.qdd) == Control::Stop {
                        return Control::Stop;
                    }
                }
                Control::Continue
            }
            Output::Final => Control::Continue,
        }
    }

    /// Emits the requested points of the step `(t, x0) → (t1, x1)`.
    fn step(&mut self, t: f64, t1: f64, x0: &State, x1: &State, is_last: bool) -> Control {
        match self.output {
            Output::Steps => self.emit(t1, &x1.q, &x1.qd, &x1.qdd),
            Output::Final => {
                if is_last {
                    self.emit(t1, &x1.q, &x1.qd, &x1.qdd)
                } else {
                    Control::Continue
                }
            }
            Output::Times(times) => {
                let dir = (t1 - t).signum();
                while self.next_time < times.len() {
                    let tau = times[self.next_time];
                    if !is_last && dir * (tau - t1) > 0.0 {
                        break;
                    }
                    self.next_time += 1;
                    let c = if tau == t1 || is_last && dir * (tau - t1) >= 0.0 {
                        self.emit(tau, &x1.q, &x1.qd, &x1.qdd)
                    } else {
                        let mut buf = std::mem::replace(&mut self.buf, State::zeros(0));
                        hermite(t, t1, x0, x1, tau, &mut buf);
                        let c = self.emit(tau, &buf.q, &buf.qd, &buf.qdd);
                        self.buf = buf;
                        c
                    };
                    if c == Control::Stop {
                        return Control::Stop;
                    }
                }
                Control::Continue
            }
        }
    }
}

/// Hermite interpolation inside the step `[t, t1]`.
fn hermite(t: f64, t1: f64, x0: &State, x1: &State, tau: f64, out: &mut State) {
    let h = t1 - t;
    let s = (tau - t) / h;
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    for i in 0..x0.q.len() {
        out.q[i] = h00 * x0.q[i] + h10 * h * x0.qd[i] + h01 * x1.q[i] + h11 * h * x1.qd[i];
        out.qd[i] = h00 * x0.qd[i] + h10 * h * x0.qdd[i] + h01 * x1.qd[i] + h11 * h * x1.qdd[i];
        out.qdd[i] = (1.0 - s) * x0.qdd[i] + s * x1.qdd[i];
    }
}

/// Generalized-α integrator with step-size control; see the
/// [module documentation](self).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GeneralizedAlpha {
    /// The options.
    pub options: GeneralizedAlphaOptions,
}

/// Tangent matrices and the factored iteration matrix.
struct Linear {
    mass: Mat<f64>,
    damping: Mat<f64>,
    stiffness: Mat<f64>,
    lu: DenseLu,
    /// Step size for which `lu` holds `S`, if it is valid.
    h_lu: Option<f64>,
    /// Why the last factorization of `S` failed.
    lu_error: Option<LuError>,
    /// Whether the tangent was evaluated at the start of the current step.
    fresh: bool,
    /// The tangent should be re-evaluated before the next step.
    stale: bool,
}

/// Result of one Newton solve.
enum Newton {
    Converged { theta_max: f64 },
    Failed,
    Singular,
}

impl GeneralizedAlpha {
    /// Creates the integrator with the given options.
    pub fn new(options: GeneralizedAlphaOptions) -> Self {
        Self { options }
    }

    /// Integrates from `(t0, q0, q̇0)` to `t_end > t0` and stores the points
    /// selected by `output`.
    pub fn solve<S: SecondOrderSystem + ?Sized>(
        &self,
        sys: &mut S,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        t_end: f64,
        output: &Output,
    ) -> Result<SecondOrderSolution, OdeError> {
        self.solve_with(sys, t0, q0, qd0, t_end, output, |_, _, _, _| {
            Control::Continue
        })
    }

    /// Like [`GeneralizedAlpha::solve`], calling `observer(t, q, q̇, q̈)` at
    /// every output point; the integration stops cleanly when it returns
    /// [`Control::Stop`].
    #[allow(clippy::too_many_arguments)]
    pub fn solve_with<S, F>(
        &self,
        sys: &mut S,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        t_end: f64,
        output: &Output,
        observer: F,
    ) -> Result<SecondOrderSolution, OdeError>
    where
        S: SecondOrderSystem + ?Sized,
        F: FnMut(f64, &[f64], &[f64], &[f64]) -> Control,
    {
        let o = &self.options;
        let n = sys.dim();
        check_interval(t0, t_end)?;
        if t_end < t0 {
            return Err(OdeError::InvalidInterval {
                t0,
                t_end,
                reason: "generalized-α integrates forward in time only",
            });
        }
        check_vector("q0", q0, n)?;
        check_vector("qd0", qd0, n)?;
        check_positive("rtol", o.rtol)?;
        let atol = o.atol.expand("atol", n)?;
        check_optional_positive("h0", o.h0)?;
        check_optional_positive("hmax", o.hmax)?;
        check_optional_positive("fixed_step", o.fixed_step)?;
        check_positive("newton_tol", o.newton_tol)?;
        if !(0.0..=1.0).contains(&o.rho_inf) {
            return Err(OdeError::InvalidOption {
                name: "rho_inf",
                reason: format!("must be in [0, 1], got {}", o.rho_inf),
            });
        }
        if !(o.jacobian_refresh > 0.0 && o.jacobian_refresh < 1.0) {
            return Err(OdeError::InvalidOption {
                name: "jacobian_refresh",
                reason: format!("must be in (0, 1), got {}", o.jacobian_refresh),
            });
        }
        if o.max_newton_iterations == 0 || o.max_steps == 0 {
            return Err(OdeError::InvalidOption {
                name: if o.max_steps == 0 {
                    "max_steps"
                } else {
                    "max_newton_iterations"
                },
                reason: "must be at least 1".into(),
            });
        }
        if let Some(a0) = &o.initial_acceleration {
            check_vector("initial_acceleration", a0, n)?;
        }
        output.validate(t0, t_end)?;

        let par = AlphaParameters::from_rho_inf(o.rho_inf);
        let span = t_end - t0;
        let hmax = o.hmax.unwrap_or(span).min(span);
        let mut stats = Stats::default();
        let mut lin = Linear {
            mass: Mat::zeros(n, n),
            damping: Mat::zeros(n, n),
            stiffness: Mat::zeros(n, n),
            // only an exactly zero pivot is singular: the integrator's own
            // error control judges an ill-conditioned but invertible matrix
            lu: DenseLu::new(n).with_singular_pivot_ratio(0.0),
            h_lu: None,
            lu_error: None,
            fresh: false,
            stale: true,
        };
        let mut x0 = State::zeros(n);
        let mut x1 = State::zeros(n);
        let mut r = vec![0.0; n];
        let mut dq = vec![0.0; n];
        let mut sink = Sink {
            output,
            next_time: 0,
            solution: SecondOrderSolution::with_capacity(n, output.capacity_hint()),
            observer,
            buf: State::zeros(n),
        };
        let mut t = t0;
        x0.q.copy_from_slice(q0);
        x0.qd.copy_from_slice(qd0);

        // The integration proper. A stop request honoured inside a tangent
        // evaluation (`RhsErrorKind::Interrupted`, the tangent of a large
        // model takes long) ends it as a stop between steps does.
        #[allow(clippy::redundant_closure_call)]
        let run = (|| -> Result<(), OdeError> {
            // Consistent initial acceleration.
            match &o.initial_acceleration {
                Some(a0) => x0.qdd.copy_from_slice(a0),
                None => {
                    let zeros = &x1.qdd; // all zero at this point
                    eval_tangent(sys, t, &x0.q, &x0.qd, zeros, &mut lin, &mut stats)?;
                    lin.lu.matrix_mut().copy_from(&lin.mass);
                    stats.lu_decompositions += 1;
                    if let Err(source) = lin.lu.factor_in_place() {
                        return Err(OdeError::SingularMatrix {
                            what: "mass",
                            t,
                            source,
                        });
                    }
                    eval_residual(sys, t, &x0.q, &x0.qd, zeros, &mut r, &mut stats)?;
                    for (a, ri) in x0.qdd.iter_mut().zip(&r) {
                        *a = -ri;
                    }
                    lin.lu.solve_vec(&mut x0.qdd);
                    if let Some(index) = first_non_finite(&x0.qdd) {
                        return Err(OdeError::NonFiniteState { t, index });
                    }
                    // The tangent is kept for the first step (evaluated at q̈ = 0).
                    lin.stale = false;
                }
            }
            x0.a.copy_from_slice(&x0.qdd);

            if sink.initial(t, &x0) == Control::Stop {
                return Ok(());
            }

            let mut h = match (o.fixed_step, o.h0) {
                (Some(hf), _) => hf,
                (None, Some(h0)) => h0.min(hmax),
                (None, None) => (0.01 * span).min(hmax),
            };
            let mut eta = 1.0f64;
            let pow = 1.0 / 3.0;
            // the previous accepted step and its initial acceleration, for the
            // velocity error estimate
            let mut h_prev: Option<f64> = None;
            let mut qdd_prev = vec![0.0; n];
            let mut err_work = ErrorWork {
                eq: vec![0.0; n],
                ev: vec![0.0; n],
                tmp: vec![0.0; n],
            };

            loop {
                if stats.steps_accepted >= o.max_steps {
                    return Err(OdeError::MaxStepsExceeded {
                        t,
                        max_steps: o.max_steps,
                    });
                }
                let remaining = t_end - t;
                let mut done = false;
                let stretch = if o.fixed_step.is_some() {
                    1.0 - 1e-9
                } else {
                    1.0 / 1.1
                };
                if h >= remaining * stretch {
                    h = remaining;
                    done = true;
                }
                if lin.stale {
                    eval_tangent(sys, t, &x0.q, &x0.qd, &x0.qdd, &mut lin, &mut stats)?;
                    lin.stale = false;
                    lin.fresh = true;
                    lin.h_lu = None;
                }
                let mut rejected = false;
                let (t1, theta_max, err) = loop {
                    if sys.stop_requested() {
                        sink.solution.status = Status::Stopped { t };
                        return Ok(());
                    }
                    let h_min = 16.0 * spacing(t);
                    if h < h_min {
                        return Err(OdeError::StepSizeTooSmall { t, h, h_min });
                    }
                    let t1 = if done { t_end } else { t + h };
                    if lin.h_lu != Some(h) {
                        build_iteration_matrix(&mut lin, &par, h);
                        stats.lu_decompositions += 1;
                        match lin.lu.factor_in_place() {
                            Ok(_) => lin.h_lu = Some(h),
                            Err(e) => {
                                lin.h_lu = None;
                                lin.lu_error = Some(e);
                            }
                        }
                    }
                    let result = if lin.h_lu.is_some() {
                        newton(
                            sys, o, &par, &atol, t1, h, &x0, &mut x1, &mut r, &mut dq, &mut lin,
                            &mut eta, &mut stats,
                        )?
                    } else {
                        Newton::Singular
                    };
                    match result {
                        Newton::Converged { theta_max } => {
                            if o.fixed_step.is_some() {
                                break (t1, theta_max, 0.0);
                            }
                            let err = local_error_norm(
                                &par,
                                h,
                                h_prev.map(|hp| (hp, qdd_prev.as_slice())),
                                &x0,
                                &x1,
                                &mut lin,
                                &mut err_work,
                                &atol,
                                o.rtol,
                            );
                            if err <= 1.0 {
                                break (t1, theta_max, err);
                            }
                            stats.steps_rejected += 1;
                            rejected = true;
                            h *= (0.9 * err.powf(-pow)).max(0.2);
                            done = false;
                            if theta_max > o.jacobian_refresh && !lin.fresh {
                                eval_tangent(sys, t, &x0.q, &x0.qd, &x0.qdd, &mut lin, &mut stats)?;
                                lin.fresh = true;
                                lin.h_lu = None;
                            }
                        }
                        Newton::Failed | Newton::Singular => {
                            let singular = matches!(result, Newton::Singular);
                            stats.newton_failures += usize::from(!singular);
                            if !lin.fresh {
                                eval_tangent(sys, t, &x0.q, &x0.qd, &x0.qdd, &mut lin, &mut stats)?;
                                lin.fresh = true;
                                lin.h_lu = None;
                            } else if o.fixed_step.is_some() {
                                return Err(if singular {
                                    OdeError::SingularMatrix {
                                        what: "iteration",
                                        t,
                                        source: lin.lu_error.unwrap_or(LuError::Singular {
                                            n: x0.q.len(),
                                            index: 0,
                                            pivot_ratio: 0.0,
                                            threshold: 0.0,
                                        }),
                                    }
                                } else {
                                    OdeError::NewtonFailed { t, h }
                                });
                            } else {
                                rejected = true;
                                h *= 0.5;
                                done = false;
                            }
                            eta = 1.0;
                        }
                    }
                };

                let h_taken = t1 - t;
                stats.record_accepted(h_taken);
                let control = sink.step(t, t1, &x0, &x1, done);
                qdd_prev.copy_from_slice(&x0.qdd);
                h_prev = Some(h_taken);
                std::mem::swap(&mut x0, &mut x1);
                t = t1;
                lin.fresh = false;
                if theta_max > o.jacobian_refresh {
                    lin.stale = true;
                }
                if done || control == Control::Stop {
                    break;
                }
                if sys.step_accepted(t, &x0.q, &x0.qd) == Control::Stop {
                    sink.solution.status = Status::Stopped { t };
                    break;
                }
                if o.fixed_step.is_none() {
                    let mut factor = if err > 0.0 {
                        (0.9 * err.powf(-pow)).clamp(0.2, 5.0)
                    } else {
                        5.0
                    };
                    if rejected {
                        factor = factor.min(1.0);
                    }
                    if (1.0..1.2).contains(&factor) {
                        factor = 1.0;
                    }
                    h = (h_taken * factor).min(hmax);
                }
            }
            Ok(())
        })();
        match run {
            Ok(()) => {}
            Err(e) if e.is_interrupted_rhs() => sink.solution.status = Status::Stopped { t },
            Err(e) => return Err(e),
        }
        sink.solution.stats = stats;
        Ok(sink.solution)
    }
}

fn eval_residual<S: SecondOrderSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    r: &mut [f64],
    stats: &mut Stats,
) -> Result<(), OdeError> {
    stats.rhs_evals += 1;
    sys.residual(t, q, qd, qdd, r)
        .map_err(|e| wrap_rhs_error(t, e))?;
    match first_non_finite(r) {
        Some(index) => Err(OdeError::NonFiniteRhs {
            what: "residual",
            t,
            index,
        }),
        None => Ok(()),
    }
}

fn eval_tangent<S: SecondOrderSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    lin: &mut Linear,
    stats: &mut Stats,
) -> Result<(), OdeError> {
    stats.jacobian_evals += 1;
    sys.tangent(
        t,
        q,
        qd,
        qdd,
        &mut lin.mass,
        &mut lin.damping,
        &mut lin.stiffness,
    )
    .map_err(|e| wrap_rhs_error(t, e))?;
    let n = q.len();
    for (m, mat) in [&lin.mass, &lin.damping, &lin.stiffness].iter().enumerate() {
        if mat.nrows() != n || mat.ncols() != n {
            return Err(OdeError::DimensionMismatch {
                what: "tangent matrix",
                expected: n,
                found: mat.nrows(),
            });
        }
        for j in 0..n {
            for i in 0..n {
                if !mat[(i, j)].is_finite() {
                    return Err(OdeError::NonFiniteRhs {
                        what: "tangent",
                        t,
                        index: m * n * n + j * n + i,
                    });
                }
            }
        }
    }
    Ok(())
}

/// Work vectors of the error estimate.
struct ErrorWork {
    /// `e_q`, then its filtered value.
    eq: Vec<f64>,
    /// `e_v`, then its filtered value.
    ev: Vec<f64>,
    /// `β'·M·e` before the solve.
    tmp: Vec<f64>,
}

/// The weighted RMS norm of the filtered local error estimates of the step
/// `x0 → x1` of size `h` (module documentation, "Error estimate"), over
/// the `2n` components of `(q, q̇)` with `sc_i = atol_i +
/// rtol·max(|y_n,i|, |y_{n+1},i|)`. `prev` is the previous step's size and
/// initial acceleration `q̈_{n−1}`; without it `e_v = 0`. `lin.lu` must hold
/// `S` for this `h`.
#[allow(clippy::too_many_arguments)]
fn local_error_norm(
    par: &AlphaParameters,
    h: f64,
    prev: Option<(f64, &[f64])>,
    x0: &State,
    x1: &State,
    lin: &mut Linear,
    w: &mut ErrorWork,
    atol: &[f64],
    rtol: f64,
) -> f64 {
    let n = x0.q.len();
    let cq = par.error_constant() * h * h;
    for i in 0..n {
        w.eq[i] = cq * (x1.qdd[i] - x0.qdd[i]);
    }
    filter(lin, par, h, &mut w.eq, &mut w.tmp);
    match prev {
        Some((hp, qdd_prev)) => {
            let cv = par.velocity_error_constant() * 2.0 * h * h / (h + hp);
            let ratio = h / hp;
            for i in 0..n {
                let d1 = x1.qdd[i] - x0.qdd[i];
                let d0 = x0.qdd[i] - qdd_prev[i];
                w.ev[i] = cv * (d1 - ratio * d0);
            }
            filter(lin, par, h, &mut w.ev, &mut w.tmp);
        }
        None => w.ev.fill(0.0),
    }
    let scaled = |e: f64, atol: f64, y0: f64, y1: f64| {
        let r = e / (atol + rtol * y0.abs().max(y1.abs()));
        r * r
    };
    let mut sum = 0.0;
    for i in 0..n {
        sum += scaled(w.eq[i], atol[i], x0.q[i], x1.q[i]);
        sum += scaled(w.ev[i], atol[i], x0.qd[i], x1.qd[i]);
    }
    (sum / (2 * n).max(1) as f64).sqrt()
}

/// `e ← S⁻¹·β'·M·e`: the filter of the error estimate of stiff implicit
/// methods (Hairer & Wanner, *Solving ODEs II*, IV.8, eq. 8.20, after
/// Shampine), with generalized-α's iteration matrix. Components with
/// `h·ω ≪ 1` pass (factor `1 − O(h²ω²)`); stiff ones, which the method damps
/// and does not resolve, are scaled by about `β'/ω²` instead of driving
/// the step size down to their period.
fn filter(lin: &mut Linear, par: &AlphaParameters, h: f64, e: &mut [f64], tmp: &mut [f64]) {
    let beta_p = (1.0 - par.alpha_m) / (par.beta * h * h * (1.0 - par.alpha_f));
    let n = e.len();
    tmp.fill(0.0);
    for j in 0..n {
        let ej = beta_p * e[j];
        if ej != 0.0 {
            for (i, t) in tmp.iter_mut().enumerate() {
                *t += lin.mass[(i, j)] * ej;
            }
        }
    }
    lin.lu.solve_vec(tmp);
    e.copy_from_slice(tmp);
}

/// `S = β'·M + γ'·C + K` into the LU workspace.
fn build_iteration_matrix(lin: &mut Linear, par: &AlphaParameters, h: f64) {
    let beta_p = (1.0 - par.alpha_m) / (par.beta * h * h * (1.0 - par.alpha_f));
    let gamma_p = par.gamma / (par.beta * h);
    let n = lin.mass.nrows();
    let mut s = lin.lu.matrix_mut();
    for j in 0..n {
        for i in 0..n {
            s[(i, j)] =
                beta_p * lin.mass[(i, j)] + gamma_p * lin.damping[(i, j)] + lin.stiffness[(i, j)];
        }
    }
}

/// Predicts the state at `t1 = t + h` and solves the step equations by
/// modified Newton iterations.
#[allow(clippy::too_many_arguments)]
fn newton<S: SecondOrderSystem + ?Sized>(
    sys: &mut S,
    o: &GeneralizedAlphaOptions,
    par: &AlphaParameters,
    atol: &[f64],
    t1: f64,
    h: f64,
    x0: &State,
    x1: &mut State,
    r: &mut [f64],
    dq: &mut [f64],
    lin: &mut Linear,
    eta: &mut f64,
    stats: &mut Stats,
) -> Result<Newton, OdeError> {
    let n = x0.q.len();
    let AlphaParameters {
        alpha_m,
        alpha_f,
        beta,
        gamma,
    } = *par;
    let beta_p = (1.0 - alpha_m) / (beta * h * h * (1.0 - alpha_f));
    let gamma_p = gamma / (beta * h);
    // Predictor: q̈_{n+1} = q̈_n.
    for i in 0..n {
        let qdd1 = x0.qdd[i];
        let a1 =
            ((1.0 - alpha_f) * qdd1 + alpha_f * x0.qdd[i] - alpha_m * x0.a[i]) / (1.0 - alpha_m);
        x1.qdd[i] = qdd1;
        x1.qd[i] = x0.qd[i] + h * ((1.0 - gamma) * x0.a[i] + gamma * a1);
        x1.q[i] = x0.q[i] + h * x0.qd[i] + h * h * ((0.5 - beta) * x0.a[i] + beta * a1);
    }
    let mut eta_k = eta.max(f64::EPSILON).powf(0.8);
    let mut prev_norm = 0.0;
    let mut theta_max: f64 = 0.0;
    for it in 0..o.max_newton_iterations {
        // an iterate the system cannot evaluate (e.g. a configuration the
        // mechanism cannot reach) fails this Newton solve, as a diverging one
        // does: the step is retried with a fresh tangent or halved
        match eval_residual(sys, t1, &x1.q, &x1.qd, &x1.qdd, r, stats) {
            Ok(()) => {}
            Err(e) if e.is_recoverable_rhs() && o.fixed_step.is_none() => {
                return Ok(Newton::Failed);
            }
            Err(e) => return Err(e),
        }
        for (d, ri) in dq.iter_mut().zip(r.iter()) {
            *d = -ri;
        }
        lin.lu.solve_vec(dq);
        stats.newton_iterations += 1;
        if first_non_finite(dq).is_some() {
            return Ok(Newton::Failed);
        }
        let (mut sum, mut sum_v) = (0.0, 0.0);
        for i in 0..n {
            x1.q[i] += dq[i];
            x1.qd[i] += gamma_p * dq[i];
            x1.qdd[i] += beta_p * dq[i];
            let w = atol[i] + o.rtol * x1.q[i].abs();
            sum += (dq[i] / w) * (dq[i] / w);
            let wv = atol[i] + o.rtol * x1.qd[i].abs();
            let dv = gamma_p * dq[i];
            sum_v += (dv / wv) * (dv / wv);
        }
        // the increment of q and the one it makes in q̇ = γ/(βh)·Δq: with
        // small steps a position increment within tolerance can still leave
        // a velocity error that the position error estimate never sees
        let norm = (sum.max(sum_v) / n.max(1) as f64).sqrt();
        if it > 0 {
            let theta = norm / prev_norm;
            theta_max = theta_max.max(theta);
            if theta >= 1.0 {
                return Ok(Newton::Failed);
            }
            eta_k = theta / (1.0 - theta);
        }
        if eta_k * norm <= o.newton_tol || norm == 0.0 {
            *eta = eta_k;
            for i in 0..n {
                x1.a[i] = ((1.0 - alpha_f) * x1.qdd[i] + alpha_f * x0.qdd[i] - alpha_m * x0.a[i])
                    / (1.0 - alpha_m);
            }
            return Ok(Newton::Converged { theta_max });
        }
        prev_norm = norm;
    }
    Ok(Newton::Failed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_from_rho_inf() {
        // ρ∞ = 1: trapezoidal rule (average acceleration).
        let p = AlphaParameters::from_rho_inf(1.0);
        assert!((p.alpha_m - 0.5).abs() < 1e-15 && (p.alpha_f - 0.5).abs() < 1e-15);
        assert!((p.gamma - 0.5).abs() < 1e-15 && (p.beta - 0.25).abs() < 1e-15);
        assert!((p.error_constant() - 1.0 / 12.0).abs() < 1e-15);
        assert!((p.velocity_error_constant() - 1.0 / 12.0).abs() < 1e-15);
        // ρ∞ = 0.8 (Chung & Hulbert 1993, eq. 25 and 17-20).
        let p = AlphaParameters::from_rho_inf(0.8);
        assert!((p.alpha_m - 1.0 / 3.0).abs() < 1e-15);
        assert!((p.alpha_f - 4.0 / 9.0).abs() < 1e-15);
        assert!((p.gamma - (0.5 + 4.0 / 9.0 - 1.0 / 3.0)).abs() < 1e-15);
    }

    /// `q̈ = t²/2` (`q⃛ = t`, `q⁗ = 1`), from rest.
    struct Quadrature;

    impl SecondOrderSystem for Quadrature {
        fn dim(&self) -> usize {
            1
        }
        fn residual(
            &mut self,
            t: f64,
            _q: &[f64],
            _qd: &[f64],
            qdd: &[f64],
            r: &mut [f64],
        ) -> Result<(), crate::RhsError> {
            r[0] = qdd[0] - 0.5 * t * t;
            Ok(())
        }
        fn tangent(
            &mut self,
            _t: f64,
            _q: &[f64],
            _qd: &[f64],
            _qdd: &[f64],
            m: &mut Mat<f64>,
            c: &mut Mat<f64>,
            k: &mut Mat<f64>,
        ) -> Result<(), crate::RhsError> {
            m[(0, 0)] = 1.0;
            c[(0, 0)] = 0.0;
            k[(0, 0)] = 0.0;
            Ok(())
        }
    }

    /// The error constants of the module documentation, checked against the
    /// method itself: on `q̈ = f(t)` the local errors add up without
    /// propagation, so at `T = 1` with a fixed step `h` the velocity error is
    /// `C_v·h²·∫q⁗ = C_v·h²` and the position error
    /// `C_q·h²·(q̈(1) − q̈(0)) + C_v·h²·∫t dt = (C_q + C_v)·h²/2`, up to
    /// `O(h³)` (the start `a_0 = q̈_0` is `O(h²)` off the expansion of `a`).
    #[test]
    fn error_constants_match_the_method() {
        for rho in [0.0, 0.5, 0.8, 1.0] {
            let par = AlphaParameters::from_rho_inf(rho);
            let (cq, cv) = (par.error_constant(), par.velocity_error_constant());
            let h = 1e-3;
            let opts = GeneralizedAlphaOptions::default()
                .rho_inf(rho)
                .fixed_step(h)
                .rtol(1e-13)
                .atol(1e-15);
            let sol = GeneralizedAlpha::new(opts)
                .solve(&mut Quadrature, 0.0, &[0.0], &[0.0], 1.0, &Output::Final)
                .unwrap();
            let i = sol.len() - 1;
            let ev = (sol.qd(i)[0] - 1.0 / 6.0) / (h * h);
            let eq = (sol.q(i)[0] - 1.0 / 24.0) / (h * h);
            assert!((ev / cv - 1.0).abs() < 0.02, "ρ∞ {rho}: {ev} vs C_v {cv}");
            assert!(
                (eq / (0.5 * (cq + cv)) - 1.0).abs() < 0.02,
                "ρ∞ {rho}: {eq} vs (C_q + C_v)/2 {}",
                0.5 * (cq + cv)
            );
        }
    }
}
