//! Solid meshes from files, for the built-in FE and for CalculiX run by the
//! builder (`ModelSource::Mesh` of a spec, the one-command build of
//! [`crate::from_mesh`]):
//!
//! * gmsh `.msh`, ASCII, format 4.1 (gmsh 4's default) or 2.2: nodes, the
//!   volume elements (4- and 10-node tetrahedra, 8- and 20-node hexahedra,
//!   6- and 15-node wedges) turned into the Abaqus/CalculiX node order, and
//!   the physical groups as named node sets;
//! * a gmsh `.geo` script, meshed by `gmsh` with second-order elements
//!   ([`mesh_geo`]) into a `.msh`;
//! * an Abaqus/CalculiX `.inp` mesh ([`crate::readers::read_inp`]): its
//!   solid elements and *NSET.
//!
//! [`run_calculix`] writes a CalculiX deck of a mesh and a material, runs
//! `ccx` for its stiffness and mass (`*FREQUENCY, SOLVER=MATRIXSTORAGE`)
//! and reads them back.

use crate::geometry::SolidKind;
use crate::model::{FeModel, NodeSet};
use crate::readers::{read_calculix, read_inp};
use crate::solid::SolidMesh;
use crate::Error;
use flexmb_element::Material;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A group of nodes of a mesh file (a gmsh physical group, an *NSET).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshGroup {
    /// Its name; an unnamed gmsh physical group is called by its tag.
    pub name: String,
    /// "physical surface", "physical volume", "node set", ….
    pub what: String,
    /// The gmsh physical tag.
    pub tag: Option<i64>,
    /// Node indices into [`MeshFile::coords`], sorted.
    pub nodes: Vec<usize>,
}

/// A solid mesh read from a file.
#[derive(Clone, Debug, Default)]
pub struct MeshFile {
    /// Node labels (the file's node tags).
    pub ids: Vec<u64>,
    /// Node coordinates (m). Only nodes of solid elements are kept.
    pub coords: Vec<[f64; 3]>,
    /// Element kinds.
    pub kinds: Vec<SolidKind>,
    /// Element nodes (indices into `coords`) in the Abaqus/CalculiX order.
    pub elements: Vec<Vec<usize>>,
    /// Element labels.
    pub element_ids: Vec<u64>,
    /// Named node groups, sorted by name.
    pub groups: Vec<MeshGroup>,
    /// The files read.
    pub files: Vec<PathBuf>,
}

/// An isotropic linear-elastic material of a mesh (SI units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshMaterial {
    /// Young's modulus E (Pa).
    pub e: f64,
    /// Poisson's ratio ν.
    pub nu: f64,
    /// Density ρ (kg/m³).
    pub rho: f64,
}

/// The materials known by name to `--material` (the thesis's steel of
/// §2.5 and §3.5, E = 2.1e11 Pa, G = 8.0e10 Pa, ρ = 7800 kg/m³, and common
/// aluminium and titanium alloys).
pub const NAMED_MATERIALS: [(&str, MeshMaterial); 3] = [
    (
        "steel",
        MeshMaterial {
            e: 2.1e11,
            nu: 0.3125,
            rho: 7800.0,
        },
    ),
    (
        "aluminium",
        MeshMaterial {
            e: 7.0e10,
            nu: 0.33,
            rho: 2700.0,
        },
    ),
    (
        "titanium",
        MeshMaterial {
            e: 1.14e11,
            nu: 0.34,
            rho: 4430.0,
        },
    ),
];

impl MeshMaterial {
    /// A named material of [`NAMED_MATERIALS`] (`aluminum` is `aluminium`).
    pub fn named(name: &str) -> Result<Self, Error> {
        let key = name
            .trim()
            .to_ascii_lowercase()
            .replace("aluminum", "aluminium");
        NAMED_MATERIALS
            .iter()
            .find(|(n, _)| *n == key)
            .map(|(_, m)| *m)
            .ok_or_else(|| {
                let names: Vec<&str> = NAMED_MATERIALS.iter().map(|(n, _)| *n).collect();
                Error::Spec(format!(
                    "unknown material '{name}': the named ones are {}, or give E=…,nu=…,rho=… in SI units",
                    names.join(", ")
                ))
            })
    }

    /// The element library's material (G = E / (2 (1 + ν))), checked: E
    /// positive, ν in (−1, 0.5), ρ positive, all finite.
    pub fn material(&self) -> Result<Material, Error> {
        let ok = self.e > 0.0
            && self.e.is_finite()
            && self.nu > -1.0
            && self.nu < 0.5
            && self.rho > 0.0
            && self.rho.is_finite();
        if !ok {
            return Err(Error::Spec(format!(
                "material E = {} Pa, ν = {}, ρ = {} kg/m³: E and ρ must be positive and finite and ν in (−1, 0.5)",
                self.e, self.nu, self.rho
            )));
        }
        Ok(Material::from_poisson(self.e, self.nu, self.rho))
    }
}

