//! Time simulation: the equations of motion in first-order form y = (q, q̇) for
//! the explicit integrators (the thesis counts evaluations of this right-hand
//! side), and in residual form with tangents for generalized-α.

use crate::culprit::{integration_error, StateLayout};
use crate::partition::PartitionWatch;
use crate::{Dynamics, DynamicsError};
use faer::Mat;
use flexmb_model::{ChartSwitch, Coordinate, EulerChart, Mechanism, PartitionSwitch};
use flexmb_ode::{
    Adams, AdamsOptions, Control, Dopri5, Dopri5Options, GeneralizedAlpha, GeneralizedAlphaOptions,
    OdeSystem, Output, RhsError, RhsErrorKind, SecondOrderSystem, Stats, Tolerance,
};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Mass, damping and stiffness tangents (M, C, K) of the residual.
pub type TangentMatrices = (Mat<f64>, Mat<f64>, Mat<f64>);

/// The integrators offered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Dormand–Prince 5(4), ode45-like (thesis chapter 5).
    Dopri5,
    /// Variable-order Adams PECE, Shampine–Gordon style (thesis chapters 3, 6, 7).
    Adams,
    /// Generalized-α, implicit, for stiff unreduced models.
    GeneralizedAlpha,
}

impl std::str::FromStr for Integrator {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "dopri5" | "ode45" | "rk45" => Ok(Integrator::Dopri5),
            "adams" | "shampine-gordon" | "de" => Ok(Integrator::Adams),
            "genalpha" | "generalized-alpha" | "implicit" => Ok(Integrator::GeneralizedAlpha),
            _ => Err(format!(
                "unknown integrator '{s}': use dopri5, adams or genalpha"
            )),
        }
    }
}

/// Settings of a simulation.
#[derive(Clone, Debug)]
pub struct SimulationOptions {
    /// Integrator.
    pub integrator: Integrator,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Output times (dense output; no extra evaluations).
    pub output_times: Vec<f64>,
    /// A request to stop, read after every accepted step (one atomic load):
    /// when it is set the run ends there as if the observer had stopped it,
    /// with the outputs reached so far and one more output at the step where
    /// it stopped (e.g. set by a signal handler).
    pub stop: Option<Arc<AtomicBool>>,
    /// The most steps the integrator may take (1 000 000 by default); a
    /// run that needs more ends with an error naming the time reached.
    pub max_steps: usize,
}

impl SimulationOptions {
    /// ode45's defaults (RelTol 1e-3, AbsTol 1e-6) with `n` equidistant
    /// outputs on [t0, t_end]. `n` = 1 gives the final state only; `n` = 0
    /// no output time at all, which [`Dynamics::simulate`] refuses with an
    /// error (it is not silently raised to 2).
    pub fn new(integrator: Integrator, t0: f64, t_end: f64, n: usize) -> Self {
        let output_times = match n {
            0 => vec![],
            1 => vec![t_end],
            _ => (0..n)
                .map(|k| t0 + (t_end - t0) * k as f64 / (n - 1) as f64)
                .collect(),
        };
        Self {
            integrator,
            rtol: 1e-3,
            atol: 1e-6,
            output_times,
            stop: None,
            max_steps: 1_000_000,
        }
    }
}

/// True if `stop` is given and set: a stop was requested.
pub(crate) fn stop_requested(stop: Option<&AtomicBool>) -> bool {
    stop.is_some_and(|s| s.load(Ordering::Relaxed))
}

/// [`DynamicsError::Interrupted`] if a stop was requested: the check
/// between the parts of a long evaluation.
pub(crate) fn check_stop(stop: Option<&AtomicBool>) -> Result<(), DynamicsError> {
    if stop_requested(stop) {
        Err(DynamicsError::Interrupted)
    } else {
        Ok(())
    }
}

/// A computed trajectory.
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// Output times.
    pub t: Vec<f64>,
    /// q at each output time.
    pub q: Vec<Vec<f64>>,
    /// q̇ at each output time.
    pub qd: Vec<Vec<f64>>,
    /// Integrator statistics (exact evaluation counts).
    pub stats: Stats,
    /// Wall time of the integration in seconds.
    pub wall_time: f64,
    /// True if stopped early by the observer or by
    /// [`SimulationOptions::stop`].
    pub stopped: bool,
    /// The nodal coordinates x at each output time, solved at the
    /// integrator's own configuration there (not again after the run, which
    /// can land on a mirrored branch of a mechanism that turned far). A
    /// later evaluation at output `k` starts its position solve from
    /// `x[k]` ([`Kinematics::set_guess`](flexmb_kinematics::Kinematics::set_guess)).
    pub x: Vec<Vec<f64>>,
    /// Chart switches of free orientation nodes during the run
    /// ([`flexmb_model::EulerChart`]); each one restarted the integrator.
    /// `q` and `qd` are always given in the chart the run started with.
    pub chart_switches: Vec<ChartSwitch>,
    /// Changes of the dependent nodal coordinates during the run (where J
    /// of the old ones got ill-conditioned, see
    /// [`Dynamics::switch_partition`]); each one restarted the integrator.
    pub partition_switches: Vec<PartitionSwitch>,
}

