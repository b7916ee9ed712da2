//! Scene files for flexible multibody mechanisms and their assembly.
//!
//! A [`Scene`] (RON via serde) lists nodes, materials, sections, elements (with
//! a chain helper that splits a member into n elements), coordinate roles (fixed,
//! prescribed, rigid deformations, the choice of degrees of freedom), loads,
//! gravity, PD controllers (thesis (7.12)), initial velocities and outputs.
//! [`Scene::build`] validates it and assembles a [`Mechanism`] in which every
//! nodal coordinate and deformation has a role (thesis (6.4)); errors name the
//! culprit: unknown or duplicate ids, non-positive properties, non-finite
//! values, malformed RON (line and column), inconsistent roles, and over- or
//! under-constrained mechanisms (found by an SVD of the constraint Jacobian).
//! [`Scene::diagnose_constraints`] ([`constraints`]) explains the latter
//! without building: each over-constraint as a loop of elements with its
//! equations, weights and direction, each under-constraint as the
//! coordinates of its mode.
//!
//! ```
//! use flexmb_model::Scene;
//! let scene = Scene::from_ron_str(r#"(
//!     dimension: Planar,
//!     materials: { "al": (e: 7.0e10, rho: 2700.0) },
//!     sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
//!     nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
//!     elements: [ (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar", n: 4))) ],
//!     fixed: [ Coord("A", Position) ],
//!     rigid: [ Def("arm", "elongation") ],
//! )"#).unwrap();
//! let mech = scene.build(None).unwrap();
//! // a pinned arm of 4 beams: the rotation at A plus 2 bending deformations per beam
//! assert_eq!(mech.n_dof(), 9);
//! ```
#![warn(missing_docs)]

mod beam_shape;
mod build;
mod chart;
pub mod constraints;
mod error;
mod loads;
mod local_span;
mod mechanism;
mod naming;
mod orientation;
mod outputs;
mod partition;
mod roles;
mod scene;
mod time_function;

pub use beam_shape::{BeamSection, Station};
pub use build::{BuildStage, CodeElement};
pub use chart::{ChartSwitch, EulerChart, CHART_SWITCH_RATIO};
pub use constraints::ConstraintDiagnosis;
pub use error::ModelError;
pub use mechanism::*;
pub use partition::PartitionSwitch;
pub use scene::*;
pub use time_function::TimeFunction;

/// The first three of `bad` by name (`name` of each index) and a count of
/// the rest, comma-separated: how errors list the entries at fault.
pub fn list_some(bad: &[usize], name: impl Fn(usize) -> String) -> String {
    let mut names: Vec<String> = bad.iter().take(3).map(|&k| name(k)).collect();
    if bad.len() > 3 {
        names.push(format!("{} more", bad.len() - 3));
    }
    names.join(", ")
}

use std::path::Path;

/// Parses RON text, reporting line and column of a syntax error, and for an
/// unknown field or variant the nearest valid name.
pub fn parse_ron<T: serde::de::DeserializeOwned>(text: &str, file: &str) -> Result<T, ModelError> {
    flexmb_input::from_ron(text).map_err(|e| ModelError::Parse {
        file: file.to_string(),
        line: e.line,
        column: e.column,
        message: e.message,
    })
}

impl Scene {
    /// Parses a scene from RON text.
    pub fn from_ron_str(text: &str) -> Result<Self, ModelError> {
        parse_ron(text, "<string>")
    }

    /// Reads a scene file.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        let text = std::fs::read_to_string(path).map_err(|e| ModelError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        parse_ron(&text, &path.display().to_string())
    }

    /// Validates and assembles the mechanism; `base_dir` resolves relative file
    /// paths (superelement files).
    pub fn build(&self, base_dir: Option<&Path>) -> Result<Mechanism, ModelError> {
        build::build(self, base_dir)
    }

    /// [`build`](Self::build) with extra elements built in Rust code, e.g.
    /// user-defined elements ([`flexmb_element::Element::custom`]) that a
    /// scene file cannot name: each [`CodeElement`] gives the element, its
    /// id and one node id per slot. The scene's selections (`fixed`, `rigid`,
    /// `prescribed`, `dofs_first`, outputs) can name its deformations by that
    /// id like those of any other element.
    pub fn build_with_elements(
        &self,
        base_dir: Option<&Path>,
        elements: &[CodeElement],
    ) -> Result<Mechanism, ModelError> {
        build::build_with_elements(self, base_dir, elements)
    }

    /// [`build`](Self::build) that calls `report` as each stage of the
    /// build starts ([`BuildStage`]), for progress on large models.
    pub fn build_reporting(
        &self,
        base_dir: Option<&Path>,
        report: &mut dyn FnMut(BuildStage),
    ) -> Result<Mechanism, ModelError> {
        build::build_reporting(self, base_dir, &[], report)
    }

    /// Writes the scene as pretty RON.
    pub fn to_ron(&self) -> String {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).unwrap_or_default()
    }
}
