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

mod jacobian_lu;
mod null_space;

use jacobian_lu::{JacobianLu, DENSE_UP_TO};
pub use null_space::null_vectors;

use faer::Mat;
use flexmb_model::{Coordinate, ERole, Mechanism, XRole};
use std::sync::Arc;

/// A read-only view of the kinematic state whose F,ξ and E,ξ are of its
/// configuration ([`Kinematics::first_order_view`]). The rates are those of
/// the last [`Kinematics::velocities`] and [`Kinematics::accelerations`].
#[derive(Clone, Copy, Debug)]
pub struct FirstOrderView<'a> {
    /// Nodal coordinates x.
    pub x: &'a [f64],
    /// Deformations ε.
    pub eps: &'a [f64],
    /// ẋ.
    pub xd: &'a [f64],
    /// ε̇.
    pub epsd: &'a [f64],
    /// ẍ for q̈ = 0.
    pub xdd0: &'a [f64],
    /// F,ξ (n_x × (n_q + n_u)).
    pub f: &'a Mat<f64>,
    /// E,ξ (n_ε × (n_q + n_u)).
    pub e: &'a Mat<f64>,
}

/// A residual within this many ε·max|x| is at the rounding level of the
/// coordinates it is computed from (a difference of two coordinates of size
/// |x| carries an error of a few ε|x|; a deformation sums a few of them).
const ROUNDING_RESIDUALS: f64 = 64.0;

/// Newton settings of the position solve.
#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    /// Converged when every constraint residual |D_c(x) − target| ≤ `tol`·L,
    /// L the mean element length (residuals are lengths or dimensionless), or
    /// when the Newton update is at rounding level (≤ 8 ε max|x|) with the
    /// residual below 1000·`tol`·L or at the rounding level of the
    /// coordinates (64 ε max|x|, x the dependent coordinates, at least 1).
    pub tol: f64,
    /// Iteration limit.
    pub max_iterations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tol: 1e-12,
            max_iterations: 30,
        }
    }
}

/// Kinematics failures, naming the coordinates involved.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum KinematicsError {
    /// The stop request given to [`Kinematics::set_stop`] was set during a
    /// position solve.
    #[error("stopped on request")]
    Interrupted,
    /// Newton did not converge.
    #[error("the position solve did not converge in {iterations} iterations (residual {residual:.3e}); largest residuals: {equations:?}; largest last updates: {coordinates:?}. {hint}")]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Final max-norm residual.
        residual: f64,
        /// Equations with the largest residuals (name = value).
        equations: Vec<String>,
        /// Dependent coordinates with the largest last updates.
        coordinates: Vec<String>,
        /// What may have caused it (a prescribed motion only where there is one).
        hint: String,
    },
    /// The Jacobian of the constraints is singular at this configuration.
    #[error("singular kinematics at this configuration (pivot ratio {pivot_ratio:.1e}): the dependent coordinates {coordinates:?} are not determined by the equations: a singular position of the mechanism (e.g. a straightened toggle), a lost constraint, or a starting guess far from the solution (take smaller steps)")]
    Singular {
        /// Smallest/largest pivot.
        pivot_ratio: f64,
        /// Coordinates in the null space.
        coordinates: Vec<String>,
    },
    /// The dependent Euler parameter of a node with the other three as DOFs
    /// approaches zero: the parametrization is singular there.
    #[error("node {node}: its Euler parameter {coordinate} = {value:.3}, made dependent by the normalization, approaches zero (the node is turned near 180° from where that chart was chosen, where the chart is singular): simulations, static solves and sweeps switch charts after each step or load increment (flexmb_model::EulerChart), so one step or increment turned the node too far (in statics: use more load steps); a reduced model switches only the charts whose Euler parameters its basis keeps as reduced coordinates (the large coordinates of a modal basis): keep the node's orientation coordinates large, keep the node within ±180° of its reference, or give the rotation to a hinge deformation")]
    EulerParameterDegenerate {
        /// The node.
        node: String,
        /// The coordinate.
        coordinate: String,
        /// Its value.
        value: f64,
    },
    /// An input slice of the wrong length (a caller's error).
    #[error("{what} has {got} entries, but this mechanism has {expected}")]
    Length {
        /// Which input.
        what: &'static str,
        /// The length this mechanism needs.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// Non-finite input.
    #[error("non-finite value in {what}: {name}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Index.
        index: usize,
        /// What that entry is, e.g. `DOF q3 = S.x (node S)`.
        name: String,
    },
}

struct ElemMap {
    /// local deformation → constraint row
    rows: Vec<Option<usize>>,
    /// local coordinate → dependent column
    cols: Vec<Option<usize>>,
    nx: usize,
    ne: usize,
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

/// When the position solve factorizes the kinematic Jacobian at the
/// converged configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Refactor {
    /// Always (F,ξ and every other derivative solve need J there).
    AtSolution,
    /// Only when chord steps converge slowly: the factorization may be of a
    /// nearby configuration, for solves that refine against the exact J.
    WhenSlow,
}

/// Iterative-refinement steps of a velocity solve with a factorization of
/// a nearby configuration before J is factorized afresh at x. Each step costs
/// a product with J and a solve, a few microseconds for the 77 × 77 Jacobian
/// of the spatial guidance against about 12 µs for a factorization.
const MAX_REFINEMENTS: usize = 3;

/// Relative accuracy of a refined velocity solve (the error left in ẋ), at
/// the level of a direct solve's rounding. 1e-12 saved refinement steps but
/// measured no faster over a response from equilibrium.
const REFINED_TOL: f64 = 1e-14;

/// Refinement steps beyond the first, summed since the last factorization,
/// after which J is factorized afresh at x for the next solves although the
/// refinement converged: a factorization then costs about what the extra
/// steps did (ski-rental rule). Measured on the spatial guidance: along the
/// first 2 ms from rest (`cargo bench -p flexmb-dynamics --bench eom`) a
/// refresh after every two-step solve beat never refreshing by 14 %, while
/// over 0.05 s of the response from equilibrium it factorized at 43 % of
/// the evaluations and was 10–15 % slower than this budget of six, which
/// factorizes at 15 % of them (the machine's noise is ±10 %).
const REFRESH_BUDGET: usize = 6;

/// Marks a local Jacobian entry that is not part of J.
const NO_ENTRY: usize = usize::MAX;

impl Kinematics {
    /// Prepares the kinematics of a mechanism, starting from its reference
    /// configuration. The kinematic Jacobian is factorized densely up to 200
    /// rows and sparsely above.
    pub fn new(mech: Arc<Mechanism>) -> Self {
        Self::with_dense_limit(mech, DENSE_UP_TO)
    }