impl MeshFile {
    /// Reads a `.msh` or `.inp` mesh (by extension); a `.geo` is meshed
    /// first by [`mesh_geo`] into `geo_out`.
    pub fn read(path: &Path, geo_out: &Path) -> Result<Self, Error> {
        match extension(path).as_str() {
            "msh" => read_msh(path),
            "inp" => from_inp(path),
            "geo" => {
                mesh_geo(path, geo_out)?;
                let mut m = read_msh(geo_out)?;
                m.files.insert(0, path.to_path_buf());
                Ok(m)
            }
            _ => Err(Error::Spec(format!(
                "{}: a mesh must be a gmsh .msh or .geo or an Abaqus/CalculiX .inp file",
                path.display()
            ))),
        }
    }

    /// The mesh with one material for every element, for the built-in FE.
    pub fn solid_mesh(&self, material: Material) -> SolidMesh {
        SolidMesh {
            ids: self.ids.clone(),
            coords: self.coords.clone(),
            kinds: self.kinds.clone(),
            elements: self.elements.clone(),
            element_ids: self.element_ids.clone(),
            element_material: vec![0; self.elements.len()],
            materials: vec![material],
        }
    }

    /// The groups as node sets of `model` (matched by node label).
    pub fn node_sets(&self, model: &FeModel) -> Vec<NodeSet> {
        self.groups
            .iter()
            .map(|g| {
                let mut nodes: Vec<usize> = g
                    .nodes
                    .iter()
                    .filter_map(|&i| model.node_index(self.ids[i]))
                    .collect();
                nodes.sort_unstable();
                NodeSet {
                    name: g.name.clone(),
                    what: g.what.clone(),
                    tag: g.tag,
                    nodes,
                }
            })
            .collect()
    }

