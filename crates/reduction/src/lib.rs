//! System model reduction that keeps the geometric non-linearity (thesis
//! chapters 5–6): the degrees of freedom q are constrained to q = G(z)
//! (6.12) and the equations of motion are projected (6.15):
//!
//! Mz z̈ = G,zᵀ (F,qᵀ(f − Mx ẍ0) − E,qᵀσ − Mq (G,zz ż)ż),  Mz = G,zᵀ Mq G,z,
//!
//! with ẍ0 the accelerations of the transfer functions for q̈ = 0 at
//! q̇ = G,z ż. The transfer functions stay non-linear; only the coordinates are
//! reduced.
//!
//! This crate provides the general reduced model over any [`Basis`], the
//! fixed basis method G = q0 + Vη (6.16) with modal (5.21) and SVD-modal
//! (5.22)–(5.23) bases, and the interpolated basis method (6.23) with cubic
//! splines and modal subspace interpolation (§6.3.3) or MAC-sorted
//! eigenvectors, its extension to two configuration coordinates on a
//! tensor grid ([`GridBasis`]: bicubic splines, MSI over the grid; beyond
//! the thesis), the per-mode SVD (6.19)–(6.21), the path eigenvectors of
//! chapter 7 (7.3)–(7.11), reduced statics with load-scale continuation
//! ([`load_scale_path`]), the reduced linearization (F.5) with its rest form
//! (F.7), and saving and loading reduced models ([`SavedModel`]).
//! [`MechanicalModel`] gives the unreduced [`Dynamics`](flexmb_dynamics::Dynamics)
//! and the [`ReducedModel`] one interface (statics, rest linearization,
//! eigenfrequencies, load sweeps, simulation). The
//! `flexmb reduce` command builds these models from a scene (docs/cli.md).
//!
//! ```
//! use flexmb_reduction::{FixedBasis, ReducedModel};
//! use flexmb_model::Scene;
//! use std::sync::Arc;
//! let scene = Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/scenes/straight_guidance_planar.ron"))).unwrap();
//! let mech = Arc::new(scene.build(None).unwrap());
//! // the first three modes at rest (MODAL-3 of thesis §5.4.1)
//! let basis = flexmb_reduction::modal_basis(&mech, 0.0, &mech.q0(), 3, None).unwrap();
//! let mut red = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
//! let mut zdd = vec![0.0; 3];
//! red.accelerations(0.05, &[0.0; 3], &[0.0; 3], &mut zdd).unwrap();
//! assert!(zdd.iter().any(|v| v.abs() > 0.0)); // the force pulse drives the reduced model
//! ```
#![warn(missing_docs)]

mod basis;
mod bicubic;
mod continuation;
mod grid;
mod ibm;
mod mechanical;
mod model;
mod msi;
mod path;
mod saved;
mod spline;
mod tangents;

pub use basis::{
    fixed_basis_frequencies, modal_basis, per_mode_svd_basis, svd_modal_basis, Basis, FixedBasis,
    PerModeSvd, SvdModal, FINAL_SVD_THRESHOLD, SVD_THRESHOLD,
};
pub use bicubic::{order_index, BicubicSpline, ORDERS};
pub use continuation::{continue_load_scale, load_scale_path, SUBSTEPS};
pub use grid::{GridBasis, GridKnots};
pub use ibm::{interpolated_basis_from_sweep, InterpolatedBasis, Knots, SubspaceInterpolation};
pub use mechanical::{Equilibrium, MechanicalModel, ModelTrajectory, StateObserver, SweepPoint};
pub use model::{ReducedLinearization, ReducedModel, ReducedTrajectory};
pub use msi::{
    largest_principal_angle, mac_sorted, modal_subspace_interpolation,
    modal_subspace_interpolation_grid, orthonormalize,
};
pub use path::{
    constrained_eigenvectors, null_space_of_transpose, unconstrained_path_eigenvectors,
};
pub use saved::{dof_names, SavedBasis, SavedModel, FORMAT_VERSION};
pub use spline::CubicSpline;
pub use tangents::equilibrium_tangents;

/// Failures of the reduction layer.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ReductionError {
    /// The unreduced dynamics failed.
    #[error("{0}")]
    Dynamics(#[from] flexmb_dynamics::DynamicsError),
    /// An eigen-analysis failed.
    #[error("{0}")]
    Linearize(#[from] flexmb_linearize::LinearizeError),
    /// Inconsistent input.
    #[error("{0}")]
    Invalid(String),
    /// No static equilibrium was found along a load-scale continuation.
    #[error(
        "no equilibrium at load scale {lambda:.4} (from {from:.4}, {substeps} substeps): {message}"
    )]
    NoEquilibrium {
        /// The load scale that could not be reached.
        lambda: f64,
        /// The load scale of the last equilibrium.
        from: f64,
        /// The most substeps tried.
        substeps: usize,
        /// The solver's last message.
        message: String,
    },
    /// A decomposition failed on finite input (a numerical failure).
    #[error("{0}")]
    Computation(String),
    /// The reduced mass matrix is singular (dependent basis vectors).
    #[error("the reduced mass matrix is not positive definite: the basis vectors are linearly dependent or carry no inertia")]
    SingularMass,
}
