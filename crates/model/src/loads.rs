//! Loads, controllers and initial velocities of a scene.

use crate::mechanism::*;
use crate::roles::resolve;
use crate::scene::*;
use crate::{ModelError, TimeFunction};
use flexmb_rotation::EulerParameters;
use nalgebra::Vector3;

pub(crate) fn assign(scene: &Scene, mech: &mut Mechanism) -> Result<(), ModelError> {
    let nd = mech.nodes.first().map_or(3, |n| n.position.len());
    for (k, l) in scene.loads.iter().enumerate() {
        let ctx = format!("load {k} on node '{}'", l.node);
        let node = mech
            .node(&l.node)
            .cloned()
            .ok_or_else(|| ModelError::UnknownId {
                kind: "node",
                id: l.node.clone(),
                context: format!("load {k}"),
                hint: String::new(),
            })?;
        let function = l.function.clone().unwrap_or(TimeFunction::Constant(1.0));
        crate::build::check_function(&ctx, &function)?;
        if l.force.is_none() && l.moment.is_none() {
            return Err(ModelError::invalid(
                ctx,
                "gives neither a force nor a moment",
            ));
        }
        if let Some(f) = &l.force {
            if f.len() != nd || f.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::invalid(
                    ctx,
                    format!("force must have {nd} finite components, got {f:?}"),
                ));
            }
            mech.loads.push(Load::Force {
                index: node.position.clone(),
                f: f.clone(),
                function: function.clone(),
            });
        }
        if let Some(m) = &l.moment {
            let o = node.orientation.clone().ok_or_else(|| {
                ModelError::invalid(
                    &ctx,
                    "a moment needs a node with a rotation (attach a beam, hinge or rigid body)",
                )
            })?;
            if m.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::invalid(
                    ctx,
                    "moment has a non-finite component",
                ));
            }
            match (o.len(), m.len()) {
                (1, 1) => mech.loads.push(Load::PlanarMoment {
                    index: o[0],
                    m: m[0],
                    function,
                }),
                (4, 3) => mech.loads.push(Load::SpatialMoment {
                    index: [o[0], o[1], o[2], o[3]],
                    m: [m[0], m[1], m[2]],
                    function,
                }),
                _ => {
                    return Err(ModelError::invalid(
                        ctx,
                        format!(
                            "moment must have {} component(s) in this scene",
                            if o.len() == 1 { 1 } else { 3 }
                        ),
                    ))
                }
            }
        }
    }
    for (k, c) in scene.controllers.iter().enumerate() {
        let ctx = format!("controller {k}");
        let cs = resolve(mech, &c.on, &ctx)?;
        if cs.len() != 1 {
            return Err(ModelError::invalid(
                ctx,
                format!("acts on {} coordinates; select exactly one", cs.len()),
            ));
        }
        if !(c.kp.is_finite() && c.kd.is_finite()) {
            return Err(ModelError::invalid(ctx, "gains must be finite"));
        }
        crate::build::check_function(&ctx, &c.reference)?;
        let free = match cs[0] {
            Coordinate::Node(i) => !matches!(mech.x_roles[i], XRole::Fixed | XRole::Input(_)),
            Coordinate::Def(j) => !matches!(mech.e_roles[j], ERole::Rigid | ERole::Input(_)),
        };
        if !free {
            return Err(ModelError::Role {
                name: mech.coordinate_name(cs[0]).to_string(),
                message: "is fixed, rigid or prescribed: a controller on it does nothing".into(),
            });
        }
        mech.controllers.push(Controller {
            on: cs[0],
            kp: c.kp,
            kd: c.kd,
            reference: c.reference.clone(),
        });
    }
    for (k, v) in scene.initial_velocity.iter().enumerate() {
        let ctx = format!("initial velocity {k}");
        let vv = crate::build::opt_vec3(&ctx, "v", &v.v)?;
        let om = crate::build::opt_vec3(&ctx, "omega", &v.omega)?;
        let about = crate::build::opt_vec3(&ctx, "about", &v.about)?;
        let nodes: Vec<NodeInfo> = if v.nodes.is_empty() {
            mech.nodes.clone()
        } else {
            v.nodes
                .iter()
                .map(|id| {
                    mech.node(id).cloned().ok_or_else(|| ModelError::UnknownId {
                        kind: "node",
                        id: id.clone(),
                        context: ctx.clone(),
                        hint: String::new(),
                    })
                })
                .collect::<Result<_, _>>()?
        };
        let w = Vector3::from(om);
        for n in nodes {
            let mut r = Vector3::zeros();
            for (k, i) in n.position.iter().enumerate() {
                r[k] = mech.x0[*i] - about[k];
            }
            let vel = Vector3::from(vv) + w.cross(&r);
            for (k, i) in n.position.iter().enumerate() {
                mech.initial_xd[*i] = vel[k];
            }
            if let Some(o) = &n.orientation {
                if o.len() == 1 {
                    mech.initial_xd[o[0]] = w.z;
                } else {
                    let l = EulerParameters([
                        mech.x0[o[0]],
                        mech.x0[o[1]],
                        mech.x0[o[2]],
                        mech.x0[o[3]],
                    ]);
                    let ld = l.lambda_dot_from_omega(&w);
                    for a in 0..4 {
                        mech.initial_xd[o[a]] = ld[a];
                    }
                }
            }
        }
    }
    Ok(())
}
