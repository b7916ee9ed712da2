//! A singular value decomposition that does not give up on ordinary input.
//!
//! faer 0.24's bidiagonal SVD reports `NoConvergence` on some small,
//! well-conditioned, finite matrices: `cargo xtask fuzz` found a 26 × 26
//! constraint Jacobian with entries in {0, ±0.5, ±0.6, ±1, ±2} and singular
//! values between 0.108 and 2.98 on which it fails (kept as a test below).
//! [`svd`], [`thin_svd`] and [`singular_values`] therefore try, in order:
//!
//! 1. faer on `A`;
//! 2. faer on `Aᵀ` (the same factors, transposed: `A = U S Vᵀ` ⇔ `Aᵀ = V S Uᵀ`),
//!    which converged on every failure seen so far;
//! 3. nalgebra's SVD, a different implementation of Golub–Kahan.
//!
//! Each result records the [`SvdMethod`] that produced it. Non-finite input is
//! refused up front with the first offending entry, because no method can
//! decompose it. Singular values are always sorted in decreasing order and the
//! columns of `U` and `V` follow them.

use faer::{Mat, MatRef};

/// Which rung of the ladder produced a decomposition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SvdMethod {
    /// faer on the matrix itself (the usual case).
    Faer,
    /// faer on the transpose.
    FaerTransposed,
    /// nalgebra's Golub–Kahan SVD.
    Nalgebra,
}

/// Why no decomposition could be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SvdError {
    /// An entry is NaN or infinite.
    #[error(
        "the {rows} × {cols} matrix has a non-finite entry {value} at row {row}, column {col}"
    )]
    NonFinite {
        /// Matrix rows.
        rows: usize,
        /// Matrix columns.
        cols: usize,
        /// Row of the first non-finite entry.
        row: usize,
        /// Its column.
        col: usize,
        /// Its value.
        value: f64,
    },
    /// Every method failed to converge.
    #[error(
        "no singular value decomposition of the {rows} × {cols} matrix converged \
         (faer on the matrix and its transpose, and nalgebra, all failed)"
    )]
    NoConvergence {
        /// Matrix rows.
        rows: usize,
        /// Matrix columns.
        cols: usize,
    },
}

/// `A = U diag(s) Vᵀ` with `s` sorted in decreasing order.
///
/// From [`svd`], `U` is m × m and `V` is n × n; from [`thin_svd`], both have
/// min(m, n) columns. `s` always has min(m, n) entries.
#[derive(Debug, Clone)]
pub struct Svd {
    /// Left singular vectors as columns.
    pub u: Mat<f64>,
    /// Singular values, decreasing.
    pub s: Vec<f64>,
    /// Right singular vectors as columns.
    pub v: Mat<f64>,
    /// The method that produced this decomposition.
    pub method: SvdMethod,
}

impl Svd {
    /// Numerical rank: the number of singular values above `rel_tol` times the
    /// largest.
    pub fn rank(&self, rel_tol: f64) -> usize {
        let smax = self.s.first().copied().unwrap_or(0.0);
        self.s
            .iter()
            .filter(|&&x| x > rel_tol * smax.max(f64::MIN_POSITIVE))
            .count()
    }
}

fn check_finite(a: MatRef<'_, f64>) -> Result<(), SvdError> {
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            let value = a[(i, j)];
            if !value.is_finite() {
                return Err(SvdError::NonFinite {
                    rows: a.nrows(),
                    cols: a.ncols(),
                    row: i,
                    col: j,
                    value,
                });
            }
        }
    }
    Ok(())
}

fn column_vec(s: faer::ColRef<'_, f64>) -> Vec<f64> {
    (0..s.nrows()).map(|i| s[i]).collect()
}