impl Trajectory {
    fn empty() -> Self {
        Self {
            t: vec![],
            q: vec![],
            qd: vec![],
            stats: Stats::default(),
            wall_time: 0.0,
            stopped: false,
            x: vec![],
            chart_switches: vec![],
            partition_switches: vec![],
        }
    }
}

/// One output point of [`Dynamics::simulate_with`].
pub struct OutputPoint<'a> {
    /// Time.
    pub t: f64,
    /// q in the chart the run started with.
    pub q: &'a [f64],
    /// q̇ in the chart the run started with.
    pub qd: &'a [f64],
    /// q in the current chart (what `dynamics` takes).
    pub q_chart: &'a [f64],
    /// q̇ in the current chart.
    pub qd_chart: &'a [f64],
    /// The dynamics in the current chart, its kinematics solved at this point
    /// to first order with velocities and accelerations (x, ε, ẋ, ε̇).
    pub dynamics: &'a mut Dynamics,
}

/// A system shared by the integrator and its output observer, so that the
/// observer can evaluate outputs with the system's own state (the
/// configuration of the integrator's last evaluation). The integrator never
/// evaluates the system while the observer runs, so the two borrows never
/// meet; if they did, the evaluation would fail with an error, not a panic.
struct Shared<'c, 's, S: ?Sized> {
    cell: &'c RefCell<&'s mut S>,
    dim: usize,
    /// [`SimulationOptions::stop`], read after every accepted step.
    stop: Option<&'c AtomicBool>,
    /// (t, y) of the step at which the stop request ended the run.
    stopped_at: Option<(f64, Vec<f64>)>,
}

impl<'c, 's, S: ?Sized> Shared<'c, 's, S> {
    fn system(&self) -> Result<std::cell::RefMut<'c, &'s mut S>, RhsError> {
        self.cell
            .try_borrow_mut()
            .map_err(|_| RhsError::new("the system was evaluated while an output was recorded"))
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for Shared<'_, '_, S> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.system()?.rhs(t, y, dy)
    }
    fn step_accepted(&mut self, t: f64, y: &[f64]) -> Control {
        if stop_requested(self.stop) {
            self.stopped_at = Some((t, y.to_vec()));
            return Control::Stop;
        }
        match self.system() {
            Ok(mut s) => s.step_accepted(t, y),
            Err(_) => Control::Continue,
        }
    }
}

impl<S: SecondOrderSystem + ?Sized> SecondOrderSystem for Shared<'_, '_, S> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        self.system()?.residual(t, q, qd, qdd, r)
    }
    fn tangent(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        mass: &mut Mat<f64>,
        damping: &mut Mat<f64>,
        stiffness: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        self.system()?
            .tangent(t, q, qd, qdd, mass, damping, stiffness)
    }
    fn step_accepted(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Control {
        match self.system() {
            Ok(mut s) => s.step_accepted(t, q, qd),
            Err(_) => Control::Continue,
        }
    }
    fn stop_requested(&mut self) -> bool {
        stop_requested(self.stop) || self.system().is_ok_and(|mut s| s.stop_requested())
    }
}

/// Integrates a first-order system y' = f(t, y) with one of the explicit
/// integrators (Dopri5 or Adams) from (t0, y0) to the last output time of
/// `opts`; `observer(sys, t, y)` sees each output, with the system in the
/// state of the integrator's last evaluation (e.g. to solve the output's
/// configuration from there), and may stop the run, as does
/// [`SimulationOptions::stop`] after any accepted step: the observer then
/// also sees the state at that step (after the last output time reached),
/// so the partial result ends where the run stopped. Returns the
/// integrator's statistics and whether the run was stopped. Reduced models
/// use this exactly like the unreduced equations of motion.
pub fn integrate_explicit<S: OdeSystem + ?Sized>(
    sys: &mut S,
    opts: &SimulationOptions,
    t0: f64,
    y0: &[f64],
    observer: impl FnMut(&mut S, f64, &[f64]) -> Control,
) -> Result<(Stats, bool), DynamicsError> {
    integrate_explicit_named(sys, opts, t0, y0, observer, |e| e.to_string())
}