    /// Counts of the element kinds, e.g. "1204 Tet10".
    pub fn describe_elements(&self) -> String {
        let mut count: BTreeMap<String, usize> = BTreeMap::new();
        for k in &self.kinds {
            *count.entry(format!("{k:?}")).or_insert(0) += 1;
        }
        count
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

fn display(path: &Path) -> String {
    path.display().to_string()
}

/// The edges (pairs of corners) of an element's midside nodes, in their order.
type Edges = &'static [(usize, usize)];

/// The gmsh element types of volume elements: (type, kind, gmsh's edges of
/// the midside nodes in their order).
const GMSH_VOLUMES: [(u32, SolidKind, Edges); 6] = [
    (4, SolidKind::Tet4, &[]),
    (
        11,
        SolidKind::Tet10,
        &[(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)],
    ),
    (5, SolidKind::Hex8, &[]),
    (
        17,
        SolidKind::Hex20,
        &[
            (0, 1),
            (0, 3),
            (0, 4),
            (1, 2),
            (1, 5),
            (2, 3),
            (2, 6),
            (3, 7),
            (4, 5),
            (4, 7),
            (5, 6),
            (6, 7),
        ],
    ),
    (6, SolidKind::Wedge6, &[]),
    (
        18,
        SolidKind::Wedge15,
        &[
            (0, 1),
            (0, 2),
            (0, 3),
            (1, 2),
            (1, 4),
            (2, 5),
            (3, 4),
            (3, 5),
            (4, 5),
        ],
    ),
];

/// Volume element types gmsh writes that the builder has no element for,
/// with what to do instead.
const GMSH_UNSUPPORTED: [(u32, &str); 7] = [
    (
        12,
        "27-node hexahedra: mesh with Mesh.SecondOrderIncomplete = 1 (20-node hexahedra)",
    ),
    (
        13,
        "18-node wedges: mesh with Mesh.SecondOrderIncomplete = 1 (15-node wedges)",
    ),
    (
        7,
        "5-node pyramids: mesh without pyramids (tetrahedra only, or hexahedra only)",
    ),
    (14, "14-node pyramids: mesh without pyramids"),
    (19, "13-node pyramids: mesh without pyramids"),
    (
        29,
        "20-node tetrahedra: mesh with second-order elements (-order 2)",
    ),
    (
        92,
        "64-node hexahedra: mesh with second-order elements (-order 2)",
    ),
];

/// The permutation taking gmsh's node order of a volume element to the
/// Abaqus/CalculiX one: node k of Abaqus is node `perm[k]` of gmsh. The
/// corners are in the same order in both; the midside nodes are matched
/// by their edges.
fn gmsh_to_abaqus(kind: SolidKind, gmsh_edges: &[(usize, usize)]) -> Vec<usize> {
    let corners = kind.n_nodes() - gmsh_edges.len();
    let mut perm: Vec<usize> = (0..corners).collect();
    for &(a, b) in kind.midside_edges() {
        let j = gmsh_edges
            .iter()
            .position(|&(c, d)| (c, d) == (a, b) || (c, d) == (b, a))
            .expect("every Abaqus edge is a gmsh edge");
        perm.push(corners + j);
    }
    perm
}

/// An element of a `.msh` file: tag, gmsh type, node tags, physical groups
/// (dimension, tag).
type RawElement = (u64, u32, Vec<u64>, Vec<(u8, i64)>);

/// A section of a `.msh` file: its name and its lines with their numbers.
type Section<'a> = (&'a str, Vec<(usize, &'a str)>);

/// What a `.msh` file holds before the nodes of solid elements are picked.
#[derive(Default)]
struct RawMsh {
    nodes: HashMap<u64, [f64; 3]>,
    node_order: Vec<u64>,
    elements: Vec<RawElement>,
    names: HashMap<(u8, i64), String>,
}

/// Reads a gmsh `.msh` file (ASCII, format 4.1 or 2.2).
pub fn read_msh(path: &Path) -> Result<MeshFile, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let file = display(path);
    let text = String::from_utf8_lossy(&bytes);
    let raw = parse_msh(&text, &file)?;
    let mut mesh = solid_from_raw(raw, &file)?;
    mesh.files.push(path.to_path_buf());
    Ok(mesh)
}

/// A reader of whitespace-separated tokens with their line numbers.
struct Tokens<'a> {
    lines: Vec<(usize, &'a str)>,
    line: usize,
    toks: std::collections::VecDeque<&'a str>,
    file: &'a str,
}

impl<'a> Tokens<'a> {
    fn new(lines: Vec<(usize, &'a str)>, file: &'a str) -> Self {
        Self {
            lines,
            line: 0,
            toks: Default::default(),
            file,
        }
    }
    fn line_no(&self) -> usize {
        self.lines
            .get(self.line.saturating_sub(1))
            .map_or(0, |l| l.0)
    }
    fn next(&mut self) -> Result<&'a str, Error> {
        while self.toks.is_empty() {
            let Some(&(_, l)) = self.lines.get(self.line) else {
                return Err(Error::truncated(
                    self.file,
                    self.lines.last().map_or(0, |l| l.0),
                    "the section ends before its data",
                ));
            };
            self.line += 1;
            self.toks = l.split_whitespace().collect();
        }
        Ok(self.toks.pop_front().expect("not empty"))
    }
    fn num<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, Error> {
        let t = self.next()?;
        t.parse().map_err(|_| {
            Error::parse(
                self.file,
                self.line_no(),
                format!("{what}: '{t}' is not a number"),
            )
        })
    }
    fn rest_of_line(&mut self) -> Vec<&'a str> {
        self.toks.drain(..).collect()
    }
}

/// The sections `$Name … $EndName` of a `.msh` text with their lines.
fn msh_sections<'a>(text: &'a str, file: &str) -> Result<Vec<Section<'a>>, Error> {
    let mut out: Vec<Section<'a>> = Vec::new();
    let mut open: Option<(&str, usize)> = None;
    for (i, l) in text.lines().enumerate() {
        let t = l.trim();
        if let Some(name) = t.strip_prefix('$') {
            match open {
                None => {
                    open = Some((name, i + 1));
                    out.push((name, Vec::new()));
                }
                Some((o, _)) if name == format!("End{o}") => open = None,
                Some((o, line)) => {
                    return Err(Error::parse(
                        file,
                        i + 1,
                        format!("${o} (line {line}) is not closed before ${name}"),
                    ))
                }
            }
        } else if open.is_some() && !t.is_empty() {
            out.last_mut().expect("open").1.push((i + 1, t));
        }
    }
    if let Some((o, line)) = open {
        return Err(Error::truncated(
            file,
            line,
            format!("${o} has no $End{o}: the file is cut off"),
        ));
    }
    Ok(out)
}

