//! `flexmb.Scene`: a scene read from a RON file or text, or built from
//! Python dicts and lists.

use crate::errors::{self, SceneError};
use flexmb::model::Scene as RsScene;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::Value;
use std::path::PathBuf;

/// A scene: nodes, materials, sections, elements, coordinate roles, loads,
/// gravity, controllers, initial velocities and outputs (docs/scene-format.md).
///
/// Read one with `Scene.load(path)` or `Scene.from_str(text)`, or build one
/// from Python dicts with `Scene.from_dict(d)`; every form is read by the
/// same strict rules (an unknown field is an error, with the nearest valid
/// name).
#[pyclass(module = "flexmb", frozen)]
#[derive(Clone)]
pub struct Scene {
    pub(crate) scene: RsScene,
    /// The directory relative file names (superelement files) are resolved in.
    pub(crate) base_dir: Option<PathBuf>,
}

#[pymethods]
impl Scene {
    /// Reads a scene file (RON). Relative file names in it (superelement
    /// files) are resolved in its directory.
    ///
    /// Raises SceneError naming the file, line and column of a syntax error,
    /// or an unknown field with the nearest valid name.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let scene = RsScene::load(&path).map_err(errors::model)?;
        Ok(Self {
            scene,
            base_dir: path.parent().map(|p| p.to_path_buf()),
        })
    }

    /// Parses a scene from RON text (as in a scene file). Relative file
    /// names in it are resolved in `base_dir` (default: the working
    /// directory).
    #[staticmethod]
    #[pyo3(signature = (text, base_dir=None))]
    fn from_str(text: &str, base_dir: Option<PathBuf>) -> PyResult<Self> {
        let scene = RsScene::from_ron_str(text).map_err(errors::model)?;
        Ok(Self { scene, base_dir })
    }

    /// Builds a scene from Python data: dicts for structs and maps, lists
    /// or tuples for sequences, strings for unit variants (`"Planar"`) and
    /// `{"Variant": payload}` for the others (`{"Beam": {...}}`,
    /// `{"Coord": ["A", "Position"]}`), None for an absent optional value;
    /// numpy arrays and scalars are accepted as numbers and lists.
    ///
    /// Raises SceneError naming the path of the offending entry (e.g.
    /// `elements[0].type`) for an unknown field or variant, a missing field or
    /// a value of the wrong kind.
    #[staticmethod]
    #[pyo3(signature = (d, base_dir=None))]
    fn from_dict(d: &Bound<'_, PyAny>, base_dir: Option<PathBuf>) -> PyResult<Self> {
        let value = to_value(d, "scene")?;
        let scene: RsScene = serde_path_to_error::deserialize(value).map_err(|e| {
            let path = e.path().to_string();
            let message = with_hint(&e.inner().to_string());
            SceneError::new_err(if path == "." {
                format!("scene dict: {message}")
            } else {
                format!("scene dict: {path}: {message}")
            })
        })?;
        Ok(Self { scene, base_dir })
    }

    /// The scene as RON text, as a scene file would hold it.
    fn to_ron(&self) -> String {
        self.scene.to_ron()
    }

    /// The scene as Python data, in the form `from_dict` reads (with every
    /// default filled in).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = serde_json::to_string(&self.scene)
            .map_err(|e| errors::argument(format!("the scene cannot be written as a dict: {e}")))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.scene.name.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene(name={:?}, {} nodes, {} elements)",
            self.scene.name,
            self.scene.nodes.len(),
            self.scene.elements.len()
        )
    }
}

/// The nearest valid name of an unknown field or variant in a serde
/// message ("unknown field `gravityy`, expected one of `name`, ..."),
/// appended as "; did you mean `gravity`?".
fn with_hint(message: &str) -> String {
    if !(message.starts_with("unknown field") || message.starts_with("unknown variant")) {
        return message.to_string();
    }
    let quoted: Vec<&str> = message.split('`').skip(1).step_by(2).collect();
    match quoted.split_first() {
        Some((found, candidates)) => match flexmb::input::nearest(found, candidates.iter()) {
            Some(best) => format!("{message}; did you mean `{best}`?"),
            None => message.to_string(),
        },
        None => message.to_string(),
    }
}

/// Converts Python data to a JSON value, naming the `path` of an entry that
/// is no number, string, bool, None, dict, list or tuple.
fn to_value(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        let v: i64 = obj.extract().map_err(|_| {
            SceneError::new_err(format!("scene dict: {path}: integer out of range"))
        })?;
        return Ok(Value::from(v));
    }
    if obj.is_instance_of::<PyFloat>() {
        let v: f64 = obj.extract()?;
        return serde_json::Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| {
                SceneError::new_err(format!("scene dict: {path}: {v} is not a finite number"))
            });
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                SceneError::new_err(format!("scene dict: {path}: a key is not a string: {k}"))
            })?;
            let sub = format!("{path}.{key}");
            map.insert(key, to_value(&v, &sub)?);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = vec![];
        for (i, v) in obj.try_iter()?.enumerate() {
            items.push(to_value(&v?, &format!("{path}[{i}]"))?);
        }
        return Ok(Value::Array(items));
    }
    // numpy arrays and scalars
    if obj.hasattr("tolist")? {
        let list = obj.call_method0("tolist")?;
        if !list.is(obj) {
            return to_value(&list, path);
        }
    }
    Err(SceneError::new_err(format!(
        "scene dict: {path}: a {} is no scene value (use dicts, lists, strings, numbers, bools or None)",
        obj.get_type().name()?
    )))
}
