//! The models a chapter compares (unreduced and reduced) and what is measured
//! on each: quasi-static eigenfrequency curves along a load parameter, and
//! time responses with their cost.

use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions, StaticOptions};
use flexmb_linearize::undamped_modes;
use flexmb_model::Mechanism;
use flexmb_reduction::{load_scale_path, Basis, FixedBasis, InterpolatedBasis, ReducedModel};
use std::sync::Arc;

/// How a model constrains the degrees of freedom.
#[derive(Clone)]
pub enum ModelKind {
    /// All degrees of freedom.
    Unreduced,
    /// A fixed basis (6.16).
    Fixed(FixedBasis),
    /// An interpolated basis (6.23).
    Interpolated(Box<InterpolatedBasis>),
}

/// A named model of a mechanism.
#[derive(Clone)]
pub struct Model {
    /// Name as in the thesis (e.g. "MSI-7").
    pub name: String,
    /// The (unreduced) mechanism it is evaluated on.
    pub mech: Arc<Mechanism>,
    /// Its constraint.
    pub kind: ModelKind,
}

impl Model {
    /// A model.
    pub fn new(name: &str, mech: &Arc<Mechanism>, kind: ModelKind) -> Self {
        Self {
            name: name.into(),
            mech: mech.clone(),
            kind,
        }
    }

    /// The reduced model, if reduced.
    pub fn reduced(&self) -> Option<ReducedModel> {
        let b: Box<dyn Basis> = match &self.kind {
            ModelKind::Unreduced => return None,
            ModelKind::Fixed(b) => Box::new(b.clone()),
            ModelKind::Interpolated(b) => b.clone(),
        };
        Some(ReducedModel::new(self.mech.clone(), b))
    }

    /// Number of coordinates integrated (n_q or n_z).
    pub fn size(&self) -> usize {
        match &self.kind {
            ModelKind::Unreduced => self.mech.n_dof(),
            ModelKind::Fixed(b) => b.n_z(),
            ModelKind::Interpolated(b) => b.n_z(),
        }
    }
}

/// Displacements of one node (from its reference position) in a
/// configuration that a solver found (no position solve of its own).
pub struct NodeProbe {
    index: Vec<usize>,
    at: Vec<f64>,
}

impl NodeProbe {
    /// A probe of node `id`.
    pub fn new(mech: &Arc<Mechanism>, id: &str) -> Result<Self, String> {
        let node = mech
            .node(id)
            .ok_or_else(|| format!("no node '{id}' in {}", mech.name))?;
        Ok(Self {
            index: node.position.clone(),
            at: node.at.clone(),
        })
    }
    /// The node's displacement in the configuration x (nodal coordinates).
    pub fn displacement_in(&self, x: &[f64]) -> Vec<f64> {
        self.index
            .iter()
            .zip(&self.at)
            .map(|(i, a)| x[*i] - a)
            .collect()
    }
}

/// One point of a quasi-static curve.
#[derive(Clone, Debug)]
pub struct CurvePoint {
    /// The load scale.
    pub lambda: f64,
    /// The probed node's displacement.
    pub position: Vec<f64>,
    /// Undamped eigenfrequencies (Hz), ascending (all of a reduced model, the
    /// requested number of an unreduced one).
    pub freqs: Vec<f64>,
    /// The highest eigenfrequency of the model (Hz).
    pub highest: f64,
}

/// The state a continuation carries: q (unreduced) or z (reduced).
enum Solver {
    Full(Box<Dynamics>, Vec<f64>),
    Reduced(Box<ReducedModel>, Vec<f64>),
}

