//! What a VTU file shows of a mechanism: its points (the nodes, then the FE
//! nodes of the superelements drawn as their mesh) at a configuration, and
//! its cells.

use crate::VtkError;
use flexmb_model::Mechanism;
use flexmb_superelement::recovery::MeshRecovery;

/// VTK cell types used besides those of the FE meshes.
const VTK_VERTEX: u8 = 1;
const VTK_LINE: u8 = 3;
const VTK_HEXAHEDRON: u8 = 12;

/// The hexahedra a beam element is drawn as with [`Beams::Boxes`], along
/// its centre line ([`flexmb_model::BeamSection::stations`]).
pub const BOX_SEGMENTS: usize = 4;

/// How beams are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Beams {
    /// As the line between their two nodes (their section in the cell data).
    #[default]
    Lines,
    /// As boxes of their section ([`flexmb_model::BeamSection::box_size`])
    /// swept along their centre line, [`BOX_SEGMENTS`] hexahedra each.
    Boxes,
}

/// A beam drawn as a box.
struct BoxPart {
    /// Its index in the mechanism's elements.
    element: usize,
    /// The index of its first corner point among the points.
    offset: usize,
    gathered: Vec<f64>,
    local: Vec<f64>,
}

/// How superelements are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Superelements {
    /// As their FE mesh, where the superelement file has one (`fe_mesh`),
    /// at the positions recovered from the element's coordinates; the chord
    /// otherwise.
    #[default]
    Mesh,
    /// As the chord line between their two nodes: much smaller files when a
    /// large mesh would be written in every frame.
    Chord,
}

/// A superelement drawn as its FE mesh.
struct MeshPart<'a> {
    /// Its index in the mechanism's elements.
    element: usize,
    recovery: MeshRecovery<'a>,
    /// The index of its first FE node among the points.
    offset: usize,
    /// The element's coordinates (r_p, λp, r_q, λq, η̄), as it measures them.
    local: Vec<f64>,
    gathered: Vec<f64>,
}

/// A mechanism prepared for drawing: the recovery of every superelement
/// mesh it draws and the points at the reference configuration.
pub struct Drawing<'a> {
    pub(crate) mech: &'a Mechanism,
    parts: Vec<MeshPart<'a>>,
    boxes: Vec<BoxPart>,
    n_points: usize,
    /// Every point at the reference configuration x0.
    pub(crate) reference: Vec<[f64; 3]>,
}

impl<'a> Drawing<'a> {
    /// `mech` drawn with its superelements as `style` says and its beams as
    /// lines. An error when a superelement's mesh cannot be placed at the
    /// reference configuration.
    pub fn new(mech: &'a Mechanism, style: Superelements) -> Result<Self, VtkError> {
        Self::with_beams(mech, style, Beams::Lines)
    }

    /// [`new`](Self::new) with the beams drawn as `beams` says. A box's
    /// corners are points after the FE nodes of the meshes.
    pub fn with_beams(
        mech: &'a Mechanism,
        style: Superelements,
        beams: Beams,
    ) -> Result<Self, VtkError> {
        let mut parts = Vec::new();
        let mut n_points = mech.nodes.len();
        if style == Superelements::Mesh {
            for (e, el) in mech.elements.iter().enumerate() {
                let Some(data) = el.superelement.as_deref() else {
                    continue;
                };
                let Some(mesh) = &data.fe_mesh else {
                    continue;
                };
                let recovery =
                    MeshRecovery::new(data).map_err(|err| recovery_error(mech, e, err))?;
                let n = recovery.n_coords();
                if el.x_index.len() != n {
                    return Err(VtkError::Superelement {
                        element: el.id.clone(),
                        message: format!(
                            "has {} coordinates in the mechanism, its mesh recovery takes {n}",
                            el.x_index.len()
                        ),
                    });
                }
                parts.push(MeshPart {
                    element: e,
                    recovery,
                    offset: n_points,
                    local: vec![0.0; n],
                    gathered: vec![0.0; n],
                });
                n_points += mesh.nodes.len();
            }
        }
        let mut boxes = Vec::new();
        if beams == Beams::Boxes {
            for (e, el) in mech.elements.iter().enumerate() {
                if el.section.is_some() {
                    boxes.push(BoxPart {
                        element: e,
                        offset: n_points,
                        gathered: vec![0.0; el.x_index.len()],
                        local: vec![0.0; el.x_index.len()],
                    });
                    n_points += 4 * (BOX_SEGMENTS + 1);
                }
            }
        }
        let mut d = Self {
            mech,
            parts,
            boxes,
            n_points,
            reference: Vec::new(),
        };
        let mut reference = vec![[0.0; 3]; n_points];
        d.place_meshes(&mech.x0, &mut reference)?;
        d.place_boxes(&mech.x0, &mut reference);
        for (r, n) in reference.iter_mut().zip(&mech.nodes) {
            *r = std::array::from_fn(|k| n.at.get(k).copied().unwrap_or(0.0));
        }
        d.reference = reference;
        Ok(d)
    }

    /// The number of points: the mechanism's nodes, then the FE nodes of the
    /// superelements drawn as their mesh. Point data has one entry per point.
    pub fn n_points(&self) -> usize {
        self.n_points
    }

    /// The index of the first point of the FE mesh of element `element` (its
    /// index in the mechanism), if it is drawn as its mesh; its FE node i is
    /// point `offset + i`.
    pub fn mesh_offset(&self, element: usize) -> Option<usize> {
        self.parts
            .iter()
            .find(|p| p.element == element)
            .map(|p| p.offset)
    }

