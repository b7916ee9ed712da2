//! `cargo xtask reproduce ch4`: writes `results/ch4/` (report, curves as
//! CSV, figures as SVG and PNG) for thesis §4.4: the eigenfrequencies of the
//! two-DOF mechanism (the substitute of [`crate::ch4`]) at 50 equilibria
//! along the path (4.1), the modes labelled and tracked, the effect of G_q,
//! the model's size against the thesis's, the constraint diagnosis of its
//! skeleton and the timings.

use crate::ch4::path::Path4;
use crate::ch4::sweep::{self, ModeFeatures, F_MAX};
use crate::ch4::{self, layout::Member};
use crate::curves::StoredCurve;
use crate::models::CurvePoint;
use crate::progress::Progress;
use crate::report::{pct, sig, Figures, Table};
use flexmb_linearize::SweepPoint;
use flexmb_plot::{Plot, Series};
use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

/// Options of the reproduction.
#[derive(Clone, Debug)]
pub struct Ch4Options {
    /// Equilibria along the path (the thesis: 50).
    pub n: usize,
    /// Modes computed per point (those up to [`F_MAX`] are kept).
    pub modes: usize,
}

impl Default for Ch4Options {
    fn default() -> Self {
        Self { n: 50, modes: 12 }
    }
}

/// The modes plotted (Figs 4.14, 4.16): the first eight.
pub const PLOTTED: usize = 8;

/// Points of the stored regression curve: the first ones of the 50-point
/// sweep (the Hermite segment and the start of the circle), recomputed in CI.
pub const REGRESSION_POINTS: usize = 9;

fn io(e: std::io::Error) -> String {
    e.to_string()
}

/// The scene of the committed model.
pub fn fixture_scene(root: &Path) -> std::path::PathBuf {
    root.join("fixtures").join("scenes").join(ch4::SCENE_FILE)
}

/// The fixture directory of the stored curves.
pub fn curve_dir(root: &Path) -> std::path::PathBuf {
    root.join("fixtures").join("curves").join("ch4")
}

/// The points as curve points (x = s) with the first `count` frequencies.
fn curve_points(points: &[SweepPoint], count: usize) -> Vec<CurvePoint> {
    points
        .iter()
        .map(|p| CurvePoint {
            lambda: p.s,
            position: vec![p.s],
            freqs: p.frequencies_hz.iter().take(count).copied().collect(),
            highest: p.frequencies_hz.last().copied().unwrap_or(f64::NAN),
        })
        .collect()
}

/// The provenance of the stored curves.
fn provenance(n: usize) -> Vec<String> {
    vec![
        "thesis §4.4: the two-DOF mechanism (fixtures/scenes/two_dof_mechanism.ron), end-effector held on the path (4.1)".into(),
        format!("first {REGRESSION_POINTS} of {n} equally spaced arc lengths; x = lambda = s (m); rest linearization (E.6), no gravity"),
        "regenerate: cargo xtask regress --chapter ch4 --update".into(),
    ]
}

/// Recomputes the stored regression curve (the first points of the
/// 50-point sweep).
pub fn recompute(root: &Path, _pg: &Progress) -> Result<crate::regress::Recomputed, String> {
    let o = Ch4Options::default();
    let (mech, dofs) = sweep::mechanism(&fixture_scene(root))?;
    let values: Vec<f64> = sweep::path_values(o.n)
        .into_iter()
        .take(REGRESSION_POINTS)
        .collect();
    let points = sweep::run(&mech, dofs, &values, PLOTTED, &|_, _| {})?;
    Ok(crate::regress::Recomputed {
        dir: curve_dir(root),
        curves: vec![StoredCurve::from_points(
            "unreduced",
            &curve_points(&points, PLOTTED),
            0,
            PLOTTED,
        )],
        provenance: provenance(o.n),
    })
}

/// The computed results of the chapter.
pub struct Ch4Results {
    /// The sweep's points.
    pub points: Vec<SweepPoint>,
    /// Its wall time (s).
    pub sweep_seconds: f64,
    /// Per point, the features of its modes.
    pub features: Vec<Vec<ModeFeatures>>,
    /// Per point, the frequencies without G_q.
    pub without_gq: Vec<Vec<f64>>,
    /// Sizes: nodal coordinates, deformations, DOFs, elements.
    pub sizes: [usize; 4],
    /// MAC tracking of the first [`TRACKED`] modes along the path.
    pub tracking: flexmb_linearize::Tracking,
}

