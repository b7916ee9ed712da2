//! The RON specification behind `flexmb build-superelement SPEC.ron`: where the
//! FE model comes from, the build settings and where to write the result.
//!
//! ```ron
//! (
//!     name: "flexure",
//!     model: CalculiX(job: "flexure"),
//!     settings: (
//!         p: (0.0, 0.0, 0.0),
//!         q: (0.04, 0.0, 0.0),
//!         interface_p: NearPlane(point: (0.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-7),
//!         interface_q: NearPlane(point: (0.04, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-7),
//!         warping_p: true,
//!         warping_q: true,
//!         normal_modes: 2,
//!     ),
//!     output: "flexure.se.ron",
//! )
//! ```

use crate::abaqus::read_abaqus;
use crate::ansys::{read_ansys, AnsysFiles};
use crate::builder::{build, BuildResult, BuildSettings};
use crate::mesh_file::{run_calculix, MeshFile, MeshMaterial};
use crate::model::{FeModel, ReferenceMass};
use crate::readers::{
    read_calculix, read_matrix_market_model, write_file, write_matrix_market_dense,
};
use crate::units::{UnitSystem, UNIT_SYSTEMS};
use crate::Error;
use flexmb_element::LinearSuperelement;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Where the FE model comes from. Paths are relative to the spec's directory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ModelSource {
    /// A solid mesh with one material, its stiffness and mass computed by
    /// the built-in FE or by CalculiX (module [`crate::mesh_file`]): a gmsh
    /// `.msh` (ASCII 4.1 or 2.2), a gmsh `.geo` (meshed by `gmsh` with
    /// second-order elements into `OUTPUT.msh`, next to the output), or an
    /// Abaqus/CalculiX `.inp`. Its gmsh physical groups and *NSET are node
    /// sets for [`crate::NodeSelection::Set`]. `units` scales the mesh's
    /// coordinates only (the material is SI).
    Mesh {
        /// The mesh file.
        file: String,
        /// The material of every element (SI).
        material: MeshMaterial,
        /// The solver (default the built-in FE).
        #[serde(default)]
        solver: FeSolver,
    },
    /// CalculiX exports `JOB.sti`, `JOB.mas`, `JOB.dof` and the mesh `inp`
    /// (default `JOB.inp`).
    CalculiX {
        /// The job path without extension.
        job: String,
        /// The mesh file, if not `JOB.inp`.
        #[serde(default)]
        inp: Option<String>,
        /// A uniform density (kg/m³) for the rigid-body check of the mass
        /// matrix against the mesh; replaces the deck's *DENSITY.
        #[serde(default)]
        density: Option<f64>,
    },
    /// Matrix Market K and M with a node file and an optional DOF file.
    MatrixMarket {
        /// Stiffness file.
        k: String,
        /// Mass file.
        m: String,
        /// Node file (`label x y z`).
        nodes: String,
        /// DOF file (`node.dir` per equation); default 3 DOFs per node.
        #[serde(default)]
        dofs: Option<String>,
        /// Mesh volume (m³) for the units check, if known.
        #[serde(default)]
        volume: Option<f64>,
        /// A uniform density (kg/m³): M's rigid-body mass must then be
        /// `volume` × `density` (needs `volume`).
        #[serde(default)]
        density: Option<f64>,
    },
    /// Abaqus `*MATRIX OUTPUT` files (`FORMAT=COORDINATE`, `MATRIX INPUT` or
    /// `LABELS`) with the deck for the nodes, elements and densities
    /// (module [`crate::abaqus`]).
    Abaqus {
        /// The `.inp` deck.
        inp: String,
        /// The stiffness file (`JOB_STIF1.mtx`).
        k: String,
        /// The mass file (`JOB_MASS1.mtx`).
        m: String,
        /// A uniform density (kg/m³) for the rigid-body check of M; replaces
        /// the deck's *DENSITY.
        #[serde(default)]
        density: Option<f64>,
    },
    /// ANSYS exports: APDL Math MMF or `HBMAT` Harwell–Boeing K and M, the
    /// DOF-mapping vector or `.mapping` file, the nodal coordinates and
    /// optionally the element list (module [`crate::ansys`]).
    Ansys {
        /// Stiffness file.
        k: String,
        /// Mass file.
        m: String,
        /// The equation → node map.
        mapping: String,
        /// Nodal coordinates (decimal point or comma).
        nodes: String,
        /// Element listing, for the volume and the sparsity check.
        #[serde(default)]
        elements: Option<String>,
        /// A uniform density (kg/m³) for the rigid-body check of M (needs
        /// `elements`).
        #[serde(default)]
        density: Option<f64>,
    },
}

