//! A symmetric positive definite matrix in profile (skyline) storage and its
//! Cholesky factorization in place, with a reverse Cuthill–McKee ordering.
//!
//! The nodal mass matrix of a mechanism couples only the coordinates of one
//! element, so after a bandwidth-reducing ordering its rows are short: row i
//! holds the entries from its first non-zero column `first[i]` to the
//! diagonal. The Cholesky factor has the same profile (no fill outside it),
//! so pattern and memory are set up once and every factorization is a pass
//! of contiguous dot products over the rows.
//!
//! `flexmb-dynamics` factorizes the mass matrix of its nodal equations of
//! motion this way at every evaluation: [`reverse_cuthill_mckee`] orders the
//! coordinates once, [`Skyline::new`] sets up the profile, and
//! [`Skyline::factor`], [`Skyline::solve_lower`], [`Skyline::solve_upper`] and
//! [`Skyline::solve_lower_rows`] work in that memory without allocating.

/// Orders the vertices of a graph (adjacency lists) by reverse Cuthill–McKee:
/// breadth first from a low-degree vertex of each component, neighbours by
/// increasing degree, the whole order reversed. Returns `perm` with
/// `perm[new] = old`.
pub fn reverse_cuthill_mckee(adj: &[Vec<usize>]) -> Vec<usize> {
    let n = adj.len();
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut by_degree: Vec<usize> = (0..n).collect();
    by_degree.sort_by_key(|&v| (adj[v].len(), v));
    for &start in &by_degree {
        if seen[start] {
            continue;
        }
        // a pseudo-peripheral start: the last vertex of a breadth-first
        // sweep from `start`, repeated while the sweep gets deeper
        let root = pseudo_peripheral(adj, start);
        let head = order.len();
        seen[root] = true;
        order.push(root);
        let mut k = head;
        while k < order.len() {
            let v = order[k];
            k += 1;
            let mut next: Vec<usize> = adj[v].iter().copied().filter(|&w| !seen[w]).collect();
            next.sort_by_key(|&w| (adj[w].len(), w));
            next.dedup();
            for w in next {
                if !seen[w] {
                    seen[w] = true;
                    order.push(w);
                }
            }
        }
    }
    order.reverse();
    order
}

/// Breadth-first levels from `v`: (depth, a vertex of least degree in the last level).
fn last_level(adj: &[Vec<usize>], v: usize) -> (usize, usize) {
    let mut depth = vec![usize::MAX; adj.len()];
    depth[v] = 0;
    let mut queue = vec![v];
    let mut k = 0;
    while k < queue.len() {
        let u = queue[k];
        k += 1;
        for &w in &adj[u] {
            if depth[w] == usize::MAX {
                depth[w] = depth[u] + 1;
                queue.push(w);
            }
        }
    }
    let d = queue.iter().map(|&u| depth[u]).max().unwrap_or(0);
    let far = queue
        .iter()
        .copied()
        .filter(|&u| depth[u] == d)
        .min_by_key(|&u| (adj[u].len(), u))
        .unwrap_or(v);
    (d, far)
}

fn pseudo_peripheral(adj: &[Vec<usize>], start: usize) -> usize {
    let (mut depth, mut v) = last_level(adj, start);
    for _ in 0..8 {
        let (d, far) = last_level(adj, v);
        if d <= depth {
            break;
        }
        depth = d;
        v = far;
    }
    v
}

/// A symmetric matrix in profile storage: row i holds the columns
/// `first[i] ..= i` contiguously. After [`factor`](Self::factor) the same
/// storage holds the lower Cholesky factor L (A = L Lᵀ).
#[derive(Clone, Debug)]
pub struct Skyline {
    first: Vec<usize>,
    start: Vec<usize>,
    values: Vec<f64>,
    /// Diagonal of A before the factorization (the pivot test is relative to it).
    diag: Vec<f64>,
}