fn parse_msh(text: &str, file: &str) -> Result<RawMsh, Error> {
    let sections = msh_sections(text, file)?;
    let Some((_, fmt)) = sections.iter().find(|(n, _)| *n == "MeshFormat") else {
        return Err(Error::parse(
            file,
            1,
            "no $MeshFormat section: not a gmsh .msh file",
        ));
    };
    let head: Vec<&str> = fmt
        .first()
        .map(|l| l.1.split_whitespace().collect())
        .unwrap_or_default();
    let (version, binary) = match head.as_slice() {
        [v, t, ..] => (v.to_string(), *t != "0"),
        _ => (String::new(), false),
    };
    if binary {
        return Err(Error::parse(
            file,
            fmt[0].0,
            "a binary .msh file: save it as ASCII (gmsh option Mesh.Binary = 0, the default)",
        ));
    }
    let v4 = version.starts_with("4.1");
    if !v4 && !version.starts_with("2.") {
        return Err(Error::parse(
            file,
            fmt.first().map_or(1, |l| l.0),
            format!("MSH format {version}: flexmb reads 4.1 and 2.2 (gmsh -format msh41 or msh22)"),
        ));
    }
    let mut raw = RawMsh::default();
    let get = |name: &str| {
        sections
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, l)| l.clone())
    };
    if let Some(lines) = get("PhysicalNames") {
        let mut t = Tokens::new(lines, file);
        let n: usize = t.num("number of physical names")?;
        for _ in 0..n {
            let dim: u8 = t.num("physical dimension")?;
            let tag: i64 = t.num("physical tag")?;
            let rest = t.rest_of_line().join(" ");
            raw.names
                .insert((dim, tag), rest.trim().trim_matches('"').to_string());
        }
    }
    let Some(node_lines) = get("Nodes") else {
        return Err(Error::parse(file, 0, "no $Nodes section"));
    };
    let Some(element_lines) = get("Elements") else {
        return Err(Error::parse(file, 0, "no $Elements section"));
    };
    if v4 {
        let entities = match get("Entities") {
            Some(l) => entity_groups(l, file)?,
            None => HashMap::new(),
        };
        let mut t = Tokens::new(node_lines, file);
        let blocks: usize = t.num("number of node blocks")?;
        let _n: usize = t.num("number of nodes")?;
        t.rest_of_line();
        for _ in 0..blocks {
            let _dim: u8 = t.num("entity dimension")?;
            let _tag: i64 = t.num("entity tag")?;
            let parametric: u8 = t.num("parametric flag")?;
            let count: usize = t.num("nodes in block")?;
            let mut tags = Vec::with_capacity(count);
            for _ in 0..count {
                tags.push(t.num::<u64>("node tag")?);
            }
            for tag in tags {
                let x = [t.num("x")?, t.num("y")?, t.num("z")?];
                if parametric != 0 {
                    // parametric coordinates follow: the rest of the line
                    t.rest_of_line();
                }
                insert_node(&mut raw, tag, x, file, t.line_no())?;
            }
        }
        let mut t = Tokens::new(element_lines, file);
        let blocks: usize = t.num("number of element blocks")?;
        let _n: usize = t.num("number of elements")?;
        t.rest_of_line();
        for _ in 0..blocks {
            let dim: u8 = t.num("entity dimension")?;
            let etag: i64 = t.num("entity tag")?;
            let ty: u32 = t.num("element type")?;
            let count: usize = t.num("elements in block")?;
            let groups: Vec<(u8, i64)> = entities
                .get(&(dim, etag))
                .map(|p| p.iter().map(|&g| (dim, g)).collect())
                .unwrap_or_default();
            for _ in 0..count {
                let tag: u64 = t.num("element tag")?;
                let nodes: Vec<u64> = t
                    .rest_of_line()
                    .iter()
                    .map(|s| {
                        s.parse().map_err(|_| {
                            Error::parse(file, t.line_no(), format!("bad node tag '{s}'"))
                        })
                    })
                    .collect::<Result<_, _>>()?;
                raw.elements.push((tag, ty, nodes, groups.clone()));
            }
        }
    } else {
        let mut t = Tokens::new(node_lines, file);
        let n: usize = t.num("number of nodes")?;
        for _ in 0..n {
            let tag: u64 = t.num("node tag")?;
            let x = [t.num("x")?, t.num("y")?, t.num("z")?];
            insert_node(&mut raw, tag, x, file, t.line_no())?;
        }
        let mut t = Tokens::new(element_lines, file);
        let n: usize = t.num("number of elements")?;
        for _ in 0..n {
            let tag: u64 = t.num("element tag")?;
            let ty: u32 = t.num("element type")?;
            let ntags: usize = t.num("number of tags")?;
            let mut tags = Vec::with_capacity(ntags);
            for _ in 0..ntags {
                tags.push(t.num::<i64>("element tag")?);
            }
            let nodes: Vec<u64> = t
                .rest_of_line()
                .iter()
                .map(|s| {
                    s.parse()
                        .map_err(|_| Error::parse(file, t.line_no(), format!("bad node tag '{s}'")))
                })
                .collect::<Result<_, _>>()?;
            let dim = element_dim(ty);
            let groups = tags
                .first()
                .filter(|&&p| p != 0)
                .map(|&p| vec![(dim, p)])
                .unwrap_or_default();
            raw.elements.push((tag, ty, nodes, groups));
        }
    }
    Ok(raw)
}

fn insert_node(
    raw: &mut RawMsh,
    tag: u64,
    x: [f64; 3],
    file: &str,
    line: usize,
) -> Result<(), Error> {
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::parse(
            file,
            line,
            format!("node {tag} has non-finite coordinates {x:?}"),
        ));
    }
    if raw.nodes.insert(tag, x).is_some() {
        return Err(Error::parse(
            file,
            line,
            format!("node {tag} is defined twice"),
        ));
    }
    raw.node_order.push(tag);
    Ok(())
}

/// The dimension of a gmsh element type (for MSH 2 files, whose elements
/// carry their physical tag without its dimension).
fn element_dim(ty: u32) -> u8 {
    match ty {
        15 => 0,
        1 | 8 | 26 | 27 | 28 => 1,
        2 | 3 | 9 | 10 | 16 | 20 | 21 | 22 | 23 | 24 | 25 => 2,
        _ => 3,
    }
}

