//! Equations of motion of flexible multibody mechanisms in independent
//! coordinates (thesis Appendix D and E):
//!
//! * [`Dynamics::accelerations`]: the q̈ of Mq q̈ = F,qᵀ(f − Mx ẍ0 − h) − E,qᵀσ
//!   (D.10), with σ = Sε + Dε̇ + σ0 (E.2) including damping, initial stress and
//!   PD controllers. It is solved in nodal coordinates with multipliers for the
//!   rigid and prescribed deformations (the `nodal_eom` module: a sparse
//!   skyline factor of Mx, no F,q and no Mq); only when that system cannot be
//!   solved does it fall back to
//!   [`Dynamics::accelerations_by_projection`], which assembles
//!   Mq = F,qᵀ Mx F,q element by element and whose errors name the
//!   coordinates;
//! * [`Dynamics::residual`]: g(q, q̇, q̈, t) of (E.1);
//! * [`Dynamics::static_equilibrium`]: Newton on Kq + Gq (E.6) with load
//!   increments and held degrees of freedom;
//! * [`Dynamics::energies`] and [`Dynamics::external_power`] for checks.
//!
//! ```
//! use flexmb_model::Scene;
//! use flexmb_dynamics::Dynamics;
//! use std::sync::Arc;
//! // a rigid pendulum (point mass on a massless rigid beam) released horizontally
//! let scene = Scene::from_ron_str(r#"(
//!     dimension: Planar,
//!     gravity: Some([0.0, -9.81]),
//!     materials: { "m": (e: 1.0e9, rho: 0.0) },
//!     sections: { "s": Circle(d: 0.01) },
//!     nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
//!     elements: [
//!         (id: "rod", type: Beam((nodes: ("A", "B"), material: "m", section: "s", mass: false))),
//!         (id: "bob", type: PointMass(node: "B", mass: 2.0)),
//!     ],
//!     fixed: [ Coord("A", Position) ],
//!     rigid: [ Def("rod", "*") ],
//! )"#).unwrap();
//! let mut dy = Dynamics::new(Arc::new(scene.build(None).unwrap()));
//! let mut qdd = [0.0];
//! dy.accelerations(0.0, &[0.0], &[0.0], &mut qdd).unwrap();
//! assert!((qdd[0] + 9.81).abs() < 1e-12); // φ̈ = −g/L
//! ```
#![warn(missing_docs)]

mod culprit;
mod eom;
mod linearize;
mod momentum;
mod nodal_eom;
mod outputs;
mod partition;
mod projected;
mod reactions;
mod simulate;
mod statics;

/// A scene of `fixtures/scenes`, for the unit tests.
#[cfg(test)]
pub(crate) fn fixture(name: &str) -> flexmb_model::Scene {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    flexmb_model::Scene::load(&p).unwrap()
}

pub use culprit::{massless_dofs, null_space_dofs, short_number};
pub use eom::{Dynamics, Energies};
pub use flexmb_ode::{Control, Stats};
pub use linearize::{Linearization, LinearizedAt};
pub use momentum::Momentum;
pub use outputs::OutputTable;
pub use partition::{PARTITION_IMPROVEMENT, PARTITION_SWITCH_RATIO};
pub use simulate::{
    integrate_explicit, with_failure_cause, FirstOrder, Integrator, OutputPoint, SimulationOptions,
    Trajectory,
};
pub use statics::{StaticOptions, StaticSolution};

/// Failures of the dynamics layer, naming what failed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum DynamicsError {
    /// The kinematics failed at time t.
    #[error("at t = {t}: {source}")]
    Kinematics {
        /// Time.
        t: f64,
        /// Cause.
        source: flexmb_kinematics::KinematicsError,
    },
    /// The mass matrix Mq is not positive definite.
    #[error("the mass matrix is not positive definite: degrees of freedom without inertia: {} (give them mass, or make them rigid or prescribed)", .dofs.join(", "))]
    SingularMass {
        /// The massless DOFs.
        dofs: Vec<String>,
    },
    /// A non-finite value.
    #[error("non-finite {what} of {name} at t = {t}")]
    NonFinite {
        /// Which quantity.
        what: &'static str,
        /// Index (of the DOF, or of the element for an energy).
        index: usize,
        /// What that entry is ([`flexmb_model::Mechanism::dof_label`]), or
        /// the element at which an energy stopped being finite.
        name: String,
        /// Time.
        t: f64,
    },
    /// The static tangent is singular (buckling or a mechanism).
    #[error("singular static tangent at load factor {load_factor}: the structure buckles or a motion is unrestrained{}", culprit::listed("; the motion involves ", .unrestrained))]
    SingularTangent {
        /// Load factor reached.
        load_factor: f64,
        /// The degrees of freedom of the estimated null vectors of the
        /// tangent ([`null_space_dofs`]).
        unrestrained: Vec<String>,
        /// The failed factorization of the tangent over the free DOFs.
        #[source]
        source: flexmb_linalg::LuError,
    },
    /// Statics did not converge.
    #[error("static equilibrium not found beyond load factor {load_factor}: {cause}")]
    StaticNotConverged {
        /// Last converged load factor.
        load_factor: f64,
        /// The last failure.
        cause: String,
    },
    /// An element has flipped: its chord is turned by more than π/2 against
    /// one of its node frames ([`flexmb_element::Element::is_flipped`]), a
    /// spurious branch of its periodic deformation functions.
    #[error("element '{element}' has flipped at load factor {load_factor}: its chord is turned by {angle_deg:.1}° against its node frames (more than 90°), a state that satisfies the periodic deformation functions but is no deformation of the element; use more elements where the rotation is large, or more load steps")]
    Flipped {
        /// The element id.
        element: String,
        /// The angle between its chord and a node frame's x axis (degrees).
        angle_deg: f64,
        /// The load factor of the iterate.
        load_factor: f64,
    },
    /// Invalid argument.
    #[error("{0}")]
    Invalid(String),
    /// The integrator failed. `source` is its error as it reported it, to
    /// match on (e.g. [`OdeError::StepSizeTooSmall`](flexmb_ode::OdeError));
    /// `message` says the same with the state's components named after the
    /// mechanism's coordinates and, where there was one, the last evaluation
    /// that failed before it (the reason a step size underflowed).
    #[error("time integration failed: {message}")]
    Integration {
        /// The integrator's error.
        #[source]
        source: flexmb_ode::OdeError,
        /// The error in the mechanism's terms.
        message: String,
    },
    /// Stopped on request ([`StaticOptions::stop`]).
    #[error("stopped on request")]
    Interrupted,
}

impl DynamicsError {
    /// For an [`Integration`](Self::Integration) error that an evaluation of
    /// the equations of motion ended (the integrator's
    /// [`OdeError::Rhs`](flexmb_ode::OdeError::Rhs)): that evaluation's own
    /// error, typed (e.g. a [`Kinematics`](Self::Kinematics) failure with
    /// its [`KinematicsError`](flexmb_kinematics::KinematicsError)). `None` for other errors, and for an
    /// integration that ended for another reason (a step-size underflow).
    pub fn failed_evaluation(&self) -> Option<&DynamicsError> {
        match self {
            Self::Integration {
                source: flexmb_ode::OdeError::Rhs { source, .. },
                ..
            } => source.downcast_cause::<DynamicsError>(),
            _ => None,
        }
    }
}