/// [`integrate_explicit`] with the integrator's errors worded by `describe`
/// (which may name the state component an error is about).
fn integrate_explicit_named<S: OdeSystem + ?Sized>(
    sys: &mut S,
    opts: &SimulationOptions,
    t0: f64,
    y0: &[f64],
    mut observer: impl FnMut(&mut S, f64, &[f64]) -> Control,
    describe: impl Fn(&flexmb_ode::OdeError) -> String,
) -> Result<(Stats, bool), DynamicsError> {
    let t_end = *opts
        .output_times
        .last()
        .ok_or_else(|| DynamicsError::Invalid("no output times".into()))?;
    let out = Output::Times(opts.output_times.clone());
    let to_err = |e: flexmb_ode::OdeError| DynamicsError::Integration {
        message: describe(&e),
        source: e,
    };
    let dim = sys.dim();
    let cell = RefCell::new(sys);
    let mut shared = Shared {
        cell: &cell,
        dim,
        stop: opts.stop.as_deref(),
        stopped_at: None,
    };
    let last_output = std::cell::Cell::new(f64::NEG_INFINITY);
    let mut observe = |t: f64, y: &[f64]| {
        last_output.set(t);
        match cell.try_borrow_mut() {
            Ok(mut s) => observer(&mut **s, t, y),
            // (unreachable: the integrator is not evaluating the system)
            Err(_) => Control::Stop,
        }
    };
    let sol = match opts.integrator {
        Integrator::Dopri5 => {
            let o = Dopri5Options {
                rtol: opts.rtol,
                atol: Tolerance::Scalar(opts.atol),
                max_steps: opts.max_steps,
                ..Default::default()
            };
            Dopri5::new(o)
                .solve_with(&mut shared, t0, y0, t_end, &out, &mut observe)
                .map_err(to_err)?
        }
        Integrator::Adams => {
            let o = AdamsOptions {
                rtol: opts.rtol,
                atol: Tolerance::Scalar(opts.atol),
                max_steps: opts.max_steps,
                ..Default::default()
            };
            Adams::new(o)
                .solve_with(&mut shared, t0, y0, t_end, &out, &mut observe)
                .map_err(to_err)?
        }
        Integrator::GeneralizedAlpha => {
            return Err(DynamicsError::Invalid(
                "generalized-α needs the residual form (Dynamics::simulate); use dopri5 or adams for first-order systems".into(),
            ))
        }
    };
    if let Some((t, y)) = shared.stopped_at.take() {
        if t > last_output.get() {
            observe(t, &y);
        }
    }
    Ok((
        sol.stats.clone(),
        !matches!(sol.status, flexmb_ode::Status::Completed),
    ))
}

/// Kinematic failures at a trial state are recoverable (a smaller step
/// reaches a solvable configuration); the others abort the integration.
/// The integrator's view of a failed evaluation: a kinematics failure or a
/// non-finite value may be avoided by a smaller step, a stop request ends
/// the run cleanly, anything else is fatal. The typed error is kept as the
/// cause ([`DynamicsError::failed_evaluation`]).
fn to_rhs_error(e: DynamicsError) -> RhsError {
    let kind = match e {
        DynamicsError::Interrupted
        | DynamicsError::Kinematics {
            source: flexmb_kinematics::KinematicsError::Interrupted,
            ..
        } => RhsErrorKind::Interrupted,
        DynamicsError::Kinematics { .. } | DynamicsError::NonFinite { .. } => {
            RhsErrorKind::Recoverable
        }
        _ => RhsErrorKind::Fatal,
    };
    RhsError::from_cause(kind, e)
}

/// Values of the DOFs (or their rates).
type Q = Vec<f64>;
/// A state (t, q, q̇) of a run.
type StateAt = (f64, Q, Q);

/// An integration error `e` with the last evaluation that failed
/// recoverably (t, message), if there was one, appended: a step-size
/// underflow then names its cause (e.g. the node whose Euler chart became
/// singular). Other errors are returned as they are.
pub fn with_failure_cause(e: DynamicsError, last_failure: Option<&(f64, String)>) -> DynamicsError {
    match (last_failure, e) {
        (Some((t, m)), DynamicsError::Integration { source, message }) => {
            DynamicsError::Integration {
                source,
                message: format!("{message}; the last evaluation that failed (at t = {t:e}): {m}"),
            }
        }
        (_, e) => e,
    }
}

/// What a segment of a charted run needs between steps: the chart checks
/// and the configuration of the last accepted step (the warm start of the
/// output evaluations).
#[derive(Default)]
struct StepWatch {
    charts: Vec<EulerChart>,
    /// The watch on the dependent nodal coordinates, if they may change.
    partition: Option<PartitionWatch>,
    /// x at the last accepted step.
    x: Rc<RefCell<Vec<f64>>>,
    /// (t, q, q̇) where a chart must switch.
    switch_at: Option<StateAt>,
    /// The last evaluation that failed recoverably (the integrator retried
    /// with a smaller step): the reason to give if the run fails after it.
    last_failure: Option<(f64, String)>,
    /// The pivot ratio of J at the start of the segment, and (t, q, q̇) of
    /// the last accepted step (buffers reused from step to step): where a
    /// run ends without an evaluation that failed, the state to explain.
    start_pivot: f64,
    last_accepted: (f64, Vec<f64>, Vec<f64>),
}

impl StepWatch {
    fn new(dy: &Dynamics, partition: Option<PartitionWatch>) -> Self {
        Self {
            charts: dy.mech.euler_charts(),
            partition,
            x: Rc::new(RefCell::new(dy.kin.x().to_vec())),
            switch_at: None,
            last_failure: None,
            start_pivot: dy.kin.pivot_ratio(),
            last_accepted: (f64::NAN, vec![], vec![]),
        }
    }

