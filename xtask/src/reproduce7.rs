//! `cargo xtask reproduce ch7`: writes `results/ch7/` for thesis chapter 7
//! ([`crate::ch7`]): IBM-c and IBM-u of the two-DOF mechanism along the
//! path from 100 reference configurations, their eigenfrequencies against
//! the unreduced model's (Figs 7.2, 7.3), the closed-loop poles (Table 7.2),
//! the closed-loop response of IBM-u to the skew-sine moves with gravity
//! from the undeflected configuration and from the gravity equilibrium
//! (Figs 7.4–7.7), the unreduced closed loop for comparison, evaluations and
//! wall times against the thesis's.

use crate::ch4::path::Path4;
use crate::ch4::sweep;
use crate::ch7::{self, Variant};
use crate::curves::StoredCurve;
use crate::models::CurvePoint;
use crate::progress::Progress;
use crate::report::{pct, sig, Figures, Table};
use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions};
use flexmb_linearize::SweepPoint;
use flexmb_plot::{Plot, Series};
use flexmb_reduction::{InterpolatedBasis, MechanicalModel};
use std::fmt::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// Options of the reproduction.
#[derive(Clone, Debug)]
pub struct Ch7Options {
    /// Reference configurations (the thesis: 100).
    pub n_reference: usize,
    /// Wall-time budget of the unreduced closed loop (s): it is stopped
    /// there and reported as far as it got.
    pub unreduced_budget: f64,
}

impl Default for Ch7Options {
    fn default() -> Self {
        Self {
            n_reference: ch7::N_REFERENCE,
            unreduced_budget: 240.0,
        }
    }
}

/// The thesis's evaluations of the IBM-u closed loop (§7.2.3).
pub const THESIS_EVALUATIONS: usize = 8259;

fn io(e: std::io::Error) -> String {
    e.to_string()
}

/// One closed-loop run: its times, end-effector positions, evaluations,
/// wall time, and how far it got.
pub struct Run {
    /// What it is.
    pub label: String,
    /// Output times.
    pub t: Vec<f64>,
    /// End-effector (x, y, z) at them.
    pub ee: Vec<[f64; 3]>,
    /// Right-hand-side (or residual) evaluations.
    pub evaluations: usize,
    /// Wall time (s).
    pub seconds: f64,
    /// Stopped by the budget before the end.
    pub stopped: bool,
}

fn run_of(label: &str, mech: &flexmb_model::Mechanism, tr: &flexmb_dynamics::Trajectory) -> Run {
    Run {
        label: label.into(),
        t: tr.t.clone(),
        ee: tr.x.iter().map(|x| ch7::end_effector(mech, x)).collect(),
        evaluations: tr.stats.rhs_evals,
        seconds: tr.wall_time,
        stopped: tr.stopped,
    }
}

/// The reduced models' eigenfrequencies against the unreduced ones along
/// the path (Figs 7.2, 7.3).
pub struct Ch7Frequencies {
    /// The mechanism (no gravity, no controllers) and its path DOFs.
    pub mech: Arc<flexmb_model::Mechanism>,
    /// The end-effector's x and y DOFs.
    pub dofs: [usize; 2],
    /// The reference configurations.
    pub points: Vec<SweepPoint>,
    /// Wall time of their sweep (s).
    pub sweep_seconds: f64,
    /// The equilibria halfway between them (beyond the thesis), empty if
    /// not asked for.
    pub between: Vec<SweepPoint>,
    /// IBM-u, IBM-c and IBM-u with the path's tangents (beyond the
    /// thesis), in this order.
    pub reduced: Vec<ReducedVariant>,
}

/// One reduced model along the path and its eigenfrequencies.
pub struct ReducedVariant {
    /// Which one.
    pub variant: Variant,
    /// Whether Q is the Hermite interpolant with the equilibrium path's
    /// tangents ([`ch7::path_tangents`]), else the natural spline (6.23).
    pub tangents: bool,
    /// Its interpolated basis.
    pub basis: InterpolatedBasis,
    /// The basis's wall time (s).
    pub seconds: f64,
    /// Its first eigenfrequencies at the reference configurations.
    pub at_references: Vec<Vec<f64>>,
    /// And halfway between them.
    pub halfway: Vec<Vec<f64>>,
}

