//! Types shared by all integrators: statistics, output selection, observer
//! control, solutions, tolerances, and internal validation helpers.

use std::fmt;

use crate::error::{OdeError, RhsError};
use crate::system::OdeSystem;

/// Work statistics of one integration.
///
/// All counters are exact: every call of the user's function is counted,
/// including the initial one and those made for rejected steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// Number of calls of [`OdeSystem::rhs`] (explicit methods) or of
    /// [`SecondOrderSystem::residual`](crate::SecondOrderSystem::residual)
    /// (generalized-α).
    pub rhs_evals: usize,
    /// Number of accepted steps.
    pub steps_accepted: usize,
    /// Number of steps rejected by the local error test (for generalized-α
    /// the steps abandoned because Newton did not converge are counted in
    /// [`Stats::newton_failures`] instead).
    pub steps_rejected: usize,
    /// Newton iterations (linear solves with the iteration matrix), implicit
    /// method only.
    pub newton_iterations: usize,
    /// Newton convergence failures, implicit method only.
    pub newton_failures: usize,
    /// Evaluations of the tangent (Jacobian) matrices, implicit method only.
    pub jacobian_evals: usize,
    /// LU factorizations, implicit method only (includes the factorization of
    /// the mass matrix for the consistent initial acceleration).
    pub lu_decompositions: usize,
    /// Size of the last accepted step (signed with the direction of
    /// integration), 0 if no step was taken.
    pub last_step: f64,
    /// Smallest absolute accepted step size, 0 if no step was taken.
    pub min_step: f64,
    /// Largest absolute accepted step size, 0 if no step was taken.
    pub max_step: f64,
}

impl Stats {
    pub(crate) fn record_accepted(&mut self, h: f64) {
        let a = h.abs();
        if self.steps_accepted == 0 {
            self.min_step = a;
            self.max_step = a;
        } else {
            self.min_step = self.min_step.min(a);
            self.max_step = self.max_step.max(a);
        }
        self.last_step = h;
        self.steps_accepted += 1;
    }

    /// Adds the counts of `segment`, a later run restarted where this one
    /// ended (e.g. after an Euler-chart switch), so that the totals are
    /// those of the whole run: the counts add up, the step sizes keep the
    /// extremes over both and the last one of the latest run that stepped.
    pub fn accumulate(&mut self, segment: &Stats) {
        self.rhs_evals += segment.rhs_evals;
        self.steps_accepted += segment.steps_accepted;
        self.steps_rejected += segment.steps_rejected;
        self.newton_iterations += segment.newton_iterations;
        self.newton_failures += segment.newton_failures;
        self.jacobian_evals += segment.jacobian_evals;
        self.lu_decompositions += segment.lu_decompositions;
        if segment.steps_accepted > 0 {
            self.last_step = segment.last_step;
            self.min_step = if self.min_step == 0.0 {
                segment.min_step
            } else {
                self.min_step.min(segment.min_step)
            };
            self.max_step = self.max_step.max(segment.max_step);
        }
    }
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} successful steps, {} failed attempts, {} function evaluations",
            self.steps_accepted, self.steps_rejected, self.rhs_evals
        )?;
        if self.jacobian_evals > 0 || self.lu_decompositions > 0 || self.newton_iterations > 0 {
            write!(
                f,
                ", {} Newton iterations ({} failures), {} Jacobian evaluations, {} LU decompositions",
                self.newton_iterations,
                self.newton_failures,
                self.jacobian_evals,
                self.lu_decompositions
            )?;
        }
        write!(
            f,
            "; step sizes min {:e}, max {:e}, last {:e}",
            self.min_step, self.max_step, self.last_step
        )
    }
}

/// Returned by an observer to continue or to stop the integration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on integrating.
    Continue,
    /// Stop now; the solver returns `Ok` with the output gathered so far and
    /// [`Status::Stopped`].
    Stop,
}

/// How an integration ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Status {
    /// `t_end` was reached.
    Completed,
    /// The observer returned [`Control::Stop`] at time `t`.
    Stopped {
        /// Time of the output point at which the observer asked to stop.
        t: f64,
    },
}

