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
        let mut p = vec![0.0; self.kin.x().len()];
        self.mass_times_add(self.kin.xd(), &mut p);
        let (linear, angular) = self.resultant(&p, about, |_| true);
        Momentum { linear, angular }
    }

    /// The resultant of a covariant nodal vector v (generalized momenta, or
    /// nodal forces) over the nodes `keep` selects, at the current
    /// configuration: its projections on a rigid translation, Σ v_r, and on a
    /// rigid rotation about `about`, Σ (r − a) × v_r + ½ Σ Λ(λ) v_λ (planar:
    /// plus v_φ). For forces these are the total force and the total moment.
    /// Nodes that share their position (`position_of`, e.g. the two nodes of
    /// a hinge) count it once: a rigid translation moves each position
    /// coordinate once.
    pub(crate) fn resultant(
        &self,
        v: &[f64],
        about: [f64; 3],
        keep: impl Fn(&flexmb_model::NodeInfo) -> bool,
    ) -> ([f64; 3], [f64; 3]) {
        let x = self.kin.x();
        let mut linear = [0.0; 3];
        let mut angular = [0.0; 3];
        let spatial = self.mech.dimension == Dimension::Spatial;
        let mut counted = vec![false; x.len()];
        for node in self.mech.nodes.iter().filter(|n| keep(n)) {
            let (mut force, moment) = node_resultant(x, v, node);
            if node.position.iter().any(|&i| counted[i]) {
                force = [0.0; 3];
            }
            let mut r = [0.0; 3];
            for (k, &i) in node.position.iter().enumerate() {
                counted[i] = true;
                r[k] = x[i] - about[k];
                linear[k] += force[k];
            }
            if spatial {
                angular[0] += r[1] * force[2] - r[2] * force[1];
                angular[1] += r[2] * force[0] - r[0] * force[2];
            }
            angular[2] += r[0] * force[1] - r[1] * force[0];
            for k in 0..3 {
                angular[k] += moment[k];
            }
        }
        (linear, angular)
    }
}

/// The force (the position components of v) and the moment about the node
/// itself (½ Λ(λ) v_λ, from δλ = ½ Λᵀ δθ of (2.14); planar: v_φ in z) of a
/// covariant nodal vector v at one node.
pub(crate) fn node_resultant(
    x: &[f64],
    v: &[f64],
    node: &flexmb_model::NodeInfo,
) -> ([f64; 3], [f64; 3]) {
    let mut force = [0.0; 3];
    for (k, &i) in node.position.iter().enumerate() {
        force[k] = v[i];
    }
    let mut moment = [0.0; 3];
    match &node.orientation {
        Some(o) if o.len() == 4 => {
            let lm = EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]).lambda();
            for (k, m) in moment.iter_mut().enumerate() {
                *m = 0.5 * (0..4).map(|j| lm[(k, j)] * v[o[j]]).sum::<f64>();
            }
        }
        Some(o) if o.len() == 1 => moment[2] = v[o[0]],
        _ => {}
    }
    (force, moment)
}
