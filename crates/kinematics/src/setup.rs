//! Set-up of [`Kinematics`]: the fixed layout of the mechanism
//! ([`Layout::new`]: constraint rows, ξ indices, element maps and the
//! pattern of J), the reference configuration and the work buffers.

use crate::caches::{ElementJacobians, Factorization, FirstOrderCache};
use crate::configuration::Configuration;
use crate::jacobian_lu::DENSE_UP_TO;
use crate::layout::Layout;
use crate::position::Settings;
use crate::rates::Rates;
use crate::workspace::Workspace;
use crate::{Counters, Kinematics};
use flexmb_model::Mechanism;
use std::sync::Arc;

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
        let (n_x, n_eps) = (mech.n_x(), mech.n_eps());
        let n_c = mech.constraint_rows.len();
        let (layout, lu) = Layout::new(&mech, dense_up_to);
        let n_xi = layout.n_xi();
        let mut k = Self {
            settings: Settings::default(),
            config: Configuration::reference(&mech, n_xi),
            jac: ElementJacobians::new(&mech),
            factorization: Factorization::new(lu),
            first: FirstOrderCache::new(n_x, n_eps, n_xi),
            rates: Rates::new(n_x, n_eps, n_xi),
            counters: Counters::default(),
            ws: Workspace::new(n_c, n_x, n_xi),
            layout,
            mech,
        };
        k.start_from_reference();
        k
    }

    /// Takes the reference configuration as the last solution when it
    /// solves the constraint equations for its ξ0 = (q0, u0): the first
    /// solve then predicts from it and stays on its branch, as every later
    /// solve stays on the branch of the one before (`branch_jump` in
    /// position.rs).
    fn start_from_reference(&mut self) {
        self.set_row_targets();
        self.eval_elements(true);
        let tol = self.settings.newton.tol * self.layout.length_scale.max(1e-6);
        if self.config.eps.iter().all(|v| v.is_finite()) && self.residual_norm() <= tol {
            let c = &mut self.config;
            c.branch.copy_from_slice(&c.eps);
            c.solved = true;
        }
    }
}
