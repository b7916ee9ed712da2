//! The models a chapter compares (unreduced and reduced) and what is measured
//! on each: quasi-static eigenfrequency curves along a load parameter, and
//! time responses with their cost.

use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions, StaticOptions};
use flexmb_model::Mechanism;
use flexmb_reduction::{Basis, FixedBasis, InterpolatedBasis, MechanicalModel, ReducedModel};
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

    /// A fresh instance of the model: the unreduced dynamics or the reduced
    /// model over its basis, behind the one interface of both.
    pub fn instance(&self) -> Result<Box<dyn MechanicalModel>, String> {
        let b: Box<dyn Basis> = match &self.kind {
            ModelKind::Unreduced => return Ok(Box::new(Dynamics::new(self.mech.clone()))),
            ModelKind::Fixed(b) => Box::new(b.clone()),
            ModelKind::Interpolated(b) => b.clone(),
        };
        let reduced =
            ReducedModel::new(self.mech.clone(), b).map_err(|e| format!("{}: {e}", self.name))?;
        Ok(Box::new(reduced))
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
    let probe = NodeProbe::new(&model.mech, node)?;
    quasi_static_curve_of(model, t, lambdas, count, &|x| probe.displacement_in(x))
}

/// [`quasi_static_curve`] with the curve's `position` any function of the
/// equilibrium's nodal coordinates x (a rotation angle, say).
pub fn quasi_static_curve_of(
    model: &Model,
    t: f64,
    lambdas: &[f64],
    count: usize,
    position: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Result<Vec<CurvePoint>, String> {
    let ctx = |e: flexmb_reduction::ReductionError| format!("{}: {e}", model.name);
    let mut m = model.instance()?;
    // all frequencies, for the highest; a reduced model keeps all of them
    let all = m.n_coordinates();
    let keep = if m.is_reduced() { all } else { count };
    let points = m
        .frequency_sweep(t, lambdas, all, &mut |_| Control::Continue)
        .map_err(ctx)?;
    Ok(points
        .into_iter()
        .map(|p| CurvePoint {
            lambda: p.load_scale,
            position: position(&p.equilibrium.x),
            highest: p.frequencies.last().copied().unwrap_or(0.0),
            freqs: p.frequencies.into_iter().take(keep).collect(),
        })
        .collect())
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

/// The configuration a simulation starts from, at rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// The static equilibrium at t0 (loads and gravity at t0).
    Equilibrium,
    /// The reference configuration of the scene (undeflected).
    Reference,
}

/// Simulates a model from its static equilibrium at t0 (loads and gravity at
/// t0), at rest. `progress(t)` is called at each output time.
pub fn simulate(
    model: &Model,
    opts: &SimulationOptions,
    node: &str,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Response, String> {
    simulate_from(model, opts, node, Start::Equilibrium, progress)
}

/// Simulates a model from `start`, at rest; `progress(t)` is called at each
/// output time.
pub fn simulate_from(
    model: &Model,
    opts: &SimulationOptions,
    node: &str,
    start: Start,
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
    let mut m = model.instance()?;
    m.set_load_scale(1.0);
    let reference = m.reference_coordinates();
    let start = match start {
        // the static equilibrium at t0 under the full loads, from the reference
        Start::Equilibrium => {
            m.static_equilibrium(t0, &reference, &StaticOptions::default())
                .map_err(|e| ctx(e.to_string()))?
                .coordinates
        }
        Start::Reference => reference,
    };
    let cd0 = vec![0.0; start.len()];
    let tr = m
        .simulate(t0, &start, &cd0, opts, &mut |t, _, _| {
            progress(t);
            Control::Continue
        })
        .map_err(|e| ctx(e.to_string()))?;
    let z = m.is_reduced().then_some(tr.coordinates);
    let full = tr.full;
    let (t, q, x) = (full.t, full.q, full.x);
    let evaluations = full.stats.rhs_evals as u64;
    let steps = full.stats.steps_accepted as u64;
    let wall_time = full.wall_time;
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
    let mut m = model.instance()?;
    // the position solve starts at the configuration of the response there
    m.dynamics_mut().kinematics_mut().set_guess(&r.x[i]);
    let c = r.z.as_ref().map_or(&r.q[i], |z| &z[i]);
    m.eigenfrequencies(t, c, count).map_err(|e| e.to_string())
}
