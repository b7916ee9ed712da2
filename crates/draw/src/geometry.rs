//! What a picture shows of a mechanism in one configuration: its elements
//! as segments and markers, in model coordinates and projected.
//!
//! [`Style::Outline`] draws a beam as a thin box: the outline of its
//! section's box ([`flexmb_model::BeamSection`]) swept along its deformed
//! centre line (the four edges along it and the section at each end), and
//! a superelement whose file has its FE mesh as the outline of that mesh,
//! recovered at the configuration (`flexmb_superelement::recovery`): the
//! edges where its boundary faces meet at more than [`OUTLINE_ANGLE_DEG`]
//! at the reference ([`flexmb_element::fe_faces::feature_edges`]): the
//! part's outline, without internal edges or the grid lines of flat faces. [`Style::Lines`] draws beams as lines between their
//! nodes and superelements as their chord.

use crate::View;
use flexmb_element::fe_faces::feature_edges;
use flexmb_element::Slot;
use flexmb_model::{Mechanism, XRole};
use flexmb_superelement::recovery::MeshRecovery;

/// How beams and superelements are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Style {
    /// Beams as thin boxes of their section along their centre line,
    /// superelements as the outline of their FE mesh (their chord if their
    /// file has no mesh).
    #[default]
    Outline,
    /// Beams as lines between their nodes, superelements as their chord.
    Lines,
}

/// Segments of a beam's centre line drawn by [`Style::Outline`].
pub const BEAM_STATIONS: usize = 8;

/// The angle (degrees) between two boundary faces of a superelement's mesh
/// above which their common edge belongs to its outline.
pub const OUTLINE_ANGLE_DEG: f64 = 30.0;

/// What an item of a picture stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ItemKind {
    /// A beam (planar or spatial): a segment between its nodes.
    Beam,
    /// A truss: a segment between its nodes.
    Truss,
    /// A superelement's chord between its two interface nodes (dashed).
    SuperelementChord,
    /// An edge of the outline of a superelement's FE mesh.
    SuperelementOutline,
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
            ItemKind::SuperelementOutline => "superelements",
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

/// The items of `mech` in the configuration `x`, projected by `view`,
/// beams as lines and superelements as their chord ([`Style::Lines`]).
pub fn geometry(mech: &Mechanism, x: &[f64], view: View) -> Geometry {
    styled_geometry(mech, x, view, Style::Lines)
}

/// The polylines of a beam drawn as a thin box at `x`: the four edges
/// along its centre line and its section at each end (closed); `None` for
/// an element without a section.
fn beam_box(mech: &Mechanism, k: usize, x: &[f64]) -> Option<Vec<Vec<[f64; 3]>>> {
    let el = &mech.elements[k];
    let section = el.section.as_ref()?;
    let n = el.x_index.len();
    let (mut gathered, mut local) = (vec![0.0; n], vec![0.0; n]);
    el.measured_at(x, &mut gathered, &mut local);
    let corners: Vec<[[f64; 3]; 4]> = section
        .stations(&local, BEAM_STATIONS)
        .iter()
        .map(|s| section.corners(s))
        .collect();
    let mut out: Vec<Vec<[f64; 3]>> = (0..4)
        .map(|c| corners.iter().map(|s| s[c]).collect())
        .collect();
    for end in [&corners[0], &corners[corners.len() - 1]] {
        out.push(vec![end[0], end[1], end[2], end[3], end[0]]);
    }
    Some(out)
}

/// The outline edges of a superelement's FE mesh recovered at `x` (each a
/// polyline through its midside node, if any); `None` without a mesh with
/// cells, or where the mesh cannot be placed.
fn superelement_outline(mech: &Mechanism, k: usize, x: &[f64]) -> Option<Vec<Vec<[f64; 3]>>> {
    let el = &mech.elements[k];
    let data = el.superelement.as_deref()?;
    let mesh = data.fe_mesh.as_ref().filter(|m| !m.cells.is_empty())?;
    let mut recovery = MeshRecovery::new(data).ok()?;
    let n = el.x_index.len();
    if recovery.n_coords() != n {
        return None;
    }
    let (mut gathered, mut local) = (vec![0.0; n], vec![0.0; n]);
    el.measured_at(x, &mut gathered, &mut local);
    let mut at = vec![[0.0; 3]; mesh.nodes.len()];
    recovery.positions(&local, &mut at).ok()?;
    Some(
        feature_edges(&mesh.cells, &mesh.nodes, OUTLINE_ANGLE_DEG.to_radians())
            .iter()
            .map(|e| e.iter().map(|&i| at[i]).collect())
            .collect(),
    )
}

/// The items of `mech` in the configuration `x`, projected by `view`,
/// beams and superelements drawn as `style` says.
pub fn styled_geometry(mech: &Mechanism, x: &[f64], view: View, style: Style) -> Geometry {
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
        let outline = match (style, kind) {
            (Style::Outline, ItemKind::Beam) => beam_box(mech, k, x).map(|l| (ItemKind::Beam, l)),
            (Style::Outline, ItemKind::SuperelementChord) => {
                superelement_outline(mech, k, x).map(|l| (ItemKind::SuperelementOutline, l))
            }
            _ => None,
        };
        if let Some((kind, lines)) = outline {
            for l in lines {
                push(kind, &e.id, l);
            }
        } else {
            for w in nodes.windows(2) {
                push(kind, &e.id, vec![pos[w[0]], pos[w[1]]]);
            }
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
