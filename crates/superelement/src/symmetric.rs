//! Assembling a symmetric sparse matrix from entries given in any mix of
//! triangles, as FE packages export them: Abaqus's `FORMAT=COORDINATE` both
//! triangles, its `FORMAT=MATRIX INPUT` one triangle of its own equation
//! order (which becomes a mix once the equations are renumbered), ANSYS's
//! Harwell–Boeing the lower triangle.

use crate::Error;
use faer::sparse::SparseColMat;
use std::collections::HashMap;

/// Relative agreement required of an entry given in both triangles.
const MIRROR_RTOL: f64 = 1e-9;

/// The upper triangle (with the diagonal) of the n × n symmetric matrix whose
/// entries `(row, col, value)` (0-based) are given in either or both
/// triangles. An entry given twice at the same position, or in both triangles
/// with different values, is an error naming `file` and both equations
/// (described by `describe`).
pub(crate) fn assemble_upper(
    n: usize,
    entries: &[(usize, usize, f64)],
    file: &str,
    describe: &dyn Fn(usize) -> String,
) -> Result<SparseColMat<usize, f64>, Error> {
    let mut at: HashMap<(usize, usize), f64> = HashMap::with_capacity(entries.len());
    for &(i, j, v) in entries {
        if i >= n || j >= n {
            return Err(Error::parse(
                file,
                0,
                format!("entry ({}, {}) outside the {n} equations", i + 1, j + 1),
            ));
        }
        if at.insert((i, j), v).is_some() {
            return Err(Error::parse(
                file,
                0,
                format!(
                    "the entry of {} and {} is given twice",
                    describe(i),
                    describe(j)
                ),
            ));
        }
    }
    let mut upper: Vec<faer::sparse::Triplet<usize, usize, f64>> = Vec::with_capacity(at.len());
    for (&(i, j), &v) in &at {
        let (r, c) = (i.min(j), i.max(j));
        if i > j {
            if let Some(&w) = at.get(&(j, i)) {
                let scale = v.abs().max(w.abs());
                if (v - w).abs() > MIRROR_RTOL * scale {
                    return Err(Error::parse(
                        file,
                        0,
                        format!(
                            "the matrix is not symmetric: the entry of {} and {} is {v:e} in one triangle and {w:e} \
                             in the other",
                            describe(i),
                            describe(j)
                        ),
                    ));
                }
                // the upper-triangle copy is kept
                continue;
            }
        }
        upper.push(faer::sparse::Triplet::new(r, c, v));
    }
    SparseColMat::try_new_from_triplets(n, n, &upper)
        .map_err(|e| Error::parse(file, 0, format!("{e:?}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense(a: &SparseColMat<usize, f64>) -> Vec<Vec<f64>> {
        let n = a.nrows();
        let mut d = vec![vec![0.0; n]; n];
        for j in 0..n {
            let col = a.as_ref().col_range(j);
            let rows = &a.symbolic().row_idx()[col.clone()];
            let vals = &a.val()[col];
            for (&i, &v) in rows.iter().zip(vals) {
                d[i][j] += v;
            }
        }
        d
    }

    #[test]
    fn one_triangle_both_triangles_and_a_mix_give_the_same_upper_triangle() {
        let name = |e: usize| format!("eq {e}");
        let full = [
            (0, 0, 4.0),
            (0, 1, 1.0),
            (1, 0, 1.0),
            (1, 1, 3.0),
            (2, 0, -2.0),
            (0, 2, -2.0),
            (2, 2, 5.0),
        ];
        let lower = [
            (0, 0, 4.0),
            (1, 0, 1.0),
            (1, 1, 3.0),
            (2, 0, -2.0),
            (2, 2, 5.0),
        ];
        let mixed = [
            (0, 0, 4.0),
            (0, 1, 1.0),
            (1, 1, 3.0),
            (2, 0, -2.0),
            (2, 2, 5.0),
        ];
        let want = vec![
            vec![4.0, 1.0, -2.0],
            vec![0.0, 3.0, 0.0],
            vec![0.0, 0.0, 5.0],
        ];
        for e in [&full[..], &lower[..], &mixed[..]] {
            let a = assemble_upper(3, e, "f", &name).unwrap();
            assert_eq!(dense(&a), want);
        }
    }

    #[test]
    fn asymmetry_and_repeated_entries_name_the_equations() {
        let name = |e: usize| format!("eq {e}");
        let e = assemble_upper(2, &[(0, 1, 1.0), (1, 0, 1.5)], "k.mtx", &name).unwrap_err();
        assert!(
            e.to_string().contains("not symmetric") && e.to_string().contains("eq 1"),
            "{e}"
        );
        let e = assemble_upper(2, &[(0, 1, 1.0), (0, 1, 1.0)], "k.mtx", &name).unwrap_err();
        assert!(e.to_string().contains("given twice"), "{e}");
        let e = assemble_upper(2, &[(0, 2, 1.0)], "k.mtx", &name).unwrap_err();
        assert!(e.to_string().contains("outside"), "{e}");
    }
}
