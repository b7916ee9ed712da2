//! # flexmb
//!
//! Flexible multibody dynamics and model reduction for large-stroke compliant
//! mechanisms, after S.E. Boer's thesis *Model reduction for flexible
//! multibody systems* (equation numbers refer to it). This crate is the front
//! door: it re-exports each layer as a module and the commonly used types in
//! [`prelude`]; the layers are separate crates, usable on their own.
//!
//! ## The workflow
//!
//! A scene (RON text or file, [`model::Scene`]) becomes a mechanism with its
//! degrees of freedom chosen; its equations of motion ([`dynamics::Dynamics`])
//! give static equilibria, rest linearizations with eigenfrequencies and time
//! responses; a reduced model ([`reduction::ReducedModel`]) constrains the
//! degrees of freedom to q = G(z) and is studied through the same interface,
//! [`MechanicalModel`](reduction::MechanicalModel):
//!
//! ```
//! use flexmb::prelude::*;
//! use std::sync::Arc;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // scene → mechanism: the planar straight guidance of thesis §5.4
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/scenes/straight_guidance_planar.ron");
//! let scene = Scene::load(std::path::Path::new(path))?;
//! let mech = Arc::new(scene.build(None)?);
//!
//! // mechanism → equilibrium → eigenfrequencies, all degrees of freedom
//! let mut full = Dynamics::new(mech.clone());
//! let eq = full.equilibrium_under_loads(0.0)?;
//! let f_full = full.eigenfrequencies(0.0, &eq.coordinates, 3)?;
//!
//! // reduce: the three lowest modes at the equilibrium (MODAL-3)
//! let basis = modal_basis(&mech, 0.0, &eq.coordinates, 3, None)?;
//! let mut reduced = ReducedModel::new(mech.clone(), Box::new(basis))?;
//! let f_red = reduced.eigenfrequencies(0.0, &reduced.reference_coordinates(), 3)?;
//! for (r, f) in f_red.iter().zip(&f_full) {
//!     assert!((r / f - 1.0).abs() < 1e-8); // a modal basis keeps its modes' frequencies
//! }
//!
//! // simulate: one study for both models, through the one interface
//! fn response(m: &mut dyn MechanicalModel) -> Result<ModelTrajectory, ReductionError> {
//!     let c0 = m.reference_coordinates();
//!     let cd0 = vec![0.0; c0.len()];
//!     let opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 0.1, 11);
//!     m.simulate(0.0, &c0, &cd0, &opts, &mut |_, _, _| Control::Continue)
//! }
//! let unreduced = response(&mut Dynamics::new(mech.clone()))?;
//! let modal = response(&mut reduced)?;
//! // the reduced model needs far fewer evaluations for its slow modes
//! assert!(modal.full.stats.rhs_evals < unreduced.full.stats.rhs_evals);
//! # Ok(())
//! # }
//! ```
//!
//! ## The layers
//!
//! From the bottom: [`dual`] numbers and [`rotation`]s (Euler parameters);
//! the [`element`] library and the [`superelement`] builder (FE matrices →
//! S̄, M̄); the [`linalg`] kernels, the integrators of [`ode`] and the strict
//! [`input`] readers; scenes and mechanisms ([`model`]); transfer functions
//! ([`kinematics`]); equations of motion, statics and simulation
//! ([`dynamics`]); eigen-analyses and sweeps ([`linearize`]); system model
//! reduction ([`reduction`]); SVG plots and CSV tables ([`plot`]). The
//! command line `flexmb` (package `flexmb-cli`) and `cargo xtask reproduce`
//! are built on the same crates.
//!
//! ## Examples
//!
//! `crates/flexmb/examples/`, each checking its own result and run in CI
//! (`cargo run --release -p flexmb --example NAME`):
//!
//! * `pendulum`: a pendulum from a scene string, its period against the
//!   exact large-amplitude period;
//! * `guidance_sweep`: the eigenfrequencies of the spatial straight guidance
//!   (thesis §6.4) along its load, against `fixtures/curves/ch6`;
//! * `reduce_and_simulate`: an SVD-modal reduced model against the
//!   unreduced response;
//! * `superelement_from_fe`: a superelement built from FE matrices
//!   assembled in code, its frequencies against the FE model's own;
//! * `custom_basis`: a reduction basis of one's own through
//!   [`Basis`](reduction::Basis);
//! * `custom_element`: an element written outside the element crate
//!   ([`element::DeformationKernel`], [`element::Element::custom`]), placed
//!   in a mechanism built from a scene, its statics and eigenfrequencies
//!   against the analytic values.
#![warn(missing_docs)]

/// The dense and sparse matrices of the system level (faer), as in
/// [`Basis`](reduction::Basis) and the linearizations.
pub use faer;
pub use flexmb_draw as draw;
pub use flexmb_dual as dual;
pub use flexmb_dynamics as dynamics;
pub use flexmb_element as element;
pub use flexmb_input as input;
pub use flexmb_kinematics as kinematics;
pub use flexmb_linalg as linalg;
pub use flexmb_linearize as linearize;
pub use flexmb_model as model;
pub use flexmb_ode as ode;
pub use flexmb_plot as plot;
pub use flexmb_reduction as reduction;
pub use flexmb_rotation as rotation;
pub use flexmb_superelement as superelement;
/// nalgebra, for the small fixed-size matrices of element code (an
/// element's stiffness and mass in [`element::Element::custom`]).
pub use nalgebra;

/// The commonly used types of the layers: scenes and mechanisms, the
/// equations of motion and their options, eigen-analyses, and reduced models
/// with the one model interface [`MechanicalModel`](crate::reduction::MechanicalModel).
pub mod prelude {
    pub use flexmb_dynamics::{
        Control, Dynamics, DynamicsError, Integrator, Linearization, OutputTable,
        SimulationOptions, StaticOptions, StaticSolution, Trajectory,
    };
    pub use flexmb_element::{Element, Material};
    pub use flexmb_linearize::{
        damped_modes, undamped_modes, LinearizeError, SweepOptions, SweepParameter,
    };
    pub use flexmb_model::{Mechanism, ModelError, Scene};
    pub use flexmb_reduction::{
        modal_basis, svd_modal_basis, Basis, Equilibrium, FixedBasis, InterpolatedBasis,
        MechanicalModel, ModelTrajectory, ReducedModel, ReductionError, SavedModel,
    };
}
