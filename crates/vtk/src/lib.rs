//! VTK output of flexmb mechanisms (issue 21): a configuration, a
//! trajectory or a mode shape as VTU files (VTK XML unstructured grids,
//! ASCII) and a PVD collection that ParaView and pyvista open as a time
//! series.
//!
//! * Points are the mechanism's nodes at their current positions (planar
//!   mechanisms at z = 0), then the FE nodes of each superelement drawn as
//!   its mesh. Point data: `displacement` from the reference configuration
//!   (for FE nodes: from their recovered reference positions), and whatever
//!   the caller adds (one entry per point, [`Drawing::n_points`]).
//! * Cells: a superelement whose file has an FE mesh (`fe_mesh`,
//!   `flexmb_element::FeMesh`) is drawn as its FE cells (VTK tetra,
//!   hexahedron, wedge and their quadratic forms, in VTK's node order) at
//!   the positions that `flexmb_superelement::recovery::MeshRecovery`
//!   places them at from the element's coordinates (r_p, λp, r_q, λq, η̄),
//!   measured from its nodes' initial orientations as the element measures
//!   them (λ ∘ λ0*). [`Superelements::Chord`] draws every superelement as
//!   its chord instead (smaller files); a superelement without a mesh is
//!   always its chord. Beams, trusses and hinges are lines between their
//!   two nodes (a hinge's nodes coincide), point masses and rigid bodies
//!   vertices. With [`Beams::Boxes`] ([`Drawing::with_beams`]) a beam is
//!   instead [`BOX_SEGMENTS`] hexahedra: the box of its section (a
//!   rectangle's sides, a circle's or tube's outer diameter, √A for given
//!   properties) swept along its centre line, the cubic through its nodes
//!   tangent to their frames ([`flexmb_model::BeamSection`]), their corners
//!   points after the FE nodes. Cell data: `element` (the index of the
//!   element in the mechanism, the same on all cells of a mesh or box),
//!   `kind` (an integer: 1 beam, 2 truss, 3 hinge, 4 superelement, 5 point
//!   mass, 6 rigid body, 0 other: [`KINDS`]), `axial_stiffness`, the first
//!   diagonal entry of the element's stiffness times its reference length
//!   (EA of a beam or truss, zero for kinds without an elongation), and a
//!   beam's section: `section_shape` (1 rectangle, 2 circle, 3 tube, 4
//!   given properties, 0 not a beam: a truss has no section in a scene),
//!   `section_dimensions` (rectangle by, bz, 0; circle d, d, 0; tube
//!   d_outer, d_outer, d_inner; zeros otherwise) and `section_area` (m²).
//! * Field data (values of the whole data set, e.g. a mode's frequency):
//!   [`configuration_with_fields`].
//! * A mode shape is an animated series over one period ([`mode_frames`],
//!   point data `mode_shape`). Each frame is the configuration x0 + s Δx
//!   drawn as any other: a superelement's mesh is recovered at it (the node
//!   orientations normalized), not linearized about x0; its `mode_shape`
//!   is the displacement of the extreme frame ([`Drawing::displacements`]).
//!   [`node_vectors`] gives the node vectors of any vector on the nodal
//!   coordinates.
//! * A series is written as `NAME_0000.vtu`, … and `NAME.pvd`.
//!
//! [`Drawing`] prepares a mechanism once (the mesh recoveries and the
//! reference points) for the frames of a series; the free functions make
//! one with the meshes drawn.

mod drawing;
mod xml;

pub use drawing::{Beams, Drawing, Superelements, BOX_SEGMENTS};

use flexmb_model::Mechanism;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Why writing failed.
#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    /// A file could not be written.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// The reason.
        message: String,
    },
    /// The nodal coordinates do not belong to the mechanism.
    #[error("{what} has {got} entries, the mechanism has {want} nodal coordinates")]
    Size {
        /// Which vector.
        what: String,
        /// Its length.
        got: usize,
        /// The expected length.
        want: usize,
    },
    /// Point data of the wrong length.
    #[error("point data '{name}' has {got} entries, the file has {want} points ({nodes} nodes, then the FE nodes of the superelement meshes)")]
    PointData {
        /// The data's name.
        name: String,
        /// Its length.
        got: usize,
        /// The number of points.
        want: usize,
        /// The number of mechanism nodes.
        nodes: usize,
    },
    /// A superelement's mesh cannot be placed.
    #[error("superelement '{element}': {message}")]
    Superelement {
        /// The element's id.
        element: String,
        /// The reason.
        message: String,
    },
}

/// The kind codes of the `kind` cell data.
pub const KINDS: [(&str, i32); 7] = [
    ("other", 0),
    ("beam", 1),
    ("truss", 2),
    ("hinge", 3),
    ("superelement", 4),
    ("point mass", 5),
    ("rigid body", 6),
];

/// The node vectors (one 3-vector per node, z = 0 in a planar mechanism)
/// of a vector `v` on the nodal coordinates: the node displacements of an
/// increment Δx, e.g. a mode shape in nodal coordinates (the orientation
/// coordinates are left out). Nodes only: [`Drawing::displacements`] gives
/// every point, FE nodes included.
pub fn node_vectors(mech: &Mechanism, v: &[f64]) -> Result<Vec<[f64; 3]>, VtkError> {
    if v.len() != mech.n_x() {
        return Err(VtkError::Size {
            what: "the nodal vector".into(),
            got: v.len(),
            want: mech.n_x(),
        });
    }
    Ok(mech
        .nodes
        .iter()
        .map(|n| std::array::from_fn(|d| n.position.get(d).map_or(0.0, |&i| v[i])))
        .collect())
}

