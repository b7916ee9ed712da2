//! Estimated null vectors of a (numerically) singular square matrix, to name
//! the coordinates of a motion that a singular tangent or mass matrix leaves
//! unrestrained. For error paths only: one dense LU with full pivoting,
//! O(n³) like the factorization that failed.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::full_pivoting::factor::{lu_in_place, lu_in_place_scratch};
use faer::{Mat, MatRef, Par};

/// Pivots of the full-pivoting LU below this fraction of the first are taken
/// as zero (the rank deficiency); the last pivot always is.
const NULL_PIVOT_RATIO: f64 = 1e-10;

/// Estimated null vectors of the square matrix `a`, at most `max` of them,
/// each scaled to a largest component of 1: with full pivoting,
/// P A Qᵀ = L U and U = [U₁₁ U₁₂; 0 ≈0] with U₁₁ of rank r, the null space
/// is Qᵀ [−U₁₁⁻¹ U₁₂; I]. The columns of the trailing pivots give one vector
/// each; the last pivot gives one even if it is not small (the matrix was
/// found singular by another test). Empty for an empty or non-finite `a`.
pub fn null_vectors(a: MatRef<'_, f64>, max: usize) -> Vec<Vec<f64>> {
    let n = a.nrows();
    if n == 0 || a.ncols() != n || max == 0 {
        return vec![];
    }
    if (0..n).any(|j| a.col(j).iter().any(|v| !v.is_finite())) {
        return vec![];
    }
    let mut lu = a.to_owned();
    let (mut rf, mut rb, mut cf, mut cb) = (vec![0; n], vec![0; n], vec![0; n], vec![0; n]);
    let mut mem = MemBuffer::new(lu_in_place_scratch::<usize, f64>(
        n,
        n,
        Par::Seq,
        Default::default(),
    ));
    lu_in_place(
        lu.as_mut(),
        &mut rf,
        &mut rb,
        &mut cf,
        &mut cb,
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    );
    let rank = numerical_rank(&lu);
    (rank..n)
        .rev()
        .take(max)
        .map(|k| {
            let z = trailing_null_vector(&lu, rank, k);
            // LU column b is column cf[b] of A
            let mut x = vec![0.0; n];
            for (b, v) in z.iter().enumerate() {
                x[cf[b]] = *v;
            }
            let m = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if m > 0.0 && m.is_finite() {
                x.iter_mut().for_each(|v| *v /= m);
            }
            x
        })
        .collect()
}

/// The number of leading pivots of the full-pivoting factor `lu` above
/// [`NULL_PIVOT_RATIO`] of the first, at most n − 1.
fn numerical_rank(lu: &Mat<f64>) -> usize {
    let n = lu.nrows();
    let first = lu[(0, 0)].abs();
    let r = (0..n)
        // (a NaN pivot counts as zero)
        .position(|k| {
            lu[(k, k)].abs().partial_cmp(&(NULL_PIVOT_RATIO * first))
                != Some(std::cmp::Ordering::Greater)
        })
        .unwrap_or(n);
    r.min(n - 1)
}

/// z with z_k = 1, zero at the other trailing pivots, and U₁₁ z₁ = −U[0..r, k]
/// (back substitution on the leading r rows of U).
fn trailing_null_vector(lu: &Mat<f64>, r: usize, k: usize) -> Vec<f64> {
    let n = lu.nrows();
    let mut z = vec![0.0; n];
    z[k] = 1.0;
    for i in (0..r).rev() {
        let s: f64 = (i + 1..r).map(|j| lu[(i, j)] * z[j]).sum::<f64>() + lu[(i, k)];
        z[i] = -s / lu[(i, i)];
    }
    z
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ‖A x‖∞ relative to ‖A‖∞ (x has a largest component of 1).
    fn residual(a: &Mat<f64>, x: &[f64]) -> f64 {
        let n = a.nrows();
        let norm = (0..n)
            .map(|i| (0..n).map(|j| a[(i, j)].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        (0..n)
            .map(|i| (0..n).map(|j| a[(i, j)] * x[j]).sum::<f64>().abs())
            .fold(0.0, f64::max)
            / norm
    }

    #[test]
    fn a_zero_row_and_column_give_their_unit_vector() {
        // the DOF 2 has no stiffness at all
        let a = Mat::from_fn(4, 4, |i, j| {
            if i == 2 || j == 2 {
                0.0
            } else if i == j {
                3.0 + i as f64
            } else {
                0.5
            }
        });
        let v = null_vectors(a.as_ref(), 3);
        assert_eq!(v.len(), 1);
        assert_eq!(v[0], vec![0.0, 0.0, 1.0, 0.0]);
    }

    #[test]
    fn a_coupled_null_vector_and_a_two_dimensional_null_space_are_found() {
        // rank 3 of 5, non-symmetric, null space spanned by two vectors
        let b = Mat::from_fn(5, 3, |i, j| ((i * 3 + j * 5) % 7) as f64 - 2.5);
        let c = Mat::from_fn(3, 5, |i, j| {
            ((i * 2 + j * 7) % 5) as f64 + 0.5 * i as f64 - 1.0
        });
        let a = &b * &c;
        let v = null_vectors(a.as_ref(), 6);
        assert_eq!(v.len(), 2);
        for x in &v {
            assert!(residual(&a, x) < 1e-12, "{x:?}: {}", residual(&a, x));
        }
        // independent
        let dot: f64 = v[0].iter().zip(&v[1]).map(|(p, q)| p * q).sum();
        let n0: f64 = v[0].iter().map(|p| p * p).sum();
        let n1: f64 = v[1].iter().map(|p| p * p).sum();
        assert!(dot.abs() < 0.999 * (n0 * n1).sqrt());
    }

    #[test]
    fn non_finite_and_empty_matrices_give_nothing() {
        let a = Mat::from_fn(2, 2, |i, _| if i == 0 { f64::NAN } else { 1.0 });
        assert!(null_vectors(a.as_ref(), 2).is_empty());
        assert!(null_vectors(Mat::<f64>::zeros(0, 0).as_ref(), 2).is_empty());
    }
}
