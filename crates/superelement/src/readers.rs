//! Readers (and a writer) for exported FE matrices.
//!
//! * Matrix Market coordinate files (`real` or `integer`, `symmetric` or
//!   `general`) for K and M, with a node file (`label x y z` per line) and an
//!   optional DOF file; without one, every node has 3 DOFs in node order.
//! * CalculiX: `JOB.sti` and `JOB.mas` (`row col value`, 1-based, one triangle
//!   with the diagonal), `JOB.dof` (one `node.dir` per equation, dir 1–3 = ux,
//!   uy, uz; parsed as text because "1.10" is not "1.1"), and the node
//!   coordinates (and solid elements, for the mesh volume) from the `.inp` mesh
//!   or the deck that `*INCLUDE`s it (as written by `gmsh -format inp`).
//!   DOFs removed by *BOUNDARY / *EQUATION are absent from all three files.

use crate::model::{DofMap, FeModel};
use crate::Error;
use faer::sparse::{SparseColMat, SparseColMatRef};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

fn read(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| Error::io(path, e))
}

fn fname(path: &Path) -> String {
    path.display().to_string()
}

/// Reads a Matrix Market coordinate matrix (real or integer; symmetric or
/// general). Symmetric files store one triangle; the result holds what the file
/// holds (the model canonicalizes it).
pub fn read_matrix_market(path: &Path) -> Result<SparseColMat<usize, f64>, Error> {
    let text = read(path)?;
    parse_matrix_market(&text, &fname(path))
}

/// Parses Matrix Market text (see [`read_matrix_market`]).
pub fn parse_matrix_market(text: &str, file: &str) -> Result<SparseColMat<usize, f64>, Error> {
    let mut lines = text.lines().enumerate();
    let (_, header) = lines
        .next()
        .ok_or_else(|| Error::parse(file, 1, "empty file"))?;
    let h: Vec<String> = header
        .split_whitespace()
        .map(|s| s.to_ascii_lowercase())
        .collect();
    if h.len() < 5 || h[0] != "%%matrixmarket" || h[1] != "matrix" {
        return Err(Error::parse(
            file,
            1,
            format!("not a Matrix Market matrix header: '{header}'"),
        ));
    }
    if h[2] != "coordinate" {
        return Err(Error::parse(
            file,
            1,
            format!("only 'coordinate' storage is supported, got '{}'", h[2]),
        ));
    }
    if h[3] != "real" && h[3] != "integer" {
        return Err(Error::parse(
            file,
            1,
            format!("only real or integer fields are supported, got '{}'", h[3]),
        ));
    }
    let symmetric = match h[4].as_str() {
        "symmetric" => true,
        "general" => false,
        other => {
            return Err(Error::parse(
                file,
                1,
                format!("only 'symmetric' or 'general' are supported, got '{other}'"),
            ))
        }
    };
    let mut size: Option<(usize, usize, usize)> = None;
    let mut trip = Vec::new();
    for (ln, line) in lines {
        let t = line.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        match size {
            None => {
                if f.len() != 3 {
                    return Err(Error::parse(
                        file,
                        ln + 1,
                        format!("expected 'rows cols entries', got '{t}'"),
                    ));
                }
                let p = |s: &str| {
                    s.parse::<usize>()
                        .map_err(|_| Error::parse(file, ln + 1, format!("'{s}' is not a count")))
                };
                size = Some((p(f[0])?, p(f[1])?, p(f[2])?));
                trip.reserve(p(f[2])?);
            }
            Some((nr, nc, _)) => {
                let (i, j, v) = parse_triplet(&f, t, file, ln + 1)?;
                if i == 0 || j == 0 || i > nr || j > nc {
                    return Err(Error::parse(
                        file,
                        ln + 1,
                        format!("index ({i}, {j}) outside the declared {nr} × {nc} (1-based)"),
                    ));
                }
                trip.push((i - 1, j - 1, v));
            }
        }
    }
    let (nr, nc, nnz) = size.ok_or_else(|| Error::parse(file, 0, "no size line"))?;
    if trip.len() != nnz {
        return Err(Error::parse(
            file,
            0,
            format!(
                "the size line declares {nnz} entries but the file has {}",
                trip.len()
            ),
        ));
    }
    if symmetric && trip.iter().any(|t| t.0 < t.1) && trip.iter().any(|t| t.0 > t.1) {
        return Err(Error::parse(
            file,
            0,
            "a 'symmetric' file must store one triangle only, this one has entries in both",
        ));
    }
    to_csc(nr, nc, trip, file)
}

