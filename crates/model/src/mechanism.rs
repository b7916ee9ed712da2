//! The assembled mechanism: every nodal coordinate and deformation classified
//! (thesis §5.2.2, §6.2.2, (6.4)), ready for the kinematics.

use crate::scene::{Dimension, OutputSpec};
use crate::TimeFunction;
use flexmb_element::{Element, LinearSuperelement};
use std::sync::Arc;

/// Role of a nodal coordinate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum XRole {
    /// Fixed at its reference value.
    Fixed,
    /// The `k`-th degree of freedom.
    Dof(usize),
    /// The `k`-th prescribed input.
    Input(usize),
    /// The `k`-th dependent (calculable) coordinate.
    Dependent(usize),
}

/// Role of a deformation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ERole {
    /// Kept zero.
    Rigid,
    /// The `k`-th degree of freedom.
    Dof(usize),
    /// The `k`-th prescribed input.
    Input(usize),
    /// Follows from the configuration.
    Dependent,
}

/// A generalized coordinate: a nodal coordinate or a deformation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Coordinate {
    /// Nodal coordinate with this global index.
    Node(usize),
    /// Deformation with this global index.
    Def(usize),
}

/// An element placed in the mechanism.
#[derive(Clone, Debug)]
pub struct MechElement {
    /// Its id (chain members: `CHAIN.k`).
    pub id: String,
    /// The id it was declared under (the chain's id for chain members).
    pub group: String,
    /// The element.
    pub element: Element,
    /// Global nodal-coordinate index of each local coordinate.
    pub x_index: Vec<usize>,
    /// Index of its first deformation in the global deformation vector.
    pub eps_offset: usize,
    /// A superelement's data as read from its file (shared between the
    /// elements that use the same file): S̄, M̄, R0 and, if the builder wrote
    /// it, the FE mesh with its recovery (`flexmb_superelement::recovery`
    /// places it; the VTK writer draws it). For a superelement, `x_index`
    /// gathers exactly the coordinates that recovery takes: (r_p, λp, r_q,
    /// λq, η̄) with η̄ its p, q and normal mode groups in turn. `None` for
    /// the other elements.
    pub superelement: Option<Arc<LinearSuperelement>>,
    /// A beam's cross-section and reference frame, for drawing it as a box
    /// ([`crate::BeamSection`]); `None` for the other elements.
    pub section: Option<crate::BeamSection>,
}

impl MechElement {
    /// Copies the element's coordinates out of `global` (one entry per nodal
    /// coordinate) into `local` (the element's order).
    pub fn gather(&self, global: &[f64], local: &mut [f64]) {
        for (l, i) in local.iter_mut().zip(&self.x_index) {
            *l = global[*i];
        }
    }

    /// The element's coordinates at `x` (one entry per nodal coordinate) as
    /// the element measures them, into `local` (the element's order, with
    /// `gathered` as work space, both of the element's length): rotations
    /// since the nodes' initial orientations (λ ∘ λ0*, φ − φ0), the Euler
    /// parameters of its orientation slots normalized. What drawing a
    /// superelement's mesh (`flexmb_superelement::recovery`) or a beam's
    /// box ([`crate::BeamSection`]) takes.
    pub fn measured_at(&self, x: &[f64], gathered: &mut [f64], local: &mut [f64]) {
        self.gather(x, gathered);
        self.element.measured_coordinates(gathered, local);
        let mut at = 0;
        for slot in self.element.slots() {
            if matches!(slot, flexmb_element::Slot::Orientation) {
                let lam = &mut local[at..at + 4];
                let n = lam.iter().map(|v| v * v).sum::<f64>().sqrt();
                if n > 0.0 {
                    lam.iter_mut().for_each(|v| *v /= n);
                }
            }
            at += slot.len();
        }
    }

    /// Adds `s · local` (the element's order) to `global`.
    pub fn scatter_add(&self, local: &[f64], s: f64, global: &mut [f64]) {
        for (l, i) in local.iter().zip(&self.x_index) {
            global[*i] += s * l;
        }
    }
}

/// A node with the global indices of its coordinates.
#[derive(Clone, Debug)]
pub struct NodeInfo {
    /// Its id.
    pub id: String,
    /// Reference position.
    pub at: Vec<f64>,
    /// Indices of the position coordinates.
    pub position: Vec<usize>,
    /// Indices of the orientation coordinates (1 angle or 4 Euler parameters), if used.
    pub orientation: Option<Vec<usize>>,
}

/// A prescribed coordinate or deformation.
#[derive(Clone, Debug)]
pub struct Input {
    /// What is prescribed.
    pub target: Coordinate,
    /// Its value in time.
    pub function: TimeFunction,
}

/// A nodal load.
#[derive(Clone, Debug)]
pub enum Load {
    /// A force on position coordinates.
    Force {
        /// Indices of the position coordinates.
        index: Vec<usize>,
        /// Force vector.
        f: Vec<f64>,
        /// Time history.
        function: TimeFunction,
    },
    /// A moment on a planar angle.
    PlanarMoment {
        /// Index of the angle.
        index: usize,
        /// Moment.
        m: f64,
        /// Time history.
        function: TimeFunction,
    },
    /// A moment (global axes) on Euler parameters: generalized force 2Λᵀm.
    SpatialMoment {
        /// Indices of λ0..λ3.
        index: [usize; 4],
        /// Moment vector.
        m: [f64; 3],
        /// Time history.
        function: TimeFunction,
    },
}

