//! Validation of a scene and its assembly into a [`Mechanism`].

use crate::mechanism::*;
use crate::scene::*;
use crate::{ModelError, TimeFunction};
use flexmb_element::{BeamOptions, Element, LinearSuperelement, Material, SectionShape};
use flexmb_rotation::EulerParameters;
use nalgebra::Vector3;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod chains;
mod checks;
mod nodes;
mod reference;

use chains::{chain_n, chain_nodes, default_up, BYTES_PER_ELEMENT, MAX_CHAIN_N};
pub(crate) use checks::{check_function, opt_vec3};
use checks::{closest, finite_vec, vec3};
use nodes::{material, position_of_cycle};
use reference::check_reference_configuration;

/// Where a slot of an element attaches.
#[derive(Clone, Debug)]
enum Attach {
    Pos(String),
    /// An orientation slot measured from the node's initial orientation.
    Orient(String),
    /// An orientation slot whose element is given in the node's own axes
    /// (a rigid body): it takes the node's orientation as it is.
    Carried(String),
    Group(String),
}

struct Expanded {
    id: String,
    group: String,
    element: Element,
    attach: Vec<Attach>,
    /// A beam's section, for drawing.
    section: Option<crate::BeamSection>,
}

/// An element built in Rust code, for instance a user-defined element
/// ([`Element::custom`]), placed between the nodes of a scene by
/// [`Scene::build_with_elements`](crate::Scene::build_with_elements).
#[derive(Clone, Debug)]
pub struct CodeElement {
    /// Unique id among the scene's elements: selections (`Def(id, name)`,
    /// outputs) and messages use it, as for a scene element.
    pub id: String,
    /// The element.
    pub element: Element,
    /// One node id per slot of the element, in slot order: a
    /// [`Slot::Position2`](flexmb_element::Slot)/`Position3` slot takes the
    /// node's position, an `Angle`/`Orientation` slot its orientation (planar
    /// angle or Euler parameters, allocated when an element needs it). Mode
    /// slots are not supported here.
    pub nodes: Vec<String>,
}

/// Assembles a scene. `base_dir` resolves relative superelement file paths.
pub fn build(scene: &Scene, base_dir: Option<&Path>) -> Result<Mechanism, ModelError> {
    build_with_elements(scene, base_dir, &[])
}

/// Assembles a scene with extra elements built in code, placed after the
/// scene's own elements (see [`CodeElement`]).
pub fn build_with_elements(
    scene: &Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
) -> Result<Mechanism, ModelError> {
    build_reporting(scene, base_dir, extra, &mut |_| {})
}

/// A stage of [`Scene::build_reporting`](crate::Scene::build_reporting), in the order they run. On a model of
/// 10⁴–10⁵ coordinates the elements and the DOF choice take seconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildStage {
    /// Nodes, materials and sections.
    Nodes,
    /// The elements (chains expanded, superelement files read).
    Elements,
    /// The nodal coordinates and the placement of the elements on them.
    Coordinates,
    /// Every element undeformed at the scene's node positions.
    ReferenceConfiguration,
    /// Roles (fixed, rigid, prescribed) and the choice of the degrees of
    /// freedom.
    DegreesOfFreedom,
    /// Loads, controllers, initial velocities and outputs.
    Loads,
}

impl BuildStage {
    /// What the stage does, for a progress line.
    pub fn describe(&self) -> &'static str {
        match self {
            BuildStage::Nodes => "reading nodes, materials and sections",
            BuildStage::Elements => "building the elements",
            BuildStage::Coordinates => "allocating the nodal coordinates",
            BuildStage::ReferenceConfiguration => "checking the reference configuration",
            BuildStage::DegreesOfFreedom => "choosing the degrees of freedom",
            BuildStage::Loads => "assigning loads and outputs",
        }
    }
}

/// [`build_with_elements`] that calls `report` as each [`BuildStage`]
/// starts: for progress on large models.
pub fn build_reporting(
    scene: &Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
    report: &mut dyn FnMut(BuildStage),
) -> Result<Mechanism, ModelError> {
    let (mut mech, roles_scene) = assemble(scene, base_dir, extra, report)?;
    report(BuildStage::DegreesOfFreedom);
    crate::roles::assign(&roles_scene, &mut mech)?;
    mech.check_output_supports()?;
    report(BuildStage::Loads);
    crate::loads::assign(scene, &mut mech)?;
    Ok(mech)
}

