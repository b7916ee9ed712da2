//! VTK output of flexmb mechanisms (issue 21): a configuration, a
//! trajectory or a mode shape as VTU files (VTK XML unstructured grids,
//! ASCII) and a PVD collection that ParaView and pyvista open as a time
//! series.
//!
//! * Points are the mechanism's nodes at their current positions (planar
//!   mechanisms at z = 0). Point data: `displacement` from the reference
//!   positions, and whatever the caller adds (velocities, …).
//! * Cells: beams, trusses, hinges and superelements as lines between their
//!   two nodes (a hinge's nodes coincide), point masses and rigid bodies as
//!   vertices. Cell data: `element` (the index of the element in the
//!   mechanism), `kind` (an integer: 1 beam, 2 truss, 3 hinge, 4
//!   superelement, 5 point mass, 6 rigid body, 0 other: [`KINDS`]) and `axial_stiffness`, the first diagonal entry of
//!   the element's stiffness times its reference length (EA of a beam or
//!   truss, zero for kinds without an elongation).
//! * Field data (values of the whole data set, e.g. a mode's frequency):
//!   [`configuration_with_fields`].
//! * A mode shape is an animated series over one period ([`mode_frames`],
//!   point data `mode_shape`); [`node_vectors`] gives the node vectors of
//!   any vector on the nodal coordinates, to write modes as point data.
//! * A series is written as `NAME_0000.vtu`, … and `NAME.pvd`.
//!
//! Not yet: superelements drawn as their FE mesh with the displacement field
//! recovered from their modes (the `.se.ron` file now holds the mesh and its
//! recovery, `flexmb_element::FeMesh`, placed by
//! `flexmb_superelement::recovery::MeshRecovery`; this writer does not use
//! them yet and draws the chord), and beams extruded to their section.

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
}

/// VTK cell types used.
const VTK_VERTEX: u8 = 1;
const VTK_LINE: u8 = 3;

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

fn kind_code(type_name: &str) -> i32 {
    let t = type_name.to_ascii_lowercase();
    let table = [
        ("beam", 1),
        ("truss", 2),
        ("hinge", 3),
        ("superelement", 4),
        ("mass", 5),
        ("rigid", 6),
    ];
    table
        .iter()
        .find(|(k, _)| t.contains(k))
        .map_or(0, |&(_, c)| c)
}

