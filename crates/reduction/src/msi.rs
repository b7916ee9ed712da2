//! Modal subspace interpolation (thesis §6.3.3, steps 1–8) and the MAC-sorted
//! alternative.

use faer::Mat;

/// Orthonormalizes the columns (Gram–Schmidt twice), step 1.
pub fn orthonormalize(v: &Mat<f64>) -> Mat<f64> {
    let (n, r) = (v.nrows(), v.ncols());
    let mut q = v.clone();
    for j in 0..r {
        for _ in 0..2 {
            for k in 0..j {
                let p: f64 = (0..n).map(|i| q[(i, k)] * q[(i, j)]).sum();
                for i in 0..n {
                    q[(i, j)] -= p * q[(i, k)];
                }
            }
        }
        let nrm = (0..n).map(|i| q[(i, j)].powi(2)).sum::<f64>().sqrt();
        for i in 0..n {
            q[(i, j)] /= nrm;
        }
    }
    q
}

/// Steps 1–7 of the MSI algorithm: the base vectors W(i) that span the same
/// subspaces as the eigenvectors V(i) but vary as little as possible from one
/// configuration to the next (steps 3–6: W(i+1) = normalized columns of
/// V(i+1)V(i+1)ᵀW(i)), then mass-normalized with M(i) (step 7, (6.26)) when
/// mass matrices are given. Step 8 (interpolation) is done by the caller.
pub fn modal_subspace_interpolation(v: &[Mat<f64>], mass: Option<&[Mat<f64>]>) -> Vec<Mat<f64>> {
    let vs: Vec<Mat<f64>> = v.iter().map(orthonormalize).collect();
    let mut w: Vec<Mat<f64>> = Vec::with_capacity(vs.len());
    if vs.is_empty() {
        return w;
    }
    w.push(vs[0].clone());
    for i in 0..vs.len() - 1 {
        w.push(msi_step(&vs[i + 1], &w[i]));
    }
    if let Some(m) = mass {
        for (wi, mi) in w.iter_mut().zip(m) {
            mass_normalize(wi, mi);
        }
    }
    w
}

/// Steps 3–6 of MSI: the base vectors at the next configuration, whose
/// orthonormal eigenvectors are `vn`, from those `w` at the previous one:
/// the columns of vn vnᵀ w, each normalized to unit length.
pub(crate) fn msi_step(vn: &Mat<f64>, w: &Mat<f64>) -> Mat<f64> {
    let mut next = vn * (vn.transpose() * w);
    let (n, r) = (next.nrows(), next.ncols());
    for j in 0..r {
        let nrm = (0..n).map(|k| next[(k, j)].powi(2)).sum::<f64>().sqrt();
        for k in 0..n {
            next[(k, j)] /= nrm;
        }
    }
    next
}

/// Step 7 of MSI, (6.26): each column w scaled to w/√(wᵀMw).
pub(crate) fn mass_normalize(w: &mut Mat<f64>, m: &Mat<f64>) {
    let mw = m * &*w;
    for j in 0..w.ncols() {
        let s: f64 = (0..w.nrows()).map(|k| w[(k, j)] * mw[(k, j)]).sum();
        let f = 1.0 / s.sqrt();
        for k in 0..w.nrows() {
            w[(k, j)] *= f;
        }
    }
}

/// MSI over a tensor grid of configurations (two configuration coordinates,
/// [`crate::GridBasis`]): `v` holds the eigenvectors at the n1 × n2 grid
/// points, point (i, j) at index i + n1 j (the first coordinate fastest).
/// Steps 1–6 run along the first row (j = 0) from its first point, then
/// along every column (i fixed) from that row, so each point's base vectors
/// are projected from a neighbour's, as in the one-parameter MSI; step 7
/// mass-normalizes with `mass` when given. With one column of data repeated
/// over the rows, every row gets the one-parameter MSI's vectors.
pub fn modal_subspace_interpolation_grid(
    v: &[Mat<f64>],
    n1: usize,
    n2: usize,
    mass: Option<&[Mat<f64>]>,
) -> Vec<Mat<f64>> {
    if v.len() != n1 * n2 || v.is_empty() {
        return vec![];
    }
    let vs: Vec<Mat<f64>> = v.iter().map(orthonormalize).collect();
    let mut w: Vec<Option<Mat<f64>>> = vec![None; vs.len()];
    w[0] = Some(vs[0].clone());
    for i in 1..n1 {
        let prev = w[i - 1].as_ref().map(|p| msi_step(&vs[i], p));
        w[i] = prev;
    }
    for j in 1..n2 {
        for i in 0..n1 {
            let prev = w[i + n1 * (j - 1)]
                .as_ref()
                .map(|p| msi_step(&vs[i + n1 * j], p));
            w[i + n1 * j] = prev;
        }
    }
    let mut w: Vec<Mat<f64>> = w.into_iter().flatten().collect();
    if let Some(m) = mass {
        for (wi, mi) in w.iter_mut().zip(m) {
            mass_normalize(wi, mi);
        }
    }
    w
}

/// The alternative of the thesis's MAC-7 model: eigenvectors sorted by MAC mode
/// tracking and sign-aligned with the previous configuration.
pub fn mac_sorted(v: &[Mat<f64>]) -> Vec<Mat<f64>> {
    let tr = flexmb_linearize::track_modes(v, None);
    let mut out: Vec<Mat<f64>> = vec![];
    for (i, vi) in v.iter().enumerate() {
        let mut m = Mat::from_fn(vi.nrows(), vi.ncols(), |r, t| vi[(r, tr.perms[i][t])]);
        if let Some(prev) = out.last() {
            for t in 0..m.ncols() {
                let d: f64 = (0..m.nrows()).map(|r| m[(r, t)] * prev[(r, t)]).sum();
                if d < 0.0 {
                    for r in 0..m.nrows() {
                        m[(r, t)] = -m[(r, t)];
                    }
                }
            }
        }
        out.push(m);
    }
    out
}

/// The largest principal angle (radians) between the column spaces of a and b
/// (of equal dimension), from its sine ‖(I − QaQaᵀ)Qb‖₂ (accurate for small angles).
///
/// An error when the spectral norm cannot be computed (non-finite input, or
/// no SVD converged), never a silent 0.
pub fn largest_principal_angle(a: &Mat<f64>, b: &Mat<f64>) -> Result<f64, flexmb_linalg::SvdError> {
    let (qa, qb) = (orthonormalize(a), orthonormalize(b));
    let r = &qb - &qa * (qa.transpose() * &qb);
    let s = flexmb_linalg::singular_values(r.as_ref())?;
    Ok(s.iter().copied().fold(0.0f64, f64::max).min(1.0).asin())
}