    /// Converts an evaluation failure, noting a recoverable one.
    fn failed(&mut self, t: f64, e: DynamicsError) -> RhsError {
        let r = to_rhs_error(e);
        if r.is_recoverable() {
            self.last_failure = Some((t, r.message().to_string()));
        }
        r
    }

    /// An integration error with the last recoverable evaluation failure
    /// when there was one: a step-size underflow names its cause. Without
    /// one (an implicit integrator whose Newton iterations stop converging,
    /// or a step size that shrinks on error estimates alone), the state of
    /// the last accepted step is explained instead
    /// ([`Dynamics::explain_stall`]).
    fn with_cause(&self, dy: &mut Dynamics, e: DynamicsError) -> DynamicsError {
        if self.last_failure.is_some() {
            return with_failure_cause(e, self.last_failure.as_ref());
        }
        let (t, q, qd) = &self.last_accepted;
        match e {
            DynamicsError::Integration { source, message } if !q.is_empty() => {
                let why = dy.explain_stall(*t, q, qd, self.start_pivot);
                DynamicsError::Integration {
                    source,
                    message: format!("{message}; {why}"),
                }
            }
            e => e,
        }
    }

    fn accepted(&mut self, dy: &mut Dynamics, t: f64, q: &[f64], qd: &[f64]) -> Control {
        let (ta, qa, qda) = &mut self.last_accepted;
        *ta = t;
        qa.clear();
        qa.extend_from_slice(q);
        qda.clear();
        qda.extend_from_slice(qd);
        self.x.borrow_mut().copy_from_slice(dy.kin.x());
        if self.charts.iter().any(|c| c.needs_switch(q).is_some()) || self.partition_degraded(dy) {
            self.switch_at = Some((t, q.to_vec(), qd.to_vec()));
            return Control::Stop;
        }
        Control::Continue
    }

    /// Whether J of the dependent coordinates has got ill-conditioned at
    /// the configuration of the last evaluation and another set is better
    /// there; where the set is still the best, the reference of the
    /// watch becomes the pivot ratio now.
    fn partition_degraded(&mut self, dy: &mut Dynamics) -> bool {
        let Some(w) = &mut self.partition else {
            return false;
        };
        let now = dy.kin.pivot_ratio();
        if !w.degraded(now) {
            return false;
        }
        let chosen = w.quality(dy);
        if dy.better_dependent_set(chosen, &[]).is_some() {
            return true;
        }
        w.reference = now;
        false
    }
}

/// The first-order form y = (q, q̇), ẏ = (q̇, q̈).
pub struct FirstOrder<'a> {
    dy: &'a mut Dynamics,
    qdd: Vec<f64>,
    watch: Option<StepWatch>,
}

impl OdeSystem for FirstOrder<'_> {
    fn dim(&self) -> usize {
        2 * self.dy.n_q()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.dy.n_q();
        let (q, qd) = y.split_at(n);
        if let Err(e) = self.dy.accelerations(t, q, qd, &mut self.qdd) {
            return Err(match &mut self.watch {
                Some(w) => w.failed(t, e),
                None => to_rhs_error(e),
            });
        }
        dy[..n].copy_from_slice(qd);
        dy[n..].copy_from_slice(&self.qdd);
        Ok(())
    }
    fn step_accepted(&mut self, t: f64, y: &[f64]) -> Control {
        let n = self.dy.n_q();
        match &mut self.watch {
            Some(w) => w.accepted(&mut *self.dy, t, &y[..n], &y[n..]),
            None => Control::Continue,
        }
    }
}

struct Residual<'a> {
    dy: &'a mut Dynamics,
    watch: StepWatch,
    /// [`SimulationOptions::stop`], read after every accepted step.
    stop: Option<&'a AtomicBool>,
    /// (t, q, q̇) of the step at which the stop request ended the run.
    stopped_at: Option<StateAt>,
}

impl SecondOrderSystem for Residual<'_> {
    fn dim(&self) -> usize {
        self.dy.n_q()
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        self.dy
            .residual(t, q, qd, qdd, r)
            .map_err(|e| self.watch.failed(t, e))
    }
    fn tangent(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        mass: &mut Mat<f64>,
        damping: &mut Mat<f64>,
        stiffness: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        let (m, d, k) = self
            .dy
            .tangent_matrices_until(t, q, qd, qdd, self.stop)
            .map_err(|e| self.watch.failed(t, e))?;
        mass.copy_from(&m);
        damping.copy_from(&d);
        stiffness.copy_from(&k);
        Ok(())
    }
    fn step_accepted(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Control {
        if stop_requested(self.stop) {
            self.stopped_at = Some((t, q.to_vec(), qd.to_vec()));
            return Control::Stop;
        }
        self.watch.accepted(self.dy, t, q, qd)
    }
    /// Also before every step attempt: one accepted step can take several
    /// Newton failures, tangents and retries (the first steps of a run do).
    fn stop_requested(&mut self) -> bool {
        stop_requested(self.stop)
    }
}

