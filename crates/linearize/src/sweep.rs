//! Eigenfrequencies along the range of motion: at each of n configurations the
//! static equilibrium (a continuation from the previous one), then the rest
//! linearization (E.6) and the undamped modes; the linearizations and eigen
//! analyses run in parallel (rayon), each worker with its own dynamics.

use crate::{undamped_modes_until, LinearizeError, Modes};
use faer::Mat;
use flexmb_dynamics::{short_number, Dynamics, DynamicsError, StaticOptions};
use flexmb_model::{ChartSwitch, Mechanism, PartitionSwitch};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Equilibria, modes and mass matrices of one worker's block of
/// configurations (in the sweep's chart), with each configuration's index
/// (the block's first ones if stopped).
type BlockResult = Result<Vec<(usize, Vec<f64>, Modes, Mat<f64>)>, LinearizeError>;

/// What varies along the sweep.
pub enum SweepParameter {
    /// The nodal loads are scaled by s (gravity stays).
    LoadScale,
    /// The degree of freedom with this index is held at s (its reaction is the
    /// actuation force).
    Dof(usize),
    /// Several degrees of freedom follow a path P(s) (thesis (4.1)).
    Path {
        /// The held DOF indices.
        dofs: Vec<usize>,
        /// Their values as functions of s.
        path: Box<dyn Fn(f64) -> Vec<f64> + Sync + Send>,
    },
}

/// Settings of a sweep.
pub struct SweepOptions {
    /// Sweep parameter values.
    pub values: Vec<f64>,
    /// Number of modes per configuration.
    pub modes: usize,
    /// Time at which loads are evaluated.
    pub t: f64,
    /// Keep the mode shapes (in q).
    pub keep_vectors: bool,
}

/// One configuration of a sweep.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// The sweep parameter.
    pub s: f64,
    /// The equilibrium DOFs, in the chart of the sweep's mechanism (also
    /// where the static solve switched the chart of an orientation that
    /// turned far: every point is in the same DOFs).
    pub q: Vec<f64>,
    /// The generalized forces that hold the held DOFs at their values (the
    /// actuation force along the stroke; [`SweepParameter::Dof`] and
    /// [`SweepParameter::Path`], in their order), from the static
    /// out-of-balance at the equilibrium; empty for a load sweep.
    pub holding: Vec<f64>,
    /// The nodal coordinates of the equilibrium (the configuration the
    /// static solve converged to: a position solve from q alone, from
    /// another starting guess, can land on another branch).
    pub x: Vec<f64>,
    /// Undamped eigenfrequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Mode shapes (if kept), in the DOFs of [`q`](Self::q).
    pub modes: Option<Mat<f64>>,
    /// Mass matrix (if the shapes are kept: for MAC with mass weighting), in
    /// the DOFs of [`q`](Self::q).
    pub mass: Option<Mat<f64>>,
}

/// Sweep configuration `i` for messages: "load scale 0.5", or "s = 0.01:
/// DOF q3 = S.x (node S) held at 0.51" (every held DOF, at most four named).
fn describe_point(mech: &Mechanism, param: &SweepParameter, s: f64) -> String {
    let held = |dofs: &[usize], values: &[f64]| {
        let mut v: Vec<String> = dofs
            .iter()
            .zip(values)
            .take(4)
            .map(|(k, v)| format!("{} held at {}", mech.dof_label(*k), short_number(*v)))
            .collect();
        if dofs.len() > 4 {
            v.push(format!("and {} more held DOFs", dofs.len() - 4));
        }
        v.join(", ")
    };
    match param {
        SweepParameter::LoadScale => format!("load scale {s}"),
        SweepParameter::Dof(k) => held(&[*k], &[s]),
        SweepParameter::Path { dofs, path } => format!("s = {s}: {}", held(dofs, &path(s))),
    }
}

/// The error of sweep configuration `i` with the cause `message`.
fn failed_at(
    mech: &Mechanism,
    param: &SweepParameter,
    opts: &SweepOptions,
    i: usize,
    message: String,
) -> LinearizeError {
    let s = opts.values[i];
    LinearizeError::SweepConfiguration {
        index: i + 1,
        count: opts.values.len(),
        s,
        at: describe_point(mech, param, s),
        message,
    }
}

