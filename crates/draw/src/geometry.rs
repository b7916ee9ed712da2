//! What a picture shows of a mechanism in one configuration: its elements
//! as segments and markers, in model coordinates and projected.

use crate::View;
use flexmb_element::Slot;
use flexmb_model::{Mechanism, XRole};

/// What an item of a picture stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ItemKind {
    /// A beam (planar or spatial): a segment between its nodes.
    Beam,
    /// A truss: a segment between its nodes.
    Truss,
    /// A superelement's chord between its two interface nodes (dashed).
    SuperelementChord,
    /// A superelement's interface node (a marker).
    InterfaceNode,
    /// A hinge (a marker at its node).
    Hinge,
    /// A point mass or planar mass (a marker).
    PointMass,
    /// A rigid body (a marker at its node).
    RigidBody,
    /// A node whose position is fixed (a ground marker).
    FixedNode,
    /// An element of another type (its nodes joined by segments).
    Other,
}

impl ItemKind {
    /// Whether the item is drawn as a marker (one point), not a segment.
    pub fn is_marker(self) -> bool {
        matches!(
            self,
            ItemKind::InterfaceNode
                | ItemKind::Hinge
                | ItemKind::PointMass
                | ItemKind::RigidBody
                | ItemKind::FixedNode
        )
    }

    /// The legend label of the kind.
    pub fn label(self) -> &'static str {
        match self {
            ItemKind::Beam => "beams",
            ItemKind::Truss => "trusses",
            ItemKind::SuperelementChord => "superelements (chord)",
            ItemKind::InterfaceNode => "interface nodes",
            ItemKind::Hinge => "hinges",
            ItemKind::PointMass => "point masses",
            ItemKind::RigidBody => "rigid bodies",
            ItemKind::FixedNode => "fixed nodes",
            ItemKind::Other => "other elements",
        }
    }
}

/// One item: a segment (two points) or a marker (one point).
#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    /// What it stands for.
    pub kind: ItemKind,
    /// The element's id, or the node's for a fixed node.
    pub id: String,
    /// Its points in model coordinates (m; z = 0 for planar mechanisms).
    pub model: Vec<[f64; 3]>,
    /// Its points projected by the view (m on the screen plane).
    pub projected: Vec<[f64; 2]>,
}

/// A mechanism in one configuration, seen from one view.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// The view.
    pub view: View,
    /// The items, in the mechanism's element order, fixed nodes last.
    pub items: Vec<Item>,
}

/// The position (m, z = 0 if planar) of every node of `mech` in the
/// configuration `x` (nodal coordinates).
pub fn node_positions(mech: &Mechanism, x: &[f64]) -> Vec<[f64; 3]> {
    mech.nodes
        .iter()
        .map(|n| {
            let mut p = [0.0; 3];
            for (c, i) in p.iter_mut().zip(&n.position) {
                *c = x[*i];
            }
            p
        })
        .collect()
}

/// The node that owns each nodal coordinate (position or orientation).
fn owners(mech: &Mechanism) -> Vec<Option<usize>> {
    let mut own = vec![None; mech.n_x()];
    for (k, n) in mech.nodes.iter().enumerate() {
        for i in n.position.iter().chain(n.orientation.iter().flatten()) {
            own[*i] = Some(k);
        }
    }
    own
}

/// The kind of an element by its type name, `None` for one that is not
/// drawn (the Euler-parameter normalization).
fn kind_of(type_name: &str) -> Option<ItemKind> {
    Some(match type_name {
        "planar beam" | "beam" => ItemKind::Beam,
        "planar truss" | "truss" => ItemKind::Truss,
        "superelement" => ItemKind::SuperelementChord,
        "planar hinge" | "hinge" => ItemKind::Hinge,
        "planar mass" | "point mass" => ItemKind::PointMass,
        "rigid body" => ItemKind::RigidBody,
        "Euler-parameter normalization" => return None,
        _ => ItemKind::Other,
    })
}

/// The nodes an element connects, in order, each once: those of its
/// position slots, else those of its other nodal coordinates.
fn element_nodes(mech: &Mechanism, own: &[Option<usize>], k: usize) -> Vec<usize> {
    let e = &mech.elements[k];
    let mut at_positions = vec![];
    let mut all = vec![];
    let mut off = 0;
    for s in e.element.slots() {
        let idx = &e.x_index[off..off + s.len()];
        off += s.len();
        let Some(node) = idx.first().and_then(|i| own[*i]) else {
            continue;
        };
        if matches!(s, Slot::Position2 | Slot::Position3) && !at_positions.contains(&node) {
            at_positions.push(node);
        }
        if !all.contains(&node) {
            all.push(node);
        }
    }
    if at_positions.is_empty() {
        all
    } else {
        at_positions
    }
}

/// The items of `mech` in the configuration `x`, projected by `view`.
pub fn geometry(mech: &Mechanism, x: &[f64], view: View) -> Geometry {
    let pos = node_positions(mech, x);
    let own = owners(mech);
    let mut items = vec![];
    let mut push = |kind: ItemKind, id: &str, pts: Vec<[f64; 3]>| {
        let projected = pts.iter().map(|p| view.project(*p)).collect();
        items.push(Item {
            kind,
            id: id.to_string(),
            model: pts,
            projected,
        });
    };
    for (k, e) in mech.elements.iter().enumerate() {
        let Some(kind) = kind_of(e.element.type_name()) else {
            continue;
        };
        let nodes = element_nodes(mech, &own, k);
        if nodes.is_empty() {
            continue;
        }
        if kind.is_marker() || nodes.len() == 1 {
            let kind = if kind.is_marker() {
                kind
            } else {
                ItemKind::Other
            };
            push(kind, &e.id, vec![pos[nodes[0]]]);
            continue;
        }
        for w in nodes.windows(2) {
            push(kind, &e.id, vec![pos[w[0]], pos[w[1]]]);
        }
        if kind == ItemKind::SuperelementChord {
            for n in [nodes[0], nodes[nodes.len() - 1]] {
                push(ItemKind::InterfaceNode, &e.id, vec![pos[n]]);
            }
        }
    }
    for (k, n) in mech.nodes.iter().enumerate() {
        let fixed =
            !n.position.is_empty() && n.position.iter().all(|i| mech.x_roles[*i] == XRole::Fixed);
        if fixed {
            push(ItemKind::FixedNode, &n.id, vec![pos[k]]);
        }
    }
    Geometry { view, items }
}

impl Geometry {
    /// The diagonal of the box around all drawn points (model coordinates,
    /// m): the size of the mechanism.
    pub fn size(&self) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in self.items.iter().flat_map(|i| &i.model) {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let d2: f64 = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum();
        if d2.is_finite() {
            d2.sqrt()
        } else {
            0.0
        }
    }
}
