//! Velocities ẋ = F,ξ ξ̇ and ε̇ = E,ξ ξ̇ (thesis (5.8a), (6.6a)) by a solve
//! with J, directly or by iterative refinement on a factorization of a nearby
//! configuration.

use crate::{Kinematics, KinematicsError};
use flexmb_model::ERole;

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
        self.set_xi_rates(qd);
        let (rates, first) = (&mut self.rates, &self.first);
        rates.xd.fill(0.0);
        rates.epsd.fill(0.0);
        for c in 0..self.layout.n_xi() {
            let v = rates.xid[c];
            if v == 0.0 {
                continue;
            }
            for (d, f) in rates.xd.iter_mut().zip(first.f.col_as_slice(c)) {
                *d += f * v;
            }
            for (d, e) in rates.epsd.iter_mut().zip(first.e.col_as_slice(c)) {
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
        self.ws.xi_dir.copy_from_slice(&self.rates.xid);
        self.solve_along_direction(false)?;
        self.scatter_solved_direction_into_xd();
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
            ("q̇", qd.len(), self.layout.n_q),
            ("F,q q̇", fq_qd.len(), self.mech.n_x()),
        ])?;
        self.set_xi_rates(qd);
        let n_q = self.layout.n_q;
        let mut solved = Ok(());
        if self.rates.xid[n_q..].iter().any(|v| *v != 0.0) {
            let dir = &mut self.ws.xi_dir;
            dir[..n_q].fill(0.0);
            dir[n_q..].copy_from_slice(&self.rates.xid[n_q..]);
            solved = self.solve_along_direction(false);
            if solved.is_ok() {
                self.scatter_solved_direction_into_xd();
            }
            for (v, a) in self.rates.xd.iter_mut().zip(fq_qd) {
                *v += a;
            }
        } else {
            self.rates.xd.copy_from_slice(fq_qd);
        }
        solved?;
        self.deformation_rates();
        Ok(())
    }

    /// ξ̇ = (q̇, u̇(t)).
    fn set_xi_rates(&mut self, qd: &[f64]) {
        let n_q = self.layout.n_q;
        let xid = &mut self.rates.xid;
        xid[..n_q].copy_from_slice(qd);
        for (k, u) in self.mech.inputs.iter().enumerate() {
            xid[n_q + k] = u.function.eval(self.config.t).1;
        }
    }

    /// ẋ from the solved direction (`ws.xi_dir`, `ws.dep`) of
    /// [`solve_along_direction`](Self::solve_along_direction).
    fn scatter_solved_direction_into_xd(&mut self) {
        let ws = &self.ws;
        self.layout
            .scatter_direction(&self.mech, &ws.xi_dir, &ws.dep, &mut self.rates.xd);
    }

    /// ε̇ from ξ̇ and ẋ: exact on the constraint rows (the rate of the DOF or
    /// input they are, or zero), D,x ẋ elsewhere.
    fn deformation_rates(&mut self) {
        let (layout, rates) = (&self.layout, &mut self.rates);
        let n_q = layout.n_q;
        for (j, r) in self.mech.e_roles.iter().enumerate() {
            if layout.row_of[j].is_some() {
                rates.epsd[j] = match r {
                    ERole::Dof(k) => rates.xid[*k],
                    ERole::Input(k) => rates.xid[n_q + k],
                    _ => 0.0,
                };
            }
        }
        for &(ei, a) in &layout.free_deformations {
            let e = &self.mech.elements[ei];
            let nx = layout.maps[ei].nx;
            let row = &self.jac.local[ei][a * nx..(a + 1) * nx];
            rates.epsd[e.eps_offset + a] = e
                .x_index
                .iter()
                .zip(row)
                .map(|(gi, d)| d * rates.xd[*gi])
                .sum();
        }
    }

    /// Solves the constraint equations differentiated along the direction
    /// of ξ = (q, u) in `ws.xi_dir`, J y_dep = B dir (minus D_c,xx\[ẋ, ẋ\] on
    /// the constraint rows when `convective`, the second time derivative
    /// (5.8b)), with [`solve_refined`](Self::solve_refined): y_dep into
    /// `ws.dep`. [`Layout::scatter_direction`](crate::layout::Layout::scatter_direction)
    /// of the two gives y over all nodal coordinates.
    pub(crate) fn solve_along_direction(
        &mut self,
        convective: bool,
    ) -> Result<(), KinematicsError> {
        let ws = &mut self.ws;
        self.layout.direction_rhs(
            &self.mech,
            &self.jac.local,
            convective.then_some(self.rates.dxx_vv.as_slice()),
            &ws.xi_dir,
            &mut ws.vel_rhs,
        );
        self.solve_refined()
    }

    /// Solves J(x) v = b, b = `ws.vel_rhs`, v into `ws.dep`, at the solved
    /// configuration: directly when the factorization is of this x, else
    /// by iterative refinement with the factorization of a nearby
    /// configuration, converged when the update, or the error it leaves
    /// (update × ρ/(1 − ρ) with the observed contraction ρ of the updates),
    /// is below 1e-14 of |v|; falling back to a fresh factorization when the
    /// updates do not shrink at least fourfold per step or
    /// [`MAX_REFINEMENTS`] steps do not converge.
    fn solve_refined(&mut self) -> Result<(), KinematicsError> {
        if !self.factorization.valid {
            self.factor_at_x()?;
        }
        let (ws, f) = (&mut self.ws, &mut self.factorization);
        let (b, v, res) = (&ws.vel_rhs, &mut ws.dep, &mut ws.vel_res);
        v.copy_from_slice(b);
        f.lu.solve_vec(v);
        if f.at_x {
            return Ok(());
        }
        // the first iterate's size stands for the initial error's bound
        let mut prev = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut converged = false;
        let mut steps = 0;
        for _ in 0..MAX_REFINEMENTS {
            steps += 1;
            self.counters.refinements += 1;
            res.copy_from_slice(b);
            self.layout.sub_jacobian_times(&self.jac.local, v, res);
            f.lu.solve_vec(res);
            let (mut d, mut vmax) = (0.0f64, 0.0f64);
            for (vi, ri) in v.iter_mut().zip(res.iter()) {
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
        if !converged {
            self.factor_at_x()?;
            let ws = &mut self.ws;
            ws.dep.copy_from_slice(&ws.vel_rhs);
            self.factorization.lu.solve_vec(&mut ws.dep);
        } else {
            f.extra_refinements += steps - 1;
            if f.extra_refinements >= REFRESH_BUDGET {
                // converged, but the factorization has aged: a fresh one here
                // serves the next evaluations (the result stays the refined one)
                self.factor_at_x()?;
            }
        }
        Ok(())
    }
}
