//! `cargo xtask reproduce ch7xy`: writes `results/ch7xy/` for the
//! two-coordinate interpolated basis of [`crate::ch7xy`] (beyond the
//! thesis, issue 18): the curse of dimensionality measured (ω1–ω8 of grid
//! models of 2 × 2 … n × n references against the unreduced model at
//! check points off the grids), and the closed loop of the finest grid
//! model on a path the one-coordinate models were not built for.

use crate::ch7;
use crate::ch7xy::{self, OffCentreCircle};
use crate::curves::StoredCurve;
use crate::models::CurvePoint;
use crate::progress::Progress;
use crate::report::{pct, sig, Figures, Table};
use crate::reproduce7::{
    closed_loop_pair, median_and_max, reference_end_effector, tracking_figures, Run,
};
use flexmb_linearize::SweepPoint;
use flexmb_model::Mechanism;
use flexmb_plot::{Plot, Series};
use flexmb_reduction::GridBasis;
use std::fmt::Write;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Options of the two-coordinate study.
#[derive(Clone, Debug)]
pub struct XyOptions {
    /// Grid lines of the finest grid (n − 1 a power of two: the coarser
    /// grids 2, 3, 5, … are its sub-grids).
    pub finest: usize,
    /// Check points over the workspace (Halton).
    pub checks: usize,
    /// Check points on the path (4.1).
    pub path_checks: usize,
    /// Points along the off-centre circle for its frequencies.
    pub circle_points: usize,
    /// Run the closed loop on the off-centre circle.
    pub closed_loop: bool,
}

impl Default for XyOptions {
    fn default() -> Self {
        Self {
            finest: 17,
            checks: 32,
            path_checks: 12,
            circle_points: 16,
            closed_loop: true,
        }
    }
}

/// One grid model and its frequencies at the check points.
pub struct GridModel {
    /// Grid lines per coordinate (n × n references).
    pub n: usize,
    /// Whether Q is the Hermite interpolant with the equilibrium surface's
    /// tangents ([`ch7xy::grid_tangents`]), else the natural spline.
    pub tangents: bool,
    /// Its basis.
    pub basis: GridBasis,
    /// The basis's wall time (s), the references' sweep not included.
    pub seconds: f64,
    /// ω1–ω8 at the workspace check points, the path check points, and the
    /// grid's cell centres (when the finest grid holds them).
    pub at_checks: Vec<Vec<f64>>,
    /// At the path check points.
    pub at_path: Vec<Vec<f64>>,
    /// At the cell centres, with the index of their unreduced equilibria in
    /// the finest grid.
    pub at_centres: Vec<(usize, Vec<f64>)>,
}

/// Everything the study computes.
pub struct XyResults {
    /// The mechanism (no gravity, no controllers) and its x, y DOFs.
    pub mech: Arc<Mechanism>,
    /// The end-effector's x and y DOFs.
    pub dofs: [usize; 2],
    /// The equilibria of the finest grid (grid order).
    pub grid: Vec<SweepPoint>,
    /// Their sweep's wall time (s).
    pub sweep_seconds: f64,
    /// The workspace check points' equilibria.
    pub checks: Vec<SweepPoint>,
    /// The path check points' equilibria.
    pub path: Vec<SweepPoint>,
    /// The grid models, coarsest first.
    pub models: Vec<GridModel>,
    /// The unreduced equilibria along the off-centre circle, and the
    /// finest model's frequencies there.
    pub circle: Vec<SweepPoint>,
    /// The finest grid model's ω1–ω8 along the circle.
    pub circle_reduced: Vec<Vec<f64>>,
    /// The closed loops on the circle (from the undeflected configuration,
    /// from the gravity equilibrium), the reference end-effector path and
    /// s(t) at the output times.
    pub runs: Vec<Run>,
    /// The reference end-effector (x, y, z) at the outputs.
    pub reference: Vec<[f64; 3]>,
    /// Why the closed loop failed, if it did.
    pub closed_loop_error: Option<String>,
}

