//! One command from a mesh to a superelement (`flexmb build-superelement
//! --mesh PART --material M --interface p=… --interface q=… --out DIR`):
//! the spec that the four hand-written files of the CalculiX route add up
//! to, worked out from the mesh.
//!
//! 1. A `.geo` is meshed by gmsh into `DIR/NAME.msh` ([`crate::mesh_file`]).
//! 2. The model is loaded as [`ModelSource::Mesh`] (built-in FE or CalculiX).
//! 3. Each interface is a named node set of the mesh (a gmsh physical
//!    surface by name or tag, an *NSET) or the nodes on a plane; p and q go
//!    to the centroids of the surfaces they cover
//!    ([`crate::interface::interface_geometry`]). Interfaces without nodes
//!    and interfaces that share nodes are errors.
//! 4. The spec is written to `DIR/NAME.spec.ron` and built by
//!    [`build_loaded`], the function behind `flexmb build-superelement
//!    SPEC.ron` (so `flexmb build-superelement DIR/NAME.spec.ron` builds the
//!    same part again), into `DIR/NAME.se.ron`. The builder refuses warping
//!    modes on interfaces that are curved or not normal to p → q
//!    ([`crate::interface::check_warping_plane`]).
//!
//! [`MeshBuildOutput::report`] is the readable account of the build; the
//! command line adds a scene stub.

use crate::interface::{interface_geometry, InterfaceGeometry};
use crate::mesh_file::{mesh_geo, MeshMaterial};
use crate::model::{norm, sub, FeModel, NodeSelection};
use crate::spec::{build_loaded, load_model, BuildOutput, FeSolver, ModelSource, Spec};
use crate::{BuildSettings, Error, RigidBodyProperties};
use std::path::{Path, PathBuf};

/// How an interface is chosen.
#[derive(Clone, Debug, PartialEq)]
pub enum InterfaceChoice {
    /// A named node set of the mesh: a gmsh physical surface (by name or
    /// tag) or another physical group, an *NSET of an `.inp` mesh.
    Set(String),
    /// The nodes on a plane (within 1e-6 of the mesh's bounding-box
    /// diagonal).
    Plane {
        /// A point of the plane (m, in the mesh's coordinates).
        point: [f64; 3],
        /// Its normal (need not be unit).
        normal: [f64; 3],
    },
}

impl InterfaceChoice {
    /// Parses `NAME` or `TAG` (a node set), `plane:x=V` (also y, z) or
    /// `plane:PX,PY,PZ,NX,NY,NZ` (a point and a normal).
    pub fn parse(text: &str) -> Result<Self, Error> {
        let t = text.trim();
        let Some(plane) = t.strip_prefix("plane:") else {
            if t.is_empty() {
                return Err(Error::Spec(
                    "an empty interface: give a physical surface (name or tag), a node set or plane:z=VALUE".into(),
                ));
            }
            return Ok(InterfaceChoice::Set(t.to_string()));
        };
        let bad = || {
            Error::Spec(format!(
                "interface '{text}': a plane is plane:x=VALUE (or y, z) or plane:PX,PY,PZ,NX,NY,NZ (a point and a \
                 normal, in metres)"
            ))
        };
        if let Some((axis, value)) = plane.split_once('=') {
            let d = match axis.trim() {
                "x" | "X" => 0,
                "y" | "Y" => 1,
                "z" | "Z" => 2,
                _ => return Err(bad()),
            };
            let v: f64 = value.trim().parse().map_err(|_| bad())?;
            if !v.is_finite() {
                return Err(bad());
            }
            let mut point = [0.0; 3];
            let mut normal = [0.0; 3];
            point[d] = v;
            normal[d] = 1.0;
            return Ok(InterfaceChoice::Plane { point, normal });
        }
        let v: Vec<f64> = plane
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        if v.len() != 6 || v.iter().any(|x| !x.is_finite()) || norm([v[3], v[4], v[5]]) == 0.0 {
            return Err(bad());
        }
        Ok(InterfaceChoice::Plane {
            point: [v[0], v[1], v[2]],
            normal: [v[3], v[4], v[5]],
        })
    }

