//! The sparse choice of DOFs (thesis (6.4)) for large models: the same
//! greedy choice as the dense SVD, with the accepted rows kept in connected
//! blocks that are eliminated as they become determined.

use super::local::choose_local;
use super::*;

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

pub(super) struct Blocks {
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
    pub(super) fn new(n_free: usize) -> Self {
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
    pub(super) fn residual(&mut self, a: &[(usize, f64)]) -> f64 {
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
    pub(super) fn commit(&mut self, nr: f64) {
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
    pub(super) fn undetermined(&self) -> Vec<usize> {
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

/// The choice of DOFs with the sparse method; errors are worded by the dense
/// method when it fits in memory (so they are the same as for a small model).
/// The local bounds are tried first (`Method::Sparse`): when they decide
/// every step and find no error, their choice is the blocks' choice.
pub(super) fn choose_sparse(
    scene: &Scene,
    p: &Problem,
    m: Method,
) -> Result<Vec<Coordinate>, ModelError> {
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
