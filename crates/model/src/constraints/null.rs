//! A localized basis of the left null space of a sparse matrix with
//! unit-norm rows: the redundant combinations of its rows, each as sparse as
//! the method below makes it.
//!
//! 1. **Peeling.** A row with an entry in a column that no other remaining
//!    row touches cannot take part in a null combination (`yᵀA = 0` in that
//!    column forces its coefficient to zero): it is removed, and the removal
//!    is repeated until no row has such a private column. An entry counts
//!    when it exceeds [`PEEL_TOL`] (rows have unit norm); a smaller entry is
//!    treated as absent, which only keeps more rows. An open chain peels away
//!    completely; what remains are the closed loops.
//! 2. **Blocks.** The remaining rows split into connected blocks (rows that
//!    share a column); blocks are independent, each gets its own dense SVD
//!    ([`flexmb_linalg::svd`], faer), and its left singular vectors with
//!    singular value ≤ [`RANK_TOL`] × max(σ₁, 1) span its left null space.
//! 3. **Localization.** The null-space basis of a block is not unique; it is
//!    rotated toward sparsity by Gauss–Jordan elimination to reduced row
//!    echelon form (pivot: the largest remaining entry), which separates loops
//!    that share no equation, and then by pairwise support reduction: a basis
//!    vector is replaced by its combination with another one whenever that
//!    cancels entries and leaves fewer nonzeros. The span is unchanged by
//!    both.
//! 4. **Balls** (blocks of two or more null vectors and at most
//!    [`BALL_MAX_ROWS`] rows): loops that share equations (two cells of a
//!    ladder, the thesis's two parallelograms sharing the CrossBar) need
//!    more than pairwise steps. Around every unit (an element, or one fixed
//!    coordinate), the ball of units within graph distance r grows (r = 1,
//!    2, …) until the rows of the ball, peeled within the ball, have a null
//!    combination of their own; those (localized as in 3) are candidates,
//!    taken smallest ball first while independent of those taken (Gram–
//!    Schmidt, relative residual 1e-6), and the basis of 3 completes them if
//!    needed. A ball's null vector is one of the block: its rows vanish
//!    outside the ball's columns.

use crate::roles::{check_dense, RANK_TOL};
use crate::ModelError;
use faer::Mat;

/// Entries below this × the row's norm do not make a column private.
pub(crate) const PEEL_TOL: f64 = 1e-6;

/// Entries below this × the largest of a localized vector count as zero.
pub(crate) const SUPPORT_TOL: f64 = 1e-8;

/// The left null space, localized: each vector as (row, weight) pairs with
/// the largest |weight| equal to 1, sorted by decreasing |weight|.
pub(crate) struct NullSpace {
    /// The vectors.
    pub vectors: Vec<Vec<(usize, f64)>>,
    /// Rows of the largest block that went to the dense SVD.
    pub largest_block: usize,
    /// Rows left after peeling.
    pub core_rows: usize,
}

/// The localized left null space of `rows` (sparse, over `n_cols` columns;
/// singular values count as zero below [`RANK_TOL`] × the largest row norm
/// or σ₁, so rows should be of comparable norm). `what` names the matrix in
/// errors.
pub(crate) fn left_null_space(
    rows: &[Vec<(usize, f64)>],
    units: &[usize],
    n_cols: usize,
    what: &str,
) -> Result<NullSpace, ModelError> {
    let scale = rows.iter().map(|r| norm(r)).fold(0.0f64, f64::max);
    let all: Vec<usize> = (0..rows.len()).collect();
    let core = peel(rows, &all);
    let blocks = blocks(rows, &core, n_cols);
    let mut vectors = vec![];
    let mut largest_block = 0;
    for b in &blocks {
        largest_block = largest_block.max(b.len());
        for v in block_null_space(rows, b, units, scale, what)? {
            vectors.push(v);
        }
    }
    vectors.sort_by_key(|v| v.iter().map(|(r, _)| *r).min());
    Ok(NullSpace {
        vectors,
        largest_block,
        core_rows: core.len(),
    })
}