    /// As [`new`](Self::new), with the kinematic Jacobian factorized densely
    /// only when it has at most `dense_up_to` rows (sparse otherwise).
    pub fn with_dense_limit(mech: Arc<Mechanism>, dense_up_to: usize) -> Self {
        faer::set_global_parallelism(faer::Par::Seq);
        let n_x = mech.n_x();
        let n_eps = mech.n_eps();
        let n_c = mech.constraint_rows.len();
        let mut row_of = vec![None; n_eps];
        for (r, j) in mech.constraint_rows.iter().enumerate() {
            row_of[*j] = Some(r);
        }
        let n_q = mech.n_dof();
        let n_u = mech.inputs.len();
        let mut xi_of_x = vec![None; n_x];
        let mut xi_of_e = vec![None; n_eps];
        for (k, c) in mech.dofs.iter().enumerate() {
            match c {
                Coordinate::Node(i) => xi_of_x[*i] = Some(k),
                Coordinate::Def(j) => xi_of_e[*j] = Some(k),
            }
        }
        for (k, inp) in mech.inputs.iter().enumerate() {
            match inp.target {
                Coordinate::Node(i) => xi_of_x[i] = Some(n_q + k),
                Coordinate::Def(j) => xi_of_e[j] = Some(n_q + k),
            }
        }
        let maps: Vec<ElemMap> = mech
            .elements
            .iter()
            .map(|e| {
                let ne = e.element.n_eps();
                ElemMap {
                    rows: (0..ne).map(|k| row_of[e.eps_offset + k]).collect(),
                    cols: e
                        .x_index
                        .iter()
                        .map(|i| match mech.x_roles[*i] {
                            XRole::Dependent(k) => Some(k),
                            _ => None,
                        })
                        .collect(),
                    nx: e.element.n_x(),
                    ne,
                }
            })
            .collect();
        let length_scale = characteristic_length(&mech);
        let jac_local = mech
            .elements
            .iter()
            .map(|e| vec![0.0; e.element.n_eps() * e.element.n_x()])
            .collect();
        let n_xi = n_q + n_u;
        let (lu, jpos) = jacobian_pattern(&maps, n_c, dense_up_to);
        let free_deformations = mech
            .elements
            .iter()
            .enumerate()
            .flat_map(|(k, e)| (0..maps[k].ne).map(move |a| (k, a, e.eps_offset + a)))
            .filter(|&(_, _, j)| row_of[j].is_none())
            .map(|(k, a, _)| (k, a))
            .collect();
        let mut s = Self {
            opts: NewtonOptions::default(),
            stop: None,
            maps,
            row_of,
            xi_of_x,
            xi_of_e,
            length_scale,
            n_q,
            n_u,
            t: 0.0,
            xi: vec![0.0; n_xi],
            xi_prev: vec![0.0; n_xi],
            x: mech.x0.clone(),
            eps: vec![0.0; n_eps],
            prev_eps: vec![0.0; n_eps],
            jac_local,
            lu,
            jpos,
            free_deformations,
            f: Mat::zeros(n_x, n_xi),
            e: Mat::zeros(n_eps, n_xi),
            first_order_valid: false,
            have_solution: false,
            xid: vec![0.0; n_xi],
            xd: vec![0.0; n_x],
            epsd: vec![0.0; n_eps],
            xdd0: vec![0.0; n_x],
            epsdd0: vec![0.0; n_eps],
            rhs: Mat::zeros(n_c, n_xi),
            work: vec![0.0; n_c.max(n_x)],
            target: vec![0.0; n_c],
            iterations: 0,
            x_good: mech.x0.clone(),
            xi_good: vec![0.0; n_xi],
            xi_target: vec![0.0; n_xi],
            lu_valid: false,
            lu_at_x: false,
            factorizations: 0,
            refinements: 0,
            extra_refinements: 0,
            continuations: 0,
            dx: vec![0.0; n_c],
            rhs_vec: vec![0.0; n_c],
            last_update: vec![0.0; n_c],
            dxx_vv: vec![0.0; n_eps],
            vel_rhs: vec![0.0; n_c],
            vel_res: vec![0.0; n_c],
            mech,
        };
        s.xi[..n_q].copy_from_slice(&s.mech.q0());
        s.xi_good.copy_from_slice(&s.xi);
        s
    }

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
        self.have_solution = false;
        self.lu_at_x = false;
        self.first_order_valid = false;
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

    fn eval_elements(&mut self, with_jac: bool) {
        let mech = &self.mech;
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (k, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[k];
            if m.ne == 0 {
                continue;
            }
            for (c, gi) in e.x_index.iter().enumerate() {
                xl[c] = self.x[*gi];
            }
            let o = e.eps_offset;
            let prev = &self.prev_eps[o..o + m.ne];
            let out = &mut self.eps[o..o + m.ne];
            if with_jac {
                e.element.deformations_and_jacobian(
                    &xl[..m.nx],
                    Some(prev),
                    out,
                    &mut self.jac_local[k],
                );
            } else {
                e.element.deformations(&xl[..m.nx], Some(prev), out);
            }
        }
    }

    /// Fails when a node's only dependent Euler parameter nears zero.
    fn check_euler_parameters(&self) -> Result<(), KinematicsError> {
        for n in &self.mech.nodes {
            let Some(o) = &n.orientation else { continue };
            if o.len() != 4 {
                continue;
            }
            let deps: Vec<usize> = o
                .iter()
                .copied()
                .filter(|i| matches!(self.mech.x_roles[*i], XRole::Dependent(_)))
                .collect();
            let dofs = o
                .iter()
                .filter(|i| matches!(self.mech.x_roles[**i], XRole::Dof(_)))
                .count();
            if deps.len() == 1 && dofs == 3 && self.x[deps[0]].abs() < 0.05 {
                return Err(KinematicsError::EulerParameterDegenerate {
                    node: n.id.clone(),
                    coordinate: self.mech.x_names[deps[0]].clone(),
                    value: self.x[deps[0]],
                });
            }
        }
        Ok(())
    }

    fn residual_norm(&self) -> f64 {
        self.mech
            .constraint_rows
            .iter()
            .enumerate()
            .map(|(r, j)| (self.eps[*j] - self.target[r]).abs())
            .fold(0.0f64, f64::max)
    }

    /// Scatters the element Jacobians into the values of J.
    fn assemble_jacobian(&mut self) {
        let values = self.lu.values_mut();
        values.fill(0.0);
        for (jl, pos) in self.jac_local.iter().zip(&self.jpos) {
            for (v, &p) in jl.iter().zip(pos) {
                if p != NO_ENTRY {
                    values[p] += v;
                }
            }
        }
    }

    /// The error for a singular J, naming the dependent coordinates it
    /// leaves undetermined. A failed factorization is often recoverable (an
    /// iterate far from the solution; the integrator retries with a smaller
    /// step), so this must stay cheap: the null vector by a dense SVD only
    /// for a Jacobian small enough to be factorized densely (at most
    /// `DENSE_UP_TO` rows, milliseconds); for a large one the coordinate of
    /// the sparse factorization's smallest pivot (the SVD of the 1680 × 1680
    /// J of the 1440-DOF flexure chain took 4 s, at every failed iterate of
    /// a time step).
    fn singular_error(&self) -> KinematicsError {
        let n = self.mech.dependent.len();
        let names = if n <= DENSE_UP_TO {
            self.null_space_names()
        } else {
            self.lu
                .smallest_pivot_column()
                .map(|c| vec![self.mech.x_names[self.mech.dependent[c]].clone()])
                .unwrap_or_default()
        };
        KinematicsError::Singular {
            pivot_ratio: self.lu.pivot_ratio,
            coordinates: names,
        }
    }