/// One `row col value` line (1-based indices, not yet range-checked), as
/// Matrix Market coordinate entries and CalculiX `.sti`/`.mas` files hold them.
fn parse_triplet(
    f: &[&str],
    line: &str,
    file: &str,
    ln: usize,
) -> Result<(usize, usize, f64), Error> {
    if f.len() != 3 {
        return Err(Error::parse(
            file,
            ln,
            format!("expected 'row col value', got '{line}'"),
        ));
    }
    let i: usize = f[0]
        .parse()
        .map_err(|_| Error::parse(file, ln, format!("bad row index '{}'", f[0])))?;
    let j: usize = f[1]
        .parse()
        .map_err(|_| Error::parse(file, ln, format!("bad column index '{}'", f[1])))?;
    let v =
        parse_f64(f[2]).ok_or_else(|| Error::parse(file, ln, format!("bad value '{}'", f[2])))?;
    Ok((i, j, v))
}

fn parse_f64(s: &str) -> Option<f64> {
    // Fortran-style exponents (1.0D+03) appear in some exports
    s.parse::<f64>()
        .ok()
        .or_else(|| s.replace(['D', 'd'], "e").parse().ok())
}

fn to_csc(
    nr: usize,
    nc: usize,
    trip: Vec<(usize, usize, f64)>,
    file: &str,
) -> Result<SparseColMat<usize, f64>, Error> {
    let t: Vec<faer::sparse::Triplet<usize, usize, f64>> = trip
        .into_iter()
        .map(|(i, j, v)| faer::sparse::Triplet::new(i, j, v))
        .collect();
    SparseColMat::try_new_from_triplets(nr, nc, &t)
        .map_err(|e| Error::parse(file, 0, format!("{e:?}")))
}

/// Writes a symmetric matrix stored as its upper triangle as a Matrix Market
/// `coordinate real symmetric` file (the lower triangle, as the format asks).
pub fn write_matrix_market(path: &Path, a: SparseColMatRef<'_, usize, f64>) -> Result<(), Error> {
    let mut s = String::new();
    s.push_str(
        "%%MatrixMarket matrix coordinate real symmetric\n% written by flexmb-superelement\n",
    );
    let mut entries = Vec::new();
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            entries.push((j.max(i), j.min(i), v));
        }
    }
    s.push_str(&format!("{} {} {}\n", a.nrows(), a.ncols(), entries.len()));
    for (i, j, v) in entries {
        s.push_str(&format!("{} {} {:.17e}\n", i + 1, j + 1, v));
    }
    write_file(path, &s)
}

/// Writes a dense symmetric matrix as a Matrix Market `array real general` file.
pub fn write_matrix_market_dense(path: &Path, a: &nalgebra::DMatrix<f64>) -> Result<(), Error> {
    let mut s = String::from(
        "%%MatrixMarket matrix array real general\n% written by flexmb-superelement\n",
    );
    s.push_str(&format!("{} {}\n", a.nrows(), a.ncols()));
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            s.push_str(&format!("{:.17e}\n", a[(i, j)]));
        }
    }
    write_file(path, &s)
}

pub(crate) fn write_file(path: &Path, s: &str) -> Result<(), Error> {
    let mut f = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    f.write_all(s.as_bytes()).map_err(|e| Error::io(path, e))
}

