//! The first stage of the build ([`BuildStage::Nodes`]): the nodes with
//! their positions (shared by `position_of`, checked for cycles) and
//! initial orientations, the materials, checked field by field, the
//! sections and gravity.

use super::*;

/// The nodes of a scene as read: positions by id, the declaration order
/// (the chain helpers of the elements stage append their intermediate
/// nodes), the shared positions (`position_of`: a node → the node that owns
/// its position) and the initial orientations (as coordinate values).
pub(super) struct NodeTable {
    pub(super) at: BTreeMap<String, Vec<f64>>,
    pub(super) order: Vec<String>,
    pub(super) shares: HashMap<String, String>,
    pub(super) initial_orientation: HashMap<String, Vec<f64>>,
}

impl NodeTable {
    /// The position of node `id`, or an error naming it in `ctx` with the
    /// nearest known id.
    pub(super) fn position(&self, id: &str, ctx: &str) -> Result<Vec<f64>, ModelError> {
        self.at
            .get(id)
            .cloned()
            .ok_or_else(|| ModelError::UnknownId {
                kind: "node",
                id: id.to_string(),
                context: ctx.to_string(),
                hint: closest(id, self.at.keys()),
            })
    }
}

/// The scene's nodes, each checked: a non-empty unique id, a finite
/// position of the scene's dimension (or that of an earlier node it shares
/// by `position_of`, with no cycle), a valid initial orientation.
pub(super) fn read_nodes(scene: &Scene, dim: Dimension) -> Result<NodeTable, ModelError> {
    let nd = dim.position_len();
    let mut node_at: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut node_order: Vec<String> = vec![];
    let mut shares: HashMap<String, String> = HashMap::new();
    let mut initial_orientation: HashMap<String, Vec<f64>> = HashMap::new();
    position_of_cycle(&scene.nodes)?;
    for n in &scene.nodes {
        if n.id.is_empty() {
            return Err(ModelError::invalid("node", "an empty id"));
        }
        let mut n = n.clone();
        if let Some(other) = &n.position_of {
            if !node_at.contains_key(other) && scene.nodes.iter().any(|m| m.id == *other) {
                return Err(ModelError::invalid(
                    format!("node '{}' position_of", n.id),
                    format!("'{other}' is declared after '{}': a node shares the position of an earlier node; declare '{other}' first", n.id),
                ));
            }
            let at = node_at
                .get(other)
                .cloned()
                .ok_or_else(|| ModelError::UnknownId {
                    kind: "node",
                    id: other.clone(),
                    context: format!("node '{}' position_of (name an earlier node)", n.id),
                    hint: closest(other, node_at.keys()),
                })?;
            if !n.at.is_empty() && n.at != at {
                return Err(ModelError::invalid(
                    format!("node '{}'", n.id),
                    format!(
                        "gives a position {:?} different from that of '{other}' {:?}",
                        n.at, at
                    ),
                ));
            }
            n.at = at;
            let root = shares.get(other).cloned().unwrap_or_else(|| other.clone());
            shares.insert(n.id.clone(), root);
        }
        if n.at.len() != nd {
            return Err(ModelError::invalid(
                format!("node '{}'", n.id),
                format!(
                    "position has {} components, a {dim:?} scene needs {nd}",
                    n.at.len()
                ),
            ));
        }
        finite_vec(&format!("node '{}' position", n.id), &n.at)?;
        if node_at.insert(n.id.clone(), n.at.clone()).is_some() {
            return Err(ModelError::DuplicateId {
                kind: "node",
                id: n.id.clone(),
            });
        }
        if let Some(o) = &n.orientation {
            let values = crate::orientation::reference_values(&n.id, o, dim)?;
            initial_orientation.insert(n.id.clone(), values);
        }
        node_order.push(n.id.clone());
    }
    Ok(NodeTable {
        at: node_at,
        order: node_order,
        shares,
        initial_orientation,
    })
}

/// The materials and sections of a scene, by id.
pub(super) struct Library {
    pub(super) materials: BTreeMap<String, Material>,
    pub(super) sections: BTreeMap<String, SectionShape>,
}

impl Library {
    /// The materials and sections of `scene`, each checked (the errors name
    /// the entry and the field).
    pub(super) fn read(scene: &Scene) -> Result<Library, ModelError> {
        let mut materials = BTreeMap::new();
        for (id, m) in &scene.materials {
            let mat = material(id, m)?;
            materials.insert(id.clone(), mat);
        }
        let sections: BTreeMap<String, SectionShape> = scene
            .sections
            .iter()
            .map(|(id, s)| {
                let shape = match s {
                    SectionSpec::Rectangle { by, bz } => {
                        SectionShape::Rectangle { by: *by, bz: *bz }
                    }
                    SectionSpec::Circle { d } => SectionShape::Circle { d: *d },
                    SectionSpec::Tube { d_outer, d_inner } => SectionShape::Tube {
                        d_outer: *d_outer,
                        d_inner: *d_inner,
                    },
                    SectionSpec::User(p) => SectionShape::User(*p),
                };
                shape
                    .properties(0.3)
                    .map(|_| (id.clone(), shape))
                    .map_err(|e| ModelError::invalid(format!("section '{id}'"), e.to_string()))
            })
            .collect::<Result<_, _>>()?;
        Ok(Library {
            materials,
            sections,
        })
    }

    /// Material `id` of element context `ctx`.
    pub(super) fn material(&self, id: &str, ctx: &str) -> Result<Material, ModelError> {
        self.materials
            .get(id)
            .copied()
            .ok_or_else(|| ModelError::UnknownId {
                kind: "material",
                id: id.to_string(),
                context: ctx.to_string(),
                hint: closest(id, self.materials.keys()),
            })
    }

