//! The first stage of the build ([`BuildStage::Nodes`]): the materials,
//! checked field by field, and the `position_of` references of the nodes,
//! checked for cycles.

use super::*;

/// The material of a scene entry, checked field by field: E > 0, ρ ≥ 0, ν in
/// (−1, 0.5), G > 0 with the ν it implies in (−1, 0.5), all finite, and G and
/// ν consistent if both are given. Errors name the material and the field.
pub(super) fn material(id: &str, m: &MaterialSpec) -> Result<Material, ModelError> {
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
pub(super) fn position_of_cycle(nodes: &[NodeSpec]) -> Result<(), ModelError> {
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