/// Reads a node file: one `label x y z` per line (whitespace or commas; `#`,
/// `%` and `**` start comments).
pub fn read_nodes(path: &Path) -> Result<(Vec<u64>, Vec<[f64; 3]>), Error> {
    let text = read(path)?;
    let file = fname(path);
    let mut ids = Vec::new();
    let mut xs = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') || t.starts_with('%') || t.starts_with("**") {
            continue;
        }
        let f: Vec<&str> = t
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        if f.len() != 4 {
            return Err(Error::parse(
                &file,
                ln + 1,
                format!("expected 'label x y z', got '{t}'"),
            ));
        }
        let id: u64 = f[0]
            .parse()
            .map_err(|_| Error::parse(&file, ln + 1, format!("bad node label '{}'", f[0])))?;
        let mut x = [0.0; 3];
        for d in 0..3 {
            x[d] = parse_f64(f[1 + d]).ok_or_else(|| {
                Error::parse(&file, ln + 1, format!("bad coordinate '{}'", f[1 + d]))
            })?;
        }
        ids.push(id);
        xs.push(x);
    }
    Ok((ids, xs))
}

/// Writes a node file (see [`read_nodes`]).
pub fn write_nodes(path: &Path, ids: &[u64], coords: &[[f64; 3]]) -> Result<(), Error> {
    let mut s = String::from("# label x y z [m]\n");
    for (id, x) in ids.iter().zip(coords) {
        s.push_str(&format!("{id} {:.17e} {:.17e} {:.17e}\n", x[0], x[1], x[2]));
    }
    write_file(path, &s)
}

/// Parses CalculiX `.dof` text: one `node.dir` per equation. Returns (node
/// label, direction 0..3) per equation.
pub fn parse_calculix_dof(text: &str, file: &str) -> Result<Vec<(u64, u8)>, Error> {
    let mut out = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let (a, b) = t
            .split_once('.')
            .ok_or_else(|| Error::parse(file, ln + 1, format!("expected 'node.dir', got '{t}'")))?;
        let node: u64 = a
            .trim()
            .parse()
            .map_err(|_| Error::parse(file, ln + 1, format!("bad node label '{a}' in '{t}'")))?;
        let dir: u32 = b
            .trim()
            .parse()
            .map_err(|_| Error::parse(file, ln + 1, format!("bad direction '{b}' in '{t}'")))?;
        if !(1..=3).contains(&dir) {
            return Err(Error::parse(
                file,
                ln + 1,
                format!(
                    "'{t}' is node {node} direction {dir}; only translations 1–3 are supported (a solid model); \
                     note that '{node}.{b}' is not '{node}.{}'",
                    b.trim_end_matches('0')
                ),
            ));
        }
        out.push((node, (dir - 1) as u8));
    }
    Ok(out)
}

/// Parses CalculiX `.sti` / `.mas` text: `row col value`, 1-based.
pub fn parse_calculix_matrix(
    text: &str,
    file: &str,
    n: usize,
) -> Result<SparseColMat<usize, f64>, Error> {
    let mut trip = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        let (i, j, v) = parse_triplet(&f, t, file, ln + 1)?;
        if i == 0 || j == 0 || i > n || j > n {
            return Err(Error::parse(
                file,
                ln + 1,
                format!("index ({i}, {j}) outside 1..{n} (the .dof file lists {n} equations)"),
            ));
        }
        if v != 0.0 {
            trip.push((i - 1, j - 1, v));
        }
    }
    to_csc(n, n, trip, file)
}

/// Nodes and solid elements of an Abaqus/CalculiX `.inp` mesh.
#[derive(Clone, Debug, Default)]
pub struct InpMesh {
    /// Node labels.
    pub ids: Vec<u64>,
    /// Coordinates.
    pub coords: Vec<[f64; 3]>,
    /// Solid elements: (type, node labels).
    pub elements: Vec<(String, Vec<u64>)>,
    /// Node sets (*NSET) by upper-case name.
    pub nsets: HashMap<String, Vec<u64>>,
    /// The files read: the `.inp` and the files it `*INCLUDE`s (empty when
    /// parsed from text).
    pub files: Vec<PathBuf>,
}

