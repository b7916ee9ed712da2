//! Re-partitioning of the nodal coordinates into degrees of freedom and
//! dependent ones (generalized coordinate partitioning).
//!
//! With absolute nodal coordinates as DOFs, the dependent coordinates are
//! solved from the constraint equations D_c(x) = (0, q_ε, u_ε) (thesis
//! (5.7), (6.5)); the choice made at the reference configuration is regular
//! only near it. A beam that has turned by 90° no longer determines the x
//! coordinates of its nodes by its rigid elongations, a node that has
//! turned by 180° no longer determines its dependent scalar Euler parameter
//! by the normalization (2.9). The remedy is to choose the dependent set
//! again at the current configuration (the choice itself is made from J in
//! `flexmb_dynamics`); this module does the bookkeeping: which coordinates
//! may change role, and the exchange of roles that keeps every slot of q
//! and of the dependent coordinates that does not change.
//!
//! The Euler parameters of a node with three DOF parameters are left to its
//! chart ([`crate::EulerChart`]): they are not [`partition_eligible`]
//! (Mechanism::partition_eligible), so both rules never act on one
//! coordinate.

use crate::mechanism::{Coordinate, Mechanism, XRole};

/// A change of the dependent set: for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct PartitionSwitch {
    /// Time (or load factor, in statics) of the switch.
    pub t: f64,
    /// The coordinates that were dependent and became DOFs (e.g. `T.y`).
    pub now_dof: Vec<String>,
    /// The coordinates that were DOFs and became dependent (e.g. `T.x`),
    /// each in the q slot of the one at the same place in `now_dof`.
    pub now_dependent: Vec<String>,
}

impl Mechanism {
    /// The nodal coordinates whose role a re-partitioning may change: DOFs
    /// and dependent coordinates, except the Euler parameters of the nodes
    /// that have a chart ([`euler_charts`](Self::euler_charts)). Empty when
    /// no such coordinate is a DOF or none is dependent (nothing to
    /// exchange), e.g. with deformations as DOFs.
    pub fn partition_eligible(&self) -> Vec<usize> {
        let charted: Vec<usize> = self
            .euler_charts()
            .iter()
            .flat_map(|c| {
                self.nodes[c.node]
                    .orientation
                    .clone()
                    .expect("a chart's node has an orientation")
            })
            .collect();
        let eligible: Vec<usize> = (0..self.n_x())
            .filter(|i| matches!(self.x_roles[*i], XRole::Dof(_) | XRole::Dependent(_)))
            .filter(|i| !charted.contains(i))
            .collect();
        let dofs = eligible
            .iter()
            .filter(|i| matches!(self.x_roles[**i], XRole::Dof(_)))
            .count();
        if dofs == 0 || dofs == eligible.len() {
            return vec![];
        }
        eligible
    }