/// The grid sizes studied: 2, 3, 5, 9, … up to `finest` (each a sub-grid
/// of the next).
pub fn grid_sizes(finest: usize) -> Vec<usize> {
    let mut out = vec![];
    let mut n = finest;
    while n >= 2 {
        out.push(n);
        if n == 2 {
            break;
        }
        n = (n - 1) / 2 + 1;
    }
    out.reverse();
    out
}

/// The Halton check points ordered for a continuation: by rows of an 8 × 8
/// binning of the workspace, every other row backwards.
fn ordered_checks(count: usize) -> Vec<[f64; 2]> {
    let mut p = ch7xy::halton_points(count);
    let bin = |v: f64| ((v + ch7xy::HALF_WIDTH) / (2.0 * ch7xy::HALF_WIDTH) * 8.0).floor() as i64;
    p.sort_by(|a, b| {
        let (ra, rb) = (bin(a[1]), bin(b[1]));
        ra.cmp(&rb).then_with(|| {
            let c = a[0].total_cmp(&b[0]);
            if ra % 2 == 0 {
                c
            } else {
                c.reverse()
            }
        })
    });
    p
}

/// The relative error of each of the first `count` modes at each point.
pub fn errors(full: &[SweepPoint], reduced: &[Vec<f64>], k: usize) -> Vec<f64> {
    full.iter()
        .zip(reduced)
        .map(|(p, r)| ((r[k] - p.frequencies_hz[k]) / p.frequencies_hz[k]).abs())
        .collect()
}

/// The largest of `e` (0 if empty).
fn worst(e: &[f64]) -> f64 {
    e.iter().copied().fold(0.0, f64::max)
}

impl GridModel {
    /// "5 × 5" or "5 × 5 + tangents".
    pub fn label(&self) -> String {
        let t = if self.tangents { " + tangents" } else { "" };
        format!("{0} × {0}{t}", self.n)
    }

    /// The largest relative error of mode k over the workspace and path
    /// check points and the cell centres.
    pub fn worst_error(&self, r: &XyResults, k: usize) -> f64 {
        let centres: Vec<SweepPoint> = self
            .at_centres
            .iter()
            .map(|(i, _)| r.grid[*i].clone())
            .collect();
        let c: Vec<Vec<f64>> = self.at_centres.iter().map(|(_, f)| f.clone()).collect();
        worst(&errors(&r.checks, &self.at_checks, k))
            .max(worst(&errors(&r.path, &self.at_path, k)))
            .max(worst(&errors(&centres, &c, k)))
    }
}

/// The indices in the finest grid (n_f lines) of the cell centres of the
/// n × n sub-grid, if the finest grid holds them.
fn centre_indices(n_f: usize, n: usize) -> Vec<usize> {
    let step = (n_f - 1) / (n - 1);
    if step < 2 {
        return vec![];
    }
    let h = step / 2;
    (0..(n - 1) * (n - 1))
        .map(|k| {
            let (i, j) = (k % (n - 1), k / (n - 1));
            (i * step + h) + n_f * (j * step + h)
        })
        .collect()
}

