//! ANSYS exports: the stiffness and mass matrices written by APDL Math
//! (`*EXPORT` in MMF, i.e. Matrix Market) or by `HBMAT` (Harwell–Boeing), the
//! map from equations to nodes, and the nodal coordinates (and, optionally,
//! the element list, for the mesh's volume and the sparsity check).
//!
//! * **K and M**: Matrix Market `coordinate real symmetric` (one triangle) or
//!   general, or Harwell–Boeing `RSA`/`RUA`; told apart by the first line.
//! * **The equation map**, either
//!   - the Matrix Market `array integer` DOF-mapping vector of APDL Math: the
//!     node number of each block of three equations (ux, uy, uz), in equation
//!     order, so it has a third as many entries as K has equations; or
//!   - the `.mapping` file of `HBMAT, …, Mapping=YES`: one line per equation,
//!     `equation node dof` with dof `UX`, `UY`, `UZ` (or 1, 2, 3); lines that
//!     do not start with an equation number (headers) are skipped.
//! * **Nodal coordinates**: `node x y z` per line, separated by tabs, blanks
//!   or semicolons, with a decimal point or a decimal comma (`-4,99e-016`,
//!   as a German-locale export writes them); lines that do not start with a
//!   node number (headers such as `Knotennummer`) are skipped. A line
//!   without blanks is read as comma-separated with decimal points.
//! * **Elements** (optional): `number type node…` per line, types `Hex8`,
//!   `Hex20`, `Tet4`, `Tet10`, `Wedge6`, `Wedge15` or `SOLID185` (hex8),
//!   `SOLID186` (hex20), `SOLID187` (tet10), `SOLID285` (tet4), whose node
//!   orders are those of the corresponding Abaqus/CalculiX elements.
//!
//! Only translations are read: a rotation in the `.mapping` file is an error
//! naming it. As with every matrix file, the units are not in the data: an
//! export in mm–t–s or from another material is set by the spec's `units`
//! and `stiffness_scale`.

use crate::geometry::SolidKind;
use crate::harwell_boeing::parse_harwell_boeing;
use crate::model::{FeModel, SolidElements, Sources};
use crate::readers::{check_not_cut_off, fname, model_from_parts, parse_matrix_market, read};
use crate::symmetric::assemble_upper;
use crate::Error;
use std::collections::HashMap;
use std::path::Path;

/// Matrix entries (row, column, value), 0-based, as stored.
pub type Entries = Vec<(usize, usize, f64)>;

/// The size and entries of a Matrix Market or Harwell–Boeing matrix file.
pub fn parse_matrix_file(text: &str, file: &str) -> Result<(usize, Entries), Error> {
    if text
        .trim_start()
        .to_ascii_lowercase()
        .starts_with("%%matrixmarket")
    {
        let a = parse_matrix_market(text, file)?;
        if a.nrows() != a.ncols() {
            return Err(Error::parse(
                file,
                1,
                format!("the matrix is {} × {}, not square", a.nrows(), a.ncols()),
            ));
        }
        let mut entries = Vec::with_capacity(a.val().len());
        for j in 0..a.ncols() {
            let range = a.as_ref().col_range(j);
            for p in range {
                entries.push((a.symbolic().row_idx()[p], j, a.val()[p]));
            }
        }
        Ok((a.nrows(), entries))
    } else {
        let m = parse_harwell_boeing(text, file)?;
        Ok((m.n, m.entries))
    }
}

/// A number with a decimal point or a decimal comma.
fn number(s: &str) -> Option<f64> {
    s.parse::<f64>()
        .ok()
        .or_else(|| s.replace(',', ".").parse().ok())
}

