//! Charts of the Euler parameters of orientation nodes with nodal DOFs.
//!
//! A node whose orientation is free (three Euler parameters are degrees of
//! freedom) has its fourth parameter made dependent by the normalization
//! λᵀλ = 1 (thesis (2.9)). That choice is a chart of the unit sphere: it is
//! regular only while the dependent parameter stays away from zero, i.e.
//! within 180° of the orientation where it was chosen. A body that turns
//! further needs another chart: the component that is now largest becomes
//! the dependent one, and the one it replaces becomes a DOF in the same slot
//! of q.
//!
//! The rule (see docs/ARCHITECTURE.md): a node's chart is switched when its
//! dependent parameter falls below half of the largest of its four
//! components in magnitude. The largest component of a unit quaternion is at
//! least ½, so along a continuous motion the switch happens while the
//! dependent parameter is still about ¼ or more, far from the singularity
//! at zero. The new dependent parameter is the largest one, so the next
//! switch is a factor two in ratio away (no chattering).

use crate::mechanism::{Coordinate, Mechanism, XRole};

/// Switch when |λ_dependent| < `CHART_SWITCH_RATIO` · max_i |λ_i|.
pub const CHART_SWITCH_RATIO: f64 = 0.5;

/// One orientation node whose normalization determines one Euler parameter
/// while the other three are degrees of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EulerChart {
    /// Index of the node in [`Mechanism::nodes`].
    pub node: usize,
    /// Nodal-coordinate index of the dependent parameter.
    pub dependent: usize,
    /// Its index among the dependent coordinates (`XRole::Dependent(k)`).
    pub dependent_slot: usize,
    /// The three DOF parameters: (slot in q, nodal-coordinate index).
    pub dofs: [(usize, usize); 3],
}

impl EulerChart {
    /// The component that should become the dependent one at the DOF values
    /// `q`, as (q slot, nodal-coordinate index), if this chart is no longer
    /// good there. Uses only q: |λ_dep| = √(1 − Σ q_j²).
    pub fn needs_switch(&self, q: &[f64]) -> Option<(usize, usize)> {
        let s: f64 = self.dofs.iter().map(|(j, _)| q[*j] * q[*j]).sum();
        let dep = (1.0 - s).max(0.0).sqrt();
        let (slot, big) = self
            .dofs
            .iter()
            .copied()
            .max_by(|a, b| q[a.0].abs().total_cmp(&q[b.0].abs()))?;
        (dep < CHART_SWITCH_RATIO * q[slot].abs()).then_some((slot, big))
    }
}

/// A chart switch that happened: for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartSwitch {
    /// Time of the switch (the load factor, in a static solve).
    pub t: f64,
    /// The node.
    pub node: String,
    /// The coordinate that was dependent and became a DOF (e.g. `A.l0`).
    pub now_dof: String,
    /// The coordinate that was a DOF and became dependent (e.g. `A.l2`).
    pub now_dependent: String,
}

impl Mechanism {
    /// The orientation nodes whose chart may need switching: exactly three
    /// Euler parameters are DOFs and the fourth is dependent.
    pub fn euler_charts(&self) -> Vec<EulerChart> {
        let mut out = vec![];
        for (n, node) in self.nodes.iter().enumerate() {
            let Some(o) = &node.orientation else { continue };
            if o.len() != 4 {
                continue;
            }
            let mut dofs = vec![];
            let mut dep = vec![];
            for &i in o {
                match self.x_roles[i] {
                    XRole::Dof(j) => dofs.push((j, i)),
                    XRole::Dependent(k) => dep.push((k, i)),
                    _ => {}
                }
            }
            if dofs.len() == 3 && dep.len() == 1 {
                out.push(EulerChart {
                    node: n,
                    dependent: dep[0].1,
                    dependent_slot: dep[0].0,
                    dofs: [dofs[0], dofs[1], dofs[2]],
                });
            }
        }
        out
    }

    /// Makes the nodal coordinate `x_new_dep` of `chart` (now the DOF in q
    /// slot `slot`) dependent, and the chart's dependent coordinate the DOF in
    /// that slot. Everything else (constraint rows, other roles) is unchanged.
    pub fn switch_chart(
        &mut self,
        chart: &EulerChart,
        slot: usize,
        x_new_dep: usize,
        t: f64,
    ) -> ChartSwitch {
        debug_assert_eq!(self.x_roles[x_new_dep], XRole::Dof(slot));
        let old = chart.dependent;
        self.x_roles[old] = XRole::Dof(slot);
        self.x_roles[x_new_dep] = XRole::Dependent(chart.dependent_slot);
        self.dofs[slot] = Coordinate::Node(old);
        self.dependent[chart.dependent_slot] = x_new_dep;
        ChartSwitch {
            t,
            node: self.nodes[chart.node].id.clone(),
            now_dof: self.x_names[old].clone(),
            now_dependent: self.x_names[x_new_dep].clone(),
        }
    }
}
