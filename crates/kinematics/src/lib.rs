//! Geometric transfer functions of a flexible mechanism (thesis (5.7), (6.5)):
//! x = F(q, u), ε = E(q, u) for the degrees of freedom q and the prescribed
//! inputs u, solved by Newton's method, and their derivatives:
//!
//! * first order: F,ξ and E,ξ (ξ = (q, u)) from one factorization of the
//!   Jacobian J of the constraint equations w.r.t. the dependent coordinates;
//! * second order: the convective terms (F,ξξ ξ̇)ξ̇ and (E,ξξ ξ̇)ξ̇ by one more
//!   solve with −D,xx\[ẋ, ẋ\] (thesis (5.8b), (6.6b));
//! * the contraction F,qqᵀ w + E,qqᵀ σ of the geometric stiffness (E.5e) by one
//!   adjoint solve with Jᵀ and element Hessians weighted by σ and the adjoint
//!   multipliers. No third-order tensor is ever formed.
//!
//! For one evaluation of the equations of motion, which needs only x, ẋ and
//! the convective terms, [`Kinematics::solve_chord`] keeps the factorization
//! of J from nearby configurations and [`Kinematics::velocities_refined`]
//! refines against the exact J, so J is factorized only now and then.
//!
//! The constraint equations are the rigid, degree-of-freedom and prescribed
//! deformations (including the Euler-parameter normalizations): D_c(x) = (0, q_ε, u_ε).
//!
//! ```
//! use flexmb_model::Scene;
//! use flexmb_kinematics::Kinematics;
//! use std::sync::Arc;
//! let scene = Scene::from_ron_str(r#"(
//!     dimension: Planar,
//!     materials: { "al": (e: 7.0e10, rho: 2700.0) },
//!     sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
//!     nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
//!     elements: [ (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))) ],
//!     fixed: [ Coord("A", Position) ],
//!     rigid: [ Def("arm", "*") ],
//! )"#).unwrap();
//! let mut k = Kinematics::new(Arc::new(scene.build(None).unwrap()));
//! // one DOF, the angle of node A: rotate the rigid arm to 90° in 15° steps
//! for step in 1..=6 {
//!     k.solve(&[step as f64 * 15f64.to_radians()], 0.0).unwrap();
//!     k.first_order(); // also enables the first-order predictor of the next solve
//! }
//! let b = &k.mechanism().node("B").unwrap().position;
//! assert!((k.x()[b[0]]).abs() < 1e-12 && (k.x()[b[1]] - 1.0).abs() < 1e-12);
//! ```
#![warn(missing_docs)]

mod acceleration;
mod caches;
mod configuration;
mod errors;
mod first_order;
mod jacobian_lu;
mod layout;
mod null_space;
mod position;
mod rates;
mod second_order;
mod sensitivity;
mod setup;
mod velocity;
mod workspace;

pub use null_space::null_vectors;

pub use errors::KinematicsError;
pub use first_order::FirstOrderView;
pub use position::NewtonOptions;

use caches::{ElementJacobians, Factorization, FirstOrderCache};
use configuration::Configuration;
use faer::Mat;
use flexmb_model::Mechanism;
use layout::Layout;
use position::Settings;
use rates::Rates;
use std::sync::Arc;
use workspace::Workspace;