/// Modes tracked by MAC along the path: the eight plotted and two more,
/// which modes from above can cross into.
pub const TRACKED: usize = 10;

/// The tracks of the modes: per track, its frequency at each point.
pub fn tracked_frequencies(r: &Ch4Results) -> Vec<Vec<f64>> {
    (0..TRACKED)
        .map(|t| {
            r.points
                .iter()
                .zip(&r.tracking.perms)
                .map(|(p, perm)| p.frequencies_hz[perm[t]])
                .collect()
        })
        .collect()
}

/// Runs the sweep and its analyses on the committed model.
pub fn compute(root: &Path, o: &Ch4Options, pg: &Progress) -> Result<Ch4Results, String> {
    let (mech, dofs) = sweep::mechanism(&fixture_scene(root))?;
    let values = sweep::path_values(o.n);
    let bar = pg.bar(
        "ch4 sweep along the path (equilibria, then modes)",
        2 * o.n as u64,
    );
    let t = Instant::now();
    let points = sweep::run(&mech, dofs, &values, o.modes, &|d, _| bar.set(d as u64))?;
    let sweep_seconds = t.elapsed().as_secs_f64();
    bar.finish();
    let features = points
        .iter()
        .map(|p| sweep::features(&mech, p))
        .collect::<Result<Vec<_>, String>>()?;
    let without_gq = sweep::without_gq(&mech, &points, PLOTTED)?;
    // MAC with the mass of each point, over the first TRACKED shapes
    let sets: Vec<faer::Mat<f64>> = points
        .iter()
        .map(|p| {
            let v = p.modes.as_ref().expect("kept");
            v.subcols(0, TRACKED.min(v.ncols())).to_owned()
        })
        .collect();
    let masses: Vec<faer::Mat<f64>> = points
        .iter()
        .map(|p| p.mass.clone().expect("kept"))
        .collect();
    let tracking = flexmb_linearize::track_modes(&sets, Some(&masses));
    Ok(Ch4Results {
        points,
        sweep_seconds,
        features,
        without_gq,
        sizes: [mech.n_x(), mech.n_eps(), mech.n_dof(), mech.elements.len()],
        tracking,
    })
}

/// Writes the report of §4.4 into `out`.
pub fn reproduce(root: &Path, out: &Path, pg: &Progress) -> Result<(), String> {
    let start = Instant::now();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let o = Ch4Options::default();
    let r = compute(root, &o, pg)?;
    let cdir = out.join("curves");
    StoredCurve::from_points("unreduced", &curve_points(&r.points, o.modes), 0, o.modes)
        .write(&cdir, &provenance(o.n)[..1])
        .map_err(io)?;
    let mut figs = Figures::default();
    figures(&r, out, &mut figs).map_err(io)?;
    let (mech, _) = sweep::mechanism(&fixture_scene(root))?;
    pictures(&mech, &r, out, &mut figs).map_err(io)?;
    let diagnosis = constraint_summary(root)?;
    // the independent check: one base cross-hinge against its stored
    // CalculiX solid (also `cargo xtask hinge4`)
    let hinge = ch4::hinge_check::Comparison::compute(root)?;
    let hinge_section = hinge.section(&mut figs, out).map_err(io)?;
    let wall = start.elapsed().as_secs_f64();
    let mut md = report(&o, &r, &figs, &diagnosis, wall);
    md += &hinge_section;
    std::fs::write(out.join("report.md"), md).map_err(io)
}

/// Dashed vertical lines at the path's marks (Figs 4.14, 4.16).
fn marks(p: &mut Plot, lo: f64, hi: f64) {
    for (i, s) in Path4::new().marks().iter().enumerate() {
        let label = if i == 0 { "s1 … s5" } else { "" };
        p.push(Series::dashed(label, &[*s, *s], &[lo, hi]).with_color((150, 150, 150)));
    }
}

