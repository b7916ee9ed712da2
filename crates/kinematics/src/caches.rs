//! The derivative caches of [`Kinematics`](crate::Kinematics), each with
//! the flag that says whether it is of the current configuration x:
//!
//! * [`ElementJacobians`]: the element Jacobians D,x, of x when `at_x`.
//!   Newton's trial steps evaluate ε alone and clear `at_x`; a converged
//!   solve and a restored configuration evaluate them at x, so after every
//!   solve (successful or not) they are of the configuration it left. Every
//!   product with B, J or D,x reads them there.
//! * [`Factorization`]: the LU of J. `valid` says it holds a usable
//!   factorization, of x or of a nearby earlier configuration (chord
//!   steps, refined solves); `at_x` that it is of x itself. `at_x` implies
//!   `valid`: both are set by a successful factorization only, a failed one
//!   clears both, and every move of x (a Newton step, the predictor, the
//!   known coordinates of a new target, a guess) clears `at_x`. A failed
//!   solve clears both, since its last factorization may be of a
//!   configuration far off, neither at x nor fit to predict from.
//! * [`FirstOrderCache`]: F,ξ and E,ξ, of x when `valid`. Set by
//!   [`Kinematics::first_order`](crate::Kinematics::first_order); cleared by
//!   every solve (after its predictor read them), a guess and a failed
//!   solve. The readers compute them first when stale, so no public
//!   accessor returns them of another configuration.

use crate::jacobian_lu::JacobianLu;
use faer::Mat;
use flexmb_model::Mechanism;

/// The local deformation Jacobians D,x of every element (row-major,
/// n_ε,e × n_x,e).
pub(crate) struct ElementJacobians {
    /// D,x of each element, at the x of the last evaluation with Jacobians.
    pub(crate) local: Vec<Vec<f64>>,
    /// `local` is of the current x (the last element evaluation computed
    /// them).
    pub(crate) at_x: bool,
}

impl ElementJacobians {
    /// Zeros of each element's size, not of any configuration.
    pub(crate) fn new(mech: &Mechanism) -> Self {
        let local = mech
            .elements
            .iter()
            .map(|e| vec![0.0; e.element.n_eps() * e.element.n_x()])
            .collect();
        Self { local, at_x: false }
    }
}

/// The LU factorization of the kinematic Jacobian J (sparse, or dense when
/// small) and what it is of.
pub(crate) struct Factorization {
    /// The factorization, with J's pattern and work memory.
    pub(crate) lu: JacobianLu,
    /// `lu` holds a usable factorization (of x or of a nearby configuration).
    pub(crate) valid: bool,
    /// `lu` is of the current x; implies `valid`.
    pub(crate) at_x: bool,
    /// Refinement steps beyond the first since the last factorization (the
    /// ski-rental budget of the refined velocity solves; reset by every
    /// factorization).
    pub(crate) extra_refinements: usize,
}

impl Factorization {
    /// `lu` set up but not factorized.
    pub(crate) fn new(lu: JacobianLu) -> Self {
        Self {
            lu,
            valid: false,
            at_x: false,
            extra_refinements: 0,
        }
    }

    /// Forgets the factorization: neither of x nor usable to predict or
    /// refine from (after a failed factorization or solve).
    pub(crate) fn invalidate(&mut self) {
        self.valid = false;
        self.at_x = false;
    }
}

/// The first-order transfer functions F,ξ and E,ξ (thesis (5.8a), (6.6a)).
pub(crate) struct FirstOrderCache {
    /// F,ξ (n_x × (n_q + n_u)). Its rows of fixed coordinates are zero and
    /// those of the coordinates in ξ unit vectors at every configuration:
    /// [`Kinematics::first_order`](crate::Kinematics::first_order) writes
    /// only the dependent rows.
    pub(crate) f: Mat<f64>,
    /// E,ξ (n_ε × (n_q + n_u)).
    pub(crate) e: Mat<f64>,
    /// `f` and `e` are of the current configuration.
    pub(crate) valid: bool,
}

