//! Coordinate and deformation roles, and the choice of degrees of freedom
//! (thesis (6.4)): fixed / DOF / prescribed / dependent nodal coordinates and
//! rigid / DOF / prescribed / dependent deformations. Counts and regularity are
//! checked with an SVD of the constraint Jacobian at the reference
//! configuration, which also names redundant equations or undetermined
//! coordinates.

use crate::local_span::{LocalSpan, Verdict};
use crate::mechanism::*;
use crate::scene::*;
use crate::ModelError;
use faer::Mat;

/// Resolves a selection to coordinates.
pub(crate) fn resolve(
    mech: &Mechanism,
    s: &Select,
    ctx: &str,
) -> Result<Vec<Coordinate>, ModelError> {
    let unknown_node = |id: &str| ModelError::UnknownId {
        kind: "node",
        id: id.to_string(),
        context: ctx.to_string(),
        hint: String::new(),
    };
    match s {
        Select::Node(id) => {
            let n = mech.node(id).ok_or_else(|| unknown_node(id))?;
            let mut v: Vec<Coordinate> = n.position.iter().map(|i| Coordinate::Node(*i)).collect();
            if let Some(o) = &n.orientation {
                v.extend(o.iter().map(|i| Coordinate::Node(*i)));
            }
            Ok(v)
        }
        Select::Coord(id, c) => {
            let n = mech.node(id).ok_or_else(|| unknown_node(id))?;
            let orient = || {
                n.orientation.clone().ok_or_else(|| {
                    ModelError::invalid(ctx, format!("node '{id}' has no orientation coordinates (no element uses its rotation)"))
                })
            };
            let idx: Vec<usize> = match c {
                Component::X => vec![n.position[0]],
                Component::Y => vec![n.position[1]],
                Component::Z => {
                    if n.position.len() < 3 {
                        return Err(ModelError::invalid(ctx, "Z in a planar scene"));
                    }
                    vec![n.position[2]]
                }
                Component::Position => n.position.clone(),
                Component::Angle => {
                    let o = orient()?;
                    if o.len() != 1 {
                        return Err(ModelError::invalid(
                            ctx,
                            "Angle in a spatial scene: use Lambda(k) or Orientation",
                        ));
                    }
                    o
                }
                Component::Lambda(k) => {
                    let o = orient()?;
                    if o.len() != 4 || *k > 3 {
                        return Err(ModelError::invalid(
                            ctx,
                            format!("Lambda({k}) needs a spatial node and k in 0..=3"),
                        ));
                    }
                    vec![o[*k as usize]]
                }
                Component::Orientation => orient()?,
            };
            Ok(idx.into_iter().map(Coordinate::Node).collect())
        }
        Select::Modes(g) => {
            let (_, idx) = mech
                .mode_groups
                .iter()
                .find(|(n, _)| n == g)
                .ok_or_else(|| ModelError::UnknownId {
                    kind: "mode group",
                    id: g.clone(),
                    context: ctx.to_string(),
                    hint: String::new(),
                })?;
            Ok(idx.iter().map(|i| Coordinate::Node(*i)).collect())
        }
        Select::Def(eid, name) => {
            let members: Vec<&MechElement> = mech
                .elements
                .iter()
                .filter(|e| e.id == *eid || e.group == *eid)
                .collect();
            if members.is_empty() {
                return Err(ModelError::UnknownId {
                    kind: "element",
                    id: eid.clone(),
                    context: ctx.to_string(),
                    hint: String::new(),
                });
            }
            let mut v = vec![];
            for e in members {
                let names = e.element.deformation_names();
                for (k, n) in names.iter().enumerate() {
                    if name == "*" || n == name {
                        v.push(Coordinate::Def(e.eps_offset + k));
                    }
                }
                if name != "*" && !names.iter().any(|n| n == name) && e.element.n_eps() > 0 {
                    return Err(ModelError::invalid(
                        ctx,
                        format!(
                            "element '{}' ({}) has no deformation '{name}'; it has {:?}",
                            e.id,
                            e.element.type_name(),
                            names
                        ),
                    ));
                }
            }
            Ok(v)
        }
    }
}

/// The global deformation Jacobian D,x at x, sparse: for every deformation its
/// nonzero entries (global nodal index, value), sorted by index. Entries of one
/// index are summed in element order, as a dense assembly would.
pub(crate) fn sparse_jacobian(mech: &Mechanism, x: &[f64]) -> Vec<Vec<(usize, f64)>> {
    let mut rows: Vec<Vec<(usize, f64)>> = vec![vec![]; mech.n_eps()];
    let mut xl = vec![];
    let mut eps = vec![];
    let mut jl = vec![];
    for e in &mech.elements {
        let (ne, nx) = (e.element.n_eps(), e.element.n_x());
        if ne == 0 {
            continue;
        }
        xl.clear();
        xl.extend(e.x_index.iter().map(|i| x[*i]));
        eps.clear();
        eps.resize(ne, 0.0);
        jl.clear();
        jl.resize(ne * nx, 0.0);
        e.element
            .deformations_and_jacobian(&xl, None, &mut eps, &mut jl);
        for r in 0..ne {
            let row = &mut rows[e.eps_offset + r];
            for (c, gi) in e.x_index.iter().enumerate() {
                row.push((*gi, jl[r * nx + c]));
            }
        }
    }
    for row in &mut rows {
        // stable: equal indices keep element order, so the sums are those of
        // the dense assembly `0.0 + v1 + v2 + ...`
        row.sort_by_key(|(i, _)| *i);
        let mut merged: Vec<(usize, f64)> = Vec::with_capacity(row.len());
        for (i, v) in row.drain(..) {
            match merged.last_mut() {
                Some((j, s)) if *j == i => *s += v,
                _ => merged.push((i, 0.0 + v)),
            }
        }
        *row = merged;
    }
    rows
}

fn dense_of(rows: &[Vec<(usize, f64)>], m: usize, n: usize) -> Mat<f64> {
    let mut j = Mat::<f64>::zeros(m, n);
    for (r, row) in rows.iter().enumerate() {
        for (c, v) in row {
            j[(r, *c)] = *v;
        }
    }
    j
}

/// Physical memory in bytes (`MemTotal` of /proc/meminfo, else 8 GiB).
pub(crate) fn physical_memory() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("MemTotal:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or(8 << 30, |kb| kb * 1024)
}

