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
        OutputSpec::Position(id) => node(id).map(|_| ()),
        OutputSpec::Rotation(id) => match node(id)?.orientation {
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
        OutputSpec::Energies | OutputSpec::Dofs => Ok(()),
    }
}

impl Mechanism {
    /// Checks the requested outputs against the mechanism: every node,
    /// element and deformation they name exists, and a `Rotation` output's
    /// node has rotation coordinates. The error names the output.
    pub fn check_outputs(&self) -> Result<(), ModelError> {
        self.outputs.iter().try_for_each(|o| check_output(self, o))
    }
}
