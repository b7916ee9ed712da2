//! The elements stage of the build ([`BuildStage::Elements`]): every scene
//! element checked and built (chains expanded into their members,
//! superelement files read once each), then the elements built in code,
//! each with the node or mode group every slot attaches to.

use super::*;

/// The elements of a scene as built, with what the later stages need.
pub(super) struct ElementSet {
    /// The elements (chain members one by one), in scene order, then those
    /// built in code.
    pub(super) expanded: Vec<Expanded>,
    /// Mode groups (superelement interfaces and normal modes, warping
    /// coordinates) and their sizes, in the order they were met.
    pub(super) mode_groups: Vec<(String, usize)>,
    /// Mode groups that the elements restrain (warping at a clamped end).
    pub(super) restrained: Vec<Select>,
    /// Where each superelement's FE part has its axis, for the reference
    /// check's message.
    pub(super) part_axes: HashMap<String, PartAxis>,
    /// The data of each superelement, by element id.
    pub(super) part_data: HashMap<String, Arc<LinearSuperelement>>,
}

/// Builds the elements of `scene` and then `extra`; the chain helpers add
/// their intermediate nodes to `nodes`.
pub(super) fn expand_elements(
    scene: &Scene,
    base_dir: Option<&Path>,
    extra: &[CodeElement],
    lib: &Library,
    nodes: &mut NodeTable,
) -> Result<ElementSet, ModelError> {
    let mut ex = Expander {
        dim: scene.dimension,
        base_dir,
        lib,
        nodes,
        files: HashMap::new(),
        ids: HashMap::new(),
        chain_total: 0,
        set: ElementSet {
            expanded: vec![],
            mode_groups: vec![],
            restrained: vec![],
            part_axes: HashMap::new(),
            part_data: HashMap::new(),
        },
    };
    for entry in &scene.elements {
        ex.entry(entry)?;
    }
    for c in extra {
        ex.code_element(c)?;
    }
    if ex.set.expanded.is_empty() {
        return Err(ModelError::invalid("scene", "has no elements"));
    }
    Ok(ex.set)
}

/// The state of the elements stage.
struct Expander<'a> {
    dim: Dimension,
    base_dir: Option<&'a Path>,
    lib: &'a Library,
    nodes: &'a mut NodeTable,
    /// Superelement files read so far, each read once.
    files: HashMap<PathBuf, Arc<LinearSuperelement>>,
    /// Element ids seen so far (duplicates are errors).
    ids: HashMap<String, ()>,
    /// Elements made by the chain helpers so far, for the memory estimate.
    chain_total: usize,
    set: ElementSet,
}

/// An element error of element `id`.
fn element_error(id: &str) -> impl Fn(flexmb_element::ElementError) -> ModelError + '_ {
    move |e| ModelError::Element {
        id: id.to_string(),
        source: e,
    }
}

/// The id of member `k` of a chain `id` of `n` elements.
fn member_id(id: &str, n: usize, k: usize) -> String {
    if n == 1 {
        id.to_string()
    } else {
        format!("{id}.{}", k + 1)
    }
}

