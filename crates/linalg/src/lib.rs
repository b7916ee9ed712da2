//! System-level linear algebra for flexmb, on faer.
//!
//! Layering: this crate sits below every crate that decomposes a system
//! matrix, so that each algorithm exists once (`ARCHITECTURE.md`). Small
//! fixed-size element math stays on nalgebra in `flexmb-element`.
//!
//! - [`svd`](mod@svd): singular value decompositions that fall back to other methods
//!   when faer does not converge, with rank and null spaces.
//! - [`lu`]: a dense LU factorization with partial pivoting in reused memory,
//!   with pivot-ratio singularity detection (integrators, kinematics, statics).
//! - [`skyline`]: a symmetric positive-definite matrix in profile storage, its
//!   Cholesky factorization in place and a reverse Cuthill–McKee ordering (the
//!   mass matrix of the nodal equations of motion).
//! - [`eigen`]: the dense generalized symmetric-definite eigensolver
//!   `K v = λ M v` (Cholesky of K or M, transformation, `self_adjoint_eigen`,
//!   back-substitution, Rayleigh quotients; modes, buckling, Rayleigh–Ritz),
//!   with only the pairs asked for computed (Krylov–Schur) for a few modes of
//!   a large model.
//! - [`sparse_cholesky`]: a supernodal sparse Cholesky factorization and, with
//!   it as a shift-invert operator, the lowest eigenpairs of a large sparse
//!   pencil (Craig–Bampton reduction of solid models).
//!
//! A failed decomposition is a typed error ([`SvdError`], [`LuError`],
//! [`skyline::NotPositiveDefinite`], [`EigenError`], [`CholeskyError`]); the
//! physics crates wrap it as the source of their own errors.

mod abandon;
pub mod eigen;
pub mod lu;
mod shift_invert;
pub mod skyline;
pub mod sparse_cholesky;
pub mod svd;

pub use eigen::{
    generalized_eigen, generalized_eigen_until, generalized_eigenvalues, Definite, EigenError,
    GeneralizedEigen, Member,
};
pub use lu::{DenseLu, LuError, SINGULAR_PIVOT_RATIO};
pub use sparse_cholesky::{lowest_eigenpairs, CholeskyError, SparseCholesky};
pub use svd::{singular_values, svd, thin_svd, Svd, SvdError, SvdMethod};