impl InpMesh {
    /// Volume of the solid elements from their corner nodes (straight-edged
    /// tetrahedral decomposition; for the units check).
    pub fn volume(&self) -> Option<f64> {
        let idx: HashMap<u64, usize> = self
            .ids
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i))
            .collect();
        let tet = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| {
            let u = crate::model::sub(b, a);
            let v = crate::model::sub(c, a);
            let w = crate::model::sub(d, a);
            (crate::model::dot(u, crate::model::cross(v, w)) / 6.0).abs()
        };
        let mut vol = 0.0;
        let mut any = false;
        for (ty, nodes) in &self.elements {
            let p: Option<Vec<[f64; 3]>> = nodes
                .iter()
                .map(|n| idx.get(n).map(|&i| self.coords[i]))
                .collect();
            let Some(p) = p else { continue };
            let t = ty.to_ascii_uppercase();
            let v = if t.starts_with("C3D4") || t.starts_with("C3D10") {
                tet(p[0], p[1], p[2], p[3])
            } else if t.starts_with("C3D8") || t.starts_with("C3D20") {
                // split the hexahedron into 6 tetrahedra around the diagonal 0–6
                [
                    [0, 1, 2, 6],
                    [0, 2, 3, 6],
                    [0, 3, 7, 6],
                    [0, 7, 4, 6],
                    [0, 4, 5, 6],
                    [0, 5, 1, 6],
                ]
                .iter()
                .map(|q| tet(p[q[0]], p[q[1]], p[q[2]], p[q[3]]))
                .sum()
            } else if t.starts_with("C3D6") || t.starts_with("C3D15") {
                tet(p[0], p[1], p[2], p[3])
                    + tet(p[1], p[2], p[3], p[4])
                    + tet(p[2], p[3], p[4], p[5])
            } else {
                continue;
            };
            any = true;
            vol += v;
        }
        any.then_some(vol)
    }
}

/// How deep `*INCLUDE`s may nest (deeper is taken for a cycle).
const MAX_INCLUDE_DEPTH: usize = 16;

#[derive(PartialEq)]
enum Block {
    None,
    Node,
    Element(String),
    Nset(String, bool),
}

/// The state of the `.inp` parser, kept across `*INCLUDE`d files (an include
/// is textual: a block may continue into or out of the included file).
struct InpParser {
    mesh: InpMesh,
    block: Block,
    pending: Vec<u64>,
    pending_at: (String, usize),
}

/// Nodes per solid element type (C3D4, C3D10, C3D8, C3D20, C3D6, C3D15 and
/// their variants such as C3D10T, C3D20R); `None` for other types.
fn solid_element_nodes(ty: &str) -> Option<usize> {
    // longest prefixes first: C3D10 before C3D1, C3D20 before C3D2
    [
        ("C3D10", 10),
        ("C3D15", 15),
        ("C3D20", 20),
        ("C3D4", 4),
        ("C3D6", 6),
        ("C3D8", 8),
    ]
    .iter()
    .find(|(p, _)| ty.starts_with(p))
    .map(|&(_, n)| n)
}

impl InpParser {
    fn new() -> Self {
        Self {
            mesh: InpMesh::default(),
            block: Block::None,
            pending: Vec::new(),
            pending_at: (String::new(), 0),
        }
    }

    fn check_no_pending(&self, what: &str) -> Result<(), Error> {
        if self.pending.is_empty() {
            Ok(())
        } else {
            Err(Error::parse(&self.pending_at.0, self.pending_at.1, what))
        }
    }