/// Parses an ANSYS nodal-coordinate listing (see the module documentation):
/// node labels and coordinates, in file order.
pub fn parse_nodes(text: &str, file: &str) -> Result<(Vec<u64>, Vec<[f64; 3]>), Error> {
    let (mut ids, mut coords) = (Vec::new(), Vec::new());
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        let mut f: Vec<&str> = t
            .split(['\t', ' ', ';'])
            .filter(|s| !s.is_empty())
            .collect();
        if f.len() == 1 {
            f = t
                .split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .collect();
        }
        let Some(Ok(id)) = f.first().map(|s| s.parse::<u64>()) else {
            continue;
        };
        if f.len() != 4 {
            return Err(Error::parse(
                file,
                ln + 1,
                format!("expected 'node x y z', got '{t}'"),
            ));
        }
        let mut x = [0.0; 3];
        for d in 0..3 {
            x[d] = number(f[1 + d]).ok_or_else(|| {
                Error::parse(file, ln + 1, format!("bad coordinate '{}'", f[1 + d]))
            })?;
        }
        ids.push(id);
        coords.push(x);
    }
    if ids.is_empty() {
        return Err(Error::parse(file, 0, "no 'node x y z' lines"));
    }
    Ok((ids, coords))
}

/// The (node, direction 0..3) of each of `n_eq` equations from a DOF-mapping
/// vector or a `.mapping` file (see the module documentation).
pub fn parse_mapping(text: &str, file: &str, n_eq: usize) -> Result<Vec<(u64, u8)>, Error> {
    check_not_cut_off(text, file)?;
    if text
        .trim_start()
        .to_ascii_lowercase()
        .starts_with("%%matrixmarket")
    {
        return mapping_vector(text, file, n_eq);
    }
    let mut out: Vec<Option<(u64, u8)>> = vec![None; n_eq];
    for (ln, line) in text.lines().enumerate() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let Some(Ok(eq)) = f.first().map(|s| s.parse::<usize>()) else {
            continue;
        };
        if f.len() < 3 {
            return Err(Error::parse(
                file,
                ln + 1,
                format!("expected 'equation node dof', got '{}'", line.trim()),
            ));
        }
        let node: u64 = f[1]
            .parse()
            .map_err(|_| Error::parse(file, ln + 1, format!("bad node '{}'", f[1])))?;
        let dir = match f[2].to_ascii_uppercase().as_str() {
            "UX" | "1" => 0,
            "UY" | "2" => 1,
            "UZ" | "3" => 2,
            other => {
                return Err(Error::parse(
                    file,
                    ln + 1,
                    format!(
                        "node {node} DOF {other}: only translations (UX, UY, UZ) are read; a part with rotations \
                         (shells, beams) or other fields cannot be built into a superelement from these matrices"
                    ),
                ))
            }
        };
        if eq == 0 || eq > n_eq {
            return Err(Error::Mismatch(format!(
                "{file}, line {}: equation {eq}, but the matrices have {n_eq} equations: {file} is from another model",
                ln + 1
            )));
        }
        if out[eq - 1].replace((node, dir)).is_some() {
            return Err(Error::parse(
                file,
                ln + 1,
                format!("equation {eq} is mapped twice"),
            ));
        }
    }
    let missing: Vec<String> = (0..n_eq)
        .filter(|&e| out[e].is_none())
        .take(8)
        .map(|e| (e + 1).to_string())
        .collect();
    if !missing.is_empty() {
        return Err(Error::Mismatch(format!(
            "{file} maps no node to equation(s) {} of the {n_eq}: it is from another model or cut off",
            missing.join(", ")
        )));
    }
    Ok(out.into_iter().flatten().collect())
}

fn mapping_vector(text: &str, file: &str, n_eq: usize) -> Result<Vec<(u64, u8)>, Error> {
    let mut data = text
        .lines()
        .enumerate()
        .skip(1)
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('%'));
    let (sl, size) = data
        .next()
        .ok_or_else(|| Error::parse(file, 0, "no size line"))?;
    let s: Vec<usize> = size
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    if s.len() != 2 || s[1] != 1 {
        return Err(Error::parse(
            file,
            sl + 1,
            format!("expected the size 'n 1' of a vector, got '{size}'"),
        ));
    }
    let nodes: Vec<u64> = data
        .map(|(ln, l)| {
            l.trim()
                .parse::<u64>()
                .map_err(|_| Error::parse(file, ln + 1, format!("bad node number '{}'", l.trim())))
        })
        .collect::<Result<_, _>>()?;
    if nodes.len() != s[0] {
        return Err(Error::truncated(
            file,
            text.lines().count(),
            format!(
                "the size line declares {} nodes, the file has {}",
                s[0],
                nodes.len()
            ),
        ));
    }
    if 3 * nodes.len() != n_eq {
        return Err(Error::Mismatch(format!(
            "{file} maps {} nodes, 3 equations each ({}), but the matrices have {n_eq} equations: {file} is from \
             another model",
            nodes.len(),
            3 * nodes.len()
        )));
    }
    Ok(nodes
        .iter()
        .flat_map(|&n| (0..3u8).map(move |d| (n, d)))
        .collect())
}

