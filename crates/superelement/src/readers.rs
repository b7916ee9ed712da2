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

use crate::geometry::{Integrator, SolidKind};
use crate::model::{DofMap, FeModel, NodeSet, SolidElements, Sources};
use crate::Error;
use faer::sparse::{SparseColMat, SparseColMatRef};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

pub(crate) fn read(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| Error::io(path, e))
}

pub(crate) fn fname(path: &Path) -> String {
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
    check_not_cut_off(text, file)?;
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
    let mut size_line = 0;
    let mut last_line = 0;
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
                size_line = ln + 1;
                // no more than the text can hold (a wrong count must not exhaust memory)
                trip.reserve(p(f[2])?.min(text.len() / 6));
            }
            Some((nr, nc, nnz)) => {
                if trip.len() == nnz {
                    return Err(Error::parse(
                        file,
                        ln + 1,
                        format!(
                            "more entries than the {nnz} the size line (line {size_line}) declares: '{t}'"
                        ),
                    ));
                }
                last_line = ln + 1;
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
    if trip.len() < nnz {
        return Err(Error::truncated(
            file,
            last_line.max(size_line),
            format!(
                "the size line (line {size_line}) declares {nnz} entries, but the file ends after {}",
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
pub(crate) fn parse_triplet(
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

pub(crate) fn parse_f64(s: &str) -> Option<f64> {
    // Fortran-style exponents (1.0D+03) appear in some exports
    s.parse::<f64>()
        .ok()
        .or_else(|| s.replace(['D', 'd'], "e").parse().ok())
}

pub(crate) fn to_csc(
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
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))?;
    }
    let mut f = std::fs::File::create(path).map_err(|e| Error::write(path, e))?;
    f.write_all(s.as_bytes()).map_err(|e| Error::write(path, e))
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
    parse_dof_lines(text, file).map_err(|e| cut_off_or(text, file, e))
}

/// Takes a syntax error on the last line of a text that does not end with an
/// end of line for what it is: the file was cut off.
fn cut_off_or(text: &str, file: &str, e: Error) -> Error {
    let last = text.lines().count();
    match &e {
        Error::Parse { line, .. } if *line == last && !text.ends_with('\n') => Error::truncated(
            file,
            last,
            format!(
                "the last line, '{}', is cut off (it has no end of line and cannot be read): {e}",
                text.lines().last().unwrap_or("").trim()
            ),
        ),
        _ => e,
    }
}

/// Errors if `text` does not end with an end of line: every line CalculiX
/// and Matrix Market writers write ends with one, and a value cut short can
/// still be read as a number (`1.2345678901234e+07` → `1.2345678901234e+0`).
pub(crate) fn check_not_cut_off(text: &str, file: &str) -> Result<(), Error> {
    if text.is_empty() || text.ends_with('\n') {
        return Ok(());
    }
    Err(Error::truncated(
        file,
        text.lines().count(),
        format!(
            "the last line, '{}', has no end of line: the file was cut off (if it is complete, end it with a \
             line break)",
            text.lines().last().unwrap_or("").trim()
        ),
    ))
}

fn parse_dof_lines(text: &str, file: &str) -> Result<Vec<(u64, u8)>, Error> {
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

/// Parses CalculiX `.sti` / `.mas` text: `row col value`, 1-based, over the
/// `n` equations of the `.dof` list. Errors if the file is cut off, has an
/// index above `n`, stops before equation `n` or lacks a diagonal entry in
/// the column it ends in (truncated; CalculiX ends every column with its
/// diagonal).
pub fn parse_calculix_matrix(
    text: &str,
    file: &str,
    n: usize,
) -> Result<SparseColMat<usize, f64>, Error> {
    let raw = CcxMatrix::parse(text, file)?;
    if raw.max > n {
        return Err(Error::Mismatch(format!(
            "{file}:{} has an entry for equation {}, but the .dof file lists {n} equations",
            raw.max_line, raw.max
        )));
    }
    if raw.max < n {
        return Err(raw.stops_early(n, "the .dof file", None));
    }
    raw.check_last_column()?;
    raw.into_csc(n)
}

/// A CalculiX `.sti` / `.mas` file as read, before it is checked against the
/// `.dof` list and the other matrix: the entries (1-based; zero off-diagonal
/// entries dropped, zero diagonals kept for the diagonal check) and where the
/// file ends.
struct CcxMatrix {
    file: String,
    entries: Vec<(usize, usize, f64)>,
    /// The largest index, and the line of its first appearance.
    max: usize,
    max_line: usize,
    /// The line and (row, column) of the last entry.
    last: Option<(usize, usize, usize)>,
}

impl CcxMatrix {
    /// Reads the entries; errors on syntax, a 0 index and a cut-off last line.
    fn parse(text: &str, file: &str) -> Result<Self, Error> {
        check_not_cut_off(text, file)?;
        let mut out = CcxMatrix {
            file: file.to_string(),
            entries: Vec::new(),
            max: 0,
            max_line: 0,
            last: None,
        };
        for (ln, line) in text.lines().enumerate() {
            let t = line.trim();
            if t.is_empty() {
                continue;
            }
            let f: Vec<&str> = t.split_whitespace().collect();
            let (i, j, v) = parse_triplet(&f, t, file, ln + 1)?;
            if i == 0 || j == 0 {
                return Err(Error::parse(
                    file,
                    ln + 1,
                    format!("index ({i}, {j}): CalculiX indices start at 1"),
                ));
            }
            if i.max(j) > out.max {
                out.max = i.max(j);
                out.max_line = ln + 1;
            }
            out.last = Some((ln + 1, i, j));
            if v != 0.0 || i == j {
                out.entries.push((i, j, v));
            }
        }
        Ok(out)
    }

    /// The error for a file whose entries stop at equation `max` < `n`, where
    /// `n` comes from `dof_file` (and `other`, the other matrix, agrees): a
    /// complete matrix of a smaller model if it ends with the diagonal of its
    /// last equation, truncated otherwise.
    fn stops_early(&self, n: usize, dof_file: &str, other: Option<&str>) -> Error {
        let also = other
            .map(|o| format!(" and {o} has entries up to equation {n}"))
            .unwrap_or_default();
        match self.last {
            None => Error::truncated(
                &self.file,
                0,
                format!("the file has no entries, but {dof_file} lists {n} equations"),
            ),
            Some((line, i, j)) if i == j && j == self.max => Error::Mismatch(format!(
                "{} holds a matrix of {} equations (it ends with the diagonal entry of equation {} at line \
                 {line}), but {dof_file} lists {n} equations{also}: {} is from another model with fewer \
                  equations (or was cut off exactly after that line)",
                self.file, self.max, self.max, self.file
            )),
            Some((line, i, j)) => Error::truncated(
                &self.file,
                line,
                format!(
                    "the file ends with the entry ({i}, {j}) and has entries up to equation {} only, but \
                     {dof_file} lists {n} equations{also}",
                    self.max
                ),
            ),
        }
    }

    /// Errors if the column of the last entry has no diagonal entry: the file
    /// was cut inside that column (CalculiX ends every column with its
    /// diagonal).
    fn check_last_column(&self) -> Result<(), Error> {
        let Some((line, i, j)) = self.last else {
            return Ok(());
        };
        if i == j || self.entries.iter().any(|&(a, b, _)| a == j && b == j) {
            return Ok(());
        }
        Err(Error::truncated(
            &self.file,
            line,
            format!(
                "the file ends with the entry ({i}, {j}), inside the column of equation {j} before its diagonal \
                 entry ({j}, {j}); CalculiX ends every column with its diagonal"
            ),
        ))
    }

    fn into_csc(self, n: usize) -> Result<SparseColMat<usize, f64>, Error> {
        let trip = self
            .entries
            .into_iter()
            .map(|(i, j, v)| (i - 1, j - 1, v))
            .collect();
        to_csc(n, n, trip, &self.file)
    }
}

/// Checks the equation counts of `.sti`, `.mas` and `.dof` against each other
/// (the largest index of each matrix must be the number of `.dof` entries)
/// and names the file that disagrees with the other two.
fn check_equation_counts(k: &CcxMatrix, m: &CcxMatrix, n: usize, dof: &str) -> Result<(), Error> {
    match (k.max == n, m.max == n) {
        (true, true) => Ok(()),
        (true, false) => Err(one_count_off(m, k, n, dof)),
        (false, true) => Err(one_count_off(k, m, n, dof)),
        (false, false) if k.max == m.max => Err(Error::Mismatch(format!(
            "{dof} lists {n} equations, but {} and {} both have entries up to equation {} ({}:{}, {}:{}): {dof} \
             is from another model (or truncated)",
            k.file, m.file, k.max, k.file, k.max_line, m.file, m.max_line
        ))),
        (false, false) => Err(Error::Mismatch(format!(
            "{dof} lists {n} equations, {} has entries up to equation {} (line {}) and {} up to {} (line {}): the \
             three files come from different models (or are truncated)",
            k.file, k.max, k.max_line, m.file, m.max, m.max_line
        ))),
    }
}

/// The error for `bad`, whose largest index differs from the `n` of the
/// `.dof` list while `good` agrees with it.
fn one_count_off(bad: &CcxMatrix, good: &CcxMatrix, n: usize, dof: &str) -> Error {
    if bad.max > n {
        Error::Mismatch(format!(
            "{}:{} has an entry for equation {}, but {dof} lists {n} equations and {} has entries up to \
             equation {n}: {} is from another model with more equations",
            bad.file, bad.max_line, bad.max, good.file, bad.file
        ))
    } else {
        bad.stops_early(n, dof, Some(&good.file))
    }
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
    /// Element labels, parallel to [`InpMesh::elements`].
    pub element_ids: Vec<u64>,
    /// Element sets (*ELSET and `ELSET=` of *ELEMENT) by upper-case name:
    /// element labels.
    pub elsets: HashMap<String, Vec<u64>>,
    /// Densities of the materials (*MATERIAL, NAME= … *DENSITY) by upper-case
    /// name: the values of the *DENSITY data lines (one per temperature).
    pub densities: HashMap<String, Vec<f64>>,
    /// Solid sections (*SOLID SECTION): (element set, material), upper case.
    pub solid_sections: Vec<(String, String)>,
    /// Keywords that couple nodes outside the elements (*EQUATION, *MPC,
    /// *TIE, *RIGID BODY, *COUPLING, *CONTACT PAIR, …), each with its file
    /// and line.
    pub couplings: Vec<String>,
}

impl InpMesh {
    /// Volume of the solid elements (C3D4/10, C3D8/20, C3D6/15 and variants)
    /// over their isoparametric geometry (for the units check); `None`
    /// without solid elements.
    pub fn volume(&self) -> Option<f64> {
        let idx = self.node_index();
        let mut integrator = Integrator::default();
        let mut vol = 0.0;
        let mut any = false;
        for (ty, nodes) in &self.elements {
            let Some(kind) = SolidKind::from_type(ty) else {
                continue;
            };
            let x: Option<Vec<[f64; 3]>> = nodes
                .iter()
                .map(|n| idx.get(n).map(|&i| self.coords[i]))
                .collect();
            let Some(m) = x.and_then(|x| integrator.moments(kind, &x, x[0])) else {
                continue;
            };
            any = true;
            vol += m.volume;
        }
        any.then_some(vol)
    }

    /// Node label → index into [`InpMesh::ids`].
    fn node_index(&self) -> HashMap<u64, usize> {
        self.ids
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i))
            .collect()
    }

    /// The density of each element (parallel to [`InpMesh::elements`]) from
    /// the *SOLID SECTION covering it and its material's *DENSITY; `None`
    /// where there is no section, the material has no density, or the density
    /// depends on temperature (several data lines).
    pub fn element_densities(&self) -> Vec<Option<f64>> {
        let mut of: HashMap<u64, Option<f64>> = HashMap::new();
        for (elset, material) in &self.solid_sections {
            let rho = match self.densities.get(material).map(|v| v.as_slice()) {
                Some(&[r]) => Some(r),
                _ => None,
            };
            for &e in self.elsets.get(elset).map(|v| v.as_slice()).unwrap_or(&[]) {
                of.insert(e, rho);
            }
        }
        self.element_ids
            .iter()
            .map(|e| of.get(e).copied().flatten())
            .collect()
    }
}

/// The most labels one `GENERATE` line may produce (more is taken for a
/// typo, not expanded until memory runs out).
const MAX_GENERATED: u64 = 10_000_000;

/// The labels of a `GENERATE` data line `first, last[, step]` of *NSET or
/// *ELSET.
fn generated(nums: &[u64], file: &str, line: usize) -> Result<Vec<u64>, Error> {
    let (a, b, step) = match *nums {
        [a] => (a, a, 1),
        [a, b] => (a, b, 1),
        [a, b, st] => (a, b, st),
        _ => {
            return Err(Error::parse(
                file,
                line,
                format!("GENERATE expects 'first, last[, step]', got {nums:?}"),
            ))
        }
    };
    if b < a || step == 0 || (b - a) / step >= MAX_GENERATED {
        return Err(Error::parse(
            file,
            line,
            format!(
                "GENERATE range {a}, {b}, {step}: needs first ≤ last, a step ≥ 1 and at most \
                 {MAX_GENERATED} labels"
            ),
        ));
    }
    Ok((a..=b).step_by(step as usize).collect())
}

/// How deep `*INCLUDE`s may nest (deeper is taken for a cycle).
const MAX_INCLUDE_DEPTH: usize = 16;

#[derive(PartialEq)]
enum Block {
    None,
    Node,
    /// Element type (upper case) and the `ELSET=` it goes to.
    Element(String, Option<String>),
    Nset(String, bool),
    /// Element set name and whether it is `GENERATE`d.
    Elset(String, bool),
    /// *DENSITY of the named material.
    Density(String),
    /// The positioning data lines of an Abaqus *INSTANCE (translation, then
    /// rotation): the instance's name.
    InstanceData(String),
}

/// Keywords that couple nodes outside the elements (the mass then couples
/// nodes that share no element).
const COUPLING_KEYWORDS: [&str; 8] = [
    "*EQUATION",
    "*MPC",
    "*TIE",
    "*RIGID BODY",
    "*COUPLING",
    "*KINEMATIC COUPLING",
    "*DISTRIBUTING COUPLING",
    "*CONTACT PAIR",
];

/// The state of the `.inp` parser, kept across `*INCLUDE`d files (an include
/// is textual: a block may continue into or out of the included file).
struct InpParser {
    mesh: InpMesh,
    block: Block,
    pending: Vec<u64>,
    pending_at: (String, usize),
    /// The current *MATERIAL (upper case).
    material: Option<String>,
    /// Element sets named inside other element sets: (set, member set).
    elset_refs: Vec<(String, String)>,
    /// The open Abaqus *PART or *INSTANCE (upper-case name), if any.
    part: Option<String>,
    instance: Option<String>,
    /// Parts and instances that define nodes, and every instance with its
    /// part: (instance, part, where).
    parts_with_nodes: Vec<String>,
    instances_with_nodes: Vec<String>,
    instances: Vec<(String, String, String)>,
}

impl InpParser {
    fn new() -> Self {
        Self {
            mesh: InpMesh::default(),
            block: Block::None,
            pending: Vec::new(),
            pending_at: (String::new(), 0),
            material: None,
            elset_refs: Vec::new(),
            part: None,
            instance: None,
            parts_with_nodes: Vec::new(),
            instances_with_nodes: Vec::new(),
            instances: Vec::new(),
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
                let upper = |key: &str| param(key).map(|v| v.to_ascii_uppercase());
                let gen = kw[1..].iter().any(|p| p.eq_ignore_ascii_case("GENERATE"));
                if COUPLING_KEYWORDS.iter().any(|k| name.starts_with(k)) {
                    self.mesh
                        .couplings
                        .push(format!("{name} at {file}:{}", ln + 1));
                }
                self.block = match name.as_str() {
                    "*NODE" => {
                        if let Some(i) = &self.instance {
                            if !self.instances_with_nodes.contains(i) {
                                self.instances_with_nodes.push(i.clone());
                            }
                        } else if let Some(p) = &self.part {
                            if !self.parts_with_nodes.contains(p) {
                                self.parts_with_nodes.push(p.clone());
                            }
                        }
                        Block::Node
                    }
                    "*PART" => {
                        self.part = upper("NAME");
                        Block::None
                    }
                    "*END PART" => {
                        self.part = None;
                        Block::None
                    }
                    "*INSTANCE" => {
                        let inst = upper("NAME").unwrap_or_default();
                        self.instances.push((
                            inst.clone(),
                            upper("PART").unwrap_or_default(),
                            format!("{file}:{}", ln + 1),
                        ));
                        self.instance = Some(inst.clone());
                        Block::InstanceData(inst)
                    }
                    "*END INSTANCE" => {
                        self.instance = None;
                        Block::None
                    }
                    "*ELEMENT" => Block::Element(upper("TYPE").unwrap_or_default(), upper("ELSET")),
                    "*NSET" => Block::Nset(upper("NSET").unwrap_or_default(), gen),
                    "*ELSET" => Block::Elset(upper("ELSET").unwrap_or_default(), gen),
                    "*MATERIAL" => {
                        self.material = upper("NAME");
                        Block::None
                    }
                    "*DENSITY" => match &self.material {
                        Some(m) => {
                            self.mesh.densities.insert(m.clone(), Vec::new());
                            Block::Density(m.clone())
                        }
                        None => Block::None,
                    },
                    "*SOLID SECTION" => {
                        if let (Some(e), Some(m)) = (upper("ELSET"), upper("MATERIAL")) {
                            self.mesh.solid_sections.push((e, m));
                        }
                        Block::None
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
                Block::InstanceData(inst) => {
                    // a translation (3 numbers) or rotation (7) line: only
                    // the identity is accepted, since the coordinates are
                    // read as written
                    let moved = f.iter().any(|v| parse_f64(v).is_none_or(|x| x != 0.0));
                    if moved {
                        return Err(Error::parse(
                            file,
                            ln + 1,
                            format!(
                                "*INSTANCE {inst} is positioned by a translation or rotation ('{t}'), which this \
                                 reader does not apply; write the deck with the instance at its part's position \
                                 (or a flattened input file)"
                            ),
                        ));
                    }
                }
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
                Block::Element(ty, elset) => {
                    // other element types (gmsh writes lines and faces too
                    // when no physical groups are defined) are skipped
                    let Some(n) = SolidKind::from_type(ty).map(SolidKind::n_nodes) else {
                        continue;
                    };
                    let elset = elset.clone();
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
                    let id = self.pending[0];
                    self.mesh.elements.push((ty.clone(), nodes));
                    self.mesh.element_ids.push(id);
                    if let Some(set) = elset {
                        self.mesh.elsets.entry(set).or_default().push(id);
                    }
                    self.pending.clear();
                }
                Block::Elset(name, generate) => {
                    let set = name.clone();
                    let generate = *generate;
                    self.elset_line(&set, generate, &f, file, ln + 1)?;
                }
                Block::Density(material) => {
                    // the first value of each data line (the others are temperatures)
                    if let Some(v) = f.first().and_then(|s| parse_f64(s)) {
                        if let Some(d) = self.mesh.densities.get_mut(material) {
                            d.push(v);
                        }
                    }
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
                    let labels = if *generate {
                        generated(&nums, file, ln + 1)?
                    } else {
                        nums
                    };
                    self.mesh
                        .nsets
                        .entry(name.clone())
                        .or_default()
                        .extend(labels);
                }
            }
        }
        Ok(())
    }

    /// One data line of *ELSET: element labels (`first, last, step` with
    /// `GENERATE`) or names of other element sets.
    fn elset_line(
        &mut self,
        set: &str,
        generate: bool,
        f: &[&str],
        file: &str,
        line: usize,
    ) -> Result<(), Error> {
        let nums: Vec<Option<u64>> = f.iter().map(|s| s.parse().ok()).collect();
        if generate {
            let n: Vec<u64> = nums.iter().map_while(|x| *x).collect();
            if n.len() != nums.len() {
                return Err(Error::parse(
                    file,
                    line,
                    format!(
                        "*ELSET, GENERATE expects 'first, last[, step]', got '{}'",
                        f.join(", ")
                    ),
                ));
            }
            let labels = generated(&n, file, line)?;
            self.mesh
                .elsets
                .entry(set.to_string())
                .or_default()
                .extend(labels);
            return Ok(());
        }
        let entry = self.mesh.elsets.entry(set.to_string()).or_default();
        for (s, n) in f.iter().zip(nums) {
            match n {
                Some(n) => entry.push(n),
                None => self
                    .elset_refs
                    .push((set.to_string(), s.to_ascii_uppercase())),
            }
        }
        Ok(())
    }

    /// Node labels are unique only within an Abaqus part or instance: one
    /// mesh is read, so nodes may come from one instance, or from one part
    /// that is instanced once.
    fn check_one_instance(&self, file: &str) -> Result<(), Error> {
        if self.instances_with_nodes.len() > 1 {
            return Err(Error::parse(
                file,
                0,
                format!(
                    "nodes are defined in {} instances ({}); their labels repeat between instances, and this reader \
                     reads the mesh of one instance: export one part, or a flattened input file",
                    self.instances_with_nodes.len(),
                    self.instances_with_nodes.join(", ")
                ),
            ));
        }
        for part in &self.parts_with_nodes {
            let of: Vec<&str> = self
                .instances
                .iter()
                .filter(|(_, p, _)| p == part)
                .map(|(i, _, _)| i.as_str())
                .collect();
            if of.len() > 1 || (self.parts_with_nodes.len() > 1 && !self.instances.is_empty()) {
                return Err(Error::parse(
                    file,
                    0,
                    format!(
                        "part {part} is instanced {} times ({}) and the deck defines nodes in {} part(s); this reader \
                         reads the mesh of one instance: export one part, or a flattened input file",
                        of.len(),
                        of.join(", "),
                        self.parts_with_nodes.len()
                    ),
                ));
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

    fn finish(mut self, file: &str) -> Result<InpMesh, Error> {
        self.check_no_pending("incomplete element definition at the end of the file")?;
        self.check_one_instance(file)?;
        if self.mesh.ids.is_empty() {
            return Err(Error::parse(file, 0, "no *NODE block"));
        }
        // element sets named in other sets, nested at most MAX_INCLUDE_DEPTH deep
        for _ in 0..MAX_INCLUDE_DEPTH {
            let mut changed = false;
            for (set, member) in &self.elset_refs {
                let add = self.mesh.elsets.get(member).cloned().unwrap_or_default();
                let to = self.mesh.elsets.entry(set.clone()).or_default();
                let before = to.len();
                to.extend(add);
                to.sort_unstable();
                to.dedup();
                changed |= to.len() != before;
            }
            if !changed {
                break;
            }
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
    let k = CcxMatrix::parse(sti, sti_name)?;
    let m = CcxMatrix::parse(mas, mas_name)?;
    check_equation_counts(&k, &m, n, dof_name)?;
    k.check_last_column()?;
    m.check_last_column()?;
    let (k, m) = (k.into_csc(n)?, m.into_csc(n)?);
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
    let deck = mesh
        .files
        .first()
        .map(|p| fname(p))
        .unwrap_or_else(|| format!("{name}.inp"));
    model.sources = Sources {
        k: sti_name.to_string(),
        m: mas_name.to_string(),
        dofs: dof_name.to_string(),
        mesh: deck.clone(),
    };
    model.solid = Some(solid_elements(&model, &mesh, &deck));
    model.node_sets = node_sets(&model, &mesh);
    Ok((model, mesh))
}

/// The *NSET of `mesh` over the nodes of `model` (labels the model does not
/// have are passed over), sorted by name.
pub(crate) fn node_sets(model: &FeModel, mesh: &InpMesh) -> Vec<NodeSet> {
    let mut out: Vec<NodeSet> = mesh
        .nsets
        .iter()
        .map(|(name, labels)| {
            let mut nodes: Vec<usize> =
                labels.iter().filter_map(|&l| model.node_index(l)).collect();
            nodes.sort_unstable();
            nodes.dedup();
            NodeSet {
                name: name.clone(),
                what: "node set".to_string(),
                tag: None,
                nodes,
            }
        })
        .collect();
    out.sort_by(|a, b| a.name.cmp(&b.name));
    out
}

/// The solid elements of `mesh` over the nodes of `model`, with the densities
/// of the deck's *SOLID SECTION / *DENSITY.
pub(crate) fn solid_elements(model: &FeModel, mesh: &InpMesh, deck: &str) -> SolidElements {
    let mut out = SolidElements {
        density_source: format!("*DENSITY in {deck}"),
        couplings: mesh.couplings.clone(),
        ..Default::default()
    };
    for ((ty, nodes), rho) in mesh.elements.iter().zip(mesh.element_densities()) {
        let Some(kind) = SolidKind::from_type(ty) else {
            continue;
        };
        let Some(idx) = nodes
            .iter()
            .map(|&n| model.node_index(n))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        out.kinds.push(kind);
        out.nodes.push(idx);
        out.density.push(rho);
    }
    out
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

pub(crate) fn model_from_parts(
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
    let (kf, mf) = (fname(k), fname(m));
    check_matrix_market_sizes([(&kk, &kf), (&mm, &mf)], dl.len(), &df)?;
    let mut model = model_from_parts(name, ids, coords, &dl, kk, mm, &df)?;
    model.sources = Sources {
        k: kf,
        m: mf,
        dofs: df,
        mesh: fname(nodes),
    };
    Ok(model)
}

/// Checks that K and M are square, of one size, and of the size of the DOF
/// list (`n` equations from `dof_file`, or 3 per node of the node file),
/// naming the file that disagrees with the other two.
pub(crate) fn check_matrix_market_sizes(
    [(k, kf), (m, mf)]: [(&SparseColMat<usize, f64>, &str); 2],
    n: usize,
    dof_file: &str,
) -> Result<(), Error> {
    for (a, f) in [(k, kf), (m, mf)] {
        if a.nrows() != a.ncols() {
            return Err(Error::parse(
                f,
                0,
                format!("the matrix is {} × {}, not square", a.nrows(), a.ncols()),
            ));
        }
    }
    let (nk, nm) = (k.nrows(), m.nrows());
    let msg = match (nk == n, nm == n) {
        (true, true) => return Ok(()),
        (true, false) => format!(
            "{mf} is {nm} × {nm}, but {kf} is {n} × {n} and {dof_file} gives {n} equations: {mf} is from another model"
        ),
        (false, true) => format!(
            "{kf} is {nk} × {nk}, but {mf} is {n} × {n} and {dof_file} gives {n} equations: {kf} is from another model"
        ),
        (false, false) if nk == nm => format!(
            "{kf} and {mf} are {nk} × {nk}, but {dof_file} gives {n} equations: {dof_file} is from another model"
        ),
        (false, false) => format!(
            "{kf} is {nk} × {nk}, {mf} is {nm} × {nm} and {dof_file} gives {n} equations: the three files come from \
             different models"
        ),
    };
    Err(Error::Mismatch(msg))
}