/// Transfer functions and their derivatives for one mechanism; holds the
/// current configuration, its derivatives and all work buffers (allocated
/// once).
///
/// Its parts, one concern each, are crate-private types that document their
/// invariants: the fixed `Layout` of the mechanism's constraint rows, ξ
/// indices and maps into J (`layout.rs`); the `Settings` of the position
/// solve (`position.rs`); the `Configuration` (t, ξ, x, ε, the branch and
/// the last converged solution, `configuration.rs`); the derivative caches
/// with their validity flags (`ElementJacobians`, the `Factorization` of J,
/// the `FirstOrderCache` F,ξ and E,ξ, `caches.rs`); the `Rates`
/// (`rates.rs`); the `Counters`; and the `Workspace` of scratch buffers
/// (`workspace.rs`).
pub struct Kinematics {
    mech: Arc<Mechanism>,
    /// Fixed after construction.
    layout: Layout,
    /// Newton options and the stop flag, set by the caller.
    settings: Settings,
    /// t, ξ, x, ε of the last solve, the branch and the last good solution.
    config: Configuration,
    /// D,x of every element; `at_x` when of `config.x`.
    jac: ElementJacobians,
    /// The LU of J; `valid` when usable, `at_x` (implies `valid`) when of
    /// `config.x`.
    factorization: Factorization,
    /// F,ξ and E,ξ; `valid` when of `config.x`.
    first: FirstOrderCache,
    /// ξ̇, ẋ, ε̇, ẍ0, ε̈0, D,xx\[ẋ, ẋ\] of the last rate evaluations.
    rates: Rates,
    /// Newton iterations, factorizations, refinements, continuations.
    counters: Counters,
    /// Scratch buffers (content meaningless between calls but for the
    /// failure report's `target` and `last_update`).
    ws: Workspace,
}

/// Cost measures of the kinematics, for the reports and the benches.
#[derive(Clone, Copy, Debug, Default)]
struct Counters {
    /// Newton iterations of the last converged solve.
    iterations: usize,
    /// Factorizations of J so far.
    factorizations: u64,
    /// Iterative-refinement steps of velocity solves so far.
    refinements: u64,
    /// Solves so far that needed continuation from the last solution.
    continuations: u64,
}

impl Kinematics {
    /// The Newton settings of the position solve.
    pub fn newton_options(&self) -> NewtonOptions {
        self.settings.newton
    }

    /// Reads `stop` at every Newton iteration of the position solve, which
    /// then ends with [`KinematicsError::Interrupted`] when it is set: an
    /// implicit time step of a large model can spend a second in position
    /// solves of iterates far from the solution. `None` (the default) never
    /// stops.
    pub fn set_stop(&mut self, stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>) {
        self.settings.stop = stop;
    }

