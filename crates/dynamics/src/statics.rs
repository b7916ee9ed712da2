//! Static equilibrium (only what statics needs: no inertia work): Newton on
//! the tangent Kq + Gq of (E.6), with load increments and optionally some
//! degrees of freedom held at given values (their reactions are reported).

use crate::{Dynamics, DynamicsError};
use faer::Mat;
use flexmb_linalg::{DenseLu, LuError};
use flexmb_model::{Coordinate, Load};
use flexmb_rotation::EulerParameters;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Settings of the static solver.
#[derive(Clone, Debug)]
pub struct StaticOptions {
    /// Number of equal load increments: the loads (and held values) go to
    /// their full values in `load_steps` steps of 1/`load_steps`. A step
    /// whose Newton iteration fails is halved (down to `min_increment`); after
    /// a converged step the increment doubles again, up to 1/`load_steps`.
    /// Without ramped loads (`ramp_loads` false, no `load_scale_from`) and
    /// held values every increment is the same problem: a failed one is
    /// retried once, with a fresh tangent.
    pub load_steps: usize,
    /// Newton iterations per increment.
    pub max_iterations: usize,
    /// Converged when ‖Δq‖∞ ≤ `tol`·(1 + ‖q‖∞) and the out-of-balance force is
    /// ≤ 1e-6 of the applied generalized forces (or absolutely tiny).
    pub tol: f64,
    /// Degrees of freedom held at values: (index in q, value).
    pub held: Vec<(usize, f64)>,
    /// Smallest load increment before giving up.
    pub min_increment: f64,
    /// Ramp the loads and gravity with the continuation parameter (true), or
    /// apply them fully from the start (false: a continuation from an
    /// equilibrium that already carries them, e.g. the previous sweep point).
    /// Held values are always ramped from their values in `q0`.
    pub ramp_loads: bool,
    /// Ramp the scale of the nodal loads ([`Dynamics::set_load_scale`]) from
    /// this value to the dynamics' load scale with the continuation
    /// parameter (gravity is not scaled): a continuation from an equilibrium
    /// under the nodal loads at this scale, e.g. the previous point of a
    /// load sweep, in increments that are cut where Newton fails (a full
    /// step may turn a node through the singular region of its Euler
    /// chart, which only the switches between increments avoid). `None`:
    /// the load scale is applied from the start.
    pub load_scale_from: Option<f64>,
    /// A request to stop, read before every Newton iteration and inside the
    /// assembly of a tangent and before its factorization (one atomic load
    /// each): when it is set the solve ends with
    /// [`DynamicsError::Interrupted`] (e.g. set by a signal handler).
    pub stop: Option<Arc<AtomicBool>>,
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            load_steps: 1,
            max_iterations: 25,
            tol: 1e-11,
            held: vec![],
            min_increment: 1e-4,
            ramp_loads: true,
            load_scale_from: None,
            stop: None,
        }
    }
}

/// A chord-Newton step is kept while it shrinks the update by at least this
/// factor; otherwise the tangent is rebuilt at the current iterate.
const CHORD_CONTRACTION: f64 = 0.2;

/// Halvings of a Newton update whose iterate flips an element, or raises
/// the out-of-balance, before the load increment is cut instead.
const MAX_FLIP_HALVINGS: usize = 10;

/// Steps up to this multiple of the convergence tolerance on q are at the
/// round-off level of the out-of-balance and exempt from the residual guard
/// of [`Dynamics::static_equilibrium`].
const RESIDUAL_GUARD_FLOOR: f64 = 1e4;

/// Rejections by the residual guard per load increment, after which the
/// increment goes on with plain (chord) Newton.
const RESIDUAL_GUARD_BUDGET: usize = 12;

/// Takes back the fraction `part` of the last update `dq` of the free DOFs
/// (1: all of it, 0.5: halve it) and keeps what remains in `dq`.
fn retract(q: &mut [f64], free: &[usize], dq: &mut [f64], part: f64) {
    for (d, i) in dq.iter_mut().zip(free) {
        q[*i] -= part * *d;
        *d *= 1.0 - part;
    }
}

