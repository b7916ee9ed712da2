//! `flexmb`: flexible multibody mechanisms from the command line.
//!
//! Exit codes: 0 success, 1 a computation failed, 2 invalid input (scene,
//! model, options out of range, an output location that cannot be written),
//! 130 interrupted by SIGINT (Ctrl-C), 143 by SIGTERM: `simulate` and
//! `sweep` write their partial results first, the other commands have none
//! and exit at once; a second signal exits at once (see [`interrupt`]). A
//! closed standard output (`flexmb info SCENE | head -1`) is no error: the
//! rest of the printout is dropped and the exit code is unchanged (see
//! [`out`]).
#![deny(clippy::print_stdout, clippy::print_stderr)]

mod coords;
mod draw;
mod finite;
mod interrupt;
mod options;
mod out;
mod path;
mod reduce;
mod reduced;
mod report;
mod superelement;
mod vtk_out;

use clap::{Args, Parser, Subcommand};
use flexmb_dynamics::{
    Control, Dynamics, Integrator, OutputTable, SimulationOptions, StaticOptions,
};
use flexmb_model::Scene;
use flexmb_plot::write_csv;
use flexmb_reduction::MechanicalModel;
use out::{errln, say};
use report::{
    count_bar, linspace, time_bar, write_frequency_sweep, write_outputs, FrequencySweep,
    OutputRows, Response,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "flexmb",
    version,
    about = "Flexible multibody dynamics and model reduction for compliant mechanisms",
    long_about = "Flexible multibody dynamics and model reduction for compliant mechanisms.\n\nScenes are RON files (see docs/scene-format.md); examples are in fixtures/scenes/.",
    after_help = "Examples:\n  flexmb info fixtures/scenes/straight_guidance_spatial.ron\n  flexmb static fixtures/scenes/straight_guidance_spatial.ron --out results/static\n  flexmb simulate fixtures/scenes/straight_guidance_planar.ron --t-end 0.5 --out results/sim\n  flexmb simulate fixtures/scenes/spin_up_planar.ron --t-end 20 --integrator adams --rtol 1e-6\n  flexmb reduce fixtures/scenes/straight_guidance_planar.ron --method modal --modes 3 --out modal3.ron\n  flexmb simulate fixtures/scenes/straight_guidance_planar.ron --reduced modal3.ron --t-end 0.5\n  flexmb build-superelement spec.ron\n  flexmb build-superelement --mesh part.geo --material steel --interface p=left --interface q=plane:x=0.1 --out results/part"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Show the assembled mechanism: sizes, degrees of freedom, inputs.
    Info {
        /// Scene file (RON).
        scene: PathBuf,
        /// Instead, diagnose the constraints at the reference configuration:
        /// each over-constraint as a loop of elements with its equations,
        /// weights and direction, each under-constraint as the coordinates
        /// of its mode (works on scenes whose build fails for being over-
        /// or under-constrained).
        #[arg(long)]
        constraints: bool,
    },
    /// Static equilibrium under the loads and gravity at t = --time.
    Static {
        /// Scene file (RON).
        scene: PathBuf,
        /// Time at which loads and inputs are evaluated.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        time: f64,
        /// Number of equal load increments (each halved while its Newton
        /// iteration fails), at least 1.
        #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
        steps: usize,
        /// Output directory.
        #[arg(long, default_value = "results/static")]
        out: PathBuf,
        /// Also write the equilibrium as VTK (static.pvd and a VTU file) to
        /// this directory.
        #[arg(long, value_name = "DIR")]
        vtk: Option<PathBuf>,
        /// How --vtk draws superelements and beams.
        #[command(flatten)]
        vtk_style: vtk_out::VtkStyle,
    },
    /// Time response from the reference configuration (or from equilibrium with --static-first).
    Simulate(SimulateArgs),
    /// Eigenfrequencies at the reference configuration or at the static equilibrium.
    Eig {
        /// Scene file (RON).
        scene: PathBuf,
        /// Number of modes, at least 1 [default: 10, or every degree of
        /// freedom if there are fewer].
        #[arg(long, allow_negative_numbers = true)]
        modes: Option<usize>,
        /// Linearize at the static equilibrium under the scene's loads and gravity.
        #[arg(long)]
        static_first: bool,
        /// Also report buckling load factors of the current loads.
        #[arg(long)]
        buckling: bool,
        /// Also write the configuration (eig.pvd, modes as point data
        /// mode_1, …) and each mode as an animated series over one period
        /// (mode_K.pvd) as VTK to this directory.
        #[arg(long, value_name = "DIR")]
        vtk: Option<PathBuf>,
        /// How --vtk draws superelements and beams.
        #[command(flatten)]
        vtk_style: vtk_out::VtkStyle,
    },
    /// Eigenfrequencies along the range of motion: over a load scale or a
    /// held coordinate, n equilibria, eigen analyses in parallel.
    Sweep(SweepArgs),
    /// Build a reduced model (fixed or interpolated basis) of a scene and save
    /// it for `simulate --reduced` and `sweep --reduced` (see docs/cli.md).
    Reduce(reduce::ReduceArgs),
    /// Draw the mechanism (reference, static equilibrium or a state) and its
    /// mode shapes as SVG or PNG (see docs/cli.md).
    Draw(draw::DrawArgs),
    /// Build a linear superelement: from FE matrices named in a spec file
    /// (see crates/superelement/README.md), or in one command from a mesh
    /// (--mesh, see docs/superelement.md).
    #[command(
        override_usage = "flexmb build-superelement SPEC.ron\n       flexmb build-superelement --mesh PART.msh|PART.geo|PART.inp --material M --interface p=… --interface q=… [OPTIONS]"
    )]
    BuildSuperelement(superelement::SuperelementArgs),
}

