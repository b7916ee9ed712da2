//! `flexmb.Model` (all degrees of freedom) and `flexmb.ReducedModel`
//! (q = G(z)): statics, eigenfrequencies, sweeps, simulation and reduction,
//! as the command line drives them (crates/cli/src/main.rs), with numpy
//! arrays in and out.

use crate::errors;
use crate::reduce::{self, ReduceArgs};
use crate::results::{arr3, mat, vec1, EigResult, SimulationResult, StaticResult, SweepResult};
use crate::run::{self, Watch};
use crate::scene::Scene;
use flexmb::dynamics::{
    Control, Dynamics, Integrator, OutputTable, SimulationOptions, StaticOptions,
};
use flexmb::faer::Mat;
use flexmb::linearize::{SweepOptions, SweepParameter};
use flexmb::model::Mechanism;
use flexmb::reduction::{MechanicalModel, ReducedModel as RsReduced, SavedModel};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;

/// Reads a sequence of floats (list, tuple or numpy array) named `what`.
pub(crate) fn floats(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let np = obj.py().import("numpy")?;
    let a = np
        .call_method1("asarray", (obj, "float64"))
        .and_then(|a| a.call_method0("ravel"))
        .map_err(|e| errors::argument(format!("{what}: not a sequence of numbers ({e})")))?;
    let v: Vec<f64> = a.call_method0("tolist")?.extract()?;
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(errors::argument(format!(
            "{what}[{i}] is {}: the values must be finite",
            v[i]
        )));
    }
    Ok(v)
}

/// `value` of `name` must be positive and finite.
fn positive(name: &str, value: f64) -> PyResult<()> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(errors::argument(format!(
            "{name} must be positive and finite; got {value}"
        )))
    }
}

/// `value` of `name` must be finite.
fn finite(name: &str, value: f64) -> PyResult<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(errors::argument(format!(
            "{name} must be a finite number; got {value}"
        )))
    }
}

/// The number of modes: `k` if given (1 ≤ k ≤ `n`), else `default` or `n`
/// if that is fewer.
fn modes_or_default(k: Option<usize>, default: usize, n: usize) -> PyResult<usize> {
    match k {
        Some(0) => Err(errors::argument(
            "k (the number of modes) must be at least 1",
        )),
        Some(k) if k > n => Err(errors::argument(format!(
            "k = {k}: the model has {n} coordinates, so at most {n} modes"
        ))),
        Some(k) => Ok(k),
        None => Ok(default.min(n)),
    }
}

/// The index of the degree of freedom called `name` (as `info()` lists
/// them); `what` names the argument.
pub(crate) fn dof_index(mech: &Mechanism, name: &str, what: &str) -> PyResult<usize> {
    if let Some(k) = mech
        .dofs
        .iter()
        .position(|c| mech.coordinate_name(*c) == name)
    {
        return Ok(k);
    }
    let known = mech
        .x_names
        .iter()
        .chain(&mech.eps_names)
        .any(|x| x == name);
    Err(errors::argument(if known {
        format!(
            "{what} '{name}' is a coordinate of the scene but not one of its degrees of freedom; \
             make it one with `dofs_first` in the scene"
        )
    } else {
        format!("{what}: unknown coordinate '{name}' (Model.info()['dofs'] lists the degrees of freedom)")
    }))
}

/// A model's summary as a dict: names and counts.
fn info_dict<'py>(py: Python<'py>, mech: &Mechanism) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &mech.name)?;
    d.set_item("summary", mech.summary())?;
    d.set_item("dimension", format!("{:?}", mech.dimension))?;
    d.set_item("n_dof", mech.n_dof())?;
    d.set_item("n_x", mech.n_x())?;
    d.set_item("n_eps", mech.n_eps())?;
    let dofs: Vec<&str> = mech.dofs.iter().map(|c| mech.coordinate_name(*c)).collect();
    d.set_item("dofs", dofs)?;
    let inputs: Vec<&str> = mech
        .inputs
        .iter()
        .map(|i| mech.coordinate_name(i.target))
        .collect();
    d.set_item("inputs", inputs)?;
    let nodes: Vec<&str> = mech.nodes.iter().map(|n| n.id.as_str()).collect();
    d.set_item("nodes", nodes)?;
    d.set_item("coordinates", mech.x_names.clone())?;
    d.set_item("deformations", mech.eps_names.clone())?;
    Ok(d)
}