/// The factorized static tangent kept between Newton iterations (and between
/// calls, e.g. along a sweep) for chord steps.
pub(crate) struct StaticFactor {
    lu: DenseLu,
    /// The free (not held) DOFs it was built for.
    free: Vec<usize>,
    /// The tangent's coupling K_fh of the free to the held DOFs (column k
    /// for the k-th held DOF, n_free rows each), for the predictor
    /// [`Dynamics::predict_free`].
    coupling: Vec<f64>,
    /// 1/|K_ii| of the free DOFs, the weights of the residual guard's
    /// energy-scaled out-of-balance Σ g_i²/|K_ii|.
    weights: Vec<f64>,
}

/// An equilibrium.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// The degrees of freedom.
    pub q: Vec<f64>,
    /// The nodal coordinates x = F(q) of the equilibrium, the configuration
    /// the solver converged to (solving F(q) again from another starting
    /// guess, e.g. the reference configuration, can land on another branch).
    pub x: Vec<f64>,
    /// The deformations ε = D(x) there.
    pub eps: Vec<f64>,
    /// Total Newton iterations.
    pub iterations: usize,
    /// Load increments used.
    pub increments: usize,
    /// Generalized reactions on the held degrees of freedom (the forces needed to hold them).
    pub reactions: Vec<f64>,
    /// The Euler-parameter charts switched on the way (free orientations
    /// turned by more than about 127° since their chart was chosen, see
    /// `flexmb_model::EulerChart`), each with the load factor at which it
    /// happened in its `t`. When there were any, `q` is in the
    /// chart of [`Dynamics::mechanism`] after the call, not in the one
    /// before it; `x` is the same in every chart.
    pub chart_switches: Vec<flexmb_model::ChartSwitch>,
    /// The changes of the dependent nodal coordinates on the way (nodal
    /// DOFs whose dependent set got ill-conditioned, e.g. the x of the nodes
    /// of a beam with rigid elongations turned near 90°; docs/ARCHITECTURE.md,
    /// "Re-partitioning of nodal DOFs"), each with its load factor in `t`:
    /// the held DOFs keep their coordinates. As with `chart_switches`, `q` is then in the set of
    /// [`Dynamics::mechanism`] after the call.
    pub partition_switches: Vec<flexmb_model::PartitionSwitch>,
}

impl Dynamics {
    /// The static out-of-balance g_s = E,qᵀσ − F,qᵀf and the tangent
    /// Kq + Gq − F,qᵀ f,x F,q (E.6) at (q, t), without inertia. Kq includes the
    /// proportional gains of controllers.
    pub fn static_tangent(
        &mut self,
        t: f64,
        q: &[f64],
    ) -> Result<(Vec<f64>, Mat<f64>), DynamicsError> {
        self.static_tangent_until(t, q, None)
    }

    /// [`static_tangent`](Self::static_tangent) that ends with
    /// [`DynamicsError::Interrupted`] when `stop` is set, read after the
    /// position solve and inside the geometric stiffness
    /// ([`flexmb_kinematics::Kinematics::second_order_contraction_until`]).
    fn static_tangent_until(
        &mut self,
        t: f64,
        q: &[f64],
        stop: Option<&AtomicBool>,
    ) -> Result<(Vec<f64>, Mat<f64>), DynamicsError> {
        self.kinematics_at(t, q, None)?;
        if crate::simulate::stop_requested(stop) {
            return Err(DynamicsError::Interrupted);
        }
        self.forces(t, false);
        self.w.copy_from_slice(&self.f);
        self.generalized_force();
        let g: Vec<f64> = self.rhs.iter().map(|v| -v).collect();
        let k = self.structural_stiffness();
        let neg_f: Vec<f64> = self.f.iter().map(|v| -v).collect();
        let sigma = self.sigma.clone();
        let mut tangent = self
            .kin
            .second_order_contraction_until(&neg_f, &sigma, stop)
            .ok_or(DynamicsError::Interrupted)?;
        tangent += &k;
        let l = self.load_stiffness(t);
        tangent -= &l;
        Ok((g, tangent))
    }

