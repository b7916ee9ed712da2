//! Reaction forces and moments at the supports: what the fixed and
//! prescribed nodal coordinates must receive to move as they do.
//!
//! The nodal equations of motion (thesis (2.40) with the virtual work of
//! (D.1)) hold at every nodal coordinate once the supports' forces r are
//! added: f + r = Mx ẍ + h + D,xᵀσ. At a free coordinate the equations of
//! motion make r zero; at a fixed or prescribed one r is the support's
//! reaction, r = Mx ẍ + h + D,xᵀσ − f, with ẍ = F,q q̈ + ẍ0 (ẍ0 the
//! convective accelerations for q̈ = 0).
//!
//! σ is zero on rigid and prescribed deformations (their stresses are
//! constraint forces the DOF formulation never needs): their multipliers
//! are found here as the least-squares solution that makes r vanish at every
//! coordinate without a support, so that each support gets its share.

use crate::{Dynamics, DynamicsError};

impl Dynamics {
    /// The generalized support forces r = Mx ẍ + h + D,xᵀσ − f at every
    /// nodal coordinate at (t, q, q̇, q̈) (q̈ from
    /// [`accelerations`](Self::accelerations), or zero in statics): the
    /// reaction at fixed and prescribed coordinates, zero elsewhere up to
    /// the accuracy of q̈. Moments follow from the Euler-parameter components
    /// as ½ Λ(λ) r_λ (see [`Dynamics::node_reaction`]).
    pub fn nodal_reactions(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Result<Vec<f64>, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        let mech = self.mech.clone();
        let view = self.kin.first_order_view();
        let n_q = mech.n_dof();
        // ẍ = ẍ0 + F,q q̈
        let mut xdd = view.xdd0.to_vec();
        for (k, a) in qdd.iter().enumerate().take(n_q) {
            if *a != 0.0 {
                for (v, f) in xdd.iter_mut().zip(view.f.col_as_slice(k)) {
                    *v += f * a;
                }
            }
        }
        let (x, xd) = (view.x, view.xd);
        let mut r: Vec<f64> = self.f.iter().map(|v| -v).collect();
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut al = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for e in mech.elements.iter().filter(|e| e.element.has_inertia()) {
            let n = e.x_index.len();
            e.gather(x, &mut xl[..n]);
            e.gather(xd, &mut vl[..n]);
            e.gather(&xdd, &mut al[..n]);
            e.element
                .inertia_force(&xl[..n], &vl[..n], &al[..n], &mut fl[..n]);
            e.scatter_add(&fl[..n], 1.0, &mut r);
        }
        self.kin.add_deformation_forces(&self.sigma, &mut r);
        self.add_constraint_stresses(&mut r);
        Ok(r)
    }

    /// Adds D,xᵀ μ to r, with μ the stresses of the rigid and prescribed
    /// deformations that make r zero at the coordinates without a support
    /// (least squares; exact at an equilibrium or along the equations of
    /// motion).
    fn add_constraint_stresses(&mut self, r: &mut [f64]) {
        use faer::linalg::solvers::SolveLstsq;
        let mech = self.mech.clone();
        let constrained: Vec<usize> = (0..mech.n_eps())
            .filter(|j| {
                matches!(
                    mech.e_roles[*j],
                    flexmb_model::ERole::Rigid | flexmb_model::ERole::Input(_)
                )
            })
            .collect();
        let unsupported: Vec<usize> = (0..mech.n_x())
            .filter(|i| {
                !matches!(
                    mech.x_roles[*i],
                    flexmb_model::XRole::Fixed | flexmb_model::XRole::Input(_)
                )
            })
            .collect();
        if constrained.is_empty() || unsupported.is_empty() {
            return;
        }
        // columns D,xᵀ e_j of the constrained deformations
        let mut unit = vec![0.0; mech.n_eps()];
        let mut cols = faer::Mat::<f64>::zeros(mech.n_x(), constrained.len());
        for (c, &j) in constrained.iter().enumerate() {
            unit[j] = 1.0;
            self.kin
                .add_deformation_forces(&unit, cols.col_as_slice_mut(c));
            unit[j] = 0.0;
        }
        // A μ = −r over the unsupported coordinates, least squares; with more
        // constraints than unsupported coordinates the system is padded with
        // zero rows (μ is then not unique, its forces at the supports are)
        let rows = unsupported.len().max(constrained.len());
        let a = faer::Mat::from_fn(rows, constrained.len(), |i, c| {
            unsupported.get(i).map_or(0.0, |&x| cols[(x, c)])
        });
        let mut b = faer::Mat::from_fn(rows, 1, |i, _| unsupported.get(i).map_or(0.0, |&x| -r[x]));
        a.qr().solve_lstsq_in_place(b.as_mut());
        for (c, _) in constrained.iter().enumerate() {
            let mu = b[(c, 0)];
            if mu.is_finite() && mu != 0.0 {
                for (ri, ci) in r.iter_mut().zip(cols.col_as_slice(c)) {
                    *ri += mu * ci;
                }
            }
        }
    }

