//! Velocities ẋ = F,ξ ξ̇ and ε̇ = E,ξ ξ̇ (thesis (5.8a), (6.6a)) by a solve
//! with J, directly or by iterative refinement on a factorization of a nearby
//! configuration.

use crate::{Kinematics, KinematicsError};
use flexmb_model::{ERole, XRole};

/// Iterative-refinement steps of a velocity solve with a factorization of
/// a nearby configuration before J is factorized afresh at x. Each step costs
/// a product with J and a solve, a few microseconds for the 77 × 77 Jacobian
/// of the spatial guidance against about 12 µs for a factorization.
const MAX_REFINEMENTS: usize = 3;

/// Relative accuracy of a refined velocity solve (the error left in ẋ), at
/// the level of a direct solve's rounding. 1e-12 saved refinement steps but
/// measured no faster over a response from equilibrium.
const REFINED_TOL: f64 = 1e-14;

/// Refinement steps beyond the first, summed since the last factorization,
/// after which J is factorized afresh at x for the next solves although the
/// refinement converged: a factorization then costs about what the extra
/// steps did (ski-rental rule). Measured on the spatial guidance: along the
/// first 2 ms from rest (`cargo bench -p flexmb-dynamics --bench eom`) a
/// refresh after every two-step solve beat never refreshing by 14 %, while
/// over 0.05 s of the response from equilibrium it factorized at 43 % of
/// the evaluations and was 10–15 % slower than this budget of six, which
/// factorizes at 15 % of them (the machine's noise is ±10 %).
const REFRESH_BUDGET: usize = 6;

impl Kinematics {
    /// ẋ = F,ξ ξ̇ and ε̇ = E,ξ ξ̇ with ξ̇ = (q̇, u̇(t)), with F,ξ and E,ξ of the
    /// current configuration (computed first if stale).
    pub fn velocities(&mut self, qd: &[f64]) {
        self.ensure_first_order();
        let (n_q, n_u) = (self.n_q, self.n_u);
        self.xid[..n_q].copy_from_slice(qd);
        for k in 0..n_u {
            self.xid[n_q + k] = self.mech.inputs[k].function.eval(self.t).1;
        }
        let n_xi = n_q + n_u;
        self.xd.fill(0.0);
        self.epsd.fill(0.0);
        for c in 0..n_xi {
            let v = self.xid[c];
            if v == 0.0 {
                continue;
            }
            for (d, f) in self.xd.iter_mut().zip(self.f.col_as_slice(c)) {
                *d += f * v;
            }
            for (d, e) in self.epsd.iter_mut().zip(self.e.col_as_slice(c)) {
                *d += e * v;
            }
        }
    }

