//! Local bounds on the distance of a sparse row to the span S of accepted
//! sparse rows, for the choice of degrees of freedom (thesis (6.4); the
//! greedy rule is in `roles.rs`).
//!
//! The exact distance of a candidate a to S depends on rows far from a (in a
//! chain without supports the motions S leaves free are rigid motions of the
//! whole chain), so an exact orthonormal basis of S or of its complement
//! fills in. The greedy only needs to know on which side of its thresholds
//! the distance lies, and two local quantities bound it:
//!
//! * restricting every vector to a set K of coordinates that contains the
//!   support of a is a contraction, so dist(a, S) ≥ dist(a, S|K), where S|K
//!   is spanned by the rows touching K restricted to K (a lower bound);
//! * the rows inside K are in S, so dist(a, S) ≤ dist(a, S_K) (an upper
//!   bound);
//! * any unit z orthogonal to S gives dist(a, S) ≥ |zᵀa|: the rigid motions of
//!   the whole mechanism, kept orthogonal to every accepted row, are such a
//!   set, and bound the distance of a nodal coordinate of a free body from
//!   below, which no local set does.
//!
//! K starts at the support of a and grows by the supports of the rows that
//! touch it until a bound decides or K closes (then both bounds are the
//! exact distance) or exceeds [`MAX_LOCAL`] coordinates; the caller then
//! uses the exact block-wise method.

/// A local problem larger than this is not tried.
pub(crate) const MAX_LOCAL: usize = 200;

/// The rigid-motion bound is trusted only above this (it is exact only up to
/// the rounding of rows that are orthogonal to it to 1e-11).
const RIGID_MIN: f64 = 1e-4;

/// On which side of the thresholds the distance lies.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Verdict {
    /// Above the upper threshold.
    Above,
    /// At or below the lower threshold.
    Below,
    /// Neither could be shown locally.
    Undecided,
}

/// The accepted rows, with what bounds distances to their span.
pub(crate) struct LocalSpan {
    rows: Vec<Vec<(usize, f64)>>,
    of_col: Vec<Vec<u32>>,
    col_stamp: Vec<u32>,
    col_pos: Vec<u32>,
    row_stamp: Vec<u32>,
    stamp: u32,
    /// Orthonormal vectors orthogonal to every accepted row, row-major
    /// (`q` values per coordinate).
    z: Vec<f64>,
    q: usize,
    kcols: Vec<usize>,
    touch: Vec<u32>,
    basis: Vec<f64>,
    v: Vec<f64>,
}

impl LocalSpan {
    /// An empty span over `n` coordinates; `z` (n × q, row-major,
    /// orthonormal columns) are directions believed orthogonal to the rows
    /// to come: each accepted row removes its component from them.
    pub(crate) fn new(n: usize, z: Vec<f64>, q: usize) -> Self {
        debug_assert_eq!(z.len(), n * q);
        LocalSpan {
            rows: vec![],
            of_col: vec![vec![]; n],
            col_stamp: vec![0; n],
            col_pos: vec![0; n],
            row_stamp: vec![],
            stamp: 0,
            z,
            q,
            kcols: vec![],
            touch: vec![],
            basis: vec![],
            v: vec![],
        }
    }