/// Which points are stored in the solution and passed to the observer.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Output {
    /// The initial point and the end of every accepted step.
    #[default]
    Steps,
    /// Exactly these times, obtained with the method's continuous extension
    /// (no extra evaluations). They must lie in the closed integration
    /// interval and be ordered in the direction of integration (repetitions
    /// are allowed).
    Times(Vec<f64>),
    /// Only the final point.
    Final,
}

impl Output {
    pub(crate) fn validate(&self, t0: f64, t_end: f64) -> Result<(), OdeError> {
        if let Output::Times(times) = self {
            let dir = (t_end - t0).signum();
            let mut prev = t0;
            for (index, &time) in times.iter().enumerate() {
                let reason = if !time.is_finite() {
                    Some("not finite")
                } else if dir * (time - t0) < 0.0 || dir * (time - t_end) > 0.0 {
                    Some("outside the integration interval")
                } else if dir * (time - prev) < 0.0 {
                    Some("not ordered in the direction of integration")
                } else {
                    None
                };
                if let Some(reason) = reason {
                    return Err(OdeError::InvalidOutputTimes {
                        index,
                        time,
                        reason,
                    });
                }
                prev = time;
            }
        }
        Ok(())
    }

    /// Number of points to reserve storage for.
    pub(crate) fn capacity_hint(&self) -> usize {
        match self {
            Output::Steps => 64,
            Output::Times(v) => v.len(),
            Output::Final => 1,
        }
    }
}

/// Solution of a first-order problem: the stored output points, statistics
/// and how the integration ended.
///
/// States are stored contiguously, one row of length [`Solution::dim`] per
/// output point.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    t: Vec<f64>,
    y: Vec<f64>,
    dim: usize,
    /// Work statistics.
    pub stats: Stats,
    /// Whether `t_end` was reached or the observer stopped the integration.
    pub status: Status,
}

impl Solution {
    pub(crate) fn with_capacity(dim: usize, points: usize) -> Self {
        Self {
            t: Vec::with_capacity(points),
            y: Vec::with_capacity(points * dim),
            dim,
            stats: Stats::default(),
            status: Status::Completed,
        }
    }

    pub(crate) fn push(&mut self, t: f64, y: &[f64]) {
        self.t.push(t);
        self.y.extend_from_slice(y);
    }

    /// Dimension of the state.
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

    /// The state at the `i`-th stored point.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    pub fn y(&self, i: usize) -> &[f64] {
        &self.y[i * self.dim..(i + 1) * self.dim]
    }

    /// All states, row after row.
    pub fn y_flat(&self) -> &[f64] {
        &self.y
    }

    /// The last stored point, if any.
    pub fn last(&self) -> Option<(f64, &[f64])> {
        let n = self.len();
        (n > 0).then(|| (self.t[n - 1], self.y(n - 1)))
    }

    /// Iterates over `(t, y)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = (f64, &[f64])> + '_ {
        self.t
            .iter()
            .copied()
            .zip(self.y.chunks_exact(self.dim.max(1)))
    }
}

/// Absolute tolerance: one value for all components or one per component.
#[derive(Clone, Debug, PartialEq)]
pub enum Tolerance {
    /// Same value for every component.
    Scalar(f64),
    /// One value per component (length must equal the dimension).
    PerComponent(Vec<f64>),
}

impl From<f64> for Tolerance {
    fn from(v: f64) -> Self {
        Tolerance::Scalar(v)
    }
}

impl From<Vec<f64>> for Tolerance {
    fn from(v: Vec<f64>) -> Self {
        Tolerance::PerComponent(v)
    }
}

impl From<&[f64]> for Tolerance {
    fn from(v: &[f64]) -> Self {
        Tolerance::PerComponent(v.to_vec())
    }
}