/// Computes the study (`o`), with progress on `pg`.
pub fn compute(root: &Path, o: &XyOptions, pg: &Progress) -> Result<XyResults, String> {
    let (mech, dofs) = ch7::mechanism(root, false, None)?;
    let nf = o.finest;
    let total = nf * nf + o.checks + o.path_checks;
    let bar = pg.bar(
        &format!("ch7xy: {nf} × {nf} grid and check equilibria"),
        2 * total as u64,
    );
    let t = Instant::now();
    let grid = ch7xy::grid_equilibria(&mech, dofs, nf, ch7::R, &|d, _| bar.set(d as u64))?;
    let sweep_seconds = t.elapsed().as_secs_f64();
    let done = 2 * (nf * nf) as u64;
    let checks =
        ch7xy::held_equilibria(&mech, dofs, &ordered_checks(o.checks), ch7::R, &|d, _| {
            bar.set(done + d as u64)
        })?;
    let done = done + 2 * o.checks as u64;
    let path =
        ch7xy::path_equilibria(&mech, dofs, o.path_checks, &|d, _| bar.set(done + d as u64))?;
    bar.finish();
    let z_of = |p: &SweepPoint| ch7xy::z_at(&mech, dofs, p);
    let t = Instant::now();
    let tangents = ch7xy::grid_tangents(&mech, dofs, &grid)?;
    let tangent_seconds = t.elapsed().as_secs_f64() / grid.len() as f64;
    let mut models = vec![];
    for (n, with_tangents) in grid_sizes(nf)
        .into_iter()
        .flat_map(|n| [(n, false), (n, true)])
    {
        let t = Instant::now();
        let step = (nf - 1) / (n - 1);
        let pts = ch7xy::sub_grid(&grid, nf, step);
        let tang = with_tangents.then(|| ch7xy::sub_grid(&tangents, nf, step));
        let basis = ch7xy::basis(&mech, &pts, n, tang.as_deref())?;
        let seconds = t.elapsed().as_secs_f64()
            + if with_tangents {
                tangent_seconds * pts.len() as f64
            } else {
                0.0
            };
        let freq =
            |p: &[SweepPoint]| ch7::reduced_frequencies_at(&mech, &basis, p, &z_of, dofs, ch7::R);
        let at_checks = freq(&checks)?;
        let at_path = freq(&path)?;
        let ci = centre_indices(nf, n);
        let centres: Vec<SweepPoint> = ci.iter().map(|i| grid[*i].clone()).collect();
        let at_centres = ci.into_iter().zip(freq(&centres)?).collect();
        let model = GridModel {
            n,
            tangents: with_tangents,
            basis,
            seconds,
            at_checks,
            at_path,
            at_centres,
        };
        pg.println(&format!(
            "ch7xy: {} grid model ({seconds:.1} s basis) evaluated",
            model.label()
        ));
        models.push(model);
    }
    // the finest model with the tangents (the more accurate form)
    let finest = &models.last().ok_or("no grid model")?.basis;
    let bar = pg.bar("ch7xy: the off-centre circle", 2 * o.circle_points as u64);
    let circle = ch7xy::circle_equilibria(&mech, dofs, o.circle_points, &|d, _| bar.set(d as u64))?;
    bar.finish();
    let circle_reduced = ch7::reduced_frequencies_at(&mech, finest, &circle, &z_of, dofs, ch7::R)?;
    // a closed loop that fails (a position solve or the integrator) is
    // reported with its message, not fatal to the study
    let (runs, reference, closed_loop_error) = if o.closed_loop {
        match circle_closed_loop(root, &mech, finest, pg) {
            Ok((r, refs)) => (r, refs, None),
            Err(e) => (vec![], vec![], Some(e)),
        }
    } else {
        (vec![], vec![], None)
    };
    Ok(XyResults {
        mech,
        dofs,
        grid,
        sweep_seconds,
        checks,
        path,
        models,
        circle,
        circle_reduced,
        runs,
        reference,
        closed_loop_error,
    })
}

/// The closed loop of the grid model on the off-centre circle with gravity
/// and chapter 7's PD controllers, whose angle references come from the
/// grid model's kinematics with η ≡ 0 along the circle (as chapter 7's from
/// IBM-u's along the path (4.1)): from the undeflected configuration and
/// from the gravity equilibrium; and the reference end-effector path.
pub fn circle_closed_loop(
    root: &Path,
    mech: &Arc<Mechanism>,
    basis: &GridBasis,
    pg: &Progress,
) -> Result<(Vec<Run>, Vec<[f64; 3]>), String> {
    let c = OffCentreCircle;
    let motion = c.motion();
    let z_of = |s: f64| c.z(s);
    let mut kin = ch7::reduced(mech, basis)?;
    let refs = ch7::angle_references_along(&mut kin, 400, c.length(), &motion, &z_of)?;
    let times = flexmb_dynamics::SimulationOptions::new(
        flexmb_dynamics::Integrator::Adams,
        0.0,
        ch7::T_END,
        ch7::OUTPUTS,
    )
    .output_times;
    let s_of_t: Vec<f64> = times.iter().map(|t| motion.value(*t)).collect();
    let reference = reference_end_effector(&mut kin, &s_of_t, &z_of)?;
    let (cmech, _) = ch7::mechanism(root, true, Some(&refs))?;
    let runs = closed_loop_pair(&cmech, basis, "grid model", pg)?;
    Ok((runs, reference))
}

