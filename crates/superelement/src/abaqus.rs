//! Abaqus `*MATRIX GENERATE` / `*MATRIX OUTPUT` exports: the stiffness and
//! mass `.mtx` files with the `.inp` deck for the nodes, elements, sets and
//! densities.
//!
//! The three formats of `*MATRIX OUTPUT` (Abaqus Keywords Reference) are read
//! and told apart by their data lines:
//!
//! * `FORMAT=COORDINATE`: `row col value` per line, 1-based equation numbers,
//!   both triangles. The equations are node-major and direction-minor over the
//!   nodes of the mesh in label order (nodes of solid elements; all nodes if
//!   the deck has no solid element), three translations each, so the equation
//!   count must be three times the node count; otherwise the file does not
//!   say which equation is which and the error asks for `FORMAT=LABELS`.
//! * `FORMAT=MATRIX INPUT` (the default) and `FORMAT=LABELS`:
//!   `row node, row dof, column node, column dof, value`, one triangle (both
//!   are accepted), a node given by its label or as `INSTANCE.LABEL`. The
//!   equations are the (node, dof) pairs that occur, ordered by node label and
//!   direction.
//!
//! Only translations (dof 1–3) of nodes in the mesh are accepted: a rotation
//! (dof 4–6, shells or beams) or an internal node (a negative label, or a
//! label not in the deck: the Lagrange multipliers and reference nodes of
//! constraints) is an error naming it. The matrices carry no units: a deck in
//! mm–t–s, or a stiffness from another material, is set by the spec's `units`
//! and `stiffness_scale` (see [`crate::units`]).

use crate::model::{FeModel, Sources};
use crate::readers::{
    check_not_cut_off, fname, model_from_parts, node_sets, parse_f64, read, read_inp,
    solid_elements,
};
use crate::readers::{parse_inp, InpMesh};
use crate::symmetric::assemble_upper;
use crate::Error;
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

/// How an Abaqus matrix file numbers its entries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AbaqusFormat {
    /// `row col value` (equation numbers).
    Coordinate,
    /// `node, dof, node, dof, value` (`MATRIX INPUT` or `LABELS`).
    NodeDof,
}

/// A (node label, direction 0..3) pair: one equation.
type NodeDir = (u64, u8);

/// One matrix file, parsed but not yet numbered.
#[derive(Debug)]
struct Parsed {
    format: AbaqusFormat,
    /// Coordinate: (row, col, value), 0-based equations.
    coordinate: Vec<(usize, usize, f64)>,
    /// Node-dof: ((node, dir), (node, dir), value), dir 0..3.
    node_dof: Vec<(NodeDir, NodeDir, f64)>,
}

/// A node field: `12`, `-3` or `PART-1.12`. Negative labels are internal
/// nodes; they are returned as `Err(label)` for the error message.
fn node_field(s: &str, file: &str, line: usize) -> Result<Result<u64, String>, Error> {
    let label = s.rsplit_once('.').map(|(_, l)| l).unwrap_or(s).trim();
    match label.parse::<i64>() {
        Ok(v) if v > 0 => Ok(Ok(v as u64)),
        Ok(_) => Ok(Err(s.to_string())),
        Err(_) => Err(Error::parse(file, line, format!("bad node '{s}'"))),
    }
}

fn dof_field(s: &str, node: &str, file: &str, line: usize) -> Result<u8, Error> {
    match s.trim().parse::<u8>() {
        Ok(d @ 1..=3) => Ok(d - 1),
        Ok(d @ 4..=6) => Err(Error::parse(
            file,
            line,
            format!(
                "node {node} dof {d} is a rotation: only solid (translational) DOFs are read; a part with shells \
                 or beams cannot be built into a superelement from these matrices"
            ),
        )),
        _ => Err(Error::parse(
            file,
            line,
            format!("node {node}: '{s}' is not a displacement DOF (1, 2 or 3)"),
        )),
    }
}

