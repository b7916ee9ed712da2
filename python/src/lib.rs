//! The Python extension module `flexmb._flexmb` (re-exported by the
//! `flexmb` package): scenes, models, reduced models and superelements on
//! the flexmb crates, with numpy arrays in and out. See docs/python.md.
//!
//! Every computation runs with the GIL released and can be stopped with
//! Ctrl-C (see [`run`]); every Rust error becomes a `FlexmbError` subclass
//! carrying flexmb's own message, and a panic is caught at the boundary.

mod errors;
mod model;
mod reduce;
mod results;
mod run;
mod scene;

use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// Builds a linear superelement from FE matrices as `flexmb
/// build-superelement SPEC` does: reads the specification file (RON; see
/// crates/superelement/README.md), reads the FE export it names relative to
/// the spec's directory, builds S̄ and M̄ and writes the superelement file
/// given by the spec's `output` (or `output=` here, relative to the working
/// directory).
///
/// Returns a SuperelementResult (summary, files written, normal-mode
/// frequencies). Raises SceneError for an unreadable or malformed spec or
/// FE file, SolverError if the build fails numerically.
#[pyfunction]
#[pyo3(signature = (spec, output=None))]
fn build_superelement(
    py: Python<'_>,
    spec: PathBuf,
    output: Option<PathBuf>,
) -> PyResult<results::SuperelementResult> {
    let mut s = flexmb::superelement::Spec::read(&spec)
        .map_err(|e| errors::SceneError::new_err(e.to_string()))?;
    if let Some(o) = output {
        let o = if o.is_relative() {
            std::env::current_dir()?.join(o)
        } else {
            o
        };
        s.output = o.display().to_string();
    }
    let base = spec.parent().unwrap_or(Path::new(".")).to_path_buf();
    let out = run::whole(py, "build_superelement", |_| {
        flexmb::superelement::build_from_spec(&s, &base)
    })?
    .map_err(|e| {
        if e.is_input() {
            errors::SceneError::new_err(e.to_string())
        } else {
            errors::solver(e)
        }
    })?;
    Ok(results::SuperelementResult {
        summary: out.result.summary(&s.name),
        written: out
            .written
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
        normal_frequencies: results::vec1(py, out.result.report.normal_frequencies_hz.clone()),
        l0: out.result.data.l0,
        n_modes: out.result.data.n_modes(),
    })
}

/// The extension module.
#[pymodule]
fn _flexmb(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<scene::Scene>()?;
    m.add_class::<model::Model>()?;
    m.add_class::<model::ReducedModel>()?;
    m.add_class::<results::StaticResult>()?;
    m.add_class::<results::EigResult>()?;
    m.add_class::<results::SweepResult>()?;
    m.add_class::<results::SimulationResult>()?;
    m.add_class::<results::SuperelementResult>()?;
    m.add_function(wrap_pyfunction!(build_superelement, m)?)?;
    m.add("FlexmbError", py.get_type::<errors::FlexmbError>())?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("ModelError", py.get_type::<errors::ModelError>())?;
    m.add("SolverError", py.get_type::<errors::SolverError>())?;
    m.add("ArgumentError", py.get_type::<errors::ArgumentError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
