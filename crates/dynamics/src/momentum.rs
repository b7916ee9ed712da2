//! Total linear and angular momentum of a mechanism, exact for every inertia
//! element (beams, masses, rigid bodies, superelements).
//!
//! The kinetic energy T = ½ ẋᵀ Mx ẋ (thesis (2.34), (3.30)) is invariant under
//! a rigid translation and a rigid rotation of the whole mechanism, so by
//! Noether's theorem the momenta conjugate to those motions are the
//! projections of the generalized momenta p = Mx ẋ = ∂T/∂ẋ on their
//! generators. A translation δr moves every position by δr: the linear
//! momentum is L = Σ_i p_{r,i}. A rotation δθ (global axes) moves a position
//! by δθ × r and Euler parameters by δλ = ½ Λ(λ)ᵀ δθ (from ω = 2Λλ̇, (2.14)),
//! and leaves mode amplitudes η̄ and planar angles' offsets unchanged (a
//! planar angle moves by δθ_z): the angular momentum about a point a is
//! H_a = Σ_i (r_i − a) × p_{r,i} + ½ Σ_k Λ(λ_k) p_{λ,k}. Both are conserved
//! exactly by the equations of motion when no external force or moment
//! acts, so they are the test of the inertia forces that energy alone
//! cannot be (energy is blind to a force normal to the velocity).

use crate::{Dynamics, DynamicsError};
use flexmb_model::Dimension;
use flexmb_rotation::EulerParameters;

/// Linear and angular momentum of a mechanism (global axes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Momentum {
    /// Linear momentum L (planar: z = 0).
    pub linear: [f64; 3],
    /// Angular momentum about the point given (planar: only z).
    pub angular: [f64; 3],
}

impl Dynamics {
    /// Linear momentum and angular momentum about `about` at (t, q, q̇).
    pub fn momentum(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        about: [f64; 3],
    ) -> Result<Momentum, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        Ok(self.momentum_here(about))
    }

    /// As [`momentum`](Self::momentum) at the current kinematic state (after a
    /// solve with velocities).
    pub fn momentum_here(&self, about: [f64; 3]) -> Momentum {
        let x = self.kin.x();
        let mut p = vec![0.0; x.len()];
        self.mass_times_add(self.kin.xd(), &mut p);
        let mut linear = [0.0; 3];
        let mut angular = [0.0; 3];
        let spatial = self.mech.dimension == Dimension::Spatial;
        for node in &self.mech.nodes {
            let pr: Vec<f64> = node.position.iter().map(|&i| p[i]).collect();
            let r: Vec<f64> = node
                .position
                .iter()
                .enumerate()
                .map(|(k, &i)| x[i] - about[k])
                .collect();
            for k in 0..pr.len() {
                linear[k] += pr[k];
            }
            if spatial {
                angular[0] += r[1] * pr[2] - r[2] * pr[1];
                angular[1] += r[2] * pr[0] - r[0] * pr[2];
                angular[2] += r[0] * pr[1] - r[1] * pr[0];
            } else {
                angular[2] += r[0] * pr[1] - r[1] * pr[0];
            }
            match &node.orientation {
                Some(o) if o.len() == 4 => {
                    let l = EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]);
                    let lm = l.lambda();
                    for (k, h) in angular.iter_mut().enumerate() {
                        *h += 0.5 * (0..4).map(|j| lm[(k, j)] * p[o[j]]).sum::<f64>();
                    }
                }
                Some(o) if o.len() == 1 => angular[2] += p[o[0]],
                _ => {}
            }
        }
        Momentum { linear, angular }
    }
}