    /// Parses `text` (from `file`); `dir` is the directory `*INCLUDE` paths are
    /// relative to, `None` when the text did not come from a file (an include
    /// is then an error).
    fn feed(
        &mut self,
        text: &str,
        file: &str,
        dir: Option<&Path>,
        depth: usize,
    ) -> Result<(), Error> {
        for (ln, line) in text.lines().enumerate() {
            let t = line.trim();
            if t.is_empty() || t.starts_with("**") {
                continue;
            }
            if t.starts_with('*') {
                let kw: Vec<String> = t.split(',').map(|s| s.trim().to_string()).collect();
                let name = kw[0].to_ascii_uppercase();
                let param = |key: &str| {
                    kw[1..].iter().find_map(|p| {
                        let (k, v) = p.split_once('=')?;
                        (k.trim().eq_ignore_ascii_case(key))
                            .then(|| v.trim().trim_matches('"').to_string())
                    })
                };
                if name == "*INCLUDE" {
                    let input = param("INPUT").ok_or_else(|| {
                        Error::parse(file, ln + 1, format!("'{t}' has no INPUT=file"))
                    })?;
                    self.include(&input, file, ln + 1, dir, depth)?;
                    continue;
                }
                self.check_no_pending("element definition continues past the block")?;
                self.block = match name.as_str() {
                    "*NODE" => Block::Node,
                    "*ELEMENT" => {
                        Block::Element(param("TYPE").unwrap_or_default().to_ascii_uppercase())
                    }
                    "*NSET" => {
                        let gen = kw[1..].iter().any(|p| p.eq_ignore_ascii_case("GENERATE"));
                        Block::Nset(param("NSET").unwrap_or_default().to_ascii_uppercase(), gen)
                    }
                    _ => Block::None,
                };
                continue;
            }
            let f: Vec<&str> = t
                .split(',')
                .map(|s| s.trim())
                .filter(|s| !s.is_empty())
                .collect();
            match &self.block {
                Block::None => {}
                Block::Node => {
                    if f.len() < 3 {
                        return Err(Error::parse(
                            file,
                            ln + 1,
                            format!("expected 'label, x, y[, z]', got '{t}'"),
                        ));
                    }
                    let id: u64 = f[0].parse().map_err(|_| {
                        Error::parse(file, ln + 1, format!("bad node label '{}'", f[0]))
                    })?;
                    let mut x = [0.0; 3];
                    for d in 0..(f.len() - 1).min(3) {
                        x[d] = parse_f64(f[1 + d]).ok_or_else(|| {
                            Error::parse(file, ln + 1, format!("bad coordinate '{}'", f[1 + d]))
                        })?;
                    }
                    self.mesh.ids.push(id);
                    self.mesh.coords.push(x);
                }
                Block::Element(ty) => {
                    // other element types (gmsh writes lines and faces too
                    // when no physical groups are defined) are skipped
                    let Some(n) = solid_element_nodes(ty) else {
                        continue;
                    };
                    if self.pending.is_empty() {
                        self.pending_at = (file.to_string(), ln + 1);
                    }
                    for s in &f {
                        self.pending.push(s.parse().map_err(|_| {
                            Error::parse(file, ln + 1, format!("bad element entry '{s}'"))
                        })?);
                    }
                    // lines break with or without a trailing comma
                    if self.pending.len() < n + 1 {
                        continue;
                    }
                    if self.pending.len() != n + 1 {
                        return Err(Error::parse(
                            &self.pending_at.0,
                            self.pending_at.1,
                            format!(
                                "a {ty} element needs {n} nodes, got {}",
                                self.pending.len() - 1
                            ),
                        ));
                    }
                    let nodes = self.pending[1..].to_vec();
                    self.mesh.elements.push((ty.clone(), nodes));
                    self.pending.clear();
                }
                Block::Nset(name, generate) => {
                    let nums: Vec<u64> = f
                        .iter()
                        .map(|s| {
                            s.parse().map_err(|_| {
                                Error::parse(file, ln + 1, format!("bad node label '{s}'"))
                            })
                        })
                        .collect::<Result<_, _>>()?;
                    let set = self.mesh.nsets.entry(name.clone()).or_default();
                    if *generate {
                        let (a, b, st) = (
                            nums[0],
                            *nums.get(1).unwrap_or(&nums[0]),
                            *nums.get(2).unwrap_or(&1),
                        );
                        let mut k = a;
                        while k <= b {
                            set.push(k);
                            k += st.max(1);
                        }
                    } else {
                        set.extend(nums);
                    }
                }
            }
        }
        Ok(())
    }