/// The cells of a mechanism: (vtk type, node indices, element index).
fn cells(mech: &Mechanism) -> Vec<(u8, Vec<usize>, usize)> {
    // the node whose first position coordinate is each x index
    let mut node_of = vec![usize::MAX; mech.n_x()];
    for (k, n) in mech.nodes.iter().enumerate() {
        if let Some(&i) = n.position.first() {
            node_of[i] = k;
        }
    }
    let mut out = Vec::new();
    for (e, el) in mech.elements.iter().enumerate() {
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

/// Node positions from nodal coordinates `x` (3 components; z = 0 in a
/// planar mechanism).
fn positions(mech: &Mechanism, x: &[f64]) -> Vec<[f64; 3]> {
    mech.nodes
        .iter()
        .map(|n| std::array::from_fn(|d| n.position.get(d).map_or(0.0, |&i| x[i])))
        .collect()
}

fn reference(mech: &Mechanism) -> Vec<[f64; 3]> {
    mech.nodes
        .iter()
        .map(|n| std::array::from_fn(|d| n.at.get(d).copied().unwrap_or(0.0)))
        .collect()
}

fn data_array(
    out: &mut String,
    name: &str,
    ty: &str,
    comps: usize,
    values: impl Iterator<Item = String>,
) {
    let _ = write!(
        out,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"ascii\">\n          "
    );
    for v in values {
        out.push_str(&v);
        out.push(' ');
    }
    out.push_str("\n        </DataArray>\n");
}

/// The node vectors (one 3-vector per node, z = 0 in a planar mechanism)
/// of a vector `v` on the nodal coordinates: the node displacements of an
/// increment Δx, e.g. a mode shape in nodal coordinates (the orientation
/// coordinates are left out).
pub fn node_vectors(mech: &Mechanism, v: &[f64]) -> Result<Vec<[f64; 3]>, VtkError> {
    if v.len() != mech.n_x() {
        return Err(VtkError::Size {
            what: "the nodal vector".into(),
            got: v.len(),
            want: mech.n_x(),
        });
    }
    Ok(positions(mech, v))
}

/// The largest length of the 3-vectors `v` (0 for none).
pub fn largest_length(v: &[[f64; 3]]) -> f64 {
    v.iter()
        .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
        .fold(0.0, f64::max)
}

/// The VTU text of the mechanism at nodal coordinates `x`, with extra point
/// vectors `point_data` (name, one 3-vector per node).
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
    if x.len() != mech.n_x() {
        return Err(VtkError::Size {
            what: "x".into(),
            got: x.len(),
            want: mech.n_x(),
        });
    }
    let pts = positions(mech, x);
    let refs = reference(mech);
    let cells = cells(mech);
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <UnstructuredGrid>\n");
    if !fields.is_empty() {
        s.push_str("    <FieldData>\n");
        for (name, v) in fields {
            let _ = writeln!(
                s,
                "      <DataArray type=\"Float64\" Name=\"{name}\" NumberOfTuples=\"1\" format=\"ascii\">{v:e}</DataArray>"
            );
        }
        s.push_str("    </FieldData>\n");
    }
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        pts.len(),
        cells.len()
    );
    s.push_str("      <Points>\n");
    data_array(
        &mut s,
        "Points",
        "Float64",
        3,
        pts.iter()
            .map(|p| format!("{:e} {:e} {:e}", p[0], p[1], p[2])),
    );
    s.push_str("      </Points>\n      <Cells>\n");
    data_array(
        &mut s,
        "connectivity",
        "Int64",
        1,
        cells
            .iter()
            .flat_map(|(_, n, _)| n.iter().map(|k| k.to_string())),
    );
    let mut off = 0;
    data_array(
        &mut s,
        "offsets",
        "Int64",
        1,
        cells.iter().map(|(_, n, _)| {
            off += n.len();
            off.to_string()
        }),
    );
    data_array(
        &mut s,
        "types",
        "UInt8",
        1,
        cells.iter().map(|(t, _, _)| t.to_string()),
    );
    s.push_str("      </Cells>\n      <PointData>\n");
    data_array(
        &mut s,
        "displacement",
        "Float64",
        3,
        pts.iter()
            .zip(&refs)
            .map(|(p, r)| format!("{:e} {:e} {:e}", p[0] - r[0], p[1] - r[1], p[2] - r[2])),
    );
    for (name, v) in point_data {
        if v.len() != pts.len() {
            return Err(VtkError::Size {
                what: format!("point data '{name}'"),
                got: v.len(),
                want: pts.len(),
            });
        }
        data_array(
            &mut s,
            name,
            "Float64",
            3,
            v.iter()
                .map(|p| format!("{:e} {:e} {:e}", p[0], p[1], p[2])),
        );
    }
    s.push_str("      </PointData>\n      <CellData>\n");
    data_array(
        &mut s,
        "element",
        "Int64",
        1,
        cells.iter().map(|(_, _, e)| e.to_string()),
    );
    data_array(
        &mut s,
        "kind",
        "Int32",
        1,
        cells
            .iter()
            .map(|(_, _, e)| kind_code(mech.elements[*e].element.type_name()).to_string()),
    );
    data_array(
        &mut s,
        "axial_stiffness",
        "Float64",
        1,
        cells.iter().map(|(_, _, e)| {
            let el = &mech.elements[*e].element;
            let k = el.stiffness();
            let ea = match (el.reference_length(), k.nrows()) {
                (Some(l), n) if n > 0 => k[(0, 0)] * l,
                _ => 0.0,
            };
            format!("{ea:e}")
        }),
    );
    s.push_str("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    Ok(s)
}

/// A mode shape as `frames` configurations over one period: x0 + a sin(2πk/frames) Δx,
/// with the amplitude `a` chosen so that the largest node displacement is
/// `size` (m); the time value of frame k is its phase k/frames. Each frame
/// has the point data `mode_shape`, the node displacements of a Δx (largest
/// length `size`: ParaView's "warp by vector" with scale 1 shows the
/// extreme), and the field data `fields` (e.g. the frequency).
pub fn mode_frames(
    mech: &Mechanism,
    x0: &[f64],
    dx: &[f64],
    size: f64,
    frames: usize,
    fields: &[(&str, f64)],
) -> Result<Vec<(f64, String)>, VtkError> {
    if dx.len() != mech.n_x() {
        return Err(VtkError::Size {
            what: "the mode shape".into(),
            got: dx.len(),
            want: mech.n_x(),
        });
    }
    let d = positions(mech, dx);
    let max = largest_length(&d);
    let a = if max > 0.0 { size / max } else { 0.0 };
    let shape: Vec<[f64; 3]> = d.iter().map(|p| p.map(|c| a * c)).collect();
    (0..frames.max(1))
        .map(|k| {
            let phase = k as f64 / frames.max(1) as f64;
            let s = a * (2.0 * std::f64::consts::PI * phase).sin();
            let x: Vec<f64> = x0.iter().zip(dx).map(|(x, d)| x + s * d).collect();
            configuration_with_fields(mech, &x, &[("mode_shape", shape.clone())], fields)
                .map(|t| (phase, t))
        })
        .collect()
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