/// Options of `flexmb simulate`.
#[derive(Args)]
struct SimulateArgs {
    /// Scene file (RON).
    scene: PathBuf,
    /// End time (s), positive.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    t_end: f64,
    /// Number of output points, at least 2 (t = 0 and --t-end).
    #[arg(long, default_value_t = 501, allow_negative_numbers = true)]
    outputs: usize,
    /// dopri5 (ode45-like), adams (Shampine–Gordon) or genalpha (implicit;
    /// unreduced models only).
    #[arg(long, default_value = "dopri5")]
    integrator: String,
    /// Relative tolerance, positive (ode45 default 1e-3).
    #[arg(long, default_value_t = 1e-3, allow_hyphen_values = true)]
    rtol: f64,
    /// Absolute tolerance, positive (ode45 default 1e-6).
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    atol: f64,
    /// Start from the static equilibrium at t = 0.
    #[arg(long)]
    static_first: bool,
    /// Integrate this reduced model of the scene (written by `flexmb reduce`)
    /// instead of all degrees of freedom; explicit integrators only.
    #[arg(long, value_name = "MODEL.ron")]
    reduced: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "results/simulate")]
    out: PathBuf,
    /// Also write the configuration at every output time as VTK
    /// (simulate.pvd and one VTU file per output) to this directory.
    #[arg(long, value_name = "DIR")]
    vtk: Option<PathBuf>,
    /// How --vtk draws superelements and beams.
    #[command(flatten)]
    vtk_style: vtk_out::VtkStyle,
}

/// Options of `flexmb sweep`.
#[derive(Args)]
struct SweepArgs {
    /// Scene file (RON).
    scene: PathBuf,
    /// `load` (scale the scene's loads), a coordinate/deformation name such
    /// as `S.x` or `flexure1.3.bending_z_p` (`flexmb info` lists them; swept
    /// as its change from the reference configuration), or `path` (several
    /// coordinates along the path of --path, s from --from to --to).
    /// With --reduced: `load` only.
    #[arg(long)]
    over: String,
    /// First value of the sweep parameter.
    #[arg(long, allow_hyphen_values = true)]
    from: f64,
    /// Last value (not --from).
    #[arg(long, allow_hyphen_values = true)]
    to: f64,
    /// Number of configurations, at least 2 (--from and --to).
    #[arg(long, default_value_t = 50, allow_negative_numbers = true)]
    n: usize,
    /// Modes per configuration, at least 1 [default: 6, or every degree of
    /// freedom if there are fewer].
    #[arg(long, allow_negative_numbers = true)]
    modes: Option<usize>,
    /// Time at which the scene's loads are evaluated (a load sweep scales
    /// them: pick a time where they act, e.g. the peak of a pulse).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    t_load: f64,
    /// With `--over path`: a CSV file `s,NAME,...` giving each coordinate's
    /// change from the reference configuration as a function of s (linear
    /// between rows); the path P(s) of thesis (4.1).
    #[arg(long, value_name = "PATH.csv")]
    path: Option<PathBuf>,
    /// Sweep this reduced model of the scene (written by `flexmb reduce`):
    /// reduced static equilibria by continuation from load scale 0, reduced
    /// eigenfrequencies (F.7) at each.
    #[arg(long, value_name = "MODEL.ron")]
    reduced: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "results/sweep")]
    out: PathBuf,
    /// Also write the equilibrium at every sweep point as VTK (sweep.pvd,
    /// the sweep parameter as time, the modes as point data mode_1, …) to
    /// this directory.
    #[arg(long, value_name = "DIR")]
    vtk: Option<PathBuf>,
    /// How --vtk draws superelements and beams.
    #[command(flatten)]
    vtk_style: vtk_out::VtkStyle,
}

