//! Analyses of the linearized equations of flexible mechanisms (thesis
//! Appendix E, (4.2)): undamped eigenfrequencies and modes, damped and
//! gyroscopic modes with damping ratios, buckling load factors, mode shapes in
//! nodal coordinates, the MAC matrix and MAC mode tracking, and sweeps of the
//! eigenfrequencies along a load, a coordinate or a path, in parallel.
//!
//! The generalized symmetric-definite eigensolver behind the undamped modes
//! and buckling is `flexmb_linalg::generalized_eigen` (one copy, shared with
//! the superelement builder).
//!
//! ```
//! use flexmb_model::Scene;
//! use flexmb_dynamics::Dynamics;
//! use std::sync::Arc;
//! // a mass on a massless cantilever: one bending mode, ω² = 3EI/(m L³)
//! let scene = Scene::from_ron_str(r#"(
//!     dimension: Planar,
//!     materials: { "s": (e: 2.0e11, rho: 1.0) },
//!     sections: { "b": User((area: 1e-4, iy: 1e-9, iz: 1e-9, j: 1e-9, ky: inf, kz: inf)) },
//!     nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
//!     elements: [
//!         (id: "beam", type: Beam((nodes: ("A", "B"), material: "s", section: "b", mass: false))),
//!         (id: "m", type: PointMass(node: "B", mass: 2.0, inertia: Some(1e-6))),
//!     ],
//!     fixed: [ Node("A") ],
//!     rigid: [ Def("beam", "elongation") ],
//! )"#).unwrap();
//! let mut dy = Dynamics::new(Arc::new(scene.build(None).unwrap()));
//! let q0 = dy.mechanism().q0();
//! let lin = dy.linearize_at_rest(0.0, &q0).unwrap();
//! let modes = flexmb_linearize::undamped_modes(&lin, 1).unwrap();
//! let expect = (3.0 * 2.0e11 * 1e-9 / 2.0f64).sqrt() / (2.0 * std::f64::consts::PI);
//! assert!((modes.frequencies_hz()[0] / expect - 1.0).abs() < 1e-3);
//! ```
#![warn(missing_docs)]

mod mac;
mod modes;
mod sweep;

pub use mac::{mac, mac_matrix, track_modes, Tracking};
pub use modes::{
    asymmetry, buckling_factors, damped_modes, damped_modes_of, generalized_symmetric,
    undamped_modes, undamped_modes_until, DampedMode, Modes,
};
pub use sweep::{sweep, sweep_until, SweepOptions, SweepOutcome, SweepParameter, SweepPoint};

use faer::Mat;

/// `prefix` and the non-empty names joined by commas, or nothing.
fn listed(prefix: &str, names: &[String]) -> String {
    let names: Vec<&str> = names
        .iter()
        .map(|s| s.as_str())
        .filter(|s| !s.is_empty())
        .collect();
    if names.is_empty() {
        String::new()
    } else {
        format!("{prefix}{}", names.join(", "))
    }
}

/// Mode shapes in nodal coordinates: F,q V (n_x × k), at the configuration of
/// the last evaluation of `dy` (F,q is computed there if that evaluation did
/// not need it, e.g. after `Dynamics::accelerations`).
pub fn nodal_mode_shapes(dy: &mut flexmb_dynamics::Dynamics, vectors: &Mat<f64>) -> Mat<f64> {
    let n_q = vectors.nrows();
    let f = dy.kinematics_mut().f_xi().subcols(0, n_q);
    f * vectors
}

/// Failures of the analyses.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum LinearizeError {
    /// Inconsistent matrix sizes.
    #[error("dimension mismatch: {0}")]
    Dimension(String),
    /// A non-finite entry.
    #[error("non-finite entries in the {0}")]
    NonFinite(&'static str),
    /// The mass matrix is not positive definite.
    #[error(
        "the mass matrix is not positive definite: some degree of freedom has no inertia{}",
        listed(": ", dofs)
    )]
    MassNotPositive {
        /// The DOFs without inertia (empty when the matrices come without a
        /// mechanism), see [`flexmb_dynamics::massless_dofs`].
        dofs: Vec<String>,
    },
    /// The structural stiffness is not positive definite (buckling needs it).
    #[error("the structural stiffness is not positive definite: the structure has a mechanism (unrestrained motion){}", listed("; it involves ", dofs))]
    StiffnessNotPositive {
        /// The DOFs of the unrestrained motion (empty without a mechanism),
        /// see [`flexmb_dynamics::null_space_dofs`].
        dofs: Vec<String>,
    },
    /// An eigen solver did not converge.
    #[error(
        "the eigenvalue solver did not converge{}",
        listed(" ", std::slice::from_ref(at))
    )]
    NoConvergence {
        /// The configuration ([`flexmb_dynamics::LinearizedAt::describe`]),
        /// empty when the matrices come without one.
        at: String,
    },
    /// The stop request was set ([`undamped_modes_until`]).
    #[error("the eigen analysis was stopped on request")]
    Interrupted,
    /// A configuration of a sweep failed: its equilibrium, its linearization
    /// or its eigen analysis.
    #[error("sweep configuration {index} of {count} ({at}): {message}")]
    SweepConfiguration {
        /// Its number, from 1.
        index: usize,
        /// The number of configurations.
        count: usize,
        /// Sweep parameter.
        s: f64,
        /// The configuration: the load scale, or the held DOFs and values.
        at: String,
        /// Cause.
        message: String,
    },
}