/// The rows of the nodes' position components of each column of `shapes`
/// (n_x × k): (k, n_nodes, dim), row-major.
fn nodal_positions(mech: &Mechanism, shapes: &Mat<f64>) -> (usize, usize, Vec<f64>) {
    let dim = mech.nodes.first().map_or(0, |n| n.position.len());
    let mut flat = vec![];
    for j in 0..shapes.ncols() {
        for n in &mech.nodes {
            flat.extend(n.position.iter().map(|i| shapes[(*i, j)]));
        }
    }
    (mech.nodes.len(), dim, flat)
}

/// The columns of `m` as rows.
fn columns(m: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..m.ncols())
        .map(|j| (0..m.nrows()).map(|i| m[(i, j)]).collect())
        .collect()
}

/// What a simulation returns from its worker: the run (or its error) and
/// the output rows.
type Run = Result<
    (
        flexmb::reduction::ModelTrajectory,
        Vec<Vec<f64>>,
        Vec<String>,
    ),
    PyErr,
>;

/// The options of one simulation, checked.
struct SimArgs {
    opts: SimulationOptions,
    t_end: f64,
    static_first: bool,
}

impl SimArgs {
    fn new(
        t_end: f64,
        outputs: usize,
        integrator: &str,
        rtol: f64,
        atol: f64,
        static_first: bool,
    ) -> PyResult<Self> {
        let integrator: Integrator = integrator.parse().map_err(errors::argument)?;
        positive("t_end", t_end)?;
        if outputs < 2 {
            return Err(errors::argument(format!(
                "outputs must be at least 2 (the output points include t = 0 and t_end); got {outputs}"
            )));
        }
        positive("rtol", rtol)?;
        positive("atol", atol)?;
        let mut opts = SimulationOptions::new(integrator, 0.0, t_end, outputs);
        opts.rtol = rtol;
        opts.atol = atol;
        Ok(Self {
            opts,
            t_end,
            static_first,
        })
    }
}

