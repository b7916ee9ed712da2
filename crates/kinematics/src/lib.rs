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
mod errors;
mod first_order;
mod jacobian_lu;
mod null_space;
mod position;
mod second_order;
mod sensitivity;
mod setup;
mod velocity;

use jacobian_lu::JacobianLu;
pub use null_space::null_vectors;

pub use errors::KinematicsError;
pub use first_order::FirstOrderView;
pub use position::NewtonOptions;

use faer::Mat;
use flexmb_model::Mechanism;
use std::sync::Arc;

struct ElemMap {
    /// local deformation → constraint row
    rows: Vec<Option<usize>>,
    /// local coordinate → dependent column
    cols: Vec<Option<usize>>,
    nx: usize,
    ne: usize,
}

/// An entry ∂D_r/∂x_i of a constraint row r with respect to a nodal
/// coordinate x_i in ξ (ξ index `col`): position `local` in the element
/// Jacobian of `element`.
struct XiEntry {
    row: usize,
    col: usize,
    element: usize,
    local: usize,
}

/// Transfer functions and their derivatives for one mechanism; holds the
/// current configuration and all work buffers (allocated once).
pub struct Kinematics {
    mech: Arc<Mechanism>,
    /// A stop request read at every Newton iteration of the position
    /// solve ([`set_stop`](Self::set_stop)).
    stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    opts: NewtonOptions,
    maps: Vec<ElemMap>,
    /// global row of each deformation (if it is an equation)
    row_of: Vec<Option<usize>>,
    /// ξ index of each coordinate: nodal coordinate → Some(k), deformation → Some(k)
    xi_of_x: Vec<Option<usize>>,
    xi_of_e: Vec<Option<usize>>,
    /// The entries of D_c,x_ξ, the nodal columns of the right-hand side B of
    /// (5.8a), element by element (products with directions of ξ).
    xi_entries: Vec<XiEntry>,
    /// The rows of J element by element, as (constraint row, (element, range
    /// of `dep_entries`)), with `dep_entries` (dependent column, position in
    /// the element Jacobian): products J v at the current x.
    dep_rows: Vec<(usize, (usize, std::ops::Range<usize>))>,
    dep_entries: Vec<(usize, usize)>,
    length_scale: f64,
    n_q: usize,
    n_u: usize,
    // state
    t: f64,
    xi: Vec<f64>,
    xi_prev: Vec<f64>,
    x: Vec<f64>,
    eps: Vec<f64>,
    prev_eps: Vec<f64>,
    jac_local: Vec<Vec<f64>>,
    /// The element Jacobians are of the current x (the last element
    /// evaluation computed them).
    jac_at_x: bool,
    /// LU of J (sparse, or dense when small); `jpos[k][a·n_x,e + c]` is the position of element k's
    /// local entry (a, c) in its values (`NO_ENTRY` when not in J).
    lu: JacobianLu,
    jpos: Vec<Vec<usize>>,
    /// (element, local index) of the deformations that are not constraint rows.
    free_deformations: Vec<(usize, usize)>,
    f: Mat<f64>,
    e: Mat<f64>,
    first_order_valid: bool,
    have_solution: bool,
    // velocity level
    xid: Vec<f64>,
    /// A direction of ξ (q̈ and ü, or a direction of q) for the solves
    /// along one.
    xi_dir: Vec<f64>,
    /// The right-hand sides of a block of directions
    /// ([`transfer_matrix`](Kinematics::transfer_matrix)).
    block: Mat<f64>,
    xd: Vec<f64>,
    epsd: Vec<f64>,
    // acceleration level
    xdd0: Vec<f64>,
    epsdd0: Vec<f64>,
    // scratch
    rhs: Mat<f64>,
    work: Vec<f64>,
    target: Vec<f64>,
    iterations: usize,
    x_good: Vec<f64>,
    /// The first-order prediction of the current solve, for the branch
    /// guard (`branch_jump` in position.rs).
    x_predicted: Vec<f64>,
    xi_good: Vec<f64>,
    /// The target ξ = (q, u) of the current solve.
    xi_target: Vec<f64>,
    lu_valid: bool,
    /// The factorization of J is of the current x (not of an earlier one).
    lu_at_x: bool,
    /// Factorizations of J so far.
    factorizations: u64,
    /// Iterative-refinement steps of velocity solves so far.
    refinements: u64,
    /// Refinement steps beyond the first since the last factorization.
    extra_refinements: usize,
    /// Solves that needed continuation from the last solution.
    continuations: u64,
    dx: Vec<f64>,
    rhs_vec: Vec<f64>,
    last_update: Vec<f64>,
    /// D,xx\[ẋ, ẋ\] of every deformation, after [`convective_terms`](Kinematics::convective_terms).
    dxx_vv: Vec<f64>,
    /// Right-hand side and residual of the refined velocity solve.
    vel_rhs: Vec<f64>,
    vel_res: Vec<f64>,
}

/// Marks a local Jacobian entry that is not part of J.
const NO_ENTRY: usize = usize::MAX;

impl Kinematics {
    /// The Newton settings of the position solve.
    pub fn newton_options(&self) -> NewtonOptions {
        self.opts
    }