impl FirstOrderCache {
    /// Zeros, not of any configuration.
    pub(crate) fn new(n_x: usize, n_eps: usize, n_xi: usize) -> Self {
        Self {
            f: Mat::zeros(n_x, n_xi),
            e: Mat::zeros(n_eps, n_xi),
            valid: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Kinematics, NewtonOptions};
    use flexmb_model::Scene;
    use std::path::Path;
    use std::sync::Arc;

    fn guidance() -> Kinematics {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/scenes/straight_guidance_spatial.ron");
        Kinematics::new(Arc::new(Scene::load(&p).unwrap().build(None).unwrap()))
    }

    /// The invariant that holds at every point: a factorization of x is a
    /// usable one.
    fn assert_at_x_implies_valid(k: &Kinematics, when: &str) {
        let f = &k.factorization;
        assert!(!f.at_x || f.valid, "{when}: at_x without valid");
    }

    /// The flags say what the module documentation says through solves,
    /// chord solves, guesses and a failed solve.
    #[test]
    fn cache_flags_follow_their_documented_invariants() {
        let mut k = guidance();
        assert_at_x_implies_valid(&k, "new");
        // the reference solves the constraints for ξ0: it counts as solved
        // (the first solve predicts from it), with no factorization yet
        assert!(!k.factorization.valid && !k.first.valid && k.config.solved && k.jac.at_x);
        let q0 = k.mechanism().q0();
        let q = |s: f64| -> Vec<f64> {
            q0.iter()
                .enumerate()
                .map(|(i, v)| v + s * ((i % 7) as f64 - 3.0))
                .collect()
        };

        k.solve(&q(1e-4), 0.0).unwrap();
        assert_at_x_implies_valid(&k, "solve");
        assert!(k.factorization.at_x && k.jac.at_x && k.config.solved);
        assert!(!k.first.valid, "a solve leaves F,ξ stale");
        assert_eq!(k.config.x_good, k.config.x);
        assert_eq!(k.config.branch, k.config.eps);

        k.first_order();
        assert!(k.first.valid);

        // a chord solve to a nearby q converges without refactorizing at x
        k.solve_chord(&q(1.1e-4), 0.0).unwrap();
        assert_at_x_implies_valid(&k, "solve_chord");
        assert!(k.jac.at_x && k.factorization.valid && !k.first.valid);
        let chord_at_x = k.factorization.at_x;
        k.velocities_refined(&vec![1e-2; k.n_q()]).unwrap();
        assert_at_x_implies_valid(&k, "velocities_refined");
        assert!(
            chord_at_x || k.counters.refinements > 0,
            "velocities on an older factorization are refined"
        );
        // F,ξ needs J at x: reading it factorizes there
        k.f_xi();
        assert!(k.factorization.at_x && k.first.valid);

        let x = k.x().to_vec();
        k.set_guess(&x);
        assert_at_x_implies_valid(&k, "set_guess");
        assert!(!k.config.solved && !k.jac.at_x && !k.factorization.at_x && !k.first.valid);

        k.solve(&q(1.2e-4), 0.0).unwrap();
        let (x_good, xi_good) = (k.x().to_vec(), k.xi().to_vec());
        k.first_order();
        // no iteration allowed: the solve and its continuation fail
        k.set_newton_options(NewtonOptions {
            max_iterations: 0,
            ..NewtonOptions::default()
        });
        assert!(k.solve(&q(1e-2), 0.0).is_err());
        assert_at_x_implies_valid(&k, "a failed solve");
        assert!(!k.factorization.valid && !k.first.valid);
        assert!(k.config.solved && k.jac.at_x);
        assert_eq!(k.x(), &x_good[..]);
        assert_eq!(k.xi(), &xi_good[..]);
    }
}
