//! The result objects: plain containers of numpy arrays and counts, built
//! once and read-only.

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A 1-D float array.
pub fn vec1(py: Python<'_>, v: Vec<f64>) -> Py<PyArray1<f64>> {
    PyArray1::from_vec(py, v).unbind()
}

/// A 2-D float array of `rows`, each of length `ncols` (the rows of a
/// stopped run are complete, so the lengths agree).
pub fn mat(py: Python<'_>, rows: &[Vec<f64>], ncols: usize) -> Py<PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    let a = Array2::from_shape_vec((rows.len(), ncols), flat)
        .unwrap_or_else(|_| Array2::zeros((0, ncols)));
    a.into_pyarray(py).unbind()
}

/// A 3-D float array of shape `shape` from row-major `flat`.
pub fn arr3(py: Python<'_>, shape: (usize, usize, usize), flat: Vec<f64>) -> Py<PyArray3<f64>> {
    Array3::from_shape_vec(shape, flat)
        .unwrap_or_else(|_| Array3::zeros((0, 0, 0)))
        .into_pyarray(py)
        .unbind()
}

/// A static equilibrium (`Model.static`).
#[pyclass(module = "flexmb", frozen, get_all)]
pub struct StaticResult {
    /// The degrees of freedom q at the equilibrium, shape (n_dof,).
    pub q: Py<PyArray1<f64>>,
    /// All nodal coordinates x, shape (n_x,) (names: `Model.info()["coordinates"]`).
    pub x: Py<PyArray1<f64>>,
    /// Node positions, shape (n_nodes, dim), rows in the order of `node_ids`.
    pub positions: Py<PyArray2<f64>>,
    /// Node displacements from the reference configuration, shape (n_nodes, dim).
    pub displacements: Py<PyArray2<f64>>,
    /// All deformations ε, shape (n_eps,), named by `deformation_names`.
    pub deformations: Py<PyArray1<f64>>,
    /// The node ids, one per row of `positions`.
    pub node_ids: Vec<String>,
    /// The deformation names, one per entry of `deformations`.
    pub deformation_names: Vec<String>,
    /// Newton iterations used.
    pub iterations: usize,
    /// Load increments used.
    pub increments: usize,
}

/// Undamped modes (`Model.eig`, `ReducedModel.eig`).
#[pyclass(module = "flexmb", frozen, get_all)]
pub struct EigResult {
    /// Undamped eigenfrequencies (Hz), ascending, shape (k,); negative for an
    /// unstable (buckled) direction.
    pub frequencies: Py<PyArray1<f64>>,
    /// Mode shapes at the nodes: the position components of each mode,
    /// shape (k, n_nodes, dim), nodes in the order of `node_ids`.
    pub mode_shapes: Py<PyArray3<f64>>,
    /// Mode shapes in all nodal coordinates x, shape (k, n_x).
    pub nodal: Py<PyArray2<f64>>,
    /// Mass-normalized eigenvectors in the degrees of freedom, shape (k, n_dof).
    pub vectors: Py<PyArray2<f64>>,
    /// The node ids of `mode_shapes`.
    pub node_ids: Vec<String>,
    /// Damped eigenfrequencies (Hz) if the model has damping, else None.
    pub damped_frequencies: Option<Py<PyArray1<f64>>>,
    /// Damping ratios of the damped modes, else None.
    pub damping_ratios: Option<Py<PyArray1<f64>>>,
}

/// Eigenfrequencies along a sweep (`Model.sweep`, `ReducedModel.sweep`).
#[pyclass(module = "flexmb", frozen, get_all)]
pub struct SweepResult {
    /// The sweep values reached, shape (n,) (all of them unless interrupted).
    pub values: Py<PyArray1<f64>>,
    /// The undamped eigenfrequencies (Hz), shape (n, k).
    pub frequencies: Py<PyArray2<f64>>,
    /// The values of the held coordinates at each point, shape (n, len(held)).
    pub holding: Py<PyArray2<f64>>,
    /// The names of the held coordinates (none for a load sweep).
    pub held: Vec<String>,
    /// True if the sweep was interrupted.
    pub stopped: bool,
}

/// A time response (`Model.simulate`, `ReducedModel.simulate`).
#[pyclass(module = "flexmb", frozen, get_all)]
pub struct SimulationResult {
    /// Output times, shape (n,).
    pub t: Py<PyArray1<f64>>,
    /// The degrees of freedom q at each output, shape (n, n_dof) (for a
    /// reduced model: q = G(z)).
    pub q: Py<PyArray2<f64>>,
    /// Their rates, shape (n, n_dof).
    pub qd: Py<PyArray2<f64>>,
    /// The model's own coordinates at each output: q, or z for a reduced
    /// model, shape (n, n_coordinates).
    pub coordinates: Py<PyArray2<f64>>,
    /// The scene's outputs (its `outputs`, or the degrees of freedom if it
    /// names none): column name → array of shape (n,), as in the CLI's
    /// outputs.csv.
    pub outputs: Py<PyDict>,
    /// The output column names, in the CLI's order.
    pub output_names: Vec<String>,
    /// Integrator statistics: rhs_evals (function evaluations),
    /// steps_accepted, steps_rejected, newton_iterations, newton_failures,
    /// jacobian_evals, lu_decompositions.
    pub stats: Py<PyDict>,
    /// Wall time of the integration (s).
    pub wall_time: f64,
    /// True if the run was stopped early (interrupted).
    pub stopped: bool,
}

#[pymethods]
impl SimulationResult {
    /// The number of right-hand-side (function) evaluations.
    #[getter]
    fn rhs_evals(&self, py: Python<'_>) -> PyResult<usize> {
        self.stats
            .bind(py)
            .get_item("rhs_evals")?
            .map_or(Ok(0), |v| v.extract())
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "SimulationResult({} outputs, {} evaluations{})",
            self.t.bind(py).len()?,
            self.rhs_evals(py)?,
            if self.stopped { ", stopped" } else { "" }
        ))
    }
}

/// What `build_superelement` built.
#[pyclass(module = "flexmb", frozen, get_all)]
pub struct SuperelementResult {
    /// The readable account of the build (as the CLI prints it).
    pub summary: String,
    /// The files written (the superelement file first).
    pub written: Vec<String>,
    /// Fixed-interface normal-mode frequencies (Hz).
    pub normal_frequencies: Py<PyArray1<f64>>,
    /// Undeformed length l0 between the interface points (m).
    pub l0: f64,
    /// Number of deformation modes beyond the 12 interface coordinates.
    pub n_modes: usize,
}