    /// The node selection of the spec for this choice in `model`.
    fn selection(&self, model: &FeModel) -> NodeSelection {
        match self {
            InterfaceChoice::Set(name) => NodeSelection::Set(name.clone()),
            InterfaceChoice::Plane { point, normal } => NodeSelection::NearPlane {
                point: *point,
                normal: *normal,
                tolerance: 1e-6 * bbox_diagonal(model),
            },
        }
    }
}

fn bbox(model: &FeModel) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for c in model.coords() {
        for d in 0..3 {
            lo[d] = lo[d].min(c[d]);
            hi[d] = hi[d].max(c[d]);
        }
    }
    (lo, hi)
}

fn bbox_diagonal(model: &FeModel) -> f64 {
    let (lo, hi) = bbox(model);
    norm(sub(hi, lo))
}

/// What to build (the options of the command).
#[derive(Clone, Debug)]
pub struct MeshBuild {
    /// The part's name: the element id of the scene stub and the stem of
    /// the files written.
    pub name: String,
    /// The mesh: `.msh`, `.geo` or `.inp`.
    pub mesh: PathBuf,
    /// The material of every element.
    pub material: MeshMaterial,
    /// The FE solver.
    pub solver: FeSolver,
    /// Interface p (p goes to its centroid).
    pub p: InterfaceChoice,
    /// Interface q.
    pub q: InterfaceChoice,
    /// Warping modes (3.4) of both interfaces.
    pub warping: bool,
    /// Fixed-interface normal modes.
    pub normal_modes: usize,
    /// The output directory (created).
    pub out_dir: PathBuf,
}

/// One interface as built.
#[derive(Clone, Debug)]
pub struct InterfaceInfo {
    /// How it was chosen, e.g. "physical surface 'left' (tag 2, 25 nodes)".
    pub what: String,
    /// Its geometry (centroid = p or q).
    pub geometry: InterfaceGeometry,
}

/// What [`build_from_mesh`] did.
#[derive(Clone, Debug)]
pub struct MeshBuildOutput {
    /// The request.
    pub request: MeshBuild,
    /// The spec it wrote and built.
    pub spec: Spec,
    /// The spec's file (`DIR/NAME.spec.ron`).
    pub spec_file: PathBuf,
    /// The build.
    pub output: BuildOutput,
    /// Interfaces p and q.
    pub interfaces: [InterfaceInfo; 2],
    /// Nodes and elements of the mesh, e.g. (1234, "600 Tet10").
    pub mesh_size: (usize, String),
    /// The mesh's volume (m³).
    pub volume: Option<f64>,
    /// The rigid-body properties of M applied to rigid fields against those
    /// of the mesh's volume × density.
    pub rigid_body: Option<crate::consistency::RigidBodyComparison>,
    /// The files the model was read from (the mesh, CalculiX's exports).
    pub model_files: Vec<PathBuf>,
    /// Warnings (besides the build's).
    pub warnings: Vec<String>,
}

/// Checks a part name for use as a file stem and an element id.
fn check_name(name: &str) -> Result<(), Error> {
    let ok = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-'));
    if ok {
        Ok(())
    } else {
        Err(Error::Spec(format!(
            "the part's name '{name}' must be letters, digits, '_' and '-' (it names the files and the scene's element)"
        )))
    }
}

