//! The error type of the builder. Every message names the culprit (a node, an
//! equation, a file and line, a mode) and, where possible, what would fix it.

use std::path::PathBuf;

/// Errors of the superelement builder and its readers.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file has a syntax error.
    #[error("{file}:{line}: {msg}")]
    Parse {
        /// The file.
        file: String,
        /// 1-based line number (0 if not known).
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// A file ends early, or lacks entries that every complete file of its
    /// kind has (line: the last line read, 0 if not known).
    #[error("{file}:{line}: truncated or incomplete: {msg}")]
    Truncated {
        /// The file.
        file: String,
        /// 1-based line number (0 if not known).
        line: usize,
        /// What is missing.
        msg: String,
    },
    /// Input files that do not belong together: K, M, the DOF list and the
    /// mesh (the message names the file at fault).
    #[error("mismatched input files: {0}")]
    Mismatch(String),
    /// A matrix entry that no stiffness or mass of a solid can have (a
    /// non-positive or missing diagonal).
    #[error("{file}: {msg}")]
    Matrix {
        /// The file (or "K" / "M" when not read from a file).
        file: String,
        /// What is wrong, naming the equation, node and direction.
        msg: String,
    },
    /// A file could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Matrix or vector sizes do not agree.
    #[error("size mismatch: {0}")]
    SizeMismatch(String),
    /// A matrix that must be symmetric is not.
    #[error("not symmetric: {0}")]
    NotSymmetric(String),
    /// The stiffness matrix is not positive semi-definite.
    #[error("stiffness is not positive semi-definite: {0}")]
    NotPositiveSemiDefinite(String),
    /// The part (or a piece of it) is not attached to the interfaces: the interior
    /// stiffness is singular.
    #[error("part not attached (singular interior stiffness): {0}")]
    NotAttached(String),
    /// An interface node set is unusable.
    #[error("interface {side}: {msg}")]
    Interface {
        /// "p" or "q" (or the name of a rigid link).
        side: String,
        /// What is wrong.
        msg: String,
    },
    /// A node selection could not be resolved.
    #[error("node selection: {0}")]
    Selection(String),
    /// Modes are (nearly) linearly dependent.
    #[error("linearly dependent modes: {0}")]
    DependentModes(String),
    /// The data look like they are in the wrong units.
    #[error("units look wrong: {0}")]
    Units(String),
    /// A prescribed displacement pattern is unusable.
    #[error("displacement pattern {name}: {msg}")]
    Pattern {
        /// The pattern's name.
        name: String,
        /// What is wrong.
        msg: String,
    },
    /// A point mass or rigid link is unusable.
    #[error("point mass / rigid link {name}: {msg}")]
    PointMass {
        /// Its name.
        name: String,
        /// What is wrong.
        msg: String,
    },
    /// A numerical solver failed.
    #[error("solver: {0}")]
    Solver(String),
    /// An external program (gmsh, CalculiX) is missing or failed.
    #[error("{program}: {msg}")]
    Tool {
        /// The program.
        program: String,
        /// What happened, with its error lines.
        msg: String,
    },
    /// An invalid setting or specification.
    #[error("invalid specification: {0}")]
    Spec(String),
    /// The element library rejected the result.
    #[error(transparent)]
    Element(#[from] flexmb_element::ElementError),
    /// An eigensolver failed (`flexmb-linalg`).
    #[error("eigensolver: {0}")]
    Eigen(#[from] flexmb_linalg::EigenError),
    /// A sparse Cholesky factorization could not be set up (`flexmb-linalg`).
    #[error("solver: {0}")]
    Cholesky(#[from] flexmb_linalg::CholeskyError),
}

impl Error {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
    pub(crate) fn write(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Write {
            path: path.into(),
            source,
        }
    }
    pub(crate) fn truncated(file: &str, line: usize, msg: impl Into<String>) -> Self {
        Error::Truncated {
            file: file.to_string(),
            line,
            msg: msg.into(),
        }
    }
    pub(crate) fn parse(file: &str, line: usize, msg: impl Into<String>) -> Self {
        Error::Parse {
            file: file.to_string(),
            line,
            msg: msg.into(),
        }
    }
    pub(crate) fn interface(side: &str, msg: impl Into<String>) -> Self {
        Error::Interface {
            side: side.to_string(),
            msg: msg.into(),
        }
    }

    /// Whether the error lies in the input (files, specification, model
    /// data: exit code 2 on the command line) rather than in a computation or
    /// in writing the output (exit code 1).
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            Error::Solver(_)
                | Error::Write { .. }
                | Error::Element(_)
                | Error::Eigen(_)
                | Error::Cholesky(_)
        )
    }
}