fn parse_matrix(text: &str, file: &str) -> Result<Parsed, Error> {
    check_not_cut_off(text, file)?;
    let mut out = Parsed {
        format: AbaqusFormat::Coordinate,
        coordinate: Vec::new(),
        node_dof: Vec::new(),
    };
    let mut format: Option<AbaqusFormat> = None;
    let mut internal: Vec<String> = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('*') {
            continue;
        }
        let f: Vec<&str> = t
            .split([',', ' ', '\t'])
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect();
        let this = match f.len() {
            3 => AbaqusFormat::Coordinate,
            5 => AbaqusFormat::NodeDof,
            _ => {
                return Err(Error::parse(
                    file,
                    ln + 1,
                    format!(
                        "expected 'row col value' (FORMAT=COORDINATE) or 'node, dof, node, dof, value' (FORMAT=MATRIX \
                         INPUT or LABELS), got '{t}'"
                    ),
                ))
            }
        };
        match format {
            None => format = Some(this),
            Some(f0) if f0 != this => {
                return Err(Error::parse(
                    file,
                    ln + 1,
                    format!("'{t}' is in another format than the lines before it"),
                ))
            }
            _ => {}
        }
        let value = parse_f64(f[f.len() - 1])
            .ok_or_else(|| Error::parse(file, ln + 1, format!("bad value '{}'", f[f.len() - 1])))?;
        match this {
            AbaqusFormat::Coordinate => {
                let idx = |s: &str| {
                    s.parse::<usize>().ok().filter(|&i| i > 0).ok_or_else(|| {
                        Error::parse(file, ln + 1, format!("bad equation number '{s}'"))
                    })
                };
                out.coordinate.push((idx(f[0])? - 1, idx(f[1])? - 1, value));
            }
            AbaqusFormat::NodeDof => {
                let (a, b) = (
                    node_field(f[0], file, ln + 1)?,
                    node_field(f[2], file, ln + 1)?,
                );
                match (a, b) {
                    (Ok(a), Ok(b)) => {
                        let da = dof_field(f[1], f[0], file, ln + 1)?;
                        let db = dof_field(f[3], f[2], file, ln + 1)?;
                        out.node_dof.push(((a, da), (b, db), value));
                    }
                    (Err(x), _) | (_, Err(x)) => {
                        if internal.len() < 8 && !internal.contains(&x) {
                            internal.push(x);
                        }
                    }
                }
            }
        }
    }
    if !internal.is_empty() {
        return Err(internal_nodes(file, &internal));
    }
    out.format = format.ok_or_else(|| Error::parse(file, 0, "no matrix entries"))?;
    Ok(out)
}

fn internal_nodes(file: &str, labels: &[String]) -> Error {
    Error::parse(
        file,
        0,
        format!(
            "internal node(s) {} (negative or not in the deck): the Lagrange multipliers or reference nodes of \
             constraints (*TIE, *MPC, *COUPLING, *RIGID BODY, …) are in the matrix; export the part's matrices \
             without those constraints",
            labels.join(", ")
        ),
    )
}

/// The model from an Abaqus deck (`inp`, with `*INCLUDE`s) and its stiffness
/// and mass `.mtx` exports, in any of the three formats (both files in the
/// same). Returns the model and the mesh.
pub fn read_abaqus(inp: &Path, k: &Path, m: &Path) -> Result<(FeModel, InpMesh), Error> {
    let mesh = read_inp(inp)?;
    let name = inp
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    abaqus_from_mesh(
        [(&read(k)?, &fname(k)), (&read(m)?, &fname(m))],
        mesh,
        &fname(inp),
        &name,
    )
}

/// [`read_abaqus`] on text (the deck may not `*INCLUDE`).
pub fn parse_abaqus(inp: &str, k: &str, m: &str, name: &str) -> Result<(FeModel, InpMesh), Error> {
    let deck = format!("{name}.inp");
    let mesh = parse_inp(inp, &deck)?;
    abaqus_from_mesh(
        [
            (k, &format!("{name}_STIF.mtx")),
            (m, &format!("{name}_MASS.mtx")),
        ],
        mesh,
        &deck,
        name,
    )
}