/// Builds a superelement from a mesh (see the module docs) and writes the
/// spec and the superelement into `req.out_dir`.
pub fn build_from_mesh(req: &MeshBuild) -> Result<MeshBuildOutput, Error> {
    check_name(&req.name)?;
    req.material.material()?;
    let dir = &req.out_dir;
    std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))?;
    let ext = req
        .mesh
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut extra_files = Vec::new();
    let file = if ext == "geo" {
        let msh = dir.join(format!("{}.msh", req.name));
        mesh_geo(&req.mesh, &msh)?;
        extra_files.push(req.mesh.clone());
        format!("{}.msh", req.name)
    } else {
        let abs = std::fs::canonicalize(&req.mesh).map_err(|e| Error::io(&req.mesh, e))?;
        abs.to_string_lossy().to_string()
    };
    let mut spec = Spec {
        name: req.name.clone(),
        model: ModelSource::Mesh {
            file,
            material: req.material,
            solver: req.solver,
        },
        units: None,
        stiffness_scale: None,
        mass_scale: None,
        settings: BuildSettings::new(
            [0.0; 3],
            [1.0, 0.0, 0.0],
            NodeSelection::Ids(vec![]),
            NodeSelection::Ids(vec![]),
        ),
        output: format!("{}.se.ron", req.name),
        m_bar_matrix_market: None,
    };
    let (model, mut files) = load_model(&spec, dir)?;
    extra_files.append(&mut files);
    let files = extra_files;

    let mut warnings = Vec::new();
    let mut sel = Vec::new();
    let mut nodes = Vec::new();
    let mut infos = Vec::new();
    for (side, choice) in [("p", &req.p), ("q", &req.q)] {
        let (s, n, what) = resolve(&model, side, choice)?;
        let mut g = interface_geometry(&model, &n);
        // rounding noise of the centroid of a centred part reads as zero
        let tiny = 1e-12 * bbox_diagonal(&model);
        for c in g.centroid.iter_mut() {
            if c.abs() <= tiny {
                *c = 0.0;
            }
        }
        if g.area.is_none() {
            warnings.push(format!(
                "interface {side} ({what}) covers no face of the mesh's surface: {side} is at the mean of its {} \
                 nodes, not at a surface centroid",
                n.len()
            ));
        }
        sel.push(s);
        nodes.push(n);
        infos.push(InterfaceInfo { what, geometry: g });
    }
    let shared: Vec<usize> = nodes[0]
        .iter()
        .filter(|i| nodes[1].binary_search(i).is_ok())
        .copied()
        .collect();
    if let Some(&first) = shared.first() {
        let x = model.coords()[first];
        return Err(Error::interface(
            "p",
            format!(
                "interfaces p ({}) and q ({}) overlap: they share {} nodes (e.g. node {} at ({:.6e}, {:.6e}, {:.6e})); \
                 an interface node is attached to one boundary node: choose interfaces that do not touch",
                infos[0].what,
                infos[1].what,
                shared.len(),
                model.node_ids()[first],
                x[0],
                x[1],
                x[2]
            ),
        ));
    }
    let (p, q) = (infos[0].geometry.centroid, infos[1].geometry.centroid);
    if !(norm(sub(q, p)) > 1e-9 * bbox_diagonal(&model)) {
        return Err(Error::Spec(format!(
            "interfaces p ({}) and q ({}) have the same centroid {p:?}: a superelement needs p and q apart",
            infos[0].what, infos[1].what
        )));
    }
    let mut settings = BuildSettings::new(p, q, sel.remove(0), sel.remove(0));
    settings.warping_p = req.warping;
    settings.warping_q = req.warping;
    settings.normal_modes = req.normal_modes;
    spec.settings = settings;
    let spec_file = dir.join(format!("{}.spec.ron", req.name));
    write_spec(&spec_file, &spec)?;
    let output = build_loaded(&spec, dir, &model, &files)?;
    let mut written = vec![spec_file.clone()];
    written.extend(output.written.iter().cloned());
    let output = BuildOutput { written, ..output };
    let mut interfaces = infos.into_iter();
    let mesh_size = (
        model.n_nodes(),
        model
            .solid
            .as_ref()
            .map(|s| {
                let mut count = std::collections::BTreeMap::new();
                for k in &s.kinds {
                    *count.entry(format!("{k:?}")).or_insert(0usize) += 1;
                }
                count
                    .iter()
                    .map(|(k, n)| format!("{n} {k}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_default(),
    );
    Ok(MeshBuildOutput {
        request: req.clone(),
        spec,
        spec_file,
        output,
        interfaces: [interfaces.next().expect("p"), interfaces.next().expect("q")],
        mesh_size,
        volume: model.volume,
        rigid_body: model.compare_rigid_body(),
        model_files: files,
        warnings,
    })
}

/// The selection, nodes and description of an interface choice, with the
/// errors of a choice that selects nothing or a whole volume.
fn resolve(
    model: &FeModel,
    side: &str,
    choice: &InterfaceChoice,
) -> Result<(NodeSelection, Vec<usize>, String), Error> {
    let sel = choice.selection(model);
    let what = match choice {
        InterfaceChoice::Set(name) => {
            let set = model
                .node_set(name)
                .map_err(|e| Error::interface(side, e.to_string()))?;
            if set.what.contains("volume") {
                return Err(Error::interface(
                    side,
                    format!(
                        "{} is a volume: an interface is a surface (a physical surface, a node set of one face, or \
                         plane:…)",
                        set.describe()
                    ),
                ));
            }
            if set.nodes.is_empty() {
                return Err(Error::interface(
                    side,
                    format!(
                        "{} has no node of the part's solid elements",
                        set.describe()
                    ),
                ));
            }
            set.describe()
        }
        InterfaceChoice::Plane { point, normal } => {
            let n = norm(*normal);
            let u: [f64; 3] = std::array::from_fn(|d| normal[d] / n);
            let (lo, hi) =
                model
                    .coords()
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                        let s = (0..3).map(|d| (c[d] - point[d]) * u[d]).sum::<f64>();
                        (lo.min(s), hi.max(s))
                    });
            let text = plane_text(*point, u);
            if lo > 1e-6 * bbox_diagonal(model) || hi < -1e-6 * bbox_diagonal(model) {
                let (a, b) = bbox(model);
                return Err(Error::interface(
                    side,
                    format!(
                        "the plane {text} selects no node: the part lies {:.6e} … {:.6e} m from it along its normal \
                         (the mesh spans x {:.6e} … {:.6e}, y {:.6e} … {:.6e}, z {:.6e} … {:.6e} m)",
                        lo, hi, a[0], b[0], a[1], b[1], a[2], b[2]
                    ),
                ));
            }
            format!("the plane {text}")
        }
    };
    let nodes = sel
        .resolve(model, &format!("interface {side}"))
        .map_err(|e| Error::interface(side, format!("{what}: {e}")))?;
    let what = match choice {
        InterfaceChoice::Plane { .. } => format!("{what} ({} nodes)", nodes.len()),
        _ => what,
    };
    Ok((sel, nodes, what))
}

/// "x = 0.1" for an axis plane, else "through (…) normal to (…)".
fn plane_text(point: [f64; 3], u: [f64; 3]) -> String {
    if let Some(d) = (0..3).find(|&d| u[d].abs() == 1.0) {
        format!("{} = {}", ["x", "y", "z"][d], point[d])
    } else {
        format!(
            "through ({}, {}, {}) normal to ({:.4}, {:.4}, {:.4})",
            point[0], point[1], point[2], u[0], u[1], u[2]
        )
    }
}

fn write_spec(path: &Path, spec: &Spec) -> Result<(), Error> {
    let body = ron::ser::to_string_pretty(spec, ron::ser::PrettyConfig::default())
        .map_err(|e| Error::Spec(format!("cannot serialize the spec: {e}")))?;
    crate::readers::write_file(
        path,
        &format!(
            "// Written by `flexmb build-superelement --mesh …`: the spec it built, with p and q at the\n\
             // interface centroids. `flexmb build-superelement {}` builds the part again.\n{body}\n",
            path.file_name().map(|s| s.to_string_lossy().to_string()).unwrap_or_default()
        ),
    )
}

fn v3(v: [f64; 3]) -> String {
    format!("({:.6e}, {:.6e}, {:.6e})", v[0], v[1], v[2])
}

fn hz(f: &[f64]) -> String {
    f.iter()
        .map(|x| format!("{x:.4}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl MeshBuildOutput {
    /// The eigenfrequencies (Hz) of the part clamped at p, its p-side
    /// interface modes fixed (a clamped interface cannot warp), free at q
    /// with its q-side modes and the normal modes free: the scene stub's.
    pub fn clamped_free_frequencies(&self) -> Result<Vec<f64>, Error> {
        let res = &self.output.result;
        let (kp, kq, kf) = res.data.mode_counts();
        let keep: Vec<usize> = (6..12).chain(12 + kp..12 + kp + kq + kf).collect();
        res.frequencies(&keep)
    }

    /// The build report (markdown): the mesh, the interfaces, the
    /// superelement and its mode groups, its rigid-body properties, the
    /// frequencies of the reduced part, what was checked, warnings, files.
    pub fn report(&self) -> String {
        let req = &self.request;
        let res = &self.output.result;
        let d = &res.data;
        let r = &res.report;
        let name = &req.name;
        let mut s = format!("# Superelement `{name}`\n\n");
        s.push_str(&format!(
            "Built from `{}` by {} ({} nodes: {}), material E = {:e} Pa, ν = {}, ρ = {} kg/m³.\n\n",
            req.mesh.display(),
            match req.solver {
                FeSolver::Builtin => "the built-in FE",
                FeSolver::CalculiX => "CalculiX",
            },
            self.mesh_size.0,
            self.mesh_size.1,
            req.material.e,
            req.material.nu,
            req.material.rho
        ));
        s.push_str("## Interfaces\n\n| | chosen as | nodes | centroid (m) | area (m²) | plane normal | off the plane (m) | angle to p → q |\n|---|---|---|---|---|---|---|---|\n");
        let axis = sub(
            self.interfaces[1].geometry.centroid,
            self.interfaces[0].geometry.centroid,
        );
        for (side, i) in ["p", "q"].iter().zip(&self.interfaces) {
            let g = &i.geometry;
            s.push_str(&format!(
                "| {side} | {} | {} | {} | {} | ({:.4}, {:.4}, {:.4}) | {:.2e} | {:.4}° |\n",
                i.what,
                g.nodes,
                v3(g.centroid),
                g.area.map_or("–".to_string(), |a| format!("{a:.6e}")),
                g.normal[0],
                g.normal[1],
                g.normal[2],
                g.out_of_plane,
                g.angle_to(axis).to_degrees()
            ));
        }
        let (kp, kq, kf) = d.mode_counts();
        let ax = [d.r0[0][0], d.r0[1][0], d.r0[2][0]];
        let ay = [d.r0[0][1], d.r0[1][1], d.r0[2][1]];
        s.push_str(&format!(
            "\n## The superelement\n\nl0 = {:.6e} m from p to q; element x axis (p → q) ({:.6}, {:.6}, {:.6}), y axis \
             ({:.6}, {:.6}, {:.6}). Coordinates: 12 of the interfaces, then\n\n",
            d.l0, ax[0], ax[1], ax[2], ay[0], ay[1], ay[2]
        ));
        s.push_str(&format!(
            "* mode group `{name}.p`: {kp} warping mode(s) of interface p\n* mode group `{name}.q`: {kq} warping \
             mode(s) of interface q\n* mode group `{name}.f`: {kf} fixed-interface normal mode(s)\n\n\
             (share a group with a neighbour by naming it in the scene's `share: (…)`, fix it with `fixed: \
             [Modes(\"{name}.p\")]`).\n"
        ));
        let rb = RigidBodyProperties::from_m_bar(&d.m_bar_matrix(), d.l0);
        let com_global: [f64; 3] = std::array::from_fn(|i| {
            self.spec.settings.p[i] + (0..3).map(|k| d.r0[i][k] * rb.com[k]).sum::<f64>()
        });
        s.push_str(&format!(
            "\n## Rigid body\n\nFrom M̄: mass {:.6e} kg (the FE model: {:.6e} kg{}), centre of mass {} m (global; {} \
             from p in the element frame).\n\nInertia tensor about the centre of mass, element frame (kg m²):\n\n",
            rb.mass,
            r.fe_mass,
            self.volume
                .map(|v| format!(", volume {v:.6e} m³ × density {} kg/m³ = {:.6e} kg", req.material.rho, v * req.material.rho))
                .unwrap_or_default(),
            v3(com_global),
            v3(rb.com)
        ));
        s.push_str("```\n");
        for row in rb.inertia {
            s.push_str(&format!(
                "{:14.6e} {:14.6e} {:14.6e}\n",
                row[0], row[1], row[2]
            ));
        }
        s.push_str("```\n\n## Frequencies of the reduced part\n\n");
        if !r.normal_frequencies_hz.is_empty() {
            s.push_str(&format!(
                "* fixed-interface normal modes (both interfaces clamped): {} Hz\n",
                hz(&r.normal_frequencies_hz)
            ));
        }
        if let Ok(f) = self.clamped_free_frequencies() {
            s.push_str(&format!(
                "* clamped at p (which cannot warp), free at q (free to warp): {} Hz (lowest {}; the scene stub's \
                 `flexmb eig`)\n",
                hz(&f[..f.len().min(6)]),
                f.len().min(6)
            ));
        }
        let all: Vec<usize> = (0..12 + d.n_modes()).collect();
        if let Ok(f) = res.frequencies(&all) {
            let elastic = &f[6.min(f.len())..];
            s.push_str(&format!(
                "* free–free: six rigid-body modes (largest {:.2e} Hz), then {} Hz\n",
                f[..6.min(f.len())]
                    .iter()
                    .fold(0.0f64, |m, x| m.max(x.abs())),
                hz(&elastic[..elastic.len().min(6)])
            ));
        }
        s.push_str("\n## What was checked\n\n");
        s.push_str(
            "* K, M, the DOF list and the mesh against each other (sizes, diagonals, symmetry, rigid motions free of \
             energy, M's sparsity within the elements);\n",
        );
        if let Some(c) = &self.rigid_body {
            s.push_str(&format!(
                "* M applied to rigid motions against the mesh's volume × density: mass {:.1e}, centre of mass {:.1e}, \
                 inertia {:.1e} relative difference (1e-3 allowed);\n",
                c.difference[0], c.difference[1], c.difference[2]
            ));
        }
        if let Some(m) = &r.material {
            s.push_str(&format!(
                "* the material from linear-field energies of K and M: wave speed √(E/ρ) = {:.4e} m/s (the material's \
                 {:.4e}), ν = {:.4} (the material's {});\n",
                m.wave_speed,
                (req.material.e / req.material.rho).sqrt(),
                m.poisson,
                req.material.nu
            ));
        }
        s.push_str(
            "* every node attached to p or q; interfaces with at least 3 non-collinear nodes, not overlapping, \
             with all their DOFs;\n",
        );
        if req.warping {
            s.push_str(&format!(
                "* warping modes: both interfaces planar and normal to p → q (angles above, refused above {}°);\n",
                crate::interface::WARPING_ANGLE_LIMIT_DEG
            ));
        }
        s.push_str("* S̄ positive semi-definite, the modes linearly independent in M̄ and S̄.\n");
        let warnings: Vec<&String> = self.warnings.iter().chain(&r.warnings).collect();
        let advice = r.material.as_ref().and_then(|m| m.advice());
        if !warnings.is_empty() || advice.is_some() {
            s.push_str("\n## Warnings\n\n");
            for w in warnings {
                s.push_str(&format!("* {w}\n"));
            }
            if let Some(a) = advice {
                s.push_str(&format!("* {a}\n"));
            }
        }
        s.push_str("\n## Files\n\n");
        for f in &self.model_files {
            s.push_str(&format!("* read `{}`\n", f.display()));
        }
        for f in &self.output.written {
            s.push_str(&format!("* wrote `{}`\n", f.display()));
        }
        let t: Vec<String> = r
            .timings
            .iter()
            .map(|(k, v)| format!("{k} {v:.3} s"))
            .collect();
        s.push_str(&format!("\nTime: {}.\n", t.join(", ")));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interface_choices_parse_and_bad_ones_say_the_forms() {
        assert_eq!(
            InterfaceChoice::parse("left").unwrap(),
            InterfaceChoice::Set("left".into())
        );
        assert_eq!(
            InterfaceChoice::parse(" 7 ").unwrap(),
            InterfaceChoice::Set("7".into())
        );
        assert_eq!(
            InterfaceChoice::parse("plane:z=0.5").unwrap(),
            InterfaceChoice::Plane {
                point: [0.0, 0.0, 0.5],
                normal: [0.0, 0.0, 1.0]
            }
        );
        assert_eq!(
            InterfaceChoice::parse("plane:0,0,1,0,1,1").unwrap(),
            InterfaceChoice::Plane {
                point: [0.0, 0.0, 1.0],
                normal: [0.0, 1.0, 1.0]
            }
        );
        for bad in [
            "plane:w=1",
            "plane:z=",
            "plane:z=nan",
            "plane:1,2,3",
            "plane:0,0,0,0,0,0",
            "",
        ] {
            let e = InterfaceChoice::parse(bad).unwrap_err().to_string();
            assert!(e.contains("plane:") || e.contains("empty"), "{bad}: {e}");
        }
        assert!(check_name("flexure-1_a").is_ok());
        assert!(
            check_name("a b").is_err() && check_name("").is_err() && check_name("../x").is_err()
        );
    }
}
