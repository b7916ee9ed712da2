//! The position solve x = F(q, u), ε = E(q, u) (thesis (5.7), (6.5)) by
//! Newton's method on the constraint equations D_c(x) = (0, q_ε, u_ε), with a
//! first-order predictor, chord steps on a kept factorization of J and
//! continuation from the last solution.

use crate::{Kinematics, KinematicsError, NO_ENTRY};
use flexmb_model::{ERole, XRole};

/// A residual within this many ε·max|x| is at the rounding level of the
/// coordinates it is computed from (a difference of two coordinates of size
/// |x| carries an error of a few ε|x|; a deformation sums a few of them).
const ROUNDING_RESIDUALS: f64 = 64.0;

/// A converged solve whose Newton corrections moved a dependent coordinate
/// by more than this fraction of the prediction's largest motion is taken for
/// a step too large for the branch (continued from the last solution in
/// smaller steps). Along a smooth branch the ratio is of the order of the
/// step over the branch's radius of curvature; a solve that folded a
/// two-link arm's elbow the other way had 0.37, legitimate steps of a tenth
/// of the curvature radius have a few hundredths.
const BRANCH_RATIO: f64 = 0.25;

/// The continuation's finest division of a step, where a correction up to
/// the whole predicted motion passes the branch guard.
const FINEST_STEPS: usize = 64;

/// Newton corrections below this fraction of the mechanism's length scale
/// are never taken for a jump to another branch (a branch is a finite
/// distance away; smaller corrections are of steps from a poor prediction).
const BRANCH_NOISE: f64 = 1e-3;

/// Newton settings of the position solve.
#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    /// Converged when every constraint residual |D_c(x) − target| ≤ `tol`·L,
    /// L the mean element length (residuals are lengths or dimensionless), or
    /// when the Newton update is at rounding level (≤ 8 ε max|x|) with the
    /// residual below 1000·`tol`·L or at the rounding level of the
    /// coordinates (64 ε max|x|, x the dependent coordinates, at least 1).
    pub tol: f64,
    /// Iteration limit.
    pub max_iterations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tol: 1e-12,
            max_iterations: 30,
        }
    }
}

/// When the position solve factorizes the kinematic Jacobian at the
/// converged configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Refactor {
    /// Always (F,ξ and every other derivative solve need J there).
    AtSolution,
    /// Only when chord steps converge slowly: the factorization may be of a
    /// nearby configuration, for solves that refine against the exact J.
    WhenSlow,
}

impl Kinematics {
    /// ε = D(x) of every element at the current x, with the element
    /// Jacobians D,x if `with_jac` (dual numbers: several times the cost of
    /// ε alone for a spatial beam, which Newton's trial steps need only).
    pub(crate) fn eval_elements(&mut self, with_jac: bool) {
        self.jac_at_x = with_jac;
        let mech = &self.mech;
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (k, e) in mech.elements.iter().enumerate() {
            let m = &self.maps[k];
            if m.ne == 0 {
                continue;
            }
            for (c, gi) in e.x_index.iter().enumerate() {
                xl[c] = self.x[*gi];
            }
            let o = e.eps_offset;
            let prev = &self.prev_eps[o..o + m.ne];
            let out = &mut self.eps[o..o + m.ne];
            if with_jac {
                e.element.deformations_and_jacobian(
                    &xl[..m.nx],
                    Some(prev),
                    out,
                    &mut self.jac_local[k],
                );
            } else {
                e.element.deformations(&xl[..m.nx], Some(prev), out);
            }
        }
    }

    /// Fails when a node's only dependent Euler parameter nears zero.
    fn check_euler_parameters(&self) -> Result<(), KinematicsError> {
        for n in &self.mech.nodes {
            let Some(o) = &n.orientation else { continue };
            if o.len() != 4 {
                continue;
            }
            // (counted, not collected: this runs at every solve)
            let is_dep = |i: &&usize| matches!(self.mech.x_roles[**i], XRole::Dependent(_));
            let deps = o.iter().filter(is_dep).count();
            let dofs = o
                .iter()
                .filter(|i| matches!(self.mech.x_roles[**i], XRole::Dof(_)))
                .count();
            let Some(&dep) = o.iter().find(is_dep) else {
                continue;
            };
            if deps == 1 && dofs == 3 && self.x[dep].abs() < 0.05 {
                return Err(KinematicsError::EulerParameterDegenerate {
                    node: n.id.clone(),
                    coordinate: self.mech.x_names[dep].clone(),
                    value: self.x[dep],
                });
            }
        }
        Ok(())
    }

