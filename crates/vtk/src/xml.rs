//! The VTU text (VTK XML unstructured grid, ASCII) of a drawn configuration.

use crate::Drawing;
use std::fmt::Write as _;

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

fn vector(p: &[f64; 3]) -> String {
    format!("{:e} {:e} {:e}", p[0], p[1], p[2])
}

/// The VTU text of `drawing` with its points at `pts`, point data (one
/// vector per point, checked by the caller) and field data.
pub(crate) fn unstructured_grid(
    drawing: &Drawing<'_>,
    pts: &[[f64; 3]],
    point_data: &[(&str, Vec<[f64; 3]>)],
    fields: &[(&str, f64)],
) -> String {
    let mech = drawing.mech;
    let cells = drawing.cells();
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
    data_array(&mut s, "Points", "Float64", 3, pts.iter().map(vector));
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
            .zip(&drawing.reference)
            .map(|(p, r)| vector(&std::array::from_fn(|d| p[d] - r[d]))),
    );
    for (name, v) in point_data {
        data_array(&mut s, name, "Float64", 3, v.iter().map(vector));
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
    let section = |e: usize| {
        mech.elements[e]
            .section
            .as_ref()
            .map(|b| (b.code_and_dimensions(), b.area()))
    };
    data_array(
        &mut s,
        "section_shape",
        "Int32",
        1,
        cells
            .iter()
            .map(|(_, _, e)| section(*e).map_or(0, |((c, _), _)| c).to_string()),
    );
    data_array(
        &mut s,
        "section_dimensions",
        "Float64",
        3,
        cells
            .iter()
            .map(|(_, _, e)| vector(&section(*e).map_or([0.0; 3], |((_, d), _)| d))),
    );
    data_array(
        &mut s,
        "section_area",
        "Float64",
        1,
        cells
            .iter()
            .map(|(_, _, e)| format!("{:e}", section(*e).map_or(0.0, |(_, a)| a))),
    );
    s.push_str("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    s
}
