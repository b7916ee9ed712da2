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
        self.set_xi_rates(qd);
        let xid = std::mem::take(&mut self.xid);
        let mut xd = std::mem::take(&mut self.xd);
        let solved = self.solve_direction(&xid, false, &mut xd);
        self.xid = xid;
        self.xd = xd;
        solved?;
        self.deformation_rates();
        Ok(())
    }

    /// ẋ and ε̇ for q̇ (n_q entries) whose nodal velocity F,q q̇ (n_x
    /// entries) the caller already has, e.g. F,z ż of a reduced model from
    /// the columns F,z = F,q G,z ([`transfer_matrix`](Self::transfer_matrix)):
    /// ẋ = F,q q̇ + F,u u̇(t), the inputs' part by one solve as in
    /// [`velocities_refined`](Self::velocities_refined) (none when no input
    /// moves), and ε̇ from ẋ. The result is that of `velocities_refined(q̇)`
    /// to rounding if `fq_qd` is F,q q̇ at the current configuration.
    pub fn velocities_from(&mut self, qd: &[f64], fq_qd: &[f64]) -> Result<(), KinematicsError> {
        self.check_lengths(&[
            ("q̇", qd.len(), self.n_q),
            ("F,q q̇", fq_qd.len(), self.mech.n_x()),
        ])?;
        self.set_xi_rates(qd);
        let n_q = self.n_q;
        let mut xd = std::mem::take(&mut self.xd);
        let mut solved = Ok(());
        if self.xid[n_q..].iter().any(|v| *v != 0.0) {
            let mut dir = std::mem::take(&mut self.xi_dir);
            dir[..n_q].fill(0.0);
            dir[n_q..].copy_from_slice(&self.xid[n_q..]);
            solved = self.solve_direction(&dir, false, &mut xd);
            self.xi_dir = dir;
            for (v, a) in xd.iter_mut().zip(fq_qd) {
                *v += a;
            }
        } else {
            xd.copy_from_slice(fq_qd);
        }
        self.xd = xd;
        solved?;
        self.deformation_rates();
        Ok(())
    }

    /// ξ̇ = (q̇, u̇(t)).
    fn set_xi_rates(&mut self, qd: &[f64]) {
        let n_q = self.n_q;
        self.xid[..n_q].copy_from_slice(qd);
        for (k, u) in self.mech.inputs.iter().enumerate() {
            self.xid[n_q + k] = u.function.eval(self.t).1;
        }
    }

    /// ε̇ from ξ̇ and ẋ: exact on the constraint rows (the rate of the DOF or
    /// input they are, or zero), D,x ẋ elsewhere.
    fn deformation_rates(&mut self) {
        let n_q = self.n_q;
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
    }

    /// Solves the constraint equations differentiated along the direction
    /// `dir` of ξ = (q, u), J y_dep = B dir (minus D_c,xx\[ẋ, ẋ\] on the
    /// constraint rows when `convective`, the second time derivative (5.8b)),
    /// with [`solve_refined`](Self::solve_refined), and writes y over all
    /// nodal coordinates into `out`: `dir` on those in ξ, zero on the fixed
    /// ones.
    pub(crate) fn solve_direction(
        &mut self,
        dir: &[f64],
        convective: bool,
        out: &mut [f64],
    ) -> Result<(), KinematicsError> {
        let mut rhs = std::mem::take(&mut self.vel_rhs);
        self.direction_rhs(dir, convective, &mut rhs);
        let mut v = std::mem::take(&mut self.rhs_vec);
        let solved = self.solve_refined(&rhs, &mut v);
        if solved.is_ok() {
            self.scatter_direction(dir, &v, out);
        }
        self.vel_rhs = rhs;
        self.rhs_vec = v;
        solved
    }

    /// The right-hand side B dir of J y_dep = B dir for a direction `dir`
    /// of ξ (thesis (5.8a)): `dir`'s entry on the rows of degree-of-freedom
    /// and prescribed deformations, minus D_c,x_i dir_i over the nodal
    /// coordinates x_i in ξ; started from −D_c,xx\[ẋ, ẋ\] (of the last
    /// [`convective_terms`](Self::convective_terms)) when `convective`.
    pub(crate) fn direction_rhs(&self, dir: &[f64], convective: bool, rhs: &mut [f64]) {
        let n_q = self.n_q;
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            rhs[r] = if convective { -self.dxx_vv[*j] } else { 0.0 };
            match self.mech.e_roles[*j] {
                ERole::Dof(k) => rhs[r] += dir[k],
                ERole::Input(k) => rhs[r] += dir[n_q + k],
                _ => {}
            }
        }
        self.for_each_nodal_xi_entry(|r, k, d| rhs[r] -= d * dir[k]);
    }

    /// A direction over all nodal coordinates from its ξ part `dir` and the
    /// solved dependent part `dep` (zero on fixed coordinates).
    pub(crate) fn scatter_direction(&self, dir: &[f64], dep: &[f64], out: &mut [f64]) {
        let n_q = self.n_q;
        for (i, r) in self.mech.x_roles.iter().enumerate() {
            out[i] = match r {
                XRole::Fixed => 0.0,
                XRole::Dof(k) => dir[*k],
                XRole::Input(k) => dir[n_q + k],
                XRole::Dependent(k) => dep[*k],
            };
        }
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
        for (r, (element, entries)) in &self.dep_rows {
            let jl = &self.jac_local[*element];
            let s: f64 = self.dep_entries[entries.clone()]
                .iter()
                .map(|(k, local)| jl[*local] * v[*k])
                .sum();
            out[*r] -= s;
        }
    }
}