/// The physical tags of each entity (dim, tag) of a 4.1 `$Entities` section.
fn entity_groups(
    lines: Vec<(usize, &str)>,
    file: &str,
) -> Result<HashMap<(u8, i64), Vec<i64>>, Error> {
    let mut t = Tokens::new(lines, file);
    let counts: [usize; 4] = [
        t.num("number of points")?,
        t.num("number of curves")?,
        t.num("number of surfaces")?,
        t.num("number of volumes")?,
    ];
    let mut out = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag: i64 = t.num("entity tag")?;
            // a point has x y z, the others a bounding box
            let coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..coords {
                t.num::<f64>("entity coordinate")?;
            }
            let np: usize = t.num("number of physical tags")?;
            let mut phys = Vec::with_capacity(np);
            for _ in 0..np {
                phys.push(t.num::<i64>("physical tag")?);
            }
            if dim > 0 {
                let nb: usize = t.num("number of bounding entities")?;
                for _ in 0..nb {
                    t.num::<i64>("bounding entity")?;
                }
            }
            out.insert((dim as u8, tag), phys);
        }
    }
    Ok(out)
}

/// The solid mesh of a parsed `.msh`: volume elements in the Abaqus order,
/// the nodes they use, the physical groups.
fn solid_from_raw(raw: RawMsh, file: &str) -> Result<MeshFile, Error> {
    let mut mesh = MeshFile::default();
    let mut unsupported: BTreeMap<u32, usize> = BTreeMap::new();
    let mut seen_elements = std::collections::HashSet::new();
    let mut index: HashMap<u64, usize> = HashMap::new();
    let mut solid_nodes: Vec<(Vec<u64>, SolidKind, u64)> = Vec::new();
    for (tag, ty, nodes, _) in &raw.elements {
        if let Some(&(_, kind, edges)) = GMSH_VOLUMES.iter().find(|v| v.0 == *ty) {
            if !seen_elements.insert(*tag) {
                continue; // MSH 2 repeats an element for each physical group
            }
            if nodes.len() != kind.n_nodes() {
                return Err(Error::parse(
                    file,
                    0,
                    format!(
                        "element {tag} of type {ty} has {} nodes, a {kind:?} has {}",
                        nodes.len(),
                        kind.n_nodes()
                    ),
                ));
            }
            let perm = gmsh_to_abaqus(kind, edges);
            solid_nodes.push((perm.iter().map(|&j| nodes[j]).collect(), kind, *tag));
        } else if element_dim(*ty) == 3 {
            *unsupported.entry(*ty).or_insert(0) += 1;
        }
    }
    if let Some((&ty, &n)) = unsupported.iter().next() {
        let advice = GMSH_UNSUPPORTED
            .iter()
            .find(|u| u.0 == ty)
            .map_or("an element type the builder has no element for", |u| u.1);
        return Err(Error::Spec(format!(
            "{file}: {n} volume elements of gmsh type {ty}: {advice} (the builder has 4- and 10-node tetrahedra, 8- and \
             20-node hexahedra, 6- and 15-node wedges)"
        )));
    }
    if solid_nodes.is_empty() {
        let groups: Vec<String> = raw
            .names
            .iter()
            .map(|((d, t), n)| format!("{} '{n}' (tag {t})", dim_name(*d)))
            .collect();
        let why = if raw.names.is_empty() && raw.elements.is_empty() {
            "it has no elements".to_string()
        } else if groups.is_empty() {
            "its elements are all points, lines or surfaces".to_string()
        } else {
            format!(
                "gmsh saves only the elements of physical groups, and it has {}, but no physical volume: add \
                 `Physical Volume(\"PART\") = {{1}};` (all volumes of the part) to the .geo",
                groups.join(", ")
            )
        };
        return Err(Error::Spec(format!("{file} has no volume elements: {why}")));
    }
    // nodes of the volume elements, in the file's node order
    let used: std::collections::HashSet<u64> = solid_nodes
        .iter()
        .flat_map(|(n, _, _)| n.iter().copied())
        .collect();
    for &tag in &raw.node_order {
        if used.contains(&tag) {
            index.insert(tag, mesh.coords.len());
            mesh.ids.push(tag);
            mesh.coords.push(raw.nodes[&tag]);
        }
    }
    for (nodes, kind, tag) in solid_nodes {
        let idx = nodes
            .iter()
            .map(|n| {
                index.get(n).copied().ok_or_else(|| {
                    Error::parse(
                        file,
                        0,
                        format!("element {tag} refers to node {n}, which is not in $Nodes"),
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        mesh.kinds.push(kind);
        mesh.elements.push(idx);
        mesh.element_ids.push(tag);
    }
    // physical groups: the nodes of their elements that the solid mesh has
    let mut groups: BTreeMap<(u8, i64), Vec<usize>> = BTreeMap::new();
    for (_, _, nodes, phys) in &raw.elements {
        for g in phys {
            let list = groups.entry(*g).or_default();
            list.extend(nodes.iter().filter_map(|n| index.get(n).copied()));
        }
    }
    for ((dim, tag), mut nodes) in groups {
        nodes.sort_unstable();
        nodes.dedup();
        let name = raw
            .names
            .get(&(dim, tag))
            .filter(|n| !n.is_empty())
            .cloned()
            .unwrap_or_else(|| tag.to_string());
        mesh.groups.push(MeshGroup {
            name,
            what: format!("physical {}", dim_name(dim)),
            tag: Some(tag),
            nodes,
        });
    }
    mesh.groups.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(mesh)
}

fn dim_name(dim: u8) -> &'static str {
    ["point", "curve", "surface", "volume"][dim.min(3) as usize]
}

/// The solid mesh of an Abaqus/CalculiX `.inp` file: its solid elements and
/// *NSET.
fn from_inp(path: &Path) -> Result<MeshFile, Error> {
    let inp = read_inp(path)?;
    let file = display(path);
    let index_of: HashMap<u64, usize> =
        inp.ids.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let mut mesh = MeshFile {
        files: inp.files.clone(),
        ..Default::default()
    };
    let mut index: HashMap<u64, usize> = HashMap::new();
    let mut cells = Vec::new();
    for ((ty, nodes), &label) in inp.elements.iter().zip(&inp.element_ids) {
        let Some(kind) = SolidKind::from_type(ty) else {
            continue;
        };
        if nodes.len() != kind.n_nodes() {
            return Err(Error::parse(
                &file,
                0,
                format!(
                    "element {label} ({ty}) has {} nodes, a {kind:?} has {}",
                    nodes.len(),
                    kind.n_nodes()
                ),
            ));
        }
        cells.push((kind, nodes.clone(), label));
    }
    if cells.is_empty() {
        return Err(Error::Spec(format!(
            "{file} has no solid elements (C3D4, C3D10, C3D8, C3D20, C3D6, C3D15 and their variants)"
        )));
    }
    for (kind, nodes, label) in cells {
        let mut idx = Vec::with_capacity(nodes.len());
        for n in nodes {
            let i = match index.get(&n) {
                Some(&i) => i,
                None => {
                    let Some(&k) = index_of.get(&n) else {
                        return Err(Error::parse(
                            &file,
                            0,
                            format!("element {label} refers to node {n}, which has no *NODE line"),
                        ));
                    };
                    index.insert(n, mesh.coords.len());
                    mesh.ids.push(n);
                    mesh.coords.push(inp.coords[k]);
                    mesh.coords.len() - 1
                }
            };
            idx.push(i);
        }
        mesh.kinds.push(kind);
        mesh.elements.push(idx);
        mesh.element_ids.push(label);
    }
    for (name, labels) in &inp.nsets {
        let mut nodes: Vec<usize> = labels
            .iter()
            .filter_map(|l| index.get(l).copied())
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        mesh.groups.push(MeshGroup {
            name: name.clone(),
            what: "node set".to_string(),
            tag: None,
            nodes,
        });
    }
    mesh.groups.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(mesh)
}

/// Runs an external program in `dir`; a missing program and a failed run
/// are errors naming it, with `install` advice and the end of its output.
fn run_tool(program: &str, args: &[&str], dir: &Path, install: &str) -> Result<String, Error> {
    let out = Command::new(program)
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| {
            let msg = if e.kind() == std::io::ErrorKind::NotFound {
                format!("`{program}` is not installed or not on PATH: {install}")
            } else {
                format!("cannot run `{program}`: {e}")
            };
            Error::Tool {
                program: program.to_string(),
                msg,
            }
        })?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let errors: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("Error") || l.contains("*ERROR"))
        .collect();
    if !out.status.success() || !errors.is_empty() {
        let tail: Vec<&str> = if errors.is_empty() {
            let l: Vec<&str> = text.lines().collect();
            l[l.len().saturating_sub(8)..].to_vec()
        } else {
            errors.into_iter().take(8).collect()
        };
        return Err(Error::Tool {
            program: program.to_string(),
            msg: format!(
                "`{program} {}` in {} failed ({}):\n{}",
                args.join(" "),
                dir.display(),
                out.status,
                tail.join("\n")
            ),
        });
    }
    Ok(text)
}

/// Meshes a gmsh `.geo` script into `out` (a `.msh` file, format 4.1) with
/// second-order elements: `gmsh GEO -3 -order 2 -setnumber
/// Mesh.SecondOrderIncomplete 1 -format msh41 -o OUT` (incomplete: 20-node
/// hexahedra and 15-node wedges, which CalculiX and the built-in FE have,
/// rather than 27 and 18 nodes). gmsh missing, a failed run (its error
/// lines are quoted) and no output are errors.
pub fn mesh_geo(geo: &Path, out: &Path) -> Result<(), Error> {
    if !geo.is_file() {
        return Err(Error::io(
            geo,
            std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        ));
    }
    let geo_abs = std::fs::canonicalize(geo).map_err(|e| Error::io(geo, e))?;
    let dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))?;
    let _ = std::fs::remove_file(out);
    let out_name = out
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    run_tool(
        "gmsh",
        &[
            &geo_abs.to_string_lossy(),
            "-3",
            "-order",
            "2",
            "-setnumber",
            "Mesh.SecondOrderIncomplete",
            "1",
            "-format",
            "msh41",
            "-o",
            &out_name,
        ],
        dir,
        "apt-get install gmsh (Debian/Ubuntu), or mesh the part yourself and give the .msh",
    )?;
    if !out.is_file() {
        return Err(Error::Tool {
            program: "gmsh".into(),
            msg: format!("gmsh wrote no {} from {}", out.display(), geo.display()),
        });
    }
    Ok(())
}

