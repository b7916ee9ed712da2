//! Eigenvectors for an interpolated basis along a path P(s) of several
//! coordinates (thesis chapter 7, §7.1.2–§7.1.3): constrained eigenvectors
//! (7.3)–(7.5), where the motion along the path is suppressed, and
//! unconstrained eigenvectors (7.6)–(7.11), where the combination of the first
//! m eigenvectors that moves along the path is removed.

use crate::msi::orthonormalize;
use crate::ReductionError;
use faer::linalg::solvers::Solve;
use faer::Mat;
use flexmb_linearize::generalized_symmetric;

/// An orthonormal basis of the null space of vᵀ (k × (k − 1)): the directions
/// perpendicular to v ((7.4) and Null(η_pᵀ) of (7.6)).
pub fn null_space_of_transpose(v: &[f64]) -> Result<Mat<f64>, ReductionError> {
    let k = v.len();
    let nrm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if nrm.is_nan() || nrm <= 0.0 || !nrm.is_finite() {
        return Err(ReductionError::Invalid(
            "the path direction is zero or not finite".into(),
        ));
    }
    // Householder reflector H = I − 2uuᵀ/(uᵀu) maps v/|v| to ±e_p; its other
    // columns span the complement of v.
    let p = (0..k)
        .max_by(|a, b| v[*a].abs().total_cmp(&v[*b].abs()))
        .unwrap_or(0);
    let mut u: Vec<f64> = v.iter().map(|x| x / nrm).collect();
    // u = v/|v| + sign(v_p) e_p: no cancellation
    u[p] += if u[p] >= 0.0 { 1.0 } else { -1.0 };
    let uu: f64 = u.iter().map(|x| x * x).sum();
    let cols: Vec<usize> = (0..k).filter(|c| *c != p).collect();
    Ok(Mat::from_fn(k, k - 1, |i, j| {
        let c = cols[j];
        let e = if i == c { 1.0 } else { 0.0 };
        e - 2.0 * u[i] * u[c] / uu
    }))
}

/// Constrained eigenvectors (7.3)–(7.5): with q_s the direction of the path in
/// the degrees of freedom (k; zero for the DOFs not on the path) and
/// P = Null(q_sᵀ), the first `r` solutions of Pᵀ(K + G − ω²M)P v = 0, returned
/// as P v (k × r), with their eigenfrequencies (Hz). `k_total` is K + G of
/// the rest linearization (E.6) at the configuration, `m` its mass matrix.
pub fn constrained_eigenvectors(
    k_total: &Mat<f64>,
    m: &Mat<f64>,
    q_s: &[f64],
    r: usize,
) -> Result<(Mat<f64>, Vec<f64>), ReductionError> {
    let k = q_s.len();
    if k_total.nrows() != k || m.nrows() != k || r >= k {
        return Err(ReductionError::Invalid(format!(
            "constrained eigenvectors: {k} path-direction entries, matrices of order {} and {}, {r} modes",
            k_total.nrows(),
            m.nrows()
        )));
    }
    let p = null_space_of_transpose(q_s)?;
    let kp = p.transpose() * k_total * &p;
    let mp = p.transpose() * m * &p;
    let modes = generalized_symmetric(&kp, &mp, r)?;
    let v = &p * Mat::from_fn(k - 1, r, |i, j| modes.vectors[(i, j)]);
    Ok((v, modes.frequencies_hz()))
}

/// Unconstrained eigenvectors along a path (7.6)–(7.11): from the first r
/// unconstrained eigenvectors `vu` (k × r) of a mechanism with m degrees of
/// freedom, the rows `f_p` (m × k) of F,q and E,q of the path coordinates, and
/// the path direction `p_s` = P,s(s) (m), the k × (r − 1) matrix
/// V = [V_b, V_a] with V_b = V_p Null(η_pᵀ), where V_p η_p moves along the
/// path: [F_p,q; E_p,q] V_p η_p = P,s (7.11). `vu` is orthonormalized first,
/// as (7.6) assumes.
pub fn unconstrained_path_eigenvectors(
    vu: &Mat<f64>,
    f_p: &Mat<f64>,
    p_s: &[f64],
) -> Result<Mat<f64>, ReductionError> {
    let (k, r) = (vu.nrows(), vu.ncols());
    let m = p_s.len();
    if f_p.nrows() != m || f_p.ncols() != k || m == 0 || m > r {
        return Err(ReductionError::Invalid(format!(
            "unconstrained path eigenvectors: {m} path coordinates, path rows {}×{}, {r} eigenvectors of length {k}",
            f_p.nrows(),
            f_p.ncols()
        )));
    }
    let vo = orthonormalize(vu);
    let vp = Mat::from_fn(k, m, |i, j| vo[(i, j)]);
    let a = f_p * &vp;
    let lu = a.partial_piv_lu();
    let mut eta = Mat::from_fn(m, 1, |i, _| p_s[i]);
    lu.solve_in_place(eta.as_mut());
    let eta: Vec<f64> = (0..m).map(|i| eta[(i, 0)]).collect();
    if eta.iter().any(|x| !x.is_finite()) {
        return Err(ReductionError::Invalid(
            "the first m eigenvectors cannot describe the path direction ([F_p,q; E_p,q] V_p is singular)".into(),
        ));
    }
    let vb = if m > 1 {
        &vp * null_space_of_transpose(&eta)?
    } else {
        Mat::zeros(k, 0)
    };
    Ok(Mat::from_fn(k, r - 1, |i, j| {
        if j < m - 1 {
            vb[(i, j)]
        } else {
            vo[(i, j + 1)]
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn null_space_is_orthonormal_and_perpendicular() {
        for v in [
            vec![3.0, 0.0, -4.0, 1.0],
            vec![0.0, 1.0],
            vec![-1e-3, 2.0, 5.0],
        ] {
            let p = null_space_of_transpose(&v).unwrap();
            let k = v.len();
            assert_eq!((p.nrows(), p.ncols()), (k, k - 1));
            for a in 0..k - 1 {
                let d: f64 = (0..k).map(|i| p[(i, a)] * v[i]).sum();
                assert!(d.abs() < 1e-14, "not perpendicular: {d}");
                for b in 0..k - 1 {
                    let g: f64 = (0..k).map(|i| p[(i, a)] * p[(i, b)]).sum();
                    let e = if a == b { 1.0 } else { 0.0 };
                    assert!((g - e).abs() < 1e-14);
                }
            }
        }
        assert!(null_space_of_transpose(&[0.0, 0.0]).is_err());
    }
}