/// A PD controller on a coordinate or deformation (thesis (7.12)).
#[derive(Clone, Debug)]
pub struct Controller {
    /// Controlled coordinate.
    pub on: Coordinate,
    /// Proportional gain.
    pub kp: f64,
    /// Derivative gain.
    pub kd: f64,
    /// Reference.
    pub reference: TimeFunction,
}

/// The assembled mechanism.
#[derive(Clone, Debug)]
pub struct Mechanism {
    /// Scene name.
    pub name: String,
    /// Planar or spatial.
    pub dimension: Dimension,
    /// Nodes.
    pub nodes: Vec<NodeInfo>,
    /// Superelement mode groups: name and coordinate indices.
    pub mode_groups: Vec<(String, Vec<usize>)>,
    /// Reference nodal coordinates.
    pub x0: Vec<f64>,
    /// Names of the nodal coordinates, e.g. `B.x`, `B.l2`, `w1.eta1`.
    pub x_names: Vec<String>,
    /// Names of the deformations, e.g. `f1.3.bending_y_p`.
    pub eps_names: Vec<String>,
    /// Elements.
    pub elements: Vec<MechElement>,
    /// Role of each nodal coordinate.
    pub x_roles: Vec<XRole>,
    /// Role of each deformation.
    pub e_roles: Vec<ERole>,
    /// The degrees of freedom q, in order.
    pub dofs: Vec<Coordinate>,
    /// The prescribed inputs u, in order.
    pub inputs: Vec<Input>,
    /// Dependent nodal coordinates, in order of their `XRole::Dependent` index.
    pub dependent: Vec<usize>,
    /// Deformations that are equations for the dependent coordinates (rigid,
    /// degree of freedom or prescribed), in row order.
    pub constraint_rows: Vec<usize>,
    /// Gravity.
    pub gravity: Option<[f64; 3]>,
    /// Loads.
    pub loads: Vec<Load>,
    /// Controllers.
    pub controllers: Vec<Controller>,
    /// Requested outputs.
    pub outputs: Vec<OutputSpec>,
    /// Initial nodal velocities (rigid-body fields of the scene), before projection on the DOFs.
    pub initial_xd: Vec<f64>,
}

impl Mechanism {
    /// Number of nodal coordinates.
    pub fn n_x(&self) -> usize {
        self.x0.len()
    }
    /// Number of deformations.
    pub fn n_eps(&self) -> usize {
        self.eps_names.len()
    }
    /// Number of degrees of freedom.
    pub fn n_dof(&self) -> usize {
        self.dofs.len()
    }
    /// Name of a generalized coordinate.
    pub fn coordinate_name(&self, c: Coordinate) -> &str {
        match c {
            Coordinate::Node(i) => &self.x_names[i],
            Coordinate::Def(j) => &self.eps_names[j],
        }
    }
    /// The node with this id.
    pub fn node(&self, id: &str) -> Option<&NodeInfo> {
        self.nodes.iter().find(|n| n.id == id)
    }
    /// Global deformation indices of an element by id, with their names.
    pub fn element_by_id(&self, id: &str) -> Option<&MechElement> {
        self.elements.iter().find(|e| e.id == id)
    }
    /// The degree-of-freedom values at the reference configuration.
    pub fn q0(&self) -> Vec<f64> {
        self.dofs
            .iter()
            .map(|c| match c {
                Coordinate::Node(i) => self.x0[*i],
                Coordinate::Def(_) => 0.0,
            })
            .collect()
    }
    /// The first element that has flipped at the nodal coordinates `x` (its
    /// chord turned by more than π/2 against a node frame,
    /// [`Element::is_flipped`]), with that angle (rad): a spurious state of the
    /// periodic deformation functions. No allocation: cheap enough for every
    /// Newton iterate.
    pub fn flipped_element(&self, x: &[f64]) -> Option<(&MechElement, f64)> {
        // the chord and the node frames are in the first 14 local coordinates
        let mut xl = [0.0; 14];
        self.elements.iter().find_map(|e| {
            let n = e.x_index.len().min(xl.len());
            e.gather(x, &mut xl[..n]);
            e.element
                .is_flipped(&xl[..n])
                .then(|| (e, e.element.chord_angle(&xl[..n]).unwrap_or(f64::NAN)))
        })
    }

    /// A one-line summary.
    pub fn summary(&self) -> String {
        format!(
            "{}: {} nodal coordinates, {} deformations, {} elements, {} degrees of freedom, {} inputs, {} dependent coordinates",
            if self.name.is_empty() { "mechanism" } else { &self.name },
            self.n_x(),
            self.n_eps(),
            self.elements.len(),
            self.n_dof(),
            self.inputs.len(),
            self.dependent.len()
        )
    }
}
