//! `flexmb`: flexible multibody mechanisms from the command line.
//!
//! Exit codes: 0 success, 1 a computation failed, 2 invalid input (scene,
//! options), 130 interrupted (partial results are written).

use clap::{Parser, Subcommand};
use flexmb_dynamics::{
    Control, Dynamics, Integrator, OutputTable, SimulationOptions, StaticOptions,
};
use flexmb_model::Scene;
use flexmb_plot::{write_csv, Plot, Series};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "flexmb",
    version,
    about = "Flexible multibody dynamics and model reduction for compliant mechanisms",
    long_about = "Flexible multibody dynamics and model reduction for compliant mechanisms.\n\nScenes are RON files (see docs/scene-format.md); examples are in fixtures/scenes/.",
    after_help = "Examples:\n  flexmb info fixtures/scenes/straight_guidance_spatial.ron\n  flexmb static fixtures/scenes/straight_guidance_spatial.ron --out results/static\n  flexmb simulate fixtures/scenes/straight_guidance_planar.ron --t-end 0.5 --out results/sim\n  flexmb simulate fixtures/scenes/spin_up_planar.ron --t-end 20 --integrator adams --rtol 1e-6\n  flexmb build-superelement spec.ron"
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
    },
    /// Static equilibrium under the loads and gravity at t = --time.
    Static {
        /// Scene file (RON).
        scene: PathBuf,
        /// Time at which loads and inputs are evaluated.
        #[arg(long, default_value_t = 0.0)]
        time: f64,
        /// Initial number of load increments.
        #[arg(long, default_value_t = 1)]
        steps: usize,
        /// Output directory.
        #[arg(long, default_value = "results/static")]
        out: PathBuf,
    },
    /// Time response from the reference configuration (or from equilibrium with --static-first).
    Simulate {
        /// Scene file (RON).
        scene: PathBuf,
        /// End time (s).
        #[arg(long, default_value_t = 1.0)]
        t_end: f64,
        /// Number of output points.
        #[arg(long, default_value_t = 501)]
        outputs: usize,
        /// dopri5 (ode45-like), adams (Shampine–Gordon) or genalpha (implicit).
        #[arg(long, default_value = "dopri5")]
        integrator: String,
        /// Relative tolerance (ode45 default 1e-3).
        #[arg(long, default_value_t = 1e-3)]
        rtol: f64,
        /// Absolute tolerance (ode45 default 1e-6).
        #[arg(long, default_value_t = 1e-6)]
        atol: f64,
        /// Start from the static equilibrium at t = 0.
        #[arg(long)]
        static_first: bool,
        /// Output directory.
        #[arg(long, default_value = "results/simulate")]
        out: PathBuf,
    },
    /// Eigenfrequencies at the reference configuration or at the static equilibrium.
    Eig {
        /// Scene file (RON).
        scene: PathBuf,
        /// Number of modes.
        #[arg(long, default_value_t = 10)]
        modes: usize,
        /// Linearize at the static equilibrium under the scene's loads and gravity.
        #[arg(long)]
        static_first: bool,
        /// Also report buckling load factors of the current loads.
        #[arg(long)]
        buckling: bool,
    },
    /// Eigenfrequencies along the range of motion: over a load scale or a
    /// held coordinate, n equilibria, eigen analyses in parallel.
    Sweep {
        /// Scene file (RON).
        scene: PathBuf,
        /// `load` (scale the scene's loads) or a coordinate/deformation name
        /// such as `S.x` or `flexure1.3.bending_z_p` (`flexmb info` lists them);
        /// a coordinate is swept as its change from the reference configuration.
        #[arg(long)]
        over: String,
        /// First value of the sweep parameter.
        #[arg(long)]
        from: f64,
        /// Last value.
        #[arg(long)]
        to: f64,
        /// Number of configurations.
        #[arg(long, default_value_t = 50)]
        n: usize,
        /// Modes per configuration.
        #[arg(long, default_value_t = 6)]
        modes: usize,
        /// Output directory.
        #[arg(long, default_value = "results/sweep")]
        out: PathBuf,
    },
    /// Build a linear superelement from FE matrices (see crates/superelement/README.md).
    BuildSuperelement {
        /// Specification file (RON).
        spec: PathBuf,
    },
}

