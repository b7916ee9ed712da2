//! Errors of scene parsing, validation and assembly. Every message names the
//! culprit and, where possible, what would fix it.

/// A scene could not be read or assembled.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// Malformed RON.
    #[error("scene file {file}: line {line}, column {column}: {message}")]
    Parse {
        /// File name (or `<string>`).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the parser expected.
        message: String,
    },
    /// A file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// The system's message.
        message: String,
    },
    /// A referenced id does not exist.
    #[error("{context}: unknown {kind} '{id}'{hint}")]
    UnknownId {
        /// What kind of id (node, material, ...).
        kind: &'static str,
        /// The id.
        id: String,
        /// Where it was referenced.
        context: String,
        /// A suggestion, if any.
        hint: String,
    },
    /// Two things have the same id.
    #[error("duplicate {kind} id '{id}'")]
    DuplicateId {
        /// What kind of id.
        kind: &'static str,
        /// The id.
        id: String,
    },
    /// A value is out of range.
    #[error("{context}: {message}")]
    Invalid {
        /// Where.
        context: String,
        /// What is wrong.
        message: String,
    },
    /// An element could not be built.
    #[error("element '{id}': {source}")]
    Element {
        /// The element id.
        id: String,
        /// The element library's error.
        source: flexmb_element::ElementError,
    },
    /// Conflicting roles for one coordinate or deformation.
    #[error("{name}: {message}")]
    Role {
        /// The coordinate or deformation.
        name: String,
        /// The conflict.
        message: String,
    },
    /// More independent equations than the free coordinates allow.
    #[error("over-constrained mechanism: these equations are redundant (an SVD of the constraint Jacobian finds them dependent): {redundant:?}. Release some of them (make them free instead of rigid, or remove a support)")]
    OverConstrained {
        /// Names of the redundant rigid/prescribed deformations or coordinates.
        redundant: Vec<String>,
    },
    /// Free coordinates that nothing determines.
    #[error("under-constrained mechanism: {count} motion(s) are not determined by the degrees of freedom and constraints; involved coordinates: {undetermined:?}. Add degrees of freedom (or use automatic DOF choice), or constrain these coordinates")]
    UnderConstrained {
        /// Number of undetermined motions.
        count: usize,
        /// Names of the coordinates taking part in them.
        undetermined: Vec<String>,
    },
    /// A decomposition failed on finite input (a numerical failure, not a
    /// modelling error).
    #[error("{what}: {source}")]
    Computation {
        /// What was being decomposed.
        what: String,
        /// The linear-algebra error.
        source: flexmb_linalg::SvdError,
    },
    /// A dense matrix or a model too large for this machine.
    #[error("{what}, more than a quarter of this machine's memory ({limit}); make the model smaller (fewer chain elements `n`) or split it")]
    TooLarge {
        /// What would be allocated, with its size.
        what: String,
        /// The limit.
        limit: String,
    },
}

impl ModelError {
    pub(crate) fn invalid(context: impl Into<String>, message: impl Into<String>) -> Self {
        ModelError::Invalid {
            context: context.into(),
            message: message.into(),
        }
    }
}