impl ReducedVariant {
    /// "IBM-u", "IBM-c" or "IBM-u + tangents".
    pub fn label(&self) -> String {
        Self::label_of(self.variant, self.tangents)
    }

    fn label_of(v: Variant, tangents: bool) -> String {
        let t = if tangents { " + tangents" } else { "" };
        format!("{}{t}", v.label())
    }
}

/// The reference configurations, IBM-u and IBM-c, and their eigenfrequencies
/// at the `n_reference` reference configurations (and halfway between them
/// if `between`).
pub fn frequencies(
    root: &Path,
    n_reference: usize,
    between: bool,
    pg: &Progress,
) -> Result<Ch7Frequencies, String> {
    let (mech, dofs) = ch7::mechanism(root, false, None)?;
    let values = ch7::reference_values(n_reference);
    let mids: Vec<f64> = if between {
        values.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect()
    } else {
        vec![]
    };
    let bar = pg.bar(
        "ch7 reference configurations along the path",
        2 * (values.len() + mids.len()) as u64,
    );
    let t = Instant::now();
    let points = sweep::run(&mech, dofs, &values, ch7::R, &|d, _| bar.set(d as u64))?;
    let sweep_seconds = t.elapsed().as_secs_f64();
    let done = 2 * values.len() as u64;
    let between = if mids.is_empty() {
        vec![]
    } else {
        sweep::run(&mech, dofs, &mids, ch7::R, &|d, _| bar.set(done + d as u64))?
    };
    bar.finish();
    let mut reduced = vec![];
    for (v, tangents) in [
        (Variant::Unconstrained, false),
        (Variant::Constrained, false),
        (Variant::Unconstrained, true),
    ] {
        let t = Instant::now();
        let mut b = ch7::basis(&mech, dofs, &points, v, ch7::R)?;
        if tangents {
            b = b
                .with_tangents(ch7::path_tangents(&mech, dofs, &points)?)
                .map_err(|e| e.to_string())?;
        }
        let basis_seconds = t.elapsed().as_secs_f64();
        let label = ReducedVariant::label_of(v, tangents);
        pg.println(&format!("{label} basis in {basis_seconds:.1} s"));
        let at = ch7::reduced_frequencies(&mech, &b, &points, dofs, ch7::R)?;
        let mid = ch7::reduced_frequencies(&mech, &b, &between, dofs, ch7::R)?;
        reduced.push(ReducedVariant {
            variant: v,
            tangents,
            basis: b,
            seconds: basis_seconds,
            at_references: at,
            halfway: mid,
        });
    }
    Ok(Ch7Frequencies {
        mech,
        dofs,
        points,
        sweep_seconds,
        between,
        reduced,
    })
}

/// The fixture directory of the stored curves.
pub fn curve_dir(root: &Path) -> std::path::PathBuf {
    root.join("fixtures").join("curves").join("ch7")
}

/// The stored curves: the unreduced, IBM-u and IBM-c eigenfrequencies at the
/// reference configurations.
pub fn stored_curves(f: &Ch7Frequencies) -> Vec<StoredCurve> {
    let curve = |model: &str, freqs: &dyn Fn(usize) -> Vec<f64>| {
        let pts: Vec<CurvePoint> = f
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| CurvePoint {
                lambda: p.s,
                position: vec![p.s],
                freqs: freqs(i),
                highest: f64::NAN,
            })
            .collect();
        StoredCurve::from_points(model, &pts, 0, ch7::R)
    };
    let mut out = vec![curve("unreduced", &|i| {
        f.points[i].frequencies_hz[..ch7::R].to_vec()
    })];
    for r in &f.reduced {
        out.push(curve(
            &r.label()
                .to_lowercase()
                .replace('-', "_")
                .replace(" + ", "_"),
            &|i| r.at_references[i].clone(),
        ));
    }
    out
}

fn provenance(n: usize) -> Vec<String> {
    vec![
        "thesis §7.2.2: the two-DOF mechanism with its actuator hinges (fixtures/scenes/two_dof_mechanism_actuated.ron), no gravity".into(),
        format!("{n} equally spaced arc lengths; x = lambda = s (m); unreduced (E.6) and IBM-u, IBM-c (F.7) at rest"),
        "regenerate: cargo xtask regress --chapter ch7 --update".into(),
    ]
}

