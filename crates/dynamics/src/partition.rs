//! Generalized coordinate partitioning at run time: when the kinematic
//! Jacobian J = ∂D_c/∂x_dep (thesis (5.8a), (6.6a)) of the dependent nodal
//! coordinates gets ill-conditioned along a motion, the dependent set is
//! chosen again at the current configuration, and q, q̇ are mapped through
//! x, ẋ as for an Euler-parameter chart (docs/ARCHITECTURE.md,
//! "Re-partitioning of nodal DOFs").
//!
//! The choice: a column-pivoted Householder QR of the constraint Jacobian
//! D_c,x over the eligible coordinates
//! ([`flexmb_model::Mechanism::partition_eligible`]) and the dependent ones
//! that are not eligible (those come first, they stay dependent), picking
//! at each step the column with the largest part orthogonal to those
//! picked, a current dependent one weighted by [`KEEP_PREFERENCE`]. The
//! picked columns are a well-conditioned square block; the others are the
//! new DOFs.

use crate::{Dynamics, DynamicsError};
use flexmb_model::{Mechanism, PartitionSwitch, XRole};
use std::sync::Arc;

/// Re-partition when the pivot ratio of J falls below this fraction of its
/// value just after the dependent set was chosen.
pub const PARTITION_SWITCH_RATIO: f64 = 0.1;

/// A current dependent coordinate's column counts this many times its
/// length in the choice: the set changes only for a clearly better one.
pub const KEEP_PREFERENCE: f64 = 2.0;

/// The state of a run's watch on the dependent set.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PartitionWatch {
    /// The pivot ratio of J just after the set was chosen.
    pub(crate) reference: f64,
}

impl PartitionWatch {
    /// Whether the pivot ratio `now` calls for a new choice.
    pub(crate) fn degraded(&self, now: f64) -> bool {
        now < PARTITION_SWITCH_RATIO * self.reference
    }
}

impl Dynamics {
    /// A watch on the dependent set at the current (solved) configuration,
    /// if this mechanism has one to re-choose.
    pub(crate) fn partition_watch(&mut self) -> Option<PartitionWatch> {
        if self.mech.partition_eligible().is_empty() {
            return None;
        }
        Some(PartitionWatch {
            reference: self.kin.pivot_ratio_at_x(),
        })
    }

    /// The best-conditioned dependent set at the current (solved)
    /// configuration, by the column-pivoted QR of the module docs, as nodal
    /// coordinate indices in the order of the picks. `None` if the
    /// constraint Jacobian has no square regular block over the candidates
    /// (a picked column is at the rounding level of the largest).
    pub fn best_dependent_set(&self) -> Option<Vec<usize>> {
        let mech = &self.mech;
        let eligible = mech.partition_eligible();
        let forced: Vec<usize> = mech
            .dependent
            .iter()
            .copied()
            .filter(|i| !eligible.contains(i))
            .collect();
        let cols: Vec<usize> = forced.iter().chain(&eligible).copied().collect();
        let a = constraint_jacobian(mech, |k| self.kin.element_jacobian(k), &cols);
        let n_c = mech.constraint_rows.len();
        let weight: Vec<f64> = cols
            .iter()
            .map(|i| match mech.x_roles[*i] {
                XRole::Dependent(_) => KEEP_PREFERENCE,
                _ => 1.0,
            })
            .collect();
        let picks = pivoted_qr_picks(a, n_c, cols.len(), forced.len(), &weight)?;
        Some(picks.into_iter().map(|c| cols[c]).collect())
    }

    /// [`best_dependent_set`](Self::best_dependent_set) if it is not the
    /// current one.
    pub fn better_dependent_set(&self) -> Option<Vec<usize>> {
        let mut best = self.best_dependent_set()?;
        best.sort_unstable();
        let mut now = self.mech.dependent.clone();
        now.sort_unstable();
        (best != now).then_some(best)
    }

    /// Chooses the dependent set again at (t, q, q̇) if a better one exists
    /// ([`best_dependent_set`](Self::best_dependent_set)): rebuilds the
    /// dynamics with it, its position solve starting from the current
    /// configuration, and returns q, q̇ in it (mapped through x, ẋ). `None`
    /// if the set stays. The switch is appended to `log`.
    pub fn switch_partition(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        log: &mut Vec<PartitionSwitch>,
    ) -> Result<Option<(Vec<f64>, Vec<f64>)>, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        let Some(best) = self.best_dependent_set() else {
            return Ok(None);
        };
        let mut mech = (*self.mech).clone();
        let Some(sw) = mech.repartition(&best, t) else {
            return Ok(None);
        };
        log.push(sw);
        let x = self.kin.x().to_vec();
        let mech = Arc::new(mech);
        let (q1, qd1) = self.in_chart_of(&mech);
        self.replace_mechanism(mech);
        self.kin.set_guess(&x);
        self.kinematics_at(t, &q1, None)?;
        Ok(Some((q1, qd1)))
    }
}