enum Failure {
    Input(String),
    Compute(String),
    Interrupted,
}

fn load(path: &Path) -> Result<(Scene, Arc<flexmb_model::Mechanism>), Failure> {
    let scene = Scene::load(path).map_err(|e| Failure::Input(e.to_string()))?;
    let mech = scene
        .build(path.parent())
        .map_err(|e| Failure::Input(e.to_string()))?;
    Ok((scene, Arc::new(mech)))
}

fn io_err(e: std::io::Error, what: &Path) -> Failure {
    Failure::Compute(format!("cannot write {}: {e}", what.display()))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let result = match cli.command {
        Command::Info { scene } => info(&scene),
        Command::Static {
            scene,
            time,
            steps,
            out,
        } => statics(&scene, time, steps, &out),
        Command::Simulate {
            scene,
            t_end,
            outputs,
            integrator,
            rtol,
            atol,
            static_first,
            out,
        } => simulate(
            &scene,
            t_end,
            outputs,
            &integrator,
            rtol,
            atol,
            static_first,
            &out,
            &interrupted,
        ),
        Command::Eig {
            scene,
            modes,
            static_first,
            buckling,
        } => eig(&scene, modes, static_first, buckling),
        Command::Sweep {
            scene,
            over,
            from,
            to,
            n,
            modes,
            out,
        } => sweep(&scene, &over, from, to, n, modes, &out),
        Command::BuildSuperelement { spec } => build_superelement(&spec),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(Failure::Compute(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
        Err(Failure::Interrupted) => {
            eprintln!("interrupted: partial results written");
            ExitCode::from(130)
        }
    }
}

fn info(path: &Path) -> Result<(), Failure> {
    let (_, mech) = load(path)?;
    println!("{}", mech.summary());
    println!("degrees of freedom:");
    for (k, c) in mech.dofs.iter().enumerate() {
        println!("  q{k:<3} {}", mech.coordinate_name(*c));
    }
    if !mech.inputs.is_empty() {
        println!("prescribed inputs:");
        for i in &mech.inputs {
            println!("  {}", mech.coordinate_name(i.target));
        }
    }
    Ok(())
}

fn statics(path: &Path, t: f64, steps: usize, out: &Path) -> Result<(), Failure> {
    let (_, mech) = load(path)?;
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: steps,
        ..Default::default()
    };
    let sol = dy
        .static_equilibrium(t, &mech.q0(), &opts)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    println!("{}", mech.summary());
    println!(
        "equilibrium found in {} Newton iterations, {} load increments",
        sol.iterations, sol.increments
    );
    std::fs::create_dir_all(out).map_err(|e| io_err(e, out))?;
    let mut kin = flexmb_kinematics::Kinematics::new(mech.clone());
    kin.solve(&sol.q, t)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let mut rows = vec![];
    for n in &mech.nodes {
        let d: Vec<String> = n
            .position
            .iter()
            .zip(&n.at)
            .map(|(i, a)| format!("{:+.6e}", kin.x()[*i] - a))
            .collect();
        println!("  {:<14} displacement [{}]", n.id, d.join(", "));
        rows.push(n.position.iter().map(|i| kin.x()[*i]).collect::<Vec<f64>>());
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
    let eps: Vec<Vec<f64>> = kin.eps().iter().map(|v| vec![*v]).collect();
    write_csv(
        &p,
        &[format!("rows: {}", mech.eps_names.join(" "))],
        &["epsilon".to_string()],
        &eps,
    )
    .map_err(|e| io_err(e, &p))?;
    println!("wrote {}", out.display());
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn simulate(
    path: &Path,
    t_end: f64,
    n_out: usize,
    integrator: &str,
    rtol: f64,
    atol: f64,
    static_first: bool,
    out: &Path,
    interrupted: &Arc<AtomicBool>,
) -> Result<(), Failure> {
    let integrator: Integrator = integrator.parse().map_err(Failure::Input)?;
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(Failure::Input(format!(
            "--t-end must be positive, got {t_end}"
        )));
    }
    if !(rtol > 0.0 && atol > 0.0) {
        return Err(Failure::Input("--rtol and --atol must be positive".into()));
    }
    let (_, mech) = load(path)?;
    let mut dy = Dynamics::new(mech.clone());
    let mut q0 = mech.q0();
    if static_first {
        q0 = dy
            .static_equilibrium(0.0, &q0, &StaticOptions::default())
            .map_err(|e| Failure::Compute(e.to_string()))?
            .q;
    }
    let qd0 = dy
        .initial_qd(0.0, &q0)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let mut opts = SimulationOptions::new(integrator, 0.0, t_end, n_out);
    opts.rtol = rtol;
    opts.atol = atol;
    println!("{}", mech.summary());
    let pb = ProgressBar::new(1000);
    pb.set_style(
        ProgressStyle::with_template(
            "{bar:40} {percent:>3}% t = {msg} s, {elapsed} elapsed, ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let flag = interrupted.clone();
    let result = dy.simulate(0.0, &q0, &qd0, &opts, |t, _, _| {
        pb.set_position((1000.0 * t / t_end) as u64);
        pb.set_message(format!("{t:.4}"));
        if flag.load(Ordering::SeqCst) {
            Control::Stop
        } else {
            Control::Continue
        }
    });
    pb.finish_and_clear();
    let traj = result.map_err(|e| Failure::Compute(e.to_string()))?;
    println!(
        "{} outputs to t = {:.4} s: {} function evaluations, {} steps ({} rejected), {:.2} s wall time",
        traj.t.len(),
        traj.t.last().copied().unwrap_or(0.0),
        traj.stats.rhs_evals,
        traj.stats.steps_accepted,
        traj.stats.steps_rejected,
        traj.wall_time
    );
    std::fs::create_dir_all(out).map_err(|e| io_err(e, out))?;
    let table = OutputTable::new(&dy).map_err(|e| Failure::Input(e.to_string()))?;
    let mut rows = vec![];
    for ((t, q), qd) in traj.t.iter().zip(&traj.q).zip(&traj.qd) {
        let mut r = vec![*t];
        r.extend(
            table
                .row(&mut dy, *t, q, qd)
                .map_err(|e| Failure::Compute(e.to_string()))?,
        );
        rows.push(r);
    }
    let mut header = vec!["t".to_string()];
    header.extend(table.header.iter().cloned());
    let csv = out.join("outputs.csv");
    let comments = vec![
        format!("flexmb simulate {}", path.display()),
        format!(
            "integrator {integrator:?}, rtol {rtol:e}, atol {atol:e}, {} function evaluations",
            traj.stats.rhs_evals
        ),
    ];
    write_csv(&csv, &comments, &header, &rows).map_err(|e| io_err(e, &csv))?;
    let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let mut plot = Plot::new(&format!("{} — outputs", mech.name), "t (s)", "value (SI)");
    for (k, h) in table.header.iter().enumerate().take(12) {
        let y: Vec<f64> = rows.iter().map(|r| r[k + 1]).collect();
        plot.push(Series::line(h, &t, &y));
    }
    let svg = out.join("outputs.svg");
    plot.save(&svg).map_err(|e| io_err(e, &svg))?;
    println!("wrote {} and {}", csv.display(), svg.display());
    // the path of every node whose position is an output (e.g. a manipulator tip)
    for (k, h) in table.header.iter().enumerate() {
        if let Some(node) = h.strip_suffix(".x") {
            if table.header.get(k + 1).map(|n| n.as_str()) == Some(&format!("{node}.y")) {
                let x: Vec<f64> = rows.iter().map(|r| r[k + 1]).collect();
                let y: Vec<f64> = rows.iter().map(|r| r[k + 2]).collect();
                let p = Plot::new(&format!("path of {node}"), "x (m)", "y (m)")
                    .series(Series::line(node, &x, &y));
                let f = out.join(format!("path_{node}.svg"));
                p.save(&f).map_err(|e| io_err(e, &f))?;
                println!("wrote {}", f.display());
            }
        }
    }
    if traj.stopped {
        return Err(Failure::Interrupted);
    }
    Ok(())
}

fn eig(path: &Path, k: usize, static_first: bool, buckling: bool) -> Result<(), Failure> {
    let (_, mech) = load(path)?;
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
    println!("{}", mech.summary());
    println!(
        "undamped eigenfrequencies (Hz){}:",
        if static_first {
            " at the static equilibrium"
        } else {
            " at the reference configuration"
        }
    );
    for (i, f) in modes.frequencies_hz().iter().enumerate() {
        println!("  {:>3}  {f:>14.6}", i + 1);
    }
    let has_damping = lin.d.col_iter().any(|c| c.iter().any(|v| *v != 0.0));
    if has_damping {
        let d =
            flexmb_linearize::damped_modes(&lin).map_err(|e| Failure::Compute(e.to_string()))?;
        println!("damped modes (frequency Hz, damping ratio):");
        for (i, m) in d.iter().take(k).enumerate() {
            println!(
                "  {:>3}  {:>14.6}  {:>8.4}",
                i + 1,
                m.frequency_hz,
                m.damping_ratio
            );
        }
    }
    if buckling {
        match flexmb_linearize::buckling_factors(&lin, 3.min(k)) {
            Ok(mu) => println!("buckling load factors: {mu:?}"),
            Err(e) => println!("buckling: {e}"),
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn sweep(
    path: &Path,
    over: &str,
    from: f64,
    to: f64,
    n: usize,
    k: usize,
    out: &Path,
) -> Result<(), Failure> {
    if n < 1 || !from.is_finite() || !to.is_finite() {
        return Err(Failure::Input(
            "--n must be ≥ 1 and --from/--to finite".into(),
        ));
    }
    let mut scene = Scene::load(path).map_err(|e| Failure::Input(e.to_string()))?;
    let values: Vec<f64> = (0..n)
        .map(|i| {
            if n == 1 {
                from
            } else {
                from + (to - from) * i as f64 / (n - 1) as f64
            }
        })
        .collect();
    let (mech, param) = if over == "load" {
        let mech = scene
            .build(path.parent())
            .map_err(|e| Failure::Input(e.to_string()))?;
        (Arc::new(mech), flexmb_linearize::SweepParameter::LoadScale)
    } else {
        // make the coordinate a degree of freedom, then hold it
        let probe = scene
            .build(path.parent())
            .map_err(|e| Failure::Input(e.to_string()))?;
        let select = if let Some(i) = probe.x_names.iter().position(|x| x == over) {
            let _ = i;
            let (node, comp) = over
                .rsplit_once('.')
                .ok_or_else(|| Failure::Input(format!("bad coordinate '{over}'")))?;
            let c = match comp {
                "x" => flexmb_model::Component::X,
                "y" => flexmb_model::Component::Y,
                "z" => flexmb_model::Component::Z,
                "angle" => flexmb_model::Component::Angle,
                l if l.starts_with('l') => flexmb_model::Component::Lambda(
                    l[1..]
                        .parse()
                        .map_err(|_| Failure::Input(format!("bad coordinate '{over}'")))?,
                ),
                _ => return Err(Failure::Input(format!("bad coordinate '{over}'"))),
            };
            flexmb_model::Select::Coord(node.to_string(), c)
        } else if let Some(j) = probe.eps_names.iter().position(|x| x == over) {
            let e = probe
                .elements
                .iter()
                .find(|e| e.eps_offset <= j && j < e.eps_offset + e.element.n_eps())
                .expect("owner");
            flexmb_model::Select::Def(
                e.id.clone(),
                e.element.deformation_names()[j - e.eps_offset].clone(),
            )
        } else {
            return Err(Failure::Input(format!("'{over}' is neither `load` nor a coordinate or deformation of the scene (see `flexmb info`)")));
        };
        scene.dofs_first.insert(0, select);
        let mech = Arc::new(
            scene
                .build(path.parent())
                .map_err(|e| Failure::Input(e.to_string()))?,
        );
        let k = mech
            .dofs
            .iter()
            .position(|c| mech.coordinate_name(*c) == over)
            .expect("first DOF");
        // the sweep parameter is the change from the reference configuration
        let q_ref = mech.q0()[k];
        let param = flexmb_linearize::SweepParameter::Path {
            dofs: vec![k],
            path: Box::new(move |s| vec![q_ref + s]),
        };
        (mech, param)
    };
    println!("{}", mech.summary());
    let pb = ProgressBar::new(2 * n as u64);
    pb.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    pb.set_message("equilibria, then eigen analyses");
    let start = std::time::Instant::now();
    let opts = flexmb_linearize::SweepOptions {
        values,
        modes: k,
        t: 0.0,
        keep_vectors: false,
    };
    let pts = flexmb_linearize::sweep(&mech, &param, &opts, &|d, _| pb.set_position(d as u64))
        .map_err(|e| Failure::Compute(e.to_string()))?;
    pb.finish_and_clear();
    let wall = start.elapsed().as_secs_f64();
    println!("{n} configurations, {k} modes each, in {wall:.2} s");
    std::fs::create_dir_all(out).map_err(|e| io_err(e, out))?;
    let mut header = vec![if over == "load" {
        "load_scale".to_string()
    } else {
        format!("{over} change")
    }];
    header.extend((1..=k).map(|i| format!("f{i}_hz")));
    let rows: Vec<Vec<f64>> = pts
        .iter()
        .map(|p| {
            std::iter::once(p.s)
                .chain(p.frequencies_hz.iter().copied())
                .collect()
        })
        .collect();
    let csv = out.join("eigenfrequencies.csv");
    write_csv(
        &csv,
        &[
            format!(
                "flexmb sweep {} --over {over} --from {from} --to {to} --n {n} --modes {k}",
                path.display()
            ),
            "undamped eigenfrequencies at static equilibria (rest linearization, thesis (E.6))"
                .into(),
        ],
        &header,
        &rows,
    )
    .map_err(|e| io_err(e, &csv))?;
    let mut plot = Plot::new(
        &format!("{}: eigenfrequencies", mech.name),
        over,
        "frequency (Hz)",
    );
    let s: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    for i in 0..k {
        let f: Vec<f64> = rows
            .iter()
            .map(|r| r.get(i + 1).copied().unwrap_or(f64::NAN))
            .collect();
        plot.push(Series::line(&format!("ω{}", i + 1), &s, &f));
    }
    let svg = out.join("eigenfrequencies.svg");
    plot.save(&svg).map_err(|e| io_err(e, &svg))?;
    println!("wrote {} and {}", csv.display(), svg.display());
    Ok(())
}

fn build_superelement(spec_path: &Path) -> Result<(), Failure> {
    let spec =
        flexmb_superelement::Spec::read(spec_path).map_err(|e| Failure::Input(e.to_string()))?;
    let base = spec_path.parent().unwrap_or(Path::new("."));
    let out = flexmb_superelement::build_from_spec(&spec, base)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    println!("{:#?}", out.result.report);
    for f in &out.written {
        println!("wrote {}", f.display());
    }
    Ok(())
}