/// Integrates `model` as `flexmb simulate` does: from its reference
/// coordinates (or its static equilibrium under the loads at t = 0), the
/// scene's initial velocities, the loads at full scale, recording the
/// scene's outputs; interruptible, with progress.
fn simulate_model<M: MechanicalModel + Send>(
    py: Python<'_>,
    model: &mut M,
    args: SimArgs,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<SimulationResult> {
    let SimArgs {
        mut opts,
        t_end,
        static_first,
    } = args;
    let work = |w: &Watch| -> Run {
        opts.stop = Some(w.stop.clone());
        let c0 = if static_first {
            model
                .equilibrium_under_loads(0.0)
                .map_err(|e| {
                    errors::solver(format!("static equilibrium before the simulation: {e}"))
                })?
                .coordinates
        } else {
            model.reference_coordinates()
        };
        model.set_load_scale(1.0);
        let cd0 = model
            .initial_velocities(0.0, &c0)
            .map_err(errors::reduction)?;
        let table =
            OutputTable::new(model.dynamics()).map_err(|e| errors::argument(e.to_string()))?;
        let header = table.header.clone();
        let mut observer = |t: f64| {
            w.progress(t / t_end);
            Control::Continue
        };
        let (traj, rows) = model
            .simulate_outputs(0.0, &c0, &cd0, &opts, &table, &mut observer)
            .map_err(errors::reduction)?;
        Ok((traj, rows, header))
    };
    let (run, interrupt) = run::long(py, "simulate", progress, work)?;
    let ((traj, rows, header), interrupt) = run::settle(run, interrupt)?;
    let full = &traj.full;
    let n_q = model.dynamics().n_q();
    let nc = model.n_coordinates();
    let outputs = PyDict::new(py);
    for (k, name) in header.iter().enumerate() {
        let col: Vec<f64> = rows.iter().map(|r| r[k]).collect();
        outputs.set_item(name, vec1(py, col))?;
    }
    let s = &full.stats;
    let stats = PyDict::new(py);
    for (k, v) in [
        ("rhs_evals", s.rhs_evals),
        ("steps_accepted", s.steps_accepted),
        ("steps_rejected", s.steps_rejected),
        ("newton_iterations", s.newton_iterations),
        ("newton_failures", s.newton_failures),
        ("jacobian_evals", s.jacobian_evals),
        ("lu_decompositions", s.lu_decompositions),
    ] {
        stats.set_item(k, v)?;
    }
    let result = SimulationResult {
        t: vec1(py, full.t.clone()),
        q: mat(py, &full.q, n_q),
        qd: mat(py, &full.qd, n_q),
        coordinates: mat(py, &traj.coordinates, nc),
        outputs: outputs.unbind(),
        output_names: header,
        stats: stats.unbind(),
        wall_time: full.wall_time,
        stopped: full.stopped,
    };
    finish(py, result, interrupt)
}

/// Returns `result`, or raises the interrupt with it attached as `partial`.
fn finish<T: pyo3::PyClass + Into<pyo3::PyClassInitializer<T>>>(
    py: Python<'_>,
    result: T,
    interrupt: Option<PyErr>,
) -> PyResult<T> {
    match interrupt {
        None => Ok(result),
        Some(e) => {
            let partial = Py::new(py, result)?;
            e.value(py).setattr("partial", partial)?;
            Err(e)
        }
    }
}

/// A mechanism with all its degrees of freedom: `Model(scene)`.
///
/// Builds the scene's mechanism (validating it, choosing the degrees of
/// freedom) and its equations of motion. Raises ModelError for an invalid
/// mechanism, SolverError if the assembly fails numerically.
#[pyclass(module = "flexmb", frozen)]
pub struct Model {
    mech: Arc<Mechanism>,
    scene: Scene,
}

impl Model {
    /// Fresh equations of motion for one computation: every call starts
    /// from the scene's reference state, as each `flexmb` command does, so
    /// its numbers (down to the evaluation counts) do not depend on the
    /// calls before it.
    fn dynamics(&self) -> Dynamics {
        Dynamics::new(self.mech.clone())
    }
}

#[pymethods]
impl Model {
    #[new]
    fn new(py: Python<'_>, scene: &Scene) -> PyResult<Self> {
        let s = scene.clone();
        let mech = run::whole(py, "building the mechanism", |_| {
            s.scene.build(s.base_dir.as_deref())
        })?
        .map_err(errors::model)?;
        Ok(Self {
            mech: Arc::new(mech),
            scene: scene.clone(),
        })
    }

    /// The mechanism: name, summary, dimension, counts (n_dof, n_x, n_eps)
    /// and the names of its degrees of freedom, inputs, nodes, nodal
    /// coordinates and deformations (as `flexmb info` prints them).
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        info_dict(py, &self.mech)
    }

    /// The static equilibrium under the loads and gravity at time `t`, in
    /// `steps` equal load increments (each halved while Newton fails), from
    /// the reference configuration, as `flexmb static`.
    ///
    /// Returns a StaticResult: positions and displacements of the nodes
    /// (n_nodes, dim), deformations, q and x. Raises SolverError if no
    /// equilibrium is found.
    #[pyo3(name = "static", signature = (t=0.0, steps=1))]
    fn statics(&self, py: Python<'_>, t: f64, steps: usize) -> PyResult<StaticResult> {
        finite("t", t)?;
        if steps < 1 {
            return Err(errors::argument(
                "steps must be at least 1 (the number of load increments); got 0",
            ));
        }
        let mut dy = self.dynamics();
        let q0 = self.mech.q0();
        let dy = &mut dy;
        let sol = run::whole(py, "static", |w| {
            let opts = StaticOptions {
                load_steps: steps,
                stop: Some(w.stop.clone()),
                ..Default::default()
            };
            dy.static_equilibrium(t, &q0, &opts)
        })?
        .map_err(errors::solver)?;
        let m = &self.mech;
        let dim = m.nodes.first().map_or(0, |n| n.position.len());
        let pos: Vec<Vec<f64>> = m
            .nodes
            .iter()
            .map(|n| n.position.iter().map(|i| sol.x[*i]).collect())
            .collect();
        let disp: Vec<Vec<f64>> = m
            .nodes
            .iter()
            .map(|n| {
                n.position
                    .iter()
                    .zip(&n.at)
                    .map(|(i, a)| sol.x[*i] - a)
                    .collect()
            })
            .collect();
        Ok(StaticResult {
            q: vec1(py, sol.q.clone()),
            x: vec1(py, sol.x.clone()),
            positions: mat(py, &pos, dim),
            displacements: mat(py, &disp, dim),
            deformations: vec1(py, sol.eps.clone()),
            node_ids: m.nodes.iter().map(|n| n.id.clone()).collect(),
            deformation_names: m.eps_names.clone(),
            iterations: sol.iterations,
            increments: sol.increments,
        })
    }

    /// The `k` lowest undamped eigenfrequencies (default 10, or every degree
    /// of freedom if fewer) and mode shapes of the rest linearization at the
    /// reference configuration, or with `static_first` at the static
    /// equilibrium under the loads and gravity at t = 0, as `flexmb eig`.
    ///
    /// Returns an EigResult: frequencies (Hz), nodal mode shapes
    /// (k, n_nodes, dim), and damped modes if the model has damping.
    #[pyo3(signature = (k=None, static_first=false))]
    fn eig(&self, py: Python<'_>, k: Option<usize>, static_first: bool) -> PyResult<EigResult> {
        let k = modes_or_default(k, 10, self.mech.n_dof())?;
        let mut dy = self.dynamics();
        let dy = &mut dy;
        let q0 = self.mech.q0();
        let out = run::whole(py, "eig", |w| -> PyResult<_> {
            let q = if static_first {
                let opts = StaticOptions {
                    stop: Some(w.stop.clone()),
                    ..Default::default()
                };
                dy.static_equilibrium(0.0, &q0, &opts)
                    .map_err(errors::solver)?
                    .q
            } else {
                q0
            };
            let lin = dy.linearize_at_rest(0.0, &q).map_err(errors::solver)?;
            let modes = flexmb::linearize::undamped_modes(&lin, k).map_err(errors::solver)?;
            let nodal = flexmb::linearize::nodal_mode_shapes(dy, &modes.vectors);
            let damped = lin.d.col_iter().any(|c| c.iter().any(|v| *v != 0.0));
            let damped = if damped {
                Some(flexmb::linearize::damped_modes(&lin).map_err(errors::solver)?)
            } else {
                None
            };
            Ok((modes, nodal, damped))
        })??;
        let (modes, nodal, damped) = out;
        let (nn, dim, flat) = nodal_positions(&self.mech, &nodal);
        let k = modes.len();
        let (df, dr) = match damped {
            Some(d) => {
                let d: Vec<_> = d.into_iter().take(k).collect();
                (
                    Some(vec1(py, d.iter().map(|m| m.frequency_hz).collect())),
                    Some(vec1(py, d.iter().map(|m| m.damping_ratio).collect())),
                )
            }
            None => (None, None),
        };
        Ok(EigResult {
            frequencies: vec1(py, modes.frequencies_hz()),
            mode_shapes: arr3(py, (k, nn, dim), flat),
            nodal: mat(py, &columns(&nodal), nodal.nrows()),
            vectors: mat(py, &columns(&modes.vectors), modes.vectors.nrows()),
            node_ids: self.mech.nodes.iter().map(|n| n.id.clone()).collect(),
            damped_frequencies: df,
            damping_ratios: dr,
        })
    }

    /// The undamped eigenfrequencies along the range of motion, as `flexmb
    /// sweep`: the static equilibria at each of `values` of `over`, then an
    /// eigen analysis at each (in parallel).
    ///
    /// `over` is `"load"` (the scene's loads, evaluated at `t_load`, scaled
    /// by each value; continuation from the first) or the name of a degree
    /// of freedom (held at its reference value plus each value). `modes`
    /// defaults to 6 (or every degree of freedom if fewer). Returns a
    /// SweepResult with `frequencies` of shape (len(values), modes). Ctrl-C
    /// stops it: the KeyboardInterrupt carries the points done as `partial`.
    #[pyo3(signature = (over="load", values=None, modes=None, t_load=0.0, progress=None))]
    fn sweep(
        &self,
        py: Python<'_>,
        over: &str,
        values: Option<&Bound<'_, PyAny>>,
        modes: Option<usize>,
        t_load: f64,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<SweepResult> {
        let values = values.ok_or_else(|| errors::argument("sweep needs values=[...]"))?;
        let values = floats(values, "values")?;
        if values.len() < 2 {
            return Err(errors::argument(format!(
                "values: a sweep needs at least 2 values; got {}",
                values.len()
            )));
        }
        finite("t_load", t_load)?;
        let k = modes_or_default(modes, 6, self.mech.n_dof())?;
        let (param, held) = if over == "load" {
            (SweepParameter::LoadScale, vec![])
        } else {
            let j = dof_index(&self.mech, over, "over")?;
            let q_ref = self.mech.q0()[j];
            let param = SweepParameter::Path {
                dofs: vec![j],
                path: Box::new(move |s| vec![q_ref + s]),
            };
            (param, vec![over.to_string()])
        };
        let opts = SweepOptions {
            values,
            modes: k,
            t: t_load,
            keep_vectors: false,
        };
        let mech = &self.mech;
        let (outcome, interrupt) = run::long(py, "sweep", progress, |w| {
            flexmb::linearize::sweep_until(
                mech,
                &param,
                &opts,
                &|d, total| w.progress(d as f64 / total.max(1) as f64),
                Some(&w.stop),
            )
        })?;
        let (outcome, interrupt) = run::settle(outcome.map_err(errors::solver), interrupt)?;
        let pts = outcome.points;
        let result = SweepResult {
            values: vec1(py, pts.iter().map(|p| p.s).collect()),
            frequencies: mat(
                py,
                &pts.iter()
                    .map(|p| p.frequencies_hz.clone())
                    .collect::<Vec<_>>(),
                k,
            ),
            holding: mat(
                py,
                &pts.iter().map(|p| p.holding.clone()).collect::<Vec<_>>(),
                held.len(),
            ),
            held,
            stopped: outcome.stopped,
        };
        finish(py, result, interrupt)
    }

    /// The time response from the reference configuration (or with
    /// `static_first` from the static equilibrium at t = 0), as `flexmb
    /// simulate`: `outputs` equidistant output times on [0, t_end], the
    /// integrator `"dopri5"` (ode45-like), `"adams"` or `"genalpha"`, with
    /// relative and absolute tolerances `rtol`, `atol`.
    ///
    /// `progress`: True for a tqdm bar (if tqdm is installed), or a callable
    /// taking the fraction done. Returns a SimulationResult (t, q, qd, the
    /// scene's outputs, the evaluation counts). Ctrl-C stops the run within
    /// a step: the KeyboardInterrupt carries the outputs so far as `partial`.
    #[pyo3(signature = (t_end=1.0, outputs=501, integrator="dopri5", rtol=1e-3, atol=1e-6, static_first=false, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        t_end: f64,
        outputs: usize,
        integrator: &str,
        rtol: f64,
        atol: f64,
        static_first: bool,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<SimulationResult> {
        let args = SimArgs::new(t_end, outputs, integrator, rtol, atol, static_first)?;
        simulate_model(py, &mut self.dynamics(), args, progress)
    }

    /// A reduced model q = G(z) of this model, as `flexmb reduce`: `method`
    /// is "modal" (the first `modes` modes at the reference configuration,
    /// optionally `keep`ing named degrees of freedom), "svd-modal" (the first
    /// `modes` modes of each configuration of a sweep, weights ω^-`a`, one
    /// SVD), "fbm-svd" (per-mode SVDs), "ibm-msi" or "ibm-mac" (an
    /// interpolated basis along a held degree of freedom s). The sweep
    /// methods take `over` ("load" or a degree of freedom) and `values`
    /// (load scales, or changes of the degree of freedom from its reference
    /// value); `threshold`, `final_threshold` the SVD rules; `t_load` the
    /// time of the loads; `no_gravity` builds the basis without gravity.
    #[pyo3(signature = (method, modes, keep=None, a=None, threshold=None, final_threshold=None, over=None, values=None, t_load=0.0, no_gravity=false, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn reduce(
        &self,
        py: Python<'_>,
        method: &str,
        modes: usize,
        keep: Option<Vec<String>>,
        a: Option<f64>,
        threshold: Option<f64>,
        final_threshold: Option<f64>,
        over: Option<String>,
        values: Option<&Bound<'_, PyAny>>,
        t_load: f64,
        no_gravity: bool,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<ReducedModel> {
        let args = ReduceArgs {
            method: method.parse().map_err(errors::argument)?,
            modes,
            keep: keep.unwrap_or_default(),
            a,
            threshold,
            final_threshold,
            over,
            values: values.map(|v| floats(v, "values")).transpose()?,
            t_load,
            no_gravity,
        };
        args.check(&self.mech)?;
        let basis_mech = if no_gravity {
            let mut s = self.scene.scene.clone();
            s.gravity = None;
            let base = self.scene.base_dir.clone();
            Arc::new(
                run::whole(py, "building the mechanism", |_| s.build(base.as_deref()))?
                    .map_err(errors::model)?,
            )
        } else {
            self.mech.clone()
        };
        let name = self.scene.scene.name.clone();
        let (saved, interrupt) = run::long(py, "reduce", progress, |w| {
            reduce::build(&basis_mech, &args, &name, w)
        })?;
        if let Some(e) = interrupt {
            return Err(e);
        }
        ReducedModel::from_saved(py, self.mech.clone(), saved?)
    }

    /// A reduced model saved by `flexmb reduce` (or `ReducedModel.save`),
    /// applied to this model; raises ModelError if it was built for other
    /// degrees of freedom.
    fn load_reduced(&self, py: Python<'_>, path: PathBuf) -> PyResult<ReducedModel> {
        let saved =
            SavedModel::load(&path).map_err(|e| errors::SceneError::new_err(e.to_string()))?;
        ReducedModel::from_saved(py, self.mech.clone(), saved)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({:?}, {} degrees of freedom)",
            self.mech.name,
            self.mech.n_dof()
        )
    }
}

