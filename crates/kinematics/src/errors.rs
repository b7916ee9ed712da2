//! The kinematics' errors, and the reports that name the coordinates and
//! equations involved when the position solve (thesis (5.7), (6.5)) fails or
//! J is singular.

use crate::jacobian_lu::DENSE_UP_TO;
use crate::Kinematics;

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
    /// The converged configuration is not the one the last solution
    /// continues to: Newton moved a dependent coordinate from the
    /// first-order prediction by more than the prediction moved, even in the
    /// finest (64) continuation steps from the last solution (the solve
    /// jumped to another branch of the constraint equations, e.g. an elbow
    /// that folded the other way, or the steps cross a branching
    /// configuration).
    #[error("the position solve jumped to another branch: {coordinate} moved {correction:.3e} away from its first-order prediction, more than the step's predicted motion ({predicted:.3e}), even in 64 continuation steps from the last solution: the mechanism passes a singular (branching) configuration between them; take smaller steps, or set a guess on the wanted branch (Kinematics::set_guess)")]
    BranchJump {
        /// The dependent coordinate with the largest correction.
        coordinate: String,
        /// Its distance from the first-order prediction.
        correction: f64,
        /// The largest motion the prediction made.
        predicted: f64,
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

impl Kinematics {
    /// The error for a singular J, naming the dependent coordinates it
    /// leaves undetermined. A failed factorization is often recoverable (an
    /// iterate far from the solution; the integrator retries with a smaller
    /// step), so this must stay cheap: the null vector by a dense SVD only
    /// for a Jacobian small enough to be factorized densely (at most
    /// `DENSE_UP_TO` rows, milliseconds); for a large one the coordinate of
    /// the sparse factorization's smallest pivot (the SVD of the 1680 × 1680
    /// J of the 1440-DOF flexure chain took 4 s, at every failed iterate of
    /// a time step).
    pub(crate) fn singular_error(&self) -> KinematicsError {
        let n = self.mech.dependent.len();
        let names = if n <= DENSE_UP_TO {
            self.null_space_names()
        } else {
            self.factorization
                .lu
                .smallest_pivot_column()
                .map(|c| vec![self.mech.x_names[self.mech.dependent[c]].clone()])
                .unwrap_or_default()
        };
        KinematicsError::Singular {
            pivot_ratio: self.factorization.lu.pivot_ratio,
            coordinates: names,
        }
    }

    /// The dependent coordinates that J at the current configuration
    /// determines worst: those with a large share in its smallest singular
    /// value's right singular vector (a dense SVD up to `DENSE_UP_TO` rows),
    /// or the column of the smallest pivot of a large sparse factorization.
    /// For reports on a configuration near a singular one; J must have been
    /// factorized there (a solve does it).
    pub fn least_determined_coordinates(&self) -> Vec<String> {
        match self.singular_error() {
            KinematicsError::Singular { coordinates, .. } => coordinates,
            _ => unreachable!("singular_error gives Singular"),
        }
    }

    /// The dependent coordinates with a large share in J's null vector (its
    /// smallest singular value's right singular vector).
    fn null_space_names(&self) -> Vec<String> {
        let mut names = vec![];
        if let Ok(svd) = flexmb_linalg::svd(self.factorization.lu.to_dense().as_ref()) {
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

    /// The failure report of a position solve that did not converge.
    /// The last Newton update taken is `Workspace::last_update`.
    pub(crate) fn not_converged(&self) -> KinematicsError {
        let last_update = &self.ws.last_update;
        let mut eq: Vec<(f64, String)> = self
            .mech
            .constraint_rows
            .iter()
            .enumerate()
            .map(|(r, j)| {
                (
                    (self.config.eps[*j] - self.ws.target[r]).abs(),
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
            iterations: self.settings.newton.max_iterations,
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
}