/// Recomputes the stored regression curves (about a minute).
pub fn recompute(root: &Path, pg: &Progress) -> Result<crate::regress::Recomputed, String> {
    let f = frequencies(root, ch7::N_REFERENCE, false, pg)?;
    Ok(crate::regress::Recomputed {
        dir: curve_dir(root),
        curves: stored_curves(&f),
        provenance: provenance(ch7::N_REFERENCE),
    })
}

/// Everything the report shows.
pub struct Ch7Results {
    /// The eigenfrequencies along the path.
    pub freq: Ch7Frequencies,
    /// Closed-loop poles at s = 0: reduced IBM-u, unreduced, and IBM-u with
    /// the path's tangents.
    pub poles: [Vec<flexmb_linearize::DampedMode>; 3],
    /// The closed-loop runs: IBM-u from the undeflected configuration and
    /// from the gravity equilibrium, and the unreduced model.
    pub runs: Vec<Run>,
    /// The reference end-effector path (x, y, z) at the output times (IBM-u
    /// with η ≡ 0, no gravity).
    pub reference: Vec<[f64; 3]>,
    /// The angle references at the output times.
    pub angles: Vec<[f64; 2]>,
    /// s(t) at the output times.
    pub s_of_t: Vec<f64>,
}

/// The closed-loop poles of a linearization's matrices.
fn poles(
    m: &faer::Mat<f64>,
    d: &faer::Mat<f64>,
    k: &faer::Mat<f64>,
) -> Result<Vec<flexmb_linearize::DampedMode>, String> {
    flexmb_linearize::damped_modes_of(m, d, k).map_err(|e| e.to_string())
}