/// A number as CalculiX reads it: its input fields are 20 characters wide,
/// and a longer number is cut silently (`-4.19518626912272E-05` would be
/// read as −4.195), so 13 significant digits, at most 20 characters.
fn ccx_number(v: f64) -> String {
    format!("{v:.12E}")
}

/// The CalculiX element type of a kind.
fn ccx_type(kind: SolidKind) -> &'static str {
    match kind {
        SolidKind::Tet4 => "C3D4",
        SolidKind::Tet10 => "C3D10",
        SolidKind::Hex8 => "C3D8",
        SolidKind::Hex20 => "C3D20",
        SolidKind::Wedge6 => "C3D6",
        SolidKind::Wedge15 => "C3D15",
    }
}

/// The text of a CalculiX deck of `mesh` with `material` in one element set
/// and one matrix-storage step (stiffness and mass, no boundary conditions).
pub fn calculix_deck(mesh: &MeshFile, material: &MeshMaterial, title: &str) -> String {
    let mut s = format!(
        "** {title}\n** written by flexmb: stiffness and mass of the part, free-free\n*NODE\n"
    );
    for (id, x) in mesh.ids.iter().zip(&mesh.coords) {
        s.push_str(&format!(
            "{id}, {}, {}, {}\n",
            ccx_number(x[0]),
            ccx_number(x[1]),
            ccx_number(x[2])
        ));
    }
    for kind in SolidKind::ALL {
        let of_kind: Vec<usize> = (0..mesh.kinds.len())
            .filter(|&e| mesh.kinds[e] == kind)
            .collect();
        if of_kind.is_empty() {
            continue;
        }
        s.push_str(&format!("*ELEMENT, TYPE={}, ELSET=PART\n", ccx_type(kind)));
        for e in of_kind {
            let labels: Vec<String> = mesh.elements[e]
                .iter()
                .map(|&i| mesh.ids[i].to_string())
                .collect();
            // at most 16 entries a line: the label and 15 nodes, then the rest
            let (first, rest) = labels.split_at(labels.len().min(15));
            s.push_str(&format!("{}, {}", mesh.element_ids[e], first.join(", ")));
            if rest.is_empty() {
                s.push('\n');
            } else {
                s.push_str(&format!(",\n{}\n", rest.join(", ")));
            }
        }
    }
    s.push_str(&format!(
        "*MATERIAL, NAME=MATERIAL\n*ELASTIC\n{}, {}\n*DENSITY\n{}\n*SOLID SECTION, ELSET=PART, MATERIAL=MATERIAL\n\
         *STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n",
        ccx_number(material.e),
        ccx_number(material.nu),
        ccx_number(material.rho)
    ));
    s
}