/// Why a command failed, which decides the exit code.
enum Failure {
    /// Invalid input: scene, model or options (exit code 2).
    Input(String),
    /// A computation failed (exit code 1).
    Compute(String),
    /// Stopped by SIGINT or SIGTERM (exit code 130 or 143); says what was
    /// written.
    Interrupted(String),
}

/// Reads a scene and builds its mechanism.
fn load(path: &Path) -> Result<(Scene, Arc<flexmb_model::Mechanism>), Failure> {
    let scene = Scene::load(path).map_err(|e| Failure::Input(e.to_string()))?;
    let mech = build(&scene, path)?;
    Ok((scene, Arc::new(mech)))
}

/// Builds the mechanism of `scene` (read from `path`), with a spinner that
/// names the stage while it takes (the elements and the DOF choice of a
/// large model), and on stderr the stages that took more than a second.
fn build(scene: &Scene, path: &Path) -> Result<flexmb_model::Mechanism, Failure> {
    let spinner = report::spinner("building the mechanism");
    let mut stage: Option<(flexmb_model::BuildStage, std::time::Instant)> = None;
    let mut done = |next: Option<flexmb_model::BuildStage>| {
        if let Some((s, t)) = stage.take() {
            let dt = t.elapsed().as_secs_f64();
            if dt > 1.0 {
                spinner.suspend(|| errln(&format!("{} took {dt:.1} s", s.describe())));
            }
        }
        if let Some(s) = next {
            spinner.set_message(format!("building the mechanism: {}", s.describe()));
            stage = Some((s, std::time::Instant::now()));
        }
    };
    let mech = scene.build_reporting(path.parent(), &mut |s| done(Some(s)));
    done(None);
    spinner.finish_and_clear();
    mech.map_err(|e| match e {
        // a numerical failure on a valid scene, not bad input
        flexmb_model::ModelError::Computation { .. } => Failure::Compute(e.to_string()),
        flexmb_model::ModelError::OverConstrained { .. }
        | flexmb_model::ModelError::UnderConstrained { .. } => Failure::Input(format!(
            "{e}\n(`flexmb info --constraints {}` names each over-constraint's loop and direction, and each undetermined motion)",
            path.display()
        )),
        _ => Failure::Input(e.to_string()),
    })
}

/// A failed write.
fn io_err(e: std::io::Error, what: &Path) -> Failure {
    Failure::Compute(format!("cannot write {}: {e}", what.display()))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = interrupt::grace_from_env() {
        return exit_code(Err(Failure::Input(e)));
    }
    if let Err(e) = interrupt::install() {
        errln(&format!(
            "warning: cannot handle SIGINT and SIGTERM ({e}): a signal ends the run without partial results"
        ));
    }
    let result = run(cli.command);
    exit_code(result)
}

/// Runs a command.
fn run(command: Command) -> Result<(), Failure> {
    match command {
        Command::Info { scene, constraints } => {
            if constraints {
                info_constraints(&scene)
            } else {
                info(&scene)
            }
        }
        Command::Static {
            scene,
            time,
            steps,
            out,
            vtk,
            vtk_style,
        } => statics(
            &scene,
            time,
            steps,
            &out,
            vtk.as_deref().map(|d| vtk_out::VtkOut::new(d, vtk_style)),
        ),
        Command::Simulate(a) => simulate(&a),
        Command::Eig {
            scene,
            modes,
            static_first,
            buckling,
            vtk,
            vtk_style,
        } => eig(
            &scene,
            modes,
            static_first,
            buckling,
            vtk.as_deref().map(|d| vtk_out::VtkOut::new(d, vtk_style)),
        ),
        Command::Sweep(a) => sweep(&a),
        Command::Reduce(a) => reduce::reduce(&a),
        Command::Draw(a) => draw::draw(&a),
        Command::BuildSuperelement(a) => superelement::build_superelement(&a),
    }
}