/// The fixture directory of the stored curves.
pub fn curve_dir(root: &Path) -> std::path::PathBuf {
    root.join("fixtures").join("curves").join("ch7xy")
}

/// The stored curves of a study: the unreduced ω1–ω8 and each grid
/// model's at the workspace check points (x = the check point's index).
pub fn stored_curves(r: &XyResults) -> Vec<StoredCurve> {
    let curve = |model: &str, f: &dyn Fn(usize) -> Vec<f64>| {
        let pts: Vec<CurvePoint> = (0..r.checks.len())
            .map(|i| CurvePoint {
                lambda: i as f64,
                position: vec![r.checks[i].q[r.dofs[0]] - r.mech.q0()[r.dofs[0]]],
                freqs: f(i),
                highest: f64::NAN,
            })
            .collect();
        StoredCurve::from_points(model, &pts, 0, ch7::R)
    };
    let mut out = vec![curve("unreduced", &|i| {
        r.checks[i].frequencies_hz[..ch7::R].to_vec()
    })];
    for m in &r.models {
        let t = if m.tangents { " tangents" } else { "" };
        out.push(curve(&format!("grid {0}x{0}{t}", m.n), &|i| {
            m.at_checks[i].clone()
        }));
    }
    out
}

/// The small study that CI recomputes and regresses: grids up to 5 × 5,
/// 16 workspace and 6 path check points, no closed loop.
pub fn ci_options() -> XyOptions {
    XyOptions {
        finest: 5,
        checks: 16,
        path_checks: 6,
        circle_points: 6,
        closed_loop: false,
    }
}

/// Recomputes the stored curves of the CI study.
pub fn recompute(root: &Path, pg: &Progress) -> Result<crate::regress::Recomputed, String> {
    let r = compute(root, &ci_options(), pg)?;
    Ok(crate::regress::Recomputed {
        dir: curve_dir(root),
        curves: stored_curves(&r),
        provenance: vec![
            "issue 18, beyond the thesis: the chapter-7 mechanism (no gravity) reduced over the end-effector's x and y on n × n grids".into(),
            "the 16 Halton check points of the workspace; lambda = the point's index, x = its x offset (m); unreduced (E.6) and grid models (F.7) at rest; \"tangents\": Q the Hermite interpolant with the equilibrium tangents".into(),
            "regenerate: cargo xtask regress --chapter ch7xy --update".into(),
        ],
    })
}

fn io(e: std::io::Error) -> String {
    e.to_string()
}

/// Writes the report into `out`.
pub fn reproduce(root: &Path, out: &Path, pg: &Progress) -> Result<(), String> {
    let start = Instant::now();
    let load = crate::report::load_average_phrase();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let o = XyOptions::default();
    let r = compute(root, &o, pg)?;
    let mut figs = Figures::default();
    figures(&r, out, &mut figs).map_err(io)?;
    write_csv(&r, out).map_err(io)?;
    let md = report(&o, &r, &figs, start.elapsed().as_secs_f64(), &load);
    std::fs::write(out.join("report.md"), md).map_err(io)
}

/// The largest error per mode and grid as CSV.
fn write_csv(r: &XyResults, out: &Path) -> std::io::Result<()> {
    let mut header = vec![
        "n".to_string(),
        "references".to_string(),
        "tangents".to_string(),
    ];
    header.extend((1..=ch7::R).map(|k| format!("max_error_f{k}")));
    let rows: Vec<Vec<f64>> = r
        .models
        .iter()
        .map(|m| {
            let mut row = vec![
                m.n as f64,
                (m.n * m.n) as f64,
                f64::from(u8::from(m.tangents)),
            ];
            row.extend((0..ch7::R).map(|k| m.worst_error(r, k)));
            row
        })
        .collect();
    flexmb_plot::write_csv(
        &out.join("grid_errors.csv"),
        &["the largest relative error of each mode over all check points".into()],
        &header,
        &rows,
    )
}