    fn include(
        &mut self,
        input: &str,
        file: &str,
        line: usize,
        dir: Option<&Path>,
        depth: usize,
    ) -> Result<(), Error> {
        let Some(dir) = dir else {
            return Err(Error::parse(
                file,
                line,
                format!(
                    "*INCLUDE, INPUT={input}: includes are followed only when reading a file \
                     (readers::read_inp), not when parsing text"
                ),
            ));
        };
        if depth >= MAX_INCLUDE_DEPTH {
            return Err(Error::parse(
                file,
                line,
                format!(
                    "*INCLUDE, INPUT={input}: includes nested more than {MAX_INCLUDE_DEPTH} deep \
                     (a file including itself?)"
                ),
            ));
        }
        let path = dir.join(input);
        let text = read(&path)?;
        self.mesh.files.push(path.clone());
        let sub_dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        self.feed(&text, &fname(&path), Some(&sub_dir), depth + 1)
    }

    fn finish(self, file: &str) -> Result<InpMesh, Error> {
        self.check_no_pending("incomplete element definition at the end of the file")?;
        if self.mesh.ids.is_empty() {
            return Err(Error::parse(file, 0, "no *NODE block"));
        }
        Ok(self.mesh)
    }
}

/// Parses the *NODE, *ELEMENT (solid types C3D*) and *NSET blocks of `.inp`
/// text as written by `gmsh -format inp` or CalculiX. Other keywords and
/// element types are skipped; an `*INCLUDE` is an error here (text has no
/// directory to resolve it against, see [`read_inp`]).
pub fn parse_inp(text: &str, file: &str) -> Result<InpMesh, Error> {
    let mut p = InpParser::new();
    p.feed(text, file, None, 0)?;
    p.finish(file)
}

/// Reads an `.inp` file like [`parse_inp`], following `*INCLUDE, INPUT=...`
/// (relative paths are relative to the including file's directory; `ccx` run
/// in the deck's directory resolves them the same way). [`InpMesh::files`]
/// lists the file and everything it includes.
pub fn read_inp(path: &Path) -> Result<InpMesh, Error> {
    let text = read(path)?;
    let file = fname(path);
    let mut p = InpParser::new();
    p.mesh.files.push(path.to_path_buf());
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    p.feed(&text, &file, Some(&dir), 0)?;
    p.finish(&file)
}

/// Builds a model from CalculiX exports: `JOB.sti`, `JOB.mas`, `JOB.dof` and
/// the `.inp` mesh (`inp`, default `JOB.inp`, read with [`read_inp`], so a
/// deck that `*INCLUDE`s the gmsh mesh works). Returns the model and the mesh.
pub fn read_calculix(job: &Path, inp: Option<&Path>) -> Result<(FeModel, InpMesh), Error> {
    let with = |ext: &str| job.with_extension(ext);
    let (sti, mas, dof) = (with("sti"), with("mas"), with("dof"));
    let inp_path = inp.map(|p| p.to_path_buf()).unwrap_or_else(|| with("inp"));
    let mesh = read_inp(&inp_path)?;
    calculix_from_mesh(
        [
            (&read(&sti)?, &fname(&sti)),
            (&read(&mas)?, &fname(&mas)),
            (&read(&dof)?, &fname(&dof)),
        ],
        mesh,
        &job.file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default(),
    )
}

