//! The scene file format (RON via serde). See `docs/scene-format.md` for a full
//! example; every field is described here.

use crate::TimeFunction;
use flexmb_element::{SectionProperties, VelocityTransform};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Planar (x, y, φ) or spatial (x, y, z, λ) mechanism.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub enum Dimension {
    /// Planar: nodes have (x, y) and, where an element needs one, an angle φ.
    Planar,
    /// Spatial: nodes have (x, y, z) and, where needed, Euler parameters λ.
    #[default]
    Spatial,
}

impl Dimension {
    /// Position coordinates of a node: 2 (planar) or 3 (spatial).
    pub fn position_len(self) -> usize {
        match self {
            Dimension::Planar => 2,
            Dimension::Spatial => 3,
        }
    }
}

/// A material: E, ρ, and either G or Poisson's ratio ν.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus (Pa).
    pub e: f64,
    /// Shear modulus (Pa); if absent, from `nu`.
    #[serde(default)]
    pub g: Option<f64>,
    /// Poisson's ratio; used when `g` is absent (default 0.3).
    #[serde(default)]
    pub nu: Option<f64>,
    /// Density (kg/m³).
    pub rho: f64,
}

/// A cross-section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SectionSpec {
    /// Solid rectangle: side `by` along local y, `bz` along local z (m).
    Rectangle {
        /// Side along local y.
        by: f64,
        /// Side along local z.
        bz: f64,
    },
    /// Solid circle of diameter `d`.
    Circle {
        /// Diameter.
        d: f64,
    },
    /// Circular tube.
    Tube {
        /// Outer diameter.
        d_outer: f64,
        /// Inner diameter.
        d_inner: f64,
    },
    /// Properties given directly (use `inf` shear factors for Euler–Bernoulli).
    User(SectionProperties),
}

/// A node: its id and reference position (2 or 3 components).
///
/// A node may share the position coordinates of another node while having its
/// own orientation (`position_of`): two bodies joined by a hinge at one point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSpec {
    /// Unique id.
    pub id: String,
    /// Reference position (m); may be omitted with `position_of`.
    #[serde(default)]
    pub at: Vec<f64>,
    /// Share the position coordinates of this (earlier) node.
    #[serde(default)]
    pub position_of: Option<String>,
    /// The orientation the node starts in (default: the global axes). The
    /// elements on the node start undeformed in it; a rigid body's `com`
    /// and `inertia` are given in the node's axes, so they turn with it.
    #[serde(default)]
    pub orientation: Option<OrientationSpec>,
}

/// An initial orientation of a node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum OrientationSpec {
    /// Spatial: a rotation by `angle` (rad) about `axis` (3 components, any
    /// non-zero length), right-handed.
    AxisAngle {
        /// The axis (global).
        axis: Vec<f64>,
        /// The angle (rad).
        angle: f64,
    },
    /// Spatial: the rotation vector θ n (rad, 3 components).
    RotationVector(Vec<f64>),
    /// Spatial: Euler parameters (λ0, λ1, λ2, λ3), λ0 the scalar part; unit
    /// within 1e-9 (then normalized).
    EulerParameters(Vec<f64>),
    /// Planar: the angle φ (rad) counter-clockwise.
    Angle(f64),
}

fn unique_material_ids<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<BTreeMap<String, MaterialSpec>, D::Error> {
    flexmb_input::unique_keys_named(d, "material id")
}

fn unique_section_ids<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<BTreeMap<String, SectionSpec>, D::Error> {
    flexmb_input::unique_keys_named(d, "section id")
}

fn default_true() -> bool {
    true
}
fn default_one() -> usize {
    1
}

/// Options of a beam in a scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamSpec {
    /// End nodes (p, q).
    pub nodes: (String, String),
    /// Material id.
    pub material: String,
    /// Section id.
    pub section: String,
    /// Spatial only: a vector giving the local y direction (default: global z
    /// unless the beam is along z, then global y... set it explicitly for clarity).
    #[serde(default)]
    pub up: Option<Vec<f64>>,
    /// Split into `n` equal elements (the chain helper); intermediate nodes are
    /// named `ID.n1`, `ID.n2`, ..., elements `ID.1` ... `ID.n`.
    #[serde(default = "default_one")]
    pub n: usize,
    /// Timoshenko bending (default) or Euler–Bernoulli.
    #[serde(default = "default_true")]
    pub timoshenko: bool,
    /// Second-order shortening/bowing term in the elongation (default on).
    #[serde(default = "default_true")]
    pub shortening: bool,
    /// Distributed mass (default on).
    #[serde(default = "default_true")]
    pub mass: bool,
    /// Velocity transformation of the inertia (default B3).
    #[serde(default)]
    pub transform: VelocityTransform,
    /// Spatial only: Vlasov torsion with warping, one warping coordinate
    /// w = φ′ (rad/m) per node of the chain, in one-mode groups `ID.w0` …
    /// `ID.wN` shared by neighbouring elements (N + 1 coordinates for
    /// `n: N`). `p` and `q` say what the chain's end groups are. Default
    /// `None`: the thesis's beam (St-Venant torsion, free warping).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warping: Option<WarpingSpec>,
    /// Spatial `Rectangle` sheets only: the anticlastic curl (the Poisson
    /// share of the weak-axis bending, `flexmb_element::anticlastic_overlay`),
    /// two curl amplitudes (1/m) per node of the chain in two-mode groups
    /// `ID.a0` … `ID.aN` shared by neighbouring elements. `p` and `q` say
    /// what the chain's end groups are, as for `warping`: `Restrained` where
    /// the sheet meets a clamp or a rigid body (its edge stays straight),
    /// `Free` at a free end, `Shared` where two sheets continue each other.
    /// Poisson's ratio is the material's, E/(2G) − 1. Default `None`: the
    /// thesis's beam (free curl everywhere, EI).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anticlastic: Option<WarpingSpec>,
}