/// faer's full or thin SVD of `a`, or `None` when it does not converge.
fn faer_svd(a: MatRef<'_, f64>, thin: bool) -> Option<(Mat<f64>, Vec<f64>, Mat<f64>)> {
    if thin {
        let d = a.thin_svd().ok()?;
        Some((
            d.U().to_owned(),
            column_vec(d.S().column_vector()),
            d.V().to_owned(),
        ))
    } else {
        let d = a.svd().ok()?;
        Some((
            d.U().to_owned(),
            column_vec(d.S().column_vector()),
            d.V().to_owned(),
        ))
    }
}

/// Completes the orthonormal columns `q` (m × k) to an m × m orthogonal
/// matrix whose first k columns are `q`, from a Householder QR of `q`.
fn complete_basis(q: &Mat<f64>) -> Mat<f64> {
    let (m, k) = (q.nrows(), q.ncols());
    if k >= m {
        return q.clone();
    }
    let full_q = q.qr().compute_Q();
    Mat::from_fn(m, m, |i, j| if j < k { q[(i, j)] } else { full_q[(i, j)] })
}

/// nalgebra's SVD (thin), sorted; completed to full factors unless `thin`.
fn nalgebra_svd(a: MatRef<'_, f64>, thin: bool) -> Option<(Mat<f64>, Vec<f64>, Mat<f64>)> {
    let (m, n) = (a.nrows(), a.ncols());
    let b = nalgebra::DMatrix::from_fn(m, n, |i, j| a[(i, j)]);
    // a generous iteration limit instead of nalgebra's "no limit" (0)
    let max_iter = 200 * (m + n).max(1);
    let d = nalgebra::SVD::try_new(b, true, true, f64::EPSILON, max_iter)?;
    let (u, vt) = (d.u?, d.v_t?);
    let k = d.singular_values.len();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&x, &y| d.singular_values[y].total_cmp(&d.singular_values[x]));
    let s: Vec<f64> = order.iter().map(|&i| d.singular_values[i]).collect();
    let u_thin = Mat::from_fn(m, k, |i, j| u[(i, order[j])]);
    let v_thin = Mat::from_fn(n, k, |i, j| vt[(order[j], i)]);
    if thin {
        Some((u_thin, s, v_thin))
    } else {
        Some((complete_basis(&u_thin), s, complete_basis(&v_thin)))
    }
}

fn decompose(a: MatRef<'_, f64>, thin: bool) -> Result<Svd, SvdError> {
    check_finite(a)?;
    let (m, n) = (a.nrows(), a.ncols());
    if m == 0 || n == 0 {
        let (ku, kv) = if thin { (0, 0) } else { (m, n) };
        return Ok(Svd {
            u: Mat::identity(m, ku),
            s: vec![],
            v: Mat::identity(n, kv),
            method: SvdMethod::Faer,
        });
    }
    let (parts, method) = if let Some(p) = faer_svd(a, thin) {
        (p, SvdMethod::Faer)
    } else if let Some((v, s, u)) = faer_svd(a.transpose(), thin) {
        ((u, s, v), SvdMethod::FaerTransposed)
    } else if let Some(p) = nalgebra_svd(a, thin) {
        (p, SvdMethod::Nalgebra)
    } else {
        return Err(SvdError::NoConvergence { rows: m, cols: n });
    };
    let (u, s, v) = parts;
    Ok(Svd { u, s, v, method })
}

/// Full SVD: `U` is m × m, `V` is n × n (their trailing columns span the left
/// and right null spaces beyond the rank).
pub fn svd(a: MatRef<'_, f64>) -> Result<Svd, SvdError> {
    decompose(a, false)
}

/// Thin SVD: `U` is m × k and `V` is n × k with k = min(m, n).
pub fn thin_svd(a: MatRef<'_, f64>) -> Result<Svd, SvdError> {
    decompose(a, true)
}