impl Solver {
    fn new(model: &Model) -> Self {
        match model.reduced() {
            None => Solver::Full(Box::new(Dynamics::new(model.mech.clone())), model.mech.q0()),
            Some(r) => {
                let z = r.basis().z_reference();
                Solver::Reduced(Box::new(r), z)
            }
        }
    }
    fn state(&self) -> Vec<f64> {
        match self {
            Solver::Full(_, q) | Solver::Reduced(_, q) => q.clone(),
        }
    }
    fn set_state(&mut self, s: Vec<f64>) {
        match self {
            Solver::Full(_, q) | Solver::Reduced(_, q) => *q = s,
        }
    }
    /// Scales the scene's loads by λ (gravity stays).
    fn set_load_scale(&mut self, lambda: f64) {
        match self {
            Solver::Full(dy, _) => dy.set_load_scale(lambda),
            Solver::Reduced(r, _) => r.set_load_scale(lambda),
        }
    }
    /// Equilibrium at load scale λ from the current state.
    fn equilibrium(&mut self, t: f64, lambda: f64, first: bool) -> Result<(), String> {
        match self {
            Solver::Full(dy, q) => {
                dy.set_load_scale(lambda);
                let o = StaticOptions {
                    ramp_loads: first,
                    ..Default::default()
                };
                *q = dy
                    .static_equilibrium(t, q, &o)
                    .map_err(|e| e.to_string())?
                    .q;
            }
            Solver::Reduced(r, z) => {
                r.set_load_scale(lambda);
                *z = r.static_equilibrium(t, z, &[]).map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    }
    /// The nodal coordinates of the last position solve.
    fn x(&self) -> Vec<f64> {
        match self {
            Solver::Full(dy, _) => dy.kinematics().x().to_vec(),
            Solver::Reduced(r, _) => r.dynamics().kinematics().x().to_vec(),
        }
    }
    /// Starts the next position solve at the configuration x.
    fn set_guess(&mut self, x: &[f64]) {
        match self {
            Solver::Full(dy, _) => dy.kinematics_mut().set_guess(x),
            Solver::Reduced(r, _) => r.dynamics_mut().kinematics_mut().set_guess(x),
        }
    }
    /// Eigenfrequencies at the current state (load scale as last set).
    fn frequencies(&mut self, t: f64, count: usize) -> Result<(Vec<f64>, f64), String> {
        match self {
            Solver::Full(dy, q) => {
                let lin = dy.linearize_at_rest(t, q).map_err(|e| e.to_string())?;
                let all = undamped_modes(&lin, lin.m.nrows()).map_err(|e| e.to_string())?;
                let f = all.frequencies_hz();
                let highest = f.last().copied().unwrap_or(0.0);
                Ok((f.into_iter().take(count).collect(), highest))
            }
            Solver::Reduced(r, z) => {
                let z = z.clone();
                let f = r.frequencies_at_rest(t, &z).map_err(|e| e.to_string())?;
                let highest = f.last().copied().unwrap_or(0.0);
                Ok((f, highest))
            }
        }
    }
}

/// The quasi-static eigenfrequency curve of a model: at each load scale of
/// `lambdas` (loads evaluated at `t`, gravity as in the scene) the static
/// equilibrium by continuation from λ = 0 outwards
/// ([`flexmb_reduction::load_scale_path`]), the probed node's
/// position and the eigenfrequencies of the rest linearization ((E.6) or
/// (F.7)). `count` limits the unreduced model's frequencies.
pub fn quasi_static_curve(
    model: &Model,
    t: f64,
    lambdas: &[f64],
    node: &str,
    count: usize,
) -> Result<Vec<CurvePoint>, String> {
    let ctx = |e: String| format!("{}: {e}", model.name);
    let probe = NodeProbe::new(&model.mech, node)?;
    let mut s = Solver::new(model);
    s.equilibrium(t, 0.0, true).map_err(ctx)?;
    // a state is the equilibrium and its configuration: every position solve
    // starts at the configuration of the equilibrium it continues from or
    // evaluates, never at another end of the path
    let at_zero = (s.state(), s.x());
    // continuation outwards from λ = 0 (shared with `flexmb sweep --reduced`)
    type State = (Vec<f64>, Vec<f64>);
    let mut solve = |state: &State, l: f64| -> Result<State, String> {
        s.set_state(state.0.clone());
        s.set_guess(&state.1);
        s.equilibrium(t, l, false)?;
        Ok((s.state(), s.x()))
    };
    let states = load_scale_path(&at_zero, lambdas, &mut solve, &mut |_| {})
        .map_err(|e| ctx(e.to_string()))?;
    lambdas
        .iter()
        .zip(states)
        .map(|(l, (state, x))| {
            s.set_state(state);
            s.set_guess(&x);
            s.set_load_scale(*l);
            let (freqs, highest) = s.frequencies(t, count).map_err(ctx)?;
            Ok(CurvePoint {
                lambda: *l,
                position: probe.displacement_in(&x),
                freqs,
                highest,
            })
        })
        .collect()
}

/// A time response and what it cost.
#[derive(Clone, Debug)]
pub struct Response {
    /// Output times.
    pub t: Vec<f64>,
    /// The probed node's displacement at each output time.
    pub position: Vec<Vec<f64>>,
    /// The DOFs q at each output time.
    pub q: Vec<Vec<f64>>,
    /// The nodal coordinates x at each output time, solved along the run.
    pub x: Vec<Vec<f64>>,
    /// The reduced coordinates z at each output time (reduced models).
    pub z: Option<Vec<Vec<f64>>>,
    /// Right-hand-side (or residual) evaluations.
    pub evaluations: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Wall time of the integration (s).
    pub wall_time: f64,
    /// Integrator and tolerances, for the report.
    pub settings: String,
}

/// Simulates a model from its static equilibrium at t0 (loads and gravity at
/// t0), at rest. `progress(t)` is called at each output time.
pub fn simulate(
    model: &Model,
    opts: &SimulationOptions,
    node: &str,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Response, String> {
    let ctx = |e: String| format!("{}: {e}", model.name);
    let t0 = opts.output_times[0];
    let settings = format!(
        "{} rtol {:.0e} atol {:.0e}",
        match opts.integrator {
            Integrator::Dopri5 => "DOPRI5 (ode45-like)",
            Integrator::Adams => "Adams (Shampine–Gordon)",
            Integrator::GeneralizedAlpha => "generalized-α (implicit)",
        },
        opts.rtol,
        opts.atol
    );
    let probe = NodeProbe::new(&model.mech, node)?;
    let mut s = Solver::new(model);
    s.equilibrium(t0, 1.0, true).map_err(ctx)?;
    let start = s.state();
    let (t, q, x, z, evaluations, steps, wall_time) = match s {
        Solver::Full(mut dy, _) => {
            let qd0 = vec![0.0; start.len()];
            let tr = dy
                .simulate(t0, &start, &qd0, opts, |t, _, _| {
                    progress(t);
                    Control::Continue
                })
                .map_err(|e| ctx(e.to_string()))?;
            (
                tr.t,
                tr.q,
                tr.x,
                None,
                tr.stats.rhs_evals as u64,
                tr.stats.steps_accepted as u64,
                tr.wall_time,
            )
        }
        Solver::Reduced(mut r, _) => {
            let zd0 = vec![0.0; start.len()];
            let tr = r
                .simulate(t0, &start, &zd0, opts, |t, _, _| {
                    progress(t);
                    Control::Continue
                })
                .map_err(|e| ctx(e.to_string()))?;
            let q: Vec<Vec<f64>> = tr.z.iter().map(|z| r.full_coordinates(z)).collect();
            (
                tr.t,
                q,
                tr.x,
                Some(tr.z),
                tr.stats.rhs_evals as u64,
                tr.stats.steps_accepted as u64,
                tr.wall_time,
            )
        }
    };
    // from the configurations solved along the run (not again afterwards)
    let position = x.iter().map(|xx| probe.displacement_in(xx)).collect();
    Ok(Response {
        t,
        position,
        q,
        x,
        z,
        evaluations,
        steps,
        wall_time,
        settings,
    })
}

/// Undamped eigenfrequencies (Hz) of a model at rest at the state of output
/// `i` of its response ((E.6), reduced (F.7)), the first `count`.
pub fn frequencies_along(
    model: &Model,
    r: &Response,
    i: usize,
    count: usize,
) -> Result<Vec<f64>, String> {
    let t = r.t[i];
    // the position solves start at the configuration of the response there
    match (model.reduced(), &r.z) {
        (Some(mut red), Some(z)) => {
            red.dynamics_mut().kinematics_mut().set_guess(&r.x[i]);
            let f = red
                .frequencies_at_rest(t, &z[i])
                .map_err(|e| e.to_string())?;
            Ok(f.into_iter().take(count).collect())
        }
        _ => {
            let mut dy = Dynamics::new(model.mech.clone());
            dy.kinematics_mut().set_guess(&r.x[i]);
            let lin = dy
                .linearize_at_rest(t, &r.q[i])
                .map_err(|e| e.to_string())?;
            Ok(undamped_modes(&lin, count)
                .map_err(|e| e.to_string())?
                .frequencies_hz())
        }
    }
}