    /// Makes exactly the nodal coordinates `dependent` (as many as
    /// [`Mechanism::dependent`] has, each a dependent coordinate now or one
    /// of [`partition_eligible`](Self::partition_eligible)) the dependent
    /// ones. A coordinate that stays in its role keeps its slot; each one
    /// that becomes a DOF takes the q slot of one that becomes dependent,
    /// which takes its dependent slot (in index order). Constraint rows,
    /// deformation roles and inputs are unchanged. `None` when `dependent`
    /// is the current set, or is not a valid one.
    pub fn repartition(&mut self, dependent: &[usize], t: f64) -> Option<PartitionSwitch> {
        if dependent.len() != self.dependent.len() {
            return None;
        }
        let eligible = self.partition_eligible();
        let valid = dependent.iter().all(|i| {
            *i < self.n_x()
                && (matches!(self.x_roles[*i], XRole::Dependent(_)) || eligible.contains(i))
        });
        let mut sorted = dependent.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        if !valid || sorted.len() != dependent.len() {
            return None;
        }
        // dependent now, a DOF after; a DOF now, dependent after
        let mut to_dof: Vec<usize> = self
            .dependent
            .iter()
            .copied()
            .filter(|i| !sorted.contains(i))
            .collect();
        let to_dep: Vec<usize> = sorted
            .iter()
            .copied()
            .filter(|i| matches!(self.x_roles[*i], XRole::Dof(_)))
            .collect();
        to_dof.sort_unstable();
        if to_dof.is_empty() {
            return None;
        }
        debug_assert_eq!(to_dof.len(), to_dep.len());
        for (&a, &b) in to_dof.iter().zip(&to_dep) {
            let (XRole::Dependent(k), XRole::Dof(j)) = (self.x_roles[a], self.x_roles[b]) else {
                unreachable!("roles checked above");
            };
            self.x_roles[a] = XRole::Dof(j);
            self.x_roles[b] = XRole::Dependent(k);
            self.dofs[j] = Coordinate::Node(a);
            self.dependent[k] = b;
        }
        Some(PartitionSwitch {
            t,
            now_dof: to_dof.iter().map(|i| self.x_names[*i].clone()).collect(),
            now_dependent: to_dep.iter().map(|i| self.x_names[*i].clone()).collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::{Coordinate, DofChoice, Scene, XRole};

    /// A planar arm of two rigid trusses with nodal DOFs: B.x, B.y, C.x,
    /// C.y with two rigid lengths, so two of them are dependent.
    fn arm() -> crate::Mechanism {
        let mut s = Scene::from_ron_str(
            r#"(
    dimension: Planar,
    materials: { "al": (e: 7.0e10, rho: 2700.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]), (id: "C", at: [2.0, 0.0]) ],
    elements: [
        (id: "t1", type: Truss(nodes: ("A", "B"), ea: 1.0e6, mass_per_length: 1.0)),
        (id: "t2", type: Truss(nodes: ("B", "C"), ea: 1.0e6, mass_per_length: 1.0)),
    ],
    fixed: [ Node("A") ],
    rigid: [ Def("t1", "*"), Def("t2", "*") ],
)"#,
        )
        .unwrap();
        s.dofs = DofChoice::NodalCoordinates;
        s.build(None).unwrap()
    }

    #[test]
    fn a_repartition_exchanges_roles_slot_by_slot_and_keeps_the_rest() {
        let mut m = arm();
        let before = m.clone();
        let el = m.partition_eligible();
        assert_eq!(el.len(), 4, "{:?}", m.x_names);
        let dep: Vec<usize> = m.dependent.clone();
        let dofs: Vec<usize> = el.iter().copied().filter(|i| !dep.contains(i)).collect();
        // the current set: nothing to do
        assert!(m.repartition(&dep, 0.0).is_none());
        // not a valid set: a repeated coordinate, a wrong count, a fixed one
        assert!(m.repartition(&[dep[0], dep[0]], 0.0).is_none());
        assert!(m.repartition(&dep[..1], 0.0).is_none());
        let fixed = (0..m.n_x())
            .find(|i| m.x_roles[*i] == XRole::Fixed)
            .unwrap();
        assert!(m.repartition(&[dep[0], fixed], 0.0).is_none());
        // exchange one: the new dependent takes the old one's dependent
        // slot, the old one its q slot
        let sw = m.repartition(&[dep[0], dofs[1]], 2.5).unwrap();
        assert_eq!(sw.t, 2.5);
        assert_eq!(sw.now_dof, vec![m.x_names[dep[1]].clone()]);
        assert_eq!(sw.now_dependent, vec![m.x_names[dofs[1]].clone()]);
        let XRole::Dof(j) = before.x_roles[dofs[1]] else {
            panic!()
        };
        assert_eq!(m.dofs[j], Coordinate::Node(dep[1]));
        assert_eq!(m.x_roles[dep[1]], XRole::Dof(j));
        assert_eq!(m.x_roles[dofs[1]], XRole::Dependent(1));
        assert_eq!(m.dependent, vec![dep[0], dofs[1]]);
        // everything else as it was
        assert_eq!(m.x_roles[dep[0]], before.x_roles[dep[0]]);
        assert_eq!(m.x_roles[dofs[0]], before.x_roles[dofs[0]]);
        assert_eq!(m.constraint_rows, before.constraint_rows);
        assert_eq!(m.e_roles, before.e_roles);
        // and back
        let back = m.repartition(&dep, 3.0).unwrap();
        assert_eq!(back.now_dof, sw.now_dependent);
        assert_eq!(m.x_roles, before.x_roles);
        assert_eq!(m.dofs, before.dofs);
        assert_eq!(m.dependent, before.dependent);
    }

    #[test]
    fn deformation_dofs_leave_nothing_to_repartition() {
        let mut s = Scene::from_ron_str(
            r#"(
    dimension: Planar,
    materials: { "al": (e: 7.0e10, rho: 2700.0) },
    sections: { "bar": Rectangle(by: 0.01, bz: 0.02) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
    elements: [ (id: "b", type: Beam((nodes: ("A", "B"), material: "al", section: "bar"))) ],
    fixed: [ Node("A") ],
)"#,
        )
        .unwrap();
        s.dofs = DofChoice::Deformations;
        let m = s.build(None).unwrap();
        assert!(m.partition_eligible().is_empty());
    }
}