/// The FE solver of a [`ModelSource::Mesh`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FeSolver {
    /// The built-in solid FE ([`crate::solid::SolidMesh::assemble`]; with
    /// CalculiX's quadrature, so the two agree to rounding).
    #[default]
    Builtin,
    /// CalculiX: a deck written and `ccx` run next to the output
    /// ([`crate::mesh_file::run_calculix`]).
    CalculiX,
}

/// A build specification.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// A name for the part.
    pub name: String,
    /// The FE model.
    pub model: ModelSource,
    /// The unit system of the FE files: "SI" (default), "mm-t-s",
    /// "mm-kg-ms" or "mm-kg-s" ([`crate::units::UNIT_SYSTEMS`]).
    #[serde(default)]
    pub units: Option<String>,
    /// A factor on the stiffness after the units (e.g. 1e-2 for K exported
    /// with E = 2.1e11 from a model meant to have 2.1e9).
    #[serde(default)]
    pub stiffness_scale: Option<f64>,
    /// A factor on the mass after the units.
    #[serde(default)]
    pub mass_scale: Option<f64>,
    /// What to build.
    pub settings: BuildSettings,
    /// The RON file to write the superelement to (relative to the spec's directory).
    pub output: String,
    /// Also write M̄ as a Matrix Market array file (for large M̄).
    #[serde(default)]
    pub m_bar_matrix_market: Option<String>,
}

impl Spec {
    /// Parses a RON spec.
    pub fn from_ron(text: &str, file: &str) -> Result<Self, Error> {
        flexmb_input::from_ron(text)
            .map_err(|e| Error::parse(file, e.line, format!("column {}: {}", e.column, e.message)))
    }
    /// Reads a RON spec file.
    pub fn read(path: &Path) -> Result<Self, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_ron(&text, &path.display().to_string())
    }
}

/// What [`build_from_spec`] produced.
#[derive(Clone, Debug)]
pub struct BuildOutput {
    /// The build result.
    pub result: BuildResult,
    /// Files written.
    pub written: Vec<PathBuf>,
}

/// 64-bit FNV-1a hash of a byte string (provenance of source files).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn source_entry(path: &Path) -> Result<String, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    Ok(format!(
        "{} ({} bytes, fnv1a64 {:016x})",
        path.file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default(),
        bytes.len(),
        fnv1a64(&bytes)
    ))
}

/// The factors (length, stiffness, mass) that take the spec's FE files to
/// SI (`units`, `stiffness_scale`, `mass_scale`).
pub fn si_factors(spec: &Spec) -> Result<(f64, f64, f64), Error> {
    let u = match &spec.units {
        Some(name) => UnitSystem::named(name)?,
        None => UNIT_SYSTEMS[0],
    };
    Ok(u.to_si(
        spec.stiffness_scale.unwrap_or(1.0),
        spec.mass_scale.unwrap_or(1.0),
    ))
}

/// The path of the output without its extension (`DIR/part` for
/// `DIR/part.se.ron`): work files of a [`ModelSource::Mesh`] are named after it.
pub fn output_stem(spec: &Spec, base_dir: &Path) -> PathBuf {
    let out = base_dir.join(&spec.output);
    let name = out
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let stem = name
        .strip_suffix(".se.ron")
        .or_else(|| name.strip_suffix(".ron"))
        .unwrap_or(&name)
        .to_string();
    out.with_file_name(if stem.is_empty() { "part".into() } else { stem })
}

