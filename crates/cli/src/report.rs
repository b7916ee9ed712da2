//! What the commands write, shared by unreduced and reduced models: the time
//! response table (`outputs.csv`/`.svg`/`.png`, node paths), the eigenfrequency
//! sweep (`eigenfrequencies.csv`/`.svg`/`.png`) and progress bars.

use crate::out::say;
use crate::{finite, io_err, Failure};
use flexmb_dynamics::{Dynamics, OutputTable};
use flexmb_plot::{write_csv, Plot, Series};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;

/// `n` equidistant values from `from` to `to` (`from` alone when n = 1).
pub(crate) fn linspace(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            if n == 1 {
                from
            } else {
                from + (to - from) * i as f64 / (n - 1) as f64
            }
        })
        .collect()
}

/// A progress bar over `len` items: equilibria, then eigen analyses.
pub(crate) fn count_bar(len: u64, message: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    pb.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    pb.set_message(message.to_string());
    pb
}

/// A spinner with the elapsed time for a set-up phase of unknown length
/// (building a large mechanism: the DOF choice of 10⁵ coordinates takes
/// seconds), drawn on a terminal only and ticking on its own thread.
pub(crate) fn spinner(message: &str) -> ProgressBar {
    let pb = ProgressBar::new_spinner();
    pb.set_style(
        ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    pb.set_message(message.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// A progress bar over simulated time (per mille of the end time).
pub(crate) fn time_bar() -> ProgressBar {
    let pb = ProgressBar::new(1000);
    pb.set_style(
        ProgressStyle::with_template(
            "{bar:40} {percent:>3}% t = {msg} s, {elapsed} elapsed, ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    pb
}

/// A time response in the unreduced coordinates (a reduced one mapped by
/// q = G(z), q̇ = G,z ż) with the configuration x at each output, solved
/// along the run, and what it cost: the dynamics' trajectory.
pub(crate) use flexmb_dynamics::Trajectory as Response;

/// Output rows (t, then the scene's outputs), evaluated along the run.
pub(crate) type OutputRows = Vec<Vec<f64>>;

/// The line `flexmb simulate` prints: outputs, evaluations, steps, time.
pub(crate) fn summary(r: &Response) -> String {
    format!(
        "{} outputs to t = {:.4} s: {} function evaluations, {} steps ({} rejected), {:.2} s wall time",
        r.t.len(),
        r.t.last().copied().unwrap_or(0.0),
        r.stats.rhs_evals,
        r.stats.steps_accepted,
        r.stats.steps_rejected,
        r.wall_time
    ) + &match r.chart_switches.len() {
        0 => String::new(),
        n => format!(", {n} chart switches of free orientations (each a restart)"),
    } + &match r.partition_switches.len() {
        0 => String::new(),
        n => format!(", {n} changes of the dependent nodal coordinates (each a restart)"),
    }
}

/// Writes `out/outputs.csv` (the scene's outputs, or the DOFs, at each output
/// time, each from the configuration the run had there: `rows`, from
/// [`MechanicalModel::simulate_outputs`](flexmb_reduction::MechanicalModel::simulate_outputs)),
/// `out/outputs.svg` and `.png` (the first
/// twelve columns) and `out/path_N.svg` and `.png` for every node N whose x
/// and y are outputs.
pub(crate) fn write_outputs(
    dy: &Dynamics,
    rows: OutputRows,
    comments: &[String],
    out: &Path,
) -> Result<(), Failure> {
    std::fs::create_dir_all(out).map_err(|e| io_err(e, out))?;
    let table = OutputTable::new(dy).map_err(|e| Failure::Input(e.to_string()))?;
    let mut header = vec!["t".to_string()];
    header.extend(table.header.iter().cloned());
    finite::check_table("simulate outputs", &header, &rows)?;
    let csv = out.join("outputs.csv");
    write_csv(&csv, comments, &header, &rows).map_err(|e| io_err(e, &csv))?;
    let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let name = &dy.mechanism().name;
    let mut plot = Plot::new(&format!("{name} — outputs"), "t (s)", "value (SI)");
    for (k, h) in table.header.iter().enumerate().take(12) {
        let y: Vec<f64> = rows.iter().map(|r| r[k + 1]).collect();
        plot.push(Series::line(h, &t, &y));
    }
    let svg = out.join("outputs.svg");
    let (svg, png) = plot.save_both(&svg).map_err(|e| io_err(e, &svg))?;
    say!(
        "wrote {}, {} and {}",
        csv.display(),
        svg.display(),
        png.display()
    );
    // the path of every node whose position is an output (e.g. a manipulator tip)
    for (k, h) in table.header.iter().enumerate() {
        if let Some(node) = h.strip_suffix(".x") {
            if table.header.get(k + 1).map(|n| n.as_str()) == Some(&format!("{node}.y")) {
                let x: Vec<f64> = rows.iter().map(|r| r[k + 1]).collect();
                let y: Vec<f64> = rows.iter().map(|r| r[k + 2]).collect();
                let p = Plot::new(&format!("path of {node}"), "x (m)", "y (m)")
                    .series(Series::line(node, &x, &y));
                let f = out.join(format!("path_{node}.svg"));
                let (svg, png) = p.save_both(&f).map_err(|e| io_err(e, &f))?;
                say!("wrote {} and {}", svg.display(), png.display());
            }
        }
    }
    Ok(())
}

/// An eigenfrequency sweep: the parameter and the frequencies (Hz) at each
/// configuration.
pub(crate) struct FrequencySweep<'a> {
    /// Title of the plot (the mechanism or model).
    pub title: &'a str,
    /// The CSV column and plot axis of the parameter (`load_scale`,
    /// `S.x change`).
    pub parameter: String,
    /// The parameter values.
    pub s: Vec<f64>,
    /// The frequencies at each value (`modes` of them).
    pub frequencies: Vec<Vec<f64>>,
    /// Number of modes (columns).
    pub modes: usize,
    /// The held coordinates' names and, at each value, the generalized
    /// forces that hold them (a sweep over held coordinates; empty
    /// otherwise).
    pub holding: (Vec<String>, Vec<Vec<f64>>),
}

/// Writes `out/eigenfrequencies.csv` (the parameter, f1_hz … fk_hz, and
/// `hold:NAME` for each held coordinate: the force that holds it) and
/// `out/eigenfrequencies.svg` and `.png`, plus `out/holding_force.svg` and `.png` for a sweep over
/// held coordinates.
pub(crate) fn write_frequency_sweep(
    sw: &FrequencySweep,
    comments: &[String],
    out: &Path,
) -> Result<(), Failure> {
    for (s, f) in sw.s.iter().zip(&sw.frequencies) {
        finite::check("sweep", std::iter::once(*s).chain(f.iter().copied()), |i| {
            let at = format!("at {} = {s}", sw.parameter);
            match i {
                0 => format!("the sweep parameter {}", sw.parameter),
                i => format!("the eigenfrequency of mode {i} {at}"),
            }
        })?;
    }
    std::fs::create_dir_all(out).map_err(|e| io_err(e, out))?;
    let (held, forces) = &sw.holding;
    let mut header = vec![sw.parameter.clone()];
    header.extend((1..=sw.modes).map(|i| format!("f{i}_hz")));
    header.extend(held.iter().map(|h| format!("hold:{h}")));
    let rows: Vec<Vec<f64>> =
        sw.s.iter()
            .zip(&sw.frequencies)
            .enumerate()
            .map(|(r, (s, f))| {
                let hold = forces.get(r).into_iter().flatten().copied();
                std::iter::once(*s)
                    .chain((0..sw.modes).map(|i| f.get(i).copied().unwrap_or(f64::NAN)))
                    .chain(hold)
                    .collect()
            })
            .collect();
    let csv = out.join("eigenfrequencies.csv");
    write_csv(&csv, comments, &header, &rows).map_err(|e| io_err(e, &csv))?;
    let mut plot = Plot::new(
        &format!("{}: eigenfrequencies", sw.title),
        &sw.parameter,
        "frequency (Hz)",
    );
    for i in 0..sw.modes {
        let f: Vec<f64> = rows.iter().map(|r| r[i + 1]).collect();
        plot.push(Series::line(&format!("ω{}", i + 1), &sw.s, &f));
    }
    let svg = out.join("eigenfrequencies.svg");
    let (svg, png) = plot.save_both(&svg).map_err(|e| io_err(e, &svg))?;
    say!(
        "wrote {}, {} and {}",
        csv.display(),
        svg.display(),
        png.display()
    );
    if !held.is_empty() {
        let mut plot = Plot::new(
            &format!("{}: force holding the swept coordinates", sw.title),
            &sw.parameter,
            "generalized holding force (N, N m)",
        );
        for (k, h) in held.iter().enumerate() {
            let f: Vec<f64> = rows.iter().map(|r| r[1 + sw.modes + k]).collect();
            plot.push(Series::line(h, &sw.s, &f));
        }
        let svg = out.join("holding_force.svg");
        let (svg, png) = plot.save_both(&svg).map_err(|e| io_err(e, &svg))?;
        say!("wrote {} and {}", svg.display(), png.display());
    }
    Ok(())
}