impl Tolerance {
    /// Expands to one value per component, checking that all are finite and
    /// strictly positive.
    pub(crate) fn expand(&self, name: &'static str, dim: usize) -> Result<Vec<f64>, OdeError> {
        let v = match self {
            Tolerance::Scalar(a) => vec![*a; dim],
            Tolerance::PerComponent(v) => {
                if v.len() != dim {
                    return Err(OdeError::DimensionMismatch {
                        what: name,
                        expected: dim,
                        found: v.len(),
                    });
                }
                v.clone()
            }
        };
        if let Tolerance::Scalar(a) = self {
            check_positive(name, *a)?;
        }
        for &a in &v {
            check_positive(name, a)?;
        }
        Ok(v)
    }
}

pub(crate) fn check_positive(name: &'static str, v: f64) -> Result<(), OdeError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(OdeError::InvalidOption {
            name,
            reason: format!("must be finite and > 0, got {v}"),
        })
    }
}

pub(crate) fn check_optional_positive(name: &'static str, v: Option<f64>) -> Result<(), OdeError> {
    match v {
        Some(v) => check_positive(name, v),
        None => Ok(()),
    }
}

pub(crate) fn check_interval(t0: f64, t_end: f64) -> Result<(), OdeError> {
    let reason = if !t0.is_finite() || !t_end.is_finite() {
        Some("bounds must be finite")
    } else if t0 == t_end {
        Some("t_end must differ from t0")
    } else {
        None
    };
    match reason {
        Some(reason) => Err(OdeError::InvalidInterval { t0, t_end, reason }),
        None => Ok(()),
    }
}

pub(crate) fn check_vector(what: &'static str, v: &[f64], dim: usize) -> Result<(), OdeError> {
    if v.len() != dim {
        return Err(OdeError::DimensionMismatch {
            what,
            expected: dim,
            found: v.len(),
        });
    }
    if let Some(index) = first_non_finite(v) {
        return Err(OdeError::NonFiniteInitialValue { what, index });
    }
    Ok(())
}

#[inline]
pub(crate) fn first_non_finite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

pub(crate) fn check_state(t: f64, y: &[f64]) -> Result<(), OdeError> {
    match first_non_finite(y) {
        Some(index) => Err(OdeError::NonFiniteState { t, index }),
        None => Ok(()),
    }
}

pub(crate) fn wrap_rhs_error(t: f64, source: RhsError) -> OdeError {
    OdeError::Rhs { t, source }
}

/// Calls the right-hand side, counts the call and checks the result.
#[inline]
pub(crate) fn eval_rhs<S: OdeSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    dy: &mut [f64],
    stats: &mut Stats,
) -> Result<(), OdeError> {
    stats.rhs_evals += 1;
    sys.rhs(t, y, dy).map_err(|e| wrap_rhs_error(t, e))?;
    match first_non_finite(dy) {
        Some(index) => Err(OdeError::NonFiniteRhs {
            what: "rhs",
            t,
            index,
        }),
        None => Ok(()),
    }
}

/// Spacing of the floating-point numbers at `|t|` (MATLAB's `eps(t)`).
pub(crate) fn spacing(t: f64) -> f64 {
    let a = t.abs();
    if !a.is_finite() {
        return f64::NAN;
    }
    f64::from_bits(a.to_bits() + 1) - a
}

/// Collects output points of a first-order integration and calls the
/// observer.
pub(crate) struct FirstOrderSink<'o, F> {
    output: &'o Output,
    next_time: usize,
    pub(crate) solution: Solution,
    observer: F,
    dir: f64,
    /// Scratch vector for interpolated states.
    pub(crate) buf: Vec<f64>,
}

impl<'o, F: FnMut(f64, &[f64]) -> Control> FirstOrderSink<'o, F> {
    pub(crate) fn new(output: &'o Output, dim: usize, dir: f64, observer: F) -> Self {
        Self {
            output,
            next_time: 0,
            solution: Solution::with_capacity(dim, output.capacity_hint()),
            observer,
            dir,
            buf: vec![0.0; dim],
        }
    }

    fn emit(&mut self, t: f64, y: &[f64]) -> Control {
        self.solution.push(t, y);
        let c = (self.observer)(t, y);
        if c == Control::Stop {
            self.solution.status = Status::Stopped { t };
        }
        c
    }