/// The solid kind of an ANSYS element type name.
fn element_kind(ty: &str) -> Option<SolidKind> {
    match ty.to_ascii_uppercase().as_str() {
        "HEX8" | "SOLID185" => Some(SolidKind::Hex8),
        "HEX20" | "SOLID186" => Some(SolidKind::Hex20),
        "TET4" | "SOLID285" => Some(SolidKind::Tet4),
        "TET10" | "SOLID187" => Some(SolidKind::Tet10),
        "WEDGE6" => Some(SolidKind::Wedge6),
        "WEDGE15" => Some(SolidKind::Wedge15),
        _ => None,
    }
}

/// Parses an element listing: (kind, node labels) of the solid elements;
/// other types are skipped, a wrong node count is an error.
pub fn parse_elements(text: &str, file: &str) -> Result<Vec<(SolidKind, Vec<u64>)>, Error> {
    let mut out = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let f: Vec<&str> = line
            .split(['\t', ' ', ';', ','])
            .filter(|s| !s.is_empty())
            .collect();
        if f.len() < 2 || f[0].parse::<u64>().is_err() {
            continue;
        }
        let Some(kind) = element_kind(f[1]) else {
            continue;
        };
        let nodes: Vec<u64> = f[2..]
            .iter()
            .map(|s| {
                s.parse()
                    .map_err(|_| Error::parse(file, ln + 1, format!("bad node '{s}'")))
            })
            .collect::<Result<_, _>>()?;
        if nodes.len() != kind.n_nodes() {
            return Err(Error::parse(
                file,
                ln + 1,
                format!(
                    "a {} element needs {} nodes, got {}",
                    f[1],
                    kind.n_nodes(),
                    nodes.len()
                ),
            ));
        }
        out.push((kind, nodes));
    }
    Ok(out)
}

/// Paths of an ANSYS export set.
#[derive(Clone, Copy, Debug)]
pub struct AnsysFiles<'a> {
    /// Stiffness (MMF or Harwell–Boeing).
    pub k: &'a Path,
    /// Mass (MMF or Harwell–Boeing).
    pub m: &'a Path,
    /// DOF-mapping vector or `.mapping` file.
    pub mapping: &'a Path,
    /// Nodal coordinates.
    pub nodes: &'a Path,
    /// Element listing, if any.
    pub elements: Option<&'a Path>,
}

/// Reads an ANSYS export set (see the module documentation) into a model.
pub fn read_ansys(name: &str, files: AnsysFiles<'_>) -> Result<FeModel, Error> {
    let (kf, mf, mapf, nf) = (
        fname(files.k),
        fname(files.m),
        fname(files.mapping),
        fname(files.nodes),
    );
    let elements = match files.elements {
        Some(p) => Some((read(p)?, fname(p))),
        None => None,
    };
    parse_ansys(
        name,
        [
            (&read(files.k)?, &kf),
            (&read(files.m)?, &mf),
            (&read(files.mapping)?, &mapf),
            (&read(files.nodes)?, &nf),
        ],
        elements.as_ref().map(|(t, f)| (t.as_str(), f.as_str())),
    )
}