/// A reduced model q = G(z) of a mechanism (from `Model.reduce` or
/// `Model.load_reduced`), studied like the unreduced one: `simulate`,
/// `sweep` (over the load scale) and `eig`, and saved for the command line
/// (`flexmb simulate --reduced`) with `save`.
#[pyclass(module = "flexmb", frozen)]
pub struct ReducedModel {
    mech: Arc<Mechanism>,
    saved: SavedModel,
    n_z: usize,
}

impl ReducedModel {
    /// The model `saved` of `mech`; ModelError if it does not fit.
    fn from_saved(py: Python<'_>, mech: Arc<Mechanism>, saved: SavedModel) -> PyResult<Self> {
        let m = mech.clone();
        let s = saved.clone();
        let n_z = run::whole(py, "reduced model", |_| s.into_model(m).map(|r| r.n_z()))?
            .map_err(|e| errors::ModelError::new_err(e.to_string()))?;
        Ok(Self { mech, saved, n_z })
    }

    /// A fresh reduced model for one computation (as `flexmb simulate
    /// --reduced` reads it), so that no call depends on the ones before.
    fn model(&self) -> PyResult<RsReduced> {
        self.saved
            .into_model(self.mech.clone())
            .map_err(|e| errors::ModelError::new_err(e.to_string()))
    }
}