/// The rows of `subset` that remain after repeatedly removing rows with a
/// column that no other remaining row of `subset` touches.
fn peel(rows: &[Vec<(usize, f64)>], subset: &[usize]) -> Vec<usize> {
    let mut local: std::collections::HashMap<usize, usize> = Default::default();
    let mut sig: Vec<Vec<usize>> = Vec::with_capacity(subset.len());
    for r in subset {
        let n = norm(&rows[*r]);
        let cs: Vec<usize> = rows[*r]
            .iter()
            .filter(|(_, v)| v.abs() > PEEL_TOL * n)
            .map(|(c, _)| {
                let next = local.len();
                *local.entry(*c).or_insert(next)
            })
            .collect();
        sig.push(cs);
    }
    let mut count = vec![0usize; local.len()];
    let mut col_rows: Vec<Vec<usize>> = vec![vec![]; local.len()];
    for (k, cs) in sig.iter().enumerate() {
        for c in cs {
            count[*c] += 1;
            col_rows[*c].push(k);
        }
    }
    let mut alive = vec![true; subset.len()];
    let mut stack: Vec<usize> = (0..subset.len())
        .filter(|k| sig[*k].iter().any(|c| count[*c] == 1))
        .collect();
    while let Some(k) = stack.pop() {
        if !alive[k] {
            continue;
        }
        alive[k] = false;
        for c in &sig[k] {
            count[*c] -= 1;
            if count[*c] == 1 {
                if let Some(&o) = col_rows[*c].iter().find(|o| alive[**o]) {
                    stack.push(o);
                }
            }
        }
    }
    (0..subset.len())
        .filter(|k| alive[*k])
        .map(|k| subset[k])
        .collect()
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The connected blocks of the `core` rows (linked through any shared
/// column), each ascending; blocks in order of their first row.
fn blocks(rows: &[Vec<(usize, f64)>], core: &[usize], n_cols: usize) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..core.len()).collect();
    let mut owner = vec![usize::MAX; n_cols];
    for (k, r) in core.iter().enumerate() {
        for (c, _) in &rows[*r] {
            if owner[*c] == usize::MAX {
                owner[*c] = k;
            } else {
                let (a, b) = (find(&mut parent, owner[*c]), find(&mut parent, k));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut index = vec![usize::MAX; core.len()];
    let mut out: Vec<Vec<usize>> = vec![];
    for k in 0..core.len() {
        let root = find(&mut parent, k);
        if index[root] == usize::MAX {
            index[root] = out.len();
            out.push(vec![]);
        }
        out[index[root]].push(core[k]);
    }
    out
}

/// Blocks up to this many rows are localized by balls as well.
pub(crate) const BALL_MAX_ROWS: usize = 1500;

/// The left null space of the rows `sub` (a dense SVD), each vector over
/// `sub` (local indices) and localized by [`localize`].
fn dense_null(
    rows: &[Vec<(usize, f64)>],
    sub: &[usize],
    scale: f64,
    what: &str,
) -> Result<Vec<Vec<f64>>, ModelError> {
    let mut cols: Vec<usize> = sub
        .iter()
        .flat_map(|r| rows[*r].iter().map(|(c, _)| *c))
        .collect();
    cols.sort_unstable();
    cols.dedup();
    let m = sub.len();
    check_dense(what, m, cols.len().max(m), 3)?;
    let z = if cols.is_empty() {
        // zero rows only: each is redundant by itself
        Mat::<f64>::identity(m, m)
    } else {
        let mut a = Mat::<f64>::zeros(m, cols.len());
        for (i, r) in sub.iter().enumerate() {
            for (c, v) in &rows[*r] {
                let j = cols.binary_search(c).expect("collected");
                a[(i, j)] += *v;
            }
        }
        // U must be complete (m × m): the thin SVD gives it when m ≤ columns
        let svd = if m <= cols.len() {
            flexmb_linalg::thin_svd
        } else {
            flexmb_linalg::svd
        };
        let d = svd(a.as_ref()).map_err(|source| ModelError::Computation {
            what: what.to_string(),
            source,
        })?;
        let tol = RANK_TOL * d.s.first().copied().unwrap_or(0.0).max(scale);
        let rank = d.s.iter().filter(|s| **s > tol).count();
        Mat::from_fn(m, m - rank, |i, j| d.u[(i, rank + j)])
    };
    let mut basis: Vec<Vec<f64>> = (0..z.ncols())
        .map(|j| (0..m).map(|i| z[(i, j)]).collect())
        .collect();
    localize(&mut basis);
    Ok(basis)
}

/// The localized left null vectors of one block (global row indices).
fn block_null_space(
    rows: &[Vec<(usize, f64)>],
    block: &[usize],
    units: &[usize],
    scale: f64,
    what: &str,
) -> Result<Vec<Vec<(usize, f64)>>, ModelError> {
    let mut basis = dense_null(rows, block, scale, what)?;
    if basis.len() >= 2 && block.len() <= BALL_MAX_ROWS {
        basis = by_balls(rows, block, units, basis, scale, what)?;
    }
    Ok(basis
        .into_iter()
        .map(|v| {
            let mut s: Vec<(usize, f64)> = v
                .iter()
                .enumerate()
                .filter(|(_, w)| **w != 0.0)
                .map(|(i, w)| (block[i], *w))
                .collect();
            s.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()).then(a.0.cmp(&b.0)));
            s
        })
        .collect())
}

/// Sequential localization by balls: around every unit (an element, or a
/// support), the ball of units within graph distance r (units are adjacent
/// when their rows share a column) grows until its own rows have a null
/// combination; those combinations (localized within the ball) are
/// candidates, taken smallest ball first while they are independent of the
/// ones taken. `fallback` (the block's localized basis) completes the basis
/// if the balls do not. Every candidate is a null vector of the block: a
/// ball's rows vanish outside the ball's columns.
fn by_balls(
    rows: &[Vec<(usize, f64)>],
    block: &[usize],
    units: &[usize],
    fallback: Vec<Vec<f64>>,
    scale: f64,
    what: &str,
) -> Result<Vec<Vec<f64>>, ModelError> {
    let k = fallback.len();
    let m = block.len();
    // units of the block and their local rows
    let mut ids: Vec<usize> = block.iter().map(|r| units[*r]).collect();
    ids.sort_unstable();
    ids.dedup();
    let nu = ids.len();
    let mut unit_rows: Vec<Vec<usize>> = vec![vec![]; nu];
    for (i, r) in block.iter().enumerate() {
        unit_rows[ids.binary_search(&units[*r]).expect("collected")].push(i);
    }
    // adjacency through shared columns
    let mut col_units: std::collections::HashMap<usize, Vec<usize>> = Default::default();
    for (u, rs) in unit_rows.iter().enumerate() {
        for i in rs {
            for (c, _) in &rows[block[*i]] {
                let e = col_units.entry(*c).or_default();
                if e.last() != Some(&u) {
                    e.push(u);
                }
            }
        }
    }
    let mut adj: Vec<Vec<usize>> = vec![vec![]; nu];
    for us in col_units.values() {
        for a in us {
            for b in us {
                if a != b && !adj[*a].contains(b) {
                    adj[*a].push(*b);
                }
            }
        }
    }
    // candidates (ball size, vector over the block)
    let mut seen: std::collections::HashSet<Vec<usize>> = Default::default();
    let mut candidates: Vec<(usize, Vec<f64>)> = vec![];
    for center in 0..nu {
        let mut dist = vec![usize::MAX; nu];
        dist[center] = 0;
        let mut ball = vec![center];
        let mut frontier = vec![center];
        loop {
            let mut next = vec![];
            for u in &frontier {
                for v in &adj[*u] {
                    if dist[*v] == usize::MAX {
                        dist[*v] = dist[*u] + 1;
                        next.push(*v);
                    }
                }
            }
            if next.is_empty() {
                break;
            }
            ball.extend(&next);
            frontier = next;
            if ball.len() == nu {
                break; // the whole block: the fallback
            }
            let mut key = ball.clone();
            key.sort_unstable();
            if !seen.insert(key.clone()) {
                continue;
            }
            // only the rows of the ball that survive peeling within it can
            // combine to zero (most balls peel away completely)
            let global: Vec<usize> = key
                .iter()
                .flat_map(|u| unit_rows[*u].iter().map(|i| block[*i]))
                .collect();
            let global = peel(rows, &global);
            if global.is_empty() {
                continue;
            }
            let sub: Vec<usize> = global
                .iter()
                .map(|r| block.binary_search(r).expect("in the block"))
                .collect();
            let found = dense_null(rows, &global, scale, what)?;
            if !found.is_empty() {
                for v in found {
                    let mut w = vec![0.0; m];
                    for (x, i) in v.iter().zip(&sub) {
                        w[*i] = *x;
                    }
                    candidates.push((key.len(), w));
                }
                break;
            }
        }
    }
    candidates.sort_by_key(|(size, v)| (*size, support(v)));
    let mut taken: Vec<Vec<f64>> = vec![];
    let mut ortho: Vec<Vec<f64>> = vec![];
    for v in candidates.into_iter().map(|(_, v)| v).chain(fallback) {
        if taken.len() == k {
            break;
        }
        let mut r = v.clone();
        let n0 = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        for _ in 0..2 {
            for q in &ortho {
                let p: f64 = r.iter().zip(q).map(|(a, b)| a * b).sum();
                for (x, y) in r.iter_mut().zip(q) {
                    *x -= p * y;
                }
            }
        }
        let nr = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        if nr > 1e-6 * n0 {
            ortho.push(r.into_iter().map(|x| x / nr).collect());
            taken.push(v);
        }
    }
    Ok(taken)
}

fn norm(r: &[(usize, f64)]) -> f64 {
    r.iter().map(|(_, v)| v * v).sum::<f64>().sqrt()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Scales `v` to a largest |entry| of 1 with a positive largest entry, and
/// zeroes entries below [`SUPPORT_TOL`].
fn normalize(v: &mut [f64]) {
    let (mut big, mut at) = (0.0f64, 0);
    for (i, x) in v.iter().enumerate() {
        if x.abs() > big {
            (big, at) = (x.abs(), i);
        }
    }
    if big == 0.0 {
        return;
    }
    let s = v[at].signum() / big;
    for x in v.iter_mut() {
        *x *= s;
        if x.abs() < SUPPORT_TOL {
            *x = 0.0;
        }
    }
}

fn support(v: &[f64]) -> usize {
    v.iter().filter(|x| **x != 0.0).count()
}

/// Rotates the basis (rows of the k × m `basis`) toward sparsity without
/// changing its span: reduced row echelon form with complete pivoting, then
/// pairwise support reduction (see the module documentation).
fn localize(basis: &mut [Vec<f64>]) {
    let k = basis.len();
    if k == 0 {
        return;
    }
    let m = basis[0].len();
    // ---- Gauss–Jordan to reduced row echelon form
    let mut pivot_used = vec![false; m];
    for i in 0..k {
        let (mut best, mut at) = (0.0f64, (i, 0));
        for (r, v) in basis.iter().enumerate().skip(i) {
            for (c, x) in v.iter().enumerate() {
                if !pivot_used[c] && x.abs() > best {
                    (best, at) = (x.abs(), (r, c));
                }
            }
        }
        if best == 0.0 {
            break;
        }
        basis.swap(i, at.0);
        let c = at.1;
        pivot_used[c] = true;
        let p = basis[i][c];
        for x in basis[i].iter_mut() {
            *x /= p;
        }
        let pivot_row = basis[i].clone();
        for (r, v) in basis.iter_mut().enumerate() {
            if r != i && v[c] != 0.0 {
                let f = v[c];
                for (x, y) in v.iter_mut().zip(&pivot_row) {
                    *x -= f * y;
                }
                v[c] = 0.0;
            }
        }
    }
    for v in basis.iter_mut() {
        normalize(v);
    }
    // ---- pairwise support reduction: v_j ← v_j − (v_j[c]/v_i[c]) v_i
    // where that leaves fewer nonzeros; every pass lowers the total support
    if k == 1 {
        return;
    }
    let mut improved = true;
    let mut passes = 0;
    while improved && passes < 4 * k {
        improved = false;
        passes += 1;
        for j in 0..k {
            for i in 0..k {
                if i == j {
                    continue;
                }
                let mut best: Option<(usize, Vec<f64>)> = None;
                let bi = max_abs(&basis[i]);
                for c in 0..m {
                    let (vi, vj) = (basis[i][c], basis[j][c]);
                    if vj == 0.0 || vi.abs() < 0.1 * bi {
                        continue;
                    }
                    let f = vj / vi;
                    let mut w: Vec<f64> = basis[j]
                        .iter()
                        .zip(&basis[i])
                        .map(|(a, b)| a - f * b)
                        .collect();
                    w[c] = 0.0;
                    normalize(&mut w);
                    let s = support(&w);
                    let limit = best.as_ref().map_or(support(&basis[j]), |(s, _)| *s);
                    if s > 0 && s < limit {
                        best = Some((s, w));
                    }
                }
                if let Some((_, w)) = best {
                    basis[j] = w;
                    improved = true;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(v: &[(usize, f64)]) -> Vec<(usize, f64)> {
        let n = v.iter().map(|(_, x)| x * x).sum::<f64>().sqrt();
        v.iter().map(|(c, x)| (*c, x / n)).collect()
    }

    /// The rows of a graph's incidence matrix (edges as rows, nodes as
    /// columns, one node grounded i.e. dropped): the left null space is the
    /// cycle space, of dimension edges − nodes + components (Euler).
    fn incidence(edges: &[(usize, usize)], ground: usize) -> Vec<Vec<(usize, f64)>> {
        edges
            .iter()
            .map(|&(a, b)| {
                let mut r = vec![];
                if a != ground {
                    r.push((a, 1.0));
                }
                if b != ground {
                    r.push((b, -1.0));
                }
                r.sort_by_key(|x| x.0);
                unit(&r)
            })
            .collect()
    }

    #[test]
    fn a_ladder_of_two_cells_gives_the_two_cells() {
        // nodes 0-1-2 on top, 3-4-5 below; rungs 0-3, 1-4, 2-5. The rung 1-4
        // is shared by the cells {0-1, 1-4, 4-3, 3-0} and {1-2, 2-5, 5-4, 4-1}
        let edges = [(0, 1), (1, 2), (3, 4), (4, 5), (0, 3), (1, 4), (2, 5)];
        let ns = left_null_space(
            &incidence(&edges, 0),
            &(0..7).collect::<Vec<_>>(),
            6,
            "test",
        )
        .unwrap();
        assert_eq!(ns.vectors.len(), 7 - 6 + 1);
        let mut cells: Vec<Vec<usize>> = ns
            .vectors
            .iter()
            .map(|v| {
                let mut e: Vec<usize> = v.iter().map(|(r, _)| *r).collect();
                e.sort();
                e
            })
            .collect();
        cells.sort();
        assert_eq!(cells, vec![vec![0, 2, 4, 5], vec![1, 3, 5, 6]]);
        for v in &ns.vectors {
            assert!((v[0].1.abs() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_tree_peels_away_and_disjoint_cycles_separate() {
        // a tree: no cycle, all rows peeled
        let tree = incidence(&[(0, 1), (1, 2), (1, 3), (3, 4)], 0);
        let ns = left_null_space(&tree, &[0, 1, 2, 3], 5, "test").unwrap();
        assert!(ns.vectors.is_empty());
        assert_eq!(ns.core_rows, 0);
        // two triangles joined by a bridge 2-3
        let edges = [(0, 1), (1, 2), (2, 0), (2, 3), (3, 4), (4, 5), (5, 3)];
        let ns = left_null_space(
            &incidence(&edges, 0),
            &(0..7).collect::<Vec<_>>(),
            6,
            "test",
        )
        .unwrap();
        let sets: Vec<Vec<usize>> = ns
            .vectors
            .iter()
            .map(|v| {
                let mut e: Vec<usize> = v.iter().map(|(r, _)| *r).collect();
                e.sort();
                e
            })
            .collect();
        assert_eq!(sets, vec![vec![0, 1, 2], vec![4, 5, 6]]);
        // the bridge has no private column, so it is not peeled: one block,
        // whose two cycles the localization separates (the bridge's weight
        // is zero in both)
        assert_eq!(ns.core_rows, 7);
        assert_eq!(ns.largest_block, 7);
        // each vector is a null combination of the rows
        for v in &ns.vectors {
            let mut s = [0.0; 6];
            let rows = incidence(&edges, 0);
            for (r, w) in v {
                for (c, x) in &rows[*r] {
                    s[*c] += w * x;
                }
            }
            assert!(s.iter().all(|x| x.abs() < 1e-12), "{s:?}");
        }
    }

    #[test]
    fn zero_and_repeated_rows_are_redundant() {
        let rows = vec![
            vec![],
            unit(&[(0, 1.0), (1, 1.0)]),
            unit(&[(0, 2.0), (1, 2.0)]),
        ];
        let ns = left_null_space(&rows, &[0, 1, 2], 2, "test").unwrap();
        assert_eq!(ns.vectors.len(), 2);
        assert_eq!(ns.vectors[0], vec![(0, 1.0)]);
        let v = &ns.vectors[1];
        assert_eq!(v.len(), 2);
        assert!((v[0].1 + v[1].1).abs() < 1e-12, "{v:?}");
    }
}