    pub(crate) fn residual_norm(&self) -> f64 {
        self.mech
            .constraint_rows
            .iter()
            .enumerate()
            .map(|(r, j)| (self.eps[*j] - self.target[r]).abs())
            .fold(0.0f64, f64::max)
    }

    /// Evaluates the element Jacobians at the current x if the last
    /// evaluation was of ε only (ε does not change: the plain and the dual
    /// evaluation give it bit for bit alike).
    fn ensure_jacobians(&mut self) {
        if !self.jac_at_x {
            self.eval_elements(true);
        }
    }

    /// Scatters the element Jacobians into the values of J.
    fn assemble_jacobian(&mut self) {
        let values = self.lu.values_mut();
        values.fill(0.0);
        for (jl, pos) in self.jac_local.iter().zip(&self.jpos) {
            for (v, &p) in jl.iter().zip(pos) {
                if p != NO_ENTRY {
                    values[p] += v;
                }
            }
        }
    }

    /// Solves the configuration for degrees of freedom `q` at time `t`
    /// (prescribed inputs from their time functions). Starts from the last
    /// solution, extrapolated to first order with F,ξ when available.
    pub fn solve(&mut self, q: &[f64], t: f64) -> Result<(), KinematicsError> {
        self.solve_with(q, t, Refactor::AtSolution)
    }

    /// As [`solve`](Self::solve), but without factorizing J at the converged
    /// configuration when chord steps converged fast: for callers that need
    /// only the configuration, the element Jacobians and solves that refine
    /// against the exact J ([`velocities_refined`](Self::velocities_refined)),
    /// as one evaluation of the equations of motion in nodal coordinates
    /// does. Every method that needs J factorized at x (F,ξ, adjoint and
    /// sensitivity solves) factorizes it first if it is not.
    pub fn solve_chord(&mut self, q: &[f64], t: f64) -> Result<(), KinematicsError> {
        self.solve_with(q, t, Refactor::WhenSlow)
    }

    fn solve_with(&mut self, q: &[f64], t: f64, mode: Refactor) -> Result<(), KinematicsError> {
        let r = self.solve_inner(q, t, mode);
        match &r {
            Ok(()) => {
                self.x_good.copy_from_slice(&self.x);
                self.xi_good.copy_from_slice(&self.xi);
            }
            // back to the last converged configuration: the next solve
            // (e.g. a retried, smaller step) starts from a good guess
            Err(_) => self.restore_last_solution(),
        }
        r
    }

    /// Returns to the last converged configuration after a failed solve: x
    /// and ξ, the deformations and element Jacobians there, and no
    /// factorization (the last one may be of a configuration far off, and
    /// must neither pass for one at x nor predict from it).
    fn restore_last_solution(&mut self) {
        self.x.copy_from_slice(&self.x_good);
        self.xi.copy_from_slice(&self.xi_good);
        self.have_solution = true;
        self.first_order_valid = false;
        self.lu_valid = false;
        self.lu_at_x = false;
        self.eval_elements(true);
    }