    /// The dependent coordinates with a large share in J's null vector (its
    /// smallest singular value's right singular vector).
    fn null_space_names(&self) -> Vec<String> {
        let mut names = vec![];
        if let Ok(svd) = flexmb_linalg::svd(self.lu.to_dense().as_ref()) {
            let n = svd.s.len();
            if n > 0 {
                let v = &svd.v;
                let j = n - 1;
                let mx = (0..n).map(|i| v[(i, j)].abs()).fold(0.0f64, f64::max);
                for i in 0..n {
                    if v[(i, j)].abs() > 0.2 * mx {
                        names.push(self.mech.x_names[self.mech.dependent[i]].clone());
                    }
                }
            }
        }
        names
    }

    /// Solves the configuration for degrees of freedom `q` at time `t`
    /// (prescribed inputs from their time functions). Starts from the last
    /// solution, extrapolated to first order with F,ξ when available.
    pub fn solve(&mut self, q: &[f64], t: f64) -> Result<(), KinematicsError> {
        self.solve_with(q, t, Refactor::AtSolution)
    }

    /// As [`solve`](Self::solve), but without factorizing J at the converged
    /// configuration when chord steps converged fast: for callers that need
    /// only the configuration, the element Jacobians and solves that refine
    /// against the exact J ([`velocities_refined`](Self::velocities_refined)),
    /// as one evaluation of the equations of motion in nodal coordinates
    /// does. Every method that needs J factorized at x (F,ξ, adjoint and
    /// sensitivity solves) factorizes it first if it is not.
    pub fn solve_chord(&mut self, q: &[f64], t: f64) -> Result<(), KinematicsError> {
        self.solve_with(q, t, Refactor::WhenSlow)
    }

    fn solve_with(&mut self, q: &[f64], t: f64, mode: Refactor) -> Result<(), KinematicsError> {
        let r = self.solve_inner(q, t, mode);
        match &r {
            Ok(()) => {
                self.x_good.copy_from_slice(&self.x);
                self.xi_good.copy_from_slice(&self.xi);
            }
            // back to the last converged configuration: the next solve
            // (e.g. a retried, smaller step) starts from a good guess
            Err(_) => self.restore_last_solution(),
        }
        r
    }

    /// Returns to the last converged configuration after a failed solve: x
    /// and ξ, the deformations and element Jacobians there, and no
    /// factorization (the last one may be of a configuration far off, and
    /// must neither pass for one at x nor predict from it).
    fn restore_last_solution(&mut self) {
        self.x.copy_from_slice(&self.x_good);
        self.xi.copy_from_slice(&self.xi_good);
        self.have_solution = true;
        self.first_order_valid = false;
        self.lu_valid = false;
        self.lu_at_x = false;
        self.eval_elements(true);
    }

    fn solve_inner(&mut self, q: &[f64], t: f64, mode: Refactor) -> Result<(), KinematicsError> {
        if q.len() != self.n_q {
            return Err(KinematicsError::Length {
                what: "q",
                expected: self.n_q,
                got: q.len(),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            // every non-finite entry (up to three by name), not just the first
            let bad: Vec<usize> = (i..q.len()).filter(|&k| !q[k].is_finite()).collect();
            return Err(KinematicsError::NonFinite {
                what: "q",
                index: i,
                name: flexmb_model::list_some(&bad, |k| self.mech.dof_label(k)),
            });
        }
        // ξ = (q, u) in a buffer kept between solves (no allocation per solve)
        let mut target = std::mem::take(&mut self.xi_target);
        target[..self.n_q].copy_from_slice(q);
        for k in 0..self.n_u {
            target[self.n_q + k] = self.mech.inputs[k].function.value(t);
        }
        self.t = t;
        let r = self.solve_to(&target, mode);
        self.xi_target = target;
        r
    }

    /// [`solve_inner`](Self::solve_inner) for the full target ξ: one Newton
    /// solve, then a continuation from the last converged ξ if that fails.
    fn solve_to(&mut self, target: &[f64], mode: Refactor) -> Result<(), KinematicsError> {
        let first = self.solve_xi(target, mode);
        if first.is_ok() || matches!(first, Err(KinematicsError::EulerParameterDegenerate { .. })) {
            return first;
        }
        // continuation from the last converged configuration: reach the target
        // in 2, 4, …, 64 equal steps of ξ (large jumps, e.g. a first solve far
        // from the reference configuration)
        self.continuations += 1;
        let start = self.xi_good.clone();
        let mut err = first;
        for n in [2usize, 4, 8, 16, 32, 64] {
            self.restore_last_solution();
            let mut ok = true;
            for j in 1..=n {
                let s = j as f64 / n as f64;
                let mid: Vec<f64> = start
                    .iter()
                    .zip(target)
                    .map(|(a, b)| a + s * (b - a))
                    .collect();
                // intermediate solutions feed the F,ξ predictor: J at each
                if let Err(e) = self.solve_xi(&mid, Refactor::AtSolution) {
                    err = Err(e);
                    ok = false;
                    break;
                }
                self.first_order();
            }
            if ok {
                return Ok(());
            }
        }
        err
    }

    /// One Newton solve for the full ξ = (q, u).
    ///
    /// Chord Newton: the factorization of J is kept from step to step (and
    /// from the previous solve) while the residual shrinks at least tenfold
    /// per step, and refactorized at the current x otherwise. With
    /// [`Refactor::AtSolution`] J is also factorized at the converged point
    /// (F,ξ needs it there); with [`Refactor::WhenSlow`] the last factorization
    /// may be of a nearby configuration, and `lu_at_x` says whether it is not.
    fn solve_xi(&mut self, xi: &[f64], mode: Refactor) -> Result<(), KinematicsError> {
        let n_q = self.n_q;
        self.xi_prev.copy_from_slice(&self.xi);
        self.xi.copy_from_slice(xi);
        // targets of the constraint rows
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            self.target[r] = match self.mech.e_roles[*j] {
                ERole::Dof(k) => self.xi[k],
                ERole::Input(k) => self.xi[n_q + k],
                _ => 0.0,
            };
        }
        let mut moved = self.have_solution && self.predict();
        self.first_order_valid = false;
        // known coordinates
        for (i, r) in self.mech.x_roles.iter().enumerate() {
            let v = match r {
                XRole::Fixed => self.mech.x0[i],
                XRole::Dof(k) => self.xi[*k],
                XRole::Input(k) => self.xi[n_q + k],
                XRole::Dependent(_) => continue,
            };
            if self.x[i] != v {
                self.x[i] = v;
                moved = true;
            }
        }
        if moved {
            self.lu_at_x = false;
        }
        let tol = self.opts.tol * self.length_scale.max(1e-6);
        let n_c = self.mech.constraint_rows.len();
        let mut last_update = std::mem::take(&mut self.last_update);
        last_update.fill(0.0);
        let mut lu_fresh_for_steps = self.lu_valid;
        let mut prev_res = f64::INFINITY;
        self.eval_elements(true);
        let mut res = self.load_residual();
        let mut outcome = None;
        for it in 0..=self.opts.max_iterations {
            if self
                .stop
                .as_ref()
                .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
            {
                self.last_update = last_update;
                return Err(KinematicsError::Interrupted);
            }
            if !res.is_finite() {
                break;
            }
            // converged: residual below tolerance, or Newton updates at rounding
            // level while the residual is small (it cannot decrease further)
            let x_scale = self
                .mech
                .dependent
                .iter()
                .fold(1.0f64, |m, &i| m.max(self.x[i].abs()));
            // (the residual of a length cannot be computed more accurately than
            // the rounding of the coordinates it is computed from: a mechanism
            // far from the origin, or large against its elements, stalls
            // there, however small tol · L is)
            let stalled = it > 0
                && last_update.iter().fold(0.0f64, |m, v| m.max(v.abs()))
                    <= 8.0 * f64::EPSILON * x_scale
                && res <= (1e3 * tol).max(ROUNDING_RESIDUALS * f64::EPSILON * x_scale);
            if res <= tol || stalled {
                outcome = Some(self.converged(it, mode));
                break;
            }
            if it == self.opts.max_iterations {
                break;
            }
            // a fresh factorization at this x: without a usable one, or when
            // chord steps converge slowly
            if !lu_fresh_for_steps || (it > 0 && res > 0.1 * prev_res) {
                if let Err(e) = self.factor_at_x() {
                    outcome = Some(Err(e));
                    break;
                }
                lu_fresh_for_steps = true;
            }
            prev_res = res;
            self.dx[..n_c].copy_from_slice(&self.work[..n_c]);
            self.lu.solve_vec(&mut self.dx[..n_c]);
            // step with backtracking: halve while the residual grows; the trial
            // evaluation (with Jacobians) serves the next iteration
            let mut step = 1.0;
            loop {
                self.add_to_dependent(step);
                self.eval_elements(true);
                let trial = self.residual_norm();
                if (trial.is_finite() && (trial < res || res < 1e3 * tol)) || step < 0.04 {
                    // the smallest step is accepted anyway: Newton may still recover
                    break;
                }
                self.add_to_dependent(-step);
                step *= 0.5;
            }
            self.lu_at_x = false;
            for (u, d) in last_update.iter_mut().zip(&self.dx) {
                *u = d * step;
            }
            res = self.load_residual();
        }
        let result = match outcome {
            Some(r) => r,
            None => Err(self.not_converged(&last_update)),
        };
        self.last_update = last_update;
        result
    }

    /// x_dep += s · dx.
    fn add_to_dependent(&mut self, s: f64) {
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            self.x[i] += s * self.dx[k];
        }
    }