/// The largest length of the 3-vectors `v` (0 for none).
pub fn largest_length(v: &[[f64; 3]]) -> f64 {
    v.iter()
        .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
        .fold(0.0, f64::max)
}

/// The VTU text of the mechanism at nodal coordinates `x`, with extra point
/// vectors `point_data` (name, one 3-vector per point), superelements drawn
/// as their meshes.
pub fn configuration(
    mech: &Mechanism,
    x: &[f64],
    point_data: &[(&str, Vec<[f64; 3]>)],
) -> Result<String, VtkError> {
    configuration_with_fields(mech, x, point_data, &[])
}

/// [`configuration`] with field data: values of the whole data set (name,
/// value), e.g. the frequency of a mode, in the VTU's `FieldData`.
pub fn configuration_with_fields(
    mech: &Mechanism,
    x: &[f64],
    point_data: &[(&str, Vec<[f64; 3]>)],
    fields: &[(&str, f64)],
) -> Result<String, VtkError> {
    Drawing::new(mech, Superelements::Mesh)?.configuration(x, point_data, fields)
}

/// [`Drawing::mode_frames`] with the superelements drawn as their meshes.
pub fn mode_frames(
    mech: &Mechanism,
    x0: &[f64],
    dx: &[f64],
    size: f64,
    frames: usize,
    fields: &[(&str, f64)],
) -> Result<Vec<(f64, String)>, VtkError> {
    Drawing::new(mech, Superelements::Mesh)?.mode_frames(x0, dx, size, frames, fields)
}

impl Drawing<'_> {
    /// The VTU text at nodal coordinates `x` with point data `point_data`
    /// (name, one 3-vector per point) and field data `fields` (name, value).
    pub fn configuration(
        &mut self,
        x: &[f64],
        point_data: &[(&str, Vec<[f64; 3]>)],
        fields: &[(&str, f64)],
    ) -> Result<String, VtkError> {
        let pts = self.points(x)?;
        if let Some((name, v)) = point_data.iter().find(|(_, v)| v.len() != pts.len()) {
            return Err(VtkError::PointData {
                name: name.to_string(),
                got: v.len(),
                want: pts.len(),
                nodes: self.mech.nodes.len(),
            });
        }
        Ok(xml::unstructured_grid(self, &pts, point_data, fields))
    }

    /// A mode shape as `frames` configurations over one period: x0 + a
    /// sin(2πk/frames) Δx, with the amplitude `a` chosen so that the largest
    /// node displacement is `size` (m); the time value of frame k is its
    /// phase k/frames. Each frame has the point data `mode_shape`, the
    /// displacements of a Δx ([`displacements`](Self::displacements): the
    /// largest node's length is `size`, ParaView's "warp by vector" with
    /// scale 1 shows the extreme), and the field data `fields` (e.g. the
    /// frequency). Superelement meshes are recovered at each frame's
    /// configuration, not linearized.
    pub fn mode_frames(
        &mut self,
        x0: &[f64],
        dx: &[f64],
        size: f64,
        frames: usize,
        fields: &[(&str, f64)],
    ) -> Result<Vec<(f64, String)>, VtkError> {
        let d = node_vectors(self.mech, dx)?;
        let max = largest_length(&d);
        let a = if max > 0.0 { size / max } else { 0.0 };
        let shape = self.displacements(x0, dx, a)?;
        (0..frames.max(1))
            .map(|k| {
                let phase = k as f64 / frames.max(1) as f64;
                let s = a * (2.0 * std::f64::consts::PI * phase).sin();
                let x: Vec<f64> = x0.iter().zip(dx).map(|(x, d)| x + s * d).collect();
                self.configuration(&x, &[("mode_shape", shape.clone())], fields)
                    .map(|t| (phase, t))
            })
            .collect()
    }
}

/// Writes `frames` (time, VTU text) as `dir/NAME_0000.vtu`, … and the
/// collection `dir/NAME.pvd`; returns the files written.
pub fn write_series(
    dir: &Path,
    name: &str,
    frames: &[(f64, String)],
) -> Result<Vec<PathBuf>, VtkError> {
    let write = |p: &Path, text: &str| {
        std::fs::write(p, text).map_err(|e| VtkError::Write {
            path: p.display().to_string(),
            message: e.to_string(),
        })
    };
    std::fs::create_dir_all(dir).map_err(|e| VtkError::Write {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut written = Vec::new();
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n  <Collection>\n",
    );
    for (k, (t, text)) in frames.iter().enumerate() {
        let file = format!("{name}_{k:04}.vtu");
        let p = dir.join(&file);
        write(&p, text)?;
        written.push(p);
        let _ = writeln!(
            pvd,
            "    <DataSet timestep=\"{t:e}\" part=\"0\" file=\"{file}\"/>"
        );
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    let p = dir.join(format!("{name}.pvd"));
    write(&p, &pvd)?;
    written.push(p);
    Ok(written)
}