/// Runs chapter 7 (`o`), with progress on `pg`.
pub fn compute(root: &Path, o: &Ch7Options, pg: &Progress) -> Result<Ch7Results, String> {
    // 1.-2. the reference configurations (no gravity, no controllers), the
    // bases and their eigenfrequencies
    let freq = frequencies(root, o.n_reference, true, pg)?;
    let mech = freq.mech.clone();
    let ibm_u = &freq.reduced[0].basis;
    // 3. the angle references from IBM-u's kinematics with η ≡ 0
    let mut kin_model = ch7::reduced(&mech, ibm_u)?;
    let refs = ch7::angle_references(&mut kin_model, 4 * o.n_reference)?;
    // 4. closed-loop poles at s = 0, without gravity
    let (lmech, _) = ch7::mechanism(root, false, Some(&refs))?;
    let reduced_poles_of = |b: &flexmb_reduction::InterpolatedBasis| {
        let mut lm = ch7::reduced(&lmech, b)?;
        let z0 = vec![0.0; lm.n_z()];
        let lin = lm
            .linearize(0.0, &z0, &z0, &z0)
            .map_err(|e| e.to_string())?;
        poles(&lin.m, &lin.damping, &lin.stiffness)
    };
    let reduced_poles = reduced_poles_of(ibm_u)?;
    let tangent_poles = reduced_poles_of(&freq.reduced[2].basis)?;
    let mut dy = Dynamics::new(lmech.clone());
    let q0 = lmech.q0();
    let n = q0.len();
    let full = dy
        .linearize(0.0, &q0, &vec![0.0; n], &vec![0.0; n])
        .map_err(|e| e.to_string())?;
    let unreduced_poles = poles(&full.m, &full.damping_total(), &full.stiffness_total())?;
    // 5. the closed loop with gravity
    let (cmech, _) = ch7::mechanism(root, true, Some(&refs))?;
    let times =
        SimulationOptions::new(Integrator::Adams, 0.0, ch7::T_END, ch7::OUTPUTS).output_times;
    let motion = ch7::reference_motion();
    let s_of_t: Vec<f64> = times.iter().map(|t| motion.value(*t)).collect();
    let angles: Vec<[f64; 2]> = times
        .iter()
        .map(|t| [refs[0].value(*t), refs[1].value(*t)])
        .collect();
    let n_z = kin_model.n_z();
    let z_of = |s: f64| {
        let mut z = vec![0.0; n_z];
        z[0] = s;
        z
    };
    let reference = reference_end_effector(&mut kin_model, &s_of_t, &z_of)?;
    let mut runs = closed_loop_pair(&cmech, ibm_u, "IBM-u", pg)?;
    // 6. the unreduced closed loop, generalized-α, within its budget
    let stop = Arc::new(AtomicBool::new(false));
    let timer = {
        let stop = stop.clone();
        let budget = o.unreduced_budget;
        std::thread::spawn(move || {
            let start = Instant::now();
            while start.elapsed().as_secs_f64() < budget {
                if stop.load(std::sync::atomic::Ordering::Relaxed) {
                    return;
                }
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
        })
    };
    let mut dy = Dynamics::new(cmech.clone());
    let mut opts =
        SimulationOptions::new(Integrator::GeneralizedAlpha, 0.0, ch7::T_END, ch7::OUTPUTS);
    opts.rtol = 1e-3;
    opts.atol = 1e-6;
    opts.stop = Some(stop.clone());
    let bar = pg.bar("unreduced closed loop (generalized-α)", 1000);
    let tr = dy
        .simulate(0.0, &cmech.q0(), &vec![0.0; n], &opts, |t, _, _| {
            bar.set((t / ch7::T_END * 1000.0) as u64);
            Control::Continue
        })
        .map_err(|e| format!("the unreduced closed loop: {e}"))?;
    bar.finish();
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = timer.join();
    runs.push(run_of(
        "unreduced (generalized-α) from the undeflected configuration",
        &cmech,
        &tr,
    ));
    Ok(Ch7Results {
        freq,
        poles: [reduced_poles, unreduced_poles, tangent_poles],
        runs,
        reference,
        angles,
        s_of_t,
    })
}

/// The end-effector (x, y, z) of the reduced model `kin` (no gravity) with
/// η ≡ 0 at the arc lengths `s`, at z = `z_of(s)`: the reference path the
/// controllers' angle references describe.
pub fn reference_end_effector(
    kin: &mut flexmb_reduction::ReducedModel,
    s: &[f64],
    z_of: &dyn Fn(f64) -> Vec<f64>,
) -> Result<Vec<[f64; 3]>, String> {
    s.iter()
        .map(|s| {
            let q = kin.full_coordinates(&z_of(*s));
            let dy = kin.dynamics_mut();
            dy.kinematics_mut()
                .solve(&q, 0.0)
                .map_err(|e| e.to_string())?;
            Ok(ch7::end_effector(dy.mechanism(), dy.kinematics().x()))
        })
        .collect()
}

/// The closed loop of a reduced `model` (of the mechanism with gravity and
/// the PD controllers) over [`ch7::T_END`] with [`ch7::OUTPUTS`] outputs,
/// Adams (rtol 1e-3, atol 1e-6), from `z0` at rest, or from the gravity
/// equilibrium next to it if `from_equilibrium`, with a progress bar.
pub fn reduced_closed_loop(
    model: &mut flexmb_reduction::ReducedModel,
    z0: &[f64],
    from_equilibrium: bool,
    label: &str,
    pg: &Progress,
) -> Result<Run, String> {
    let mut z = z0.to_vec();
    if from_equilibrium {
        let eq = MechanicalModel::static_equilibrium(
            model,
            0.0,
            &z,
            &flexmb_dynamics::StaticOptions::default(),
        )
        .map_err(|e| format!("the gravity equilibrium of {label}: {e}"))?;
        z = eq.coordinates;
    }
    let mut o = SimulationOptions::new(Integrator::Adams, 0.0, ch7::T_END, ch7::OUTPUTS);
    o.rtol = 1e-3;
    o.atol = 1e-6;
    let bar = pg.bar(label, 1000);
    let rest = vec![0.0; z.len()];
    let tr = MechanicalModel::simulate(model, 0.0, &z, &rest, &o, &mut |t, _, _| {
        bar.set((t / ch7::T_END * 1000.0) as u64);
        Control::Continue
    })
    .map_err(|e| format!("{label}: {e}"))?;
    bar.finish();
    let mech = model.dynamics().mechanism().clone();
    Ok(run_of(label, &mech, &tr.full))
}

/// Writes the report of chapter 7 into `out`.
pub fn reproduce(root: &Path, out: &Path, pg: &Progress) -> Result<(), String> {
    let start = Instant::now();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let o = Ch7Options::default();
    let r = compute(root, &o, pg)?;
    let mut figs = Figures::default();
    figures(&r, out, &mut figs).map_err(io)?;
    pictures(&r.freq, out, &mut figs).map_err(io)?;
    let md = report(&o, &r, &figs, start.elapsed().as_secs_f64());
    std::fs::write(out.join("report.md"), md).map_err(io)
}

/// The relative differences of mode k between reduced model `v` (0: IBM-u,
/// 1: IBM-c, 2: IBM-u + tangents) and the unreduced one, at the reference configurations, or
/// halfway between them if `between`.
pub fn mode_errors(f: &Ch7Frequencies, v: usize, k: usize, between: bool) -> Vec<f64> {
    let (points, reduced) = if between {
        (&f.between, &f.reduced[v].halfway)
    } else {
        (&f.points, &f.reduced[v].at_references)
    };
    points
        .iter()
        .zip(reduced)
        .map(|(p, r)| ((r[k] - p.frequencies_hz[k]) / p.frequencies_hz[k]).abs())
        .collect()
}

/// The median and the largest of `e`.
pub fn median_and_max(e: &[f64]) -> (f64, f64) {
    let mut e = e.to_vec();
    e.sort_by(f64::total_cmp);
    (
        e.get(e.len() / 2).copied().unwrap_or(f64::NAN),
        e.last().copied().unwrap_or(f64::NAN),
    )
}

/// The mechanism at the reference configuration nearest the third stop
/// (halfway round the circle) over the undeflected one, and its mode 3
/// there, which both reduced models keep (issue 23).
fn pictures(f: &Ch7Frequencies, out: &Path, figs: &mut Figures) -> std::io::Result<()> {
    use flexmb_draw::{Configuration, DrawOptions, View};
    let stop = Path4::new().marks()[2];
    let i = (0..f.points.len())
        .min_by(|a, b| {
            (f.points[*a].s - stop)
                .abs()
                .total_cmp(&(f.points[*b].s - stop).abs())
        })
        .unwrap_or(0);
    let at = Configuration {
        mechanism: f.mech.clone(),
        q: f.points[i].q.clone(),
        x: f.points[i].x.clone(),
        t: 0.0,
        load_scale: 1.0,
    };
    crate::pictures::save(
        figs,
        out,
        "mech_stop3",
        &at,
        &DrawOptions {
            view: Some(View::Xy),
            reference: true,
            title: Some(format!(
                "The mechanism at s = {:.4} m (the third stop), the undeflected one lighter",
                f.points[i].s
            )),
            ..Default::default()
        },
    )?;
    crate::pictures::save(
        figs,
        out,
        "mech_mode3_stop3",
        &at,
        &DrawOptions {
            view: Some(View::Iso),
            mode: Some(3),
            phases: Some(2),
            title: Some(format!(
                "Mode 3 at the third stop ({:.1} Hz; IBM-u {:.1} Hz, IBM-c {:.1} Hz)",
                f.points[i].frequencies_hz[2],
                f.reduced[0].at_references[i][2],
                f.reduced[1].at_references[i][2]
            )),
            ..Default::default()
        },
    )?;
    Ok(())
}

fn figures(r: &Ch7Results, out: &Path, figs: &mut Figures) -> std::io::Result<()> {
    let f = &r.freq;
    let s: Vec<f64> = f.points.iter().map(|p| p.s).collect();
    for (stem, title, modes) in [
        ("fig7_2_omega1_2", "Fig. 7.2: ω1, ω2 along the path", 0..2),
        (
            "fig7_3_omega3_8",
            "Fig. 7.3: ω3–ω8 along the path",
            2..ch7::R,
        ),
    ] {
        let mut p = Plot::new(title, "arc length s (m)", "eigenfrequency (Hz)");
        for k in modes {
            let u: Vec<f64> = f.points.iter().map(|p| p.frequencies_hz[k]).collect();
            p.push(Series::line(&format!("ω{} unreduced", k + 1), &s, &u));
            for r in &f.reduced {
                let y: Vec<f64> = r.at_references.iter().map(|f| f[k]).collect();
                p.push(Series::dashed(&format!("ω{} {}", k + 1, r.label()), &s, &y));
            }
        }
        figs.save(&p, out, stem)?;
    }
    let t: Vec<f64> = r.runs[0].t.clone();
    let mut p = Plot::new("Fig. 7.4: the reference motion", "t (s)", "s (m), φ (rad)");
    p.push(Series::line("s(t)", &t, &r.s_of_t));
    for (k, name) in ["φx ref", "φy ref"].iter().enumerate() {
        let a: Vec<f64> = r.angles.iter().map(|a| a[k]).collect();
        p.push(Series::line(name, &t, &a));
    }
    figs.save(&p, out, "fig7_4_reference")?;
    tracking_figures(
        figs,
        out,
        &r.reference,
        &r.runs[..2],
        &r.runs[1],
        [
            ("fig7_5a_path", "Fig. 7.5a: the end-effector in the plane"),
            (
                "fig7_5b_errors",
                "Fig. 7.5b: tracking errors of IBM-u (from the gravity equilibrium)",
            ),
        ],
    )?;
    let mut p = Plot::new("Fig. 7.6: z of the end-effector", "t (s)", "z (m)");
    for run in &r.runs {
        let z: Vec<f64> = run.ee.iter().map(|p| p[2]).collect();
        p.push(Series::line(&run.label, &run.t, &z));
    }
    figs.save(&p, out, "fig7_6_z")?;
    let (f, a) = spectrum(r);
    let mut p = Plot::new(
        "Fig. 7.7: single-sided amplitude spectrum of z_eq − z_undef (IBM-u)",
        "frequency (Hz)",
        "amplitude (m)",
    );
    let keep: Vec<usize> = (1..f.len()).filter(|k| f[*k] <= 300.0).collect();
    p.push(Series::line(
        "|Z(f)|",
        &keep.iter().map(|k| f[*k]).collect::<Vec<_>>(),
        &keep.iter().map(|k| a[*k]).collect::<Vec<_>>(),
    ));
    figs.save(&p, out, "fig7_7_spectrum")?;
    Ok(())
}

/// Two figures of closed-loop `runs` against the `reference` end-effector
/// path: the paths in the plane, and the x, y tracking errors of `tracked`
/// over time; `names` are (file stem, title) of each.
pub fn tracking_figures(
    figs: &mut Figures,
    out: &Path,
    reference: &[[f64; 3]],
    runs: &[Run],
    tracked: &Run,
    names: [(&str, &str); 2],
) -> std::io::Result<()> {
    let mut p = Plot::new(names[0].1, "x (m)", "y (m)").equal_aspect();
    let xy = |e: &[[f64; 3]]| -> (Vec<f64>, Vec<f64>) { e.iter().map(|p| (p[0], p[1])).unzip() };
    let (x, y) = xy(reference);
    p.push(Series::line("reference", &x, &y));
    for run in runs {
        let (x, y) = xy(&run.ee);
        p.push(Series::dashed(&run.label, &x, &y));
    }
    figs.save(&p, out, names[0].0)?;
    let mut p = Plot::new(names[1].1, "t (s)", "error (m)");
    for (k, name) in ["x_ref − x", "y_ref − y"].iter().enumerate() {
        let e: Vec<f64> = reference
            .iter()
            .zip(&tracked.ee)
            .map(|(a, b)| a[k] - b[k])
            .collect();
        p.push(Series::line(name, &tracked.t, &e));
    }
    figs.save(&p, out, names[1].0)
}

/// The closed loops of a reduced model of `cmech` (gravity, controllers)
/// with `basis` from z = 0 at rest and from the gravity equilibrium next to
/// it ([`reduced_closed_loop`]), labelled "`name` from …".
pub fn closed_loop_pair<B: flexmb_reduction::Basis + Clone + 'static>(
    cmech: &Arc<flexmb_model::Mechanism>,
    basis: &B,
    name: &str,
    pg: &Progress,
) -> Result<Vec<Run>, String> {
    let z0 = vec![0.0; basis.n_z()];
    [
        ("the undeflected configuration", false),
        ("the gravity equilibrium", true),
    ]
    .into_iter()
    .map(|(from, from_equilibrium)| {
        let mut model = ch7::reduced(cmech, basis)?;
        reduced_closed_loop(
            &mut model,
            &z0,
            from_equilibrium,
            &format!("{name} from {from}"),
            pg,
        )
    })
    .collect()
}