    /// Writes −(D_c(x) − target) to `work` and returns its max-norm.
    fn load_residual(&mut self) -> f64 {
        let mut res = 0.0f64;
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            let v = self.eps[*j] - self.target[r];
            self.work[r] = -v;
            res = res.max(v.abs());
        }
        res
    }

    /// Bookkeeping of a converged solve (and the factorization `mode` asks for).
    fn converged(&mut self, it: usize, mode: Refactor) -> Result<(), KinematicsError> {
        if mode == Refactor::AtSolution && !self.lu_at_x {
            self.factor_at_x()?;
        }
        self.check_euler_parameters()?;
        self.iterations = it;
        self.prev_eps.copy_from_slice(&self.eps);
        self.have_solution = true;
        Ok(())
    }

    /// Factorizes J at the current x (element Jacobians evaluated there).
    fn factor_at_x(&mut self) -> Result<(), KinematicsError> {
        self.assemble_jacobian();
        self.factorizations += 1;
        self.extra_refinements = 0;
        if !self.lu.factor() {
            self.lu_valid = false;
            self.lu_at_x = false;
            return Err(self.singular_error());
        }
        self.lu_valid = true;
        self.lu_at_x = true;
        Ok(())
    }

    /// First-order predictor of the dependent coordinates for the change of
    /// ξ since the last solution: x += F,ξ Δξ when F,ξ is at hand, else one
    /// chord step J Δx_dep = (target − D_c) − D_c,x_ξ Δx_ξ with the last
    /// factorization and the element Jacobians of the last solution (the same
    /// step to first order). Returns whether x changed.
    fn predict(&mut self) -> bool {
        let n_xi = self.n_q + self.n_u;
        let mut moved = false;
        if self.first_order_valid {
            for c in 0..n_xi {
                let d = self.xi[c] - self.xi_prev[c];
                if d != 0.0 {
                    moved = true;
                    for &i in &self.mech.dependent {
                        self.x[i] += self.f[(i, c)] * d;
                    }
                }
            }
            return moved;
        }
        if !self.lu_valid || self.xi == self.xi_prev {
            return false;
        }
        let mut rhs = std::mem::take(&mut self.dx);
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            rhs[r] = self.target[r] - self.eps[*j];
        }
        let (xi, xi_prev) = (&self.xi, &self.xi_prev);
        self.for_each_nodal_xi_entry(|r, k, d| rhs[r] -= d * (xi[k] - xi_prev[k]));
        self.lu.solve_vec(&mut rhs);
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            self.x[i] += rhs[k];
        }
        self.dx = rhs;
        true
    }

    /// The failure report of a position solve that did not converge.
    fn not_converged(&self, last_update: &[f64]) -> KinematicsError {
        let mut eq: Vec<(f64, String)> = self
            .mech
            .constraint_rows
            .iter()
            .enumerate()
            .map(|(r, j)| {
                (
                    (self.eps[*j] - self.target[r]).abs(),
                    self.mech.eps_names[*j].clone(),
                )
            })
            .collect();
        eq.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut co: Vec<(f64, String)> = self
            .mech
            .dependent
            .iter()
            .enumerate()
            .map(|(k, i)| {
                (
                    last_update.get(k).copied().unwrap_or(0.0).abs(),
                    self.mech.x_names[*i].clone(),
                )
            })
            .collect();
        co.sort_by(|a, b| b.0.total_cmp(&a.0));
        let residual = eq.first().map_or(f64::NAN, |e| e.0);
        let hint = if self.mech.inputs.is_empty() {
            "The configuration may be out of reach of the degrees of freedom, or the starting configuration too far from it (take smaller steps)"
        } else {
            "The configuration may be out of reach (a prescribed motion beyond the mechanism's range) or the step too large"
        };
        KinematicsError::NotConverged {
            hint: hint.into(),
            iterations: self.opts.max_iterations,
            residual,
            equations: eq
                .iter()
                .take(5)
                .map(|(v, n)| format!("{n} = {v:.3e}"))
                .collect(),
            coordinates: co
                .iter()
                .take(5)
                .map(|(v, n)| format!("{n} ({v:.3e})"))
                .collect(),
        }
    }
    /// Factorizes J at the solved configuration if its factorization is of
    /// another one (after [`solve_chord`](Self::solve_chord)). A singular J
    /// leaves the factorization invalid and every later solve NaN.
    fn ensure_lu_at_x(&mut self) {
        if self.have_solution && !self.lu_at_x {
            let _ = self.factor_at_x();
        }
    }

    /// F,ξ and E,ξ at the last solved configuration, from the factorization of
    /// the last Newton iteration (thesis (5.8a), (6.6a)).
    pub fn first_order(&mut self) {
        self.ensure_lu_at_x();
        let (n_q, n_u) = (self.n_q, self.n_u);
        let n_xi = n_q + n_u;
        self.rhs.fill(0.0);
        // deformation coordinates in ξ: unit entries on their rows
        for (j, k) in self.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(r)) = (k, self.row_of[j]) {
                self.rhs[(r, *k)] = 1.0;
            }
        }
        // nodal coordinates in ξ: −∂D_c/∂x_i
        let mut rhs = std::mem::replace(&mut self.rhs, Mat::new());
        self.for_each_nodal_xi_entry(|r, k, d| rhs[(r, k)] -= d);
        self.rhs = rhs;
        self.lu.solve_in_place(self.rhs.as_mut());
        // rows of fixed coordinates stay zero and those of ξ stay unit: only
        // the dependent rows change (F and E start as zeros)
        for c in 0..n_xi {
            let src = self.rhs.col_as_slice(c);
            let dst = self.f.col_as_slice_mut(c);
            for (k, &i) in self.mech.dependent.iter().enumerate() {
                dst[i] = src[k];
            }
        }
        for (i, k) in self.xi_of_x.iter().enumerate() {
            if let Some(k) = k {
                self.f[(i, *k)] = 1.0;
            }
        }
        // E,ξ = D,x F,ξ on the deformations that are not constraint rows;
        // exact (zero or unit) on rigid / DOF / input rows
        for (j, k) in self.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(_)) = (k, self.row_of[j]) {
                self.e[(j, *k)] = 1.0;
            }
        }
        for &(ei, a) in &self.free_deformations {
            let e = &self.mech.elements[ei];
            let nx = self.maps[ei].nx;
            let row = &self.jac_local[ei][a * nx..(a + 1) * nx];
            let j = e.eps_offset + a;
            for col in 0..n_xi {
                let fcol = self.f.col_as_slice(col);
                let mut s = 0.0;
                for (c, gi) in e.x_index.iter().enumerate() {
                    s += row[c] * fcol[*gi];
                }
                self.e[(j, col)] = s;
            }
        }
        self.first_order_valid = true;
    }

    /// Visits the entries ∂D_r/∂x_i of the constraint rows r with respect to
    /// the nodal coordinates x_i that belong to ξ (k = ξ index of x_i): the
    /// nodal columns of the right-hand side B of (5.8a), up to sign.
    fn for_each_nodal_xi_entry(&self, mut visit: impl FnMut(usize, usize, f64)) {
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
            for (c, gi) in e.x_index.iter().enumerate() {
                let Some(k) = self.xi_of_x[*gi] else { continue };
                for (a, r) in m.rows.iter().enumerate() {
                    if let Some(r) = r {
                        visit(*r, k, jl[a * m.nx + c]);
                    }
                }
            }
        }
    }

    /// F,ξᵀ y for a vector y over the nodal coordinates, at the last solved
    /// configuration, by one adjoint solve with Jᵀ and without forming F,ξ:
    /// with F,ξ = J⁻¹B on the dependent coordinates (thesis (5.8a)),
    /// F,ξᵀy = y_ξ + Bᵀ(J⁻ᵀ y_dep), B the right-hand side of
    /// [`first_order`](Self::first_order). `out` has n_q + n_u entries.
    pub fn transfer_transpose_times(&mut self, y: &[f64], out: &mut [f64]) {
        self.ensure_lu_at_x();
        let mech = self.mech.clone();
        let mut mu = std::mem::take(&mut self.rhs_vec);
        for (k, &i) in mech.dependent.iter().enumerate() {
            mu[k] = y[i];
        }
        self.lu.solve_transpose_vec(&mut mu);
        out.fill(0.0);
        // nodal coordinates in ξ: their own entry minus Σ μ_r ∂D_r/∂x_i
        for (i, k) in self.xi_of_x.iter().enumerate() {
            if let Some(k) = k {
                out[*k] += y[i];
            }
        }
        self.for_each_nodal_xi_entry(|r, k, d| out[k] -= d * mu[r]);
        // deformation coordinates in ξ: a unit entry on their row
        for (j, k) in self.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(r)) = (k, self.row_of[j]) {
                out[*k] += mu[r];
            }
        }
        self.rhs_vec = mu;
    }

    /// y += D,xᵀ s, the nodal forces of deformation stresses s (all
    /// deformations, at the last solved configuration).
    pub fn add_deformation_forces(&self, s: &[f64], y: &mut [f64]) {
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
            for a in 0..m.ne {
                let v = s[e.eps_offset + a];
                if v == 0.0 {
                    continue;
                }
                for (c, gi) in e.x_index.iter().enumerate() {
                    y[*gi] += jl[a * m.nx + c] * v;
                }
            }
        }
    }

    /// ẋ = F,ξ ξ̇ and ε̇ = E,ξ ξ̇ with ξ̇ = (q̇, u̇(t)), with F,ξ and E,ξ of the
    /// current configuration (computed first if stale).
    pub fn velocities(&mut self, qd: &[f64]) {
        self.ensure_first_order();
        let (n_q, n_u) = (self.n_q, self.n_u);
        self.xid[..n_q].copy_from_slice(qd);
        for k in 0..n_u {
            self.xid[n_q + k] = self.mech.inputs[k].function.eval(self.t).1;
        }
        let n_xi = n_q + n_u;
        self.xd.fill(0.0);
        self.epsd.fill(0.0);
        for c in 0..n_xi {
            let v = self.xid[c];
            if v == 0.0 {
                continue;
            }
            for (d, f) in self.xd.iter_mut().zip(self.f.col_as_slice(c)) {
                *d += f * v;
            }
            for (d, e) in self.epsd.iter_mut().zip(self.e.col_as_slice(c)) {
                *d += e * v;
            }
        }
    }

    /// ẋ and ε̇ for ξ̇ = (q̇, u̇(t)) without F,ξ: one solve of
    /// J ẋ_dep = ė_c − D_c,x_ξ ẋ_ξ (the time derivative of the constraint
    /// equations D_c(x) = (0, q_ε, u_ε), thesis (5.8a)) with the factorization of
    /// J at hand. After [`solve_chord`](Self::solve_chord) that factorization
    /// may be of a nearby configuration: the solution is then refined against
    /// the exact J(x) (iterative refinement), and J is factorized afresh only
    /// if the refinement does not contract fast. ε̇ is exact on the constraint
    /// rows and D,x ẋ elsewhere.
    pub fn velocities_refined(&mut self, qd: &[f64]) -> Result<(), KinematicsError> {
        let (n_q, n_u) = (self.n_q, self.n_u);
        self.xid[..n_q].copy_from_slice(qd);
        for k in 0..n_u {
            self.xid[n_q + k] = self.mech.inputs[k].function.eval(self.t).1;
        }
        let mut rhs = std::mem::take(&mut self.vel_rhs);
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            rhs[r] = match self.mech.e_roles[*j] {
                ERole::Dof(k) => self.xid[k],
                ERole::Input(k) => self.xid[n_q + k],
                _ => 0.0,
            };
        }
        let xid = &self.xid;
        self.for_each_nodal_xi_entry(|r, k, d| rhs[r] -= d * xid[k]);
        let mut v = std::mem::take(&mut self.rhs_vec);
        let solved = self.solve_refined(&rhs, &mut v);
        self.vel_rhs = rhs;
        if let Err(e) = solved {
            self.rhs_vec = v;
            return Err(e);
        }
        for (i, r) in self.mech.x_roles.iter().enumerate() {
            self.xd[i] = match r {
                XRole::Fixed => 0.0,
                XRole::Dof(k) => self.xid[*k],
                XRole::Input(k) => self.xid[n_q + k],
                XRole::Dependent(k) => v[*k],
            };
        }
        self.rhs_vec = v;
        for (j, r) in self.mech.e_roles.iter().enumerate() {
            if self.row_of[j].is_some() {
                self.epsd[j] = match r {
                    ERole::Dof(k) => self.xid[*k],
                    ERole::Input(k) => self.xid[n_q + k],
                    _ => 0.0,
                };
            }
        }
        for &(ei, a) in &self.free_deformations {
            let e = &self.mech.elements[ei];
            let nx = self.maps[ei].nx;
            let row = &self.jac_local[ei][a * nx..(a + 1) * nx];
            self.epsd[e.eps_offset + a] = e
                .x_index
                .iter()
                .zip(row)
                .map(|(gi, d)| d * self.xd[*gi])
                .sum();
        }
        Ok(())
    }

    /// Solves J(x) v = b at the solved configuration: directly when the
    /// factorization is of this x, else by iterative refinement with the
    /// factorization of a nearby configuration, converged when the update,
    /// or the error it leaves (update × ρ/(1 − ρ) with the observed
    /// contraction ρ of the updates), is below 1e-14 of |v|; falling back to
    /// a fresh factorization when the updates do not shrink at least
    /// fourfold per step or [`MAX_REFINEMENTS`] steps do not converge.
    fn solve_refined(&mut self, b: &[f64], v: &mut [f64]) -> Result<(), KinematicsError> {
        if !self.lu_valid {
            self.factor_at_x()?;
        }
        v.copy_from_slice(b);
        self.lu.solve_vec(v);
        if self.lu_at_x {
            return Ok(());
        }
        let mut res = std::mem::take(&mut self.vel_res);
        // the first iterate's size stands for the initial error's bound
        let mut prev = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut converged = false;
        let mut steps = 0;
        for _ in 0..MAX_REFINEMENTS {
            steps += 1;
            self.refinements += 1;
            res.copy_from_slice(b);
            self.sub_jacobian_times(v, &mut res);
            self.lu.solve_vec(&mut res);
            let (mut d, mut vmax) = (0.0f64, 0.0f64);
            for (vi, ri) in v.iter_mut().zip(&res) {
                *vi += ri;
                d = d.max(ri.abs());
                vmax = vmax.max(vi.abs());
            }
            if !d.is_finite() {
                break;
            }
            // with the observed contraction ρ = d/d_prev the error left after
            // this update is about d ρ/(1 − ρ)
            let rho = if prev > 0.0 { d / prev } else { 0.0 };
            if d <= REFINED_TOL * vmax
                || (rho < 0.25 && d * rho / (1.0 - rho) <= REFINED_TOL * vmax)
            {
                converged = true;
                break;
            }
            if rho > 0.25 {
                break;
            }
            prev = d;
        }
        self.vel_res = res;
        if !converged {
            self.factor_at_x()?;
            v.copy_from_slice(b);
            self.lu.solve_vec(v);
        } else {
            self.extra_refinements += steps - 1;
            if self.extra_refinements >= REFRESH_BUDGET {
                // converged, but the factorization has aged: a fresh one here
                // serves the next evaluations (the result stays the refined one)
                self.factor_at_x()?;
            }
        }
        Ok(())
    }

    /// out −= J(x) v, J = ∂D_c/∂x_dep from the element Jacobians at x.
    fn sub_jacobian_times(&self, v: &[f64], out: &mut [f64]) {
        for (m, jl) in self.maps.iter().zip(&self.jac_local) {
            for (a, r) in m.rows.iter().enumerate() {
                let Some(r) = r else { continue };
                let row = &jl[a * m.nx..(a + 1) * m.nx];
                let mut s = 0.0;
                for (c, col) in m.cols.iter().enumerate() {
                    if let Some(k) = col {
                        s += row[c] * v[*k];
                    }
                }
                out[*r] -= s;
            }
        }
    }

    /// The convective terms D,xx\[ẋ, ẋ\] of every deformation at the current
    /// configuration and velocities (zero for elements at rest), the
    /// velocity-quadratic part of ε̈ = D,x ẍ + D,xx\[ẋ, ẋ\] (thesis (5.8b)).
    pub fn convective_terms(&mut self) -> &[f64] {
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            if m.ne == 0 {
                continue;
            }
            let mut moving = false;
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = self.x[*gi];
                vl[k] = self.xd[*gi];
                moving |= vl[k] != 0.0;
            }
            let out = &mut self.dxx_vv[e.eps_offset..e.eps_offset + m.ne];
            if moving {
                e.element
                    .deformation_second_derivative(&xl[..m.nx], &vl[..m.nx], &vl[..m.nx], out);
            } else {
                out.fill(0.0);
            }
        }
        &self.dxx_vv
    }

    /// The accelerations for q̈ = 0: ẍ0 = F,u ü + (F,ξξ ξ̇)ξ̇ and the matching
    /// ε̈0, by one solve with −D,xx\[ẋ, ẋ\] (thesis (5.8b)). Call after
    /// [`velocities`](Self::velocities). Then ẍ = F,q q̈ + ẍ0.
    pub fn accelerations(&mut self) {
        self.ensure_lu_at_x();
        let n_u = self.n_u;
        let mech = self.mech.clone();
        // c = D,xx[ẋ, ẋ] per element
        self.convective_terms();
        self.epsdd0.copy_from_slice(&self.dxx_vv);
        let mut rhs = std::mem::take(&mut self.rhs_vec);
        for (r, j) in mech.constraint_rows.iter().enumerate() {
            rhs[r] = -self.dxx_vv[*j];
        }
        // prescribed input accelerations ü
        let mut udd = vec![0.0; n_u];
        for k in 0..n_u {
            udd[k] = mech.inputs[k].function.eval(self.t).2;
            if let Coordinate::Def(j) = mech.inputs[k].target {
                if let Some(r) = self.row_of[j] {
                    rhs[r] += udd[k];
                }
            }
        }
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
            for (cc, gi) in e.x_index.iter().enumerate() {
                if let XRole::Input(k) = mech.x_roles[*gi] {
                    for (a, r) in m.rows.iter().enumerate() {
                        if let Some(r) = r {
                            rhs[*r] -= jl[a * m.nx + cc] * udd[k];
                        }
                    }
                }
            }
        }
        self.lu.solve_vec(&mut rhs);
        self.xdd0.fill(0.0);
        for (k, &i) in mech.dependent.iter().enumerate() {
            self.xdd0[i] = rhs[k];
        }
        for (i, r) in mech.x_roles.iter().enumerate() {
            if let XRole::Input(k) = r {
                self.xdd0[i] = udd[*k];
            }
        }
        // ε̈0 = D,x ẍ0 + D,xx[ẋ, ẋ] (rows: exact targets)
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
            for a in 0..m.ne {
                let j = e.eps_offset + a;
                if self.row_of[j].is_some() {
                    self.epsdd0[j] = match mech.e_roles[j] {
                        ERole::Input(k) => udd[k],
                        _ => 0.0,
                    };
                    continue;
                }
                let mut s = self.epsdd0[j];
                for (cc, gi) in e.x_index.iter().enumerate() {
                    s += jl[a * m.nx + cc] * self.xdd0[*gi];
                }
                self.epsdd0[j] = s;
            }
        }
        self.rhs_vec = rhs;
    }

    /// Sensitivities of the velocities to q at the current state (after
    /// [`velocities`](Self::velocities)): X1 = ∂ẋ/∂q = (F,qq q̇) (n_x × n_q) and
    /// ∂ε̇/∂q (n_ε × n_q). Column k solves J X1_dep = −D_c,xx\[F,q e_k, ẋ\].
    pub fn velocity_sensitivity(&mut self) -> (Mat<f64>, Mat<f64>) {
        self.ensure_lu_at_x();
        self.ensure_first_order();
        let mech = self.mech.clone();
        let (n_q, n_x, n_e) = (self.n_q, mech.n_x(), mech.n_eps());
        let n_c = mech.constraint_rows.len();
        // c_k = D,xx[F e_k, ẋ] for every deformation
        let mut c = Mat::<f64>::zeros(n_e, n_q);
        self.directional_second(&mut c, |_, _| None);
        let mut rhs = Mat::from_fn(n_c, n_q, |r, k| -c[(mech.constraint_rows[r], k)]);
        self.lu.solve_in_place(rhs.as_mut());
        let mut x1 = Mat::<f64>::zeros(n_x, n_q);
        for k in 0..n_q {
            for (r, &i) in mech.dependent.iter().enumerate() {
                x1[(i, k)] = rhs[(r, k)];
            }
        }
        // ∂ε̇/∂q = D,xx[F e_k, ẋ] + D,x X1
        let mut ed = c;
        self.add_jacobian_times(&x1, &mut ed);
        for j in 0..n_e {
            if self.row_of[j].is_some() {
                for k in 0..n_q {
                    ed[(j, k)] = 0.0;
                }
            }
        }
        (x1, ed)
    }

    /// X2 = ∂ẍ/∂q (n_x × n_q) at fixed q̇, q̈ for the full accelerations `xdd`,
    /// given X1 from [`velocity_sensitivity`](Self::velocity_sensitivity):
    /// J X2_dep = −(D_c,xx\[F e_k, ẍ\] + D_c,xxx\[F e_k, ẋ, ẋ\] + 2 D_c,xx\[X1 e_k, ẋ\]).
    pub fn acceleration_sensitivity(&mut self, xdd: &[f64], x1: &Mat<f64>) -> Mat<f64> {
        self.ensure_lu_at_x();
        self.ensure_first_order();
        let mech = self.mech.clone();
        let (n_q, n_x) = (self.n_q, mech.n_x());
        let n_c = mech.constraint_rows.len();
        let mut rhs = Mat::<f64>::zeros(n_c, n_q);
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut al = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut gl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o1 = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o2 = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o3 = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            if m.ne == 0 || m.rows.iter().all(|r| r.is_none()) {
                continue;
            }
            for (a, gi) in e.x_index.iter().enumerate() {
                xl[a] = self.x[*gi];
                vl[a] = self.xd[*gi];
                al[a] = xdd[*gi];
            }
            for k in 0..n_q {
                let mut any = false;
                for (a, gi) in e.x_index.iter().enumerate() {
                    fl[a] = self.f[(*gi, k)];
                    gl[a] = x1[(*gi, k)];
                    any |= fl[a] != 0.0 || gl[a] != 0.0;
                }
                if !any {
                    continue;
                }
                let nx = m.nx;
                e.element.deformation_second_derivative(
                    &xl[..nx],
                    &fl[..nx],
                    &al[..nx],
                    &mut o1[..m.ne],
                );
                e.element.deformation_third_derivative(
                    &xl[..nx],
                    &fl[..nx],
                    &vl[..nx],
                    &vl[..nx],
                    &mut o2[..m.ne],
                );
                e.element.deformation_second_derivative(
                    &xl[..nx],
                    &gl[..nx],
                    &vl[..nx],
                    &mut o3[..m.ne],
                );
                for (a, r) in m.rows.iter().enumerate() {
                    if let Some(r) = r {
                        rhs[(*r, k)] -= o1[a] + o2[a] + 2.0 * o3[a];
                    }
                }
            }
        }
        self.lu.solve_in_place(rhs.as_mut());
        let mut x2 = Mat::<f64>::zeros(n_x, n_q);
        for k in 0..n_q {
            for (r, &i) in mech.dependent.iter().enumerate() {
                x2[(i, k)] = rhs[(r, k)];
            }
        }
        x2
    }

    /// out(j, k) += Σ D_j,x · cols(:, k) over the elements.
    fn add_jacobian_times(&self, cols: &Mat<f64>, out: &mut Mat<f64>) {
        let n_k = cols.ncols();
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
            for a in 0..m.ne {
                let j = e.eps_offset + a;
                for k in 0..n_k {
                    let mut s = 0.0;
                    for (c, gi) in e.x_index.iter().enumerate() {
                        s += jl[a * m.nx + c] * cols[(*gi, k)];
                    }
                    out[(j, k)] += s;
                }
            }
        }
    }

    /// out(j, k) = D_j,xx\[F,q e_k, ẋ\] for every deformation.
    fn directional_second(
        &self,
        out: &mut Mat<f64>,
        _unused: impl Fn(usize, usize) -> Option<f64>,
    ) {
        let n_q = self.n_q;
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            if m.ne == 0 {
                continue;
            }
            let mut moving = false;
            for (a, gi) in e.x_index.iter().enumerate() {
                xl[a] = self.x[*gi];
                vl[a] = self.xd[*gi];
                moving |= vl[a] != 0.0;
            }
            if !moving {
                continue;
            }
            for k in 0..n_q {
                let mut any = false;
                for (a, gi) in e.x_index.iter().enumerate() {
                    fl[a] = self.f[(*gi, k)];
                    any |= fl[a] != 0.0;
                }
                if !any {
                    continue;
                }
                e.element.deformation_second_derivative(
                    &xl[..m.nx],
                    &fl[..m.nx],
                    &vl[..m.nx],
                    &mut o[..m.ne],
                );
                for a in 0..m.ne {
                    out[(e.eps_offset + a, k)] = o[a];
                }
            }
        }
    }

    /// The contraction G = F,qqᵀ w + E,qqᵀ σ (n_q × n_q, symmetric), the
    /// geometric-stiffness term of (E.5e), by one adjoint solve:
    /// G = F,qᵀ (Σ_dep σⱼ Dⱼ,xx − Σ_rows μᵣ Dᵣ,xx) F,q with Jᵀμ = (w + D,xᵀσ_dep)_dep.
    /// Call after [`first_order`](Self::first_order).
    pub fn second_order_contraction(&mut self, w: &[f64], sigma: &[f64]) -> Mat<f64> {
        let hf = self.weighted_hessian_times_f(w, sigma);
        self.contract_with_f(&hf)
    }

    /// [`second_order_contraction`](Self::second_order_contraction) that
    /// returns `None` if `stop` is set after the element loop, before the
    /// product with F,qᵀ (each about half of the cost for a large model).
    pub fn second_order_contraction_until(
        &mut self,
        w: &[f64],
        sigma: &[f64],
        stop: Option<&std::sync::atomic::AtomicBool>,
    ) -> Option<Mat<f64>> {
        let hf = self.weighted_hessian_times_f(w, sigma);
        if stop.is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed)) {
            return None;
        }
        Some(self.contract_with_f(&hf))
    }

    /// HF = Σ_e scatter(H_e F_e) of
    /// [`second_order_contraction`](Self::second_order_contraction) (n_x × n_q).
    fn weighted_hessian_times_f(&mut self, w: &[f64], sigma: &[f64]) -> Mat<f64> {
        self.ensure_lu_at_x();
        self.ensure_first_order();
        let mech = self.mech.clone();
        let n_q = self.n_q;
        let n_c = mech.constraint_rows.len();
        // y = w + D,xᵀ σ_dep on the dependent coordinates
        let mut y = vec![0.0; n_c];
        for (k, &i) in mech.dependent.iter().enumerate() {
            y[k] = w[i];
        }
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
            for a in 0..m.ne {
                let j = e.eps_offset + a;
                if self.row_of[j].is_some() || sigma[j] == 0.0 {
                    continue;
                }
                for (cc, col) in m.cols.iter().enumerate() {
                    if let Some(col) = col {
                        y[*col] += jl[a * m.nx + cc] * sigma[j];
                    }
                }
            }
        }
        self.lu.solve_transpose_vec(&mut y);
        let mu = y;
        // HF = Σ_e scatter(H_e F_e), then G = F,qᵀ HF with one product
        let n_x = mech.n_x();
        let mut hf = Mat::<f64>::zeros(n_x, n_q);
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut wl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut h =
            vec![0.0; flexmb_element::MAX_ELEMENT_COORDS * flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            if m.ne == 0 {
                continue;
            }
            let mut any = false;
            for a in 0..m.ne {
                let j = e.eps_offset + a;
                wl[a] = match self.row_of[j] {
                    Some(r) => -mu[r],
                    None => sigma[j],
                };
                any |= wl[a] != 0.0;
            }
            if !any {
                continue;
            }
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = self.x[*gi];
            }
            let nx = m.nx;
            e.element
                .deformation_weighted_hessian(&xl[..nx], &wl[..m.ne], &mut h[..nx * nx]);
            for c in 0..n_q {
                let fcol = self.f.col_as_slice(c);
                let mut nz = false;
                for (a, gi) in e.x_index.iter().enumerate() {
                    fl[a] = fcol[*gi];
                    nz |= fl[a] != 0.0;
                }
                if !nz {
                    continue;
                }
                let out = hf.col_as_slice_mut(c);
                for (a, gi) in e.x_index.iter().enumerate() {
                    let row = &h[a * nx..a * nx + nx];
                    let mut s = 0.0;
                    for b in 0..nx {
                        s += row[b] * fl[b];
                    }
                    out[*gi] += s;
                }
            }
        }
        hf
    }

    /// G = F,qᵀ HF, symmetric, for HF of
    /// [`weighted_hessian_times_f`](Self::weighted_hessian_times_f).
    fn contract_with_f(&self, hf: &Mat<f64>) -> Mat<f64> {
        let n_q = self.n_q;
        // G is symmetric (each H_e is): only its lower triangle is computed,
        // half the cost of the dense product (the bulk of a linearization of
        // a large model: 0.28 s of 0.46 s for the 1440-DOF flexure chain),
        // then mirrored
        use faer::linalg::matmul::triangular::{matmul, BlockStructure};
        let mut g = Mat::<f64>::zeros(n_q, n_q);
        matmul(
            g.as_mut(),
            BlockStructure::TriangularLower,
            faer::Accum::Replace,
            self.f.subcols(0, n_q).transpose(),
            BlockStructure::Rectangular,
            hf.as_ref(),
            BlockStructure::Rectangular,
            1.0,
            faer::Par::Seq,
        );
        for c in 0..n_q {
            for r in c + 1..n_q {
                g[(c, r)] = g[(r, c)];
            }
        }
        g
    }
}