#[pymethods]
impl ReducedModel {
    /// The number of reduced coordinates z.
    #[getter]
    fn n_z(&self) -> usize {
        self.n_z
    }

    /// How the basis was built.
    #[getter]
    fn description(&self) -> String {
        self.saved.description.clone()
    }

    /// True for an interpolated basis (ibm-msi, ibm-mac, or a grid basis
    /// over two configuration coordinates).
    #[getter]
    fn interpolated(&self) -> bool {
        self.saved.basis.configuration_coordinates() > 0
    }

    /// The unreduced mechanism's `info()` plus n_z and the description.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = info_dict(py, &self.mech)?;
        d.set_item("n_z", self.n_z)?;
        d.set_item("description", &self.saved.description)?;
        Ok(d)
    }

    /// Writes the model as RON, for `flexmb simulate --reduced` and
    /// `flexmb sweep --reduced` and `Model.load_reduced`.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.saved
            .save(&path)
            .map_err(|e| errors::FlexmbError::new_err(format!("{}: {e}", path.display())))
    }

    /// The `k` lowest undamped eigenfrequencies (Hz) of the reduced rest
    /// linearization (F.7) at the reference coordinates (default: all).
    #[pyo3(signature = (k=None))]
    fn eig<'py>(
        &self,
        py: Python<'py>,
        k: Option<usize>,
    ) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let k = modes_or_default(k, self.n_z, self.n_z)?;
        let mut red = self.model()?;
        let red = &mut red;
        let f = run::whole(py, "eig", |_| {
            let z = red.reference_coordinates();
            red.eigenfrequencies(0.0, &z, k)
        })?
        .map_err(errors::reduction)?;
        Ok(numpy::PyArray1::from_vec(py, f))
    }

    /// The time response, as `Model.simulate` (explicit integrators only:
    /// "dopri5" or "adams"), from the reduced reference coordinates or with
    /// `static_first` the reduced static equilibrium at t = 0.
    #[pyo3(signature = (t_end=1.0, outputs=501, integrator="dopri5", rtol=1e-3, atol=1e-6, static_first=false, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        t_end: f64,
        outputs: usize,
        integrator: &str,
        rtol: f64,
        atol: f64,
        static_first: bool,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<SimulationResult> {
        let args = SimArgs::new(t_end, outputs, integrator, rtol, atol, static_first)?;
        if args.opts.integrator == Integrator::GeneralizedAlpha {
            return Err(errors::argument(
                "a reduced model is integrated with an explicit integrator (dopri5 or adams); \
                 genalpha is for stiff unreduced models",
            ));
        }
        simulate_model(py, &mut self.model()?, args, progress)
    }

    /// The reduced eigenfrequencies (F.7) at the reduced static equilibria
    /// along the load scales `values` (loads at `t_load`, continuation from
    /// load scale 0), as `flexmb sweep --reduced`; `modes` defaults to 6 (at
    /// most n_z). Ctrl-C during the eigen analyses returns the points done
    /// as the KeyboardInterrupt's `partial`.
    #[pyo3(signature = (values, over="load", modes=None, t_load=0.0, progress=None))]
    fn sweep(
        &self,
        py: Python<'_>,
        values: &Bound<'_, PyAny>,
        over: &str,
        modes: Option<usize>,
        t_load: f64,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<SweepResult> {
        if over != "load" {
            return Err(errors::argument(format!(
                "a reduced model sweeps over \"load\" only (got over={over:?}): its equilibria keep \
                 all reduced coordinates free; sweep a coordinate with the unreduced Model"
            )));
        }
        let values = floats(values, "values")?;
        if values.len() < 2 {
            return Err(errors::argument(format!(
                "values: a sweep needs at least 2 values; got {}",
                values.len()
            )));
        }
        finite("t_load", t_load)?;
        let mut red = self.model()?;
        let k = modes.unwrap_or(6).min(self.n_z);
        if k == 0 {
            return Err(errors::argument("modes must be at least 1"));
        }
        let n = values.len();
        let red = &mut red;
        let vals = &values;
        let (points, interrupt) = run::long(py, "sweep", progress, |w| {
            red.frequency_sweep(t_load, vals, k, &mut |d| {
                w.progress(d as f64 / (2 * n) as f64);
                // the equilibria (a continuation) have no partial result
                if d >= n && w.stopped() {
                    Control::Stop
                } else {
                    Control::Continue
                }
            })
        })?;
        let (points, interrupt) = run::settle(points.map_err(errors::reduction), interrupt)?;
        let done = points.len();
        let result = SweepResult {
            values: vec1(py, values[..done].to_vec()),
            frequencies: mat(
                py,
                &points
                    .into_iter()
                    .map(|p| p.frequencies)
                    .collect::<Vec<_>>(),
                k,
            ),
            holding: mat(py, &vec![vec![]; done], 0),
            held: vec![],
            stopped: done < n,
        };
        finish(py, result, interrupt)
    }

    fn __repr__(&self) -> PyResult<String> {
        Ok(format!(
            "ReducedModel({} coordinates from {}: {})",
            self.n_z,
            self.mech.n_dof(),
            self.saved.description
        ))
    }
}