/// The model from `.sti`, `.mas` and `.dof` (text, file name) and the mesh.
/// Nodes that are in no solid element and have no equation (geometry points,
/// nodes of other element types) are left out, so that a geometric interface
/// selection does not pick them up; nodes of solid elements without equations
/// stay (their DOFs were removed by *BOUNDARY / *EQUATION).
fn calculix_from_mesh(
    [(sti, sti_name), (mas, mas_name), (dof, dof_name)]: [(&str, &str); 3],
    mesh: InpMesh,
    name: &str,
) -> Result<(FeModel, InpMesh), Error> {
    let dofs = parse_calculix_dof(dof, dof_name)?;
    let n = dofs.len();
    let k = parse_calculix_matrix(sti, sti_name, n)?;
    let m = parse_calculix_matrix(mas, mas_name, n)?;
    let (ids, coords) = if mesh.elements.is_empty() {
        (mesh.ids.clone(), mesh.coords.clone())
    } else {
        let used: std::collections::HashSet<u64> = mesh
            .elements
            .iter()
            .flat_map(|(_, nodes)| nodes.iter().copied())
            .chain(dofs.iter().map(|&(node, _)| node))
            .collect();
        mesh.ids
            .iter()
            .zip(&mesh.coords)
            .filter(|(id, _)| used.contains(id))
            .map(|(&id, &c)| (id, c))
            .unzip()
    };
    let mut model = model_from_parts(name, ids, coords, &dofs, k, m, dof_name)?;
    model.volume = mesh.volume();
    Ok((model, mesh))
}

/// Parses a CalculiX export set given as text (the same as [`read_calculix`],
/// but the `.inp` text may not `*INCLUDE` other files).
pub fn parse_calculix(
    sti: &str,
    mas: &str,
    dof: &str,
    inp: &str,
    name: &str,
) -> Result<(FeModel, InpMesh), Error> {
    let mesh = parse_inp(inp, &format!("{name}.inp"))?;
    calculix_from_mesh(
        [
            (sti, &format!("{name}.sti")),
            (mas, &format!("{name}.mas")),
            (dof, &format!("{name}.dof")),
        ],
        mesh,
        name,
    )
}

fn model_from_parts(
    name: &str,
    ids: Vec<u64>,
    coords: Vec<[f64; 3]>,
    dofs: &[(u64, u8)],
    k: SparseColMat<usize, f64>,
    m: SparseColMat<usize, f64>,
    dof_file: &str,
) -> Result<FeModel, Error> {
    let index: HashMap<u64, usize> = ids.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let eqs = dofs
        .iter()
        .enumerate()
        .map(|(e, &(node, d))| {
            index.get(&node).map(|&i| (i, d)).ok_or_else(|| {
                Error::parse(
                    dof_file,
                    e + 1,
                    format!("node {node} has a DOF but no coordinates in the mesh"),
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let map = DofMap::from_equations(ids.len(), eqs)?;
    FeModel::new(name, ids, coords, map, k.as_ref(), m.as_ref())
}

/// Builds a model from Matrix Market K and M, a node file and an optional DOF
/// file (CalculiX `.dof` syntax); without it every node has 3 DOFs, node-major.
pub fn read_matrix_market_model(
    name: &str,
    k: &Path,
    m: &Path,
    nodes: &Path,
    dofs: Option<&Path>,
) -> Result<FeModel, Error> {
    let (ids, coords) = read_nodes(nodes)?;
    let kk = read_matrix_market(k)?;
    let mm = read_matrix_market(m)?;
    let dl: Vec<(u64, u8)> = match dofs {
        Some(p) => parse_calculix_dof(&read(p)?, &fname(p))?,
        None => ids
            .iter()
            .flat_map(|&id| (0..3u8).map(move |d| (id, d)))
            .collect(),
    };
    let df = dofs.map(fname).unwrap_or_else(|| fname(nodes));
    model_from_parts(name, ids, coords, &dl, kk, mm, &df)
}