/// Failure of [`Skyline::factor`]: the row whose pivot is not positive.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error(
    "the skyline matrix is not positive definite: the Cholesky pivot of row {row} \
     is not above 1e-13 of its diagonal entry (or not finite)"
)]
pub struct NotPositiveDefinite {
    /// The row (in the skyline's order) whose pivot failed.
    pub row: usize,
}

impl Skyline {
    /// The profile of an n × n matrix with the given (row, column) couplings
    /// (either triangle; the diagonal is always in).
    pub fn new(n: usize, couplings: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let mut first: Vec<usize> = (0..n).collect();
        for (a, b) in couplings {
            let (i, j) = if a >= b { (a, b) } else { (b, a) };
            first[i] = first[i].min(j);
        }
        let mut start = Vec::with_capacity(n + 1);
        let mut s = 0;
        for (i, f) in first.iter().enumerate() {
            start.push(s);
            s += i - f + 1;
        }
        start.push(s);
        Self {
            first,
            start,
            values: vec![0.0; s],
            diag: vec![0.0; n],
        }
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.first.len()
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Sets every entry to zero.
    pub fn clear(&mut self) {
        self.values.fill(0.0);
    }

    /// A(i, j) += v for i ≥ j inside the profile.
    pub fn add_lower(&mut self, i: usize, j: usize, v: f64) {
        let p = self.position(i, j);
        self.values[p] += v;
    }

    /// Storage position of entry (i, j), i ≥ j inside the profile, for
    /// [`add_at`](Self::add_at).
    pub fn position(&self, i: usize, j: usize) -> usize {
        assert!(
            j <= i && j >= self.first[i],
            "({i}, {j}) is outside the profile"
        );
        self.start[i] + j - self.first[i]
    }

    /// The entry at storage position p += v.
    #[inline]
    pub fn add_at(&mut self, p: usize, v: f64) {
        self.values[p] += v;
    }

    /// Entry (i, j), i ≥ j (zero outside the profile).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if j < self.first[i] || j > i {
            0.0
        } else {
            self.values[self.start[i] + j - self.first[i]]
        }
    }

    /// Row i of the stored lower triangle, columns `first(i) ..= i`.
    fn row(&self, i: usize) -> &[f64] {
        &self.values[self.start[i]..self.start[i + 1]]
    }

    /// Cholesky factorization in place, row by row (each entry one dot
    /// product of two row segments). Fails when a pivot is not above
    /// 1e-13 of the row's original diagonal entry (or not finite).
    pub fn factor(&mut self) -> Result<(), NotPositiveDefinite> {
        let n = self.n();
        for i in 0..n {
            self.diag[i] = self.get(i, i);
        }
        for i in 0..n {
            let fi = self.first[i];
            let (before, rest) = self.values.split_at_mut(self.start[i]);
            let row_i = &mut rest[..i - fi + 1];
            for j in fi..i {
                let fj = self.first[j];
                let k0 = fi.max(fj);
                let row_j = &before[self.start[j]..self.start[j + 1]];
                let s = dot(&row_i[k0 - fi..j - fi], &row_j[k0 - fj..j - fj]);
                // L(j, j) is the last entry of row j
                row_i[j - fi] = (row_i[j - fi] - s) / row_j[j - fj];
            }
            let off = &row_i[..i - fi];
            let d = row_i[i - fi] - dot(off, off);
            let positive = d.is_finite() && d > 1e-13 * self.diag[i].abs();
            if !positive {
                return Err(NotPositiveDefinite { row: i });
            }
            row_i[i - fi] = d.sqrt();
        }
        Ok(())
    }

    /// Solves L z = b in place (after [`factor`](Self::factor)).
    pub fn solve_lower(&self, b: &mut [f64]) {
        for i in 0..self.n() {
            let fi = self.first[i];
            let row = self.row(i);
            let s = dot(&row[..i - fi], &b[fi..i]);
            b[i] = (b[i] - s) / row[i - fi];
        }
    }

    /// Solves Lᵀ x = b in place (after [`factor`](Self::factor)).
    pub fn solve_upper(&self, b: &mut [f64]) {
        for i in (0..self.n()).rev() {
            let fi = self.first[i];
            let row = self.row(i);
            let xi = b[i] / row[i - fi];
            b[i] = xi;
            for (bk, l) in b[fi..i].iter_mut().zip(&row[..i - fi]) {
                *bk -= l * xi;
            }
        }
    }

    /// Solves L Y = B in place for a row-major n × m block whose row i is
    /// zero beyond its first `active[i]` entries (`active` non-decreasing):
    /// then so is row i of Y, and only those entries are computed.
    pub fn solve_lower_rows(&self, y: &mut [f64], m: usize, active: &[usize]) {
        for i in 0..self.n() {
            let fi = self.first[i];
            let row = self.row(i);
            let (done, rest) = y.split_at_mut(i * m);
            let yi = &mut rest[..active[i]];
            for (k, l) in (fi..i).zip(row) {
                let p = active[k];
                if p == 0 || *l == 0.0 {
                    continue;
                }
                for (a, b) in yi[..p].iter_mut().zip(&done[k * m..k * m + p]) {
                    *a -= l * b;
                }
            }
            let d = 1.0 / row[i - fi];
            for a in yi.iter_mut() {
                *a *= d;
            }
        }
    }
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    // four partial sums: independent chains the compiler can vectorize
    let mut s = [0.0f64; 4];
    let (ac, ar) = a.split_at(a.len() / 4 * 4);
    let (bc, br) = b.split_at(ac.len());
    for (x, y) in ac.chunks_exact(4).zip(bc.chunks_exact(4)) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (x, y) in ar.iter().zip(br) {
        t += x * y;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random SPD matrix with a band-plus-scatter pattern, as a dense array
    /// and as a skyline, its couplings shuffled by a fixed permutation.
    fn spd(n: usize, seed: u64) -> (Vec<f64>, Vec<(usize, usize)>) {
        let mut state = seed;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut a = vec![0.0; n * n];
        let mut pairs = vec![];
        for i in 0..n {
            for j in 0..i {
                if i - j <= 3 || (i * 7 + j * 3) % 11 == 0 {
                    let v = rnd();
                    a[i * n + j] = v;
                    a[j * n + i] = v;
                    pairs.push((i, j));
                }
            }
        }
        for i in 0..n {
            let s: f64 = (0..n).map(|j| a[i * n + j].abs()).sum();
            a[i * n + i] = s + 0.5 + rnd().abs();
        }
        (a, pairs)
    }

    #[test]
    fn cholesky_solves_agree_with_the_dense_matrix() {
        for (n, seed) in [(1usize, 1u64), (7, 2), (40, 3)] {
            let (a, pairs) = spd(n, seed);
            let mut s = Skyline::new(n, pairs.iter().copied());
            for i in 0..n {
                for j in 0..=i {
                    if a[i * n + j] != 0.0 {
                        s.add_lower(i, j, a[i * n + j]);
                    }
                }
            }
            s.factor().unwrap();
            // x = A⁻¹ b, checked by the residual with the dense A
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut x = b.clone();
            s.solve_lower(&mut x);
            s.solve_upper(&mut x);
            for i in 0..n {
                let r: f64 = (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - b[i];
                assert!(r.abs() < 1e-12, "n = {n}, row {i}: residual {r}");
            }
            // L Y = B for a block with growing active columns equals column solves
            let m = 3;
            let active: Vec<usize> = (0..n).map(|i| (i * m / n.max(1) + 1).min(m)).collect();
            let mut y = vec![0.0; n * m];
            for i in 0..n {
                for c in 0..active[i] {
                    y[i * m + c] = ((i + 3 * c) as f64 * 0.11).cos();
                }
            }
            let b0 = y.clone();
            s.solve_lower_rows(&mut y, m, &active);
            for c in 0..m {
                let mut col: Vec<f64> = (0..n).map(|i| b0[i * m + c]).collect();
                s.solve_lower(&mut col);
                for i in 0..n {
                    assert!((col[i] - y[i * m + c]).abs() < 1e-13, "n = {n}, ({i}, {c})");
                }
            }
        }
    }

    /// The tridiagonal matrix tridiag(−1, 2, −1) of order 4 with x = (1, 2, 3, 4):
    /// b = A x = (0, 0, 0, 5); its factor has L(i, i) = √((i + 2)/(i + 1)).
    #[test]
    fn known_solution_of_a_tridiagonal_system() {
        let n = 4;
        let mut s = Skyline::new(n, (1..n).map(|i| (i, i - 1)));
        assert_eq!((s.n(), s.nnz()), (4, 7));
        for i in 0..n {
            s.add_lower(i, i, 2.0);
            if i > 0 {
                s.add_at(s.position(i, i - 1), -1.0);
            }
        }
        assert_eq!(s.get(0, 2), 0.0);
        s.factor().unwrap();
        for i in 0..n {
            let expect = ((i as f64 + 2.0) / (i as f64 + 1.0)).sqrt();
            assert!((s.get(i, i) - expect).abs() < 1e-15);
        }
        let mut x = vec![0.0, 0.0, 0.0, 5.0];
        s.solve_lower(&mut x);
        s.solve_upper(&mut x);
        for (xi, ei) in x.iter().zip([1.0, 2.0, 3.0, 4.0]) {
            assert!((xi - ei).abs() < 1e-14, "{x:?}");
        }
        s.clear();
        assert_eq!(s.get(3, 3), 0.0);
    }

    #[test]
    fn a_matrix_that_is_not_positive_definite_names_its_row() {
        let mut s = Skyline::new(3, [(1, 0), (2, 1)]);
        s.add_lower(0, 0, 1.0);
        s.add_lower(1, 0, 2.0);
        s.add_lower(1, 1, 1.0); // 1 − 2² < 0
        s.add_lower(2, 2, 1.0);
        let err = s.factor().unwrap_err();
        assert_eq!(err, NotPositiveDefinite { row: 1 });
        assert!(err.to_string().contains("row 1"), "{err}");
        // a zero matrix: the first pivot fails
        let mut zero = Skyline::new(2, [(1, 0)]);
        assert_eq!(zero.factor(), Err(NotPositiveDefinite { row: 0 }));
        let mut z = Skyline::new(2, []);
        z.add_lower(0, 0, 1.0);
        z.add_lower(1, 1, f64::NAN);
        assert_eq!(z.factor(), Err(NotPositiveDefinite { row: 1 }));
    }

    #[test]
    fn reverse_cuthill_mckee_narrows_a_scrambled_chain() {
        // a path 0-1-2-…-19 with scrambled labels: RCM recovers bandwidth 1
        let n = 20;
        let label: Vec<usize> = (0..n).map(|i| (i * 7) % n).collect();
        let mut adj = vec![vec![]; n];
        for i in 0..n - 1 {
            adj[label[i]].push(label[i + 1]);
            adj[label[i + 1]].push(label[i]);
        }
        let perm = reverse_cuthill_mckee(&adj);
        let mut pos = vec![0; n];
        for (new, old) in perm.iter().enumerate() {
            pos[*old] = new;
        }
        let mut sorted = perm.clone();
        sorted.sort();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>());
        let band = (0..n)
            .flat_map(|v| adj[v].iter().map(move |w| (v, *w)))
            .map(|(v, w)| pos[v].abs_diff(pos[w]))
            .max()
            .unwrap();
        assert_eq!(band, 1);
        // disconnected vertices are all placed
        let perm = reverse_cuthill_mckee(&[vec![], vec![2], vec![1]]);
        assert_eq!(perm.len(), 3);
    }
}
