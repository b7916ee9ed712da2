//! System-level dense linear algebra for flexmb, on faer.
//!
//! Layering: this crate sits below every crate that decomposes a system
//! matrix, so that each algorithm exists once (`ARCHITECTURE.md`). Small
//! fixed-size element math stays on nalgebra in `flexmb-element`.
//!
//! - [`svd`](mod@svd): singular value decompositions that fall back to other methods
//!   when faer does not converge, with rank and null spaces.

pub mod svd;

pub use svd::{singular_values, svd, thin_svd, Svd, SvdError, SvdMethod};
