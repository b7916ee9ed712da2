//! The convective terms D,xx\[ẋ, ẋ\] and the accelerations for q̈ = 0,
//! ẍ0 = F,u ü + (F,ξξ ξ̇)ξ̇ and ε̈0, by one more solve with J
//! (thesis (5.8b), (6.6b)); and ẍ for a given q̈ in one refined solve.

use crate::{Kinematics, KinematicsError};
use flexmb_model::ERole;

impl Kinematics {
    /// The convective terms D,xx\[ẋ, ẋ\] of every deformation at the current
    /// configuration and velocities (zero for elements at rest), the
    /// velocity-quadratic part of ε̈ = D,x ẍ + D,xx\[ẋ, ẋ\] (thesis (5.8b)).
    pub fn convective_terms(&mut self) -> &[f64] {
        let rates = &mut self.rates;
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.layout.maps[ei];
            if m.ne == 0 {
                continue;
            }
            let mut moving = false;
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = self.config.x[*gi];
                vl[k] = rates.xd[*gi];
                moving |= vl[k] != 0.0;
            }
            let out = &mut rates.dxx_vv[e.eps_offset..e.eps_offset + m.ne];
            if moving {
                e.element
                    .deformation_second_derivative(&xl[..m.nx], &vl[..m.nx], &vl[..m.nx], out);
            } else {
                out.fill(0.0);
            }
        }
        &self.rates.dxx_vv
    }

    /// The accelerations for q̈ = 0: ẍ0 = F,u ü + (F,ξξ ξ̇)ξ̇ and the matching
    /// ε̈0, by one solve with −D,xx\[ẋ, ẋ\] (thesis (5.8b)). Call after
    /// [`velocities`](Self::velocities). Then ẍ = F,q q̈ + ẍ0.
    pub fn accelerations(&mut self) {
        self.ensure_lu_at_x();
        // c = D,xx[ẋ, ẋ] per element
        self.convective_terms();
        // the direction ξ̈ = (0, ü)
        self.second_derivative_direction(None);
        let (layout, mech, rates, ws) = (&self.layout, &*self.mech, &mut self.rates, &mut self.ws);
        rates.epsdd0.copy_from_slice(&rates.dxx_vv);
        let dir = &ws.xi_dir;
        layout.direction_rhs(mech, &self.jac.local, Some(&rates.dxx_vv), dir, &mut ws.dep);
        self.factorization.lu.solve_vec(&mut ws.dep);
        layout.scatter_direction(mech, dir, &ws.dep, &mut rates.xdd0);
        // ε̈0 = D,x ẍ0 + D,xx[ẋ, ẋ] (rows: exact targets)
        let n_q = layout.n_q;
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &layout.maps[ei];
            let jl = &self.jac.local[ei];
            for a in 0..m.ne {
                let j = e.eps_offset + a;
                if layout.row_of[j].is_some() {
                    rates.epsdd0[j] = match mech.e_roles[j] {
                        ERole::Input(k) => dir[n_q + k],
                        _ => 0.0,
                    };
                    continue;
                }
                let mut s = rates.epsdd0[j];
                for (cc, gi) in e.x_index.iter().enumerate() {
                    s += jl[a * m.nx + cc] * rates.xdd0[*gi];
                }
                rates.epsdd0[j] = s;
            }
        }
    }

    /// The nodal accelerations ẍ = F,q q̈ + F,u ü + (F,ξξ ξ̇)ξ̇ for the given
    /// q̈ (n_q entries) at the current configuration and velocities (after
    /// [`velocities_refined`](Self::velocities_refined) or
    /// [`velocities`](Self::velocities)), into `xdd` (n_x entries), without
    /// F,ξ: D,xx\[ẋ, ẋ\] ([`convective_terms`](Self::convective_terms),
    /// updated here) and one solve of the constraint equations
    /// differentiated twice (thesis (5.8b)), refined against the exact J(x)
    /// as the velocities are. A reduced model's q̈ = G,z z̈ + (G,zz ż)ż
    /// needs it for q̈ = (G,zz ż)ż: the whole convective part of ẍ in one
    /// solve (thesis (6.15)).
    pub fn accelerations_refined(
        &mut self,
        qdd: &[f64],
        xdd: &mut [f64],
    ) -> Result<(), KinematicsError> {
        self.check_lengths(&[
            ("q̈", qdd.len(), self.layout.n_q),
            ("ẍ", xdd.len(), self.mech.n_x()),
        ])?;
        self.convective_terms();
        self.second_derivative_direction(Some(qdd));
        self.solve_along_direction(true)?;
        self.layout
            .scatter_direction(&self.mech, &self.ws.xi_dir, &self.ws.dep, xdd);
        Ok(())
    }

    /// ξ̈ = (q̈, ü(t)) into `ws.xi_dir`, q̈ = 0 when not given.
    fn second_derivative_direction(&mut self, qdd: Option<&[f64]>) {
        let n_q = self.layout.n_q;
        let dir = &mut self.ws.xi_dir;
        match qdd {
            Some(qdd) => dir[..n_q].copy_from_slice(qdd),
            None => dir[..n_q].fill(0.0),
        }
        for (k, u) in self.mech.inputs.iter().enumerate() {
            dir[n_q + k] = u.function.eval(self.config.t).2;
        }
    }
}