fn abaqus_from_mesh(
    [(k_text, k_name), (m_text, m_name)]: [(&str, &str); 2],
    mesh: InpMesh,
    deck: &str,
    name: &str,
) -> Result<(FeModel, InpMesh), Error> {
    let k = parse_matrix(k_text, k_name)?;
    let m = parse_matrix(m_text, m_name)?;
    if k.format != m.format {
        return Err(Error::Mismatch(format!(
            "{k_name} is in {:?} format and {m_name} in {:?}: export both with the same FORMAT",
            k.format, m.format
        )));
    }
    // the mesh's nodes: those of solid elements (all if there are none), by label
    let in_elements: BTreeSet<u64> = mesh
        .elements
        .iter()
        .flat_map(|(_, n)| n.iter().copied())
        .collect();
    let coords_of: HashMap<u64, [f64; 3]> = mesh
        .ids
        .iter()
        .copied()
        .zip(mesh.coords.iter().copied())
        .collect();
    let mesh_nodes: Vec<u64> = if in_elements.is_empty() {
        mesh.ids
            .iter()
            .copied()
            .collect::<BTreeSet<u64>>()
            .into_iter()
            .collect()
    } else {
        in_elements.into_iter().collect()
    };
    let (dofs, k_entries, m_entries): (Vec<(u64, u8)>, _, _) = match k.format {
        AbaqusFormat::Coordinate => {
            let n_of = |p: &Parsed| {
                p.coordinate
                    .iter()
                    .map(|&(i, j, _)| i.max(j) + 1)
                    .max()
                    .unwrap_or(0)
            };
            let (nk, nm, want) = (n_of(&k), n_of(&m), 3 * mesh_nodes.len());
            if nk != want || nm != want {
                let culprit = match (nk == want, nm == want) {
                    (true, false) => format!("{m_name} has {nm} equations, {k_name} {nk}: {m_name} is from another model"),
                    (false, true) => format!("{k_name} has {nk} equations, {m_name} {nm}: {k_name} is from another model"),
                    _ => format!("{k_name} has {nk} equations and {m_name} {nm}"),
                };
                return Err(Error::Mismatch(format!(
                    "{culprit}, but {deck} has {} nodes in its solid elements, which with 3 translations each make \
                     {want} equations. FORMAT=COORDINATE does not say which equation is which node; if the matrices \
                     come from another deck, or the model has constraints or DOFs other than solid translations, \
                     export them with FORMAT=LABELS",
                    mesh_nodes.len()
                )));
            }
            let dofs = mesh_nodes
                .iter()
                .flat_map(|&n| (0..3u8).map(move |d| (n, d)))
                .collect();
            (dofs, k.coordinate, m.coordinate)
        }
        AbaqusFormat::NodeDof => {
            let mut pairs: BTreeSet<(u64, u8)> = BTreeSet::new();
            for p in [&k, &m] {
                for &(a, b, _) in &p.node_dof {
                    pairs.insert(a);
                    pairs.insert(b);
                }
            }
            let missing: Vec<String> = pairs
                .iter()
                .map(|&(n, _)| n)
                .collect::<BTreeSet<u64>>()
                .into_iter()
                .filter(|n| !coords_of.contains_key(n))
                .take(8)
                .map(|n| n.to_string())
                .collect();
            if !missing.is_empty() {
                let file = if k.node_dof.iter().any(|&((a, _), (b, _), _)| {
                    missing.contains(&a.to_string()) || missing.contains(&b.to_string())
                }) {
                    k_name
                } else {
                    m_name
                };
                return Err(internal_nodes(file, &missing));
            }
            let dofs: Vec<(u64, u8)> = pairs.into_iter().collect();
            let eq: HashMap<(u64, u8), usize> =
                dofs.iter().enumerate().map(|(e, &p)| (p, e)).collect();
            let number = |p: &Parsed| {
                p.node_dof
                    .iter()
                    .map(|&(a, b, v)| (eq[&a], eq[&b], v))
                    .collect::<Vec<_>>()
            };
            (dofs.clone(), number(&k), number(&m))
        }
    };
    let describe = |e: usize| {
        let (n, d) = dofs[e];
        format!("node {n} {}", ["ux", "uy", "uz"][d as usize])
    };
    let n = dofs.len();
    let kk = assemble_upper(n, &k_entries, k_name, &describe)?;
    let mm = assemble_upper(n, &m_entries, m_name, &describe)?;
    // the nodes that have equations or belong to elements, in label order
    let used: BTreeSet<u64> = dofs
        .iter()
        .map(|&(n, _)| n)
        .chain(mesh_nodes.iter().copied())
        .collect();
    let (ids, coords): (Vec<u64>, Vec<[f64; 3]>) =
        used.iter().map(|&id| (id, coords_of[&id])).unzip();
    let mut model = model_from_parts(name, ids, coords, &dofs, kk, mm, k_name)?;
    model.volume = mesh.volume();
    model.sources = Sources {
        k: k_name.to_string(),
        m: m_name.to_string(),
        dofs: format!("the equation order of {k_name}"),
        mesh: deck.to_string(),
    };
    model.solid = Some(solid_elements(&model, &mesh, deck));
    model.node_sets = node_sets(&model, &mesh);
    Ok((model, mesh))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two C3D4 tetrahedra sharing a face (5 nodes, 15 equations).
    const DECK: &str = "*Heading\n*Part, name=p\n*End Part\n*Assembly, name=A\n*Instance, name=p-1, part=p\n*Node\n\
        1, 0., 0., 0.\n2, 1., 0., 0.\n3, 0., 1., 0.\n4, 0., 0., 1.\n5, 1., 1., 1.\n\
        *Element, type=C3D4\n1, 1, 2, 3, 4\n2, 2, 3, 4, 5\n*End Instance\n*End Assembly\n";

    #[test]
    fn a_rotation_an_internal_node_and_a_mixed_file_are_named() {
        let k = "1, 4, 1, 4, 1.0\n";
        let e = parse_matrix(k, "k.mtx").unwrap_err().to_string();
        assert!(e.contains("node 1 dof 4 is a rotation"), "{e}");
        let k = "1, 1, 1, 1, 1.0\n-7, 1, -7, 1, 1.0\n";
        let e = parse_matrix(k, "k.mtx").unwrap_err().to_string();
        assert!(e.contains("internal node(s) -7"), "{e}");
        let k = "1 1 1.0\n1, 1, 1, 1, 1.0\n";
        let e = parse_matrix(k, "k.mtx").unwrap_err().to_string();
        assert!(e.contains("another format") && e.contains("k.mtx:2"), "{e}");
        let e = parse_matrix("1 1 1.0", "k.mtx").unwrap_err().to_string();
        assert!(e.contains("cut off"), "{e}");
    }

    #[test]
    fn coordinate_and_node_dof_files_of_one_matrix_give_one_model() {
        // a symmetric 15 × 15 pattern: a diagonal and couplings between nodes
        let mut coord = String::new();
        let mut labels = String::new();
        for i in 0..15usize {
            for j in 0..15usize {
                let v = if i == j {
                    10.0 + i as f64
                } else if (i + j) % 4 == 0 {
                    -0.5 - (i * j) as f64 * 0.01
                } else {
                    0.0
                };
                if v != 0.0 {
                    coord.push_str(&format!("{} {} {v:e}\n", i + 1, j + 1));
                    if i >= j {
                        labels.push_str(&format!(
                            "P-1.{}, {}, P-1.{}, {}, {v:e}\n",
                            i / 3 + 1,
                            i % 3 + 1,
                            j / 3 + 1,
                            j % 3 + 1
                        ));
                    }
                }
            }
        }
        let (a, _) = parse_abaqus(DECK, &coord, &coord, "t").unwrap();
        let (b, _) = parse_abaqus(DECK, &labels, &labels, "t").unwrap();
        assert_eq!(a.n_eq(), 15);
        assert_eq!(a.node_ids(), b.node_ids());
        assert_eq!(a.k().val(), b.k().val());
        assert_eq!(a.k().symbolic().row_idx(), b.k().symbolic().row_idx());
        // a COORDINATE file with one equation too few is from another model
        let short: String = coord
            .lines()
            .filter(|l| !l.starts_with("15 ") && !l.contains(" 15 "))
            .map(|l| format!("{l}\n"))
            .collect();
        let e = parse_abaqus(DECK, &short, &coord, "t")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t_STIF.mtx has 14 equations") && e.contains("FORMAT=LABELS"),
            "{e}"
        );
        // node 9 is not in the deck
        let e = parse_abaqus(DECK, &format!("{labels}9, 1, 9, 1, 1.0\n"), &labels, "t")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("internal node(s) 9") && e.contains("t_STIF.mtx"),
            "{e}"
        );
    }

    #[test]
    fn a_moved_instance_and_two_meshed_instances_are_refused() {
        let moved = DECK.replace(
            "*Instance, name=p-1, part=p\n",
            "*Instance, name=p-1, part=p\n 0., 0., 0.1\n",
        );
        let e = parse_inp(&moved, "d.inp").unwrap_err().to_string();
        assert!(e.contains("P-1 is positioned by a translation"), "{e}");
        let unmoved = DECK.replace(
            "*Instance, name=p-1, part=p\n",
            "*Instance, name=p-1, part=p\n 0., 0., 0.\n",
        );
        assert!(parse_inp(&unmoved, "d.inp").is_ok());
        let two = DECK.replace(
            "*End Assembly",
            "*Instance, name=p-2, part=p\n*Node\n1, 5., 0., 0.\n*End Instance\n*End Assembly",
        );
        let e = parse_inp(&two, "d.inp").unwrap_err().to_string();
        assert!(e.contains("2 instances (P-1, P-2)"), "{e}");
    }
}
