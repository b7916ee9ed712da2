//! Validation of a scene and its assembly into a [`Mechanism`].

use crate::mechanism::*;
use crate::scene::*;
use crate::{ModelError, TimeFunction};
use flexmb_element::{BeamOptions, Element, LinearSuperelement, Material, SectionShape};
use flexmb_rotation::EulerParameters;
use nalgebra::Vector3;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod chains;
mod checks;
mod coordinates;
mod elements;
mod nodes;
mod reference;

use chains::{chain_n, chain_nodes, default_up, BYTES_PER_ELEMENT, MAX_CHAIN_N};
pub(crate) use checks::{check_function, opt_vec3};
use checks::{closest, finite_vec, vec3};
use coordinates::{allocate, place, Coordinates};
use elements::{expand_elements, ElementSet, PartAxis};
use nodes::{read_gravity, read_nodes, Library, NodeTable};
use reference::check_reference_configuration;

/// Where a slot of an element attaches.
#[derive(Clone, Debug)]
enum Attach {
    Pos(String),
    /// An orientation slot measured from the node's initial orientation.
    Orient(String),
    /// An orientation slot whose element is given in the node's own axes
    /// (a rigid body): it takes the node's orientation as it is.
    Carried(String),
    Group(String),
}

struct Expanded {
    id: String,
    group: String,
    element: Element,
    attach: Vec<Attach>,
    /// A beam's section, for drawing.
    section: Option<crate::BeamSection>,
}

/// An element built in Rust code, for instance a user-defined element
/// ([`Element::custom`]), placed between the nodes of a scene by
/// [`Scene::build_with_elements`](crate::Scene::build_with_elements).
#[derive(Clone, Debug)]
pub struct CodeElement {
    /// Unique id among the scene's elements: selections (`Def(id, name)`,
    /// outputs) and messages use it, as for a scene element.
    pub id: String,
    /// The element.
    pub element: Element,
    /// One node id per slot of the element, in slot order: a
    /// [`Slot::Position2`](flexmb_element::Slot)/`Position3` slot takes the
    /// node's position, an `Angle`/`Orientation` slot its orientation (planar
    /// angle or Euler parameters, allocated when an element needs it). Mode
    /// slots are not supported here.
    pub nodes: Vec<String>,
}

/// Assembles a scene. `base_dir` resolves relative superelement file paths.
pub fn build(scene: &Scene, base_dir: Option<&Path>) -> Result<Mechanism, ModelError> {
    build_with_elements(scene, base_dir, &[])
}

/// Assembles a scene with extra elements built in code, placed after the
/// scene's own elements (see [`CodeElement`]).
pub fn build_with_elements(
    scene: &Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
) -> Result<Mechanism, ModelError> {
    build_reporting(scene, base_dir, extra, &mut |_| {})
}

/// A stage of [`Scene::build_reporting`](crate::Scene::build_reporting), in the order they run. On a model of
/// 10⁴–10⁵ coordinates the elements and the DOF choice take seconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildStage {
    /// Nodes, materials and sections.
    Nodes,
    /// The elements (chains expanded, superelement files read).
    Elements,
    /// The nodal coordinates and the placement of the elements on them.
    Coordinates,
    /// Every element undeformed at the scene's node positions.
    ReferenceConfiguration,
    /// Roles (fixed, rigid, prescribed) and the choice of the degrees of
    /// freedom.
    DegreesOfFreedom,
    /// Loads, controllers, initial velocities and outputs.
    Loads,
}

impl BuildStage {
    /// What the stage does, for a progress line.
    pub fn describe(&self) -> &'static str {
        match self {
            BuildStage::Nodes => "reading nodes, materials and sections",
            BuildStage::Elements => "building the elements",
            BuildStage::Coordinates => "allocating the nodal coordinates",
            BuildStage::ReferenceConfiguration => "checking the reference configuration",
            BuildStage::DegreesOfFreedom => "choosing the degrees of freedom",
            BuildStage::Loads => "assigning loads and outputs",
        }
    }
}

/// [`build_with_elements`] that calls `report` as each [`BuildStage`]
/// starts: for progress on large models.
pub fn build_reporting(
    scene: &Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
    report: &mut dyn FnMut(BuildStage),
) -> Result<Mechanism, ModelError> {
    let (mut mech, roles_scene) = assemble(scene, base_dir, extra, report)?;
    report(BuildStage::DegreesOfFreedom);
    crate::roles::assign(&roles_scene, &mut mech)?;
    mech.check_output_supports()?;
    report(BuildStage::Loads);
    crate::loads::assign(scene, &mut mech)?;
    Ok(mech)
}

/// Every stage of the build before the roles: the mechanism with its
/// coordinates, deformations and elements placed (roles not assigned yet),
/// and the scene the roles are to be taken from (the scene itself, or a copy
/// whose `fixed` also lists the restrained warping groups).
pub(crate) fn assemble<'s>(
    scene: &'s Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
    report: &mut dyn FnMut(BuildStage),
) -> Result<(Mechanism, std::borrow::Cow<'s, Scene>), ModelError> {
    report(BuildStage::Nodes);
    let dim = scene.dimension;
    let mut table = read_nodes(scene, dim)?;
    let lib = Library::read(scene)?;
    let gravity = read_gravity(scene, dim)?;
    report(BuildStage::Elements);
    let mut set = expand_elements(scene, base_dir, extra, &lib, &mut table)?;
    report(BuildStage::Coordinates);
    let coords = allocate(scene, &table, &set)?;
    let expanded = std::mem::take(&mut set.expanded);
    let (elements, eps_names) = place(dim, &coords, &table, expanded, &mut set.part_data)?;
    let Coordinates {
        nodes,
        x0,
        x_names,
        groups,
    } = coords;
    let n_x = x0.len();
    let n_eps = eps_names.len();
    let mech = Mechanism {
        name: scene.name.clone(),
        dimension: dim,
        nodes,
        mode_groups: groups,
        x0,
        x_names,
        eps_names,
        elements,
        x_roles: vec![XRole::Dependent(0); n_x],
        e_roles: vec![ERole::Dependent; n_eps],
        dofs: vec![],
        inputs: vec![],
        dependent: vec![],
        constraint_rows: vec![],
        gravity,
        loads: vec![],
        controllers: vec![],
        outputs: scene.outputs.clone(),
        initial_xd: vec![0.0; n_x],
    };
    mech.check_outputs()?;
    report(BuildStage::ReferenceConfiguration);
    check_reference_configuration(&mech, &set.part_axes)?;
    if set.restrained.is_empty() {
        Ok((mech, std::borrow::Cow::Borrowed(scene)))
    } else {
        let mut with_restraints = scene.clone();
        with_restraints.fixed.extend(set.restrained);
        Ok((mech, std::borrow::Cow::Owned(with_restraints)))
    }
}
