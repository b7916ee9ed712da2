//! Names of coordinates for error messages: which node, element or mode
//! group a coordinate belongs to, and labels of degrees of freedom such as
//! `DOF q3 = S.x (node S)`. Only error paths call these (they allocate).

use crate::mechanism::{Coordinate, Mechanism};

impl Mechanism {
    /// What a coordinate belongs to: `node S`, `element beam, nodes A, B`
    /// (chain members: `element arm.3 of arm, nodes …`) or `mode group w1`.
    /// Empty for an index out of range.
    pub fn coordinate_owner(&self, c: Coordinate) -> String {
        match c {
            Coordinate::Node(i) => self.nodal_owner(i),
            Coordinate::Def(j) => self.deformation_owner(j),
        }
    }

    /// The node (or mode group) of nodal coordinate `i`. Nodes that share a
    /// position (`position_of`) are all named.
    fn nodal_owner(&self, i: usize) -> String {
        let nodes: Vec<&str> = self
            .nodes
            .iter()
            .filter(|n| {
                n.position.contains(&i) || n.orientation.as_ref().is_some_and(|o| o.contains(&i))
            })
            .map(|n| n.id.as_str())
            .collect();
        if !nodes.is_empty() {
            let s = if nodes.len() > 1 { "s" } else { "" };
            return format!("node{s} {}", nodes.join(", "));
        }
        match self.mode_groups.iter().find(|(_, idx)| idx.contains(&i)) {
            Some((g, _)) => format!("mode group {g}"),
            None => String::new(),
        }
    }

    /// The element of deformation `j`, with its nodes.
    fn deformation_owner(&self, j: usize) -> String {
        let Some(e) = self
            .elements
            .iter()
            .find(|e| (e.eps_offset..e.eps_offset + e.element.n_eps()).contains(&j))
        else {
            return String::new();
        };
        if e.id.ends_with(".norm") {
            // the normalization of a node's Euler parameters
            return format!("node {}", e.group);
        }
        let of = if e.group != e.id {
            format!(" of {}", e.group)
        } else {
            String::new()
        };
        let nodes: Vec<&str> = self
            .nodes
            .iter()
            .filter(|n| {
                n.position
                    .iter()
                    .chain(n.orientation.iter().flatten())
                    .any(|i| e.x_index.contains(i))
            })
            .map(|n| n.id.as_str())
            .collect();
        if nodes.is_empty() {
            return format!("element {}{of}", e.id);
        }
        format!("element {}{of}, nodes {}", e.id, nodes.join(", "))
    }

    /// A coordinate for messages: `S.x (node S)`.
    pub fn coordinate_label(&self, c: Coordinate) -> String {
        let name = match c {
            Coordinate::Node(i) => self.x_names.get(i),
            Coordinate::Def(j) => self.eps_names.get(j),
        };
        match name {
            Some(n) => format!("{n} ({})", self.coordinate_owner(c)),
            None => format!("{c:?} (out of range)"),
        }
    }

    /// Degree of freedom `k` for messages, numbered as `flexmb info` lists
    /// them: `DOF q3 = S.x (node S)`.
    pub fn dof_label(&self, k: usize) -> String {
        match self.dofs.get(k) {
            Some(c) => format!("DOF q{k} = {}", self.coordinate_label(*c)),
            None => format!("DOF q{k} (of {})", self.dofs.len()),
        }
    }

    /// Component `i` of a first-order state y = (q, q̇) for messages:
    /// `DOF q3 = S.x (node S)` or `the rate of DOF q3 = S.x (node S)`.
    pub fn state_label(&self, i: usize) -> String {
        let n = self.n_dof();
        if i < n {
            self.dof_label(i)
        } else {
            format!("the rate of {}", self.dof_label(i - n))
        }
    }
}
