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
//! picked. The smallest of those parts, min |R_ii|, estimates the smallest
//! singular value of the picked block; the same QR over the current set
//! alone estimates its own. The set changes only if the new one's is
//! [`PARTITION_IMPROVEMENT`] times larger and at least
//! [`PARTITION_RECOVERY`] of what the current set had when it was chosen:
//! near a singular configuration of the mechanism itself (a stretched
//! toggle), where every set degrades alike, it stays, and the run ends
//! there as before, naming what failed.

use crate::{Dynamics, DynamicsError};
use flexmb_model::{Mechanism, PartitionSwitch};

/// q and q̇ in a new dependent set.
type StateInSet = (Vec<f64>, Vec<f64>);

/// Re-partition when the pivot ratio of J falls below this fraction of its
/// value just after the dependent set was chosen.
pub const PARTITION_SWITCH_RATIO: f64 = 0.1;

/// A new dependent set is taken only if its smallest singular value
/// (estimated by min |R_ii| of the pivoted QR) is this many times that of
/// the current set.
pub const PARTITION_IMPROVEMENT: f64 = 4.0;

/// … and at least this fraction of the current set's estimate when it was
/// chosen: a new set must restore the conditioning the mechanism had.
pub const PARTITION_RECOVERY: f64 = 0.5;

/// The state of a run's watch on the dependent set.
#[derive(Clone, Debug)]
pub(crate) struct PartitionWatch {
    /// The pivot ratio of J just after the set was chosen (or last found
    /// to be the best one).
    pub(crate) reference: f64,
    /// The configuration where the set was chosen.
    x_chosen: Vec<f64>,
    /// The estimated smallest singular value of J there, computed when a
    /// run first needs it ([`quality`](Self::quality)): the pivoted QR over
    /// every dependent coordinate is cubic in their number (5 s for the
    /// 1520 of the chapter-4 mechanism with its end-effector's x and y as
    /// DOFs), and most runs never degrade.
    quality: Option<f64>,
}

impl PartitionWatch {
    /// Whether the pivot ratio `now` calls for a new choice.
    pub(crate) fn degraded(&self, now: f64) -> bool {
        now < PARTITION_SWITCH_RATIO * self.reference
    }