    /// The static out-of-balance g_s = E,qᵀσ − F,qᵀf of
    /// [`static_tangent`](Self::static_tangent) without the tangent and
    /// without F,q: with E,q = D,x F,q, g_s = F,qᵀ(D,xᵀσ − f), one adjoint
    /// solve with the factorized kinematic Jacobian.
    pub fn static_residual(&mut self, t: f64, q: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        self.kin
            .solve(q, t)
            .map_err(|e| DynamicsError::Kinematics { t, source: e })?;
        self.forces(t, false);
        for (w, f) in self.w.iter_mut().zip(&self.f) {
            *w = -f;
        }
        self.kin.add_deformation_forces(&self.sigma, &mut self.w);
        let mut g = vec![0.0; self.kin.n_q() + self.kin.n_u()];
        self.kin.transfer_transpose_times(&self.w, &mut g);
        g.truncate(self.kin.n_q());
        Ok(g)
    }

    /// Kq = E,qᵀ S E,q (E.6d) plus controller gains, summed element by
    /// element over the columns where the element's rows of E,q are not all
    /// zero (with deformation DOFs of a serial chain that is the element's
    /// own DOFs: Kq is then assembled in O(n) instead of an n_ε × n_q² product).
    pub(crate) fn structural_stiffness(&mut self) -> Mat<f64> {
        let mech = &self.mech;
        let n_q = mech.n_dof();
        let view = self.kin.first_order_view();
        let (e, f) = (view.e, view.f);
        let mut gains = vec![0.0; mech.n_eps()];
        for c in &mech.controllers {
            if let Coordinate::Def(j) = c.on {
                gains[j] += c.kp;
            }
        }
        let mut k = Mat::<f64>::zeros(n_q, n_q);
        let mut cols: Vec<usize> = Vec::with_capacity(n_q);
        let mut ee: Vec<f64> = vec![];
        let mut se: Vec<f64> = vec![];
        for el in &mech.elements {
            let ne = el.element.n_eps();
            let o = el.eps_offset;
            let mut active = [0usize; flexmb_element::MAX_ELEMENT_COORDS];
            let mut na = 0;
            for a in 0..ne {
                if !matches!(
                    mech.e_roles[o + a],
                    flexmb_model::ERole::Rigid | flexmb_model::ERole::Input(_)
                ) {
                    active[na] = a;
                    na += 1;
                }
            }
            if na == 0 {
                continue;
            }
            let active = &active[..na];
            cols.clear();
            for col in 0..n_q {
                let ecol = &e.col_as_slice(col)[o..o + ne];
                if active.iter().any(|&a| ecol[a] != 0.0) {
                    cols.push(col);
                }
            }
            let nz = cols.len();
            // ee = E_e (na × nz) and se = (S_e + gains) E_e, row-major
            ee.clear();
            ee.resize(na * nz, 0.0);
            se.clear();
            se.resize(na * nz, 0.0);
            for (c, &col) in cols.iter().enumerate() {
                let ecol = &e.col_as_slice(col)[o..o + ne];
                for (i, &a) in active.iter().enumerate() {
                    ee[i * nz + c] = ecol[a];
                }
            }
            let s = el.element.stiffness();
            for (i, &a) in active.iter().enumerate() {
                for (l, &b) in active.iter().enumerate() {
                    let w = s[(a, b)] + if a == b { gains[o + a] } else { 0.0 };
                    if w == 0.0 {
                        continue;
                    }
                    for c in 0..nz {
                        se[i * nz + c] += w * ee[l * nz + c];
                    }
                }
            }
            for (c2, &col2) in cols.iter().enumerate() {
                let kcol = k.col_as_slice_mut(col2);
                for (c1, &col1) in cols.iter().enumerate() {
                    let mut v = 0.0;
                    for i in 0..na {
                        v += ee[i * nz + c1] * se[i * nz + c2];
                    }
                    kcol[col1] += v;
                }
            }
        }
        for c in &mech.controllers {
            if let Coordinate::Node(i) = c.on {
                let row: Vec<f64> = (0..n_q).map(|k| f[(i, k)]).collect();
                for a in 0..n_q {
                    for b in 0..n_q {
                        k[(a, b)] += c.kp * row[a] * row[b];
                    }
                }
            }
        }
        k
    }

