//! Validation of a scene's `outputs` when the mechanism is built, so that
//! every command (`info` included) refuses an output that names a node,
//! element or deformation the mechanism does not have, before computing.

use crate::mechanism::Mechanism;
use crate::scene::{OutputSpec, Select};
use crate::ModelError;

/// `" (did you mean 'X'?)"` for the nearest of `candidates`, or empty.
fn hint<'a>(id: &str, candidates: impl IntoIterator<Item = &'a String>) -> String {
    match flexmb_input::nearest(id, candidates) {
        Some(c) => format!(" (did you mean '{c}'?)"),
        None => String::new(),
    }
}

/// How an output is written in a scene, for messages: `Position("tip")`.
fn spelled(o: &OutputSpec) -> String {
    match o {
        OutputSpec::Position(n) => format!("Position({n:?})"),
        OutputSpec::Rotation(n) => format!("Rotation({n:?})"),
        OutputSpec::Deformation(e, d) => format!("Deformation({e:?}, {d:?})"),
        OutputSpec::Stress(e, d) => format!("Stress({e:?}, {d:?})"),
        OutputSpec::Energies => "Energies".into(),
        OutputSpec::Dofs => "Dofs".into(),
        OutputSpec::Velocity(n) => format!("Velocity({n:?})"),
        OutputSpec::AngularVelocity(n) => format!("AngularVelocity({n:?})"),
        OutputSpec::Momentum(p) => format!("Momentum({p:?})"),
        OutputSpec::Reaction(n) => format!("Reaction({n:?})"),
    }
}

/// Checks one output: its node exists (and has a rotation for `Rotation`),
/// or its element exists and has the deformation.
fn check_output(mech: &Mechanism, o: &OutputSpec) -> Result<(), ModelError> {
    let ctx = format!("output {}", spelled(o));
    let node_ids = || mech.nodes.iter().map(|n| &n.id);
    let node = |id: &str| {
        mech.node(id).ok_or_else(|| ModelError::UnknownId {
            kind: "node",
            id: id.to_string(),
            context: ctx.clone(),
            hint: hint(id, node_ids()),
        })
    };
    match o {
        OutputSpec::Position(id) | OutputSpec::Velocity(id) => node(id).map(|_| ()),
        OutputSpec::Rotation(id) | OutputSpec::AngularVelocity(id) => match node(id)?.orientation {
            Some(_) => Ok(()),
            None => Err(ModelError::invalid(
                ctx,
                format!("node '{id}' has no rotation coordinates (no element uses its rotation); ask for Position(\"{id}\")"),
            )),
        },
        OutputSpec::Deformation(eid, name) | OutputSpec::Stress(eid, name) => {
            let known = mech.elements.iter().any(|e| e.id == *eid || e.group == *eid);
            if !known {
                let ids = mech.elements.iter().flat_map(|e| [&e.id, &e.group]);
                return Err(ModelError::UnknownId {
                    kind: "element",
                    id: eid.clone(),
                    context: ctx,
                    hint: hint(eid, ids),
                });
            }
            let select = Select::Def(eid.clone(), name.clone());
            if crate::roles::resolve(mech, &select, &ctx)?.is_empty() {
                return Err(ModelError::invalid(
                    ctx,
                    format!("element '{eid}' has no deformation '{name}'"),
                ));
            }
            Ok(())
        }
        OutputSpec::Momentum(point) => {
            let dim = match mech.dimension {
                crate::Dimension::Planar => 2,
                crate::Dimension::Spatial => 3,
            };
            if point.len() != dim || point.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::invalid(
                    ctx,
                    format!("the point about which the angular momentum is taken needs {dim} finite coordinates, got {point:?}"),
                ));
            }
            Ok(())
        }
        OutputSpec::Reaction(id) => node(id).map(|_| ()),
        OutputSpec::Energies | OutputSpec::Dofs => Ok(()),
    }
}

/// Checks that a `Reaction` output's node has a support: a fixed or
/// prescribed coordinate, and all or none of its rotation coordinates (needs
/// the roles, so it runs after the DOF choice).
fn check_support(mech: &Mechanism, o: &OutputSpec) -> Result<(), ModelError> {
    let OutputSpec::Reaction(id) = o else {
        return Ok(());
    };
    let ctx = format!("output {}", spelled(o));
    let Some(n) = mech.node(id) else {
        return Ok(());
    };
    let supported = |i: &usize| {
        matches!(
            mech.x_roles[*i],
            crate::XRole::Fixed | crate::XRole::Input(_)
        )
    };
    if !n
        .position
        .iter()
        .chain(n.orientation.iter().flatten())
        .any(supported)
    {
        return Err(ModelError::invalid(
            ctx,
            format!("node '{id}' has no fixed or prescribed coordinate, so no support acts on it"),
        ));
    }
    if let Some(o) = &n.orientation {
        let k = o.iter().filter(|i| supported(i)).count();
        if k != 0 && k != o.len() {
            return Err(ModelError::invalid(
                ctx,
                format!("node '{id}' has {k} of its {} rotation coordinates fixed or prescribed: its reaction moment is not defined", o.len()),
            ));
        }
    }
    Ok(())
}

impl Mechanism {
    /// Checks the requested outputs against the mechanism: every node,
    /// element and deformation they name exists, and a `Rotation` output's
    /// node has rotation coordinates. The error names the output.
    pub fn check_outputs(&self) -> Result<(), ModelError> {
        self.outputs.iter().try_for_each(|o| check_output(self, o))
    }

    /// Checks that every `Reaction` output's node is supported (after the
    /// roles are assigned).
    pub fn check_output_supports(&self) -> Result<(), ModelError> {
        self.outputs.iter().try_for_each(|o| check_support(self, o))
    }
}
