//! `flexmb build-superelement`: from a spec file, or in one command from a
//! mesh (`--mesh`, `flexmb_superelement::from_mesh`). The one-command form
//! writes the spec it built, the superelement, a scene stub with nodes P and
//! Q at p and q and the mode groups named, and the build report.

use crate::out::{errln, say};
use crate::Failure;
use clap::Args;
use flexmb_superelement::from_mesh::{
    build_from_mesh, InterfaceChoice, MeshBuild, MeshBuildOutput,
};
use flexmb_superelement::{Error, FeSolver, MeshMaterial};
use std::path::{Path, PathBuf};

/// Options of `flexmb build-superelement`.
#[derive(Args)]
pub(crate) struct SuperelementArgs {
    /// Specification file (RON); or build from a mesh with --mesh.
    #[arg(required_unless_present = "mesh", conflicts_with = "mesh")]
    spec: Option<PathBuf>,
    /// Build from this mesh: a gmsh .msh (ASCII 4.1 or 2.2), a gmsh .geo
    /// (meshed by gmsh with second-order elements) or an Abaqus/CalculiX
    /// .inp; needs --material and two --interface.
    #[arg(long, value_name = "PART.msh|PART.geo|PART.inp")]
    mesh: Option<PathBuf>,
    /// With --mesh: steel (the thesis's: E = 2.1e11 Pa, ν = 0.3125,
    /// ρ = 7800 kg/m³), aluminium, titanium, or E=…,nu=…,rho=… (SI).
    #[arg(long, requires = "mesh")]
    material: Option<String>,
    /// With --mesh, twice: p=… and q=…, each a gmsh physical surface (name
    /// or tag) or node set of the mesh, or a plane: plane:z=0 (also x, y)
    /// or plane:PX,PY,PZ,NX,NY,NZ. p and q go to the centroids of the
    /// interfaces.
    #[arg(long, value_name = "p=SURFACE|q=SURFACE", requires = "mesh")]
    interface: Vec<String>,
    /// With --mesh: fixed-interface normal modes.
    #[arg(
        long,
        default_value_t = 0,
        requires = "mesh",
        allow_negative_numbers = true
    )]
    normal_modes: usize,
    /// With --mesh: the warping modes (3.4) of both interfaces (each must be
    /// planar and normal to p → q).
    #[arg(long, requires = "mesh")]
    warping: bool,
    /// With --mesh: builtin (the built-in solid FE) or calculix (runs ccx).
    #[arg(long, default_value = "builtin", requires = "mesh")]
    solver: String,
    /// With --mesh: the part's name (files NAME.se.ron, NAME.scene.ron, …
    /// and the scene's element) [default: the mesh file's stem].
    #[arg(long, requires = "mesh")]
    name: Option<String>,
    /// With --mesh: the output directory.
    #[arg(long, default_value = "results/superelement", requires = "mesh")]
    out: PathBuf,
}

fn failure(e: Error) -> Failure {
    // errors in the input (files, options, a model that cannot be reduced,
    // gmsh or ccx missing or failing on the input) are exit code 2; a
    // failed solver or write is exit code 1
    if e.is_input() {
        Failure::Input(e.to_string())
    } else {
        Failure::Compute(e.to_string())
    }
}

/// `flexmb build-superelement`.
pub(crate) fn build_superelement(a: &SuperelementArgs) -> Result<(), Failure> {
    match (&a.spec, &a.mesh) {
        (Some(spec), _) => from_spec(spec),
        (None, Some(mesh)) => from_mesh(a, mesh),
        (None, None) => Err(Failure::Input(
            "give a spec file, or --mesh with --material and --interface p=… --interface q=…"
                .into(),
        )),
    }
}

fn from_spec(spec_path: &Path) -> Result<(), Failure> {
    let spec =
        flexmb_superelement::Spec::read(spec_path).map_err(|e| Failure::Input(e.to_string()))?;
    let base = spec_path.parent().unwrap_or(Path::new("."));
    let out = flexmb_superelement::build_from_spec(&spec, base).map_err(failure)?;
    say!("{}", out.result.summary(&spec.name).trim_end());
    for f in &out.written {
        say!("wrote {}", f.display());
    }
    Ok(())
}

/// `E=…,nu=…,rho=…` or a named material.
fn material(text: &str) -> Result<MeshMaterial, Failure> {
    if !text.contains('=') {
        return MeshMaterial::named(text).map_err(|e| Failure::Input(e.to_string()));
    }
    let (mut e, mut nu, mut rho) = (None, None, None);
    for part in text.split(',') {
        let bad = || {
            Failure::Input(format!(
                "--material {text}: '{part}' is not KEY=VALUE with KEY one of E, nu, rho (SI units)"
            ))
        };
        let (k, v) = part.split_once('=').ok_or_else(bad)?;
        let v: f64 = v.trim().parse().map_err(|_| bad())?;
        match k.trim().to_ascii_lowercase().as_str() {
            "e" => e = Some(v),
            "nu" | "ν" => nu = Some(v),
            "rho" | "ρ" => rho = Some(v),
            _ => return Err(bad()),
        }
    }
    match (e, nu, rho) {
        (Some(e), Some(nu), Some(rho)) => {
            let m = MeshMaterial { e, nu, rho };
            m.material().map_err(|e| Failure::Input(e.to_string()))?;
            Ok(m)
        }
        _ => Err(Failure::Input(format!(
            "--material {text}: give all of E, nu and rho (e.g. E=2.1e11,nu=0.3,rho=7800), or a name"
        ))),
    }
}