    /// F,qᵀ (∂f/∂x) F,q for position-dependent loads (consistent gravity on
    /// rotating elements, moments on Euler parameters): the element blocks
    /// of ∂f/∂x are accumulated into D F,q (only the rows of loaded
    /// coordinates are non-zero), then one product F,qᵀ (D F,q), instead of
    /// a dense n_q × n_q product per element.
    pub(crate) fn load_stiffness(&mut self, t: f64) -> Mat<f64> {
        let mech = &self.mech;
        let n_q = mech.n_dof();
        let view = self.kin.first_order_view();
        let (f, x) = (view.f, view.x);
        let mut df = Mat::<f64>::zeros(f.nrows(), n_q);
        let mut loaded = false;
        // D F,q += P_eᵀ D_e P_e F,q for one element block D_e (row-major n × n)
        let mut add = |idx: &[usize], d: &[f64], n: usize| {
            loaded = true;
            for col in 0..n_q {
                let fcol = f.col_as_slice(col);
                let dcol = df.col_as_slice_mut(col);
                for a in 0..n {
                    let v: f64 = (0..n).map(|b| d[a * n + b] * fcol[idx[b]]).sum();
                    dcol[idx[a]] += v;
                }
            }
        };
        if let Some(g0) = mech.gravity {
            let g = g0.map(|v| v * self.load_factor);
            let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
            let mut d =
                vec![0.0; flexmb_element::MAX_ELEMENT_COORDS * flexmb_element::MAX_ELEMENT_COORDS];
            for e in &mech.elements {
                if !e.element.has_inertia() {
                    continue;
                }
                let n = e.x_index.len();
                for (k, gi) in e.x_index.iter().enumerate() {
                    xl[k] = x[*gi];
                }
                e.element
                    .gravity_force_derivative(&xl[..n], &g, &mut d[..n * n]);
                if d[..n * n].iter().any(|v| *v != 0.0) {
                    add(&e.x_index, &d[..n * n], n);
                }
            }
        }
        for ld in &mech.loads {
            if let Load::SpatialMoment { index, m, function } = ld {
                // f_λ = 2 Λ(λ)ᵀ m s is linear in λ: ∂f/∂λ = 2 s ∂(Λᵀm)/∂λ
                let s = self.load_factor * self.load_scale * function.value(t);
                let mut d = vec![0.0; 16];
                for b in 0..4 {
                    let mut e = [0.0; 4];
                    e[b] = 1.0;
                    let lt = EulerParameters(e).lambda().transpose();
                    for a in 0..4 {
                        d[a * 4 + b] =
                            2.0 * s * (lt[(a, 0)] * m[0] + lt[(a, 1)] * m[1] + lt[(a, 2)] * m[2]);
                    }
                }
                add(index, &d, 4);
            }
        }
        if !loaded {
            return Mat::zeros(n_q, n_q);
        }
        f.transpose() * &df
    }

    /// The tangent at q, factorized over the free DOFs and kept for chord
    /// steps; returns the out-of-balance at q. A set `stop` ends it with
    /// [`DynamicsError::Interrupted`] inside the assembly and before the
    /// factorization.
    fn refresh_static_factor(
        &mut self,
        t: f64,
        q: &[f64],
        free: &[usize],
        held: &[(usize, f64)],
        load_factor: f64,
        stop: Option<&AtomicBool>,
    ) -> Result<Vec<f64>, DynamicsError> {
        self.static_factor = None;
        let (g, tan) = self.static_tangent_until(t, q, stop)?;
        if crate::simulate::stop_requested(stop) {
            return Err(DynamicsError::Interrupted);
        }
        let tf = Mat::from_fn(free.len(), free.len(), |a, b| tan[(free[a], free[b])]);
        let mut lu = DenseLu::default();
        if let Err(source) = lu.factor(tf.as_ref()) {
            // named once, when the solve gives up (see `unrestrained_at`)
            return Err(DynamicsError::SingularTangent {
                load_factor,
                unrestrained: vec![],
                source,
            });
        }
        let coupling = held
            .iter()
            .flat_map(|&(h, _)| free.iter().map(move |&a| (a, h)))
            .map(|(a, h)| tan[(a, h)])
            .collect();
        let diag_max = free.iter().fold(0.0f64, |m, &a| m.max(tan[(a, a)].abs()));
        let weights = free
            .iter()
            .map(|&a| {
                1.0 / tan[(a, a)]
                    .abs()
                    .max(1e-12 * diag_max)
                    .max(f64::MIN_POSITIVE)
            })
            .collect();
        self.static_factor = Some(StaticFactor {
            lu,
            free: free.to_vec(),
            coupling,
            weights,
        });
        Ok(g)
    }