/// Reports the outcome of a command on stderr and gives its exit code (see
/// the crate documentation). A signal that came while complete results were
/// written still gives its own code.
fn exit_code(result: Result<(), Failure>) -> ExitCode {
    let (code, message) = match result {
        Ok(()) => match interrupt::exit_code() {
            Some(c) => (c, interrupt::report("the results are complete")),
            None => return ExitCode::SUCCESS,
        },
        Err(Failure::Input(m)) => (2, format!("error: {m}")),
        Err(Failure::Compute(m)) => (1, format!("error: {m}")),
        Err(Failure::Interrupted(what)) => (
            interrupt::exit_code().unwrap_or(130),
            interrupt::report(&what),
        ),
    };
    errln(&message);
    ExitCode::from(code)
}

/// `flexmb info`: the mechanism's summary, degrees of freedom and inputs.
fn info(path: &Path) -> Result<(), Failure> {
    let (_, mech) = load(path)?;
    say!("{}", mech.summary());
    say!("degrees of freedom:");
    for (k, c) in mech.dofs.iter().enumerate() {
        say!("  q{k:<3} {}", mech.coordinate_name(*c));
    }
    if !mech.inputs.is_empty() {
        say!("prescribed inputs:");
        for i in &mech.inputs {
            say!("  {}", mech.coordinate_name(i.target));
        }
    }
    Ok(())
}