    /// Every point at the nodal coordinates `x` (3 components; z = 0 in a
    /// planar mechanism).
    pub fn points(&mut self, x: &[f64]) -> Result<Vec<[f64; 3]>, VtkError> {
        self.check_x("x", x)?;
        let mut out = vec![[0.0; 3]; self.n_points];
        for (o, n) in out.iter_mut().zip(&self.mech.nodes) {
            *o = std::array::from_fn(|d| n.position.get(d).map_or(0.0, |&i| x[i]));
        }
        self.place_meshes(x, &mut out)?;
        self.place_boxes(x, &mut out);
        Ok(out)
    }

    /// The corners of every beam box at `x`, into `out` (all points).
    fn place_boxes(&mut self, x: &[f64], out: &mut [[f64; 3]]) {
        let mech = self.mech;
        for b in &mut self.boxes {
            let el = &mech.elements[b.element];
            let section = el.section.as_ref().expect("a beam");
            el.measured_at(x, &mut b.gathered, &mut b.local);
            for (k, st) in section.stations(&b.local, BOX_SEGMENTS).iter().enumerate() {
                let at = b.offset + 4 * k;
                out[at..at + 4].copy_from_slice(&section.corners(st));
            }
        }
    }

    /// The point displacements of the increment `a` Δx at `x`: a Δx of the
    /// node positions, and for the FE nodes the difference of the recovered
    /// positions at x + a Δx and at x (the node orientations of x + a Δx
    /// normalized), so that a mode shape's field is the displacement of its
    /// extreme frame.
    pub fn displacements(
        &mut self,
        x: &[f64],
        dx: &[f64],
        a: f64,
    ) -> Result<Vec<[f64; 3]>, VtkError> {
        self.check_x("x", x)?;
        self.check_x("the nodal vector", dx)?;
        let moved: Vec<f64> = x.iter().zip(dx).map(|(x, d)| x + a * d).collect();
        let from = self.points(x)?;
        let to = self.points(&moved)?;
        Ok(from
            .iter()
            .zip(&to)
            .map(|(p, q)| std::array::from_fn(|d| q[d] - p[d]))
            .collect())
    }

    fn check_x(&self, what: &str, x: &[f64]) -> Result<(), VtkError> {
        if x.len() == self.mech.n_x() {
            Ok(())
        } else {
            Err(VtkError::Size {
                what: what.into(),
                got: x.len(),
                want: self.mech.n_x(),
            })
        }
    }

    /// The FE node positions of every drawn mesh at `x`, into `out` (all
    /// points). The element's coordinates are gathered, measured from the
    /// initial orientations of its nodes as the element does (λ ∘ λ0*), the
    /// Euler parameters normalized.
    fn place_meshes(&mut self, x: &[f64], out: &mut [[f64; 3]]) -> Result<(), VtkError> {
        let mech = self.mech;
        for p in &mut self.parts {
            let el = &mech.elements[p.element];
            el.measured_at(x, &mut p.gathered, &mut p.local);
            let n = p.recovery.mesh().nodes.len();
            p.recovery
                .positions(&p.local, &mut out[p.offset..p.offset + n])
                .map_err(|err| recovery_error(mech, p.element, err))?;
        }
        Ok(())
    }

    /// The cells: (VTK type, point indices, element index). A superelement
    /// drawn as its mesh gives its FE cells (vertices at its FE nodes if the
    /// mesh has no cells); other elements lines between their two nodes
    /// (a hinge's coincide) or a vertex at their one node.
    pub(crate) fn cells(&self) -> Vec<(u8, Vec<usize>, usize)> {
        let mech = self.mech;
        // the node whose first position coordinate is each x index
        let mut node_of = vec![usize::MAX; mech.n_x()];
        for (k, n) in mech.nodes.iter().enumerate() {
            if let Some(&i) = n.position.first() {
                node_of[i] = k;
            }
        }
        let mut out = Vec::new();
        for (e, el) in mech.elements.iter().enumerate() {
            if let Some(p) = self.parts.iter().find(|p| p.element == e) {
                let mesh = p.recovery.mesh();
                if mesh.cells.is_empty() {
                    out.extend((0..mesh.nodes.len()).map(|i| (VTK_VERTEX, vec![p.offset + i], e)));
                }
                for c in &mesh.cells {
                    out.push((
                        c.vtk_type,
                        c.nodes.iter().map(|i| p.offset + i).collect(),
                        e,
                    ));
                }
                continue;
            }
            if let Some(b) = self.boxes.iter().find(|b| b.element == e) {
                // corners 0–3 of a station wind about the beam's axis, so
                // each hexahedron's base points into it (VTK's order)
                for k in 0..BOX_SEGMENTS {
                    let at = b.offset + 4 * k;
                    out.push((VTK_HEXAHEDRON, (at..at + 8).collect(), e));
                }
                continue;
            }
            let mut nodes: Vec<usize> = Vec::new();
            for &i in &el.x_index {
                let k = node_of[i];
                if k != usize::MAX && !nodes.contains(&k) {
                    nodes.push(k);
                }
            }
            match nodes.len() {
                0 => {}
                1 => out.push((VTK_VERTEX, nodes, e)),
                _ => out.push((VTK_LINE, nodes[..2].to_vec(), e)),
            }
        }
        out
    }
}

fn recovery_error(mech: &Mechanism, e: usize, err: flexmb_superelement::Error) -> VtkError {
    VtkError::Superelement {
        element: mech.elements[e].id.clone(),
        message: err.to_string(),
    }
}