    /// The first-order (Euler) predictor of a continuation in the held
    /// values: when the held DOFs move by Δh, the free ones follow
    /// Δq_f = −K_ff⁻¹ K_fh Δh (the tangent (E.6) of the last equilibrium,
    /// or of its last chord iterate), so that Newton starts O(Δh²) from the
    /// new equilibrium instead of O(Δh). Without it, a held coordinate that
    /// moves alone strains the loop-closure deformations by O(Δh) and Newton
    /// wanders for tens of iterations (issue 14 item 7: with gravity the
    /// sweep over S.x of the spatial guidance took 10× as long as without).
    /// Does nothing without a factor for these free DOFs.
    fn predict_free(&self, q: &mut [f64], free: &[usize], dh: &[f64]) {
        let Some(f) = &self.static_factor else {
            return;
        };
        let nf = free.len();
        if f.free != free || f.coupling.len() != nf * dh.len() || dh.iter().all(|d| *d == 0.0) {
            return;
        }
        let mut rhs = vec![0.0; nf];
        for (k, d) in dh.iter().enumerate() {
            for (r, c) in rhs.iter_mut().zip(&f.coupling[k * nf..(k + 1) * nf]) {
                *r -= c * d;
            }
        }
        f.lu.solve_vec_with(&mut rhs, &mut vec![0.0; nf]);
        if rhs.iter().all(|v| v.is_finite()) {
            for (i, d) in free.iter().zip(&rhs) {
                q[*i] += d;
            }
        }
    }

    /// The error for a static tangent found singular at q, naming the DOFs
    /// of the motion it leaves unrestrained (estimated null vectors of the
    /// tangent over the free DOFs, [`crate::null_space_dofs`]). Assembles
    /// the tangent again: called once, when the solve gives up, not at every
    /// retried increment.
    fn unrestrained_at(
        &mut self,
        t: f64,
        q: &[f64],
        free: &[usize],
        load_factor: f64,
        source: LuError,
    ) -> DynamicsError {
        let unrestrained = match self.static_tangent(t, q) {
            Ok((_, tan)) => {
                let tf = Mat::from_fn(free.len(), free.len(), |a, b| tan[(free[a], free[b])]);
                crate::null_space_dofs(&self.mech, tf.as_ref(), free)
            }
            Err(_) => vec![],
        };
        DynamicsError::SingularTangent {
            load_factor,
            unrestrained,
            source,
        }
    }

    /// Static equilibrium at time `t` (inputs at their values at t), starting
    /// from `q0`, with load increments and held degrees of freedom.
    ///
    /// Each increment of held values starts from the first-order predictor
    /// Δq_f = −K_ff⁻¹ K_fh Δh with the tangent at its start, and each
    /// Newton step must lower the energy-scaled out-of-balance Σ g_i²/|K_ii|
    /// or is halved (a chord step is retried with a fresh tangent), at most
    /// 12 times per increment; then plain Newton goes on. Together they made
    /// the held sweep of the spatial guidance under gravity 15–100× faster
    /// (issue 14 item 7, `tests/held_sweep.rs`).
    ///
    /// Stays on the physical branch: an iterate at which an element has
    /// flipped ([`flexmb_element::Element::is_flipped`]: its chord turned by
    /// more than π/2 against a node frame, where the periodic deformations
    /// (5.3b,c), (6.2b), (3.14b) fold back) has its Newton update halved, up
    /// to 10 times, then the load increment is cut; an
    /// equilibrium with a flipped element is [`DynamicsError::Flipped`].
    pub fn static_equilibrium(
        &mut self,
        t: f64,
        q0: &[f64],
        opts: &StaticOptions,
    ) -> Result<StaticSolution, DynamicsError> {
        let scale = self.load_scale;
        let solution = self.static_equilibrium_ramped(t, q0, opts, scale);
        self.load_scale = scale;
        solution
    }