/// [`read_ansys`] on texts: (text, file name) of K, M, the mapping and the
/// nodes, and of the elements if given.
pub fn parse_ansys(
    name: &str,
    [(k, kf), (m, mf), (map, mapf), (nodes, nf)]: [(&str, &str); 4],
    elements: Option<(&str, &str)>,
) -> Result<FeModel, Error> {
    let (nk, ke) = parse_matrix_file(k, kf)?;
    let (nm, me) = parse_matrix_file(m, mf)?;
    if nk != nm {
        return Err(Error::Mismatch(format!(
            "{kf} is {nk} × {nk} but {mf} is {nm} × {nm}: one of them is from another model (compare with {mapf})"
        )));
    }
    let dofs = parse_mapping(map, mapf, nk)?;
    let (ids, coords) = parse_nodes(nodes, nf)?;
    let describe = |e: usize| {
        let (n, d) = dofs[e];
        format!("node {n} {}", ["ux", "uy", "uz"][d as usize])
    };
    let kk = assemble_upper(nk, &ke, kf, &describe)?;
    let mm = assemble_upper(nk, &me, mf, &describe)?;
    let mut model = model_from_parts(name, ids, coords, &dofs, kk, mm, mapf)?;
    model.sources = Sources {
        k: kf.to_string(),
        m: mf.to_string(),
        dofs: mapf.to_string(),
        mesh: nf.to_string(),
    };
    if let Some((text, ef)) = elements {
        let list = parse_elements(text, ef)?;
        let index: HashMap<u64, usize> = model
            .node_ids()
            .iter()
            .enumerate()
            .map(|(i, &n)| (n, i))
            .collect();
        let mut solid = SolidElements {
            density_source: String::new(),
            ..Default::default()
        };
        let mut integrator = crate::geometry::Integrator::default();
        let mut volume = 0.0;
        for (kind, nodes) in list {
            let idx: Vec<usize> = nodes
                .iter()
                .map(|n| {
                    index.get(n).copied().ok_or_else(|| {
                        Error::Mismatch(format!("{ef}: node {n} of an element is not in {nf}"))
                    })
                })
                .collect::<Result<_, _>>()?;
            let x: Vec<[f64; 3]> = idx.iter().map(|&i| model.coords()[i]).collect();
            if let Some(mo) = integrator.moments(kind, &x, x[0]) {
                volume += mo.volume;
            }
            solid.kinds.push(kind);
            solid.nodes.push(idx);
            solid.density.push(None);
        }
        model.volume = Some(volume);
        model.solid = Some(solid);
    }
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_commas_tabs_and_german_headers_are_read() {
        let text = "Knotennummer\tX-Position (m)\tY-Position (m)\tZ-Position (m)\t\n1\t-4,996003611e-016\t0,15\t1,e-001\t\n7\t0,\t2\t-3,5\t\n";
        let (ids, x) = parse_nodes(text, "n.txt").unwrap();
        assert_eq!(ids, vec![1, 7]);
        assert_eq!(x[0], [-4.996003611e-16, 0.15, 0.1]);
        assert_eq!(x[1], [0.0, 2.0, -3.5]);
        // comma-separated with decimal points
        let (_, x) = parse_nodes("3,1.5,2.5,-1e-3\n", "n.csv").unwrap();
        assert_eq!(x[0], [1.5, 2.5, -1e-3]);
        let e = parse_nodes("1\t0,1\t0,2\n", "n.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected 'node x y z'"), "{e}");
    }

    #[test]
    fn both_mapping_files_give_the_equations_and_wrong_ones_are_named() {
        let vector = "%%MatrixMarket matrix array integer general\n% c\n2 1\n5\n3\n";
        assert_eq!(
            parse_mapping(vector, "map.txt", 6).unwrap(),
            vec![(5, 0), (5, 1), (5, 2), (3, 0), (3, 1), (3, 2)]
        );
        let e = parse_mapping(vector, "map.txt", 9).unwrap_err().to_string();
        assert!(e.contains("map.txt is from another model"), "{e}");
        let hb = " Matrix Eqn   Node   DOF\n      1        5     UX\n      2        5     UY\n      3        3     UZ\n";
        assert_eq!(
            parse_mapping(hb, "k.mapping", 3).unwrap(),
            vec![(5, 0), (5, 1), (3, 2)]
        );
        let e = parse_mapping(&hb.replace("UZ", "ROTZ"), "k.mapping", 3)
            .unwrap_err()
            .to_string();
        assert!(e.contains("node 3 DOF ROTZ"), "{e}");
        let e = parse_mapping(hb, "k.mapping", 4).unwrap_err().to_string();
        assert!(e.contains("equation(s) 4"), "{e}");
    }
}
