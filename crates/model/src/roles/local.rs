//! The choice of DOFs (thesis (6.4)) on local bounds ([`crate::local_span`]):
//! rows shown independent without any factorization, against the rigid
//! motions of the mechanism ((2.13) for the Euler parameters); where the
//! bounds do not decide, the sparse blocks choose.

use super::*;

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
pub(super) fn choose_local(scene: &Scene, p: &Problem) -> Option<Vec<Coordinate>> {
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
pub(super) fn regular_by_local_bounds(rows: &[Vec<(usize, f64)>], n: usize, tol: f64) -> bool {
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
