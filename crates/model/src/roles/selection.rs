//! Scene selections (`Node`, `Coord`, `Def`, ...) resolved to the mechanism's
//! nodal coordinates and deformations, the coordinates whose roles
//! (thesis (6.4)) the scene sets.

use super::*;

/// Resolves a selection to coordinates.
pub(crate) fn resolve(
    mech: &Mechanism,
    s: &Select,
    ctx: &str,
) -> Result<Vec<Coordinate>, ModelError> {
    let unknown_node = |id: &str| ModelError::UnknownId {
        kind: "node",
        id: id.to_string(),
        context: ctx.to_string(),
        hint: String::new(),
    };
    match s {
        Select::Node(id) => {
            let n = mech.node(id).ok_or_else(|| unknown_node(id))?;
            let mut v: Vec<Coordinate> = n.position.iter().map(|i| Coordinate::Node(*i)).collect();
            if let Some(o) = &n.orientation {
                v.extend(o.iter().map(|i| Coordinate::Node(*i)));
            }
            Ok(v)
        }
        Select::Coord(id, c) => {
            let n = mech.node(id).ok_or_else(|| unknown_node(id))?;
            let orient = || {
                n.orientation.clone().ok_or_else(|| {
                    ModelError::invalid(ctx, format!("node '{id}' has no orientation coordinates (no element uses its rotation)"))
                })
            };
            let idx: Vec<usize> = match c {
                Component::X => vec![n.position[0]],
                Component::Y => vec![n.position[1]],
                Component::Z => {
                    if n.position.len() < 3 {
                        return Err(ModelError::invalid(ctx, "Z in a planar scene"));
                    }
                    vec![n.position[2]]
                }
                Component::Position => n.position.clone(),
                Component::Angle => {
                    let o = orient()?;
                    if o.len() != 1 {
                        return Err(ModelError::invalid(
                            ctx,
                            "Angle in a spatial scene: use Lambda(k) or Orientation",
                        ));
                    }
                    o
                }
                Component::Lambda(k) => {
                    let o = orient()?;
                    if o.len() != 4 || *k > 3 {
                        return Err(ModelError::invalid(
                            ctx,
                            format!("Lambda({k}) needs a spatial node and k in 0..=3"),
                        ));
                    }
                    vec![o[*k as usize]]
                }
                Component::Orientation => orient()?,
            };
            Ok(idx.into_iter().map(Coordinate::Node).collect())
        }
        Select::Modes(g) => {
            let (_, idx) = mech
                .mode_groups
                .iter()
                .find(|(n, _)| n == g)
                .ok_or_else(|| ModelError::UnknownId {
                    kind: "mode group",
                    id: g.clone(),
                    context: ctx.to_string(),
                    hint: String::new(),
                })?;
            Ok(idx.iter().map(|i| Coordinate::Node(*i)).collect())
        }
        Select::Def(eid, name) => {
            let members: Vec<&MechElement> = mech
                .elements
                .iter()
                .filter(|e| e.id == *eid || e.group == *eid)
                .collect();
            if members.is_empty() {
                return Err(ModelError::UnknownId {
                    kind: "element",
                    id: eid.clone(),
                    context: ctx.to_string(),
                    hint: String::new(),
                });
            }
            let mut v = vec![];
            for e in members {
                let names = e.element.deformation_names();
                for (k, n) in names.iter().enumerate() {
                    if name == "*" || n == name {
                        v.push(Coordinate::Def(e.eps_offset + k));
                    }
                }
                if name != "*" && !names.iter().any(|n| n == name) && e.element.n_eps() > 0 {
                    return Err(ModelError::invalid(
                        ctx,
                        format!(
                            "element '{}' ({}) has no deformation '{name}'; it has {:?}",
                            e.id,
                            e.element.type_name(),
                            names
                        ),
                    ));
                }
            }
            Ok(v)
        }
    }
}