/// Writes the CalculiX deck of `mesh` as `job` + `.inp`, runs `ccx -i JOB`
/// in its directory and reads the stiffness, mass and DOF list it writes
/// (`.sti`, `.mas`, `.dof`) with the deck. The model gets the mesh's groups
/// as node sets. Returns the model and the files written by ccx and read.
pub fn run_calculix(
    mesh: &MeshFile,
    material: &MeshMaterial,
    job: &Path,
    title: &str,
) -> Result<(FeModel, Vec<PathBuf>), Error> {
    material.material()?;
    let dir = job
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))?;
    let inp = job.with_extension("inp");
    crate::readers::write_file(&inp, &calculix_deck(mesh, material, title))?;
    for ext in ["sti", "mas", "dof"] {
        let _ = std::fs::remove_file(job.with_extension(ext));
    }
    let name = job
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    run_tool(
        "ccx",
        &["-i", &name],
        dir,
        "apt-get install calculix-ccx (Debian/Ubuntu), or use the built-in FE (--solver builtin)",
    )?;
    let (mut model, deck) = read_calculix(job, None)?;
    model.node_sets = mesh.node_sets(&model);
    let files = ["sti", "mas", "dof"]
        .iter()
        .map(|e| job.with_extension(e))
        .chain(deck.files)
        .collect();
    Ok((model, files))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The midside permutations take gmsh's edges to Abaqus's: Abaqus
    /// midside node k lies on the Abaqus edge k.
    #[test]
    fn midside_nodes_are_matched_by_their_edges() {
        for &(_, kind, edges) in &GMSH_VOLUMES {
            let perm = gmsh_to_abaqus(kind, edges);
            assert_eq!(perm.len(), kind.n_nodes());
            let corners = kind.n_nodes() - edges.len();
            for (k, &(a, b)) in kind.midside_edges().iter().enumerate() {
                let (c, d) = edges[perm[corners + k] - corners];
                assert!((c, d) == (a, b) || (c, d) == (b, a), "{kind:?} midside {k}");
            }
            let mut sorted = perm.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..kind.n_nodes()).collect::<Vec<_>>());
        }
        // tet10: Abaqus = gmsh with its last two midside nodes swapped
        assert_eq!(
            gmsh_to_abaqus(SolidKind::Tet10, GMSH_VOLUMES[1].2),
            vec![0, 1, 2, 3, 4, 5, 6, 7, 9, 8]
        );
    }

    /// A number for CalculiX never has more than 20 characters and reads
    /// back to 13 digits.
    #[test]
    fn calculix_numbers_fit_its_20_character_fields() {
        for v in [
            -4.1951862691227244e-5,
            1.0 / 3.0,
            -1.7976931348623157e308,
            2.1e11,
            -0.0,
            5e-324,
        ] {
            let s = ccx_number(v);
            assert!(s.len() <= 20, "{s}");
            let back: f64 = s.parse().unwrap();
            assert!((back - v).abs() <= 5e-13 * v.abs(), "{v} → {s}");
        }
    }

    /// A 2.2 file and a 4.1 file of one tetrahedron with a physical surface
    /// give the same mesh: nodes, element in the Abaqus order, groups.
    #[test]
    fn msh_22_and_41_read_alike() {
        let v41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 5 \"base\"\n3 1 \"PART\"\n$EndPhysicalNames\n\
$Entities\n0 0 1 1\n1 0 0 0 1 1 0 1 5 0\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n\
$Nodes\n2 4 1 4\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n3 1 0 1\n4\n0 0 1\n$EndNodes\n\
$Elements\n2 2 1 2\n2 1 2 1\n1 1 2 3\n3 1 4 1\n2 1 2 3 4\n$EndElements\n";
        let v22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 5 \"base\"\n3 1 \"PART\"\n$EndPhysicalNames\n\
$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n\
$Elements\n2\n1 2 2 5 1 1 2 3\n2 4 2 1 1 1 2 3 4\n$EndElements\n";
        let a = solid_from_raw(parse_msh(v41, "a.msh").unwrap(), "a.msh").unwrap();
        let b = solid_from_raw(parse_msh(v22, "b.msh").unwrap(), "b.msh").unwrap();
        for m in [&a, &b] {
            assert_eq!(m.ids, vec![1, 2, 3, 4]);
            assert_eq!(m.kinds, vec![SolidKind::Tet4]);
            assert_eq!(m.elements, vec![vec![0, 1, 2, 3]]);
            let names: Vec<(&str, &str, usize)> = m
                .groups
                .iter()
                .map(|g| (g.name.as_str(), g.what.as_str(), g.nodes.len()))
                .collect();
            assert_eq!(
                names,
                vec![
                    ("PART", "physical volume", 4),
                    ("base", "physical surface", 3)
                ]
            );
        }
        assert_eq!(a.coords, b.coords);
    }

    /// Bad files: binary, another version, cut off, no volume elements (with
    /// the physical groups named and the fix), unsupported volume elements.
    #[test]
    fn bad_msh_files_are_named_errors() {
        let err = |t: &str| match parse_msh(t, "x.msh").and_then(|r| solid_from_raw(r, "x.msh")) {
            Ok(_) => panic!("{t} read"),
            Err(e) => e.to_string(),
        };
        assert!(err("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n").contains("binary"));
        assert!(err("$MeshFormat\n4.0 0 8\n$EndMeshFormat\n").contains("4.1 and 2.2"));
        assert!(
            err("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n").contains("cut off")
        );
        let surface_only = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 5 \"base\"\n$EndPhysicalNames\n\
$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n1 2 2 5 1 1 2 3\n$EndElements\n";
        let e = err(surface_only);
        assert!(
            e.contains("no physical volume")
                && e.contains("'base'")
                && e.contains("Physical Volume"),
            "{e}"
        );
        let hex27 = format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n27\n{}$EndNodes\n$Elements\n1\n1 12 0 {}\n$EndElements\n",
            (1..=27).map(|i| format!("{i} {i} 0 0\n")).collect::<String>(),
            (1..=27).map(|i| i.to_string()).collect::<Vec<_>>().join(" ")
        );
        assert!(err(&hex27).contains("SecondOrderIncomplete"));
    }
}