impl Expander<'_> {
    fn push(&mut self, id: String, group: &str, element: Element, attach: Vec<Attach>) {
        self.push_section(id, group, element, attach, None);
    }

    fn push_section(
        &mut self,
        id: String,
        group: &str,
        element: Element,
        attach: Vec<Attach>,
        section: Option<crate::BeamSection>,
    ) {
        self.set.expanded.push(Expanded {
            id,
            group: group.to_string(),
            element,
            attach,
            section,
        });
    }

    /// One scene element: its id unique, its chain within the helper's
    /// limits and the estimated memory, then built by kind.
    fn entry(&mut self, entry: &ElementEntry) -> Result<(), ModelError> {
        let id = entry.id.as_str();
        if self.ids.insert(id.to_string(), ()).is_some() {
            return Err(ModelError::DuplicateId {
                kind: "element",
                id: id.to_string(),
            });
        }
        let ctx = format!("element '{id}'");
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
        self.chain_total += n;
        let estimate = self.chain_total as f64 * BYTES_PER_ELEMENT;
        let limit = crate::roles::physical_memory() as f64 / 4.0;
        if estimate > limit {
            return Err(ModelError::TooLarge {
                what: format!(
                    "{ctx}: {} elements would need about {} to assemble",
                    self.chain_total,
                    crate::roles::human_bytes(estimate)
                ),
                limit: crate::roles::human_bytes(limit),
            });
        }
        match &entry.kind {
            ElementSpec::Beam(b) => self.beam(id, &ctx, b),
            ElementSpec::Truss {
                nodes,
                ea,
                mass_per_length,
                n,
            } => self.truss(id, &ctx, nodes, *ea, *mass_per_length, *n),
            ElementSpec::Hinge {
                nodes,
                axis,
                stiffness,
                bending_stiffness,
            } => self.hinge(id, &ctx, nodes, axis, *stiffness, *bending_stiffness),
            ElementSpec::PointMass {
                node,
                mass,
                inertia,
            } => self.point_mass(id, &ctx, node, *mass, *inertia),
            ElementSpec::RigidBody {
                node,
                mass,
                com,
                inertia,
            } => self.rigid_body(id, &ctx, node, *mass, com, inertia),
            ElementSpec::Superelement {
                nodes,
                file,
                transform,
                share,
            } => self.superelement(id, &ctx, nodes, file, *transform, share),
        }
    }

    /// A beam or a chain of beams (thesis (5.2)–(5.3), (6.2)), with its
    /// warping groups when it has warping.
    fn beam(&mut self, id: &str, ctx: &str, b: &BeamSpec) -> Result<(), ModelError> {
        let p = self.nodes.position(&b.nodes.0, ctx)?;
        let q = self.nodes.position(&b.nodes.1, ctx)?;
        let mat = self.lib.material(&b.material, ctx)?;
        let shape = self.lib.section(&b.section, ctx)?;
        let opts = BeamOptions {
            shortening: b.shortening,
            timoshenko: b.timoshenko,
            inertia: b.mass,
            velocity_transform: b.transform,
            warping: b.warping.is_some(),
            plate_warping: b.anticlastic.is_some(),
        };
        let warp_groups = match &b.warping {
            None => vec![],
            Some(_) if self.dim == Dimension::Planar => {
                return Err(ModelError::invalid(
                    ctx,
                    "warping is an option of spatial beams; a planar beam has no torsion",
                ))
            }
            Some(w) => self.end_groups(ctx, id, b.n, w, "w", 1)?,
        };
        let curl_groups = match &b.anticlastic {
            None => vec![],
            Some(_) if self.dim == Dimension::Planar => {
                return Err(ModelError::invalid(
                    ctx,
                    "anticlastic is an option of spatial sheet beams; a planar beam has no section height",
                ))
            }
            Some(w) => self.end_groups(ctx, id, b.n, w, "a", 2)?,
        };
        let nodes = &mut *self.nodes;
        let chain = chain_nodes(id, &b.nodes, &p, &q, b.n, &mut nodes.at, &mut nodes.order)?;
        for (k, (a, bb)) in chain.iter().enumerate() {
            let (pa, pb) = (&self.nodes.at[a], &self.nodes.at[bb]);
            let (element, frame, overlay) = match self.dim {
                Dimension::Planar => {
                    let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
                    let l = dx.hypot(dy);
                    let (c, s) = if l > 0.0 {
                        (dx / l, dy / l)
                    } else {
                        (1.0, 0.0)
                    };
                    let element =
                        Element::planar_beam([pa[0], pa[1]], [pb[0], pb[1]], &mat, &shape, &opts)
                            .map_err(element_error(id))?;
                    let frame = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
                    (element, frame, None)
                }
                Dimension::Spatial => {
                    let axis = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
                    let up = match &b.up {
                        Some(u) => vec3(ctx, "up", u)?,
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
                    .map_err(element_error(id))?;
                    // the element checked the axis and up
                    let frame =
                        flexmb_element::frame_from_axis(&axis, &up).map_err(element_error(id))?;
                    let overlay = if curl_groups.is_empty() {
                        None
                    } else {
                        let o = flexmb_element::anticlastic_overlay(
                            [pa[0], pa[1], pa[2]],
                            [pb[0], pb[1], pb[2]],
                            up,
                            &mat,
                            &shape,
                            b.mass,
                        )
                        .map_err(element_error(id))?;
                        Some(o)
                    };
                    (element, frame, overlay)
                }
            };
            let section = crate::BeamSection {
                shape,
                frame,
                planar: self.dim == Dimension::Planar,
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
            let member = member_id(id, b.n, k);
            if let Some(overlay) = overlay {
                let mut curl_attach = attach[..4].to_vec();
                curl_attach.push(Attach::Group(curl_groups[k].clone()));
                curl_attach.push(Attach::Group(curl_groups[k + 1].clone()));
                // its own group `ID.curl`: `Def("ID", …)` keeps naming the beams
                self.push(
                    format!("{member}.curl"),
                    &format!("{id}.curl"),
                    overlay,
                    curl_attach,
                );
            }
            self.push_section(member, id, element, attach, Some(section));
        }
        Ok(())
    }

    /// The one-per-node mode groups of a chain's warping (`w`) or curl
    /// (`a`) coordinates, `size` coordinates each, registered, with the
    /// `Restrained` ends fixed.
    fn end_groups(
        &mut self,
        ctx: &str,
        id: &str,
        n: usize,
        w: &WarpingSpec,
        letter: &str,
        size: usize,
    ) -> Result<Vec<String>, ModelError> {
        let groups = chain_groups(id, n, w, letter);
        for g in &groups {
            register_mode_group(&mut self.set.mode_groups, ctx, g, size)?;
        }
        for (end, g) in [(&w.p, &groups[0]), (&w.q, &groups[n])] {
            if *end == WarpingEnd::Restrained {
                self.set.restrained.push(Select::Modes(g.clone()));
            }
        }
        Ok(groups)
    }

    /// A truss or a chain of trusses.
    fn truss(
        &mut self,
        id: &str,
        ctx: &str,
        ends: &(String, String),
        ea: f64,
        mass_per_length: f64,
        n: usize,
    ) -> Result<(), ModelError> {
        let p = self.nodes.position(&ends.0, ctx)?;
        let q = self.nodes.position(&ends.1, ctx)?;
        let nodes = &mut *self.nodes;
        let chain = chain_nodes(id, ends, &p, &q, n, &mut nodes.at, &mut nodes.order)?;
        for (k, (a, bb)) in chain.iter().enumerate() {
            let (pa, pb) = (&self.nodes.at[a], &self.nodes.at[bb]);
            let element = match self.dim {
                Dimension::Planar => {
                    Element::planar_truss([pa[0], pa[1]], [pb[0], pb[1]], ea, mass_per_length)
                }
                Dimension::Spatial => Element::truss(
                    [pa[0], pa[1], pa[2]],
                    [pb[0], pb[1], pb[2]],
                    ea,
                    mass_per_length,
                ),
            }
            .map_err(element_error(id))?;
            let attach = vec![Attach::Pos(a.clone()), Attach::Pos(bb.clone())];
            self.push(member_id(id, n, k), id, element, attach);
        }
        Ok(())
    }

    /// A hinge between the orientations of two nodes (thesis (5.5); spatial
    /// with an axis).
    fn hinge(
        &mut self,
        id: &str,
        ctx: &str,
        nodes: &(String, String),
        axis: &Option<Vec<f64>>,
        stiffness: f64,
        bending_stiffness: f64,
    ) -> Result<(), ModelError> {
        self.nodes.position(&nodes.0, ctx)?;
        self.nodes.position(&nodes.1, ctx)?;
        let element = match self.dim {
            Dimension::Planar => Element::planar_hinge(stiffness),
            Dimension::Spatial => {
                let a = axis
                    .as_ref()
                    .ok_or_else(|| ModelError::invalid(ctx, "a spatial hinge needs an axis"))?;
                Element::hinge(vec3(ctx, "axis", a)?, stiffness, bending_stiffness)
            }
        }
        .map_err(element_error(id))?;
        let attach = vec![
            Attach::Orient(nodes.0.clone()),
            Attach::Orient(nodes.1.clone()),
        ];
        self.push(id.to_string(), id, element, attach);
        Ok(())
    }

    /// A point mass (planar: with an optional rotary inertia on the node's
    /// angle).
    fn point_mass(
        &mut self,
        id: &str,
        ctx: &str,
        node: &str,
        mass: f64,
        inertia: Option<f64>,
    ) -> Result<(), ModelError> {
        self.nodes.position(node, ctx)?;
        let (element, attach) = match self.dim {
            Dimension::Planar => (
                Element::planar_mass(mass, inertia).map_err(element_error(id))?,
                if inertia.is_some() {
                    vec![
                        Attach::Pos(node.to_string()),
                        Attach::Orient(node.to_string()),
                    ]
                } else {
                    vec![Attach::Pos(node.to_string())]
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
                    Element::point_mass(mass).map_err(element_error(id))?,
                    vec![Attach::Pos(node.to_string())],
                )
            }
        };
        self.push(id.to_string(), id, element, attach);
        Ok(())
    }

    /// A rigid body carried by a spatial node, its centre of mass and
    /// inertia in the node's own axes.
    fn rigid_body(
        &mut self,
        id: &str,
        ctx: &str,
        node: &str,
        mass: f64,
        com: &Option<Vec<f64>>,
        inertia: &[Vec<f64>],
    ) -> Result<(), ModelError> {
        if self.dim == Dimension::Planar {
            return Err(ModelError::invalid(
                ctx,
                "a RigidBody needs a spatial scene; use PointMass with inertia",
            ));
        }
        self.nodes.position(node, ctx)?;
        let com = opt_vec3(ctx, "com", com)?;
        if inertia.len() != 3 {
            return Err(ModelError::invalid(ctx, "inertia must be a 3 × 3 matrix"));
        }
        let j = [
            vec3(ctx, "inertia row", &inertia[0])?,
            vec3(ctx, "inertia row", &inertia[1])?,
            vec3(ctx, "inertia row", &inertia[2])?,
        ];
        let ident = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let element = Element::rigid_body(mass, com, j, ident).map_err(element_error(id))?;
        let attach = vec![
            Attach::Pos(node.to_string()),
            Attach::Carried(node.to_string()),
        ];
        self.push(id.to_string(), id, element, attach);
        Ok(())
    }

    /// A superelement from its file (read once per path), its nodes as far
    /// apart as its l0, with its interface and normal-mode groups.
    fn superelement(
        &mut self,
        id: &str,
        ctx: &str,
        nodes: &(String, String),
        file: &str,
        transform: flexmb_element::VelocityTransform,
        share: &(Option<String>, Option<String>),
    ) -> Result<(), ModelError> {
        if self.dim == Dimension::Planar {
            return Err(ModelError::invalid(
                ctx,
                "superelements need a spatial scene",
            ));
        }
        let p = self.nodes.position(&nodes.0, ctx)?;
        let q = self.nodes.position(&nodes.1, ctx)?;
        let path = match self.base_dir {
            Some(d) => d.join(file),
            None => Path::new(file).to_path_buf(),
        };
        let data = match self.files.get(&path) {
            Some(d) => d.clone(),
            None => {
                let text = std::fs::read_to_string(&path).map_err(|e| ModelError::Io {
                    path: path.display().to_string(),
                    message: e.to_string(),
                })?;
                let d: Arc<LinearSuperelement> =
                    Arc::new(crate::parse_ron(&text, &path.display().to_string())?);
                self.files.insert(path.clone(), d.clone());
                d
            }
        };
        let l = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt();
        if (l - data.l0).abs() > 1e-9 * data.l0.max(1e-12) {
            return Err(ModelError::invalid(
                ctx,
                format!(
                    "the nodes are {l} m apart but the superelement file has l0 = {} m",
                    data.l0
                ),
            ));
        }
        let element = Element::superelement(&data, transform).map_err(element_error(id))?;
        self.set.part_axes.insert(
            id.to_string(),
            PartAxis {
                p: (nodes.0.clone(), [p[0], p[1], p[2]]),
                q: (nodes.1.clone(), [q[0], q[1], q[2]]),
                l0: data.l0,
                x: std::array::from_fn(|i| data.r0[i][0]),
            },
        );
        self.set.part_data.insert(id.to_string(), data.clone());
        let (kp, kq, kf) = data.mode_counts();
        let gp = share.0.clone().unwrap_or_else(|| format!("{id}.p"));
        let gq = share.1.clone().unwrap_or_else(|| format!("{id}.q"));
        let gf = format!("{id}.f");
        for (g, k) in [(&gp, kp), (&gq, kq), (&gf, kf)] {
            register_mode_group(&mut self.set.mode_groups, ctx, g, k)?;
        }
        let attach = vec![
            Attach::Pos(nodes.0.clone()),
            Attach::Orient(nodes.0.clone()),
            Attach::Pos(nodes.1.clone()),
            Attach::Orient(nodes.1.clone()),
            Attach::Group(gp),
            Attach::Group(gq),
            Attach::Group(gf),
        ];
        self.push(id.to_string(), id, element, attach);
        Ok(())
    }

    /// An element built in code: its id unique, one node per slot, each
    /// slot fitting the scene's dimension.
    fn code_element(&mut self, c: &CodeElement) -> Result<(), ModelError> {
        let ctx = format!("element '{}' (built in code)", c.id);
        if c.id.is_empty() {
            return Err(ModelError::invalid(ctx, "an empty id"));
        }
        if self.ids.insert(c.id.clone(), ()).is_some() {
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
            self.nodes.position(n, &ctx)?;
            use flexmb_element::Slot;
            let fits = match slot {
                Slot::Position2 | Slot::Angle => self.dim == Dimension::Planar,
                Slot::Position3 | Slot::Orientation => self.dim == Dimension::Spatial,
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
                    format!("a {slot:?} slot does not fit a {:?} scene", self.dim),
                ));
            }
            attach.push(match slot {
                Slot::Position2 | Slot::Position3 => Attach::Pos(n.clone()),
                _ => Attach::Orient(n.clone()),
            });
        }
        self.push(c.id.clone(), &c.id, c.element.clone(), attach);
        Ok(())
    }
}

/// The warping (`letter` w) or curl (a) groups of a beam chain of `n`
/// elements, one per node: the ends' `Shared` names, else `ID.w0` … `ID.wN`.
fn chain_groups(id: &str, n: usize, w: &WarpingSpec, letter: &str) -> Vec<String> {
    (0..=n)
        .map(|k| match (k, &w.p, &w.q) {
            (0, WarpingEnd::Shared(g), _) => g.clone(),
            (k, _, WarpingEnd::Shared(g)) if k == n => g.clone(),
            _ => format!("{id}.{letter}{k}"),
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
pub(super) struct PartAxis {
    /// Scene node p and its position.
    pub(super) p: (String, [f64; 3]),
    /// Scene node q and its position.
    pub(super) q: (String, [f64; 3]),
    /// The part's l0.
    pub(super) l0: f64,
    /// The part's p → q direction (global, as built).
    pub(super) x: [f64; 3],
}