/// Every stage of the build before the roles: the mechanism with its
/// coordinates, deformations and elements placed (roles not assigned yet),
/// and the scene the roles are to be taken from (the scene itself, or a copy
/// whose `fixed` also lists the restrained warping groups).
pub(crate) fn assemble<'s>(
    scene: &'s Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
    report: &mut dyn FnMut(BuildStage),
) -> Result<(Mechanism, std::borrow::Cow<'s, Scene>), ModelError> {
    report(BuildStage::Nodes);
    let dim = scene.dimension;
    let nd = match dim {
        Dimension::Planar => 2,
        Dimension::Spatial => 3,
    };
    // ---- nodes
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
    // ---- materials and sections
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
                SectionSpec::Rectangle { by, bz } => SectionShape::Rectangle { by: *by, bz: *bz },
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
    let node_ref = |id: &str,
                    ctx: &str,
                    node_at: &BTreeMap<String, Vec<f64>>|
     -> Result<Vec<f64>, ModelError> {
        node_at
            .get(id)
            .cloned()
            .ok_or_else(|| ModelError::UnknownId {
                kind: "node",
                id: id.to_string(),
                context: ctx.to_string(),
                hint: closest(id, node_at.keys()),
            })
    };
    // ---- elements (chains expanded)
    report(BuildStage::Elements);
    let mut expanded: Vec<Expanded> = vec![];
    let mut element_ids = HashMap::new();
    let mut mode_groups: Vec<(String, usize)> = vec![];
    // mode groups that the scene's elements restrain (warping ends)
    let mut restrained: Vec<Select> = vec![];
    let mut part_axes: HashMap<String, PartAxis> = HashMap::new();
    // superelement data by element id, and each file read once
    let mut part_data: HashMap<String, Arc<LinearSuperelement>> = HashMap::new();
    let mut files: HashMap<PathBuf, Arc<LinearSuperelement>> = HashMap::new();
    let mut chain_total = 0usize;
    for entry in &scene.elements {
        let id = entry.id.clone();
        if element_ids.insert(id.clone(), ()).is_some() {
            return Err(ModelError::DuplicateId {
                kind: "element",
                id,
            });
        }
        let ctx = format!("element '{id}'");
        let wrap = |e: flexmb_element::ElementError| ModelError::Element {
            id: id.clone(),
            source: e,
        };
        let n = chain_n(&entry.kind);
        if n == 0 {
            return Err(ModelError::invalid(ctx, "n must be at least 1"));
        }
        if n > MAX_CHAIN_N {
            return Err(ModelError::invalid(
                ctx,
                format!(
                    "n = {n} elements in one chain is more than the {MAX_CHAIN_N} the chain helper allows"
                ),
            ));
        }
        chain_total += n;
        let estimate = chain_total as f64 * BYTES_PER_ELEMENT;
        if estimate > crate::roles::physical_memory() as f64 / 4.0 {
            return Err(ModelError::TooLarge {
                what: format!(
                    "{ctx}: {chain_total} elements would need about {} to assemble",
                    crate::roles::human_bytes(estimate)
                ),
                limit: crate::roles::human_bytes(crate::roles::physical_memory() as f64 / 4.0),
            });
        }
        match &entry.kind {
            ElementSpec::Beam(b) => {
                let p = node_ref(&b.nodes.0, &ctx, &node_at)?;
                let q = node_ref(&b.nodes.1, &ctx, &node_at)?;
                let mat = *materials
                    .get(&b.material)
                    .ok_or_else(|| ModelError::UnknownId {
                        kind: "material",
                        id: b.material.clone(),
                        context: ctx.clone(),
                        hint: closest(&b.material, materials.keys()),
                    })?;
                let shape = *sections
                    .get(&b.section)
                    .ok_or_else(|| ModelError::UnknownId {
                        kind: "section",
                        id: b.section.clone(),
                        context: ctx.clone(),
                        hint: closest(&b.section, sections.keys()),
                    })?;
                let opts = BeamOptions {
                    shortening: b.shortening,
                    timoshenko: b.timoshenko,
                    inertia: b.mass,
                    velocity_transform: b.transform,
                    warping: b.warping.is_some(),
                };
                let warp_groups =
                    match &b.warping {
                        None => vec![],
                        Some(_) if dim == Dimension::Planar => return Err(ModelError::invalid(
                            ctx,
                            "warping is an option of spatial beams; a planar beam has no torsion",
                        )),
                        Some(w) => {
                            let groups = warping_groups(&id, b.n, w);
                            for g in &groups {
                                register_mode_group(&mut mode_groups, &ctx, g, 1)?;
                            }
                            for (end, g) in [(&w.p, &groups[0]), (&w.q, &groups[b.n])] {
                                if *end == WarpingEnd::Restrained {
                                    restrained.push(Select::Modes(g.clone()));
                                }
                            }
                            groups
                        }
                    };
                let chain = chain_nodes(&id, &b.nodes, &p, &q, b.n, &mut node_at, &mut node_order)?;
                for (k, (a, bb)) in chain.iter().enumerate() {
                    let (pa, pb) = (node_at[a].clone(), node_at[bb].clone());
                    let eid = if b.n == 1 {
                        id.clone()
                    } else {
                        format!("{id}.{}", k + 1)
                    };
                    let (element, frame) = match dim {
                        Dimension::Planar => {
                            let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
                            let l = dx.hypot(dy);
                            let (c, s) = if l > 0.0 {
                                (dx / l, dy / l)
                            } else {
                                (1.0, 0.0)
                            };
                            (
                                Element::planar_beam(
                                    [pa[0], pa[1]],
                                    [pb[0], pb[1]],
                                    &mat,
                                    &shape,
                                    &opts,
                                )
                                .map_err(wrap)?,
                                [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
                            )
                        }
                        Dimension::Spatial => {
                            let axis = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
                            let up = match &b.up {
                                Some(u) => vec3(&ctx, "up", u)?,
                                None => default_up(&axis),
                            };
                            let element = Element::beam(
                                [pa[0], pa[1], pa[2]],
                                [pb[0], pb[1], pb[2]],
                                up,
                                &mat,
                                &shape,
                                &opts,
                            )
                            .map_err(wrap)?;
                            // the element checked the axis and up
                            let frame =
                                flexmb_element::frame_from_axis(&axis, &up).map_err(wrap)?;
                            (element, frame)
                        }
                    };
                    let mut attach = vec![
                        Attach::Pos(a.clone()),
                        Attach::Orient(a.clone()),
                        Attach::Pos(bb.clone()),
                        Attach::Orient(bb.clone()),
                    ];
                    if !warp_groups.is_empty() {
                        attach.push(Attach::Group(warp_groups[k].clone()));
                        attach.push(Attach::Group(warp_groups[k + 1].clone()));
                    }
                    expanded.push(Expanded {
                        id: eid,
                        group: id.clone(),
                        element,
                        attach,
                        section: Some(crate::BeamSection {
                            shape,
                            frame,
                            planar: dim == Dimension::Planar,
                        }),
                    });
                }
            }
            ElementSpec::Truss {
                nodes,
                ea,
                mass_per_length,
                n,
            } => {
                let p = node_ref(&nodes.0, &ctx, &node_at)?;
                let q = node_ref(&nodes.1, &ctx, &node_at)?;
                let chain = chain_nodes(&id, nodes, &p, &q, *n, &mut node_at, &mut node_order)?;
                for (k, (a, bb)) in chain.iter().enumerate() {
                    let (pa, pb) = (node_at[a].clone(), node_at[bb].clone());
                    let eid = if *n == 1 {
                        id.clone()
                    } else {
                        format!("{id}.{}", k + 1)
                    };
                    let element = match dim {
                        Dimension::Planar => Element::planar_truss(
                            [pa[0], pa[1]],
                            [pb[0], pb[1]],
                            *ea,
                            *mass_per_length,
                        ),
                        Dimension::Spatial => Element::truss(
                            [pa[0], pa[1], pa[2]],
                            [pb[0], pb[1], pb[2]],
                            *ea,
                            *mass_per_length,
                        ),
                    }
                    .map_err(wrap)?;
                    expanded.push(Expanded {
                        id: eid,
                        group: id.clone(),
                        element,
                        attach: vec![Attach::Pos(a.clone()), Attach::Pos(bb.clone())],
                        section: None,
                    });
                }
            }
            ElementSpec::Hinge {
                nodes,
                axis,
                stiffness,
                bending_stiffness,
            } => {
                node_ref(&nodes.0, &ctx, &node_at)?;
                node_ref(&nodes.1, &ctx, &node_at)?;
                let element = match dim {
                    Dimension::Planar => Element::planar_hinge(*stiffness),
                    Dimension::Spatial => {
                        let a = axis.as_ref().ok_or_else(|| {
                            ModelError::invalid(&ctx, "a spatial hinge needs an axis")
                        })?;
                        Element::hinge(vec3(&ctx, "axis", a)?, *stiffness, *bending_stiffness)
                    }
                }
                .map_err(wrap)?;
                expanded.push(Expanded {
                    id: id.clone(),
                    group: id.clone(),
                    element,
                    attach: vec![
                        Attach::Orient(nodes.0.clone()),
                        Attach::Orient(nodes.1.clone()),
                    ],
                    section: None,
                });
            }
            ElementSpec::PointMass {
                node,
                mass,
                inertia,
            } => {
                node_ref(node, &ctx, &node_at)?;
                let (element, attach) = match dim {
                    Dimension::Planar => (
                        Element::planar_mass(*mass, *inertia).map_err(wrap)?,
                        if inertia.is_some() {
                            vec![Attach::Pos(node.clone()), Attach::Orient(node.clone())]
                        } else {
                            vec![Attach::Pos(node.clone())]
                        },
                    ),
                    Dimension::Spatial => {
                        if inertia.is_some() {
                            return Err(ModelError::invalid(
                                ctx,
                                "use a RigidBody for rotary inertia in a spatial scene",
                            ));
                        }
                        (
                            Element::point_mass(*mass).map_err(wrap)?,
                            vec![Attach::Pos(node.clone())],
                        )
                    }
                };
                expanded.push(Expanded {
                    id: id.clone(),
                    group: id.clone(),
                    element,
                    attach,
                    section: None,
                });
            }
            ElementSpec::RigidBody {
                node,
                mass,
                com,
                inertia,
            } => {
                if dim == Dimension::Planar {
                    return Err(ModelError::invalid(
                        ctx,
                        "a RigidBody needs a spatial scene; use PointMass with inertia",
                    ));
                }
                node_ref(node, &ctx, &node_at)?;
                let com = match com {
                    Some(c) => vec3(&ctx, "com", c)?,
                    None => [0.0; 3],
                };
                if inertia.len() != 3 {
                    return Err(ModelError::invalid(&ctx, "inertia must be a 3 × 3 matrix"));
                }
                let j = [
                    vec3(&ctx, "inertia row", &inertia[0])?,
                    vec3(&ctx, "inertia row", &inertia[1])?,
                    vec3(&ctx, "inertia row", &inertia[2])?,
                ];
                let ident = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                let element = Element::rigid_body(*mass, com, j, ident).map_err(wrap)?;
                expanded.push(Expanded {
                    id: id.clone(),
                    group: id.clone(),
                    element,
                    attach: vec![Attach::Pos(node.clone()), Attach::Carried(node.clone())],
                    section: None,
                });
            }
            ElementSpec::Superelement {
                nodes,
                file,
                transform,
                share,
            } => {
                if dim == Dimension::Planar {
                    return Err(ModelError::invalid(
                        ctx,
                        "superelements need a spatial scene",
                    ));
                }
                let p = node_ref(&nodes.0, &ctx, &node_at)?;
                let q = node_ref(&nodes.1, &ctx, &node_at)?;
                let path = match base_dir {
                    Some(d) => d.join(file),
                    None => Path::new(file).to_path_buf(),
                };
                let data = match files.get(&path) {
                    Some(d) => d.clone(),
                    None => {
                        let text = std::fs::read_to_string(&path).map_err(|e| ModelError::Io {
                            path: path.display().to_string(),
                            message: e.to_string(),
                        })?;
                        let d: Arc<LinearSuperelement> =
                            Arc::new(crate::parse_ron(&text, &path.display().to_string())?);
                        files.insert(path.clone(), d.clone());
                        d
                    }
                };
                let l =
                    ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt();
                if (l - data.l0).abs() > 1e-9 * data.l0.max(1e-12) {
                    return Err(ModelError::invalid(
                        ctx,
                        format!(
                            "the nodes are {l} m apart but the superelement file has l0 = {} m",
                            data.l0
                        ),
                    ));
                }
                let element = Element::superelement(&data, *transform).map_err(wrap)?;
                part_axes.insert(
                    id.clone(),
                    PartAxis {
                        p: (nodes.0.clone(), [p[0], p[1], p[2]]),
                        q: (nodes.1.clone(), [q[0], q[1], q[2]]),
                        l0: data.l0,
                        x: std::array::from_fn(|i| data.r0[i][0]),
                    },
                );
                part_data.insert(id.clone(), data.clone());
                let (kp, kq, kf) = data.mode_counts();
                let gp = share.0.clone().unwrap_or_else(|| format!("{id}.p"));
                let gq = share.1.clone().unwrap_or_else(|| format!("{id}.q"));
                let gf = format!("{id}.f");
                for (g, k) in [(&gp, kp), (&gq, kq), (&gf, kf)] {
                    register_mode_group(&mut mode_groups, &ctx, g, k)?;
                }
                expanded.push(Expanded {
                    id: id.clone(),
                    group: id.clone(),
                    element,
                    attach: vec![
                        Attach::Pos(nodes.0.clone()),
                        Attach::Orient(nodes.0.clone()),
                        Attach::Pos(nodes.1.clone()),
                        Attach::Orient(nodes.1.clone()),
                        Attach::Group(gp),
                        Attach::Group(gq),
                        Attach::Group(gf),
                    ],
                    section: None,
                });
            }
        }
    }
    for c in extra {
        let ctx = format!("element '{}' (built in code)", c.id);
        if c.id.is_empty() {
            return Err(ModelError::invalid(ctx, "an empty id"));
        }
        if element_ids.insert(c.id.clone(), ()).is_some() {
            return Err(ModelError::DuplicateId {
                kind: "element",
                id: c.id.clone(),
            });
        }
        let slots = c.element.slots();
        if c.nodes.len() != slots.len() {
            return Err(ModelError::invalid(
                ctx,
                format!(
                    "{} node ids given for the {} slots {slots:?}; give one node per slot",
                    c.nodes.len(),
                    slots.len()
                ),
            ));
        }
        let mut attach = vec![];
        for (slot, n) in slots.iter().zip(&c.nodes) {
            node_ref(n, &ctx, &node_at)?;
            use flexmb_element::Slot;
            let fits = match slot {
                Slot::Position2 | Slot::Angle => dim == Dimension::Planar,
                Slot::Position3 | Slot::Orientation => dim == Dimension::Spatial,
                Slot::Modes(_) => {
                    return Err(ModelError::invalid(
                        ctx,
                        "mode-amplitude slots are not supported for elements built in code",
                    ))
                }
            };
            if !fits {
                return Err(ModelError::invalid(
                    ctx,
                    format!("a {slot:?} slot does not fit a {dim:?} scene"),
                ));
            }
            attach.push(match slot {
                Slot::Position2 | Slot::Position3 => Attach::Pos(n.clone()),
                _ => Attach::Orient(n.clone()),
            });
        }
        expanded.push(Expanded {
            id: c.id.clone(),
            group: c.id.clone(),
            element: c.element.clone(),
            attach,
            section: None,
        });
    }
    if expanded.is_empty() {
        return Err(ModelError::invalid("scene", "has no elements"));
    }
    // ---- coordinates
    report(BuildStage::Coordinates);
    let mut needs_orient: HashMap<String, bool> = HashMap::new();
    for e in &expanded {
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
    for id in &node_order {
        let at = node_at[id].clone();
        let position: Vec<usize> = match shares.get(id) {
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
            match dim {
                Dimension::Planar => {
                    x0.push(initial_orientation.get(id).map_or(0.0, |v| v[0]));
                    x_names.push(format!("{id}.angle"));
                    Some(vec![start])
                }
                Dimension::Spatial => {
                    match initial_orientation.get(id) {
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
    for (g, k) in &mode_groups {
        let idx: Vec<usize> = (x0.len()..x0.len() + k).collect();
        for i in 0..*k {
            x0.push(0.0);
            x_names.push(format!("{g}.eta{}", i + 1));
        }
        groups.push((g.clone(), idx));
    }
    let node_idx: HashMap<&str, usize> = nodes
        .iter()
        .enumerate()
        .map(|(i, n)| (n.id.as_str(), i))
        .collect();
    // ---- place elements
    let mut elements = vec![];
    let mut eps_names = vec![];
    for mut e in expanded {
        for (k, a) in e.attach.iter().enumerate() {
            if let Attach::Orient(n) = a {
                match initial_orientation.get(n) {
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
                Attach::Pos(n) => x_index.extend(&nodes[node_idx[n.as_str()]].position),
                Attach::Orient(n) | Attach::Carried(n) => x_index.extend(
                    nodes[node_idx[n.as_str()]]
                        .orientation
                        .as_ref()
                        .expect("allocated"),
                ),
                Attach::Group(g) => {
                    x_index.extend(&groups.iter().find(|(n, _)| n == g).expect("allocated").1)
                }
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
        for n in &nodes {
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
    let n_x = x0.len();
    let n_eps = eps_names.len();
    let mech = Mechanism {
        name: scene.name.clone(),
        dimension: dim,
        nodes,
        mode_groups: groups,
        x0,
        x_names,
        eps_names,
        elements,
        x_roles: vec![XRole::Dependent(0); n_x],
        e_roles: vec![ERole::Dependent; n_eps],
        dofs: vec![],
        inputs: vec![],
        dependent: vec![],
        constraint_rows: vec![],
        gravity,
        loads: vec![],
        controllers: vec![],
        outputs: scene.outputs.clone(),
        initial_xd: vec![0.0; n_x],
    };
    mech.check_outputs()?;
    report(BuildStage::ReferenceConfiguration);
    check_reference_configuration(&mech, &part_axes)?;
    if restrained.is_empty() {
        Ok((mech, std::borrow::Cow::Borrowed(scene)))
    } else {
        let mut with_restraints = scene.clone();
        with_restraints.fixed.extend(restrained);
        Ok((mech, std::borrow::Cow::Owned(with_restraints)))
    }
}

/// The warping groups of a beam chain of `n` elements, one per node: the
/// ends' `Shared` names, else `ID.w0` … `ID.wN`.
fn warping_groups(id: &str, n: usize, w: &WarpingSpec) -> Vec<String> {
    (0..=n)
        .map(|k| match (k, &w.p, &w.q) {
            (0, WarpingEnd::Shared(g), _) => g.clone(),
            (k, _, WarpingEnd::Shared(g)) if k == n => g.clone(),
            _ => format!("{id}.w{k}"),
        })
        .collect()
}

/// Adds mode group `g` of `k` coordinates, or checks that an earlier
/// element gave it the same size.
fn register_mode_group(
    groups: &mut Vec<(String, usize)>,
    ctx: &str,
    g: &str,
    k: usize,
) -> Result<(), ModelError> {
    match groups.iter().find(|(n, _)| n == g) {
        Some((_, n)) if *n != k => Err(ModelError::invalid(
            ctx,
            format!("mode group '{g}' has {n} modes elsewhere but {k} here"),
        )),
        Some(_) => Ok(()),
        None => {
            groups.push((g.to_string(), k));
            Ok(())
        }
    }
}

/// Where a superelement's FE part has its p → q axis: the first column of R0.
struct PartAxis {
    /// Scene node p and its position.
    p: (String, [f64; 3]),
    /// Scene node q and its position.
    q: (String, [f64; 3]),
    /// The part's l0.
    l0: f64,
    /// The part's p → q direction (global, as built).
    x: [f64; 3],
}