/// A byte count for people: 4.8 TB, 512 MB.
pub(crate) fn human_bytes(b: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if k == 0 {
        format!("{v:.0} {}", units[k])
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// Checks before allocating `copies` dense `rows × cols` matrices of f64 that
/// they need at most a quarter of the physical memory.
pub(crate) fn check_dense(
    what: &str,
    rows: usize,
    cols: usize,
    copies: usize,
) -> Result<(), ModelError> {
    check_dense_against(what, rows, cols, copies, physical_memory() / 4)
}

fn dense_bytes(rows: usize, cols: usize, copies: usize) -> f64 {
    rows as f64 * cols as f64 * copies as f64 * 8.0
}

fn check_dense_against(
    what: &str,
    rows: usize,
    cols: usize,
    copies: usize,
    limit: u64,
) -> Result<(), ModelError> {
    let bytes = dense_bytes(rows, cols, copies);
    if bytes > limit as f64 {
        return Err(ModelError::TooLarge {
            what: format!(
                "{what} of {rows} × {cols} would need {} dense ({} elements{})",
                human_bytes(bytes),
                rows as u128 * cols as u128,
                if copies > 1 {
                    format!(", {copies} copies")
                } else {
                    String::new()
                }
            ),
            limit: human_bytes(limit as f64),
        });
    }
    Ok(())
}

const RANK_TOL: f64 = 1e-9;

/// Rank and null spaces of a (row-normalized) matrix: (rank, left null
/// vectors as columns, right null space as columns), from the SVD of
/// [`flexmb_linalg::svd`] (which falls back to other methods where faer's
/// does not converge). `what` names the matrix in the error.
fn null_spaces(a: &Mat<f64>, what: &str) -> Result<(usize, Mat<f64>, Mat<f64>), ModelError> {
    let (m, n) = (a.nrows(), a.ncols());
    let d = flexmb_linalg::svd(a.as_ref()).map_err(|source| ModelError::Computation {
        what: format!("choosing the degrees of freedom: {what}"),
        source,
    })?;
    let r = d.rank(RANK_TOL);
    let left = Mat::from_fn(m, m - r, |i, j| d.u[(i, r + j)]);
    let right = Mat::from_fn(n, n - r, |i, j| d.v[(i, r + j)]);
    Ok((r, left, right))
}

fn names_in(vectors: &Mat<f64>, names: &[String]) -> Vec<String> {
    let mut out = vec![];
    for j in 0..vectors.ncols() {
        let mx = (0..vectors.nrows())
            .map(|i| vectors[(i, j)].abs())
            .fold(0.0f64, f64::max);
        for i in 0..vectors.nrows() {
            if vectors[(i, j)].abs() > 0.2 * mx && !out.contains(&names[i]) {
                out.push(names[i].clone());
            }
        }
    }
    out
}

/// Role of a coordinate or deformation while the roles are assigned.
#[derive(Clone, Copy, PartialEq, Debug)]
enum R {
    Free,
    Fixed,
    Rigid,
    Input,
}

/// How the degrees of freedom are chosen.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Method {
    /// Dense below [`DENSE_MAX_FREE`] free coordinates, sparse above.
    Auto,
    /// One SVD of the whole constraint Jacobian (the original method).
    Dense,
    /// Local bounds ([`crate::local_span`]), and where they do not decide,
    /// connected blocks, eliminated as they become determined (forced: also
    /// the final regularity check, which `Auto` does with an SVD up to
    /// [`DENSE_MAX_DEPENDENT`] dependent coordinates).
    Sparse,
    /// `Sparse` without the local bounds: the blocks alone (tests).
    #[cfg_attr(not(test), allow(dead_code))]
    Blocks,
}

/// Up to this many free coordinates the dense SVD is used: it takes
/// milliseconds there.
pub(crate) const DENSE_MAX_FREE: usize = 300;

/// Up to this many dependent coordinates the final regularity check is an SVD.
const DENSE_MAX_DEPENDENT: usize = 1000;

thread_local! {
    /// The method `assign` uses (tests compare the two).
    pub(crate) static METHOD: std::cell::Cell<Method> = const { std::cell::Cell::new(Method::Auto) };
    /// How often the local bounds did not decide and the blocks were used
    /// (tests check that a chain needs them nowhere).
    pub(crate) static BLOCK_FALLBACKS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

fn count_fallback() {
    BLOCK_FALLBACKS.with(|c| c.set(c.get() + 1));
}

/// What the choice of DOFs works on: the roles given by the scene and the
/// constraint Jacobian at the reference configuration.
struct Problem<'a> {
    mech: &'a Mechanism,
    xr: &'a [R],
    er: &'a [R],
    /// Free nodal coordinates (global indices), ascending.
    free: Vec<usize>,
    /// Position of a nodal coordinate in `free` (usize::MAX if not free).
    free_pos: Vec<usize>,
    /// Rigid and prescribed deformations: the equations.
    crow: Vec<usize>,
    /// Sparse D,x at the reference configuration.
    rows: Vec<Vec<(usize, f64)>>,
}

impl Problem<'_> {
    /// Norm of deformation row j over the free coordinates.
    fn free_norm(&self, j: usize) -> f64 {
        self.rows[j]
            .iter()
            .filter(|(i, _)| self.free_pos[*i] != usize::MAX)
            .map(|(_, v)| v.powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Row j over the free coordinates (indices into `free`), divided by `nrm`.
    fn free_row(&self, j: usize, nrm: f64) -> Vec<(usize, f64)> {
        self.rows[j]
            .iter()
            .filter(|(i, _)| self.free_pos[*i] != usize::MAX)
            .map(|(i, v)| (self.free_pos[*i], v / nrm))
            .collect()
    }

    /// A candidate as a unit-norm row over the free coordinates.
    fn candidate(&self, c: Coordinate) -> Vec<(usize, f64)> {
        match c {
            Coordinate::Node(i) => vec![(self.free_pos[i], 1.0)],
            Coordinate::Def(j) => self.free_row(j, self.free_norm(j).max(1e-300)),
        }
    }

    /// An equation row, normalized (a zero row stays zero).
    fn equation(&self, j: usize) -> Vec<(usize, f64)> {
        let nrm = self.free_norm(j);
        if nrm > 0.0 {
            self.free_row(j, nrm)
        } else {
            vec![]
        }
    }

    fn fits_dense(&self) -> bool {
        let (m, n) = (self.mech.n_eps(), self.mech.n_x());
        let (c, f) = (self.crow.len(), self.free.len());
        // D,x; C; its SVD (U, V, a copy of C); the null space
        let b = dense_bytes(m, n, 1)
            + dense_bytes(c, f, 2)
            + dense_bytes(c, c, 1)
            + dense_bytes(f, f, 2);
        b <= (physical_memory() / 4) as f64
    }
}

/// Decides whether a candidate adds a direction to the motions the chosen
/// equations leave free.
trait Oracle {
    fn accept(&mut self, c: Coordinate) -> bool;
}

/// Greedy Gram–Schmidt on the null space of the whole constraint Jacobian
/// (one dense SVD): the original method, the reference for the sparse one.
struct Dense<'p, 'a> {
    p: &'p Problem<'a>,
    jac: Mat<f64>,
    null: Mat<f64>,
    basis: Vec<Vec<f64>>,
}

/// Gram–Schmidt acceptance of `g` against an orthonormal `basis`.
fn accept_gs(g: Vec<f64>, basis: &mut Vec<Vec<f64>>) -> bool {
    let n0 = g.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n0 < 1e-12 {
        return false;
    }
    let mut r = g;
    for _ in 0..2 {
        for b in basis.iter() {
            let p: f64 = r.iter().zip(b).map(|(a, c)| a * c).sum();
            for (ri, bi) in r.iter_mut().zip(b) {
                *ri -= p * bi;
            }
        }
    }
    let nr = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    if accepted(nr, || n0) {
        basis.push(r.into_iter().map(|v| v / nr).collect());
        true
    } else {
        false
    }
}

/// The acceptance rule: residual `nr` against the norm `n0` of the candidate's
/// projection on the motions the equations leave free (needed only near the
/// threshold, so computed on demand).
fn accepted(nr: f64, n0: impl FnOnce() -> f64) -> bool {
    if nr > 1e-6 {
        return true; // n0 ≤ 1 for a unit candidate, so the threshold is ≤ 1e-6
    }
    if nr <= 1e-9 {
        return false; // the threshold is ≥ 1e-9
    }
    let n0 = n0();
    n0 >= 1e-12 && nr > 1e-6 * n0.max(1e-3)
}

impl<'p, 'a> Dense<'p, 'a> {
    fn new(p: &'p Problem<'a>) -> Result<(Self, usize), ModelError> {
        check_dense("the deformation Jacobian", p.mech.n_eps(), p.mech.n_x(), 1)?;
        check_dense("the constraint Jacobian", p.crow.len(), p.free.len(), 2)?;
        check_dense("the null space", p.free.len(), p.free.len(), 2)?;
        let jac = dense_of(&p.rows, p.mech.n_eps(), p.mech.n_x());
        let free = &p.free;
        let crow = &p.crow;
        let c = Mat::from_fn(crow.len(), free.len(), |r, c| {
            let nrm = free
                .iter()
                .map(|fc| jac[(crow[r], *fc)].powi(2))
                .sum::<f64>()
                .sqrt();
            if nrm > 0.0 {
                jac[(crow[r], free[c])] / nrm
            } else {
                0.0
            }
        });
        let (rank, left, null) =
            null_spaces(&c, "the constraint Jacobian on the free coordinates")?;
        if rank < crow.len() {
            let names: Vec<String> = crow.iter().map(|j| p.mech.eps_names[*j].clone()).collect();
            return Err(ModelError::OverConstrained {
                redundant: names_in(&left, &names),
            });
        }
        let d = null.ncols();
        Ok((
            Dense {
                p,
                jac,
                null,
                basis: vec![],
            },
            d,
        ))
    }

    fn under_constrained(&mut self, chosen: usize) -> ModelError {
        let d = self.null.ncols();
        let mut rest = vec![];
        for k in 0..d {
            let mut e = vec![0.0; d];
            e[k] = 1.0;
            let before = self.basis.len();
            if accept_gs(e, &mut self.basis) {
                rest.push(self.basis[before].clone());
            }
        }
        let null = &self.null;
        let m = Mat::from_fn(self.p.free.len(), rest.len(), |i, j| {
            (0..d).map(|k| null[(i, k)] * rest[j][k]).sum()
        });
        let names: Vec<String> = self
            .p
            .free
            .iter()
            .map(|i| self.p.mech.x_names[*i].clone())
            .collect();
        ModelError::UnderConstrained {
            count: d - chosen,
            undetermined: names_in(&m, &names),
        }
    }
}

impl Oracle for Dense<'_, '_> {
    fn accept(&mut self, c: Coordinate) -> bool {
        let (p, jac, null) = (self.p, &self.jac, &self.null);
        let d = null.ncols();
        let g: Vec<f64> = match c {
            Coordinate::Node(i) => (0..d).map(|k| null[(p.free_pos[i], k)]).collect(),
            Coordinate::Def(j) => {
                let nrm = p
                    .free
                    .iter()
                    .map(|fc| jac[(j, *fc)].powi(2))
                    .sum::<f64>()
                    .sqrt()
                    .max(1e-300);
                (0..d)
                    .map(|k| {
                        (0..p.free.len())
                            .map(|c| jac[(j, p.free[c])] / nrm * null[(c, k)])
                            .sum()
                    })
                    .collect()
            }
        };
        accept_gs(g, &mut self.basis)
    }
}

// ---- the sparse method
//
// The rows accepted so far (equations, then chosen DOFs) span a subspace S of
// the free motions; a candidate a (unit norm) is accepted when its distance to
// S is large enough. That distance is what the dense method computes (its
// Gram–Schmidt on the null space of the equations is isometric to one on the
// rows), but it only involves the rows connected to a through shared
// coordinates: S splits into blocks of rows with disjoint supports, each with
// its own orthonormal basis. A block with as many independent rows as
// coordinates spans all of them: those coordinates are determined, and are
// dropped from every later candidate (the distance does not change). In a
// chain, the block of a node closes as soon as the beam to it is chosen, so
// every block stays small.

const NO_BLOCK: u32 = u32::MAX;
const DETERMINED: u32 = u32::MAX - 1;

/// A basis row: zero before `start`, `v` from there (local indices).
struct BRow {
    start: usize,
    v: Vec<f64>,
}

#[derive(Default)]
struct Block {
    /// Free-coordinate indices of the block's local columns.
    cols: Vec<usize>,
    /// Orthonormal basis of the span of its rows.
    rows: Vec<BRow>,
}

struct Blocks {
    block_of: Vec<u32>,
    local: Vec<usize>,
    blocks: Vec<Block>,
    spare: Vec<u32>,
    /// Of the last `residual`: touched blocks with their offsets, new columns,
    /// the residual.
    touched: Vec<(u32, usize)>,
    new_cols: Vec<usize>,
    r: Vec<f64>,
}

impl Blocks {
    fn new(n_free: usize) -> Self {
        Blocks {
            block_of: vec![NO_BLOCK; n_free],
            local: vec![0; n_free],
            blocks: vec![],
            spare: vec![],
            touched: vec![],
            new_cols: vec![],
            r: vec![],
        }
    }

    /// Distance of `a` to the span of the accepted rows; `commit` then adds it.
    fn residual(&mut self, a: &[(usize, f64)]) -> f64 {
        self.touched.clear();
        self.new_cols.clear();
        let mut base: Option<u32> = None;
        for (i, _) in a {
            match self.block_of[*i] {
                DETERMINED => {}
                NO_BLOCK => self.new_cols.push(*i),
                b => {
                    if !self.touched.iter().any(|(t, _)| *t == b) {
                        self.touched.push((b, 0));
                        if base.is_none_or(|x| {
                            self.blocks[b as usize].cols.len() > self.blocks[x as usize].cols.len()
                        }) {
                            base = Some(b);
                        }
                    }
                }
            }
        }
        self.new_cols.sort_unstable();
        self.new_cols.dedup();
        // the largest block first (it keeps its local indices), then the others
        if let Some(b) = base {
            let k = self
                .touched
                .iter()
                .position(|(t, _)| *t == b)
                .expect("touched");
            self.touched.swap(0, k);
        }
        let mut off = 0;
        for t in self.touched.iter_mut() {
            t.1 = off;
            off += self.blocks[t.0 as usize].cols.len();
        }
        let len = off + self.new_cols.len();
        self.r.clear();
        self.r.resize(len, 0.0);
        for (i, v) in a {
            let pos = match self.block_of[*i] {
                DETERMINED => continue,
                NO_BLOCK => off + self.new_cols.binary_search(i).expect("new column"),
                b => {
                    let o = self
                        .touched
                        .iter()
                        .find(|(t, _)| *t == b)
                        .expect("touched")
                        .1;
                    o + self.local[*i]
                }
            };
            self.r[pos] += v;
        }
        for _ in 0..2 {
            for (b, o) in &self.touched {
                for q in &self.blocks[*b as usize].rows {
                    let seg = &mut self.r[o + q.start..o + q.start + q.v.len()];
                    let p: f64 = seg.iter().zip(&q.v).map(|(x, y)| x * y).sum();
                    for (x, y) in seg.iter_mut().zip(&q.v) {
                        *x -= p * y;
                    }
                }
            }
        }
        self.r.iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// Adds the residual of the last `residual` (norm `nr` > 0) as a basis row,
    /// merging the blocks it touches; a block that becomes square is
    /// determined and dropped.
    fn commit(&mut self, nr: f64) {
        let id = match self.touched.first() {
            Some((b, _)) => *b,
            None => match self.spare.pop() {
                Some(b) => b,
                None => {
                    self.blocks.push(Block::default());
                    (self.blocks.len() - 1) as u32
                }
            },
        };
        let mut block = std::mem::take(&mut self.blocks[id as usize]);
        for (b, o) in self.touched.iter().skip(1) {
            let other = std::mem::take(&mut self.blocks[*b as usize]);
            debug_assert_eq!(*o, block.cols.len());
            for c in &other.cols {
                self.block_of[*c] = id;
                self.local[*c] += o;
            }
            block.cols.extend(other.cols);
            block.rows.extend(other.rows.into_iter().map(|mut q| {
                q.start += o;
                q
            }));
            self.spare.push(*b);
        }
        for c in &self.new_cols {
            self.block_of[*c] = id;
            self.local[*c] = block.cols.len();
            block.cols.push(*c);
        }
        let first = self.r.iter().position(|v| *v != 0.0).unwrap_or(0);
        let last = self.r.iter().rposition(|v| *v != 0.0).map_or(0, |k| k + 1);
        block.rows.push(BRow {
            start: first,
            v: self.r[first..last.max(first)]
                .iter()
                .map(|v| v / nr)
                .collect(),
        });
        if block.rows.len() >= block.cols.len() {
            for c in &block.cols {
                self.block_of[*c] = DETERMINED;
            }
            self.spare.push(id);
        } else {
            self.blocks[id as usize] = block;
        }
    }

    /// Free coordinates the accepted rows do not determine.
    fn undetermined(&self) -> Vec<usize> {
        let mut out = vec![];
        for (i, b) in self.block_of.iter().enumerate() {
            match *b {
                DETERMINED => {}
                NO_BLOCK => out.push(i),
                b => {
                    let k = self.local[i];
                    let s: f64 = self.blocks[b as usize]
                        .rows
                        .iter()
                        .filter(|q| q.start <= k && k < q.start + q.v.len())
                        .map(|q| q.v[k - q.start].powi(2))
                        .sum();
                    if s < 1.0 - 1e-8 {
                        out.push(i);
                    }
                }
            }
        }
        out
    }
}

struct Sparse<'p, 'a> {
    p: &'p Problem<'a>,
    blocks: Blocks,
    /// The equations touching each free coordinate (for `n0` near the threshold).
    eq_of: Vec<Vec<usize>>,
}

/// Why the sparse method stops: the dense method then gives the diagnostics.
enum SparseFailure {
    /// This equation depends (nearly) on the earlier ones.
    Redundant(usize),
}

impl<'p, 'a> Sparse<'p, 'a> {
    fn new(p: &'p Problem<'a>) -> Result<Self, SparseFailure> {
        let mut s = Sparse {
            p,
            blocks: Blocks::new(p.free.len()),
            eq_of: vec![vec![]; p.free.len()],
        };
        for (k, j) in p.crow.iter().enumerate() {
            let a = p.equation(*j);
            for (i, _) in &a {
                s.eq_of[*i].push(k);
            }
            let nr = s.blocks.residual(&a);
            if nr < 1e-7 {
                return Err(SparseFailure::Redundant(*j));
            }
            s.blocks.commit(nr);
        }
        Ok(s)
    }

    /// Norm of the projection of `a` on the motions the equations leave free,
    /// from the equations connected to it.
    fn n0(&self, a: &[(usize, f64)]) -> f64 {
        let mut seen_eq = vec![false; self.p.crow.len()];
        let mut seen_col = std::collections::HashSet::new();
        let mut stack: Vec<usize> = a.iter().map(|(i, _)| *i).collect();
        let mut eqs = vec![];
        while let Some(i) = stack.pop() {
            if !seen_col.insert(i) {
                continue;
            }
            for k in &self.eq_of[i] {
                if !seen_eq[*k] {
                    seen_eq[*k] = true;
                    eqs.push(*k);
                    for (c, _) in self.p.equation(self.p.crow[*k]) {
                        stack.push(c);
                    }
                }
            }
        }
        let mut b = Blocks::new(self.p.free.len());
        for k in eqs {
            let e = self.p.equation(self.p.crow[k]);
            let nr = b.residual(&e);
            if nr > 0.0 {
                b.commit(nr);
            }
        }
        b.residual(a)
    }
}

impl Oracle for Sparse<'_, '_> {
    fn accept(&mut self, c: Coordinate) -> bool {
        let a = self.p.candidate(c);
        let nr = self.blocks.residual(&a);
        if accepted(nr, || self.n0(&a)) {
            // `n0` reuses no state of `blocks`, so its last residual is a's
            self.blocks.commit(nr);
            true
        } else {
            false
        }
    }
}

/// The greedy choice: `dofs_first`, then the scene's choice, each candidate
/// kept when the oracle finds a new direction; stops at `d`.
fn greedy(
    scene: &Scene,
    p: &Problem,
    d: usize,
    oracle: &mut dyn Oracle,
) -> Result<Vec<Coordinate>, ModelError> {
    let (mech, xr, er) = (p.mech, p.xr, p.er);
    let mut chosen: Vec<Coordinate> = vec![];
    let nodal_candidates = || -> Vec<usize> {
        // node by node: a planar angle first (a pinned link is best described by
        // its angle), then the position, then Euler parameters with the largest
        // reference value last (it becomes the dependent one); so a free body's
        // motion is described by one node's position and orientation rather than
        // by positions of other nodes (which become singular at 90°). Then modes.
        let mut v = vec![];
        for n in &mech.nodes {
            match &n.orientation {
                Some(o) if o.len() == 1 => {
                    v.push(o[0]);
                    v.extend(n.position.iter().copied());
                }
                Some(o) => {
                    v.extend(n.position.iter().copied());
                    let mut o = o.clone();
                    o.sort_by(|a, b| mech.x0[*a].abs().total_cmp(&mech.x0[*b].abs()));
                    v.extend(o);
                }
                None => v.extend(n.position.iter().copied()),
            }
        }
        for (_, g) in &mech.mode_groups {
            v.extend(g.iter().copied());
        }
        v.into_iter().filter(|i| xr[*i] == R::Free).collect()
    };
    let free_role = |c: Coordinate| match c {
        Coordinate::Node(i) => (xr[i] == R::Free, mech.x_names[i].clone()),
        Coordinate::Def(j) => (er[j] == R::Free, mech.eps_names[j].clone()),
    };
    for s in &scene.dofs_first {
        for c in resolve(mech, s, "dofs_first")? {
            let (ok, name) = free_role(c);
            if !ok {
                return Err(ModelError::Role {
                    name,
                    message: "is fixed, rigid or prescribed and cannot be a degree of freedom"
                        .into(),
                });
            }
            if !oracle.accept(c) {
                return Err(ModelError::OverConstrained {
                    redundant: vec![format!("{name} (as a degree of freedom)")],
                });
            }
            chosen.push(c);
        }
    }
    let already: std::collections::HashSet<Coordinate> = chosen.iter().copied().collect();
    match &scene.dofs {
        DofChoice::Deformations | DofChoice::NodalCoordinates => {
            if scene.dofs == DofChoice::Deformations {
                let mut real = vec![false; mech.n_eps()];
                for e in &mech.elements {
                    if e.element.type_name() != "Euler-parameter normalization" {
                        for r in &mut real[e.eps_offset..e.eps_offset + e.element.n_eps()] {
                            *r = true;
                        }
                    }
                }
                for j in 0..mech.n_eps() {
                    if chosen.len() == d {
                        break;
                    }
                    if er[j] == R::Free && real[j] && oracle.accept(Coordinate::Def(j)) {
                        chosen.push(Coordinate::Def(j));
                    }
                }
            }
            for i in nodal_candidates() {
                if chosen.len() == d {
                    break;
                }
                if !already.contains(&Coordinate::Node(i)) && oracle.accept(Coordinate::Node(i)) {
                    chosen.push(Coordinate::Node(i));
                }
            }
        }
        DofChoice::Explicit(list) => {
            let mut redundant = vec![];
            for s in list {
                for c in resolve(mech, s, "dofs")? {
                    let (ok, name) = free_role(c);
                    if !ok {
                        return Err(ModelError::Role {
                            name,
                            message:
                                "is fixed, rigid or prescribed and cannot be a degree of freedom"
                                    .into(),
                        });
                    }
                    if oracle.accept(c) {
                        chosen.push(c);
                    } else {
                        redundant.push(name);
                    }
                }
            }
            if !redundant.is_empty() {
                return Err(ModelError::OverConstrained {
                    redundant: redundant
                        .into_iter()
                        .map(|n| format!("{n} (as a degree of freedom)"))
                        .collect(),
                });
            }
        }
    }
    Ok(chosen)
}

/// The choice of DOFs with the dense method.
fn choose_dense(scene: &Scene, p: &Problem) -> Result<Vec<Coordinate>, ModelError> {
    let (mut dense, d) = Dense::new(p)?;
    let chosen = greedy(scene, p, d, &mut dense)?;
    if chosen.len() < d {
        return Err(dense.under_constrained(chosen.len()));
    }
    Ok(chosen)
}

/// The choice of DOFs with the sparse method; errors are worded by the dense
/// method when it fits in memory (so they are the same as for a small model).
/// The local bounds are tried first (`Method::Sparse`): when they decide
/// every step and find no error, their choice is the blocks' choice.
fn choose_sparse(scene: &Scene, p: &Problem, m: Method) -> Result<Vec<Coordinate>, ModelError> {
    if m == Method::Sparse {
        if let Some(chosen) = choose_local(scene, p) {
            return Ok(chosen);
        }
        count_fallback();
    }
    let mut sparse = match Sparse::new(p) {
        Ok(s) => s,
        Err(SparseFailure::Redundant(j)) => {
            if p.fits_dense() {
                choose_dense(scene, p)?;
            }
            return Err(ModelError::OverConstrained {
                redundant: vec![p.mech.eps_names[j].clone()],
            });
        }
    };
    let d = p.free.len() - p.crow.len();
    let chosen = match greedy(scene, p, d, &mut sparse) {
        Ok(c) => c,
        Err(e) => {
            if matches!(e, ModelError::OverConstrained { .. }) && p.fits_dense() {
                choose_dense(scene, p)?;
            }
            return Err(e);
        }
    };
    if chosen.len() < d {
        if p.fits_dense() {
            choose_dense(scene, p)?;
        }
        let names = sparse
            .blocks
            .undetermined()
            .into_iter()
            .map(|k| p.mech.x_names[p.free[k]].clone())
            .collect();
        return Err(ModelError::UnderConstrained {
            count: d - chosen.len(),
            undetermined: names,
        });
    }
    Ok(chosen)
}

/// The rigid motions of the whole mechanism at its reference configuration
/// on the free coordinates (n_free × q, row-major, orthonormal columns):
/// translations and rotations about the centroid of the nodes (ẋ = ω × (x −
/// c), λ̇ = ½ Λ(λ)ᵀ ω from ω = 2Λλ̇ (2.13); planar φ̇ = ω). Deformations are
/// invariant under them, so they are orthogonal to every deformation row
/// that has no fixed coordinate; [`LocalSpan::push`] removes the rest.
fn rigid_motions(p: &Problem) -> (Vec<f64>, usize) {
    let mech = p.mech;
    let spatial = mech.dimension == Dimension::Spatial;
    let dim = if spatial { 3 } else { 2 };
    let nm = if spatial { 6 } else { 3 };
    let nn = mech.nodes.len().max(1) as f64;
    let mut c = [0.0; 3];
    for n in &mech.nodes {
        for (k, i) in n.position.iter().enumerate().take(dim) {
            c[k] += mech.x0[*i] / nn;
        }
    }
    // column-major while built
    let nf = p.free.len();
    let mut cols = vec![vec![0.0; nf]; nm];
    let set = |col: &mut Vec<f64>, i: usize, v: f64| {
        if p.free_pos[i] != usize::MAX {
            col[p.free_pos[i]] = v;
        }
    };
    for n in &mech.nodes {
        let mut r = [0.0; 3];
        for (k, i) in n.position.iter().enumerate().take(dim) {
            r[k] = mech.x0[*i] - c[k];
        }
        for k in 0..dim {
            set(&mut cols[k], n.position[k], 1.0);
        }
        if spatial {
            for w in 0..3 {
                // e_w × r
                let mut e = [0.0; 3];
                e[w] = 1.0;
                let v = [
                    e[1] * r[2] - e[2] * r[1],
                    e[2] * r[0] - e[0] * r[2],
                    e[0] * r[1] - e[1] * r[0],
                ];
                for k in 0..3 {
                    set(&mut cols[3 + w], n.position[k], v[k]);
                }
                if let Some(o) = n.orientation.as_ref().filter(|o| o.len() == 4) {
                    let l = [mech.x0[o[0]], mech.x0[o[1]], mech.x0[o[2]], mech.x0[o[3]]];
                    let lam = flexmb_rotation::generic::lambda_mat(&l);
                    for k in 0..4 {
                        set(&mut cols[3 + w], o[k], 0.5 * lam[w][k]);
                    }
                }
            }
        } else {
            set(&mut cols[2], n.position[0], -r[1]);
            set(&mut cols[2], n.position[1], r[0]);
            if let Some(o) = n.orientation.as_ref().filter(|o| o.len() == 1) {
                set(&mut cols[2], o[0], 1.0);
            }
        }
    }
    let mut kept: Vec<Vec<f64>> = vec![];
    for mut v in cols {
        let n0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        for _ in 0..2 {
            for b in &kept {
                let d: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
                v.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
            }
        }
        let nv = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if nv > 1e-8 * n0.max(1e-300) {
            kept.push(v.into_iter().map(|x| x / nv).collect());
        }
    }
    let q = kept.len();
    let mut z = vec![0.0; nf * q];
    for (k, col) in kept.iter().enumerate() {
        for (i, v) in col.iter().enumerate() {
            z[i * q + k] = *v;
        }
    }
    (z, q)
}

/// The greedy choice on local bounds: every equation independent and every
/// candidate decided, or `None` (the blocks then choose, and word errors).
fn choose_local(scene: &Scene, p: &Problem) -> Option<Vec<Coordinate>> {
    let (z, q) = rigid_motions(p);
    let mut span = LocalSpan::new(p.free.len(), z, q);
    for j in &p.crow {
        let a = p.equation(*j);
        // the blocks' test: redundant below 1e-7
        if span.decide(&a, 1e-7, 0.0) != Verdict::Above {
            return None;
        }
        span.push(a);
    }
    let mut local = Local {
        p,
        span,
        undecided: false,
    };
    let d = p.free.len() - p.crow.len();
    let chosen = greedy(scene, p, d, &mut local).ok()?;
    (!local.undecided && chosen.len() == d).then_some(chosen)
}

/// The oracle of [`choose_local`]; after a step it cannot decide it
/// rejects everything, and its result is discarded.
struct Local<'p, 'a> {
    p: &'p Problem<'a>,
    span: LocalSpan,
    undecided: bool,
}

impl Oracle for Local<'_, '_> {
    fn accept(&mut self, c: Coordinate) -> bool {
        if self.undecided {
            return false;
        }
        let a = self.p.candidate(c);
        // `accepted`: above 1e-6 always, at most 1e-9 never, between by n0
        match self.span.decide(&a, 1e-6, 1e-9) {
            Verdict::Above => {
                self.span.push(a);
                true
            }
            Verdict::Below => false,
            Verdict::Undecided => {
                self.undecided = true;
                false
            }
        }
    }
}

/// The final regularity check on local bounds: true when every row is shown
/// to be independent of the earlier ones by more than `tol`.
fn regular_by_local_bounds(rows: &[Vec<(usize, f64)>], n: usize, tol: f64) -> bool {
    let mut span = LocalSpan::new(n, vec![], 0);
    for r in rows {
        if span.decide(r, tol, 0.0) != Verdict::Above {
            count_fallback();
            return false;
        }
        span.push(r.clone());
    }
    true
}

pub(crate) fn assign(scene: &Scene, mech: &mut Mechanism) -> Result<(), ModelError> {
    let n_x = mech.n_x();
    let n_eps = mech.n_eps();
    let mut xr = vec![R::Free; n_x];
    let mut er = vec![R::Free; n_eps];
    let set = |v: &mut Vec<R>, i: usize, r: R, name: &str| -> Result<(), ModelError> {
        if v[i] != R::Free && v[i] != r {
            return Err(ModelError::Role {
                name: name.to_string(),
                message: "is given two roles (fixed/rigid and prescribed); give it one".into(),
            });
        }
        v[i] = r;
        Ok(())
    };
    for e in &mech.elements {
        if e.element.type_name() == "Euler-parameter normalization" {
            er[e.eps_offset] = R::Rigid;
        }
    }
    for s in &scene.fixed {
        for c in resolve(mech, s, "fixed")? {
            match c {
                Coordinate::Node(i) => set(&mut xr, i, R::Fixed, &mech.x_names[i])?,
                Coordinate::Def(j) => {
                    return Err(ModelError::Role {
                        name: mech.eps_names[j].clone(),
                        message: "a deformation cannot be fixed; list it under `rigid`".into(),
                    })
                }
            }
        }
    }
    // a fixed orientation means all four Euler parameters fixed: its
    // normalization is then an identity, not an equation
    for e in &mech.elements {
        if e.element.type_name() == "Euler-parameter normalization"
            && e.x_index.iter().all(|i| xr[*i] == R::Fixed)
        {
            er[e.eps_offset] = R::Free;
            mech.e_roles[e.eps_offset] = ERole::Dependent;
        }
    }
    for s in &scene.rigid {
        for c in resolve(mech, s, "rigid")? {
            match c {
                Coordinate::Def(j) => set(&mut er, j, R::Rigid, &mech.eps_names[j])?,
                Coordinate::Node(i) => {
                    return Err(ModelError::Role {
                        name: mech.x_names[i].clone(),
                        message: "a nodal coordinate cannot be rigid; list it under `fixed`".into(),
                    })
                }
            }
        }
    }
    for p in &scene.prescribed {
        let cs = resolve(mech, &p.what, "prescribed")?;
        if cs.len() != 1 {
            return Err(ModelError::invalid(
                "prescribed",
                format!(
                    "{:?} selects {} coordinates; prescribe exactly one per entry",
                    p.what,
                    cs.len()
                ),
            ));
        }
        crate::build::check_function(&format!("prescribed {:?}", p.what), &p.function)?;
        let k = mech.inputs.len();
        match cs[0] {
            Coordinate::Node(i) => {
                set(&mut xr, i, R::Input, &mech.x_names[i])?;
                mech.x_roles[i] = XRole::Input(k);
            }
            Coordinate::Def(j) => {
                set(&mut er, j, R::Input, &mech.eps_names[j])?;
                mech.e_roles[j] = ERole::Input(k);
            }
        }
        mech.inputs.push(Input {
            target: cs[0],
            function: p.function.clone(),
        });
    }
    // ---- the constraint Jacobian at the reference configuration, and the DOFs
    let free: Vec<usize> = (0..n_x).filter(|i| xr[*i] == R::Free).collect();
    let mut free_pos = vec![usize::MAX; n_x];
    for (k, i) in free.iter().enumerate() {
        free_pos[*i] = k;
    }
    let crow: Vec<usize> = (0..n_eps)
        .filter(|j| matches!(er[*j], R::Rigid | R::Input))
        .collect();
    let problem = Problem {
        mech,
        xr: &xr,
        er: &er,
        free,
        free_pos,
        crow,
        rows: sparse_jacobian(mech, &mech.x0),
    };
    let method = match METHOD.with(|m| m.get()) {
        Method::Auto if problem.free.len() <= DENSE_MAX_FREE => Method::Dense,
        Method::Auto => Method::Sparse,
        m => m,
    };
    let chosen = match method {
        Method::Sparse | Method::Blocks => choose_sparse(scene, &problem, method)?,
        _ => choose_dense(scene, &problem)?,
    };
    let rows = problem.rows;
    // ---- roles
    for (k, c) in chosen.iter().enumerate() {
        match *c {
            Coordinate::Node(i) => xr[i] = R::Rigid, // marker: DOF
            Coordinate::Def(j) => er[j] = R::Input,  // marker handled below
        }
        match *c {
            Coordinate::Node(i) => mech.x_roles[i] = XRole::Dof(k),
            Coordinate::Def(j) => mech.e_roles[j] = ERole::Dof(k),
        }
    }
    mech.dofs = chosen;
    let mut dep = vec![];
    for i in 0..n_x {
        match (xr[i], mech.x_roles[i]) {
            (R::Fixed, _) => mech.x_roles[i] = XRole::Fixed,
            (R::Free, _) => {
                mech.x_roles[i] = XRole::Dependent(dep.len());
                dep.push(i);
            }
            _ => {}
        }
    }
    for j in 0..n_eps {
        if er[j] == R::Rigid {
            mech.e_roles[j] = ERole::Rigid;
        }
    }
    mech.constraint_rows = (0..n_eps)
        .filter(|j| {
            matches!(
                mech.e_roles[*j],
                ERole::Rigid | ERole::Dof(_) | ERole::Input(_)
            )
        })
        .collect();
    mech.dependent = dep;
    if mech.constraint_rows.len() != mech.dependent.len() {
        return Err(ModelError::invalid(
            "coordinate roles",
            format!(
                "{} equations (rigid, DOF and prescribed deformations) for {} dependent coordinates",
                mech.constraint_rows.len(),
                mech.dependent.len()
            ),
        ));
    }
    // ---- final regularity check of the Jacobian of the equations w.r.t. the
    // dependent coordinates. The sparse method implies it: the equations and
    // the chosen DOFs are n_free independent rows over the free coordinates
    // (every one accepted with a residual), and the DOFs among the nodal
    // coordinates are unit rows, so the rest is regular on the dependent ones.
    // In exact arithmetic, that is: numerically the check still finds an
    // equation that depends on the free coordinates only through rounding
    // errors (its normalized row is noise). Up to DENSE_MAX_DEPENDENT the SVD
    // does it, above Gram–Schmidt on the blocks of the unnormalized rows.
    let nd = mech.dependent.len();
    let mut dep_pos = vec![usize::MAX; n_x];
    for (k, i) in mech.dependent.iter().enumerate() {
        dep_pos[*i] = k;
    }
    let forced = matches!(METHOD.with(|m| m.get()), Method::Sparse | Method::Blocks);
    if method != Method::Dense && (nd > DENSE_MAX_DEPENDENT || forced) {
        // in the greedy's order (equations, then the chosen deformations), in
        // which the blocks stay small
        let mut order: Vec<usize> = mech
            .constraint_rows
            .iter()
            .copied()
            .filter(|j| !matches!(mech.e_roles[*j], ERole::Dof(_)))
            .collect();
        order.extend(mech.dofs.iter().filter_map(|c| match c {
            Coordinate::Def(j) => Some(*j),
            Coordinate::Node(_) => None,
        }));
        let dep_rows: Vec<Vec<(usize, f64)>> = order
            .iter()
            .map(|j| {
                rows[*j]
                    .iter()
                    .filter(|(i, _)| dep_pos[*i] != usize::MAX)
                    .map(|(i, v)| (dep_pos[*i], *v))
                    .collect()
            })
            .collect();
        let norm = |r: &[(usize, f64)]| r.iter().map(|(_, v)| v * v).sum::<f64>().sqrt();
        let max = dep_rows.iter().map(|r| norm(r)).fold(0.0f64, f64::max);
        let tol = RANK_TOL * max.max(1e-300);
        if method == Method::Sparse && regular_by_local_bounds(&dep_rows, nd, tol) {
            return Ok(());
        }
        let mut blocks = Blocks::new(nd);
        let mut deficient = 0;
        for r in &dep_rows {
            let nr = blocks.residual(r);
            if nr > tol {
                blocks.commit(nr);
            } else {
                deficient += 1;
            }
        }
        if deficient > 0 {
            return Err(ModelError::UnderConstrained {
                count: deficient,
                undetermined: blocks
                    .undetermined()
                    .into_iter()
                    .map(|k| mech.x_names[mech.dependent[k]].clone())
                    .collect(),
            });
        }
        return Ok(());
    }
    check_dense("the Jacobian of the equations", nd, nd, 4)?;
    let mut jd = Mat::<f64>::zeros(mech.constraint_rows.len(), nd);
    for (r, j) in mech.constraint_rows.iter().enumerate() {
        for (i, v) in &rows[*j] {
            if dep_pos[*i] != usize::MAX {
                jd[(r, dep_pos[*i])] = *v;
            }
        }
    }
    let (rank, left, right) = null_spaces(
        &jd,
        "the Jacobian of the equations on the dependent coordinates",
    )?;
    if rank < mech.dependent.len() {
        let rn: Vec<String> = mech
            .constraint_rows
            .iter()
            .map(|j| mech.eps_names[*j].clone())
            .collect();
        let cn: Vec<String> = mech
            .dependent
            .iter()
            .map(|i| mech.x_names[*i].clone())
            .collect();
        let _ = names_in(&left, &rn);
        return Err(ModelError::UnderConstrained {
            count: mech.dependent.len() - rank,
            undetermined: names_in(&right, &cn),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    /// Builds with the given method: the DOF names and the roles, or the error.
    fn build_with(scene: &Scene, dir: Option<&Path>, m: Method) -> Result<String, String> {
        METHOD.with(|c| c.set(m));
        let r = scene.build(dir);
        METHOD.with(|c| c.set(Method::Auto));
        r.map(|mech| {
            let names: Vec<&str> = mech.dofs.iter().map(|c| mech.coordinate_name(*c)).collect();
            format!(
                "dofs {names:?}\nx roles {:?}\ne roles {:?}\ndependent {:?}\nrows {:?}",
                mech.x_roles, mech.e_roles, mech.dependent, mech.constraint_rows
            )
        })
        .map_err(|e| e.to_string())
    }

    fn same(scene: &Scene, dir: Option<&Path>, what: &str) -> bool {
        let d = build_with(scene, dir, Method::Dense);
        let s = build_with(scene, dir, Method::Sparse);
        assert_eq!(d, s, "{what}: the sparse choice differs from the dense one");
        let b = build_with(scene, dir, Method::Blocks);
        assert_eq!(
            d, b,
            "{what}: the blocks' choice differs from the dense one"
        );
        d.is_ok()
    }

    fn fallbacks() -> usize {
        BLOCK_FALLBACKS.with(|c| c.get())
    }

    fn root() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    #[test]
    fn sparse_choice_equals_dense_on_every_fixture() {
        let dir = root().join("fixtures/scenes");
        let mut n = 0;
        for f in std::fs::read_dir(&dir).unwrap() {
            let path = f.unwrap().path();
            if path.extension().is_some_and(|e| e == "ron") {
                let scene = Scene::load(&path).unwrap();
                assert!(same(&scene, Some(&dir), &path.display().to_string()));
                n += 1;
            }
        }
        assert!(n >= 9, "{n} fixtures");
    }

    /// Every literal scene in the tests and doc examples of the workspace
    /// (raw strings that parse as a scene; those built with `format!` are skipped).
    #[test]
    fn sparse_choice_equals_dense_on_the_literal_test_scenes() {
        let files = [
            "crates/model/tests/bad_input.rs",
            "crates/model/src/lib.rs",
            "crates/kinematics/tests/transfer_functions.rs",
            "crates/kinematics/src/lib.rs",
            "crates/linearize/tests/analytic.rs",
            "crates/linearize/src/lib.rs",
            "crates/dynamics/src/eom.rs",
            "crates/dynamics/src/nodal_eom.rs",
            "crates/dynamics/src/lib.rs",
        ];
        let (mut parsed, mut built) = (0, 0);
        for f in files {
            let Ok(text) = std::fs::read_to_string(root().join(f)) else {
                continue;
            };
            // doc examples: without their comment markers
            let text: String = text
                .lines()
                .map(|l| {
                    let t = l.trim_start();
                    t.strip_prefix("//! ")
                        .or_else(|| t.strip_prefix("/// "))
                        .unwrap_or(l)
                })
                .collect::<Vec<_>>()
                .join("\n");
            let mut rest = text.as_str();
            while let Some(a) = rest.find("r#\"(") {
                let body = &rest[a + 3..];
                let Some(b) = body.find("\"#") else { break };
                let lit = &body[..b];
                // a format! template without arguments in the scene itself
                let unescaped = lit.replace("{{", "{").replace("}}", "}");
                if let Ok(scene) =
                    Scene::from_ron_str(lit).or_else(|_| Scene::from_ron_str(&unescaped))
                {
                    parsed += 1;
                    if same(&scene, None, f) {
                        built += 1;
                    }
                }
                rest = &body[b..];
            }
        }
        assert!(parsed >= 8 && built >= 8, "{parsed} scenes, {built} valid");
    }

    /// A small random mechanism: beams (some split), trusses and hinges between
    /// random nodes, a fixed node, random rigid deformations, either DOF choice.
    fn random_scene(seed: u64) -> String {
        let mut s = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = move |n: u64| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 33) % n
        };
        let spatial = next(2) == 1;
        let nn = 3 + next(4) as usize;
        let mut nodes = String::new();
        let mut used = vec![];
        for k in 0..nn {
            let mut p;
            loop {
                p = if spatial {
                    vec![next(4), next(4), next(3)]
                } else {
                    vec![next(4), next(4)]
                };
                if !used.contains(&p) {
                    break;
                }
            }
            used.push(p.clone());
            let at: Vec<String> = p.iter().map(|v| format!("{}.0", v)).collect();
            nodes += &format!("(id: \"N{k}\", at: [{}]), ", at.join(", "));
        }
        let mut elements = String::new();
        let mut rigid = vec![];
        let ne = 2 + next(6) as usize;
        for k in 0..ne {
            let a = next(nn as u64) as usize;
            let mut b = next(nn as u64) as usize;
            if b == a {
                b = (a + 1) % nn;
            }
            let kind = next(6);
            let id = format!("e{k}");
            match kind {
                0..=2 => {
                    let n = 1 + next(3);
                    elements += &format!("(id: \"{id}\", type: Beam((nodes: (\"N{a}\", \"N{b}\"), material: \"m\", section: \"s\", n: {n}))), ");
                    match next(4) {
                        0 => rigid.push(format!("Def(\"{id}\", \"elongation\")")),
                        1 => rigid.push(format!("Def(\"{id}\", \"*\")")),
                        _ => {}
                    }
                }
                3 | 4 => {
                    let n = 1 + next(2);
                    elements += &format!("(id: \"{id}\", type: Truss(nodes: (\"N{a}\", \"N{b}\"), ea: 1.0e6, mass_per_length: 1.0, n: {n})), ");
                    if next(2) == 0 {
                        rigid.push(format!("Def(\"{id}\", \"*\")"));
                    }
                }
                _ => {
                    let axis = if spatial {
                        ", axis: Some([0.0, 0.0, 1.0])"
                    } else {
                        ""
                    };
                    elements += &format!(
                        "(id: \"{id}\", type: Hinge(nodes: (\"N{a}\", \"N{b}\"){axis})), "
                    );
                    if next(2) == 0 {
                        rigid.push(format!("Def(\"{id}\", \"*\")"));
                    }
                }
            }
        }
        let f = next(nn as u64);
        let mut fixed = format!("Node(\"N{f}\")");
        if next(3) == 0 {
            fixed += &format!(", Coord(\"N{}\", Position)", (f + 1) % nn as u64);
        }
        let dofs = if next(3) == 0 {
            "NodalCoordinates"
        } else {
            "Deformations"
        };
        format!(
            "(dimension: {}, materials: {{ \"m\": (e: 2.0e11, rho: 7800.0) }}, sections: {{ \"s\": Rectangle(by: 0.02, bz: 0.01) }}, nodes: [{nodes}], elements: [{elements}], fixed: [{fixed}], rigid: [{}], dofs: {dofs})",
            if spatial { "Spatial" } else { "Planar" },
            rigid.join(", ")
        )
    }

    #[test]
    fn sparse_choice_equals_dense_on_random_mechanisms() {
        let (mut ok, mut err) = (0, 0);
        for seed in 0..400 {
            let text = random_scene(seed);
            let scene = Scene::from_ron_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            if same(&scene, None, &text) {
                ok += 1;
            } else {
                err += 1;
            }
        }
        assert!(ok >= 80 && err >= 40, "{ok} valid, {err} rejected");
    }

    /// The over- and under-constrained cases of tests/bad_input.rs, and a
    /// zero equation: the sparse method names the same culprits.
    #[test]
    fn sparse_diagnostics_name_the_same_culprits() {
        let base = r#"(
    dimension: Planar,
    materials: { "al": (e: 7.0e10, rho: 2700.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [1.0, 1.0]) ],
    elements: [
        (id: "ab", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))),
        (id: "bc", type: Beam((nodes: ("B", "C"), material: "al", section: "bar"))),
    ],
    fixed: [ Node("A") ],
    rigid: [ Def("ab", "elongation"), Def("bc", "elongation") ],
)"#;
        let cases = [
            ("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\"), Coord(\"C\", Position) ],\n    dofs: Explicit([Def(\"ab\", \"bending_p\"), Def(\"ab\", \"bending_q\"), Def(\"bc\", \"bending_p\"), Def(\"bc\", \"bending_q\"), Coord(\"B\", X)]),", "redundant"),
            ("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\") ],\n    dofs: Explicit([Def(\"ab\", \"bending_p\")]),", "C.x"),
            ("rigid: [ Def(\"ab\", \"elongation\"), Def(\"bc\", \"elongation\") ],", "rigid: [ Def(\"ab\", \"*\"), Def(\"bc\", \"*\") ],\n    dofs: Explicit([Def(\"ab\", \"elongation\")]),", "ab.elongation"),
            ("fixed: [ Node(\"A\") ],", "fixed: [ Node(\"A\"), Node(\"B\") ],", "ab.elongation"),
        ];
        for (from, to, named) in cases {
            let scene = Scene::from_ron_str(&base.replacen(from, to, 1)).unwrap();
            assert!(!same(&scene, None, to), "{to}");
            let e = build_with(&scene, None, Method::Sparse).unwrap_err();
            assert!(e.contains(named), "{e}");
        }
    }

    /// Chains without supports (the tumbling beam, spatial and planar, with
    /// either choice of DOFs): the same choice as the dense SVD, decided by
    /// the local bounds alone (no fallback to the blocks, which grow with
    /// the cube of n), except where a DOF candidate is determined only
    /// through the whole chain (nodal coordinates as DOFs with rigid
    /// elongations: the end node's x follows from all the elongations).
    #[test]
    fn free_chains_are_chosen_locally_as_the_dense_svd_chooses() {
        let tumbling =
            std::fs::read_to_string(root().join("fixtures/scenes/tumbling_beam.ron")).unwrap();
        let planar = r#"(
    dimension: Planar,
    materials: { "al": (e: 7.0e10, rho: 2700.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.5]) ],
    elements: [ (id: "arm", type: Beam((nodes: ("A", "B"), material: "al", section: "bar", n: 2))) ],
    rigid: [ Def("arm", "elongation") ],
)"#;
        let rigid = "rigid: [ Def(\"beam\", \"elongation\"), Def(\"beam\", \"torsion\") ],";
        let nodal = |t: &str| t.replace(")),\n    ],", ")),\n    ],\n    dofs: NodalCoordinates,");
        let mut cases = vec![];
        for n in [3, 12, 45] {
            let t = tumbling.replace("n: 2)", &format!("n: {n})"));
            cases.push((t.clone(), true));
            cases.push((t.replace(rigid, ""), true));
            cases.push((nodal(&t.replace(rigid, "")), true));
            cases.push((nodal(&t), n < 20));
            let pl = planar.replace("n: 2)", &format!("n: {n})"));
            cases.push((pl.clone(), true));
            cases.push((
                pl.replace(
                    "rigid: [ Def(\"arm\", \"elongation\") ],",
                    "dofs: NodalCoordinates,",
                ),
                true,
            ));
        }
        for (text, local) in &cases {
            let scene = Scene::from_ron_str(text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            let before = fallbacks();
            assert!(same(&scene, None, text), "{text}");
            assert_eq!(fallbacks() == before, *local, "local bounds:\n{text}");
        }
        assert_eq!(
            cases
                .iter()
                .filter(|c| c.0.contains("NodalCoordinates"))
                .count(),
            9
        );
    }

    /// `flexmb info`'s work on large free chains (cargo test --release -- --ignored).
    #[test]
    #[ignore]
    fn timing_free_chain() {
        let text =
            std::fs::read_to_string(root().join("fixtures/scenes/tumbling_beam.ron")).unwrap();
        for n in [400, 1000, 5000, 20000] {
            let scene = Scene::from_ron_str(&text.replace("n: 2)", &format!("n: {n})"))).unwrap();
            let before = fallbacks();
            let t = std::time::Instant::now();
            let m = scene.build(None).unwrap();
            eprintln!(
                "n = {n}: {:?}, {} DOFs, fallbacks {}",
                t.elapsed(),
                m.n_dof(),
                fallbacks() - before
            );
        }
    }

    #[test]
    fn a_dense_matrix_too_large_is_refused_with_its_size() {
        let e = check_dense_against("the constraint Jacobian", 720_000, 840_000, 1, 6 << 30)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("720000 × 840000")
                && e.contains("4.8 TB")
                && e.contains("604800000000 elements")
                && e.contains("6.4 GB"),
            "{e}"
        );
        assert!(check_dense_against("x", 1000, 1000, 2, 6 << 30).is_ok());
    }
}
