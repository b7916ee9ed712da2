//! The flexmb element library: non-linear finite elements for flexible
//! multibody systems in the generalized-strain tradition (thesis "Model
//! reduction for flexible multibody systems"; equation numbers refer to it).
//!
//! Every [`Element`] has nodal-coordinate [`Slot`]s (positions, orientations as
//! Euler parameters or planar angles, superelement mode amplitudes) and named
//! deformations ε = D(x) that are invariant under rigid motion. It provides
//! * ε, D,x, the directional second derivative D,xx\[a, b\] (convective terms) and
//!   the weighted Hessian Σ wᵢ Dᵢ,xx (geometric stiffness), all exact: the
//!   deformation functions are written once over a [`flexmb_dual::Real`] scalar
//!   and differentiated with dual numbers;
//! * the stress σ = Sε + Dε̇ + σ0 (E.2) with S from beam theory or S = AᵀS̄A (3.20);
//! * inertia: the mass matrix, the inertia force M ẍ + h (2.40a)/(3.34) and its
//!   exact derivatives with respect to x and ẋ, through one co-rotational code
//!   path (2.34) shared by spatial beams, superelements and rigid bodies.
//!
//! Elements: planar beam (5.3), planar truss, planar hinge (5.5), planar mass,
//! spatial beam (6.2) (optionally with Vlasov warping, one coordinate per end), spatial truss, spatial hinge, point mass, rigid body,
//! two-node superelement (chapters 2–3) and the Euler-parameter normalization.
//!
//! Your own element: implement [`DeformationKernel`] (ε = D(x) once over
//! [`flexmb_dual::Real`]) and build it with [`Element::custom`]; its exact
//! derivatives follow as for the built-ins, and
//! `flexmb_model::Scene::build_with_elements` places it in a mechanism (see
//! `docs/elements.md`, "Writing your own element", and
//! `crates/flexmb/examples/custom_element.rs`). Built-in elements stay statically dispatched.
//!
//! ```
//! use flexmb_element::{BeamOptions, Element, Material, SectionShape};
//! let steel = Material::from_poisson(2.1e11, 0.3, 7800.0);
//! let shape = SectionShape::Rectangle { by: 0.03, bz: 0.001 };
//! let beam = Element::beam([0.0; 3], [0.2, 0.0, 0.0], [0.0, 1.0, 0.0], &steel, &shape,
//!                          &BeamOptions::default()).unwrap();
//! // undeformed: x = (rp, λp, rq, λq) with identity orientations
//! let x = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.2, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
//! let mut eps = [0.0; 6];
//! let mut jac = [0.0; 6 * 14];
//! beam.deformations_and_jacobian(&x, None, &mut eps, &mut jac);
//! assert!(eps.iter().all(|e| e.abs() < 1e-15));
//! assert!((jac[7] - 1.0).abs() < 1e-15); // ∂ε1/∂x_q = 1: elongation
//! ```
#![warn(missing_docs)]

mod anticlastic;
mod beam_matrices;
mod custom;
mod element;
pub mod fe_faces;
mod inertia;
mod initial_orientation;
mod kernels;
mod kinetic;
mod section;
mod superelement;
mod warping;

pub use anticlastic::{anticlastic_overlay, ANTICLASTIC_NAMES, ANTICLASTIC_TYPE};
pub use beam_matrices::{
    equivalent_stiffness, planar_beam_m_bar, planar_beam_s_bar, shear_parameter, spatial_a_diag,
    spatial_beam_m_bar, spatial_beam_s_bar,
};
pub use custom::MAX_ELEMENT_COORDS;
pub use element::{frame_from_axis, BeamOptions, Element, Slot, FLIP_ANGLE};
pub use inertia::{VelocityTransform, MAX_MODES};
pub use kernels::DeformationKernel;
pub use kinetic::KineticEnergyKernel;
pub use section::{
    rectangle_torsion_constant, rectangle_warping_constant, Material, SectionProperties,
    SectionShape,
};
pub use superelement::{FeCell, FeMesh, LinearSuperelement, ModeKind, Provenance, Side};
pub use warping::{torsion_warping_block, warping_mass_block};

/// Errors of element construction. Messages name the property and what would fix it.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ElementError {
    /// A material or section property is out of range.
    #[error("invalid {what} = {value}: {why}")]
    InvalidProperty {
        /// The property.
        what: String,
        /// Its value.
        value: f64,
        /// Why it is invalid.
        why: String,
    },
    /// A property the element needs is not given.
    #[error("missing {what}: {why}")]
    MissingProperty {
        /// The property.
        what: String,
        /// Why it is needed, and how to give it.
        why: String,
    },
    /// Degenerate element geometry.
    #[error("invalid element geometry: {0}")]
    Geometry(String),
    /// Inconsistent superelement data.
    #[error("invalid superelement data: {0}")]
    Superelement(String),
    /// A custom element with more coordinates or deformations than the
    /// per-element buffers hold ([`MAX_ELEMENT_COORDS`]).
    #[error("custom element '{element}' has {n} {what}, more than the {max} (MAX_ELEMENT_COORDS, the size of the largest built-in element) one element may have; split it into smaller elements")]
    TooLarge {
        /// The element's type name.
        element: String,
        /// "nodal coordinates" or "deformations".
        what: &'static str,
        /// How many it has.
        n: usize,
        /// The limit, [`MAX_ELEMENT_COORDS`].
        max: usize,
    },
}
