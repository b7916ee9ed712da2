//! System-level linear algebra for flexmb, on faer.
//!
//! Layering: this crate sits below every crate that decomposes a system
//! matrix, so that each algorithm exists once (`ARCHITECTURE.md`). Small
//! fixed-size element math stays on nalgebra in `flexmb-element`.
//!
//! - [`svd`]: singular value decompositions that fall back to other methods
//!   when faer does not converge, with rank and null spaces.
//! - [`lu`]: a dense LU factorization with partial pivoting in reused memory,
//!   with pivot-ratio singularity detection (integrators, kinematics, statics).
//! - [`skyline`]: a symmetric positive-definite matrix in profile storage, its
//!   Cholesky factorization in place and a reverse Cuthill–McKee ordering (the
//!   mass matrix of the nodal equations of motion).
//!
//! A failed decomposition is a typed error ([`SvdError`], [`LuError`],
//! [`skyline::NotPositiveDefinite`]); the physics crates wrap it as the
//! source of their own errors.

pub mod lu;
pub mod skyline;
pub mod svd;

pub use lu::{DenseLu, LuError, SINGULAR_PIVOT_RATIO};
pub use svd::{singular_values, svd, thin_svd, Svd, SvdError, SvdMethod};