    /// The estimated smallest singular value of J at the configuration
    /// where the set was chosen (`dy` on the same mechanism as then).
    pub(crate) fn quality(&mut self, dy: &Dynamics) -> f64 {
        if let Some(q) = self.quality {
            return q;
        }
        let q = dy.set_quality_at(&self.x_chosen).unwrap_or(0.0);
        self.quality = Some(q);
        q
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
            reference: self.kin.pivot_ratio(),
            x_chosen: self.kin.x().to_vec(),
            quality: None,
        })
    }

    /// [`current_set_quality`](Self::current_set_quality) at the nodal
    /// coordinates `x` (element Jacobians evaluated there, not those of the
    /// kinematics' current configuration).
    fn set_quality_at(&self, x: &[f64]) -> Option<f64> {
        let jacobians: Vec<Vec<f64>> = self
            .mech
            .elements
            .iter()
            .map(|e| {
                let (ne, nx) = (e.element.n_eps(), e.element.n_x());
                let mut xl = vec![0.0; nx];
                e.gather(x, &mut xl);
                let (mut eps, mut jac) = (vec![0.0; ne], vec![0.0; ne * nx]);
                e.element
                    .deformations_and_jacobian(&xl, None, &mut eps, &mut jac);
                jac
            })
            .collect();
        let eligible = self.mech.partition_eligible();
        let (forced, rest): (Vec<usize>, Vec<usize>) = self
            .mech
            .dependent
            .iter()
            .partition(|i| !eligible.contains(i));
        let cols: Vec<usize> = forced.iter().chain(&rest).copied().collect();
        let a = constraint_jacobian(&self.mech, |k| &jacobians[k], &cols);
        let n_c = self.mech.constraint_rows.len();
        pivoted_qr_picks(a, n_c, cols.len(), forced.len()).map(|(_, r)| r)
    }

    /// The best-conditioned dependent set at the current (solved)
    /// configuration, by the column-pivoted QR of the module docs, as nodal
    /// coordinate indices in the order of the picks, with its estimated
    /// smallest singular value. `None` if the constraint Jacobian has no
    /// square regular block over the candidates (a picked column is at the
    /// rounding level of the largest).
    pub fn best_dependent_set(&self) -> Option<(Vec<usize>, f64)> {
        self.best_dependent_set_keeping(&[])
    }

    /// [`best_dependent_set`](Self::best_dependent_set) with the
    /// coordinates of the DOF slots `keep` kept as DOFs (the held DOFs of a
    /// static solve: a held value must keep its meaning).
    fn best_dependent_set_keeping(&self, keep: &[usize]) -> Option<(Vec<usize>, f64)> {
        let kept = self.kept_coordinates(keep);
        let eligible: Vec<usize> = self
            .mech
            .partition_eligible()
            .into_iter()
            .filter(|i| !kept.contains(i))
            .collect();
        let forced: Vec<usize> = self
            .mech
            .dependent
            .iter()
            .copied()
            .filter(|i| !eligible.contains(i))
            .collect();
        self.pivoted_picks(&forced, &eligible)
    }

    /// The nodal coordinates in the DOF slots `keep`.
    fn kept_coordinates(&self, keep: &[usize]) -> Vec<usize> {
        keep.iter()
            .filter_map(|s| match self.mech.dofs.get(*s) {
                Some(flexmb_model::Coordinate::Node(i)) => Some(*i),
                _ => None,
            })
            .collect()
    }

    /// The same estimate for the current dependent set.
    fn current_set_quality(&self) -> Option<f64> {
        let eligible = self.mech.partition_eligible();
        let (forced, rest): (Vec<usize>, Vec<usize>) = self
            .mech
            .dependent
            .iter()
            .partition(|i| !eligible.contains(i));
        self.pivoted_picks(&forced, &rest).map(|(_, r)| r)
    }

    /// The pivoted QR of D_c,x over the columns `forced` (taken in order)
    /// and `free` (picked): the picks as nodal coordinates and min |R_ii|.
    fn pivoted_picks(&self, forced: &[usize], free: &[usize]) -> Option<(Vec<usize>, f64)> {
        let cols: Vec<usize> = forced.iter().chain(free).copied().collect();
        let a = constraint_jacobian(&self.mech, |k| self.kin.element_jacobian(k), &cols);
        let n_c = self.mech.constraint_rows.len();
        let (picks, r_min) = pivoted_qr_picks(a, n_c, cols.len(), forced.len())?;
        Some((picks.into_iter().map(|c| cols[c]).collect(), r_min))
    }

    /// [`best_dependent_set`](Self::best_dependent_set), with the
    /// coordinates of the DOF slots `keep` kept as DOFs, if it is another
    /// set than the current one, [`PARTITION_IMPROVEMENT`] times better
    /// conditioned, and at least [`PARTITION_RECOVERY`] times as well as
    /// `chosen` (the current set's estimate when it was chosen).
    pub(crate) fn better_dependent_set(&self, chosen: f64, keep: &[usize]) -> Option<Vec<usize>> {
        let (mut best, r_best) = self.best_dependent_set_keeping(keep)?;
        best.sort_unstable();
        let mut now = self.mech.dependent.clone();
        now.sort_unstable();
        let r_now = self.current_set_quality().unwrap_or(0.0);
        let better =
            r_best > PARTITION_IMPROVEMENT * r_now && r_best >= PARTITION_RECOVERY * chosen;
        (best != now && better).then_some(best)
    }

    /// Chooses the dependent set again at (t, q, q̇) if a better one exists
    /// ([`best_dependent_set`](Self::best_dependent_set), better as for the
    /// run's watch: [`PARTITION_IMPROVEMENT`] times the current set's
    /// estimate and `PARTITION_RECOVERY` of `chosen`, the estimate the
    /// current set had when it was chosen; 0 to require only the first),
    /// the coordinates of the DOF slots `keep` staying DOFs (the held DOFs
    /// of a static solve): rebuilds the dynamics with it, its position
    /// solve starting from the current configuration, and returns q, q̇ in
    /// it (mapped through x, ẋ). `None` if the set stays. The switch is
    /// appended to `log`.
    pub fn switch_partition(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        chosen: f64,
        keep: &[usize],
        log: &mut Vec<PartitionSwitch>,
    ) -> Result<Option<StateInSet>, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        let Some(best) = self.better_dependent_set(chosen, keep) else {
            return Ok(None);
        };
        let mut mech = (*self.mech).clone();
        let Some(sw) = mech.repartition(&best, t) else {
            return Ok(None);
        };
        log.push(sw);
        self.adopt(t, mech).map(Some)
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
/// more, each the one with the largest part orthogonal to those taken.
/// Returns the taken columns and the smallest of those parts (min |R_ii|),
/// or `None` when one of them is at the rounding level of the largest
/// column.
fn pivoted_qr_picks(
    mut a: Vec<f64>,
    rows: usize,
    cols: usize,
    forced: usize,
) -> Option<(Vec<usize>, f64)> {
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
    let mut r_min = f64::INFINITY;
    for s in 0..rows {
        let c = if s < forced {
            s
        } else {
            (0..cols)
                .filter(|c| !taken[*c])
                .max_by(|x, y| col_norm(&a, *x, s).total_cmp(&col_norm(&a, *y, s)))?
        };
        let norm = col_norm(&a, c, s);
        // (a NaN norm fails too)
        if norm.is_nan() || norm <= 1e3 * f64::EPSILON * largest {
            return None;
        }
        r_min = r_min.min(norm);
        taken[c] = true;
        picks.push(c);
        // the reflection H = I − 2vvᵀ/vᵀv taking column c's rows s.. to ∓|.|e_s
        let mut v: Vec<f64> = a[c * rows + s..(c + 1) * rows].to_vec();
        v[0] += if v[0] >= 0.0 { norm } else { -norm };
        let vv: f64 = v.iter().map(|x| x * x).sum();
        for d in (0..cols).filter(|d| !taken[*d] || *d == c) {
            let col = &mut a[d * rows + s..(d + 1) * rows];
            let dot: f64 = col.iter().zip(&v).map(|(x, y)| x * y).sum();
            let f = 2.0 * dot / vv;
            for (x, y) in col.iter_mut().zip(&v) {
                *x -= f * y;
            }
        }
    }
    Some((picks, r_min))
}