impl Dynamics {
    /// The first-order system for explicit integrators.
    pub fn first_order_system(&mut self) -> FirstOrder<'_> {
        let n = self.n_q();
        FirstOrder {
            dy: self,
            qdd: vec![0.0; n],
            watch: None,
        }
    }

    /// Tangent matrices of the residual for implicit integration: M = Mq,
    /// C = Dq + controller damping, K = Kq + Gq (with Mxẍ − f in (E.5e)) −
    /// F,qᵀ f,x F,q. The velocity-dependent C and N terms of (E.5c,f) are
    /// omitted: a modified Newton iteration converges with them missing.
    pub fn tangent_matrices(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Result<TangentMatrices, DynamicsError> {
        self.tangent_matrices_until(t, q, qd, qdd, None)
    }

    /// [`tangent_matrices`](Self::tangent_matrices) that ends with
    /// [`DynamicsError::Interrupted`] when `stop` is set: it is read between
    /// the position solve and the assembly of each matrix, and inside that of
    /// the geometric stiffness, as in
    /// [`linearize_at_rest_until`](Self::linearize_at_rest_until). A
    /// generalized-α run of a large model reads its stop request here.
    pub fn tangent_matrices_until(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        stop: Option<&AtomicBool>,
    ) -> Result<TangentMatrices, DynamicsError> {
        let check = || check_stop(stop);
        check()?;
        self.kinematics_at(t, q, Some(qd))?;
        check()?;
        self.forces(t, true);
        self.inertia_until(stop)?;
        check()?;
        let n_q = self.n_q();
        let mq = self.mq.clone();
        // w' = Mx ẍ − f = −w + Mx F,q q̈
        let mut xdd_q = vec![0.0; self.w.len()];
        let f = self.kin.f_xi();
        for (c, v) in qdd.iter().enumerate().take(n_q) {
            for (o, fv) in xdd_q.iter_mut().zip(f.col_as_slice(c)) {
                *o += fv * v;
            }
        }
        let mut wq: Vec<f64> = self.w.iter().map(|v| -v).collect();
        self.mass_times_add(&xdd_q, &mut wq);
        let sigma = self.sigma.clone();
        let mut k = self
            .kin
            .second_order_contraction_until(&wq, &sigma, stop)
            .ok_or(DynamicsError::Interrupted)?;
        check()?;
        k += &self.structural_stiffness();
        k -= &self.load_stiffness(t);
        check()?;
        let d = self.damping_matrix();
        Ok((mq, d, k))
    }

    /// Dq = E,qᵀ D E,q (E.6b) plus controller derivative gains.
    pub(crate) fn damping_matrix(&mut self) -> Mat<f64> {
        let mech = &self.mech;
        let n_q = mech.n_dof();
        let view = self.kin.first_order_view();
        let (e, f) = (view.e, view.f);
        let mut d = Mat::<f64>::zeros(n_q, n_q);
        for el in &mech.elements {
            let Some(dm) = el.element.damping() else {
                continue;
            };
            let ne = el.element.n_eps();
            let o = el.eps_offset;
            let ee = Mat::from_fn(ne, n_q, |a, c| e[(o + a, c)]);
            let dd = Mat::from_fn(ne, ne, |a, b| dm[(a, b)]);
            let de = &dd * &ee;
            d += ee.transpose() * de;
        }
        for c in &mech.controllers {
            let row: Vec<f64> = match c.on {
                flexmb_model::Coordinate::Node(i) => (0..n_q).map(|k| f[(i, k)]).collect(),
                flexmb_model::Coordinate::Def(j) => (0..n_q).map(|k| e[(j, k)]).collect(),
            };
            for a in 0..n_q {
                for b in 0..n_q {
                    d[(a, b)] += c.kd * row[a] * row[b];
                }
            }
        }
        d
    }

    /// The nodal coordinates x = F(q) at an output point (t, q) that the
    /// integrator has reached, solved by a kinematics of their own that
    /// starts from this dynamics' current configuration: the one of the
    /// integrator's last evaluation, within a step of t. So the output lies
    /// on the branch the integrator followed (a solve from a far-away
    /// configuration, e.g. the end of the run, can land on a mirrored one),
    /// and the integrator's own kinematics, and with it the run, is not
    /// disturbed.
    pub fn output_configuration(&mut self, t: f64, q: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let mech = &self.mech;
        let kin = self
            .output_kin
            .get_or_insert_with(|| flexmb_kinematics::Kinematics::new(mech.clone()));
        kin.set_newton_options(self.kin.newton_options());
        kin.set_guess(self.kin.x());
        kin.set_branch(self.kin.branch());
        kin.solve(q, t)
            .map_err(|e| DynamicsError::Kinematics { t, source: e })?;
        Ok(kin.x().to_vec())
    }

    /// Integrates from (t0, q0, q̇0) to the last output time. `observer(t, q, q̇)`
    /// is called at each output time and may stop the run (partial results
    /// are kept). See [`simulate_with`](Self::simulate_with).
    pub fn simulate(
        &mut self,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        opts: &SimulationOptions,
        mut observer: impl FnMut(f64, &[f64], &[f64]) -> Control,
    ) -> Result<Trajectory, DynamicsError> {
        self.simulate_with(t0, q0, qd0, opts, |p| observer(p.t, p.q, p.qd))
    }

    /// Integrates from (t0, q0, q̇0) to the last output time; `observer` sees
    /// each output point with a [`Dynamics`] solved there, and may stop the
    /// run (partial results are kept), as may [`SimulationOptions::stop`]
    /// after any accepted step (the trajectory then ends with an output at
    /// that step).
    ///
    /// Free orientation nodes (three Euler parameters as DOFs) switch their
    /// chart when the dependent parameter gets small
    /// ([`flexmb_model::EulerChart`]): the integrator stops after that step,
    /// the DOF slot of the parameter that becomes dependent takes the one
    /// that was, q and q̇ are mapped through x and ẋ, and the integration
    /// restarts there (Adams and generalized-α restart at low order; the
    /// evaluation counts include the restarts). A body may so turn through
    /// any number of revolutions. Likewise, with nodal coordinates as DOFs,
    /// the dependent set is chosen again where its Jacobian has got
    /// ill-conditioned ([`switch_partition`](Self::switch_partition); a
    /// beam with rigid elongations turned by 90°), with a restart there
    /// ([`Trajectory::partition_switches`]). The trajectory's q and q̇ are
    /// given in the chart and dependent set the run started with, and
    /// `self` is in them again when this returns.
    pub fn simulate_with(
        &mut self,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        opts: &SimulationOptions,
        mut observer: impl FnMut(&mut OutputPoint<'_>) -> Control,
    ) -> Result<Trajectory, DynamicsError> {
        let t_end = *opts
            .output_times
            .last()
            .ok_or_else(|| DynamicsError::Invalid("no output times".into()))?;
        let start = Instant::now();
        let start_mech = self.mech.clone();
        let mut traj = Trajectory::empty();
        let (mut t, mut q, mut qd) = (t0, q0.to_vec(), qd0.to_vec());
        self.kinematics_at(t, &q, None)?;
        if let Some((q1, qd1)) = self.switch_charts(t, &q, &qd, &[], &mut traj.chart_switches)? {
            (q, qd) = (q1, qd1);
        }
        let mut partition = self.partition_watch();
        let mut times = opts.output_times.clone();
        loop {
            let seg_opts = SimulationOptions {
                output_times: times.clone(),
                ..opts.clone()
            };
            let (stats, switch_at, stopped) = self.simulate_segment(
                t,
                &q,
                &qd,
                &seg_opts,
                &start_mech,
                &mut traj,
                &mut observer,
                &mut partition,
            )?;
            // the counts of every segment between chart switches
            traj.stats.accumulate(&stats);
            traj.stopped = stopped;
            let Some((ts, qs, qds)) = switch_at else {
                break;
            };
            if stopped || ts >= t_end {
                break;
            }
            t = ts;
            self.kinematics_at(t, &qs, None)?;
            (q, qd) = (qs, qds);
            // the dependent set first, in the chart whose J the watch
            // measured; a new set or chart has a reference of its own
            let degraded = partition
                .as_mut()
                .filter(|w| w.degraded(self.kin.pivot_ratio()));
            if let Some(chosen) = degraded.map(|w| w.quality(self)) {
                let log = &mut traj.partition_switches;
                if let Some((q1, qd1)) = self.switch_partition(t, &q, &qd, chosen, &[], log)? {
                    (q, qd) = (q1, qd1);
                    partition = self.partition_watch();
                } else if let Some(w) = &mut partition {
                    // the set stays: the watch goes on from here
                    w.reference = self.kin.pivot_ratio();
                }
            }
            if let Some((q1, qd1)) =
                self.switch_charts(t, &q, &qd, &[], &mut traj.chart_switches)?
            {
                (q, qd) = (q1, qd1);
                partition = self.partition_watch();
            }
            times.retain(|&tau| tau > ts);
            if times.is_empty() {
                break;
            }
        }
        self.use_chart(&start_mech);
        traj.wall_time = start.elapsed().as_secs_f64();
        Ok(traj)
    }

    /// One integration from (t0, q0, q̇0) in the current chart, until the
    /// last output time, a stop of the observer or a needed chart switch.
    #[allow(clippy::too_many_arguments)]
    fn simulate_segment(
        &mut self,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        opts: &SimulationOptions,
        start_mech: &Arc<Mechanism>,
        traj: &mut Trajectory,
        observer: &mut impl FnMut(&mut OutputPoint<'_>) -> Control,
        partition: &mut Option<PartitionWatch>,
    ) -> Result<(Stats, Option<StateAt>, bool), DynamicsError> {
        let n = self.n_q();
        let t_end = *opts.output_times.last().expect("output times");
        let out = Output::Times(opts.output_times.clone());
        let mut out_dy = Dynamics::new(self.mech.clone());
        out_dy.kin.set_branch(self.kin.branch());
        out_dy.kin.set_newton_options(self.kin.newton_options());
        out_dy.load_factor = self.load_factor;
        out_dy.load_scale = self.load_scale;
        let watch = StepWatch::new(self, partition.take());
        let last_x = watch.x.clone();
        let mut failure: Option<DynamicsError> = None;
        let mut emit = |t: f64, q: &[f64], qd: &[f64]| -> Control {
            out_dy.kin.set_guess(&last_x.borrow());
            if let Err(e) = out_dy.kinematics_at(t, q, Some(qd)) {
                failure = Some(e);
                return Control::Stop;
            }
            let (qs, qds) = out_dy.in_chart_of(start_mech);
            traj.t.push(t);
            traj.x.push(out_dy.kin.x().to_vec());
            let c = observer(&mut OutputPoint {
                t,
                q: &qs,
                qd: &qds,
                q_chart: q,
                qd_chart: qd,
                dynamics: &mut out_dy,
            });
            traj.q.push(qs);
            traj.qd.push(qds);
            c
        };
        let mech = self.mech.clone();
        let to_err = |e: flexmb_ode::OdeError| DynamicsError::Integration {
            message: integration_error(&mech, StateLayout::SecondOrder, &e),
            source: e,
        };
        let (stats, stopped, switch_at) = match opts.integrator {
            Integrator::Dopri5 | Integrator::Adams => {
                let mut y0 = q0.to_vec();
                y0.extend_from_slice(qd0);
                let mut sys = FirstOrder {
                    dy: self,
                    qdd: vec![0.0; n],
                    watch: Some(watch),
                };
                let run = integrate_explicit_named(
                    &mut sys,
                    opts,
                    t0,
                    &y0,
                    |_, t: f64, y: &[f64]| emit(t, &y[..n], &y[n..]),
                    |e| integration_error(&mech, StateLayout::FirstOrder, e),
                );
                let watch = sys.watch.expect("set above");
                *partition = watch.partition.clone();
                let (stats, stopped) = match run {
                    Ok(r) => r,
                    Err(e @ DynamicsError::Integration { .. }) => {
                        return Err(watch.with_cause(sys.dy, e))
                    }
                    Err(e) => return Err(e),
                };
                let switch_at = watch.switch_at;
                (stats, stopped, switch_at)
            }
            Integrator::GeneralizedAlpha => {
                let o = GeneralizedAlphaOptions {
                    rtol: opts.rtol,
                    atol: Tolerance::Scalar(opts.atol),
                    max_steps: opts.max_steps,
                    ..Default::default()
                };
                // the position solves of the step's iterates read the stop
                // request too (far from the solution one can take 30
                // iterations: most of a second on the 1440-DOF chain)
                self.kin.set_stop(opts.stop.clone());
                let mut sys = Residual {
                    dy: self,
                    watch,
                    stop: opts.stop.as_deref(),
                    stopped_at: None,
                };
                let mut last_output = f64::NEG_INFINITY;
                let solved = GeneralizedAlpha::new(o).solve_with(
                    &mut sys,
                    t0,
                    q0,
                    qd0,
                    t_end,
                    &out,
                    |t, q, qd, _| {
                        last_output = t;
                        emit(t, q, qd)
                    },
                );
                sys.dy.kin.set_stop(None);
                *partition = sys.watch.partition.clone();
                let sol = match solved {
                    Ok(sol) => sol,
                    // the start-up mass matrix is singular: the projection's
                    // Mq names the degrees of freedom without inertia, as
                    // DOPRI5 and Adams report them
                    Err(e @ flexmb_ode::OdeError::SingularMatrix { what: "mass", .. }) => {
                        let mut qdd = vec![0.0; q0.len()];
                        let named = match sys.dy.accelerations_by_projection(t0, q0, qd0, &mut qdd)
                        {
                            Err(named @ DynamicsError::SingularMass { .. }) => named,
                            _ => to_err(e),
                        };
                        return Err(sys.watch.with_cause(sys.dy, named));
                    }
                    Err(e) => return Err(sys.watch.with_cause(sys.dy, to_err(e))),
                };
                if let Some((t, q, qd)) = sys.stopped_at.take() {
                    if t > last_output {
                        emit(t, &q, &qd);
                    }
                }
                let stopped = !matches!(sol.status, flexmb_ode::Status::Completed);
                (sol.stats.clone(), stopped, sys.watch.switch_at)
            }
        };
        if let Some(e) = failure {
            return Err(e);
        }
        // a stop for a chart switch is not a stop of the observer
        let stopped = stopped && switch_at.is_none();
        Ok((stats, switch_at, stopped))
    }

    /// q and q̇ in the chart of `mech` (same nodal coordinates and
    /// deformations as this dynamics' mechanism, perhaps other DOF roles,
    /// e.g. the mechanism a run started with before [`ChartSwitch`]es), read
    /// from the current kinematic state.
    pub fn in_chart_of(&self, mech: &Mechanism) -> (Vec<f64>, Vec<f64>) {
        let (x, xd, eps, epsd) = (self.kin.x(), self.kin.xd(), self.kin.eps(), self.kin.epsd());
        mech.dofs
            .iter()
            .map(|c| match *c {
                Coordinate::Node(i) => (x[i], xd[i]),
                Coordinate::Def(j) => (eps[j], epsd[j]),
            })
            .unzip()
    }

    /// The Jacobian S = ∂q'/∂q of the DOFs q' of `mech` (the same scene in
    /// another chart, as for [`in_chart_of`](Self::in_chart_of)) with respect
    /// to this dynamics' DOFs q, at the current configuration: the identity
    /// in the slots whose coordinate is the same in both, the row of F,q
    /// (or E,q) of the coordinate `mech` has in a slot where they differ.
    /// Mode shapes map as S v; a mass or stiffness matrix as S⁻ᵀ M S⁻¹
    /// (singular where the chart of `mech` is).
    pub fn chart_jacobian(&mut self, mech: &Mechanism) -> Mat<f64> {
        let n_q = self.n_q();
        let own = self.mech.clone();
        let mut s = Mat::<f64>::identity(n_q, n_q);
        for (k, (c, c_own)) in mech.dofs.iter().zip(&own.dofs).enumerate() {
            if c == c_own {
                continue;
            }
            let row = match *c {
                Coordinate::Node(i) => self.kin.f_xi().row(i).to_owned(),
                Coordinate::Def(j) => self.kin.e_xi().row(j).to_owned(),
            };
            for a in 0..n_q {
                s[(k, a)] = row[a];
            }
        }
        s
    }

    /// Switches every chart that is no longer good at (t, q) (kinematics
    /// solved there): rebuilds the dynamics in the new chart, with its
    /// position solve starting from the current configuration, and returns
    /// q, q̇ in it. `None` if no chart needs switching. Charts whose
    /// switch would change the coordinate in one of the DOF slots `keep`
    /// (held by a static solve, or not kept by a reduced model's basis)
    /// stay. The switches are appended to `log`.
    pub fn switch_charts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        keep: &[usize],
        log: &mut Vec<ChartSwitch>,
    ) -> Result<Option<(Q, Q)>, DynamicsError> {
        let charts = self.mech.euler_charts();
        let wanted: Vec<_> = charts
            .iter()
            .filter_map(|c| c.needs_switch(q).map(|s| (c, s)))
            .filter(|(_, (slot, _))| !keep.contains(slot))
            .collect();
        if wanted.is_empty() {
            return Ok(None);
        }
        self.kinematics_at(t, q, Some(qd))?;
        let mut mech = (*self.mech).clone();
        for (c, (slot, x_new_dep)) in wanted {
            log.push(mech.switch_chart(c, slot, x_new_dep, t));
        }
        self.adopt(t, mech).map(Some)
    }

    /// Rebuilds this dynamics on `mech`, the same scene with other charts
    /// or another dependent set, its position solve starting from the
    /// current configuration (kinematics solved at t), and returns q, q̇ in
    /// it, mapped through x, ẋ. Chart switches and re-partitioning share it.
    pub(crate) fn adopt(&mut self, t: f64, mech: Mechanism) -> Result<(Q, Q), DynamicsError> {
        let x = self.kin.x().to_vec();
        let mech = Arc::new(mech);
        let (q1, qd1) = self.in_chart_of(&mech);
        self.replace_mechanism(mech);
        self.kin.set_guess(&x);
        self.kinematics_at(t, &q1, None)?;
        Ok((q1, qd1))
    }

    /// Puts this dynamics in the chart of `mech` (the same scene with other
    /// Euler-parameter DOFs, e.g. the mechanism before [`ChartSwitch`]es),
    /// if it is not in it: rebuilt with its settings, its position solve
    /// starting from the current configuration.
    pub fn use_chart(&mut self, mech: &Arc<Mechanism>) {
        if !Arc::ptr_eq(&self.mech, mech) {
            let x = self.kin.x().to_vec();
            self.replace_mechanism(mech.clone());
            self.kin.set_guess(&x);
        }
    }

    /// Rebuilds this dynamics for `mech` (the same scene with other DOF
    /// roles), keeping its settings: Newton options, load factor and scale,
    /// evaluation count, and the branch of periodic deformations.
    pub(crate) fn replace_mechanism(&mut self, mech: Arc<Mechanism>) {
        let newton = self.kin.newton_options();
        let (lf, ls, ev) = (self.load_factor, self.load_scale, self.evaluations);
        let branch = self.kin.branch().to_vec();
        *self = Dynamics::new(mech);
        self.kin.set_branch(&branch);
        self.kin.set_newton_options(newton);
        self.load_factor = lf;
        self.load_scale = ls;
        self.evaluations = ev;
    }
}