/// The two `--interface` options as (p, q).
fn interfaces(list: &[String]) -> Result<(InterfaceChoice, InterfaceChoice), Failure> {
    let mut p = None;
    let mut q = None;
    for item in list {
        let Some((side, what)) = item.split_once('=') else {
            return Err(Failure::Input(format!(
                "--interface {item}: write p=SURFACE or q=SURFACE (a physical surface, node set or plane:z=VALUE)"
            )));
        };
        let choice = InterfaceChoice::parse(what).map_err(|e| Failure::Input(e.to_string()))?;
        let slot = match side.trim() {
            "p" | "P" => &mut p,
            "q" | "Q" => &mut q,
            s => {
                return Err(Failure::Input(format!(
                    "--interface {item}: the side is p or q, not '{s}'"
                )))
            }
        };
        if slot.replace(choice).is_some() {
            return Err(Failure::Input(format!(
                "--interface {}= is given twice",
                side.trim()
            )));
        }
    }
    match (p, q) {
        (Some(p), Some(q)) => Ok((p, q)),
        (p, _) => Err(Failure::Input(format!(
            "--mesh needs --interface p=… and --interface q=…; {} is missing",
            if p.is_none() { "p" } else { "q" }
        ))),
    }
}

fn from_mesh(a: &SuperelementArgs, mesh: &Path) -> Result<(), Failure> {
    let Some(m) = &a.material else {
        return Err(Failure::Input(
            "--mesh needs --material (steel, aluminium, titanium, or E=…,nu=…,rho=…)".into(),
        ));
    };
    let material = material(m)?;
    let (p, q) = interfaces(&a.interface)?;
    let solver = match a.solver.to_ascii_lowercase().as_str() {
        "builtin" => FeSolver::Builtin,
        "calculix" | "ccx" => FeSolver::CalculiX,
        s => return Err(Failure::Input(format!("--solver {s}: builtin or calculix"))),
    };
    let name = match &a.name {
        Some(n) => n.clone(),
        None => mesh
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| "part".into()),
    };
    let req = MeshBuild {
        name,
        mesh: mesh.to_path_buf(),
        material,
        solver,
        p,
        q,
        warping: a.warping,
        normal_modes: a.normal_modes,
        out_dir: a.out.clone(),
    };
    let out = build_from_mesh(&req).map_err(failure)?;
    let stub = a.out.join(format!("{}.scene.ron", req.name));
    write(&stub, &scene_stub(&out))?;
    let report = a.out.join(format!("{}.report.md", req.name));
    write(&report, &out.report())?;
    for w in out
        .warnings
        .iter()
        .chain(&out.output.result.report.warnings)
    {
        errln(&format!("warning: {w}"));
    }
    say!("{}", out.report().trim_end());
    say!("wrote {}", stub.display());
    say!("wrote {}", report.display());
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<(), Failure> {
    std::fs::write(path, text)
        .map_err(|e| Failure::Compute(format!("cannot write {}: {e}", path.display())))
}

/// A scene with the part between nodes P and Q (at p and q), P clamped, the
/// mode groups named: loadable as it is (`flexmb info`, `flexmb eig` gives
/// the clamped–free frequencies of the report) and the start of a real one.
fn scene_stub(out: &MeshBuildOutput) -> String {
    let name = &out.request.name;
    let d = &out.output.result.data;
    let (kp, kq, kf) = d.mode_counts();
    let (p, q) = (out.spec.settings.p, out.spec.settings.q);
    let v = |x: [f64; 3]| format!("[{:?}, {:?}, {:?}]", x[0], x[1], x[2]);
    let group = |k: usize, g: String| {
        if k > 0 {
            format!("Some(\"{g}\")")
        } else {
            "None".into()
        }
    };
    let mut s = format!(
        "// Scene stub of the superelement '{name}', written by `flexmb build-superelement --mesh …`.\n\
         // P and Q are at the interface centroids p and q: the part keeps the frame it was built in\n\
         // (P → Q along [{:.6}, {:.6}, {:.6}]). Mode groups:\n",
        d.r0[0][0], d.r0[1][0], d.r0[2][0]
    );
    s.push_str(&format!(
        "//   {name}.p: {kp} warping mode(s) of interface p\n//   {name}.q: {kq} warping mode(s) of interface q\n\
         //   {name}.f: {kf} fixed-interface normal mode(s)\n\
         // Share an interface's group with a neighbour by naming it in `share`; fix a group with\n\
         // `fixed: [Modes(\"{name}.p\")]` (a clamped interface that cannot warp).\n\
         // P is clamped here (and its interface modes fixed: a clamped interface cannot warp):\n\
         // `flexmb eig` gives the clamped–free frequencies of {name}.report.md.\n"
    ));
    s.push_str(&format!(
        "(\n    name: \"{name} (stub)\",\n    dimension: Spatial,\n    nodes: [\n        (id: \"P\", at: {}),\n        \
         (id: \"Q\", at: {}),\n    ],\n    elements: [\n        (id: \"{name}\", type: Superelement(nodes: (\"P\", \"Q\"), \
         file: \"{name}.se.ron\", share: ({}, {}))),\n    ],\n    fixed: [Node(\"P\"){}],\n)\n",
        v(p),
        v(q),
        group(kp, format!("{name}.p")),
        group(kq, format!("{name}.q")),
        if kp > 0 { format!(", Modes(\"{name}.p\")") } else { String::new() }
    ));
    s
}