/// `flexmb info --constraints`: the over- and under-constraints of a scene
/// ([`flexmb_model::ConstraintDiagnosis`]); exits 0 whatever it finds.
fn info_constraints(path: &Path) -> Result<(), Failure> {
    let scene = Scene::load(path).map_err(|e| Failure::Input(e.to_string()))?;
    let start = std::time::Instant::now();
    let d = scene
        .diagnose_constraints(path.parent())
        .map_err(|e| match e {
            flexmb_model::ModelError::Computation { .. } => Failure::Compute(e.to_string()),
            _ => Failure::Input(e.to_string()),
        })?;
    say!("{d}");
    say!("diagnosed in {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}

/// `flexmb static`: the equilibrium at time `t` in `steps` load increments,
/// written to `out`.
fn statics(
    path: &Path,
    t: f64,
    steps: usize,
    out: &Path,
    vtk: Option<vtk_out::VtkOut<'_>>,
) -> Result<(), Failure> {
    options::finite("--time", t)?;
    options::at_least("--steps", steps, 1, "the number of load increments")?;
    let (_, mech) = load(path)?;
    options::writable_dir("--out", out)?;
    if let Some(v) = vtk {
        options::writable_dir("--vtk", v.dir)?;
    }
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: steps,
        ..Default::default()
    };
    let sol = dy
        .static_equilibrium(t, &mech.q0(), &opts)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    // the configuration the solver converged to (solving x = F(q) again from
    // the reference configuration can fail or land on another branch),
    // checked before anything is printed or written
    let what = "static equilibrium";
    finite::check(what, sol.x.iter().copied(), |i| mech.x_names[i].clone())?;
    finite::check(what, sol.eps.iter().copied(), |j| mech.eps_names[j].clone())?;
    say!("{}", mech.summary());
    say!(
        "equilibrium found in {} Newton iterations, {} load increments",
        sol.iterations,
        sol.increments
    );
    std::fs::create_dir_all(out).map_err(|e| io_err(e, out))?;
    let mut rows = vec![];
    for n in &mech.nodes {
        let d: Vec<String> = n
            .position
            .iter()
            .zip(&n.at)
            .map(|(i, a)| format!("{:+.6e}", sol.x[*i] - a))
            .collect();
        say!("  {:<14} displacement [{}]", n.id, d.join(", "));
        rows.push(n.position.iter().map(|i| sol.x[*i]).collect::<Vec<f64>>());
    }
    let dim = mech.nodes.first().map_or(3, |n| n.position.len());
    let header: Vec<String> = ["x", "y", "z"]
        .iter()
        .take(dim)
        .map(|s| s.to_string())
        .collect();
    let p = out.join("node_positions.csv");
    let names: Vec<String> = mech.nodes.iter().map(|n| n.id.clone()).collect();
    write_csv(
        &p,
        &[
            format!("static equilibrium of {}", path.display()),
            format!("rows: nodes {}", names.join(" ")),
        ],
        &header,
        &rows,
    )
    .map_err(|e| io_err(e, &p))?;
    let p = out.join("deformations.csv");
    let eps: Vec<Vec<f64>> = sol.eps.iter().map(|v| vec![*v]).collect();
    write_csv(
        &p,
        &[format!("rows: {}", mech.eps_names.join(" "))],
        &["epsilon".to_string()],
        &eps,
    )
    .map_err(|e| io_err(e, &p))?;
    say!("wrote {}", out.display());
    if let Some(d) = vtk {
        vtk_out::write(d, "static", &mech, &[(t, &sol.x)])?;
    }
    Ok(())
}

/// `flexmb simulate`: the scene's time response, unreduced or with a reduced
/// model, written by [`write_outputs`].
fn simulate(a: &SimulateArgs) -> Result<(), Failure> {
    let integrator: Integrator = a.integrator.parse().map_err(Failure::Input)?;
    options::positive("--t-end", a.t_end)?;
    options::at_least(
        "--outputs",
        a.outputs,
        2,
        "the output points include t = 0 and --t-end",
    )?;
    options::positive("--rtol", a.rtol)?;
    options::positive("--atol", a.atol)?;
    let (_, mech) = load(&a.scene)?;
    options::writable_dir("--out", &a.out)?;
    if let Some(d) = &a.vtk {
        options::writable_dir("--vtk", d)?;
    }
    let mut opts = SimulationOptions::new(integrator, 0.0, a.t_end, a.outputs);
    opts.rtol = a.rtol;
    opts.atol = a.atol;
    opts.stop = Some(interrupt::stop_flag());
    let pb = time_bar();
    let t_end = a.t_end;
    let observer = |t: f64| {
        pb.set_position((1000.0 * t / t_end) as u64);
        pb.set_message(format!("{t:.4}"));
        Control::Continue
    };
    let (mut model, description, configuration) = match &a.reduced {
        None => {
            say!("{}", mech.summary());
            let dy: Box<dyn MechanicalModel> = Box::new(Dynamics::new(mech.clone()));
            (dy, None, 0)
        }
        Some(file) => {
            let (model, d, configuration) = reduced::model_to_simulate(&mech, file, &opts)?;
            (model, Some(d), configuration)
        }
    };
    let c0 = start_state(model.as_mut(), a.static_first, configuration)?;
    let result = simulate_model(model.as_mut(), &c0, &opts, observer);
    pb.finish_and_clear();
    let (response, rows) = result?;
    say!("{}", report::summary(&response));
    let mut comments = vec![format!("flexmb simulate {}", a.scene.display())];
    if let (Some(m), Some(d)) = (&a.reduced, &description) {
        comments.push(format!("reduced model {}: {d}", m.display()));
    }
    comments.push(format!(
        "integrator {integrator:?}, rtol {:e}, atol {:e}, {} function evaluations",
        a.rtol, a.atol, response.stats.rhs_evals
    ));
    let partial = response.stopped.then(|| stopped_run(&response, &opts));
    if let Some(p) = &partial {
        comments.push(format!("interrupted: {p}"));
    }
    write_outputs(model.dynamics(), rows, &comments, &a.out)?;
    if let Some(d) = &a.vtk {
        if response.x.len() != response.t.len() {
            return Err(Failure::Compute(format!(
                "--vtk: the run recorded nodal coordinates at {} of its {} outputs",
                response.x.len(),
                response.t.len()
            )));
        }
        // the nodal coordinates the integrator reached at each output
        let frames: Vec<(f64, &[f64])> = response
            .t
            .iter()
            .zip(&response.x)
            .map(|(t, x)| (*t, x.as_slice()))
            .collect();
        vtk_out::write(
            vtk_out::VtkOut::new(d, a.vtk_style),
            "simulate",
            &mech,
            &frames,
        )?;
    }
    match partial {
        Some(p) => Err(Failure::Interrupted(format!(
            "partial results written: {p}"
        ))),
        None => Ok(()),
    }
}

/// What a stopped run has: the output times reached, and the row at the
/// step where it stopped.
fn stopped_run(r: &Response, opts: &SimulationOptions) -> String {
    let last = r.t.last().copied().unwrap_or(0.0);
    let reached = opts.output_times.iter().filter(|t| **t <= last).count();
    let n = opts.output_times.len();
    if opts.output_times.contains(&last) {
        format!("{reached} of {n} output times, to t = {last:.6} s")
    } else {
        format!(
            "{reached} of {n} output times, then the state where the run stopped, t = {last:.6} s"
        )
    }
}

/// The coordinates a run starts from: the model's reference coordinates, or
/// with `static_first` its static equilibrium under the loads and gravity at
/// t = 0 ([`MechanicalModel::equilibrium_under_loads`]); the loads at full
/// scale. A reduced model with `configuration` > 0 configuration
/// coordinates (interpolated: s; grid: s1, s2) says where it starts.
fn start_state(
    model: &mut dyn MechanicalModel,
    static_first: bool,
    configuration: usize,
) -> Result<Vec<f64>, Failure> {
    let c0 = if static_first {
        let what = if model.is_reduced() {
            "reduced static equilibrium: "
        } else {
            ""
        };
        model
            .equilibrium_under_loads(0.0)
            .map_err(|e| Failure::Compute(format!("{what}{e}")))?
            .coordinates
    } else {
        model.reference_coordinates()
    };
    model.set_load_scale(1.0);
    if configuration > 0 {
        let names = ["s", "(s1, s2)"];
        let values: Vec<String> = c0[..configuration.min(2)]
            .iter()
            .map(|v| format!("{v:.6e}"))
            .collect();
        say!(
            "initial {} = {} ({})",
            names[configuration.min(2) - 1],
            if configuration == 1 {
                values[0].clone()
            } else {
                format!("({})", values.join(", "))
            },
            if static_first {
                "static equilibrium"
            } else {
                "the knot nearest to the scene's reference configuration"
            }
        );
    }
    Ok(c0)
}

/// Integrates `model` (all degrees of freedom or a reduced model) from the
/// coordinates `c0` with the scene's initial velocities
/// ([`MechanicalModel::initial_velocities`]), recording the scene's outputs
/// at each output time (t first).
fn simulate_model(
    model: &mut dyn MechanicalModel,
    c0: &[f64],
    opts: &SimulationOptions,
    mut observer: impl FnMut(f64) -> Control,
) -> Result<(Response, OutputRows), Failure> {
    let compute = |e: flexmb_reduction::ReductionError| Failure::Compute(e.to_string());
    let cd0 = model.initial_velocities(0.0, c0).map_err(compute)?;
    let table = OutputTable::new(model.dynamics()).map_err(|e| Failure::Input(e.to_string()))?;
    let phase = interrupt::stoppable();
    let run = model.simulate_outputs(0.0, c0, &cd0, opts, &table, &mut observer);
    phase.finish();
    let (traj, rows) = run.map_err(compute)?;
    let rows = traj
        .full
        .t
        .iter()
        .zip(rows)
        .map(|(t, r)| std::iter::once(*t).chain(r).collect())
        .collect();
    Ok((traj.full, rows))
}

/// `flexmb eig`: the first `k` eigenfrequencies at the reference
/// configuration or the static equilibrium, damped modes and buckling.
fn eig(
    path: &Path,
    modes: Option<usize>,
    static_first: bool,
    buckling: bool,
    vtk: Option<vtk_out::VtkOut<'_>>,
) -> Result<(), Failure> {
    if let Some(k) = modes {
        options::at_least("--modes", k, 1, "the number of modes")?;
    }
    let (_, mech) = load(path)?;
    if let Some(v) = vtk {
        options::writable_dir("--vtk", v.dir)?;
    }
    let k = options::modes_or_default(modes, 10, &mech)?;
    let mut dy = Dynamics::new(mech.clone());
    let mut q = mech.q0();
    if static_first {
        q = dy
            .static_equilibrium(0.0, &q, &StaticOptions::default())
            .map_err(|e| Failure::Compute(e.to_string()))?
            .q;
    }
    let lin = dy
        .linearize_at_rest(0.0, &q)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let modes =
        flexmb_linearize::undamped_modes(&lin, k).map_err(|e| Failure::Compute(e.to_string()))?;
    let at = if static_first {
        " at the static equilibrium"
    } else {
        " at the reference configuration"
    };
    let frequencies = modes.frequencies_hz();
    finite::check(&format!("eig{at}"), frequencies.iter().copied(), |i| {
        format!("the undamped eigenfrequency of mode {}", i + 1)
    })?;
    say!("{}", mech.summary());
    say!("undamped eigenfrequencies (Hz){at}:");
    for (i, f) in frequencies.iter().enumerate() {
        say!("  {:>3}  {f:>14.6}", i + 1);
    }
    let has_damping = lin.d.col_iter().any(|c| c.iter().any(|v| *v != 0.0));
    if has_damping {
        let d =
            flexmb_linearize::damped_modes(&lin).map_err(|e| Failure::Compute(e.to_string()))?;
        let values = d
            .iter()
            .take(k)
            .flat_map(|m| [m.frequency_hz, m.damping_ratio]);
        finite::check(&format!("eig{at}"), values, |i| {
            let what = ["frequency", "damping ratio"][i % 2];
            format!("the {what} of damped mode {}", i / 2 + 1)
        })?;
        say!("damped modes (frequency Hz, damping ratio):");
        for (i, m) in d.iter().take(k).enumerate() {
            say!(
                "  {:>3}  {:>14.6}  {:>8.4}",
                i + 1,
                m.frequency_hz,
                m.damping_ratio
            );
        }
    }
    if buckling {
        match flexmb_linearize::buckling_factors(&lin, 3.min(k)) {
            Ok(mu) => {
                finite::check(&format!("eig{at}"), mu.iter().copied(), |i| {
                    format!("buckling load factor {}", i + 1)
                })?;
                say!("buckling load factors: {mu:?}")
            }
            Err(e) => say!("buckling: {e}"),
        }
    }
    if let Some(d) = vtk {
        let (x, shapes) = vtk_out::nodal_modes(&mut dy, 0.0, &q, &modes.vectors)?;
        vtk_out::write_eig(d, &mech, 0.0, &x, &shapes, &frequencies)?;
    }
    Ok(())
}

/// `flexmb sweep`: eigenfrequencies at static equilibria along a load scale
/// or a held coordinate (unreduced), or along a load scale (reduced model).
fn sweep(a: &SweepArgs) -> Result<(), Failure> {
    let (over, n) = (a.over.as_str(), a.n);
    check_sweep_options(a)?;
    let values = linspace(a.from, a.to, n);
    if let Some(model) = &a.reduced {
        return reduced::sweep(a, model, &values);
    }
    let path = a.scene.as_path();
    let mut scene = Scene::load(path).map_err(|e| Failure::Input(e.to_string()))?;
    if a.path.is_some() && over != "path" {
        return Err(Failure::Input("--path needs `--over path`".into()));
    }
    let (mech, param) = if over == "load" {
        let mech = build(&scene, path)?;
        (Arc::new(mech), flexmb_linearize::SweepParameter::LoadScale)
    } else if over == "path" {
        let file = a
            .path
            .as_ref()
            .ok_or_else(|| Failure::Input("`--over path` needs --path PATH.csv".into()))?;
        let p = crate::path::TabulatedPath::read(file)?;
        let (lo, hi) = p.range();
        if a.from.min(a.to) < lo || a.from.max(a.to) > hi {
            return Err(Failure::Input(format!(
                "--from {} --to {} leaves the path's range of s [{lo}, {hi}] in {}",
                a.from,
                a.to,
                file.display()
            )));
        }
        let (mech, ks) = p.mechanism(&mut scene, path.parent())?;
        let q_ref: Vec<f64> = ks.iter().map(|k| mech.q0()[*k]).collect();
        let param = flexmb_linearize::SweepParameter::Path {
            dofs: ks,
            path: Box::new(move |s| p.at(s).iter().zip(&q_ref).map(|(d, r)| r + d).collect()),
        };
        (Arc::new(mech), param)
    } else {
        // make the coordinate a degree of freedom, then hold it
        let probe = build(&scene, path)?;
        let select = coords::selection(&probe, over)?.ok_or_else(|| {
            Failure::Input(format!("'{over}' is neither `load` nor a coordinate or deformation of the scene (see `flexmb info`)"))
        })?;
        scene.dofs_first.insert(0, select);
        let mech = Arc::new(build(&scene, path)?);
        let k = coords::dof_index(&mech, over, "--over")?;
        // the sweep parameter is the change from the reference configuration
        let q_ref = mech.q0()[k];
        let param = flexmb_linearize::SweepParameter::Path {
            dofs: vec![k],
            path: Box::new(move |s| vec![q_ref + s]),
        };
        (mech, param)
    };
    let k = options::modes_or_default(a.modes, 6, &mech)?;
    options::writable_dir("--out", &a.out)?;
    if let Some(d) = &a.vtk {
        options::writable_dir("--vtk", d)?;
    }
    say!("{}", mech.summary());
    let pb = count_bar(2 * n as u64, "equilibria, then eigen analyses");
    let start = std::time::Instant::now();
    let opts = flexmb_linearize::SweepOptions {
        values,
        modes: k,
        t: a.t_load,
        keep_vectors: a.vtk.is_some(),
    };
    let phase = interrupt::stoppable();
    let outcome = flexmb_linearize::sweep_until(
        &mech,
        &param,
        &opts,
        &|d, _| pb.set_position(d as u64),
        Some(&interrupt::stop_flag()),
    );
    phase.finish();
    pb.finish_and_clear();
    let outcome = outcome.map_err(|e| Failure::Compute(e.to_string()))?;
    if outcome.stopped && outcome.points.is_empty() {
        return Err(Failure::Interrupted(if outcome.equilibria < n {
            format!(
                "nothing written: stopped while finding the equilibria ({} of {n} found), before any eigen analysis",
                outcome.equilibria
            )
        } else {
            format!(
                "nothing written: stopped in the first eigen analyses (all {n} equilibria found, no eigen analysis finished)"
            )
        }));
    }
    let pts = outcome.points;
    let wall = start.elapsed().as_secs_f64();
    say!(
        "{} configurations, {k} modes each, in {wall:.2} s{}",
        pts.len(),
        match outcome.chart_switches.len() {
            0 => String::new(),
            c => format!(", {c} chart switches of free orientations on the way"),
        } + &match outcome.partition_switches.len() {
            0 => String::new(),
            c => format!(", {c} changes of the dependent nodal coordinates on the way"),
        }
    );
    let sw = FrequencySweep {
        title: &mech.name,
        parameter: sweep_parameter_name(over),
        s: pts.iter().map(|p| p.s).collect(),
        frequencies: pts.iter().map(|p| p.frequencies_hz.clone()).collect(),
        modes: k,
        holding: (
            held_names(&mech, &param),
            pts.iter().map(|p| p.holding.clone()).collect(),
        ),
    };
    let mut comments = vec![
        sweep_command_line(a),
        "undamped eigenfrequencies at static equilibria (rest linearization, thesis (E.6))".into(),
    ];
    let done = sw.s.len();
    if outcome.stopped {
        comments.push(format!("interrupted: {done} of {n} configurations"));
    }
    write_frequency_sweep(&sw, &comments, &a.out)?;
    if let Some(d) = &a.vtk {
        vtk_out::write_sweep_points(vtk_out::VtkOut::new(d, a.vtk_style), &mech, a.t_load, &pts)?;
    }
    if outcome.stopped {
        return Err(Failure::Interrupted(format!(
            "partial results written: {done} of {n} configurations"
        )));
    }
    Ok(())
}

/// The ranges of `flexmb sweep`'s options, unreduced or reduced, and its
/// output directory.
fn check_sweep_options(a: &SweepArgs) -> Result<(), Failure> {
    options::at_least(
        "--n",
        a.n,
        2,
        "the number of configurations, from --from to --to",
    )?;
    if let Some(k) = a.modes {
        options::at_least("--modes", k, 1, "the modes per configuration")?;
    }
    options::finite("--from", a.from)?;
    options::finite("--to", a.to)?;
    options::finite("--t-load", a.t_load)?;
    options::distinct_ends(a.from, a.to)
}

/// The CSV column of a sweep parameter: `load_scale` or `NAME change`.
fn sweep_parameter_name(over: &str) -> String {
    if over == "load" {
        "load_scale".to_string()
    } else if over == "path" {
        "s".to_string()
    } else {
        format!("{over} change")
    }
}

/// The names of the coordinates a sweep holds (none for a load sweep).
fn held_names(
    mech: &flexmb_model::Mechanism,
    param: &flexmb_linearize::SweepParameter,
) -> Vec<String> {
    use flexmb_linearize::SweepParameter;
    let dofs: &[usize] = match param {
        SweepParameter::LoadScale => &[],
        SweepParameter::Dof(k) => std::slice::from_ref(k),
        SweepParameter::Path { dofs, .. } => dofs,
    };
    dofs.iter()
        .map(|k| mech.coordinate_name(mech.dofs[*k]).to_string())
        .collect()
}

/// The command line of a sweep, for the CSV header.
fn sweep_command_line(a: &SweepArgs) -> String {
    let reduced = a
        .reduced
        .as_ref()
        .map(|m| format!(" --reduced {}", m.display()))
        .unwrap_or_default();
    let modes = a.modes.map(|k| format!(" --modes {k}")).unwrap_or_default();
    format!(
        "flexmb sweep {}{reduced} --over {} --from {} --to {} --n {}{modes} --t-load {}",
        a.scene.display(),
        a.over,
        a.from,
        a.to,
        a.n,
        a.t_load
    )
}