    /// Reads `stop` at every Newton iteration of the position solve, which
    /// then ends with [`KinematicsError::Interrupted`] when it is set: an
    /// implicit time step of a large model can spend a second in position
    /// solves of iterates far from the solution. `None` (the default) never
    /// stops.
    pub fn set_stop(&mut self, stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>) {
        self.stop = stop;
    }

    /// Sets the Newton options.
    pub fn set_newton_options(&mut self, o: NewtonOptions) {
        self.opts = o;
    }
    /// The mechanism.
    pub fn mechanism(&self) -> &Arc<Mechanism> {
        &self.mech
    }
    /// Number of degrees of freedom.
    pub fn n_q(&self) -> usize {
        self.n_q
    }
    /// Number of prescribed inputs.
    pub fn n_u(&self) -> usize {
        self.n_u
    }
    /// Nodal coordinates of the last solve.
    pub fn x(&self) -> &[f64] {
        &self.x
    }
    /// Deformations of the last solve.
    pub fn eps(&self) -> &[f64] {
        &self.eps
    }
    /// ξ = (q, u) of the last solve.
    pub fn xi(&self) -> &[f64] {
        &self.xi
    }
    /// Newton iterations of the last solve.
    pub fn iterations(&self) -> usize {
        self.iterations
    }
    /// F,ξ (n_x × (n_q + n_u)) at the current configuration. Computed here
    /// ([`first_order`](Self::first_order)) if a solve or a new guess since
    /// the last one left it stale, so it is never of another configuration.
    pub fn f_xi(&mut self) -> &Mat<f64> {
        self.ensure_first_order();
        &self.f
    }
    /// E,ξ (n_ε × (n_q + n_u)) at the current configuration (see
    /// [`f_xi`](Self::f_xi)).
    pub fn e_xi(&mut self) -> &Mat<f64> {
        self.ensure_first_order();
        &self.e
    }
    /// The current state with F,ξ and E,ξ of the current configuration
    /// (computed first if stale, see [`f_xi`](Self::f_xi)), for reading them
    /// together with x, ε and the rates.
    pub fn first_order_view(&mut self) -> FirstOrderView<'_> {
        self.ensure_first_order();
        FirstOrderView {
            x: &self.x,
            eps: &self.eps,
            xd: &self.xd,
            epsd: &self.epsd,
            xdd0: &self.xdd0,
            f: &self.f,
            e: &self.e,
        }
    }
    /// Whether F,ξ and E,ξ are of the current configuration (else the next
    /// read computes them).
    pub fn first_order_is_current(&self) -> bool {
        self.first_order_valid
    }
    fn ensure_first_order(&mut self) {
        if !self.first_order_valid {
            self.first_order();
        }
    }
    /// ẋ of the last [`velocities`](Self::velocities) call.
    pub fn xd(&self) -> &[f64] {
        &self.xd
    }
    /// ε̇ of the last [`velocities`](Self::velocities) call.
    pub fn epsd(&self) -> &[f64] {
        &self.epsd
    }
    /// ẍ for q̈ = 0: F,u ü + (F,ξξ ξ̇)ξ̇, after [`accelerations`](Self::accelerations).
    pub fn xdd0(&self) -> &[f64] {
        &self.xdd0
    }
    /// ε̈ for q̈ = 0, after [`accelerations`](Self::accelerations).
    pub fn epsdd0(&self) -> &[f64] {
        &self.epsdd0
    }
    /// D,xx\[ẋ, ẋ\] of every deformation, from the last
    /// [`convective_terms`](Self::convective_terms) call.
    pub fn convective(&self) -> &[f64] {
        &self.dxx_vv
    }
    /// The local deformation Jacobian D,x of element `k` (row-major), at the last solve.
    pub fn element_jacobian(&self, k: usize) -> &[f64] {
        &self.jac_local[k]
    }

    /// Overrides the current configuration (e.g. a previously converged state)
    /// as the starting guess of the next solve.
    pub fn set_guess(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
        self.jac_at_x = false;
        self.have_solution = false;
        self.lu_at_x = false;
        self.first_order_valid = false;
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
        if self.lu_valid {
            self.lu.pivot_ratio
        } else {
            0.0
        }
    }

    /// The deformations of the last converged solve: the branch that
    /// periodic deformations (hinge angles over many turns) are continued
    /// from in the next solve.
    pub fn branch(&self) -> &[f64] {
        &self.prev_eps
    }

    /// Continues periodic deformations from `eps` (the [`branch`](Self::branch)
    /// of another kinematics of the same scene, e.g. of the mechanism in
    /// another chart) in the next solve: a new kinematics would otherwise
    /// unwrap a hinge angle against zero, not against the turns it has made.
    pub fn set_branch(&mut self, eps: &[f64]) {
        self.prev_eps.copy_from_slice(eps);
    }

    /// Factorizations of the kinematic Jacobian so far (a cost measure).
    pub fn factorizations(&self) -> u64 {
        self.factorizations
    }

    /// Iterative-refinement steps of [`velocities_refined`](Self::velocities_refined)
    /// so far (each one product with J and one solve).
    pub fn refinements(&self) -> u64 {
        self.refinements
    }

    /// Solves so far whose first Newton solve failed and that continued from
    /// the last solution in equal steps of ξ.
    pub fn continuations(&self) -> u64 {
        self.continuations
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