/// The ends of a beam chain's warping or curl coordinates
/// ([`BeamSpec::warping`], [`BeamSpec::anticlastic`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WarpingSpec {
    /// The end at the first node.
    pub p: WarpingEnd,
    /// The end at the last node.
    pub q: WarpingEnd,
}

/// What one end of a beam chain with warping does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum WarpingEnd {
    /// The end's warping is free: its own group `ID.w0` / `ID.wN`, a degree
    /// of freedom (the beam's own free end).
    Free,
    /// The end cannot warp (w = 0): a clamp or a rigid body. Its group is
    /// fixed, as if listed under `fixed` as `Modes("ID.w0")` / `Modes("ID.wN")`.
    Restrained,
    /// The end's warping coordinate is the named mode group, shared with
    /// the other elements that name it (another chain's `Shared` end, or
    /// one of its `ID.wK` groups): two sheets that continue each other.
    /// The group must hold one coordinate.
    Shared(String),
}

/// What an element is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ElementSpec {
    /// A beam (planar or spatial after the scene's dimension).
    Beam(BeamSpec),
    /// A truss (rod) between two nodes, optionally split into `n` elements.
    Truss {
        /// End nodes.
        nodes: (String, String),
        /// Axial stiffness EA (N).
        ea: f64,
        /// Mass per length (kg/m).
        #[serde(default)]
        mass_per_length: f64,
        /// Split into n elements.
        #[serde(default = "default_one")]
        n: usize,
    },
    /// A hinge between the orientations of two nodes (planar: angles).
    Hinge {
        /// The two nodes.
        nodes: (String, String),
        /// Spatial only: the axis in the reference configuration.
        #[serde(default)]
        axis: Option<Vec<f64>>,
        /// Rotational stiffness (N m/rad), default 0.
        #[serde(default)]
        stiffness: f64,
        /// Spatial only: stiffness of the two small bending deformations, default 0
        /// (make them rigid for an ideal hinge).
        #[serde(default)]
        bending_stiffness: f64,
    },
    /// A point mass on a node's position.
    PointMass {
        /// The node.
        node: String,
        /// Mass (kg).
        mass: f64,
        /// Planar only: rotary inertia about z (kg m²), attached to the node's angle.
        #[serde(default)]
        inertia: Option<f64>,
    },
    /// A rigid body on a node's position and orientation.
    RigidBody {
        /// The node.
        node: String,
        /// Mass (kg).
        mass: f64,
        /// Centre of mass relative to the node, in global axes at the reference (m).
        #[serde(default)]
        com: Option<Vec<f64>>,
        /// Inertia tensor about the centre of mass, global axes at the reference (kg m²).
        inertia: Vec<Vec<f64>>,
    },
    /// A two-node superelement from a linear superelement file (RON).
    Superelement {
        /// Boundary nodes (p, q).
        nodes: (String, String),
        /// Path of the `LinearSuperelement` RON file, relative to the scene.
        file: String,
        /// Velocity transformation (default B3).
        #[serde(default)]
        transform: VelocityTransform,
        /// Names of the mode groups of the p-side and q-side interface modes, to
        /// share them with a neighbour (default: private groups `ID.p`, `ID.q`).
        #[serde(default)]
        share: (Option<String>, Option<String>),
    },
}

/// An element entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElementEntry {
    /// Unique id.
    pub id: String,
    /// The element.
    #[serde(rename = "type")]
    pub kind: ElementSpec,
}

/// A nodal coordinate component.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Component {
    /// x position.
    X,
    /// y position.
    Y,
    /// z position (spatial).
    Z,
    /// Planar angle φ.
    Angle,
    /// Euler parameter λ0 … λ3 (spatial).
    Lambda(u8),
    /// All position components.
    Position,
    /// The orientation (angle or all four Euler parameters).
    Orientation,
}

/// Selects coordinates or deformations in role lists.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Select {
    /// Every coordinate of a node.
    Node(String),
    /// Some coordinate(s) of a node.
    Coord(String, Component),
    /// Deformations of an element (a chain id selects all its members) by
    /// name; "*" selects all of them.
    Def(String, String),
    /// All coordinates of a superelement mode group.
    Modes(String),
}