    fn solve_inner(&mut self, q: &[f64], t: f64, mode: Refactor) -> Result<(), KinematicsError> {
        if q.len() != self.n_q {
            return Err(KinematicsError::Length {
                what: "q",
                expected: self.n_q,
                got: q.len(),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            // every non-finite entry (up to three by name), not just the first
            let bad: Vec<usize> = (i..q.len()).filter(|&k| !q[k].is_finite()).collect();
            return Err(KinematicsError::NonFinite {
                what: "q",
                index: i,
                name: flexmb_model::list_some(&bad, |k| self.mech.dof_label(k)),
            });
        }
        // ξ = (q, u) in a buffer kept between solves (no allocation per solve)
        let mut target = std::mem::take(&mut self.xi_target);
        target[..self.n_q].copy_from_slice(q);
        for k in 0..self.n_u {
            target[self.n_q + k] = self.mech.inputs[k].function.value(t);
        }
        self.t = t;
        let r = self.solve_to(&target, mode);
        self.xi_target = target;
        r
    }

    /// [`solve_inner`](Self::solve_inner) for the full target ξ: one Newton
    /// solve, then a continuation from the last converged ξ if that fails.
    fn solve_to(&mut self, target: &[f64], mode: Refactor) -> Result<(), KinematicsError> {
        let first = self.solve_xi(target, mode, BRANCH_RATIO);
        if first.is_ok() || matches!(first, Err(KinematicsError::EulerParameterDegenerate { .. })) {
            return first;
        }
        // continuation from the last converged configuration: reach the target
        // in 2, 4, …, 64 equal steps of ξ (large jumps, e.g. a first solve far
        // from the reference configuration)
        self.continuations += 1;
        let start = self.xi_good.clone();
        let mut err = first;
        for n in [2usize, 4, 8, 16, 32, FINEST_STEPS] {
            self.restore_last_solution();
            let mut ok = true;
            for j in 1..=n {
                let s = j as f64 / n as f64;
                // (the last step to the target itself, not to a rounding of it)
                let mid: Vec<f64> = start
                    .iter()
                    .zip(target)
                    .map(|(a, b)| if j == n { *b } else { a + s * (b - a) })
                    .collect();
                // J factorized at each intermediate solution: the next
                // step's chord predictor is of first order along the step
                // in the finest steps, a correction up to the predicted
                // motion itself is accepted: near a fold of the branch (a
                // configuration at the edge of reach) the ratio grows as
                // 1/distance to the fold however small the steps
                let ratio = if n == FINEST_STEPS { 1.0 } else { BRANCH_RATIO };
                match self.solve_xi(&mid, Refactor::AtSolution, ratio) {
                    Ok(()) => {}
                    // the chart's limit: smaller steps do not pass it
                    Err(e @ KinematicsError::EulerParameterDegenerate { .. }) => return Err(e),
                    Err(e) => {
                        err = Err(e);
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                return Ok(());
            }
        }
        err
    }

    /// One Newton solve for the full ξ = (q, u).
    ///
    /// Chord Newton: the factorization of J is kept from step to step (and
    /// from the previous solve) while the residual shrinks at least tenfold
    /// per step, and refactorized at the current x otherwise. With
    /// [`Refactor::AtSolution`] J is also factorized at the converged point
    /// (F,ξ needs it there); with [`Refactor::WhenSlow`] the last factorization
    /// may be of a nearby configuration, and `lu_at_x` says whether it is not.
    ///
    /// The branch guard ([`branch_jump`](Self::branch_jump)) refuses a
    /// solution whose Newton corrections exceed `branch_ratio` times the
    /// prediction's motion.
    fn solve_xi(
        &mut self,
        xi: &[f64],
        mode: Refactor,
        branch_ratio: f64,
    ) -> Result<(), KinematicsError> {
        let n_q = self.n_q;
        self.xi_prev.copy_from_slice(&self.xi);
        self.xi.copy_from_slice(xi);
        // targets of the constraint rows
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            self.target[r] = match self.mech.e_roles[*j] {
                ERole::Dof(k) => self.xi[k],
                ERole::Input(k) => self.xi[n_q + k],
                _ => 0.0,
            };
        }
        // the branch guard compares the solution with the prediction from
        // the last solution (not with a guess of `set_guess`)
        let guard = self.have_solution;
        if guard && !self.first_order_valid && !self.lu_valid && self.xi != self.xi_prev {
            // no derivative at hand (the reference, or a restored solution):
            // factorize J there for the chord predictor (a singular J
            // leaves none: the guard then compares with the unpredicted x)
            let _ = self.factor_at_x();
        }
        if guard {
            self.x_predicted.copy_from_slice(&self.x);
        }
        let mut moved = self.have_solution && self.predict();
        self.first_order_valid = false;
        // known coordinates
        for (i, r) in self.mech.x_roles.iter().enumerate() {
            let v = match r {
                XRole::Fixed => self.mech.x0[i],
                XRole::Dof(k) => self.xi[*k],
                XRole::Input(k) => self.xi[n_q + k],
                XRole::Dependent(_) => continue,
            };
            if self.x[i] != v {
                self.x[i] = v;
                moved = true;
            }
        }
        // the motion the prediction made (0 without a guard), and the
        // predicted configuration
        let mut predicted = 0.0f64;
        if guard {
            for (p, x) in self.x_predicted.iter_mut().zip(&self.x) {
                predicted = predicted.max((x - *p).abs());
                *p = *x;
            }
        }
        if moved {
            self.lu_at_x = false;
        }
        let tol = self.opts.tol * self.length_scale.max(1e-6);
        let n_c = self.mech.constraint_rows.len();
        let mut last_update = std::mem::take(&mut self.last_update);
        last_update.fill(0.0);
        let mut lu_fresh_for_steps = self.lu_valid;
        let mut prev_res = f64::INFINITY;
        // ε only; the Jacobians where J is factorized and at the solution
        self.eval_elements(false);
        let mut res = self.load_residual();
        let mut outcome = None;
        for it in 0..=self.opts.max_iterations {
            if self
                .stop
                .as_ref()
                .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
            {
                self.last_update = last_update;
                return Err(KinematicsError::Interrupted);
            }
            if !res.is_finite() {
                break;
            }
            // converged: residual below tolerance, or Newton updates at rounding
            // level while the residual is small (it cannot decrease further)
            let x_scale = self
                .mech
                .dependent
                .iter()
                .fold(1.0f64, |m, &i| m.max(self.x[i].abs()));
            // (the residual of a length cannot be computed more accurately than
            // the rounding of the coordinates it is computed from: a mechanism
            // far from the origin, or large against its elements, stalls
            // there, however small tol · L is)
            let stalled = it > 0
                && last_update.iter().fold(0.0f64, |m, v| m.max(v.abs()))
                    <= 8.0 * f64::EPSILON * x_scale
                && res <= (1e3 * tol).max(ROUNDING_RESIDUALS * f64::EPSILON * x_scale);
            if res <= tol || stalled {
                // (a node at its chart's limit is named as such, not as a
                // branch jump: smaller steps do not help there)
                let jump = guard
                    .then(|| self.branch_jump(predicted, branch_ratio))
                    .flatten();
                outcome = Some(match jump {
                    Some(jump) => Err(self.check_euler_parameters().err().unwrap_or(jump)),
                    None => self.converged(it, mode),
                });
                break;
            }
            if it == self.opts.max_iterations {
                break;
            }
            // a fresh factorization at this x: without a usable one, or when
            // chord steps converge slowly
            if !lu_fresh_for_steps || (it > 0 && res > 0.1 * prev_res) {
                if let Err(e) = self.factor_at_x() {
                    outcome = Some(Err(e));
                    break;
                }
                lu_fresh_for_steps = true;
            }
            prev_res = res;
            self.dx[..n_c].copy_from_slice(&self.work[..n_c]);
            self.lu.solve_vec(&mut self.dx[..n_c]);
            // step with backtracking: halve while the residual grows; the trial
            // evaluation (with Jacobians) serves the next iteration
            let mut step = 1.0;
            loop {
                self.add_to_dependent(step);
                self.eval_elements(false);
                let trial = self.residual_norm();
                if (trial.is_finite() && (trial < res || res < 1e3 * tol)) || step < 0.04 {
                    // the smallest step is accepted anyway: Newton may still recover
                    break;
                }
                self.add_to_dependent(-step);
                step *= 0.5;
            }
            self.lu_at_x = false;
            for (u, d) in last_update.iter_mut().zip(&self.dx) {
                *u = d * step;
            }
            res = self.load_residual();
        }
        let result = match outcome {
            Some(r) => r,
            None => Err(self.not_converged(&last_update)),
        };
        self.last_update = last_update;
        result
    }

    /// The [`KinematicsError::BranchJump`] of a converged Newton solve whose
    /// corrections moved a dependent coordinate from the first-order
    /// prediction by more than `ratio` times the largest motion of
    /// the prediction (`predicted`, the known coordinates' included): along
    /// a smooth branch the correction is of second order in the step and the
    /// prediction of first order, so this happens for steps too large for the
    /// branch's curvature, and when Newton lands on another branch of the
    /// constraint equations (an elbow folded the other way). Corrections
    /// within [`BRANCH_NOISE`] of the length scale are never a jump.
    fn branch_jump(&self, predicted: f64, ratio: f64) -> Option<KinematicsError> {
        let (mut correction, mut at) = (0.0f64, 0);
        for &i in &self.mech.dependent {
            let c = (self.x[i] - self.x_predicted[i]).abs();
            if c > correction {
                (correction, at) = (c, i);
            }
        }
        (correction > ratio * predicted && correction > BRANCH_NOISE * self.length_scale).then(
            || KinematicsError::BranchJump {
                coordinate: self.mech.x_names[at].clone(),
                correction,
                predicted,
            },
        )
    }

    /// x_dep += s · dx.
    fn add_to_dependent(&mut self, s: f64) {
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            self.x[i] += s * self.dx[k];
        }
    }

    /// Writes −(D_c(x) − target) to `work` and returns its max-norm.
    fn load_residual(&mut self) -> f64 {
        let mut res = 0.0f64;
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            let v = self.eps[*j] - self.target[r];
            self.work[r] = -v;
            res = res.max(v.abs());
        }
        res
    }

    /// Bookkeeping of a converged solve (and the factorization `mode` asks for).
    fn converged(&mut self, it: usize, mode: Refactor) -> Result<(), KinematicsError> {
        self.ensure_jacobians();
        if mode == Refactor::AtSolution && !self.lu_at_x {
            self.factor_at_x()?;
        }
        self.check_euler_parameters()?;
        self.iterations = it;
        self.prev_eps.copy_from_slice(&self.eps);
        self.have_solution = true;
        Ok(())
    }

    /// Factorizes J at the current x (element Jacobians evaluated there).
    pub(crate) fn factor_at_x(&mut self) -> Result<(), KinematicsError> {
        self.ensure_jacobians();
        self.assemble_jacobian();
        self.factorizations += 1;
        self.extra_refinements = 0;
        if !self.lu.factor() {
            self.lu_valid = false;
            self.lu_at_x = false;
            return Err(self.singular_error());
        }
        self.lu_valid = true;
        self.lu_at_x = true;
        Ok(())
    }

    /// First-order predictor of the dependent coordinates for the change of
    /// ξ since the last solution: x += F,ξ Δξ when F,ξ is at hand, else one
    /// chord step J Δx_dep = (target − D_c) − D_c,x_ξ Δx_ξ with the last
    /// factorization and the element Jacobians of the last solution (the same
    /// step to first order). Returns whether x changed.
    fn predict(&mut self) -> bool {
        let n_xi = self.n_q + self.n_u;
        let mut moved = false;
        if self.first_order_valid {
            for c in 0..n_xi {
                let d = self.xi[c] - self.xi_prev[c];
                if d != 0.0 {
                    moved = true;
                    for &i in &self.mech.dependent {
                        self.x[i] += self.f[(i, c)] * d;
                    }
                }
            }
            return moved;
        }
        if !self.lu_valid || self.xi == self.xi_prev {
            return false;
        }
        let mut rhs = std::mem::take(&mut self.dx);
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            rhs[r] = self.target[r] - self.eps[*j];
        }
        let (xi, xi_prev) = (&self.xi, &self.xi_prev);
        self.for_each_nodal_xi_entry(|r, k, d| rhs[r] -= d * (xi[k] - xi_prev[k]));
        self.lu.solve_vec(&mut rhs);
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            self.x[i] += rhs[k];
        }
        self.dx = rhs;
        true
    }

    /// Factorizes J at the solved configuration if its factorization is of
    /// another one (after [`solve_chord`](Self::solve_chord)). A singular J
    /// leaves the factorization invalid and every later solve NaN.
    pub(crate) fn ensure_lu_at_x(&mut self) {
        if self.have_solution && !self.lu_at_x {
            let _ = self.factor_at_x();
        }
    }
}