fn figures(r: &XyResults, out: &Path, figs: &mut Figures) -> std::io::Result<()> {
    let mut p = Plot::new(
        "The curse of dimensionality: the largest error of ω1–ω8 against the references",
        "reference configurations n × n",
        "largest relative error",
    )
    .log_x()
    .log_y();
    for tangents in [false, true] {
        let models: Vec<&GridModel> = r.models.iter().filter(|m| m.tangents == tangents).collect();
        let refs: Vec<f64> = models.iter().map(|m| (m.n * m.n) as f64).collect();
        for k in 0..ch7::R {
            let e: Vec<f64> = models
                .iter()
                .map(|m| m.worst_error(r, k).max(1e-12))
                .collect();
            if tangents {
                p.push(Series::line(&format!("ω{} + tangents", k + 1), &refs, &e));
            } else {
                p.push(Series::dashed(&format!("ω{}", k + 1), &refs, &e));
            }
        }
    }
    figs.save(&p, out, "xy_errors")?;
    let s: Vec<f64> = (1..=r.circle.len())
        .map(|i| OffCentreCircle.length() * i as f64 / r.circle.len() as f64)
        .collect();
    let mut p = Plot::new(
        "ω1–ω8 along the off-centre circle: unreduced and the finest grid model",
        "arc length (m)",
        "eigenfrequency (Hz)",
    )
    .log_y();
    for k in 0..ch7::R {
        let u: Vec<f64> = r.circle.iter().map(|p| p.frequencies_hz[k]).collect();
        let g: Vec<f64> = r.circle_reduced.iter().map(|f| f[k]).collect();
        p.push(Series::line(&format!("ω{} unreduced", k + 1), &s, &u));
        p.push(Series::dashed(&format!("ω{} grid", k + 1), &s, &g));
    }
    figs.save(&p, out, "xy_circle_frequencies")?;
    let mut p = Plot::new(
        "The workspace: grid points, check points, the path (4.1) and the off-centre circle",
        "x offset (m)",
        "y offset (m)",
    )
    .equal_aspect();
    let off = |pts: &[SweepPoint]| -> (Vec<f64>, Vec<f64>) {
        let q0 = r.mech.q0();
        pts.iter()
            .map(|p| {
                (
                    p.q[r.dofs[0]] - q0[r.dofs[0]],
                    p.q[r.dofs[1]] - q0[r.dofs[1]],
                )
            })
            .unzip()
    };
    let (x, y) = off(&r.grid);
    p.push(Series::points("finest grid", &x, &y));
    let (x, y) = off(&r.checks);
    p.push(Series::points("workspace check points", &x, &y));
    let (x, y) = off(&r.path);
    p.push(Series::points("path check points", &x, &y));
    let c: Vec<[f64; 2]> = (0..=400)
        .map(|i| OffCentreCircle.at(OffCentreCircle.length() * i as f64 / 400.0))
        .collect();
    p.push(Series::line(
        "off-centre circle",
        &c.iter().map(|v| v[0]).collect::<Vec<_>>(),
        &c.iter().map(|v| v[1]).collect::<Vec<_>>(),
    ));
    figs.save(&p, out, "xy_workspace")?;
    if let Some(run) = r.runs.last() {
        tracking_figures(
            figs,
            out,
            &r.reference,
            &r.runs,
            run,
            [
                (
                    "xy_closed_loop_path",
                    "The grid model's closed loop on the off-centre circle",
                ),
                (
                    "xy_closed_loop_errors",
                    "Tracking errors of the grid model (from the gravity equilibrium)",
                ),
            ],
        )?;
    }
    Ok(())
}