    /// |Zᵀa|.
    fn zt(&self, a: &[(usize, f64)], w: &mut [f64]) -> f64 {
        w.iter_mut().for_each(|x| *x = 0.0);
        for (i, v) in a {
            for (k, wk) in w.iter_mut().enumerate() {
                *wk += v * self.z[i * self.q + k];
            }
        }
        w.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// Adds an accepted row and keeps the rigid directions orthogonal to it.
    pub(crate) fn push(&mut self, a: Vec<(usize, f64)>) {
        if self.q > 0 {
            let mut w = vec![0.0; self.q];
            let nw = self.zt(&a, &mut w);
            let na = a.iter().map(|(_, v)| v * v).sum::<f64>().sqrt();
            if nw > 1e-11 * na {
                self.remove_direction(&w, nw);
            }
        }
        let r = self.rows.len() as u32;
        for (i, _) in &a {
            if self.of_col[*i].last() != Some(&r) {
                self.of_col[*i].push(r);
            }
        }
        self.rows.push(a);
        self.row_stamp.push(0);
    }

    /// Z ← Z H without its first column, H the Householder reflection that
    /// takes w to a multiple of e₀: the span of Z orthogonal to Z w.
    fn remove_direction(&mut self, w: &[f64], nw: f64) {
        let q = self.q;
        let mut h = w.to_vec();
        h[0] += nw.copysign(w[0]);
        let nh = h.iter().map(|x| x * x).sum::<f64>().sqrt();
        h.iter_mut().for_each(|x| *x /= nh);
        let n = self.z.len() / q;
        let mut out = Vec::with_capacity(n * (q - 1));
        for row in self.z.chunks(q) {
            let p: f64 = row.iter().zip(&h).map(|(a, b)| a * b).sum();
            out.extend(row.iter().zip(&h).skip(1).map(|(a, b)| a - 2.0 * p * b));
        }
        self.z = out;
        self.q = q - 1;
    }

    fn next_stamp(&mut self) {
        if self.stamp == u32::MAX {
            self.col_stamp.iter_mut().for_each(|s| *s = 0);
            self.row_stamp.iter_mut().for_each(|s| *s = 0);
            self.stamp = 0;
        }
        self.stamp += 1;
    }

    fn add_col(&mut self, i: usize) {
        if self.col_stamp[i] != self.stamp {
            self.col_stamp[i] = self.stamp;
            self.col_pos[i] = self.kcols.len() as u32;
            self.kcols.push(i);
        }
    }

    /// Whether dist(a, S) > `above` ([`Verdict::Above`]) or ≤ `below`
    /// ([`Verdict::Below`]), shown by the bounds of the module documentation.
    pub(crate) fn decide(&mut self, a: &[(usize, f64)], above: f64, below: f64) -> Verdict {
        if self.q > 0 {
            let mut w = vec![0.0; self.q];
            if self.zt(a, &mut w) > above.max(RIGID_MIN) {
                return Verdict::Above;
            }
        }
        self.next_stamp();
        self.kcols.clear();
        self.touch.clear();
        for (i, _) in a {
            self.add_col(*i);
        }
        let mut scanned = 0;
        loop {
            for k in scanned..self.kcols.len() {
                let c = self.kcols[k];
                for r in &self.of_col[c] {
                    if self.row_stamp[*r as usize] != self.stamp {
                        self.row_stamp[*r as usize] = self.stamp;
                        self.touch.push(*r);
                    }
                }
            }
            scanned = self.kcols.len();
            // in the order of acceptance, so that each row inside K keeps the
            // independence it was accepted with
            self.touch.sort_unstable();
            let stamp = self.stamp;
            let inside = |s: &Self, r: u32| {
                s.rows[r as usize]
                    .iter()
                    .all(|(i, _)| s.col_stamp[*i] == stamp)
            };
            let closed = self.touch.iter().all(|r| inside(self, *r));
            // restricted rows: any direction above rounding counts (a smaller
            // bound); rows inside: only clearly independent ones (a larger one)
            let lo = self.residual(a, false, 1e-13);
            if lo > above {
                return Verdict::Above;
            }
            let hi = if closed {
                lo
            } else {
                self.residual(a, true, 1e-10)
            };
            if hi <= below {
                return Verdict::Below;
            }
            if closed {
                return Verdict::Undecided;
            }
            let touch = std::mem::take(&mut self.touch);
            for r in &touch {
                for k in 0..self.rows[*r as usize].len() {
                    let i = self.rows[*r as usize][k].0;
                    self.add_col(i);
                }
            }
            self.touch = touch;
            if self.kcols.len() > MAX_LOCAL {
                return Verdict::Undecided;
            }
        }
    }

    /// Distance of a (supported in K) to the span of the touching rows
    /// restricted to K (`inside_only`: of those inside K), by Gram–Schmidt
    /// in the local coordinates, each row kept when its residual exceeds
    /// `tol` of its norm.
    fn residual(&mut self, a: &[(usize, f64)], inside_only: bool, tol: f64) -> f64 {
        let m = self.kcols.len();
        if m == 0 {
            return 0.0; // a zero row
        }
        self.basis.clear();
        let stamp = self.stamp;
        for t in 0..self.touch.len() {
            let row = &self.rows[self.touch[t] as usize];
            if inside_only && row.iter().any(|(i, _)| self.col_stamp[*i] != stamp) {
                continue;
            }
            self.v.clear();
            self.v.resize(m, 0.0);
            let mut full = 0.0;
            for (i, x) in row {
                full += x * x;
                if self.col_stamp[*i] == stamp {
                    self.v[self.col_pos[*i] as usize] += x;
                }
            }
            let nr = project_out(&mut self.v, &self.basis, m);
            if nr > tol * full.sqrt() {
                self.basis.extend(self.v.iter().map(|x| x / nr));
            }
        }
        self.v.clear();
        self.v.resize(m, 0.0);
        for (i, x) in a {
            self.v[self.col_pos[*i] as usize] += x;
        }
        project_out(&mut self.v, &self.basis, m)
    }
}

/// v minus its projection on the orthonormal rows of `basis` (m each), twice;
/// the norm of what is left.
fn project_out(v: &mut [f64], basis: &[f64], m: usize) -> f64 {
    for _ in 0..2 {
        for b in basis.chunks(m) {
            let p: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
            for (x, y) in v.iter_mut().zip(b) {
                *x -= p * y;
            }
        }
    }
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounds agree with the exact distance on a chain of difference
    /// rows x_k − x_{k+1}, whose complement is the uniform vector (global).
    #[test]
    fn bounds_and_the_rigid_direction_on_a_difference_chain() {
        let n = 1000;
        let z: Vec<f64> = vec![1.0 / (n as f64).sqrt(); n];
        let mut s = LocalSpan::new(n, z, 1);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        for k in 0..n - 1 {
            let a = vec![(k, h), (k + 1, -h)];
            assert_eq!(s.decide(&a, 1e-6, 1e-9), Verdict::Above, "row {k}");
            s.push(a);
        }
        // the uniform direction survives the pushes: e_0 is at 1/√n from S
        assert_eq!(s.q, 1);
        assert_eq!(s.decide(&[(0, 1.0)], 1e-6, 1e-9), Verdict::Above);
        // without it, no local set shows that
        let mut t = LocalSpan::new(n, vec![], 0);
        for k in 0..n - 1 {
            t.push(vec![(k, h), (k + 1, -h)]);
        }
        assert_eq!(t.decide(&[(0, 1.0)], 1e-6, 1e-9), Verdict::Undecided);
        // a difference of far-apart coordinates is in S, shown inside K
        let far = vec![(10, h), (13, -h)];
        assert_eq!(t.decide(&far, 1e-6, 1e-9), Verdict::Below);
        assert_eq!(s.decide(&far, 1e-6, 1e-9), Verdict::Below);
        // a pushed row that is not orthogonal removes the direction
        s.push(vec![(0, 1.0)]);
        assert_eq!(s.q, 0);
        assert_eq!(s.decide(&[(50, 1.0)], 1e-6, 1e-9), Verdict::Below);
    }
}