/// Runs a sweep. `progress(done, total)` is called as configurations finish.
pub fn sweep(
    mech: &Arc<Mechanism>,
    param: &SweepParameter,
    opts: &SweepOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<SweepPoint>, LinearizeError> {
    sweep_until(mech, param, opts, progress, None).map(|o| o.points)
}

/// What a sweep that may be stopped ([`sweep_until`]) computed.
#[derive(Clone, Debug)]
pub struct SweepOutcome {
    /// The configurations completed (equilibrium and modes), in the order of
    /// the sweep values; all of them unless stopped.
    pub points: Vec<SweepPoint>,
    /// How many equilibria were found (all n unless stopped in the first
    /// phase, which then computes no modes).
    pub equilibria: usize,
    /// True if the stop request ended the sweep early.
    pub stopped: bool,
    /// The Euler-parameter charts the static solves switched (nodes that
    /// turned far, [`flexmb_model::EulerChart`]), each with the index of
    /// the configuration whose equilibrium switched it. The points' q,
    /// shapes and masses are still in the chart of the sweep's mechanism.
    pub chart_switches: Vec<(usize, ChartSwitch)>,
    /// The changes of the dependent nodal coordinates the static solves
    /// made (nodal DOFs whose dependent set got ill-conditioned,
    /// [`flexmb_dynamics::StaticSolution::partition_switches`]), each with
    /// the index of its configuration. The points are still given in the
    /// DOFs of the sweep's mechanism.
    pub partition_switches: Vec<(usize, PartitionSwitch)>,
    /// The Newton iterations of the equilibria, in all
    /// ([`flexmb_dynamics::StaticSolution::iterations`]).
    pub iterations: usize,
}

/// True if `stop` is given and set.
fn requested(stop: Option<&Arc<AtomicBool>>) -> bool {
    stop.is_some_and(|s| s.load(Ordering::Relaxed))
}

/// [`sweep`] that ends early when `stop` is set: it is read before every
/// configuration of the equilibria and by every Newton iteration
/// ([`StaticOptions::stop`]), and inside the linearization and the eigen
/// analysis of each configuration
/// ([`Dynamics::linearize_at_rest_until`], [`undamped_modes_until`]). A sweep stopped while finding the
/// equilibria has no modes; one stopped in the eigen analyses returns the
/// configurations that are done.
pub fn sweep_until(
    mech: &Arc<Mechanism>,
    param: &SweepParameter,
    opts: &SweepOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    stop: Option<&Arc<AtomicBool>>,
) -> Result<SweepOutcome, LinearizeError> {
    let n = opts.values.len();
    let total = 2 * n;
    let mut dy = Dynamics::new(mech.clone());
    let mut q = mech.q0();
    let mut qs = Vec::with_capacity(n);
    // the configuration of each equilibrium: the linearization's position
    // solve starts there, not at the reference or at a neighbouring block
    let mut xs = Vec::with_capacity(n);
    let mut holding = Vec::with_capacity(n);
    // the chart of each equilibrium: the static solve switches the chart of
    // an orientation that turned far, and the continuation goes on in it
    let mut charts: Vec<Arc<Mechanism>> = Vec::with_capacity(n);
    let mut chart_switches = vec![];
    let mut partition_switches = vec![];
    let mut iterations = 0;
    // the equilibria since the last chart switch or failed extrapolation,
    // (s, q), at most the last three: the starting guess of the next one
    let mut recent: Vec<(f64, Vec<f64>)> = Vec::with_capacity(3);
    // phase 1: equilibria by continuation
    for (i, &s) in opts.values.iter().enumerate() {
        if requested(stop) {
            return Ok(stopped_early(
                i,
                chart_switches,
                partition_switches,
                iterations,
            ));
        }
        // the first equilibrium ramps the loads; the next ones continue from it
        let mut so = StaticOptions {
            ramp_loads: i == 0,
            stop: stop.cloned(),
            ..Default::default()
        };
        match param {
            SweepParameter::LoadScale => {
                // from the previous point's scale, in increments
                if i > 0 {
                    so.load_scale_from = Some(opts.values[i - 1]);
                }
                dy.set_load_scale(s);
            }
            SweepParameter::Dof(k) => so.held = vec![(*k, s)],
            SweepParameter::Path { dofs, path } => {
                let v = path(s);
                so.held = dofs.iter().copied().zip(v).collect();
            }
        }
        // from the quadratic extrapolation of the last three equilibria
        // (should that fail, from the last one)
        // (a load sweep ramps the scale from the last equilibrium instead)
        let extrapolated = recent.len() == 3 && !matches!(param, SweepParameter::LoadScale);
        let guess = extrapolated.then(|| extrapolate(&recent, s));
        let mut solved = match &guess {
            Some(g) => dy.static_equilibrium(opts.t, g, &so),
            None => dy.static_equilibrium(opts.t, &q, &so),
        };
        if guess.is_some() && !matches!(solved, Ok(_) | Err(DynamicsError::Interrupted)) {
            recent.clear();
            // from the last equilibrium's own configuration: the failed
            // attempt left the position solve where it failed, from which q
            // can be solved onto a flipped branch
            if let Some(x) = xs.last() {
                let x: &Vec<f64> = x;
                dy.kinematics_mut().set_guess(x);
            }
            solved = dy.static_equilibrium(opts.t, &q, &so);
        }
        if i > 0
            && matches!(param, SweepParameter::LoadScale)
            && !matches!(solved, Ok(_) | Err(DynamicsError::Interrupted))
        {
            // the loads are not ramped from the last equilibrium (it carries
            // them at its own scale): ramp the scale instead
            recent.clear();
            let s_prev = opts.values[i - 1];
            solved = load_scale_steps(&mut dy, opts.t, &q, s_prev, s, &so, &mut iterations);
        }
        let sol = match solved {
            Ok(sol) => sol,
            Err(DynamicsError::Interrupted) => {
                return Ok(stopped_early(
                    i,
                    chart_switches,
                    partition_switches,
                    iterations,
                ))
            }
            Err(e) => return Err(failed_at(mech, param, opts, i, e.to_string())),
        };
        iterations += sol.iterations;
        if !sol.chart_switches.is_empty() || !sol.partition_switches.is_empty() {
            // the earlier equilibria are in other charts or DOFs
            recent.clear();
        }
        if recent.len() == 3 {
            recent.remove(0);
        }
        recent.push((s, sol.q.clone()));
        q = sol.q;
        qs.push(q.clone());
        xs.push(sol.x);
        charts.push(dy.mechanism().clone());
        chart_switches.extend(sol.chart_switches.into_iter().map(|c| (i, c)));
        partition_switches.extend(sol.partition_switches.into_iter().map(|c| (i, c)));
        holding.push(sol.reactions);
        progress(i + 1, total);
    }
    // phase 2: linearization and eigen analysis in parallel
    let done = std::sync::atomic::AtomicUsize::new(n);
    let scale: Vec<f64> = opts
        .values
        .iter()
        .map(|s| {
            if matches!(param, SweepParameter::LoadScale) {
                *s
            } else {
                1.0
            }
        })
        .collect();
    let chunk = n.div_ceil(rayon::current_num_threads().max(1)).max(1);
    let results: Vec<BlockResult> = qs
        .par_chunks(chunk)
        .enumerate()
        .map(|(c, block)| {
            let mut dy = Dynamics::new(charts[c * chunk].clone());
            let flag = stop.map(|s| s.as_ref());
            let mut out = Vec::with_capacity(block.len());
            for (j, q) in block.iter().enumerate() {
                let i = c * chunk + j;
                if !Arc::ptr_eq(dy.mechanism(), &charts[i]) {
                    dy = Dynamics::new(charts[i].clone());
                }
                dy.set_load_scale(scale[i]);
                dy.kinematics_mut().set_guess(&xs[i]);
                let fail = |m: String| failed_at(mech, param, opts, i, m);
                let lin = match dy.linearize_at_rest_until(opts.t, q, flag) {
                    Ok(lin) => lin,
                    Err(DynamicsError::Interrupted) => break,
                    Err(e) => return Err(fail(e.to_string())),
                };
                let mut modes = match undamped_modes_until(&lin, opts.modes, flag) {
                    Ok(modes) => modes,
                    Err(LinearizeError::Interrupted) => break,
                    Err(e) => return Err(fail(e.to_string())),
                };
                let (mut q, mut m) = (q.clone(), lin.m);
                if !Arc::ptr_eq(&charts[i], mech) {
                    (q, m) = in_sweep_chart(&mut dy, mech, &mut modes, m, opts.keep_vectors)
                        .map_err(fail)?;
                }
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                progress(d, total);
                out.push((i, q, modes, m));
            }
            Ok(out)
        })
        .collect();
    let mut points = Vec::with_capacity(n);
    for r in results {
        for (i, q, modes, m) in r? {
            points.push(SweepPoint {
                s: opts.values[i],
                q,
                holding: holding[i].clone(),
                x: xs[i].clone(),
                frequencies_hz: modes.frequencies_hz(),
                modes: opts.keep_vectors.then(|| modes.vectors.clone()),
                mass: opts.keep_vectors.then_some(m),
            });
        }
    }
    Ok(SweepOutcome {
        stopped: points.len() < n,
        points,
        equilibria: n,
        chart_switches,
        partition_switches,
        iterations,
    })
}

/// The equilibrium q and, if `with_mass` (the shapes are kept), the mode
/// shapes and the mass matrix `m` of a configuration linearized by `dy` in another chart than the
/// sweep's `mech` (an orientation turned far, [`flexmb_model::EulerChart`]),
/// given in the chart of `mech`: q read from the configuration, the shapes
/// as S v and the mass as S⁻ᵀ M S⁻¹ with S = ∂q/∂q_dy
/// ([`Dynamics::chart_jacobian`]), so that every point of a sweep is in
/// one chart (mass-normalized shapes stay so). The frequencies do not
/// depend on the chart. An error if `mech`'s chart is singular there and
/// the mass is wanted.
fn in_sweep_chart(
    dy: &mut Dynamics,
    mech: &Mechanism,
    modes: &mut Modes,
    m: Mat<f64>,
    with_mass: bool,
) -> Result<(Vec<f64>, Mat<f64>), String> {
    let (q, _) = dy.in_chart_of(mech);
    if !with_mass {
        return Ok((q, m));
    }
    let s = dy.chart_jacobian(mech);
    modes.vectors = &s * &modes.vectors;
    let mut lu = flexmb_linalg::DenseLu::new(s.nrows());
    lu.factor(s.as_ref()).map_err(|e| {
        format!(
            "the mass matrix cannot be given in the sweep's degrees of freedom, whose \
             Euler-parameter chart or dependent nodal coordinates are singular at this \
             configuration ({e}): sweep a range that stays within 180° of the start \
             orientation, or use deformations as DOFs"
        )
    })?;
    // S⁻ᵀ M, then (S⁻ᵀ (S⁻ᵀ M)ᵀ)ᵀ = S⁻ᵀ M S⁻¹ (M symmetric)
    let mut y = m;
    lu.solve_transpose_in_place(y.as_mut());
    let mut m_sweep = y.transpose().to_owned();
    lu.solve_transpose_in_place(m_sweep.as_mut());
    Ok((q, m_sweep.transpose().to_owned()))
}

/// The outcome of a sweep stopped after `equilibria` equilibria.
fn stopped_early(
    equilibria: usize,
    chart_switches: Vec<(usize, ChartSwitch)>,
    partition_switches: Vec<(usize, PartitionSwitch)>,
    iterations: usize,
) -> SweepOutcome {
    SweepOutcome {
        points: vec![],
        equilibria,
        stopped: true,
        chart_switches,
        partition_switches,
        iterations,
    }
}

/// Smallest fraction of a load-scale interval that [`load_scale_steps`]
/// steps by before giving up.
const MIN_LOAD_SCALE_FRACTION: f64 = 1.0 / 1024.0;

/// The equilibrium at load scale `s` continued from the equilibrium `q` at
/// `s_prev` in steps of the load scale: half the interval first (the whole
/// of it has failed), a step that fails is halved, one that converges is
/// doubled for the next, down to [`MIN_LOAD_SCALE_FRACTION`] of the
/// interval, each step ramped from its own start
/// ([`StaticOptions::load_scale_from`]): the fallback when the continuation
/// from the previous point in one ramp failed. Adds the Newton iterations of
/// the intermediate equilibria to `iterations`; leaves the load scale at `s`.
fn load_scale_steps(
    dy: &mut Dynamics,
    t: f64,
    q: &[f64],
    s_prev: f64,
    s: f64,
    so: &StaticOptions,
    iterations: &mut usize,
) -> Result<flexmb_dynamics::StaticSolution, DynamicsError> {
    let interval = s - s_prev;
    let (mut from, mut step, mut q) = (s_prev, 0.5 * interval, q.to_vec());
    loop {
        let last = (s - from).abs() <= step.abs();
        let target = if last { s } else { from + step };
        dy.set_load_scale(target);
        let so = StaticOptions {
            load_scale_from: so.load_scale_from.map(|_| from),
            ..so.clone()
        };
        match dy.static_equilibrium(t, &q, &so) {
            Ok(sol) if last => return Ok(sol),
            Ok(sol) => {
                *iterations += sol.iterations;
                q = sol.q;
                from = target;
                step *= 2.0;
            }
            Err(DynamicsError::Interrupted) => return Err(DynamicsError::Interrupted),
            Err(e) => {
                step *= 0.5;
                if step.abs() < MIN_LOAD_SCALE_FRACTION * interval.abs() {
                    dy.set_load_scale(s);
                    return Err(e);
                }
            }
        }
    }
}

/// The starting guess for the equilibrium at `s`: the quadratic through the
/// last three equilibria (sᵢ, qᵢ), evaluated at s (Lagrange form). Its error
/// is O(Δs³), against O(Δs²) for the tangent predictor of
/// `static_equilibrium`, which starts from the last equilibrium alone: under
/// gravity the sheet flexures' soft torsion amplifies the second-order error
/// of that predictor (the first correction was 2e-4 against 1e-6 without
/// gravity, issue 14 item 7), and Newton needed about twice the iterations.
fn extrapolate(recent: &[(f64, Vec<f64>)], s: f64) -> Vec<f64> {
    let w: Vec<f64> = (0..recent.len())
        .map(|a| {
            (0..recent.len())
                .filter(|&b| b != a)
                .map(|b| (s - recent[b].0) / (recent[a].0 - recent[b].0))
                .product()
        })
        .collect();
    (0..recent[0].1.len())
        .map(|j| recent.iter().zip(&w).map(|((_, q), w)| w * q[j]).sum())
        .collect()
}