    /// Section `id` of element context `ctx`.
    pub(super) fn section(&self, id: &str, ctx: &str) -> Result<SectionShape, ModelError> {
        self.sections
            .get(id)
            .copied()
            .ok_or_else(|| ModelError::UnknownId {
                kind: "section",
                id: id.to_string(),
                context: ctx.to_string(),
                hint: closest(id, self.sections.keys()),
            })
    }
}

/// The scene's gravity as a 3-vector (z = 0 in a planar scene), checked.
pub(super) fn read_gravity(scene: &Scene, dim: Dimension) -> Result<Option<[f64; 3]>, ModelError> {
    let nd = dim.position_len();
    let gravity = match &scene.gravity {
        None => None,
        Some(g) => {
            if g.len() != nd {
                return Err(ModelError::invalid(
                    "gravity",
                    format!("has {} components, expected {nd}", g.len()),
                ));
            }
            finite_vec("gravity", g)?;
            Some([g[0], g[1], if nd == 3 { g[2] } else { 0.0 }])
        }
    };
    Ok(gravity)
}

/// The material of a scene entry, checked field by field: E > 0, ρ ≥ 0, ν in
/// (−1, 0.5), G > 0 with the ν it implies in (−1, 0.5), all finite, and G and
/// ν consistent if both are given. Errors name the material and the field.
fn material(id: &str, m: &MaterialSpec) -> Result<Material, ModelError> {
    let bad = |field: &str, v: f64, why: String| {
        Err(ModelError::invalid(
            format!("material '{id}'"),
            format!("{field} = {v}: {why}"),
        ))
    };
    if !(m.e.is_finite() && m.e > 0.0) {
        return bad(
            "e (Young's modulus)",
            m.e,
            "must be positive and finite".into(),
        );
    }
    if !(m.rho.is_finite() && m.rho >= 0.0) {
        return bad(
            "rho (density)",
            m.rho,
            "must be non-negative and finite".into(),
        );
    }
    const NU_RANGE: &str = "(−1, 0.5), the range of an isotropic elastic material";
    if let Some(nu) = m.nu {
        if !(nu > -1.0 && nu < 0.5) {
            return bad(
                "nu (Poisson's ratio)",
                nu,
                format!("must lie in {NU_RANGE}"),
            );
        }
    }
    let mat = match m.g {
        Some(g) => {
            if !(g.is_finite() && g > 0.0) {
                return bad("g (shear modulus)", g, "must be positive and finite".into());
            }
            let implied = m.e / (2.0 * g) - 1.0;
            if !(implied > -1.0 && implied < 0.5) {
                return bad(
                    "g (shear modulus)",
                    g,
                    format!(
                        "implies Poisson's ratio E/(2G) − 1 = {implied:.4}, outside {NU_RANGE} (G must exceed E/3 = {:e})",
                        m.e / 3.0
                    ),
                );
            }
            if let Some(nu) = m.nu {
                let from_nu = m.e / (2.0 * (1.0 + nu));
                if (from_nu - g).abs() > 1e-6 * g {
                    return bad(
                        "g (shear modulus)",
                        g,
                        format!("disagrees with nu = {nu}, which gives E/(2(1 + ν)) = {from_nu:e}; give only one of g and nu"),
                    );
                }
            }
            Material {
                e: m.e,
                g,
                rho: m.rho,
            }
        }
        None => Material::from_poisson(m.e, m.nu.unwrap_or(0.3), m.rho),
    };
    mat.validate()
        .map_err(|e| ModelError::invalid(format!("material '{id}'"), e.to_string()))?;
    Ok(mat)
}

/// The first cycle of `position_of` references (nodes each sharing the
/// position of the next, back to the first), as an error naming it:
/// "position_of cycle: A → B → A". O(nodes): each node is walked once.
fn position_of_cycle(nodes: &[NodeSpec]) -> Result<(), ModelError> {
    let target: HashMap<&str, &str> = nodes
        .iter()
        .filter_map(|n| n.position_of.as_deref().map(|o| (n.id.as_str(), o)))
        .collect();
    // 1: on the walk in progress, 2: walked before (on no cycle)
    let mut state: HashMap<&str, u8> = HashMap::new();
    for start in nodes {
        let mut walk: Vec<&str> = vec![];
        let mut cur = start.id.as_str();
        let back_to = loop {
            match state.get(cur) {
                Some(1) => break Some(cur),
                Some(_) => break None,
                None => {}
            }
            state.insert(cur, 1);
            walk.push(cur);
            match target.get(cur) {
                Some(next) => cur = next,
                None => break None,
            }
        };
        if let Some(k) = back_to.and_then(|c| walk.iter().position(|n| *n == c)) {
            // start at the node declared first
            let mut cycle = walk[k..].to_vec();
            let declared = |id: &str| nodes.iter().position(|n| n.id == id);
            let first = (0..cycle.len())
                .min_by_key(|i| declared(cycle[*i]))
                .unwrap_or(0);
            cycle.rotate_left(first);
            cycle.push(cycle[0]);
            return Err(ModelError::invalid(
                format!("node '{}' position_of", cycle[0]),
                format!(
                    "position_of cycle: {}; a node can only share the position of a node that has one of its own (`at`)",
                    cycle.join(" → ")
                ),
            ));
        }
        for n in walk {
            state.insert(n, 2);
        }
    }
    Ok(())
}