/// Loads the model a spec names, in SI (see [`si_factors`]).
pub fn load_model(spec: &Spec, base_dir: &Path) -> Result<(FeModel, Vec<PathBuf>), Error> {
    let (l, k, m) = si_factors(spec)?;
    let rescale = |model: &mut FeModel| model.rescale(l, k, m);
    Ok(match &spec.model {
        ModelSource::Mesh {
            file,
            material,
            solver,
        } => {
            let path = base_dir.join(file);
            let stem = output_stem(spec, base_dir);
            let mut mesh = MeshFile::read(&path, &stem.with_extension("msh"))?;
            let unit = match &spec.units {
                Some(name) => UnitSystem::named(name)?,
                None => UNIT_SYSTEMS[0],
            };
            for c in &mut mesh.coords {
                for x in c.iter_mut() {
                    *x *= unit.length;
                }
            }
            let (mut model, mut files) = match solver {
                FeSolver::Builtin => {
                    let mut model = mesh.solid_mesh(material.material()?).assemble(
                        &spec.name,
                        &format!("the material's density {} kg/m³", material.rho),
                    )?;
                    model.node_sets = mesh.node_sets(&model);
                    model.sources.mesh = file.clone();
                    (model, Vec::new())
                }
                FeSolver::CalculiX => {
                    let job_name = stem
                        .file_name()
                        .map(|s| s.to_string_lossy().to_string())
                        .unwrap_or_default();
                    let job = stem
                        .with_file_name(format!("{job_name}_ccx"))
                        .join(&job_name);
                    let (mut model, files) =
                        run_calculix(&mesh, material, &job, &format!("{} from {file}", spec.name))?;
                    model.name = spec.name.clone();
                    (model, files)
                }
            };
            model.rescale(
                1.0,
                spec.stiffness_scale.unwrap_or(1.0),
                spec.mass_scale.unwrap_or(1.0),
            )?;
            // the mesh file (and the .msh meshed from a .geo) first
            let mut all = mesh.files.clone();
            all.append(&mut files);
            (model, all)
        }
        ModelSource::CalculiX { job, inp, density } => {
            let job = base_dir.join(job);
            let inp = inp.as_ref().map(|p| base_dir.join(p));
            let (mut model, mesh) = read_calculix(&job, inp.as_deref())?;
            model.name = spec.name.clone();
            rescale(&mut model)?;
            override_density(&mut model, *density)?;
            // the .inp and everything it *INCLUDEs
            let files = ["sti", "mas", "dof"]
                .iter()
                .map(|e| job.with_extension(e))
                .chain(mesh.files)
                .collect();
            (model, files)
        }
        ModelSource::MatrixMarket {
            k,
            m,
            nodes,
            dofs,
            volume,
            density,
        } => {
            let (k, m, nodes) = (base_dir.join(k), base_dir.join(m), base_dir.join(nodes));
            let dofs = dofs.as_ref().map(|d| base_dir.join(d));
            let mut model = read_matrix_market_model(&spec.name, &k, &m, &nodes, dofs.as_deref())?;
            rescale(&mut model)?;
            // the spec's volume and density are SI
            model.volume = *volume;
            if let Some(rho) = check_density(*density)? {
                let v = volume.ok_or_else(|| {
                    Error::Spec(format!(
                        "model: MatrixMarket has density: Some({rho}) but no volume; the density is only used \
                         with the volume (mass = volume × density)"
                    ))
                })?;
                model.reference_mass = Some(ReferenceMass {
                    mass: rho * v,
                    what: format!("the spec's volume {v:e} m³ × density {rho} kg/m³"),
                });
            }
            let mut files = vec![k, m, nodes];
            files.extend(dofs);
            (model, files)
        }
        ModelSource::Abaqus { inp, k, m, density } => {
            let (inp, k, m) = (base_dir.join(inp), base_dir.join(k), base_dir.join(m));
            let (mut model, mesh) = read_abaqus(&inp, &k, &m)?;
            model.name = spec.name.clone();
            rescale(&mut model)?;
            override_density(&mut model, *density)?;
            let files = [k, m].into_iter().chain(mesh.files).collect();
            (model, files)
        }
        ModelSource::Ansys {
            k,
            m,
            mapping,
            nodes,
            elements,
            density,
        } => {
            let paths = [k, m, mapping, nodes].map(|p| base_dir.join(p));
            let elements = elements.as_ref().map(|e| base_dir.join(e));
            let files = AnsysFiles {
                k: &paths[0],
                m: &paths[1],
                mapping: &paths[2],
                nodes: &paths[3],
                elements: elements.as_deref(),
            };
            let mut model = read_ansys(&spec.name, files)?;
            rescale(&mut model)?;
            if density.is_some() && model.solid.is_none() {
                return Err(Error::Spec(
                    "model: Ansys has a density but no elements; the density is checked against the elements' \
                     volume"
                        .into(),
                ));
            }
            override_density(&mut model, *density)?;
            let mut files: Vec<PathBuf> = paths.into();
            files.extend(elements);
            (model, files)
        }
    })
}