fn report(o: &XyOptions, r: &XyResults, figs: &Figures, wall: f64, load: &str) -> String {
    let mut s = String::new();
    let per_point = r.sweep_seconds / r.grid.len() as f64;
    let _ = writeln!(
        s,
        "# Beyond the thesis: an interpolated basis over the end-effector's x and y\n\n\
         The chapter-7 mechanism (`fixtures/scenes/two_dof_mechanism_actuated.ron`, {} DOF, \
         no gravity in the references) reduced over **two configuration coordinates**, the \
         end-effector's x and y over the whole 100 × 100 mm workspace (thesis §8, \
         recommendation 3): z = (x, y, η), q = Q(x, y) + V(x, y)η + q0, Q and V bicubic \
         splines through the equilibria on an n × n tensor grid, V by MSI over the grid \
         (along the first row, then up each column) with the mass normalization (6.26). \
         V spans the unconstrained eigenvectors up to 200 Hz (the first eight, \
         orthonormalized, (7.6)) without the two mechanism modes, which Q,x and Q,y \
         carry: 6 vectors, 8 DOF as IBM-u. Every grid is built in two forms: Q the natural \
         bicubic spline through the equilibria (as the thesis's (6.23) along a path), and \
         Q the bicubic Hermite interpolant of the equilibria and the equilibrium surface's \
         tangents ∂q/∂x, ∂q/∂y there (\"+ tangents\": the static modes of the held x and \
         y from the tangent stiffness, `equilibrium_tangents`; one more linearization per \
         reference). Run time {wall:.0} s on this 2-core machine ({load}). Code: \
         `xtask/src/ch7xy.rs`, `crates/reduction/src/grid.rs`.\n",
        r.mech.n_dof()
    );
    let _ = writeln!(
        s,
        "## The curse of dimensionality\n\n\
         One sweep of the {0} × {0} grid ({1} equilibria with their modes, {2:.0} s, \
         {3:.2} s per reference); the coarser grids are its sub-grids. Each model's ω1–ω8 \
         (the rest linearization (F.7) with the holding force as a dead load, as chapter \
         7) against the unreduced ones (E.6) at points off every grid: {4} Halton points \
         over the workspace, {5} points on the path (4.1) halfway between equally spaced \
         ones, and the grid's own cell centres (nodes of the finest grid; none for the \
         finest). The largest relative error over all of them:\n",
        o.finest,
        r.grid.len(),
        r.sweep_seconds,
        per_point,
        r.checks.len(),
        r.path.len()
    );
    let mut header = vec!["grid", "references", "build (sweep + basis)"];
    let names: Vec<String> = (1..=ch7::R).map(|k| format!("ω{k}")).collect();
    header.extend(names.iter().map(|s| s.as_str()));
    let mut t = Table::new(&header);
    for m in &r.models {
        let mut row = vec![
            m.label(),
            (m.n * m.n).to_string(),
            format!("≈ {:.0} s", per_point * (m.n * m.n) as f64 + m.seconds),
        ];
        row.extend((0..ch7::R).map(|k| pct(m.worst_error(r, k))));
        t.row(row);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(
        s,
        "The build time is the finest sweep's time per reference times the grid's \
         references plus the basis (and the tangents' linearizations; measured); the \
         sweep of each reference is the same work as one of chapter 7's. The errors are \
         rank by rank: where Q,x and Q,y raise the two mechanism modes above ω3, they \
         sort among ω3–ω8 and the errors of those overstate the modes' own. The natural \
         spline's Q,x and Q,y are not the equilibrium surface's tangents even at the grid \
         points: their small components in directions 10⁴ times stiffer than the \
         mechanism's motion raise ω1 and ω2 30-fold there. With the tangents the grid \
         points keep ω1–ω8 to 5e-5 (`xtask/tests/ch7xy_claims.rs`), and what is left \
         between them is the interpolation's own error.\n"
    );
    for tangents in [false, true] {
        let models: Vec<&GridModel> = r.models.iter().filter(|m| m.tangents == tangents).collect();
        let within: Vec<String> = (0..ch7::R)
            .map(|k| {
                let first = models.iter().find(|m| {
                    models
                        .iter()
                        .filter(|b| b.n >= m.n)
                        .all(|b| b.worst_error(r, k) <= 0.01)
                });
                format!(
                    "ω{}: {}",
                    k + 1,
                    first.map_or(format!("not within {0} × {0}", o.finest), |m| format!(
                        "{0} × {0} = {1}",
                        m.n,
                        m.n * m.n
                    ))
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "**References for each mode within 1 % everywhere, Q {}** (the smallest grid \
             from which on every finer grid is within 1 %): {}.\n",
            if tangents {
                "with the tangents"
            } else {
                "the natural spline"
            },
            within.join("; ")
        );
    }
    let mut t = Table::new(&["grid", "where", "ω1 median (max)", "ω2", "ω3–ω8 largest"]);
    for m in &r.models {
        let centres: Vec<SweepPoint> = m
            .at_centres
            .iter()
            .map(|(i, _)| r.grid[*i].clone())
            .collect();
        let cf: Vec<Vec<f64>> = m.at_centres.iter().map(|(_, f)| f.clone()).collect();
        for (name, full, red) in [
            ("workspace", &r.checks[..], &m.at_checks[..]),
            ("path (4.1)", &r.path[..], &m.at_path[..]),
            ("cell centres", &centres[..], &cf[..]),
        ] {
            if full.is_empty() {
                continue;
            }
            let cell = |k: usize| {
                let (md, mx) = median_and_max(&errors(full, red, k));
                format!("{} ({})", pct(md), pct(mx))
            };
            let high = (2..ch7::R)
                .map(|k| worst(&errors(full, red, k)))
                .fold(0.0, f64::max);
            t.row(vec![m.label(), name.into(), cell(0), cell(1), pct(high)]);
        }
    }
    let _ = writeln!(
        s,
        "Median (largest) errors by kind of check point:\n\n{}",
        t.render()
    );
    s += &figs.markdown(|f| f == "xy_errors" || f == "xy_workspace");
    let _ = writeln!(
        s,
        "## A path the one-coordinate models were not built for\n\n\
         A circle of radius 25 mm about (−15, 15) mm from the undeflected position, \
         reached by a straight line from it: the one-coordinate IBM-u and IBM-c only \
         describe the path (4.1), so they cannot follow it at all. The finest grid model \
         ({0} × {0}, Q with the tangents) against the unreduced model at {1} equilibria along it:\n",
        o.finest,
        r.circle.len()
    );
    let mut t = Table::new(&["mode", "median error", "largest error"]);
    for k in 0..ch7::R {
        let (md, mx) = median_and_max(&errors(&r.circle, &r.circle_reduced, k));
        t.row(vec![format!("ω{}", k + 1), pct(md), pct(mx)]);
    }
    let _ = writeln!(s, "{}", t.render());
    s += &figs.markdown(|f| f == "xy_circle_frequencies");
    if let Some(e) = &r.closed_loop_error {
        let _ = writeln!(
            s,
            "### Closed loop on the circle\n\nThe closed loop of the {0} × {0} grid model \
             failed: {e}\n",
            o.finest
        );
    }
    if !r.runs.is_empty() {
        let _ = writeln!(
            s,
            "### Closed loop on the circle\n\n\
             Chapter 7's PD controllers (7.12) with Table 7.1's gains and gravity; the \
             angle references from the grid model's kinematics with η ≡ 0 along the \
             circle; five skew-sine moves (7.13) of 0.25 s with 0.05 s stops, to the end \
             of the lead-in and every quarter turn; 1.5 s, 1000 output steps, Adams (rtol \
             1e-3, atol 1e-6), as chapter 7's IBM-u runs.\n"
        );
        let mut t = Table::new(&[
            "run",
            "evaluations",
            "wall time",
            "largest |x_ref − x|",
            "largest |y_ref − y|",
        ]);
        for run in &r.runs {
            let err = |k: usize| {
                r.reference
                    .iter()
                    .zip(&run.ee)
                    .map(|(a, b)| (a[k] - b[k]).abs())
                    .fold(0.0, f64::max)
            };
            t.row(vec![
                run.label.clone(),
                run.evaluations.to_string(),
                format!("{:.1} s", run.seconds),
                format!("{} m", sig(err(0))),
                format!("{} m", sig(err(1))),
            ]);
        }
        let _ = writeln!(s, "{}", t.render());
        s += &figs.markdown(|f| f.starts_with("xy_closed_loop"));
    }
    s
}
