//! Error types: failures reported by user systems and by the integrators.

use std::fmt;
use std::sync::Arc;

/// Failure reported by a user-supplied right-hand side, residual or tangent.
///
/// The mechanics layer uses it, for instance, to report that the Newton
/// solve for a constrained configuration did not converge. It carries a
/// human-readable message, what the integrator may do about it
/// ([`RhsErrorKind`]), and optionally the typed error it came from
/// ([`cause`](Self::cause), [`downcast_cause`](Self::downcast_cause)). The
/// integrator adds the time at which it happened (see [`OdeError::Rhs`]).
#[derive(Clone, Debug)]
pub struct RhsError {
    message: String,
    kind: RhsErrorKind,
    cause: Option<Arc<dyn std::error::Error + Send + Sync + 'static>>,
}

/// What an integrator does with an [`RhsError`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RhsErrorKind {
    /// The integration ends with [`OdeError::Rhs`].
    Fatal,
    /// A smaller step may avoid it (e.g. a configuration solve that failed at
    /// a stage far from the solution): the step is rejected and retried.
    Recoverable,
    /// The system was asked to stop in the middle of a long evaluation (a
    /// tangent of a large model): the integration ends cleanly with
    /// [`Status::Stopped`](crate::Status::Stopped) at the last accepted time,
    /// its solution so far kept, as when `step_accepted` stops it. The
    /// implicit integrator honours it in its tangent; elsewhere it ends the
    /// integration like [`Fatal`](Self::Fatal).
    Interrupted,
}

impl RhsError {
    /// Creates an error with the given message; it aborts the integration.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            kind: RhsErrorKind::Fatal,
            cause: None,
        }
    }

    /// Creates an error that a smaller step may avoid (e.g. a configuration
    /// solve that failed at a stage far from the solution): the integrators
    /// reject the step and retry with a smaller step size.
    pub fn recoverable(message: impl Into<String>) -> Self {
        Self {
            kind: RhsErrorKind::Recoverable,
            ..Self::new(message)
        }
    }

    /// A stop request honoured inside an evaluation ([`RhsErrorKind::Interrupted`]).
    pub fn interrupted() -> Self {
        Self {
            kind: RhsErrorKind::Interrupted,
            ..Self::new("stopped on request")
        }
    }

    /// The error of kind `kind` for the typed error `cause`: its message is
    /// the cause's, and the cause is kept for [`downcast_cause`](Self::downcast_cause).
    pub fn from_cause(
        kind: RhsErrorKind,
        cause: impl std::error::Error + Send + Sync + 'static,
    ) -> Self {
        Self {
            message: cause.to_string(),
            kind,
            cause: Some(Arc::new(cause)),
        }
    }

    /// What the integrator does with it.
    pub fn kind(&self) -> RhsErrorKind {
        self.kind
    }

    /// Whether a smaller step may avoid the error.
    pub fn is_recoverable(&self) -> bool {
        self.kind == RhsErrorKind::Recoverable
    }

    /// Whether it is a stop request ([`RhsErrorKind::Interrupted`]).
    pub fn is_interrupted(&self) -> bool {
        self.kind == RhsErrorKind::Interrupted
    }

    /// The message given at creation.
    pub fn message(&self) -> &str {
        &self.message
    }

    /// The typed error this one was made from, if any. It is not returned by
    /// [`std::error::Error::source`]: the message already is its text, and
    /// a printer of the source chain would repeat it.
    pub fn cause(&self) -> Option<&(dyn std::error::Error + Send + Sync + 'static)> {
        self.cause.as_deref()
    }

    /// The cause as an `E`, if it is one.
    pub fn downcast_cause<E: std::error::Error + 'static>(&self) -> Option<&E> {
        self.cause()?.downcast_ref::<E>()
    }
}

/// Equal when message and kind are (the causes are not compared).
impl PartialEq for RhsError {
    fn eq(&self, other: &Self) -> bool {
        self.message == other.message && self.kind == other.kind
    }
}

impl fmt::Display for RhsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RhsError {}

impl From<String> for RhsError {
    fn from(message: String) -> Self {
        Self::new(message)
    }
}

impl From<&str> for RhsError {
    fn from(message: &str) -> Self {
        Self::new(message)
    }
}

impl OdeError {
    /// Whether the error is a recoverable failure of the system's evaluation.
    pub fn is_recoverable_rhs(&self) -> bool {
        matches!(self, OdeError::Rhs { source, .. } if source.is_recoverable())
    }