/// The singular values alone, decreasing.
pub fn singular_values(a: MatRef<'_, f64>) -> Result<Vec<f64>, SvdError> {
    check_finite(a)?;
    if a.nrows() == 0 || a.ncols() == 0 {
        return Ok(vec![]);
    }
    if let Ok(s) = a.singular_values() {
        return Ok(s);
    }
    if let Ok(s) = a.transpose().singular_values() {
        return Ok(s);
    }
    nalgebra_svd(a, true)
        .map(|(_, s, _)| s)
        .ok_or(SvdError::NoConvergence {
            rows: a.nrows(),
            cols: a.ncols(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The constraint Jacobian (26 × 26) on which faer 0.24's SVD reports
    /// `NoConvergence`: fuzz case 0x9ee0d2e82b774409, the spatial truss and
    /// rigid-body seed scene with its nodes reordered.
    pub(crate) fn faer_failure() -> Mat<f64> {
        const T: [(usize, usize, f64); 52] = [
            (0, 19, 1.0),
            (1, 23, 0.5),
            (2, 20, 1.0),
            (3, 20, -1.0),
            (3, 25, 0.5),
            (4, 21, 1.0),
            (5, 21, -1.0),
            (5, 24, -0.5),
            (6, 0, 1.0),
            (6, 19, -1.0),
            (7, 4, 0.5),
            (7, 23, -0.5),
            (8, 1, 1.0),
            (8, 20, -1.0),
            (8, 25, -0.5),
            (9, 1, -1.0),
            (9, 6, 0.5),
            (9, 20, 1.0),
            (10, 2, 1.0),
            (10, 21, -1.0),
            (10, 24, 0.5),
            (11, 2, -1.0),
            (11, 5, -0.5),
            (11, 21, 1.0),
            (12, 1, -1.0),
            (12, 18, 1.0),
            (13, 6, -2.0),
            (13, 10, 2.0),
            (14, 4, -2.0),
            (14, 8, 2.0),
            (15, 5, -2.0),
            (15, 9, 2.0),
            (16, 0, -1.0),
            (16, 11, 1.0),
            (17, 8, -0.6000000000000001),
            (17, 15, 0.6000000000000001),
            (18, 1, -1.0),
            (18, 10, -0.6000000000000001),
            (18, 12, 1.0),
            (19, 1, 1.0),
            (19, 12, -1.0),
            (19, 17, 0.6000000000000001),
            (20, 2, -1.0),
            (20, 9, 0.6000000000000001),
            (20, 13, 1.0),
            (21, 2, 1.0),
            (21, 13, -1.0),
            (21, 16, -0.6000000000000001),
            (22, 3, 1.0),
            (23, 7, 1.0),
            (24, 14, 1.0),
            (25, 22, 1.0),
        ];
        let mut a = Mat::zeros(26, 26);
        for (i, j, v) in T {
            a[(i, j)] = v;
        }
        a
    }

    /// ‖A − U S Vᵀ‖_max, ‖UᵀU − I‖_max and ‖VᵀV − I‖_max.
    fn errors(a: &Mat<f64>, d: &Svd) -> (f64, f64, f64) {
        let k = d.s.len();
        let us = Mat::from_fn(a.nrows(), k, |i, j| d.u[(i, j)] * d.s[j]);
        let vk = Mat::from_fn(a.ncols(), k, |i, j| d.v[(i, j)]);
        let r = a - &us * vk.transpose();
        let max = |m: &Mat<f64>| {
            (0..m.nrows())
                .flat_map(|i| (0..m.ncols()).map(move |j| (i, j)))
                .map(|(i, j)| m[(i, j)].abs())
                .fold(0.0f64, f64::max)
        };
        let gu = d.u.transpose() * &d.u - Mat::<f64>::identity(d.u.ncols(), d.u.ncols());
        let gv = d.v.transpose() * &d.v - Mat::<f64>::identity(d.v.ncols(), d.v.ncols());
        (max(&r), max(&gu), max(&gv))
    }

    #[test]
    fn the_fuzz_matrix_on_which_faer_fails_is_decomposed() {
        let a = faer_failure();
        // the reason this module exists (faer 0.24.4); after a faer upgrade
        // that fixes it, the first rung answers and the checks still hold
        let faer_fails = a.svd().is_err();
        for thin in [false, true] {
            let d = decompose(a.as_ref(), thin).unwrap();
            if faer_fails {
                assert_eq!(d.method, SvdMethod::FaerTransposed);
            }
            let (r, gu, gv) = errors(&a, &d);
            assert!(r < 1e-13 && gu < 1e-13 && gv < 1e-13, "{r} {gu} {gv}");
            assert!((d.s[25] - 0.10826864).abs() < 1e-7, "{}", d.s[25]);
            assert!((d.s[0] - 2.97577858).abs() < 1e-7, "{}", d.s[0]);
        }
        let s = singular_values(a.as_ref()).unwrap();
        assert!((s[25] - 0.10826864).abs() < 1e-7);
    }

    #[test]
    fn the_nalgebra_rung_is_sorted_complete_and_orthonormal() {
        // rectangular both ways and rank-deficient, so that the full factors
        // need the completed null-space columns
        let wide = Mat::from_fn(3, 5, |i, j| {
            ((i + 1) * (j + 2)) as f64 + (i == j) as u8 as f64
        });
        for a in [wide.clone(), wide.transpose().to_owned(), faer_failure()] {
            for thin in [false, true] {
                let (u, s, v) = nalgebra_svd(a.as_ref(), thin).unwrap();
                let d = Svd {
                    u,
                    s,
                    v,
                    method: SvdMethod::Nalgebra,
                };
                let k = a.nrows().min(a.ncols());
                assert_eq!(d.s.len(), k);
                assert!(d.s.windows(2).all(|w| w[0] >= w[1]), "{:?}", d.s);
                let (cu, cv) = if thin { (k, k) } else { (a.nrows(), a.ncols()) };
                assert_eq!((d.u.ncols(), d.v.ncols()), (cu, cv));
                let (r, gu, gv) = errors(&a, &d);
                assert!(r < 1e-12 && gu < 1e-12 && gv < 1e-12, "{r} {gu} {gv}");
                let f = faer_svd(a.as_ref(), true).or_else(|| faer_svd(a.transpose(), true));
                let (_, sf, _) = f.unwrap();
                for (x, y) in d.s.iter().zip(&sf) {
                    assert!((x - y).abs() < 1e-12 * sf[0], "{x} {y}");
                }
            }
        }
    }

    #[test]
    fn rank_and_null_spaces_of_a_rank_deficient_matrix() {
        // rank 2: the third row is the sum of the first two
        let a = faer::mat![
            [1.0, 2.0, 3.0, 4.0],
            [0.0, 1.0, 0.0, 1.0],
            [1.0, 3.0, 3.0, 5.0]
        ];
        let d = svd(a.as_ref()).unwrap();
        assert_eq!(d.rank(1e-12), 2);
        // the trailing column of U is a left null vector, the trailing two of V right ones
        let left = Mat::from_fn(3, 1, |i, _| d.u[(i, 2)]);
        let right = Mat::from_fn(4, 2, |i, j| d.v[(i, 2 + j)]);
        let l = left.transpose() * &a;
        let r = &a * &right;
        assert!((0..4).all(|j| l[(0, j)].abs() < 1e-13));
        assert!((0..3).all(|i| (0..2).all(|j| r[(i, j)].abs() < 1e-13)));
    }

    #[test]
    fn non_finite_input_names_the_entry_and_empty_input_is_empty() {
        let mut a = Mat::<f64>::identity(3, 4);
        a[(2, 1)] = f64::NAN;
        let e = svd(a.as_ref()).unwrap_err();
        assert!(
            matches!(e, SvdError::NonFinite { row: 2, col: 1, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("row 2, column 1"), "{e}");
        assert!(singular_values(a.as_ref()).is_err());
        let z = Mat::<f64>::zeros(0, 3);
        let d = svd(z.as_ref()).unwrap();
        assert_eq!(
            (d.u.nrows(), d.u.ncols(), d.v.nrows(), d.v.ncols()),
            (0, 0, 3, 3)
        );
        assert!(d.s.is_empty());
    }
}
