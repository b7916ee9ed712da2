//! The coordinates stage of the build ([`BuildStage::Coordinates`]): the
//! nodal coordinates x (positions, shared by `position_of`; an orientation,
//! a planar angle or four Euler parameters, only for the nodes whose
//! orientation an element uses; the mode groups' amplitudes) with their
//! reference values x0 and names, and the placement of every element on
//! them (its coordinate indices and deformation names), followed by one
//! normalization (2.9) per spatial orientation node.

use super::*;

/// The nodal coordinates of a mechanism.
pub(super) struct Coordinates {
    pub(super) nodes: Vec<NodeInfo>,
    pub(super) x0: Vec<f64>,
    pub(super) x_names: Vec<String>,
    /// Mode groups and their coordinate indices.
    pub(super) groups: Vec<(String, Vec<usize>)>,
}

/// Allocates the nodal coordinates of the nodes in declaration order, then
/// of the mode groups. A node given an `orientation` that no element uses is
/// an error.
pub(super) fn allocate(
    scene: &Scene,
    table: &NodeTable,
    set: &ElementSet,
) -> Result<Coordinates, ModelError> {
    let dim = scene.dimension;
    let nd = dim.position_len();
    let mut needs_orient: HashMap<String, bool> = HashMap::new();
    for e in &set.expanded {
        for a in &e.attach {
            match a {
                Attach::Orient(n) | Attach::Carried(n) => {
                    needs_orient.insert(n.clone(), true);
                }
                Attach::Pos(n) => {
                    needs_orient.entry(n.clone()).or_insert(false);
                }
                Attach::Group(_) => {}
            }
        }
    }
    for n in &scene.nodes {
        if n.orientation.is_some() && !needs_orient.get(&n.id).copied().unwrap_or(false) {
            return Err(ModelError::invalid(
                format!("node '{}' orientation", n.id),
                "no element uses the node's orientation (only beams, hinges, superelements, rigid bodies and planar masses with inertia do); remove it or attach such an element",
            ));
        }
    }
    let mut nodes = vec![];
    let mut x0 = vec![];
    let mut x_names = vec![];
    let mut position_of_node: HashMap<String, Vec<usize>> = HashMap::new();
    for id in &table.order {
        let at = table.at[id].clone();
        let position: Vec<usize> = match table.shares.get(id) {
            Some(root) => position_of_node[root].clone(),
            None => {
                let p: Vec<usize> = (0..nd).map(|k| x0.len() + k).collect();
                for (k, c) in ["x", "y", "z"].iter().take(nd).enumerate() {
                    x0.push(at[k]);
                    x_names.push(format!("{id}.{c}"));
                }
                p
            }
        };
        position_of_node.insert(id.clone(), position.clone());
        let orientation = if needs_orient.get(id).copied().unwrap_or(false) {
            let start = x0.len();
            let initial = table.initial_orientation.get(id);
            match dim {
                Dimension::Planar => {
                    x0.push(initial.map_or(0.0, |v| v[0]));
                    x_names.push(format!("{id}.angle"));
                    Some(vec![start])
                }
                Dimension::Spatial => {
                    match initial {
                        Some(l) => x0.extend(l),
                        None => x0.extend(EulerParameters::identity().0),
                    }
                    for k in 0..4 {
                        x_names.push(format!("{id}.l{k}"));
                    }
                    Some((start..start + 4).collect())
                }
            }
        } else {
            None
        };
        nodes.push(NodeInfo {
            id: id.clone(),
            at,
            position,
            orientation,
        });
    }
    let mut groups = vec![];
    for (g, k) in &set.mode_groups {
        let idx: Vec<usize> = (x0.len()..x0.len() + k).collect();
        for i in 0..*k {
            x0.push(0.0);
            x_names.push(format!("{g}.eta{}", i + 1));
        }
        groups.push((g.clone(), idx));
    }
    Ok(Coordinates {
        nodes,
        x0,
        x_names,
        groups,
    })
}

/// Places every element on the coordinates: an element on a node with an
/// initial orientation gets that change of coordinates
/// ([`Element::with_initial_orientation`]), then its coordinate indices and
/// deformation names; a spatial scene ends with the normalization of each
/// orientation node. The elements and the deformation names.
pub(super) fn place(
    dim: Dimension,
    coords: &Coordinates,
    table: &NodeTable,
    expanded: Vec<Expanded>,
    part_data: &mut HashMap<String, Arc<LinearSuperelement>>,
) -> Result<(Vec<MechElement>, Vec<String>), ModelError> {
    let node_idx: HashMap<&str, usize> = coords
        .nodes
        .iter()
        .enumerate()
        .map(|(i, n)| (n.id.as_str(), i))
        .collect();
    let mut elements = vec![];
    let mut eps_names = vec![];
    for mut e in expanded {
        for (k, a) in e.attach.iter().enumerate() {
            if let Attach::Orient(n) = a {
                match table.initial_orientation.get(n) {
                    Some(v) if !crate::orientation::is_identity(v) => {
                        e.element = e.element.with_initial_orientation(k, v).map_err(|err| {
                            ModelError::Element {
                                id: e.id.clone(),
                                source: err,
                            }
                        })?;
                    }
                    _ => {}
                }
            }
        }
        let mut x_index = vec![];
        for (slot, a) in e.element.slots().iter().zip(&e.attach) {
            match a {
                Attach::Pos(n) => x_index.extend(&coords.nodes[node_idx[n.as_str()]].position),
                Attach::Orient(n) | Attach::Carried(n) => x_index.extend(
                    coords.nodes[node_idx[n.as_str()]]
                        .orientation
                        .as_ref()
                        .expect("allocated"),
                ),
                Attach::Group(g) => x_index.extend(
                    &coords
                        .groups
                        .iter()
                        .find(|(n, _)| n == g)
                        .expect("allocated")
                        .1,
                ),
            }
            debug_assert!(slot.len() <= x_index.len());
        }
        debug_assert_eq!(x_index.len(), e.element.n_x());
        let eps_offset = eps_names.len();
        for n in e.element.deformation_names() {
            eps_names.push(format!("{}.{n}", e.id));
        }
        elements.push(MechElement {
            superelement: part_data.remove(&e.id),
            section: e.section,
            id: e.id,
            group: e.group,
            element: e.element,
            x_index,
            eps_offset,
        });
    }
    if dim == Dimension::Spatial {
        for n in &coords.nodes {
            if let Some(o) = &n.orientation {
                let element = Element::normalization();
                let eps_offset = eps_names.len();
                eps_names.push(format!("{}.normalization", n.id));
                elements.push(MechElement {
                    id: format!("{}.norm", n.id),
                    group: n.id.clone(),
                    element,
                    x_index: o.clone(),
                    eps_offset,
                    superelement: None,
                    section: None,
                });
            }
        }
    }
    Ok((elements, eps_names))
}