#[cfg(test)]
mod tests {
    use super::pivoted_qr_picks;

    #[test]
    fn the_picks_are_the_best_conditioned_columns_with_the_forced_first() {
        // 2 × 4, column-major: c0 = (1, 0), c1 = (1, 1e-3), c2 = (0, 1),
        // c3 = (2, 0)
        let a = vec![1.0, 0.0, 1.0, 1e-3, 0.0, 1.0, 2.0, 0.0];
        let picks = |forced| pivoted_qr_picks(a.clone(), 2, 4, forced).unwrap();
        // free: the largest, c3, then the one most orthogonal to it, c2;
        // R = diag(2, 1)
        assert_eq!(picks(0), (vec![3, 2], 1.0));
        // c0 forced: then c2 (c3 and c1 are nearly parallel to c0)
        assert_eq!(picks(1).0, vec![0, 2]);
        // c0 and c1 forced: |R_22| = 1e-3, the block's smallest singular
        // value to first order
        let (p, r) = pivoted_qr_picks(vec![1.0, 0.0, 1.0, 1e-3], 2, 2, 2).unwrap();
        assert_eq!(p, vec![0, 1]);
        assert!((r - 1e-3).abs() < 1e-15, "{r}");
        // rank one: no regular square block
        assert_eq!(pivoted_qr_picks(vec![1.0, 0.0, 2.0, 0.0], 2, 2, 0), None);
    }
}