    /// [`static_equilibrium`](Self::static_equilibrium) with the nodal loads
    /// at the scale `scale` at its end.
    fn static_equilibrium_ramped(
        &mut self,
        t: f64,
        q0: &[f64],
        opts: &StaticOptions,
        scale: f64,
    ) -> Result<StaticSolution, DynamicsError> {
        let n_q = self.mech.n_dof();
        let mut q = q0.to_vec();
        let mut held = vec![false; n_q];
        for &(i, _) in &opts.held {
            if i >= n_q {
                return Err(DynamicsError::Invalid(format!(
                    "held DOF index {i} ≥ {n_q}"
                )));
            }
            held[i] = true;
        }
        let held_start: Vec<f64> = opts.held.iter().map(|(i, _)| q0[*i]).collect();
        let free: Vec<usize> = (0..n_q).filter(|i| !held[*i]).collect();
        let mut lambda = 0.0;
        let max_dl = 1.0 / opts.load_steps.max(1) as f64;
        let mut dl = max_dl;
        let mut iterations = 0;
        let mut increments = 0;
        let mut last_good = q.clone();
        let mut last_err = None;
        let mut force_refresh = false;
        let mut failures = 0;
        // where the tangent was last found singular (q, load factor), to name
        // the unrestrained motion if the solve gives up
        let mut singular_at: Option<(Vec<f64>, f64)> = None;
        // the branch guard: the last update (to halve if its iterate flips an
        // element) and the configurations of the last unflipped iterate and of
        // the last converged increment (guesses for the kinematics after a
        // rejected iterate or increment)
        let mut dq_last = vec![0.0; free.len()];
        let mut dh = vec![0.0; opts.held.len()];
        // the watch on the dependent nodal coordinates (nodal DOFs), read
        // after each converged increment as a simulation reads it after
        // each step
        let mut partition = if self.mech.partition_eligible().is_empty() {
            None
        } else {
            self.kin
                .solve(&q, t)
                .ok()
                .and_then(|_| self.partition_watch())
        };
        let mut x_ok = self.kin.x().to_vec();
        let mut x_good = x_ok.clone();
        let mut chart_switches = vec![];
        let mut partition_switches = vec![];
        let held_slots: Vec<usize> = opts.held.iter().map(|(i, _)| *i).collect();
        while lambda < 1.0 - 1e-15 {
            let target = (lambda + dl).min(1.0);
            self.load_factor = if opts.ramp_loads { target } else { 1.0 };
            if let Some(s0) = opts.load_scale_from {
                self.load_scale = s0 + target * (scale - s0);
            }
            for (k, &(i, v)) in opts.held.iter().enumerate() {
                let value = held_start[k] + target * (v - held_start[k]);
                dh[k] = value - q[i];
                q[i] = value;
            }
            if dh.iter().any(|d| *d != 0.0) {
                let mut q_start = q.clone();
                for (k, &(i, _)) in opts.held.iter().enumerate() {
                    q_start[i] -= dh[k];
                }
                if self
                    .refresh_static_factor(
                        t,
                        &q_start,
                        &free,
                        &opts.held,
                        target,
                        opts.stop.as_deref(),
                    )
                    .is_ok()
                {
                    self.predict_free(&mut q, &free, &dh);
                }
            }
            let mut converged = false;
            let mut prev_dn = f64::INFINITY;
            let mut steps = 0;
            let mut halvings = 0;
            // the residual guard: the out-of-balance ‖g_f‖₂ at the iterate the
            // last step was taken from, whether that step was a chord step,
            // and the configuration there
            let mut g_from = f64::INFINITY;
            // in a narrow curved valley of the out-of-balance the halved
            // steps creep: after this many rejections per increment the
            // guard gives way to plain Newton
            let mut guard_budget = RESIDUAL_GUARD_BUDGET;
            let mut last_was_chord = false;
            while steps < opts.max_iterations {
                if crate::simulate::stop_requested(opts.stop.as_deref()) {
                    self.load_factor = 1.0;
                    return Err(DynamicsError::Interrupted);
                }
                iterations += 1;
                // chord Newton: keep the factorized tangent (of an earlier
                // iterate, increment or call) while its steps shrink by at
                // least CHORD_CONTRACTION; a chord step that does not is
                // rejected and replaced by a Newton step from the same point
                let refreshed =
                    force_refresh || self.static_factor.as_ref().is_none_or(|f| f.free != free);
                let evaluated = if refreshed {
                    self.refresh_static_factor(
                        t,
                        &q,
                        &free,
                        &opts.held,
                        target,
                        opts.stop.as_deref(),
                    )
                } else {
                    self.static_residual(t, &q)
                };
                let g = match evaluated {
                    Ok(g) => g,
                    Err(DynamicsError::Interrupted) => {
                        self.load_factor = 1.0;
                        return Err(DynamicsError::Interrupted);
                    }
                    Err(e) => {
                        if matches!(e, DynamicsError::SingularTangent { .. }) {
                            singular_at = Some((q.clone(), self.load_factor));
                        }
                        last_err = Some(e);
                        break;
                    }
                };
                force_refresh = false;
                // an iterate that flips an element is on a spurious branch of
                // the periodic deformation functions: halve the update that
                // led there (with a tangent and a kinematic guess from before
                // it), or cut the increment
                if let Some((e, angle)) = self.mech.flipped_element(self.kin.x()) {
                    if steps == 0 || halvings == MAX_FLIP_HALVINGS {
                        last_err = Some(DynamicsError::Flipped {
                            element: e.id.clone(),
                            angle_deg: angle.to_degrees(),
                            load_factor: target,
                        });
                        break;
                    }
                    halvings += 1;
                    retract(&mut q, &free, &mut dq_last, 0.5);
                    self.kin.set_guess(&x_ok);
                    force_refresh = true;
                    continue;
                }
                // the residual guard: a step that raised the out-of-balance
                // left Newton's region of convergence (the torsion of sheet
                // flexures under gravity couples to their stiff bending: one
                // full step can raise it 100-fold and Newton then wandered
                // for tens of iterations). The out-of-balance is measured
                // as Σ g_i²/|K_ii|, an energy, so that stiff elongations do
                // not outweigh soft torsions. A chord step that raised it is
                // undone and retried with a fresh tangent; a Newton step is
                // halved (a NaN counts as raised). Steps at the round-off
                // level of q are exempt.
                let gn = match &self.static_factor {
                    Some(f) if f.free == free => free
                        .iter()
                        .zip(&f.weights)
                        .map(|(i, w)| g[*i] * g[*i] * w)
                        .sum::<f64>(),
                    _ => f64::INFINITY,
                };
                let qn = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let last_dn = dq_last.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                if steps > 0
                    && guard_budget > 0
                    && !matches!(
                        gn.partial_cmp(&g_from),
                        Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
                    )
                    && last_dn > RESIDUAL_GUARD_FLOOR * opts.tol * (1.0 + qn)
                {
                    guard_budget -= 1;
                    if last_was_chord {
                        retract(&mut q, &free, &mut dq_last, 1.0);
                        last_was_chord = false;
                        steps -= 1;
                        prev_dn = f64::INFINITY;
                        self.kin.set_guess(&x_ok);
                        force_refresh = true;
                        continue;
                    }
                    if halvings < MAX_FLIP_HALVINGS {
                        halvings += 1;
                        retract(&mut q, &free, &mut dq_last, 0.5);
                        self.kin.set_guess(&x_ok);
                        continue;
                    }
                    // no descent along the Newton direction: cut the increment
                    break;
                }
                halvings = 0;
                x_ok.copy_from_slice(self.kin.x());
                if increments == 0 && steps == 0 {
                    x_good.copy_from_slice(&x_ok);
                }
                let Some(factor) = &self.static_factor else {
                    break;
                };
                let mut dq: Vec<f64> = free.iter().map(|i| -g[*i]).collect();
                factor
                    .lu
                    .solve_vec_with(&mut dq, &mut vec![0.0; free.len()]);
                let dn = dq.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                // (NaN included: a non-finite chord step is rejected too)
                let contracts = dn <= CHORD_CONTRACTION * prev_dn;
                if !refreshed && !contracts {
                    force_refresh = true;
                    continue;
                }
                if !dn.is_finite() {
                    break;
                }
                steps += 1;
                for (k, i) in free.iter().enumerate() {
                    q[*i] += dq[k];
                }
                dq_last.copy_from_slice(&dq);
                g_from = gn;
                last_was_chord = !refreshed;
                if dn <= opts.tol * (1.0 + qn) {
                    converged = true;
                    break;
                }
                prev_dn = dn;
            }
            if converged {
                lambda = target;
                increments += 1;
                // with nodal DOFs, a dependent set that has got
                // ill-conditioned is chosen again (a beam with rigid
                // elongations near 90°), the held DOFs staying DOFs; then a
                // free orientation that turned far gets a regular chart
                // before the next increment (the one it has is singular
                // 180° from where it was chosen): q in the new set and
                // chart, the same configuration
                let rest = vec![0.0; n_q];
                let degraded = partition
                    .as_mut()
                    .filter(|w| w.degraded(self.kin.pivot_ratio()));
                if let Some(chosen) = degraded.map(|w| w.quality(self)) {
                    let q_here = q.clone();
                    let log = &mut partition_switches;
                    match self.switch_partition(t, &q_here, &rest, chosen, &held_slots, log)? {
                        Some((q1, _)) => {
                            // a static solve logs the load factor
                            if let Some(sw) = partition_switches.last_mut() {
                                sw.t = lambda;
                            }
                            q = q1;
                            x_ok.copy_from_slice(self.kin.x());
                            force_refresh = true;
                            partition = self.partition_watch();
                        }
                        None => {
                            if let Some(w) = &mut partition {
                                w.reference = self.kin.pivot_ratio();
                            }
                        }
                    }
                }
                let q_here = q.clone();
                let logged = chart_switches.len();
                if let Some((q1, _)) =
                    self.switch_charts(t, &q_here, &rest, &held_slots, &mut chart_switches)?
                {
                    for sw in &mut chart_switches[logged..] {
                        sw.t = lambda;
                    }
                    q = q1;
                    x_ok.copy_from_slice(self.kin.x());
                    force_refresh = true;
                    partition = self.partition_watch();
                }
                last_good.copy_from_slice(&q);
                x_good.copy_from_slice(&x_ok);
                dl = (dl * 2.0).min(max_dl);
            } else {
                // retry a smaller increment with a tangent at its start
                force_refresh = true;
                q.copy_from_slice(&last_good);
                self.kin.set_guess(&x_good);
                let _ = self.kin.solve(&q, t);
                dl *= 0.5;
                // without ramped loads, load scale or held values every
                // increment is the same problem: one retry with a fresh
                // tangent, no more
                failures += 1;
                let ramps =
                    opts.ramp_loads || !opts.held.is_empty() || opts.load_scale_from.is_some();
                if dl < opts.min_increment || (!ramps && failures > 1) {
                    if let (
                        Some(DynamicsError::SingularTangent {
                            load_factor,
                            source,
                            ..
                        }),
                        Some((qs, lf)),
                    ) = (&last_err, &singular_at)
                    {
                        let (load_factor, source) = (*load_factor, *source);
                        self.load_factor = *lf;
                        last_err = Some(self.unrestrained_at(t, qs, &free, load_factor, source));
                        self.kin.set_guess(&x_good);
                        let _ = self.kin.solve(&q, t);
                    }
                    self.load_factor = 1.0;
                    return Err(DynamicsError::StaticNotConverged {
                        load_factor: lambda,
                        cause: last_err
                            .map(|e| e.to_string())
                            .unwrap_or_else(|| "Newton diverged".into()),
                    });
                }
            }
        }
        self.load_factor = 1.0;
        let g = self.static_residual(t, &q)?;
        if let Some((e, angle)) = self.mech.flipped_element(self.kin.x()) {
            return Err(DynamicsError::Flipped {
                element: e.id.clone(),
                angle_deg: angle.to_degrees(),
                load_factor: 1.0,
            });
        }
        let reactions = opts.held.iter().map(|(i, _)| g[*i]).collect();
        Ok(StaticSolution {
            x: self.kin.x().to_vec(),
            eps: self.kin.eps().to_vec(),
            q,
            iterations,
            increments,
            reactions,
            chart_switches,
            partition_switches,
        })
    }
}