/// The pattern of J (constraint rows × dependent coordinates) from the
/// elements' row and column maps, and each element's scatter positions.
fn jacobian_pattern(
    maps: &[ElemMap],
    n_c: usize,
    dense_up_to: usize,
) -> (JacobianLu, Vec<Vec<usize>>) {
    let mut entries = vec![];
    let mut owner = vec![];
    for (k, m) in maps.iter().enumerate() {
        for (a, r) in m.rows.iter().enumerate() {
            let Some(r) = r else { continue };
            for (c, col) in m.cols.iter().enumerate() {
                if let Some(col) = col {
                    entries.push((*r, *col));
                    owner.push((k, a * m.nx + c));
                }
            }
        }
    }
    let (lu, positions) = JacobianLu::with_dense_limit(n_c, &entries, dense_up_to);
    let mut jpos: Vec<Vec<usize>> = maps.iter().map(|m| vec![NO_ENTRY; m.ne * m.nx]).collect();
    for ((k, local), p) in owner.into_iter().zip(positions) {
        jpos[k][local] = p;
    }
    (lu, jpos)
}

/// Mean distance between the first two position slots of the elements that
/// have two nodes: the length unit of the Newton tolerance.
fn characteristic_length(mech: &Mechanism) -> f64 {
    use flexmb_element::Slot;
    let mut sum = 0.0;
    let mut n = 0usize;
    for e in &mech.elements {
        let slots = e.element.slots();
        let mut starts = vec![];
        let mut off = 0;
        for s in slots {
            if matches!(s, Slot::Position2 | Slot::Position3) {
                starts.push((off, s.len()));
            }
            off += s.len();
        }
        if starts.len() >= 2 {
            let ((a, k), (b, _)) = (starts[0], starts[1]);
            let d: f64 = (0..k)
                .map(|c| (mech.x0[e.x_index[b + c]] - mech.x0[e.x_index[a + c]]).powi(2))
                .sum::<f64>()
                .sqrt();
            if d > 0.0 {
                sum += d;
                n += 1;
            }
        }
    }
    if n == 0 {
        1.0
    } else {
        sum / n as f64
    }
}