fn figures(r: &Ch4Results, out: &Path, figs: &mut Figures) -> std::io::Result<()> {
    let s: Vec<f64> = r.points.iter().map(|p| p.s).collect();
    let column = |k: usize| -> Vec<f64> {
        r.points
            .iter()
            .map(|p| p.frequencies_hz.get(k).copied().unwrap_or(f64::NAN))
            .collect()
    };
    let mut p = Plot::new(
        "Fig. 4.14: ω1 and ω2 along the path (the actuator modes)",
        "arc length s along the path (4.1) (m)",
        "eigenfrequency (Hz)",
    );
    for k in 0..2 {
        p.push(Series::line(&format!("ω{}", k + 1), &s, &column(k)));
    }
    let top = column(1).iter().fold(0.0f64, |m, v| m.max(*v));
    marks(&mut p, 0.0, top);
    figs.save(&p, out, "fig4_14_omega1_2")?;
    let mut p = Plot::new(
        "Fig. 4.16: ω3–ω8 along the path",
        "arc length s along the path (4.1) (m)",
        "eigenfrequency (Hz)",
    );
    for k in 2..PLOTTED {
        p.push(Series::line(&format!("ω{}", k + 1), &s, &column(k)));
    }
    let top = column(PLOTTED - 1).iter().fold(0.0f64, |m, v| m.max(*v));
    marks(&mut p, 0.0, top);
    figs.save(&p, out, "fig4_16_omega3_8")?;
    // the modes followed by MAC, named by their shape at s = 0
    let mut p = Plot::new(
        "Modes tracked by MAC along the path, named by their shape at s = 0",
        "arc length s along the path (4.1) (m)",
        "eigenfrequency (Hz)",
    );
    for (t, f) in tracked_frequencies(r).iter().enumerate().skip(2) {
        let label = r.features[0][r.tracking.perms[0][t]].label();
        p.push(Series::line(&format!("track {} ({label})", t + 1), &s, f));
    }
    figs.save(&p, out, "tracked_modes")?;
    // the effect of G_q
    let mut p = Plot::new(
        "Eigenfrequencies with and without G_q",
        "arc length s along the path (4.1) (m)",
        "eigenfrequency (Hz)",
    );
    for k in 0..PLOTTED {
        p.push(Series::line(
            &format!("ω{} with G_q", k + 1),
            &s,
            &column(k),
        ));
        let w: Vec<f64> = r.without_gq.iter().map(|f| f[k]).collect();
        p.push(Series::dashed(&format!("ω{} without", k + 1), &s, &w));
    }
    figs.save(&p, out, "gq_effect")?;
    Ok(())
}

/// The sweep point nearest the second mark of the path (a quarter turn on
/// the circle: the end-effector 50 mm from its rest position along +y).
fn deflected_point(r: &Ch4Results) -> usize {
    let m = Path4::new().marks()[1];
    r.points
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1.s - m).abs().total_cmp(&(b.1.s - m).abs()))
        .map(|(i, _)| i)
        .unwrap_or(0)
}

/// The mechanism at rest and deflected (reference overlaid), and modes 3
/// and 4 there (issue 23), drawn by `flexmb_draw` from the sweep's own
/// configurations.
fn pictures(
    mech: &std::sync::Arc<flexmb_model::Mechanism>,
    r: &Ch4Results,
    out: &Path,
    figs: &mut Figures,
) -> std::io::Result<()> {
    use flexmb_draw::{Configuration, DrawOptions, View};
    let at = |i: usize| Configuration {
        mechanism: mech.clone(),
        q: r.points[i].q.clone(),
        x: r.points[i].x.clone(),
        t: 0.0,
        load_scale: 1.0,
    };
    let d = deflected_point(r);
    crate::pictures::save(
        figs,
        out,
        "mech_deflected",
        &at(d),
        &DrawOptions {
            view: Some(View::Xy),
            reference: true,
            title: Some(format!(
                "The mechanism at s = {:.4} m (end-effector 50 mm along +y), the reference lighter",
                r.points[d].s
            )),
            ..Default::default()
        },
    )?;
    for k in [3, 4] {
        for (i, tag, name) in [(0, "rest", "at rest"), (d, "deflected", "deflected")] {
            crate::pictures::save(
                figs,
                out,
                &format!("mech_mode{k}_{tag}"),
                &at(i),
                &DrawOptions {
                    view: Some(View::Iso),
                    mode: Some(k),
                    phases: Some(2),
                    title: Some(format!("Mode {k} {name}")),
                    ..Default::default()
                },
            )?;
        }
    }
    Ok(())
}

/// The constraint diagnosis of the skeleton with and without its releases,
/// as report lines.
fn constraint_summary(root: &Path) -> Result<Vec<String>, String> {
    let dir = root.join("fixtures").join("scenes");
    let mut lines = vec![];
    for (file, what) in [
        (ch4::SKELETON_RIGID_FILE, "without the releases"),
        (ch4::SKELETON_FILE, "with the releases of §4.1.3"),
    ] {
        let scene = flexmb_model::Scene::load(&dir.join(file)).map_err(|e| e.to_string())?;
        let d = scene
            .diagnose_constraints(Some(&dir))
            .map_err(|e| e.to_string())?;
        lines.push(format!(
            "- {what} (`{file}`): {} over-constraint(s), mobility {}{}",
            d.over.len(),
            d.mobility,
            if d.over.is_empty() {
                String::new()
            } else {
                format!(
                    "; {} of them out of the plane of motion",
                    d.over
                        .iter()
                        .filter(|o| matches!(
                            o.direction,
                            flexmb_model::constraints::Direction::Plane { out_of_plane, .. }
                                if out_of_plane > 0.99
                        ))
                        .count()
                )
            }
        ));
    }
    Ok(lines)
}

