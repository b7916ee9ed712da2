//! The configuration state of [`Kinematics`](crate::Kinematics): the
//! current (q, u, t), x and ε, the branch periodic deformations continue
//! from, and the last converged solution a failed solve returns to.

use flexmb_model::{Coordinate, Mechanism};

/// The configuration of the last solve.
///
/// After a converged solve `x` and `eps` solve the constraint equations for
/// `xi` at `t`, `solved` is set and (`x_good`, `xi_good`) equal (`x`, `xi`).
/// A failed solve restores (`x`, `xi`) from (`x_good`, `xi_good`) and ε
/// there, so the state is again a solution. A guess
/// ([`Kinematics::set_guess`](crate::Kinematics::set_guess)) overwrites `x`
/// and clears `solved`: `eps` and `xi` are then not of `x` until the next
/// solve.
pub(crate) struct Configuration {
    /// Time of the last solve (the inputs' time functions are read there).
    pub(crate) t: f64,
    /// ξ = (q, u) of the last solve (its target while it runs).
    pub(crate) xi: Vec<f64>,
    /// ξ before the last solve: the step Δξ the predictor extrapolates over.
    pub(crate) xi_prev: Vec<f64>,
    /// Nodal coordinates.
    pub(crate) x: Vec<f64>,
    /// Deformations ε = D(x) (of the last element evaluation).
    pub(crate) eps: Vec<f64>,
    /// The deformations of the last converged solve: periodic deformations
    /// (hinge angles over many turns) are unwrapped against them.
    pub(crate) branch: Vec<f64>,
    /// `x` is a converged solution for `xi` (so a solve may predict from it
    /// and J may be factorized there).
    pub(crate) solved: bool,
    /// x of the last converged solve (the reference configuration before the
    /// first).
    pub(crate) x_good: Vec<f64>,
    /// ξ of the last converged solve (ξ0 of the reference before the first).
    pub(crate) xi_good: Vec<f64>,
}

impl Configuration {
    /// The reference configuration x0 with ξ0 = (q0, u0) read off it (the
    /// DOFs and inputs that are nodal coordinates at their x0, deformations
    /// at 0), not yet solved
    /// ([`Kinematics::new`](crate::Kinematics::new) checks that it solves
    /// the constraints for ξ0 and then counts it as the first solution).
    pub(crate) fn reference(mech: &Mechanism, n_xi: usize) -> Self {
        let n_eps = mech.n_eps();
        let mut xi = vec![0.0; n_xi];
        let q0 = mech.q0();
        xi[..q0.len()].copy_from_slice(&q0);
        for (k, inp) in mech.inputs.iter().enumerate() {
            if let Coordinate::Node(i) = inp.target {
                xi[q0.len() + k] = mech.x0[i];
            }
        }
        Self {
            t: 0.0,
            xi_prev: xi.clone(),
            x: mech.x0.clone(),
            eps: vec![0.0; n_eps],
            branch: vec![0.0; n_eps],
            solved: false,
            x_good: mech.x0.clone(),
            xi_good: xi.clone(),
            xi,
        }
    }
}
