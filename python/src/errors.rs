//! The exceptions of the package: `FlexmbError` and its subclasses, each
//! carrying flexmb's own message, and the mapping of the Rust errors onto
//! them.

use flexmb::model::ModelError as RsModelError;
use flexmb::reduction::ReductionError;
use pyo3::exceptions::PyException;
use pyo3::PyErr;

pyo3::create_exception!(
    flexmb,
    FlexmbError,
    PyException,
    "Base class of every error flexmb raises; the message is flexmb's own and names the culprit."
);
pyo3::create_exception!(
    flexmb,
    SceneError,
    FlexmbError,
    "A scene (file, text or dict) that cannot be read: malformed RON, an unknown field or variant, a missing file."
);
pyo3::create_exception!(
    flexmb,
    ModelError,
    FlexmbError,
    "A scene that reads but is no valid mechanism (unknown ids, conflicting roles, over- or under-constrained), or a reduced model that does not fit the scene."
);
pyo3::create_exception!(
    flexmb,
    SolverError,
    FlexmbError,
    "A computation on a valid model failed: no static equilibrium, a failed eigen analysis or time integration."
);
pyo3::create_exception!(
    flexmb,
    ArgumentError,
    FlexmbError,
    "An argument out of range or of the wrong kind: a negative end time, zero modes, an unknown integrator or coordinate name."
);

/// An [`ArgumentError`] with `message`.
pub fn argument(message: impl Into<String>) -> PyErr {
    ArgumentError::new_err(message.into())
}

/// A [`SolverError`] with `message`.
pub fn solver(message: impl std::fmt::Display) -> PyErr {
    SolverError::new_err(message.to_string())
}

/// A scene error of the model layer: unreadable or malformed scenes are
/// [`SceneError`]s, numerical failures while building a valid scene
/// [`SolverError`]s, everything else (an invalid mechanism) [`ModelError`].
pub fn model(e: RsModelError) -> PyErr {
    match e {
        RsModelError::Parse { .. } | RsModelError::Io { .. } => SceneError::new_err(e.to_string()),
        RsModelError::Computation { .. } => SolverError::new_err(e.to_string()),
        _ => ModelError::new_err(e.to_string()),
    }
}

/// An error of a computation on a (reduced or unreduced) model: invalid
/// requests are [`ArgumentError`]s, the rest [`SolverError`]s.
pub fn reduction(e: ReductionError) -> PyErr {
    match e {
        ReductionError::Invalid(m) => ArgumentError::new_err(m),
        e => SolverError::new_err(e.to_string()),
    }
}

/// An internal failure (a panic caught at the boundary): never expected,
/// reported as a [`FlexmbError`] instead of crashing the interpreter.
pub fn internal(what: &str, payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let why = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown cause".into());
    FlexmbError::new_err(format!(
        "internal error in {what}: {why} (please report this as a bug)"
    ))
}