/// The spectrum of z_eq − z_undef over the 1000 steps of the IBM-u runs.
pub fn spectrum(r: &Ch7Results) -> (Vec<f64>, Vec<f64>) {
    let z: Vec<f64> = r.runs[1]
        .ee
        .iter()
        .zip(&r.runs[0].ee)
        .skip(1)
        .map(|(a, b)| a[2] - b[2])
        .collect();
    ch7::amplitude_spectrum(&z, ch7::T_END / (ch7::OUTPUTS - 1) as f64)
}

/// The local maxima of the spectrum above `floor` × its largest, by height.
pub fn peaks(f: &[f64], a: &[f64], floor: f64) -> Vec<(f64, f64)> {
    let top = a.iter().skip(1).fold(0.0f64, |m, v| m.max(*v));
    let mut p: Vec<(f64, f64)> = (2..a.len() - 1)
        .filter(|k| a[*k] > a[k - 1] && a[*k] >= a[k + 1] && a[*k] > floor * top)
        .map(|k| (f[k], a[k]))
        .collect();
    p.sort_by(|x, y| y.1.total_cmp(&x.1));
    p
}

fn report(o: &Ch7Options, r: &Ch7Results, figs: &Figures, wall: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Chapter 7: the interpolated models of the two-DOF mechanism in closed loop\n\n\
         The chapter-4 substitute mechanism with the actuator hinges of §7.2.1 \
         (`fixtures/scenes/two_dof_mechanism_actuated.ron`), reduced along the path (4.1) \
         from {} reference configurations to z = (s, η), 8 DOF, with constrained (IBM-c) \
         and unconstrained (IBM-u) eigenvectors and MSI. Run time {wall:.0} s. Choices \
         where the thesis is silent: docs/reproduce.md, \"Chapter 7\".\n",
        o.n_reference
    );
    let _ = writeln!(s, "## Reduction\n");
    let mut t = Table::new(&["", "thesis", "ours"]);
    let n_q = r.freq.points[0].q.len();
    t.row(vec!["unreduced DOFs".into(), "688".into(), n_q.to_string()]);
    t.row(vec![
        "reduced DOFs".into(),
        "8".into(),
        (1 + ch7::R - 1).to_string(),
    ]);
    t.row(vec![
        "reference configurations (sweep time)".into(),
        "100".into(),
        format!("{} ({:.1} s)", r.freq.points.len(), r.freq.sweep_seconds),
    ]);
    for v in &r.freq.reduced {
        t.row(vec![
            format!("{} basis", v.label()),
            "–".into(),
            format!("{:.1} s", v.seconds),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(
        s,
        "## Eigenfrequencies along the path (Figs 7.2, 7.3)\n\n\
         The reduced models' rest linearization (F.7) at z = (s, 0) against the \
         unreduced one (E.6), both with the end-effector's holding force as a dead \
         load: the relative difference of each mode, median and largest, at the {} \
         reference configurations (as the thesis) and at the {} equilibria halfway \
         between them (beyond the thesis). \"IBM-u + tangents\" (beyond the thesis) is \
         IBM-u with Q the cubic Hermite interpolant of the references and the \
         equilibrium path's tangents dq/ds there (`InterpolatedBasis::with_tangents`, \
         docs/reduction.md): the natural spline's Q,s is not the path's tangent, which \
         raises the mechanism modes ω1, ω2 near the path's ends and its junction.\n",
        r.freq.points.len(),
        r.freq.between.len()
    );
    let mut t = Table::new(&[
        "mode",
        "IBM-c at the references",
        "IBM-u at the references",
        "IBM-u + tangents at the references",
        "IBM-c halfway",
        "IBM-u halfway",
        "IBM-u + tangents halfway",
    ]);
    for k in 0..ch7::R {
        let cell = |v: usize, between: bool| {
            let (m, x) = median_and_max(&mode_errors(&r.freq, v, k, between));
            format!("{} ({})", pct(m), pct(x))
        };
        t.row(vec![
            format!("ω{}", k + 1),
            cell(1, false),
            cell(0, false),
            cell(2, false),
            cell(1, true),
            cell(0, true),
            cell(2, true),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    s += &figs
        .markdown(|f| f.starts_with("fig7_2") || f.starts_with("fig7_3") || f.starts_with("mech_"));
    let _ = writeln!(s, "## Closed-loop poles at s = 0 (Table 7.2)\n\nPD controllers (7.12) with Table 7.1's gains on the actuator hinges, no gravity, the state-space eigenvalues of the linearization:\n");
    let mut t = Table::new(&[
        "mode",
        "thesis (Hz, ζ)",
        "IBM-u (Hz, ζ)",
        "IBM-u + tangents (Hz, ζ)",
        "unreduced (Hz, ζ)",
    ]);
    for k in 0..2 {
        let f = |p: &[flexmb_linearize::DampedMode]| {
            p.get(k).map_or("–".into(), |m| {
                format!("{}, {:.3}", sig(m.frequency_hz), m.damping_ratio)
            })
        };
        t.row(vec![
            (k + 1).to_string(),
            format!("{}, {:.2}", ch7::THESIS_POLES[k].0, ch7::THESIS_POLES[k].1),
            f(&r.poles[0]),
            f(&r.poles[2]),
            f(&r.poles[1]),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "## Closed-loop response (Figs 7.4–7.7)\n\nFive skew-sine moves (7.13), T = 0.25 s, stopping 0.05 s at the marks of the path, 1.5 s with gravity, 1000 equidistant output steps, Adams (rtol 1e-3, atol 1e-6) for IBM-u; the angle references φx, φy from IBM-u's kinematics with η ≡ 0.\n");
    let mut t = Table::new(&[
        "run",
        "evaluations",
        "thesis",
        "wall time",
        "thesis",
        "reached t",
    ]);
    for run in &r.runs {
        t.row(vec![
            run.label.clone(),
            run.evaluations.to_string(),
            if run.label.starts_with("IBM-u") {
                THESIS_EVALUATIONS.to_string()
            } else {
                "\"millions\"".into()
            },
            format!("{:.1} s", run.seconds),
            if run.label.starts_with("IBM-u") {
                "≈ 1.5 h".into()
            } else {
                "–".into()
            },
            format!(
                "{:.3} s{}",
                run.t.last().copied().unwrap_or(0.0),
                if run.stopped { " (budget)" } else { "" }
            ),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let err = |k: usize| {
        r.reference
            .iter()
            .zip(&r.runs[1].ee)
            .map(|(a, b)| (a[k] - b[k]).abs())
            .fold(0.0, f64::max)
    };
    let _ = writeln!(
        s,
        "Largest tracking errors of IBM-u from the gravity equilibrium: x {} m, y {} m \
         (no integral action: steady errors remain at the stops, as the thesis says).\n",
        sig(err(0)),
        sig(err(1))
    );
    let (f, a) = spectrum(r);
    let pk: Vec<String> = peaks(&f, &a, 0.05)
        .iter()
        .take(6)
        .map(|(f, a)| format!("{} Hz ({} m)", sig(*f), sig(*a)))
        .collect();
    let _ = writeln!(
        s,
        "Peaks of the spectrum of z_eq − z_undef: {} (the thesis: near 65 and 110 Hz, \
         modes 3 and 4, nothing above 180 Hz).\n",
        pk.join(", ")
    );
    s += &figs.markdown(|f| {
        f.starts_with("fig7_4")
            || f.starts_with("fig7_5")
            || f.starts_with("fig7_6")
            || f.starts_with("fig7_7")
    });
    let _ = Path4::new();
    let _ = writeln!(
        s,
        "## Beyond the thesis: two configuration coordinates\n\n\
         The interpolated basis over the end-effector's x and y on the whole 100 × 100 mm \
         workspace (the thesis's recommendation 3), how many reference configurations it \
         needs for ω1–ω8 within 1 %, with and without the equilibrium tangents, and its \
         closed loop on a circle off the path (4.1): `cargo xtask reproduce ch7xy`, \
         `results/ch7xy/report.md` (its own command: its 17 × 17 sweep takes minutes; \
         `cargo xtask reproduce all` runs both).\n"
    );
    s
}