/// Replaces the element densities by the spec's `density` (kg/m³), if given.
fn override_density(model: &mut FeModel, density: Option<f64>) -> Result<(), Error> {
    if let Some(rho) = check_density(density)? {
        if let Some(solid) = &mut model.solid {
            solid.density = vec![Some(rho); solid.density.len()];
            solid.density_source = format!("the spec's density {rho} kg/m³");
        }
    }
    Ok(())
}

/// A spec's density, which must be positive and finite if given.
fn check_density(density: Option<f64>) -> Result<Option<f64>, Error> {
    match density {
        Some(rho) if !(rho > 0.0 && rho.is_finite()) => Err(Error::Spec(format!(
            "model: density = {rho}; a density must be positive and finite (kg/m³)"
        ))),
        d => Ok(d),
    }
}

/// Writes superelement data as RON.
pub fn write_ron(path: &Path, data: &LinearSuperelement) -> Result<(), Error> {
    let s = ron::ser::to_string_pretty(data, ron::ser::PrettyConfig::default())
        .map_err(|e| Error::Spec(format!("cannot serialize the superelement: {e}")))?;
    write_file(path, &s)
}

/// Reads superelement data from RON.
pub fn read_ron(path: &Path) -> Result<LinearSuperelement, Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    flexmb_input::from_ron(&text).map_err(|e| {
        Error::parse(
            &path.display().to_string(),
            e.line,
            format!("column {}: {}", e.column, e.message),
        )
    })
}

/// Loads the model, builds the superelement, records the provenance (source
/// files with their FNV-1a hashes, the settings) and writes the RON output (and
/// M̄ as Matrix Market if asked). Paths are relative to `base_dir`.
pub fn build_from_spec(spec: &Spec, base_dir: &Path) -> Result<BuildOutput, Error> {
    let (model, files) = load_model(spec, base_dir)?;
    build_loaded(spec, base_dir, &model, &files)
}

/// [`build_from_spec`] on a model already loaded by [`load_model`] from
/// `files`.
pub fn build_loaded(
    spec: &Spec,
    base_dir: &Path,
    model: &FeModel,
    files: &[PathBuf],
) -> Result<BuildOutput, Error> {
    let mut result = build(model, &spec.settings)?;
    let mut sources = Vec::new();
    for f in files {
        sources.push(source_entry(f)?);
    }
    sources.append(&mut result.data.provenance.sources);
    result.data.provenance.sources = sources;
    let settings_ron = ron::ser::to_string(&spec.settings)
        .map_err(|e| Error::Spec(format!("cannot serialize the settings: {e}")))?;
    result
        .data
        .provenance
        .settings
        .push(format!("spec settings: {settings_ron}"));
    let mut written = Vec::new();
    let out = base_dir.join(&spec.output);
    write_ron(&out, &result.data)?;
    written.push(out);
    if let Some(mm) = &spec.m_bar_matrix_market {
        let p = base_dir.join(mm);
        write_matrix_market_dense(&p, &result.data.m_bar_matrix())?;
        written.push(p);
    }
    Ok(BuildOutput { result, written })
}
