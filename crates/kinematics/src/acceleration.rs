//! The convective terms D,xx\[ẋ, ẋ\] and the accelerations for q̈ = 0,
//! ẍ0 = F,u ü + (F,ξξ ξ̇)ξ̇ and ε̈0, by one more solve with J
//! (thesis (5.8b), (6.6b)).

use crate::Kinematics;
use flexmb_model::{Coordinate, ERole, XRole};

impl Kinematics {
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
}