    /// Emits the initial point where requested.
    pub(crate) fn initial(&mut self, t0: f64, y0: &[f64]) -> Control {
        match self.output {
            Output::Steps => self.emit(t0, y0),
            Output::Times(times) => {
                while self.next_time < times.len() && times[self.next_time] == t0 {
                    self.next_time += 1;
                    if self.emit(t0, y0) == Control::Stop {
                        return Control::Stop;
                    }
                }
                Control::Continue
            }
            Output::Final => Control::Continue,
        }
    }

    /// Emits the points in `(t_old, t_new]` after an accepted step. `interp`
    /// evaluates the continuous extension at a time into a buffer.
    pub(crate) fn step(
        &mut self,
        t_new: f64,
        y_new: &[f64],
        is_last: bool,
        mut interp: impl FnMut(f64, &mut [f64]),
    ) -> Control {
        match self.output {
            Output::Steps => self.emit(t_new, y_new),
            Output::Final => {
                if is_last {
                    self.emit(t_new, y_new)
                } else {
                    Control::Continue
                }
            }
            Output::Times(times) => {
                while self.next_time < times.len() {
                    let tau = times[self.next_time];
                    if !is_last && self.dir * (tau - t_new) > 0.0 {
                        break;
                    }
                    self.next_time += 1;
                    let c = if tau == t_new || is_last && self.dir * (tau - t_new) >= 0.0 {
                        self.emit(tau, y_new)
                    } else {
                        let mut buf = std::mem::take(&mut self.buf);
                        interp(tau, &mut buf);
                        let c = self.emit(tau, &buf);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spacing_matches_matlab_eps() {
        assert_eq!(spacing(1.0), f64::EPSILON);
        assert_eq!(spacing(-1.0), f64::EPSILON);
        assert_eq!(spacing(2.0), 2.0 * f64::EPSILON);
        assert!(spacing(0.0) > 0.0);
    }

    #[test]
    fn output_validation() {
        assert!(Output::Times(vec![0.0, 0.5, 1.0])
            .validate(0.0, 1.0)
            .is_ok());
        assert!(Output::Times(vec![1.0, 0.5]).validate(1.0, 0.0).is_ok());
        assert!(Output::Times(vec![0.5, 0.2]).validate(0.0, 1.0).is_err());
        assert!(Output::Times(vec![1.5]).validate(0.0, 1.0).is_err());
        assert!(Output::Times(vec![f64::NAN]).validate(0.0, 1.0).is_err());
    }

    /// A run restarted after a chart switch: accumulated into the default
    /// (empty) statistics a segment is copied, and a second one adds its
    /// counts and keeps the extreme step sizes and its own last step. A
    /// segment without steps leaves the step sizes alone.
    #[test]
    fn restarted_segments_accumulate() {
        let seg = |evals, accepted, min, max, last| Stats {
            rhs_evals: evals,
            steps_accepted: accepted,
            steps_rejected: 1,
            newton_iterations: 2,
            newton_failures: 0,
            jacobian_evals: 1,
            lu_decompositions: 3,
            last_step: last,
            min_step: min,
            max_step: max,
        };
        let a = seg(10, 4, 0.01, 0.1, 0.05);
        let mut total = Stats::default();
        total.accumulate(&a);
        assert_eq!(total, a);
        total.accumulate(&seg(6, 2, 0.002, 0.05, 0.03));
        assert_eq!(
            (total.rhs_evals, total.steps_accepted, total.steps_rejected),
            (16, 6, 2)
        );
        assert_eq!((total.newton_iterations, total.lu_decompositions), (4, 6));
        assert_eq!(
            (total.min_step, total.max_step, total.last_step),
            (0.002, 0.1, 0.03)
        );
        total.accumulate(&seg(1, 0, 0.0, 0.0, 0.0));
        assert_eq!(
            (total.min_step, total.max_step, total.last_step),
            (0.002, 0.1, 0.03)
        );
    }
}