    /// ẋ and ε̇ for ξ̇ = (q̇, u̇(t)) without F,ξ: one solve of
    /// J ẋ_dep = ė_c − D_c,x_ξ ẋ_ξ (the time derivative of the constraint
    /// equations D_c(x) = (0, q_ε, u_ε), thesis (5.8a)) with the factorization of
    /// J at hand. After [`solve_chord`](Self::solve_chord) that factorization
    /// may be of a nearby configuration: the solution is then refined against
    /// the exact J(x) (iterative refinement), and J is factorized afresh only
    /// if the refinement does not contract fast. ε̇ is exact on the constraint
    /// rows and D,x ẋ elsewhere.
    pub fn velocities_refined(&mut self, qd: &[f64]) -> Result<(), KinematicsError> {
        let (n_q, n_u) = (self.n_q, self.n_u);
        self.xid[..n_q].copy_from_slice(qd);
        for k in 0..n_u {
            self.xid[n_q + k] = self.mech.inputs[k].function.eval(self.t).1;
        }
        let mut rhs = std::mem::take(&mut self.vel_rhs);
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            rhs[r] = match self.mech.e_roles[*j] {
                ERole::Dof(k) => self.xid[k],
                ERole::Input(k) => self.xid[n_q + k],
                _ => 0.0,
            };
        }
        let xid = &self.xid;
        self.for_each_nodal_xi_entry(|r, k, d| rhs[r] -= d * xid[k]);
        let mut v = std::mem::take(&mut self.rhs_vec);
        let solved = self.solve_refined(&rhs, &mut v);
        self.vel_rhs = rhs;
        if let Err(e) = solved {
            self.rhs_vec = v;
            return Err(e);
        }
        for (i, r) in self.mech.x_roles.iter().enumerate() {
            self.xd[i] = match r {
                XRole::Fixed => 0.0,
                XRole::Dof(k) => self.xid[*k],
                XRole::Input(k) => self.xid[n_q + k],
                XRole::Dependent(k) => v[*k],
            };
        }
        self.rhs_vec = v;
        for (j, r) in self.mech.e_roles.iter().enumerate() {
            if self.row_of[j].is_some() {
                self.epsd[j] = match r {
                    ERole::Dof(k) => self.xid[*k],
                    ERole::Input(k) => self.xid[n_q + k],
                    _ => 0.0,
                };
            }
        }
        for &(ei, a) in &self.free_deformations {
            let e = &self.mech.elements[ei];
            let nx = self.maps[ei].nx;
            let row = &self.jac_local[ei][a * nx..(a + 1) * nx];
            self.epsd[e.eps_offset + a] = e
                .x_index
                .iter()
                .zip(row)
                .map(|(gi, d)| d * self.xd[*gi])
                .sum();
        }
        Ok(())
    }

    /// Solves J(x) v = b at the solved configuration: directly when the
    /// factorization is of this x, else by iterative refinement with the
    /// factorization of a nearby configuration, converged when the update,
    /// or the error it leaves (update × ρ/(1 − ρ) with the observed
    /// contraction ρ of the updates), is below 1e-14 of |v|; falling back to
    /// a fresh factorization when the updates do not shrink at least
    /// fourfold per step or [`MAX_REFINEMENTS`] steps do not converge.
    fn solve_refined(&mut self, b: &[f64], v: &mut [f64]) -> Result<(), KinematicsError> {
        if !self.lu_valid {
            self.factor_at_x()?;
        }
        v.copy_from_slice(b);
        self.lu.solve_vec(v);
        if self.lu_at_x {
            return Ok(());
        }
        let mut res = std::mem::take(&mut self.vel_res);
        // the first iterate's size stands for the initial error's bound
        let mut prev = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut converged = false;
        let mut steps = 0;
        for _ in 0..MAX_REFINEMENTS {
            steps += 1;
            self.refinements += 1;
            res.copy_from_slice(b);
            self.sub_jacobian_times(v, &mut res);
            self.lu.solve_vec(&mut res);
            let (mut d, mut vmax) = (0.0f64, 0.0f64);
            for (vi, ri) in v.iter_mut().zip(&res) {
                *vi += ri;
                d = d.max(ri.abs());
                vmax = vmax.max(vi.abs());
            }
            if !d.is_finite() {
                break;
            }
            // with the observed contraction ρ = d/d_prev the error left after
            // this update is about d ρ/(1 − ρ)
            let rho = if prev > 0.0 { d / prev } else { 0.0 };
            if d <= REFINED_TOL * vmax
                || (rho < 0.25 && d * rho / (1.0 - rho) <= REFINED_TOL * vmax)
            {
                converged = true;
                break;
            }
            if rho > 0.25 {
                break;
            }
            prev = d;
        }
        self.vel_res = res;
        if !converged {
            self.factor_at_x()?;
            v.copy_from_slice(b);
            self.lu.solve_vec(v);
        } else {
            self.extra_refinements += steps - 1;
            if self.extra_refinements >= REFRESH_BUDGET {
                // converged, but the factorization has aged: a fresh one here
                // serves the next evaluations (the result stays the refined one)
                self.factor_at_x()?;
            }
        }
        Ok(())
    }

    /// out −= J(x) v, J = ∂D_c/∂x_dep from the element Jacobians at x.
    fn sub_jacobian_times(&self, v: &[f64], out: &mut [f64]) {
        for (m, jl) in self.maps.iter().zip(&self.jac_local) {
            for (a, r) in m.rows.iter().enumerate() {
                let Some(r) = r else { continue };
                let row = &jl[a * m.nx..(a + 1) * m.nx];
                let mut s = 0.0;
                for (c, col) in m.cols.iter().enumerate() {
                    if let Some(k) = col {
                        s += row[c] * v[*k];
                    }
                }
                out[*r] -= s;
            }
        }
    }
}