/// The largest relative change of each plotted frequency along the path:
/// (max − min)/min.
fn variation(r: &Ch4Results, k: usize) -> (f64, f64, f64) {
    let v: Vec<f64> = r.points.iter().map(|p| p.frequencies_hz[k]).collect();
    let lo = v.iter().fold(f64::INFINITY, |m, x| m.min(*x));
    let hi = v.iter().fold(0.0f64, |m, x| m.max(*x));
    (lo, hi, (hi - lo) / lo)
}

/// The largest relative effect of G_q on mode k along the path.
pub fn gq_effect(r: &Ch4Results, k: usize) -> f64 {
    r.points
        .iter()
        .zip(&r.without_gq)
        .map(|(p, w)| ((p.frequencies_hz[k] - w[k]) / p.frequencies_hz[k]).abs())
        .fold(0.0, f64::max)
}

fn report(
    o: &Ch4Options,
    r: &Ch4Results,
    figs: &Figures,
    diagnosis: &[String],
    wall: f64,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Chapter 4: the two-DOF large-stroke compliant mechanism (§4.4)\n\n\
         The mechanism's CAD and hinge positions are lost; this is the documented \
         substitute of `cargo xtask mechanism4` (docs/reproduce.md, \"Chapter 4\"): the \
         thesis's topology, Tables 4.1–4.3, FE-built member superelements. Its numbers \
         are its own; the thesis's claims are checked on it. Run time {wall:.0} s.\n"
    );
    let [nx, ne, nq, nel] = r.sizes;
    let mut t = Table::new(&["", "thesis (SPACAR)", "ours", "ratio"]);
    for (what, thesis, ours) in [
        ("nodal coordinates", 1584.0, nx as f64),
        ("deformation coordinates", 1822.0, ne as f64),
        ("degrees of freedom", 688.0, nq as f64),
    ] {
        t.row(vec![
            what.into(),
            sig(thesis),
            sig(ours),
            sig(ours / thesis),
        ]);
    }
    t.row(vec![
        "elements".into(),
        "235 beams + 23 superelements".into(),
        format!("{nel} (beam chains counted per element, rigid clamps and Euler normalizations included)"),
        "–".into(),
    ]);
    let _ = writeln!(s, "## The model against the thesis's\n\n{}", t.render());
    let mut t = Table::new(&["member", "Table 4.1 length (mm)", "thesis solid elements"]);
    for m in Member::ALL {
        t.row(vec![
            m.name().into(),
            format!("{:.1}", m.length() * 1e3),
            m.thesis_elements().to_string(),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(
        s,
        "## Exact constraint (§4.1.3)\n\nThe kinematic skeleton (rigid members, ideal \
         hinges), diagnosed by `flexmb info --constraints`:\n\n{}\n\nThe thesis: \"nine \
         times overconstrained\" without the releases, three per kinematic loop, all out of \
         the plane; exactly constrained with them, the CrossBar then free to twist.\n",
        diagnosis.join("\n")
    );
    let _ = writeln!(
        s,
        "## Eigenfrequencies along the path\n\n{} equilibria equally spaced in s over the \
         path (4.1) ({:.4} m), the end-effector's x and y held; all DOFs free in the \
         linearization, {} modes per point, those up to {F_MAX} Hz kept (the first eight \
         plotted). Sweep wall time {:.1} s ({:.2} s per point) on this 2-core machine; \
         the thesis: about two hours for its sweep, Ansys about two days.\n",
        o.n,
        Path4::new().length(),
        o.modes,
        r.sweep_seconds,
        r.sweep_seconds / o.n as f64
    );
    let below: Vec<usize> = r
        .points
        .iter()
        .map(|p| p.frequencies_hz.iter().filter(|f| **f <= F_MAX).count())
        .collect();
    let _ = writeln!(
        s,
        "Modes up to {F_MAX} Hz per point: {} to {} (the thesis: the first eight are \
         below 200 Hz).\n",
        below.iter().min().unwrap_or(&0),
        below.iter().max().unwrap_or(&0)
    );
    s += &figs.markdown(|f| f.starts_with("fig4"));
    let _ = writeln!(
        s,
        "## The mechanism and its modes\n\nDrawn by `flexmb_draw` (as `flexmb draw`) from \
         the sweep's own configurations: members as chords between their boundary nodes, \
         sheets as thin boxes of their section; modes 3 (the CrossBar's twist at rest) and \
         4 (the first out-of-plane mode) at rest and deflected, two phases each.\n"
    );
    s += &figs.markdown(|f| f.starts_with("mech_"));
    let mut t = Table::new(&[
        "mode",
        "at s = 0 (Hz)",
        "min along the path",
        "max",
        "(max − min)/min",
        "label at s = 0",
        "largest G_q effect",
    ]);
    for k in 0..PLOTTED {
        let (lo, hi, var) = variation(r, k);
        t.row(vec![
            format!("ω{}", k + 1),
            sig(r.points[0].frequencies_hz[k]),
            sig(lo),
            sig(hi),
            pct(var),
            r.features[0][k].label(),
            pct(gq_effect(r, k)),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "## Mode identification\n\nEach mode is labelled by its kinetic energy: the body group with the largest share (a member, or the hinges of a kind), and whether it moves mostly in or out of the plane of motion (z translations and rotations about in-plane axes). At the marks of the path:\n");
    let marks = Path4::new().marks();
    let mut t = Table::new(&["s (m)", "ω1 … ω8 labels"]);
    for m in std::iter::once(0.0).chain(marks) {
        let i = r
            .points
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1.s - m).abs().total_cmp(&(b.1.s - m).abs()))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let labels: Vec<String> = r.features[i]
            .iter()
            .take(PLOTTED)
            .zip(&r.points[i].frequencies_hz)
            .map(|(f, w)| format!("{} Hz {}", sig(*w), f.label()))
            .collect();
        t.row(vec![sig(r.points[i].s), labels.join("; ")]);
    }
    let _ = writeln!(s, "{}", t.render());
    let tracks = tracked_frequencies(r);
    let mut t = Table::new(&[
        "track",
        "shape at s = 0",
        "shape at the end of the path",
        "at s = 0 (Hz)",
        "min along the path",
        "lowest MAC with the previous point",
    ]);
    let last = r.points.len() - 1;
    for (k, f) in tracks.iter().enumerate() {
        let col0 = r.tracking.perms[0][k];
        let col1 = r.tracking.perms[last][k];
        let conf = r
            .tracking
            .confidence
            .iter()
            .map(|c| c[k])
            .fold(1.0, f64::min);
        t.row(vec![
            (k + 1).to_string(),
            r.features[0][col0].label(),
            r.features[last][col1].label(),
            sig(f[0]),
            sig(f.iter().fold(f64::INFINITY, |m, v| m.min(*v))),
            sig(conf),
        ]);
    }
    let _ = writeln!(
        s,
        "Followed by MAC (mass-weighted, the first {TRACKED} modes, an assignment per \
         step that maximizes the summed MAC with the previous point), the modes keep their \
         shapes along the path while the sorted frequencies change places where they \
         cross:\n\n{}",
        t.render()
    );
    s += &figs.markdown(|f| f == "tracked_modes");
    let _ = writeln!(s, "## The thesis's claims\n");
    let (_, _, v1) = variation(r, 0);
    let (_, _, v2) = variation(r, 1);
    let _ = writeln!(
        s,
        "- ω1 and ω2 \"remain fairly constant along the path\": they vary by {} and {}.",
        pct(v1),
        pct(v2)
    );
    for k in 2..PLOTTED {
        let f0 = r.points[0].frequencies_hz[k];
        let (lo, _, _) = variation(r, k);
        let _ = writeln!(
            s,
            "- ω{}: {} Hz at rest, down to {} Hz along the path ({}).",
            k + 1,
            sig(f0),
            sig(lo),
            pct((lo - f0) / f0)
        );
    }
    let _ = writeln!(
        s,
        "- G_q \"only has a small influence on the first two eigenfrequencies and negligible \
         influence on the higher\": its largest effect is {} on ω1, {} on ω2, at most {} on \
         ω3–ω8.\n",
        pct(gq_effect(r, 0)),
        pct(gq_effect(r, 1)),
        pct((2..PLOTTED).map(|k| gq_effect(r, k)).fold(0.0, f64::max))
    );
    s += &figs.markdown(|f| f == "gq_effect");
    s
}