/// D_c,x over the nodal coordinates `cols` (column-major, constraint rows ×
/// `cols.len()`), from the element Jacobians `jac(k)` (row-major, as
/// [`flexmb_kinematics::Kinematics::element_jacobian`]).
fn constraint_jacobian<'a>(
    mech: &Mechanism,
    jac: impl Fn(usize) -> &'a [f64],
    cols: &[usize],
) -> Vec<f64> {
    let n_c = mech.constraint_rows.len();
    let mut row_of = vec![usize::MAX; mech.n_eps()];
    for (r, j) in mech.constraint_rows.iter().enumerate() {
        row_of[*j] = r;
    }
    let mut col_of = vec![usize::MAX; mech.n_x()];
    for (c, i) in cols.iter().enumerate() {
        col_of[*i] = c;
    }
    let mut a = vec![0.0; n_c * cols.len()];
    for (k, e) in mech.elements.iter().enumerate() {
        let (ne, nx) = (e.element.n_eps(), e.element.n_x());
        let jl = jac(k);
        for la in 0..ne {
            let r = row_of[e.eps_offset + la];
            if r == usize::MAX {
                continue;
            }
            for (lc, gi) in e.x_index.iter().enumerate() {
                let c = col_of[*gi];
                if c != usize::MAX {
                    a[c * n_c + r] += jl[la * nx + lc];
                }
            }
        }
    }
    a
}

/// Column-pivoted Householder QR of the column-major `rows × cols` matrix
/// `a`: the first `forced` columns are taken in order, then `rows − forced`
/// more, each the one of largest weighted norm orthogonal to those taken
/// (`weight` per column). Returns the taken columns, or `None` when one of
/// them is at the rounding level of the largest column.
fn pivoted_qr_picks(
    mut a: Vec<f64>,
    rows: usize,
    cols: usize,
    forced: usize,
    weight: &[f64],
) -> Option<Vec<usize>> {
    let col_norm = |a: &[f64], c: usize, from: usize| -> f64 {
        a[c * rows + from..(c + 1) * rows]
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt()
    };
    let largest = (0..cols).map(|c| col_norm(&a, c, 0)).fold(0.0f64, f64::max);
    let mut taken = vec![false; cols];
    let mut picks = Vec::with_capacity(rows);
    for s in 0..rows {
        let c = if s < forced {
            s
        } else {
            (0..cols).filter(|c| !taken[*c]).max_by(|x, y| {
                (weight[*x] * col_norm(&a, *x, s)).total_cmp(&(weight[*y] * col_norm(&a, *y, s)))
            })?
        };
        let norm = col_norm(&a, c, s);
        if !(norm > 1e3 * f64::EPSILON * largest) {
            return None;
        }
        taken[c] = true;
        picks.push(c);
        // the reflection H = I − 2vvᵀ/vᵀv taking column c's rows s.. to ∓|.|e_s
        let mut v: Vec<f64> = a[c * rows + s..(c + 1) * rows].to_vec();
        v[0] += if v[0] >= 0.0 { norm } else { -norm };
        let vv: f64 = v.iter().map(|x| x * x).sum();
        if vv == 0.0 {
            continue;
        }
        for d in 0..cols {
            if taken[d] && d != c {
                continue;
            }
            let col = &mut a[d * rows + s..(d + 1) * rows];
            let dot: f64 = col.iter().zip(&v).map(|(x, y)| x * y).sum();
            let f = 2.0 * dot / vv;
            for (x, y) in col.iter_mut().zip(&v) {
                *x -= f * y;
            }
        }
    }
    Some(picks)
}

#[cfg(test)]
mod tests {
    use super::pivoted_qr_picks;

    #[test]
    fn the_picks_are_the_best_conditioned_columns_with_the_forced_first() {
        // 2 × 4, column-major: c0 = (1, 0), c1 = (1, 1e-3), c2 = (0, 1),
        // c3 = (2, 0)
        let a = vec![1.0, 0.0, 1.0, 1e-3, 0.0, 1.0, 2.0, 0.0];
        let w = [1.0; 4];
        // free: the largest, c3, then the one most orthogonal to it, c2
        assert_eq!(pivoted_qr_picks(a.clone(), 2, 4, 0, &w), Some(vec![3, 2]));
        // c0 forced: then c2 (c3 and c1 are nearly parallel to c0)
        assert_eq!(pivoted_qr_picks(a.clone(), 2, 4, 1, &w), Some(vec![0, 2]));
        // a weight of 3 on c0 makes it the first free pick
        let w0 = [3.0, 1.0, 1.0, 1.0];
        assert_eq!(pivoted_qr_picks(a.clone(), 2, 4, 0, &w0), Some(vec![0, 2]));
        // rank one: no regular square block
        let r1 = vec![1.0, 0.0, 2.0, 0.0];
        assert_eq!(pivoted_qr_picks(r1, 2, 2, 0, &[1.0; 2]), None);
    }
}