    /// The reaction force and moment (about the node) on node `index` of
    /// the mechanism from the generalized support forces `r` of
    /// [`nodal_reactions`](Self::nodal_reactions), at the configuration of
    /// that call. Planar: the moment is along z.
    pub fn node_reaction(&self, r: &[f64], index: usize) -> ([f64; 3], [f64; 3]) {
        crate::momentum::node_resultant(self.kin.x(), r, &self.mech.nodes[index])
    }

    /// The total force and the total moment about `about` of the generalized
    /// forces `v` on the nodes (e.g. the support forces of
    /// [`nodal_reactions`](Self::nodal_reactions)), at the current
    /// configuration.
    pub fn total_force(&self, v: &[f64], about: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        self.resultant(v, about, |_| true)
    }
}

#[cfg(test)]
mod tests {
    use crate::Dynamics;
    use flexmb_model::Scene;
    use std::sync::Arc;

    fn fixture(name: &str) -> Dynamics {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/scenes")
            .join(name);
        Dynamics::new(Arc::new(Scene::load(&p).unwrap().build(None).unwrap()))
    }

    /// Newton–Euler for the whole mechanism: the supports' forces plus the
    /// applied ones (loads, gravity) are the rate of the total momentum,
    /// L̇ = Σ (r + f)_r and Ḣ = Σ (x × (r + f)_r + ½Λ(r + f)_λ), with L̇, Ḣ
    /// by central differences along (q̇, q̈).
    fn check_momentum_balance(dy: &mut Dynamics, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        let n = q.len();
        let mut qdd = vec![0.0; n];
        dy.accelerations(t, q, qd, &mut qdd).unwrap();
        let r = dy.nodal_reactions(t, q, qd, &qdd).unwrap();
        let rf: Vec<f64> = r.iter().zip(&dy.f).map(|(a, b)| a + b).collect();
        let about = [0.0; 3];
        let (force, moment) = dy.total_force(&rf, about);
        let h = 1e-6;
        let at = |s: f64, dy: &mut Dynamics| {
            let qs: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a + s * b).collect();
            let vs: Vec<f64> = qd.iter().zip(&qdd).map(|(a, b)| a + s * b).collect();
            dy.momentum(t + s, &qs, &vs, about).unwrap()
        };
        let (p, m) = (at(h, dy), at(-h, dy));
        let mut worst = 0.0f64;
        let scale = force
            .iter()
            .chain(&moment)
            .fold(1e-12f64, |s, v| s.max(v.abs()));
        for k in 0..3 {
            let ld = (p.linear[k] - m.linear[k]) / (2.0 * h);
            let hd = (p.angular[k] - m.angular[k]) / (2.0 * h);
            worst = worst.max((ld - force[k]).abs() / scale);
            worst = worst.max((hd - moment[k]).abs() / scale);
        }
        worst
    }

    #[test]
    fn support_forces_close_the_momentum_balance() {
        for (name, t) in [
            ("straight_guidance_spatial.ron", 0.05),
            ("straight_guidance_planar.ron", 0.05),
            ("flexible_pendulum.ron", 0.0),
            ("manipulator_planar.ron", 0.3),
        ] {
            let mut dy = fixture(name);
            let q0 = dy.mechanism().q0();
            // a moving state: the initial velocities plus a rate on every DOF
            let mut qd = dy.initial_qd(0.0, &q0).unwrap();
            for (k, v) in qd.iter_mut().enumerate() {
                *v += 0.3 * ((k as f64) * 0.7).sin();
            }
            let worst = check_momentum_balance(&mut dy, t, &q0, &qd);
            assert!(
                worst < 1e-6,
                "{name}: momentum balance off by {worst:e} of the forces"
            );
        }
    }

    #[test]
    fn in_statics_the_reactions_balance_the_loads() {
        let mut dy = fixture("straight_guidance_spatial.ron");
        let q0 = dy.mechanism().q0();
        let sol = dy
            .static_equilibrium(0.05, &q0, &crate::StaticOptions::default())
            .unwrap();
        let n = sol.q.len();
        let zero = vec![0.0; n];
        let r = dy.nodal_reactions(0.05, &sol.q, &zero, &zero).unwrap();
        // free coordinates carry no reaction
        let free_max = dy
            .mechanism()
            .x_roles
            .iter()
            .zip(&r)
            .filter(|(role, _)| {
                !matches!(
                    role,
                    flexmb_model::XRole::Fixed | flexmb_model::XRole::Input(_)
                )
            })
            .fold(0.0f64, |m, (_, v)| m.max(v.abs()));
        let (force, moment) = dy.total_force(&r, [0.0; 3]);
        let rmax = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(free_max < 1e-6 * rmax, "{free_max:e} at a free coordinate");
        let f: Vec<f64> = dy.f.clone();
        let (load, load_moment) = dy.total_force(&f, [0.0; 3]);
        for k in 0..3 {
            assert!(
                (force[k] + load[k]).abs() < 1e-8 * rmax,
                "force {k}: {force:?} + {load:?}"
            );
            assert!(
                (moment[k] + load_moment[k]).abs() < 1e-8 * rmax,
                "moment {k}"
            );
        }
        // the weight is carried: 1.368 kg body + flexures under 9.81 m/s²
        assert!(force[2] > 0.0);
    }
}