/// A prescribed coordinate or deformation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Prescribed {
    /// What is prescribed (one coordinate or one deformation).
    pub what: Select,
    /// Its value in time.
    pub function: TimeFunction,
}

/// How the degrees of freedom are chosen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub enum DofChoice {
    /// Deformations where they can describe the motion, then nodal coordinates
    /// (the thesis's choice in chapter 5 and for the FBM of chapter 6).
    #[default]
    Deformations,
    /// Absolute nodal coordinates (the thesis's choice for the IBM of chapter 6).
    NodalCoordinates,
    /// Exactly these coordinates and/or deformations.
    Explicit(Vec<Select>),
}

/// A nodal load: force and/or moment times a function of time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// The node.
    pub node: String,
    /// Force vector (N) in global axes (2 or 3 components).
    #[serde(default)]
    pub force: Option<Vec<f64>>,
    /// Moment (N m): planar a scalar in a 1-vector, spatial a 3-vector in global axes.
    #[serde(default)]
    pub moment: Option<Vec<f64>>,
    /// Time history multiplying force and moment (default constant 1).
    #[serde(default)]
    pub function: Option<TimeFunction>,
}

/// A PD controller (thesis (7.12)) acting on one coordinate or deformation:
/// generalized force kp (r − y) + kd (ṙ − ẏ) on it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// The controlled coordinate or deformation.
    pub on: Select,
    /// Proportional gain.
    pub kp: f64,
    /// Derivative gain.
    #[serde(default)]
    pub kd: f64,
    /// Reference r(t).
    pub reference: TimeFunction,
}

/// Outputs to record during a simulation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum OutputSpec {
    /// Position of a node.
    Position(String),
    /// Orientation of a node (planar angle, or rotation vector).
    Rotation(String),
    /// Deformations of an element ("*" for all).
    Deformation(String, String),
    /// Stress resultants of an element ("*" for all).
    Stress(String, String),
    /// Kinetic, elastic and external-work energies.
    Energies,
    /// The degrees of freedom.
    Dofs,
    /// Velocity of a node (the rates of its position coordinates).
    Velocity(String),
    /// Angular velocity of a node: planar φ̇; spatial ω = 2Λ(λ)λ̇ in global
    /// axes (thesis (2.14)).
    AngularVelocity(String),
    /// Total linear momentum and angular momentum about a point (2 planar or
    /// 3 spatial components), exact for every inertia element: the
    /// projections of the generalized momenta on a rigid translation and
    /// rotation.
    Momentum(Vec<f64>),
    /// The force (and moment, about the node) that the supports exert on a
    /// node with fixed or prescribed coordinates, from the nodal equations of
    /// motion with the stresses of rigid and prescribed deformations.
    Reaction(String),
}

/// Initial velocity of a group of nodes moving as a rigid body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialVelocity {
    /// Nodes this applies to (empty: all non-fixed nodes).
    #[serde(default)]
    pub nodes: Vec<String>,
    /// Translational velocity of the reference point.
    #[serde(default)]
    pub v: Option<Vec<f64>>,
    /// Angular velocity (3 components; planar: only z is used).
    #[serde(default)]
    pub omega: Option<Vec<f64>>,
    /// Reference point of the rigid velocity field.
    #[serde(default)]
    pub about: Option<Vec<f64>>,
}

/// A complete scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A descriptive name.
    #[serde(default)]
    pub name: String,
    /// Planar or spatial.
    #[serde(default)]
    pub dimension: Dimension,
    /// Gravity acceleration vector (m/s²), if any.
    #[serde(default)]
    pub gravity: Option<Vec<f64>>,
    /// Materials by id (each id once).
    #[serde(default, deserialize_with = "unique_material_ids")]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Sections by id (each id once).
    #[serde(default, deserialize_with = "unique_section_ids")]
    pub sections: BTreeMap<String, SectionSpec>,
    /// Nodes.
    pub nodes: Vec<NodeSpec>,
    /// Elements.
    pub elements: Vec<ElementEntry>,
    /// Fixed coordinates.
    #[serde(default)]
    pub fixed: Vec<Select>,
    /// Rigid deformations (kept zero).
    #[serde(default)]
    pub rigid: Vec<Select>,
    /// Prescribed coordinates or deformations (inputs).
    #[serde(default)]
    pub prescribed: Vec<Prescribed>,
    /// The choice of degrees of freedom.
    #[serde(default)]
    pub dofs: DofChoice,
    /// Coordinates or deformations that must be degrees of freedom, taken
    /// before the automatic choice (e.g. a coordinate a sweep holds).
    #[serde(default)]
    pub dofs_first: Vec<Select>,
    /// Nodal loads.
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
    /// PD controllers.
    #[serde(default)]
    pub controllers: Vec<ControllerSpec>,
    /// Initial velocities (rigid-body fields on node groups).
    #[serde(default)]
    pub initial_velocity: Vec<InitialVelocity>,
    /// Outputs to record.
    #[serde(default)]
    pub outputs: Vec<OutputSpec>,
}
