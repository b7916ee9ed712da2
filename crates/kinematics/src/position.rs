//! The position solve x = F(q, u), ε = E(q, u) (thesis (5.7), (6.5)) by
//! Newton's method on the constraint equations D_c(x) = (0, q_ε, u_ε), with a
//! first-order predictor, chord steps on a kept factorization of J and
//! continuation from the last solution.

use crate::{Kinematics, KinematicsError};
use flexmb_model::{ERole, XRole};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

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

/// The settings of the position solve.
#[derive(Clone, Debug, Default)]
pub(crate) struct Settings {
    /// Newton's tolerance and iteration limit.
    pub(crate) newton: NewtonOptions,
    /// A stop request read at every Newton iteration
    /// ([`Kinematics::set_stop`]).
    pub(crate) stop: Option<Arc<AtomicBool>>,
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
        self.jac.at_x = with_jac;
        let config = &mut self.config;
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (k, e) in self.mech.elements.iter().enumerate() {
            let m = &self.layout.maps[k];
            if m.ne == 0 {
                continue;
            }
            for (c, gi) in e.x_index.iter().enumerate() {
                xl[c] = config.x[*gi];
            }
            let o = e.eps_offset;
            let prev = &config.branch[o..o + m.ne];
            let out = &mut config.eps[o..o + m.ne];
            if with_jac {
                e.element.deformations_and_jacobian(
                    &xl[..m.nx],
                    Some(prev),
                    out,
                    &mut self.jac.local[k],
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
            if deps == 1 && dofs == 3 && self.config.x[dep].abs() < 0.05 {
                return Err(KinematicsError::EulerParameterDegenerate {
                    node: n.id.clone(),
                    coordinate: self.mech.x_names[dep].clone(),
                    value: self.config.x[dep],
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
            .map(|(r, j)| (self.config.eps[*j] - self.ws.target[r]).abs())
            .fold(0.0f64, f64::max)
    }

    /// Evaluates the element Jacobians at the current x if the last
    /// evaluation was of ε only (ε does not change: the plain and the dual
    /// evaluation give it bit for bit alike).
    fn ensure_jacobians(&mut self) {
        if !self.jac.at_x {
            self.eval_elements(true);
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
                let c = &mut self.config;
                c.x_good.copy_from_slice(&c.x);
                c.xi_good.copy_from_slice(&c.xi);
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
        let c = &mut self.config;
        c.x.copy_from_slice(&c.x_good);
        c.xi.copy_from_slice(&c.xi_good);
        c.solved = true;
        self.first.valid = false;
        self.factorization.invalidate();
        self.eval_elements(true);
    }

    fn solve_inner(&mut self, q: &[f64], t: f64, mode: Refactor) -> Result<(), KinematicsError> {
        let (n_q, n_u) = (self.layout.n_q, self.layout.n_u);
        if q.len() != n_q {
            return Err(KinematicsError::Length {
                what: "q",
                expected: n_q,
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
        // the target ξ = (q, u), in a buffer kept between solves (no
        // allocation per solve)
        let target = &mut self.ws.xi_target;
        target[..n_q].copy_from_slice(q);
        for k in 0..n_u {
            target[n_q + k] = self.mech.inputs[k].function.value(t);
        }
        self.config.t = t;
        self.solve_to(mode)
    }

    /// [`solve_inner`](Self::solve_inner) for the full target ξ in
    /// `ws.xi_target`: one Newton solve, then a continuation from the last
    /// converged ξ if that fails.
    fn solve_to(&mut self, mode: Refactor) -> Result<(), KinematicsError> {
        self.step_xi(None);
        let first = self.solve_xi(mode, BRANCH_RATIO);
        if first.is_ok() || matches!(first, Err(KinematicsError::EulerParameterDegenerate { .. })) {
            return first;
        }
        // continuation from the last converged configuration: reach the target
        // in 2, 4, …, 64 equal steps of ξ (large jumps, e.g. a first solve far
        // from the reference configuration, or a step the branch guard
        // refused)
        self.counters.continuations += 1;
        let mut err = first;
        for n in [2usize, 4, 8, 16, 32, FINEST_STEPS] {
            self.restore_last_solution();
            let mut ok = true;
            for j in 1..=n {
                self.step_xi(Some(j as f64 / n as f64));
                // J factorized at each intermediate solution: the next
                // step's chord predictor is of first order along the step.
                // In the finest steps, a correction up to the predicted
                // motion itself is accepted: near a fold of the branch (a
                // configuration at the edge of reach) the ratio grows as
                // 1/distance to the fold however small the steps.
                let ratio = if n == FINEST_STEPS { 1.0 } else { BRANCH_RATIO };
                match self.solve_xi(Refactor::AtSolution, ratio) {
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

    /// Sets the ξ of the next Newton solve, keeping the current one as
    /// `xi_prev`: the target `ws.xi_target`, or with `Some(s)` the point a
    /// fraction s of the way to it from the last converged ξ (continuation;
    /// `xi_good` does not change while the continuation runs).
    fn step_xi(&mut self, s: Option<f64>) {
        let c = &mut self.config;
        c.xi_prev.copy_from_slice(&c.xi);
        let target = &self.ws.xi_target;
        match s {
            None => c.xi.copy_from_slice(target),
            // (the last step to the target itself, not to a rounding of it)
            Some(1.0) => c.xi.copy_from_slice(target),
            Some(s) => {
                for ((xi, a), b) in c.xi.iter_mut().zip(&c.xi_good).zip(target) {
                    *xi = a + s * (b - a);
                }
            }
        }
    }

    /// One Newton solve for the ξ = (q, u) that
    /// [`step_xi`](Self::step_xi) set.
    ///
    /// Chord Newton: the factorization of J is kept from step to step (and
    /// from the previous solve) while the residual shrinks at least tenfold
    /// per step, and refactorized at the current x otherwise. With
    /// [`Refactor::AtSolution`] J is also factorized at the converged point
    /// (F,ξ needs it there); with [`Refactor::WhenSlow`] the last factorization
    /// may be of a nearby configuration, and `Factorization::at_x` says whether
    /// it is not.
    fn solve_xi(&mut self, mode: Refactor, branch_ratio: f64) -> Result<(), KinematicsError> {
        let n_q = self.layout.n_q;
        self.set_row_targets();
        // the branch guard compares the solution with the prediction from
        // the last solution (not with a guess of `set_guess`)
        let guard = self.config.solved;
        if guard
            && !self.first.valid
            && !self.factorization.valid
            && self.config.xi != self.config.xi_prev
        {
            // no derivative at hand (the reference, or a restored solution):
            // factorize J there for the chord predictor (a singular J
            // leaves none: the guard then compares with the unpredicted x)
            let _ = self.factor_at_x();
        }
        if guard {
            self.ws.x_predicted.copy_from_slice(&self.config.x);
        }
        let mut moved = self.config.solved && self.predict();
        self.first.valid = false;
        // known coordinates
        let c = &mut self.config;
        for (i, r) in self.mech.x_roles.iter().enumerate() {
            let v = match r {
                XRole::Fixed => self.mech.x0[i],
                XRole::Dof(k) => c.xi[*k],
                XRole::Input(k) => c.xi[n_q + k],
                XRole::Dependent(_) => continue,
            };
            if c.x[i] != v {
                c.x[i] = v;
                moved = true;
            }
        }
        // the motion the prediction made (0 without a guard), and the
        // predicted configuration
        let mut predicted = 0.0f64;
        if guard {
            for (p, x) in self.ws.x_predicted.iter_mut().zip(&c.x) {
                predicted = predicted.max((x - *p).abs());
                *p = *x;
            }
        }
        if moved {
            self.factorization.at_x = false;
        }
        let newton = self.settings.newton;
        let tol = newton.tol * self.layout.length_scale.max(1e-6);
        let n_c = self.mech.constraint_rows.len();
        self.ws.last_update.fill(0.0);
        let mut lu_fresh_for_steps = self.factorization.valid;
        let mut prev_res = f64::INFINITY;
        // ε only; the Jacobians where J is factorized and at the solution
        self.eval_elements(false);
        let mut res = self.load_residual();
        let mut outcome = None;
        for it in 0..=newton.max_iterations {
            if self
                .settings
                .stop
                .as_ref()
                .is_some_and(|s| s.load(Ordering::Relaxed))
            {
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
                .fold(1.0f64, |m, &i| m.max(self.config.x[i].abs()));
            // (the residual of a length cannot be computed more accurately than
            // the rounding of the coordinates it is computed from: a mechanism
            // far from the origin, or large against its elements, stalls
            // there, however small tol · L is)
            let stalled = it > 0
                && self
                    .ws
                    .last_update
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()))
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
            if it == newton.max_iterations {
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
            let ws = &mut self.ws;
            ws.dx[..n_c].copy_from_slice(&ws.work[..n_c]);
            self.factorization.lu.solve_vec(&mut ws.dx[..n_c]);
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
            self.factorization.at_x = false;
            let ws = &mut self.ws;
            for (u, d) in ws.last_update.iter_mut().zip(&ws.dx) {
                *u = d * step;
            }
            res = self.load_residual();
        }
        match outcome {
            Some(r) => r,
            None => Err(self.not_converged()),
        }
    }

    /// The targets of the constraint rows for the current ξ: 0 for the
    /// rigid deformations, the DOF's or input's value for theirs.
    pub(crate) fn set_row_targets(&mut self) {
        let (n_q, xi) = (self.layout.n_q, &self.config.xi);
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            self.ws.target[r] = match self.mech.e_roles[*j] {
                ERole::Dof(k) => xi[k],
                ERole::Input(k) => xi[n_q + k],
                _ => 0.0,
            };
        }
    }

    /// The [`KinematicsError::BranchJump`] of a converged Newton solve whose
    /// corrections moved a dependent coordinate from the first-order
    /// prediction by more than `ratio` times the largest motion of the
    /// prediction (`predicted`, the known coordinates' included): along a
    /// smooth branch the correction is of second order in the step and the
    /// prediction of first order, so this happens for steps too large for
    /// the branch's curvature, and when Newton lands on another branch of
    /// the constraint equations (an elbow folded the other way). Corrections
    /// within [`BRANCH_NOISE`] of the length scale are never a jump.
    fn branch_jump(&self, predicted: f64, ratio: f64) -> Option<KinematicsError> {
        let (mut correction, mut at) = (0.0f64, 0);
        for &i in &self.mech.dependent {
            let c = (self.config.x[i] - self.ws.x_predicted[i]).abs();
            if c > correction {
                (correction, at) = (c, i);
            }
        }
        (correction > ratio * predicted && correction > BRANCH_NOISE * self.layout.length_scale)
            .then(|| KinematicsError::BranchJump {
                coordinate: self.mech.x_names[at].clone(),
                correction,
                predicted,
            })
    }

    /// x_dep += s · dx.
    fn add_to_dependent(&mut self, s: f64) {
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            self.config.x[i] += s * self.ws.dx[k];
        }
    }

    /// Writes −(D_c(x) − target) to `work` and returns its max-norm.
    fn load_residual(&mut self) -> f64 {
        let mut res = 0.0f64;
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            let v = self.config.eps[*j] - self.ws.target[r];
            self.ws.work[r] = -v;
            res = res.max(v.abs());
        }
        res
    }

    /// Bookkeeping of a converged solve (and the factorization `mode` asks for).
    fn converged(&mut self, it: usize, mode: Refactor) -> Result<(), KinematicsError> {
        self.ensure_jacobians();
        if mode == Refactor::AtSolution && !self.factorization.at_x {
            self.factor_at_x()?;
        }
        self.check_euler_parameters()?;
        self.counters.iterations = it;
        let c = &mut self.config;
        c.branch.copy_from_slice(&c.eps);
        c.solved = true;
        Ok(())
    }

    /// Factorizes J at the current x (element Jacobians evaluated there).
    pub(crate) fn factor_at_x(&mut self) -> Result<(), KinematicsError> {
        self.ensure_jacobians();
        let f = &mut self.factorization;
        self.layout
            .assemble_jacobian(&self.jac.local, f.lu.values_mut());
        self.counters.factorizations += 1;
        f.extra_refinements = 0;
        if !f.lu.factor() {
            f.invalidate();
            return Err(self.singular_error());
        }
        f.valid = true;
        f.at_x = true;
        Ok(())
    }

    /// First-order predictor of the dependent coordinates for the change of
    /// ξ since the last solution: x += F,ξ Δξ when F,ξ is at hand, else one
    /// chord step J Δx_dep = (target − D_c) − D_c,x_ξ Δx_ξ with the last
    /// factorization and the element Jacobians of the last solution (the same
    /// step to first order). Returns whether x changed.
    fn predict(&mut self) -> bool {
        let c = &mut self.config;
        let mut moved = false;
        if self.first.valid {
            for k in 0..self.layout.n_xi() {
                let d = c.xi[k] - c.xi_prev[k];
                if d != 0.0 {
                    moved = true;
                    for &i in &self.mech.dependent {
                        c.x[i] += self.first.f[(i, k)] * d;
                    }
                }
            }
            return moved;
        }
        if !self.factorization.valid || c.xi == c.xi_prev {
            return false;
        }
        let rhs = &mut self.ws.dx;
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            rhs[r] = self.ws.target[r] - c.eps[*j];
        }
        let (xi, xi_prev) = (&c.xi, &c.xi_prev);
        self.layout
            .for_each_nodal_xi_entry(&self.jac.local, |r, k, d| {
                rhs[r] -= d * (xi[k] - xi_prev[k])
            });
        self.factorization.lu.solve_vec(rhs);
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            c.x[i] += rhs[k];
        }
        true
    }

    /// Factorizes J at the solved configuration if its factorization is of
    /// another one (after [`solve_chord`](Self::solve_chord)). A singular J
    /// leaves the factorization invalid and every later solve NaN.
    pub(crate) fn ensure_lu_at_x(&mut self) {
        if self.config.solved && !self.factorization.at_x {
            let _ = self.factor_at_x();
        }
    }
}