    /// Whether the error is a stop request honoured inside an evaluation
    /// ([`RhsErrorKind::Interrupted`]).
    pub fn is_interrupted_rhs(&self) -> bool {
        matches!(self, OdeError::Rhs { source, .. } if source.is_interrupted())
    }
}

/// Errors returned by the integrators.
///
/// Input validation errors are returned before any evaluation of the system;
/// all other errors abort the integration at time `t`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OdeError {
    /// An option has an invalid value (non-positive tolerance, bad step size,
    /// parameter out of range, ...).
    #[error("invalid option `{name}`: {reason}")]
    InvalidOption {
        /// Name of the offending option.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A vector argument does not have the dimension of the system.
    #[error("dimension mismatch for `{what}`: expected {expected}, got {found}")]
    DimensionMismatch {
        /// Which argument (e.g. `y0`, `atol`).
        what: &'static str,
        /// The system dimension.
        expected: usize,
        /// The length that was passed.
        found: usize,
    },
    /// The integration interval is empty or not finite.
    #[error("invalid integration interval [{t0}, {t_end}]: {reason}")]
    InvalidInterval {
        /// Initial time.
        t0: f64,
        /// Final time.
        t_end: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// The output times are not finite, outside the interval or not ordered in
    /// the direction of integration.
    #[error("invalid output time {time} at position {index}: {reason}")]
    InvalidOutputTimes {
        /// Position of the offending entry in the list.
        index: usize,
        /// Its value.
        time: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A component of the initial state is NaN or infinite.
    #[error("initial value `{what}` has a non-finite component {index}")]
    NonFiniteInitialValue {
        /// Which argument (e.g. `y0`, `q0`, `qd0`).
        what: &'static str,
        /// Index of the first non-finite component.
        index: usize,
    },
    /// The user system returned an error.
    #[error("right-hand side failed at t = {t:e}: {source}")]
    Rhs {
        /// Time of the failing evaluation.
        t: f64,
        /// The error returned by the system.
        #[source]
        source: RhsError,
    },
    /// The right-hand side (or residual, or tangent) returned a NaN or an
    /// infinity.
    #[error("{what} returned a non-finite value at t = {t:e}, component {index}")]
    NonFiniteRhs {
        /// Which function (`rhs`, `residual`, `tangent`).
        what: &'static str,
        /// Time of the evaluation.
        t: f64,
        /// Index of the first non-finite component (for the tangent: flat
        /// column-major index into the mass, damping and stiffness matrices,
        /// in that order).
        index: usize,
    },
    /// The computed state became NaN or infinite although the right-hand side
    /// values were finite (overflow).
    #[error("state became non-finite at t = {t:e}, component {index}")]
    NonFiniteState {
        /// Time of the step that produced it.
        t: f64,
        /// Index of the first non-finite component.
        index: usize,
    },
    /// The step size needed to meet the tolerance fell below the minimum
    /// allowed by the floating-point resolution of `t`.
    #[error("step size underflow at t = {t:e}: step {h:e} is below the minimum {h_min:e}")]
    StepSizeTooSmall {
        /// Time at which the integration stopped.
        t: f64,
        /// The step size that was rejected.
        h: f64,
        /// The minimum allowed step size at `t`.
        h_min: f64,
    },
    /// The configured maximum number of steps was reached before `t_end`.
    #[error("maximum number of steps ({max_steps}) exceeded at t = {t:e}")]
    MaxStepsExceeded {
        /// Time reached.
        t: f64,
        /// The configured limit.
        max_steps: usize,
    },
    /// The tolerances are too small for the floating-point precision
    /// (Adams method, test of Shampine & Gordon).
    #[error("tolerances too small for machine precision at t = {t:e}: multiply rtol and atol by at least {factor:.3e}")]
    ToleranceTooSmall {
        /// Time at which this was detected.
        t: f64,
        /// Factor by which the tolerances should be increased.
        factor: f64,
    },
    /// The Newton iteration of the implicit method did not converge and the
    /// step size could not be reduced (fixed-step mode).
    #[error("Newton iteration did not converge at t = {t:e} with step {h:e}")]
    NewtonFailed {
        /// Start of the failed step.
        t: f64,
        /// Its size.
        h: f64,
    },
    /// A matrix that must be inverted (mass matrix or Newton iteration
    /// matrix) is singular.
    #[error("singular {what} matrix at t = {t:e}")]
    SingularMatrix {
        /// Which matrix (`mass`, `iteration`).
        what: &'static str,
        /// Time of the failure.
        t: f64,
        /// The failed factorization.
        #[source]
        source: flexmb_linalg::LuError,
    },
}
