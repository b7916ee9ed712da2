//! The modal assurance criterion and MAC-based mode tracking along a sequence
//! of configurations.

use faer::Mat;

/// MAC(a, b) = (aᵀ W b)² / ((aᵀ W a)(bᵀ W b)), with W = I or a mass matrix.
pub fn mac(a: &[f64], b: &[f64], w: Option<&Mat<f64>>) -> f64 {
    let dot = |x: &[f64], y: &[f64]| -> f64 {
        match w {
            None => x.iter().zip(y).map(|(p, q)| p * q).sum(),
            Some(m) => {
                let n = x.len();
                let mut s = 0.0;
                for i in 0..n {
                    let mut r = 0.0;
                    for j in 0..n {
                        r += m[(i, j)] * y[j];
                    }
                    s += x[i] * r;
                }
                s
            }
        }
    };
    let ab = dot(a, b);
    let den = dot(a, a) * dot(b, b);
    if den > 0.0 {
        ab * ab / den
    } else {
        0.0
    }
}

/// The MAC matrix between the columns of `a` and of `b`.
pub fn mac_matrix(a: &Mat<f64>, b: &Mat<f64>, w: Option<&Mat<f64>>) -> Mat<f64> {
    Mat::from_fn(a.ncols(), b.ncols(), |i, j| {
        mac(a.col_as_slice(i), b.col_as_slice(j), w)
    })
}

/// Mode tracking along a sequence: for each configuration, the permutation
/// that assigns its modes (columns, sorted by frequency) to the tracks of the
/// previous configuration by maximal total MAC (an exact assignment by
/// exhaustive search for up to 8 modes, greedy beyond). `perms[i][t]` is the
/// column of configuration i that continues track t; `confidence[i][t]` its MAC
/// with the previous member of the track (1 for the first configuration).
#[derive(Clone, Debug)]
pub struct Tracking {
    /// Column of each configuration assigned to each track.
    pub perms: Vec<Vec<usize>>,
    /// MAC of each assignment with the previous configuration.
    pub confidence: Vec<Vec<f64>>,
}

/// Tracks modes through a sequence of mode sets (same number of columns each).
pub fn track_modes(sets: &[Mat<f64>], w: Option<&[Mat<f64>]>) -> Tracking {
    let mut perms = vec![];
    let mut confidence = vec![];
    if sets.is_empty() {
        return Tracking { perms, confidence };
    }
    let k = sets[0].ncols();
    perms.push((0..k).collect::<Vec<_>>());
    confidence.push(vec![1.0; k]);
    for i in 1..sets.len() {
        let prev_perm = perms[i - 1].clone();
        // previous track vectors
        let prev = Mat::from_fn(sets[i - 1].nrows(), k, |r, t| {
            sets[i - 1][(r, prev_perm[t])]
        });
        let m = mac_matrix(&prev, &sets[i], w.map(|w| &w[i]));
        let assign = best_assignment(&m);
        confidence.push((0..k).map(|t| m[(t, assign[t])]).collect());
        perms.push(assign);
    }
    Tracking { perms, confidence }
}

/// The assignment track → column maximizing Σ MAC.
fn best_assignment(m: &Mat<f64>) -> Vec<usize> {
    let k = m.nrows().min(m.ncols());
    if k <= 8 {
        let mut best = (f64::NEG_INFINITY, (0..k).collect::<Vec<_>>());
        let mut perm: Vec<usize> = (0..k).collect();
        permute(&mut perm, 0, &mut |p| {
            let s: f64 = (0..k).map(|t| m[(t, p[t])]).sum();
            if s > best.0 {
                best = (s, p.to_vec());
            }
        });
        best.1
    } else {
        let mut used = vec![false; m.ncols()];
        let mut out = vec![0; k];
        let mut entries: Vec<(f64, usize, usize)> = (0..k)
            .flat_map(|t| (0..m.ncols()).map(move |c| (t, c)))
            .map(|(t, c)| (m[(t, c)], t, c))
            .collect();
        entries.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut done = vec![false; k];
        for (_, t, c) in entries {
            if !done[t] && !used[c] {
                done[t] = true;
                used[c] = true;
                out[t] = c;
            }
        }
        out
    }
}

fn permute(p: &mut Vec<usize>, i: usize, f: &mut impl FnMut(&[usize])) {
    if i == p.len() {
        f(p);
        return;
    }
    for j in i..p.len() {
        p.swap(i, j);
        permute(p, i + 1, f);
        p.swap(i, j);
    }
}