    /// Sets the Newton options.
    pub fn set_newton_options(&mut self, o: NewtonOptions) {
        self.settings.newton = o;
    }
    /// The mechanism.
    pub fn mechanism(&self) -> &Arc<Mechanism> {
        &self.mech
    }
    /// Number of degrees of freedom.
    pub fn n_q(&self) -> usize {
        self.layout.n_q
    }
    /// Number of prescribed inputs.
    pub fn n_u(&self) -> usize {
        self.layout.n_u
    }
    /// Nodal coordinates of the last solve.
    pub fn x(&self) -> &[f64] {
        &self.config.x
    }
    /// Deformations of the last solve.
    pub fn eps(&self) -> &[f64] {
        &self.config.eps
    }
    /// ξ = (q, u) of the last solve.
    pub fn xi(&self) -> &[f64] {
        &self.config.xi
    }
    /// Newton iterations of the last solve.
    pub fn iterations(&self) -> usize {
        self.counters.iterations
    }
    /// F,ξ (n_x × (n_q + n_u)) at the current configuration. Computed here
    /// ([`first_order`](Self::first_order)) if a solve or a new guess since
    /// the last one left it stale, so it is never of another configuration.
    pub fn f_xi(&mut self) -> &Mat<f64> {
        self.ensure_first_order();
        &self.first.f
    }
    /// E,ξ (n_ε × (n_q + n_u)) at the current configuration (see
    /// [`f_xi`](Self::f_xi)).
    pub fn e_xi(&mut self) -> &Mat<f64> {
        self.ensure_first_order();
        &self.first.e
    }
    /// The current state with F,ξ and E,ξ of the current configuration
    /// (computed first if stale, see [`f_xi`](Self::f_xi)), for reading them
    /// together with x, ε and the rates.
    pub fn first_order_view(&mut self) -> FirstOrderView<'_> {
        self.ensure_first_order();
        FirstOrderView {
            x: &self.config.x,
            eps: &self.config.eps,
            xd: &self.rates.xd,
            epsd: &self.rates.epsd,
            xdd0: &self.rates.xdd0,
            f: &self.first.f,
            e: &self.first.e,
        }
    }
    /// Whether F,ξ and E,ξ are of the current configuration (else the next
    /// read computes them).
    pub fn first_order_is_current(&self) -> bool {
        self.first.valid
    }
    fn ensure_first_order(&mut self) {
        if !self.first.valid {
            self.first_order();
        }
    }
    /// ẋ of the last [`velocities`](Self::velocities) call.
    pub fn xd(&self) -> &[f64] {
        &self.rates.xd
    }
    /// ε̇ of the last [`velocities`](Self::velocities) call.
    pub fn epsd(&self) -> &[f64] {
        &self.rates.epsd
    }
    /// ẍ for q̈ = 0: F,u ü + (F,ξξ ξ̇)ξ̇, after [`accelerations`](Self::accelerations).
    pub fn xdd0(&self) -> &[f64] {
        &self.rates.xdd0
    }
    /// ε̈ for q̈ = 0, after [`accelerations`](Self::accelerations).
    pub fn epsdd0(&self) -> &[f64] {
        &self.rates.epsdd0
    }
    /// D,xx\[ẋ, ẋ\] of every deformation, from the last
    /// [`convective_terms`](Self::convective_terms) call.
    pub fn convective(&self) -> &[f64] {
        &self.rates.dxx_vv
    }
    /// The local deformation Jacobian D,x of element `k` (row-major), at the last solve.
    pub fn element_jacobian(&self, k: usize) -> &[f64] {
        &self.jac.local[k]
    }

    /// Overrides the current configuration (e.g. a previously converged state)
    /// as the starting guess of the next solve.
    pub fn set_guess(&mut self, x: &[f64]) {
        self.config.x.copy_from_slice(x);
        self.config.solved = false;
        self.jac.at_x = false;
        self.factorization.at_x = false;
        self.first.valid = false;
    }

    /// The smallest over the largest pivot of the last LU factorization of
    /// the kinematic Jacobian J (with respect to the dependent
    /// coordinates), 0 when it failed: a measure of how well the dependent
    /// coordinates are determined, for watching it along a motion. It is of
    /// the configuration of the last factorization, which chord steps keep
    /// while they converge fast (within a step or so of the current one);
    /// reading it changes nothing. Its value depends on the units of the
    /// rows and columns: only its ratio to an earlier value means something.
    pub fn pivot_ratio(&self) -> f64 {
        if self.factorization.valid {
            self.factorization.lu.pivot_ratio
        } else {
            0.0
        }
    }

    /// The deformations of the last converged solve: the branch that
    /// periodic deformations (hinge angles over many turns) are continued
    /// from in the next solve.
    pub fn branch(&self) -> &[f64] {
        &self.config.branch
    }

    /// Continues periodic deformations from `eps` (the [`branch`](Self::branch)
    /// of another kinematics of the same scene, e.g. of the mechanism in
    /// another chart) in the next solve: a new kinematics would otherwise
    /// unwrap a hinge angle against zero, not against the turns it has made.
    pub fn set_branch(&mut self, eps: &[f64]) {
        self.config.branch.copy_from_slice(eps);
    }

    /// Factorizations of the kinematic Jacobian so far (a cost measure).
    pub fn factorizations(&self) -> u64 {
        self.counters.factorizations
    }

    /// Iterative-refinement steps of [`velocities_refined`](Self::velocities_refined)
    /// so far (each one product with J and one solve).
    pub fn refinements(&self) -> u64 {
        self.counters.refinements
    }

    /// Solves so far whose first Newton solve failed and that continued from
    /// the last solution in equal steps of ξ.
    pub fn continuations(&self) -> u64 {
        self.counters.continuations
    }

    /// `Ok` if every (name, length, needed) has its length, else the
    /// [`KinematicsError::Length`] of the first that does not.
    pub(crate) fn check_lengths(
        &self,
        args: &[(&'static str, usize, usize)],
    ) -> Result<(), KinematicsError> {
        match args.iter().find(|(_, got, expected)| got != expected) {
            None => Ok(()),
            Some(&(what, got, expected)) => Err(KinematicsError::Length {
                what,
                expected,
                got,
            }),
        }
    }
}
