//! The scratch buffers of [`Kinematics`](crate::Kinematics), allocated once
//! so that the per-step paths (solve, velocities, accelerations) allocate
//! nothing. A buffer's content means nothing between calls, except
//! `target` and `last_update`, which the failure report of the last
//! position solve reads.
//!
//! Being one field of `Kinematics` apart from the state and the caches, the
//! buffers are borrowed mutably next to them (`self.ws.dx` while
//! `self.layout` and `self.jac` are read), so no method takes a buffer out
//! of `self` to call another: a step that needs `&mut self` as a whole (a
//! factorization, the next Newton solve) reads its input from and writes
//! its result to named buffers here (e.g. the solves along a direction:
//! `xi_dir` and `vel_rhs` in, `dep` out).

use faer::Mat;

/// Work memory of the kinematics (n_c constraint rows, n_x coordinates, n_ξ
/// = n_q + n_u).
pub(crate) struct Workspace {
    /// The right-hand sides of F,ξ (n_c × n_ξ), solved in place
    /// ([`first_order`](crate::Kinematics::first_order)).
    pub(crate) rhs: Mat<f64>,
    /// The right-hand sides of a block of directions (n_c × k, resized
    /// when k changes: [`transfer_matrix`](crate::Kinematics::transfer_matrix)).
    pub(crate) block: Mat<f64>,
    /// The negative residual −(D_c(x) − target) of a Newton iteration, and
    /// a strided destination's column (max(n_c, n_x)).
    pub(crate) work: Vec<f64>,
    /// The targets of the constraint rows of the last position solve (n_c).
    pub(crate) target: Vec<f64>,
    /// The target ξ of the current solve (n_ξ).
    pub(crate) xi_target: Vec<f64>,
    /// A Newton update of the dependent coordinates, or the predictor's
    /// chord step (n_c).
    pub(crate) dx: Vec<f64>,
    /// The last Newton update actually taken (n_c), for the convergence
    /// test and the failure report.
    pub(crate) last_update: Vec<f64>,
    /// A direction of ξ (q̈ and ü, or a direction of q) for the solves along
    /// one (n_ξ).
    pub(crate) xi_dir: Vec<f64>,
    /// The dependent part of a solve along a direction, or the adjoint
    /// multipliers (n_c).
    pub(crate) dep: Vec<f64>,
    /// The right-hand side of the refined solve along a direction (n_c).
    pub(crate) vel_rhs: Vec<f64>,
    /// The residual of its refinement steps (n_c).
    pub(crate) vel_res: Vec<f64>,
    /// The first-order prediction of the current position solve (n_x), for
    /// the branch guard (`branch_jump` in position.rs).
    pub(crate) x_predicted: Vec<f64>,
}

impl Workspace {
    /// Buffers for n_c constraint rows, n_x coordinates and n_ξ entries of ξ.
    pub(crate) fn new(n_c: usize, n_x: usize, n_xi: usize) -> Self {
        Self {
            rhs: Mat::zeros(n_c, n_xi),
            block: Mat::zeros(0, 0),
            work: vec![0.0; n_c.max(n_x)],
            target: vec![0.0; n_c],
            xi_target: vec![0.0; n_xi],
            dx: vec![0.0; n_c],
            last_update: vec![0.0; n_c],
            xi_dir: vec![0.0; n_xi],
            dep: vec![0.0; n_c],
            vel_rhs: vec![0.0; n_c],
            vel_res: vec![0.0; n_c],
            x_predicted: vec![0.0; n_x],
        }
    }
}
