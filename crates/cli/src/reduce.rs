//! `flexmb reduce`: builds a reduced model q = G(z) of a scene (thesis
//! chapters 5–6) with one of the fixed basis methods (modal, SVD-modal,
//! per-mode SVD) or the interpolated basis method (MSI or MAC-sorted), and
//! saves it for `flexmb simulate --reduced` and `flexmb sweep --reduced`.
//! Next to the model it writes the reduced eigenfrequencies at the reference
//! configuration and, for the SVD methods, the singular values.

use crate::out::say;
use crate::report::{count_bar, linspace};
use crate::{coords, finite, io_err, Failure};
use clap::ValueEnum;
use flexmb_dynamics::Dynamics;
use flexmb_linearize::{sweep, undamped_modes, SweepOptions, SweepParameter, SweepPoint};
use flexmb_model::{Load, Mechanism};
use flexmb_plot::{write_csv, Plot, Series};
use flexmb_reduction::{
    interpolated_basis_from_sweep, modal_basis, per_mode_svd_basis, svd_modal_basis, SavedBasis,
    SavedModel, SubspaceInterpolation, FINAL_SVD_THRESHOLD, SVD_THRESHOLD,
};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How the basis is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Method {
    /// The first R modes at the reference configuration (thesis (5.21)),
    /// optionally with large coordinates kept (--keep, (5.20)).
    Modal,
    /// The first R modes of each configuration of a sweep, weighted by ω^−a,
    /// one SVD (thesis (5.22)–(5.23)).
    SvdModal,
    /// Modes 1..R over a sweep, an SVD per mode, then an SVD of the collected
    /// vectors (thesis §6.3.2, (6.19)–(6.21)).
    FbmSvd,
    /// Interpolated basis (6.23) along a held degree of freedom s, modes
    /// 2..R+1 by modal subspace interpolation (thesis §6.3.3).
    IbmMsi,
    /// As ibm-msi with MAC-sorted eigenvectors (the thesis's MAC-7).
    IbmMac,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Modal => "modal",
            Method::SvdModal => "svd-modal",
            Method::FbmSvd => "fbm-svd",
            Method::IbmMsi => "ibm-msi",
            Method::IbmMac => "ibm-mac",
        }
    }
    fn is_ibm(self) -> bool {
        matches!(self, Method::IbmMsi | Method::IbmMac)
    }
    fn needs_sweep(self) -> bool {
        self != Method::Modal
    }
    /// Default number of configurations: the thesis's ten for SVD-modal
    /// (§5.4.1) and 300 for the methods of chapter 6 (§6.4).
    fn default_n(self) -> usize {
        match self {
            Method::Modal => 1,
            Method::SvdModal => 10,
            _ => 300,
        }
    }
}

/// Options of `flexmb reduce`.
#[derive(clap::Args)]
pub(crate) struct ReduceArgs {
    /// Scene file (RON). The model is tied to its degrees of freedom: use it
    /// with this scene (or one with the same DOFs, e.g. other loads).
    scene: PathBuf,
    /// How the basis is built.
    #[arg(long, value_enum)]
    method: Method,
    /// modal: the first R modes; svd-modal: the first R modes of each
    /// configuration; fbm-svd: modes 1..R, each SVD'd; ibm-*: R interpolated
    /// modes, i.e. modes 2..R+1 (mode 1 is the motion along s).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    modes: usize,
    /// modal only: degrees of freedom kept as reduced coordinates (the large
    /// coordinates of (5.20)–(5.21)), comma-separated, named as `flexmb info`
    /// prints them.
    #[arg(long, value_delimiter = ',', value_name = "COORD,...")]
    keep: Vec<String>,
    /// svd-modal only: the weight exponent a of ω^−a (5.22) [default: 0].
    #[arg(long, allow_hyphen_values = true)]
    a: Option<f64>,
    /// svd-modal and fbm-svd: keep the singular vectors whose singular value
    /// exceeds this fraction of the sum [default: 0.01, the thesis's 1 %].
    #[arg(long, allow_hyphen_values = true)]
    threshold: Option<f64>,
    /// fbm-svd only: the rule of the last SVD (step 9 of §6.3.2) [default:
    /// 0.005; why: `FINAL_SVD_THRESHOLD` in flexmb-reduction, docs/cli.md].
    #[arg(long, allow_hyphen_values = true)]
    final_threshold: Option<f64>,
    /// The sweep of reference configurations: `load` (the scene's loads
    /// scaled; svd-modal, fbm-svd) or a degree of freedom held along the
    /// sweep (every sweep method; for ibm-* it is s of (6.23)).
    #[arg(long, value_name = "load|COORD")]
    over: Option<String>,
    /// First value of the sweep: a load scale, or the change of the held
    /// degree of freedom from its reference value.
    #[arg(long, allow_hyphen_values = true)]
    from: Option<f64>,
    /// Last value of the sweep.
    #[arg(long, allow_hyphen_values = true)]
    to: Option<f64>,
    /// Number of reference configurations [default: svd-modal 10 (thesis
    /// §5.4.1); fbm-svd, ibm-* 300 (thesis §6.4)].
    #[arg(long, allow_negative_numbers = true)]
    n: Option<usize>,
    /// Time at which the scene's loads (and inputs) are evaluated while the
    /// basis is built; a load sweep needs a time where the loads act.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    t_load: f64,
    /// Build the basis without the scene's gravity (as the thesis does,
    /// §6.4.1); the saved model is used with the scene's gravity.
    #[arg(long)]
    no_gravity: bool,
    /// The model file (RON). MODEL.frequencies.csv and, for the SVD methods,
    /// MODEL.singular_values.csv, .svg and .png are written next to it.
    #[arg(long, value_name = "MODEL.ron")]
    out: PathBuf,
}

/// Rejects options that do not apply to the method, and missing or invalid
/// values, naming the option.
fn check_options(a: &ReduceArgs) -> Result<(), Failure> {
    let m = a.method;
    let mut wrong = vec![];
    if !a.keep.is_empty() && m != Method::Modal {
        wrong.push("--keep (modal only)");
    }
    if a.a.is_some() && m != Method::SvdModal {
        wrong.push("--a (svd-modal only)");
    }
    if a.threshold.is_some() && !matches!(m, Method::SvdModal | Method::FbmSvd) {
        wrong.push("--threshold (svd-modal and fbm-svd)");
    }
    if a.final_threshold.is_some() && m != Method::FbmSvd {
        wrong.push("--final-threshold (fbm-svd only)");
    }
    if !m.needs_sweep() {
        for (given, o) in [
            (a.over.is_some(), "--over"),
            (a.from.is_some(), "--from"),
            (a.to.is_some(), "--to"),
            (a.n.is_some(), "--n"),
        ] {
            if given {
                wrong.push(o);
            }
        }
    }
    if !wrong.is_empty() {
        return Err(Failure::Input(format!(
            "{} not for --method {}{}",
            wrong.join(", "),
            m.name(),
            if m.needs_sweep() {
                ""
            } else {
                " (it uses the modes at the reference configuration, no sweep)"
            }
        )));
    }
    let input = |s: String| Err(Failure::Input(s));
    if a.modes == 0 {
        return input("--modes must be at least 1".into());
    }
    for (v, o) in [
        (a.threshold, "--threshold"),
        (a.final_threshold, "--final-threshold"),
    ] {
        if let Some(v) = v {
            if !(v > 0.0 && v < 1.0) {
                return input(format!(
                    "{o} is a fraction of the sum of the singular values, in (0, 1); got {v}"
                ));
            }
        }
    }
    if !a.t_load.is_finite() || !a.a.unwrap_or(0.0).is_finite() {
        return input("--t-load and --a must be finite".into());
    }
    if m.needs_sweep() {
        let Some(over) = &a.over else {
            return input(format!(
                "--method {} builds its basis from a sweep: give --over {} --from X --to Y",
                m.name(),
                if m.is_ibm() { "COORD" } else { "load|COORD" }
            ));
        };
        let (Some(from), Some(to)) = (a.from, a.to) else {
            return input("--over needs --from and --to".into());
        };
        if !(from.is_finite() && to.is_finite()) || from == to {
            return input(format!(
                "--from and --to must be finite and differ; got {from} and {to}"
            ));
        }
        let n = a.n.unwrap_or(m.default_n());
        if m.is_ibm() {
            if over == "load" {
                return input(format!(
                    "--method {} interpolates along a degree of freedom s held over the sweep \
                     ((6.23)); give --over COORD (e.g. S.x). `--over load` builds the fixed \
                     bases svd-modal and fbm-svd",
                    m.name()
                ));
            }
            if from > to {
                return input(format!(
                    "--method {}: the knots s must increase, give --from < --to",
                    m.name()
                ));
            }
            if n < 3 {
                return input("--n: an interpolated basis needs at least 3 configurations".into());
            }
        } else {
            crate::options::at_least(
                "--n",
                n,
                2,
                "the number of reference configurations, from --from to --to",
            )?;
        }
    }
    Ok(())
}

/// True if some load of the scene is non-zero at time t.
fn loads_act(mech: &Mechanism, t: f64) -> bool {
    mech.loads.iter().any(|l| match l {
        Load::Force { f, function, .. } => function.value(t) != 0.0 && f.iter().any(|v| *v != 0.0),
        Load::PlanarMoment { m, function, .. } => function.value(t) != 0.0 && *m != 0.0,
        Load::SpatialMoment { m, function, .. } => {
            function.value(t) != 0.0 && m.iter().any(|v| *v != 0.0)
        }
    })
}

/// The reference configurations of a sweep method, with their first `modes`
/// mode shapes, and a description of the sweep.
fn reference_sweep(
    mech: &Arc<Mechanism>,
    a: &ReduceArgs,
    modes: usize,
) -> Result<(Vec<SweepPoint>, Option<usize>, String), Failure> {
    // check_options made sure these are given
    let over = a.over.clone().unwrap_or_default();
    let (from, to) = (a.from.unwrap_or(0.0), a.to.unwrap_or(0.0));
    let n = a.n.unwrap_or(a.method.default_n());
    let values = linspace(from, to, n);
    let (param, values, dof, what) = if over == "load" {
        if !loads_act(mech, a.t_load) {
            return Err(Failure::Input(format!(
                "the scene's loads are zero at t = {} s, so a load sweep gives one configuration; \
                 pass --t-load where they act (e.g. the peak of a pulse)",
                a.t_load
            )));
        }
        let what = format!(
            "{n} configurations over load scale [{from}, {to}] at t = {} s",
            a.t_load
        );
        (SweepParameter::LoadScale, values, None, what)
    } else {
        let k = coords::dof_index(mech, &over, "--over")?;
        let q_ref = mech.q0()[k];
        let what = format!("{n} configurations with {over} changed by [{from}, {to}]");
        let values = values.iter().map(|v| q_ref + v).collect();
        (SweepParameter::Dof(k), values, Some(k), what)
    };
    let pb = count_bar(
        2 * n as u64,
        "reference configurations: equilibria, then eigen analyses",
    );
    let start = std::time::Instant::now();
    let opts = SweepOptions {
        values,
        modes,
        t: a.t_load,
        keep_vectors: true,
    };
    let pts = sweep(mech, &param, &opts, &|d, _| pb.set_position(d as u64));
    pb.finish_and_clear();
    let pts = pts.map_err(|e| {
        let s = match dof {
            Some(k) => format!(
                " (s is the value of {over}, whose reference value is {})",
                mech.q0()[k]
            ),
            None => " (s is the load scale)".into(),
        };
        Failure::Compute(format!(
            "the reference sweep did not converge{s}: {e}; narrow --from/--to or use more \
             configurations (--n)"
        ))
    })?;
    say!(
        "reference sweep: {what}, {modes} modes each, in {:.2} s",
        start.elapsed().as_secs_f64()
    );
    Ok((pts, dof, what))
}

/// Relative singular values to report: a label, the values (fraction of the
/// sum, descending) and how many were kept.
struct SingularValues {
    label: String,
    relative: Vec<f64>,
    kept: usize,
}

/// A built model: what goes into the file and what is reported.
struct Built {
    saved: SavedModel,
    singular: Vec<SingularValues>,
}

/// Builds the basis of `a.method` on `mech` (the scene, or the scene without
/// gravity) and wraps it for saving.
fn build(mech: &Arc<Mechanism>, a: &ReduceArgs) -> Result<Built, Failure> {
    let r = a.modes;
    let scene = a.scene.display().to_string();
    let compute = |e: flexmb_reduction::ReductionError| Failure::Compute(e.to_string());
    let input = |e: flexmb_reduction::ReductionError| Failure::Input(e.to_string());
    let q0 = mech.q0();
    let no_g = if a.no_gravity {
        ", basis built without gravity"
    } else {
        ""
    };
    Ok(match a.method {
        Method::Modal => {
            let keep: Vec<usize> = a
                .keep
                .iter()
                .map(|c| coords::dof_index(mech, c, "--keep"))
                .collect::<Result<_, _>>()?;
            if let Some(c) = (0..keep.len()).find(|&i| keep[..i].contains(&keep[i])) {
                return Err(Failure::Input(format!(
                    "--keep lists '{}' twice",
                    a.keep[c]
                )));
            }
            let b = modal_basis(mech, a.t_load, &q0, r, (!keep.is_empty()).then_some(&keep))
                .map_err(input)?;
            let kept = if keep.is_empty() {
                String::new()
            } else {
                format!(", keeping {}", a.keep.join(", "))
            };
            let d = format!(
                "modal: first {r} modes at the reference configuration (t = {} s){kept}{no_g}",
                a.t_load
            );
            Built {
                saved: SavedModel::fixed(&d, &scene, mech, &b),
                singular: vec![],
            }
        }
        Method::SvdModal => {
            let (pts, _, what) = reference_sweep(mech, a, r)?;
            let (w, th) = (a.a.unwrap_or(0.0), a.threshold.unwrap_or(SVD_THRESHOLD));
            let s = svd_modal_basis(&q0, &pts, r, w, th).map_err(compute)?;
            let kept = s.basis.v.ncols();
            let d = format!(
                "svd-modal: first {r} modes at {what}, weights ω^-{w}, {kept} singular vectors above {th} of the sum{no_g}"
            );
            Built {
                saved: SavedModel::fixed(&d, &scene, mech, &s.basis),
                singular: vec![SingularValues {
                    label: "relative".into(),
                    relative: s.relative,
                    kept,
                }],
            }
        }
        Method::FbmSvd => {
            let (pts, _, what) = reference_sweep(mech, a, r)?;
            let th = a.threshold.unwrap_or(SVD_THRESHOLD);
            let fth = a.final_threshold.unwrap_or(FINAL_SVD_THRESHOLD);
            let modes: Vec<usize> = (0..r).collect();
            let p = per_mode_svd_basis(&q0, &pts, &modes, th, fth).map_err(compute)?;
            let kept = p.basis.v.ncols();
            let d = format!(
                "fbm-svd: modes 1..{r} at {what}, per-mode SVD above {th}, final SVD above {fth}: {kept} vectors{no_g}"
            );
            let mut singular: Vec<SingularValues> = p
                .per_mode
                .iter()
                .map(|(j, rel, k)| SingularValues {
                    label: format!("mode{}", j + 1),
                    relative: rel.clone(),
                    kept: *k,
                })
                .collect();
            singular.push(SingularValues {
                label: "final".into(),
                relative: p.final_relative.clone(),
                kept,
            });
            Built {
                saved: SavedModel::fixed(&d, &scene, mech, &p.basis),
                singular,
            }
        }
        Method::IbmMsi | Method::IbmMac => {
            let (pts, dof, what) = reference_sweep(mech, a, r + 1)?;
            let (how, m) = if a.method == Method::IbmMsi {
                (
                    "modal subspace interpolation (mass-normalized)",
                    SubspaceInterpolation::Msi,
                )
            } else {
                ("MAC-sorted eigenvectors", SubspaceInterpolation::MacSorted)
            };
            let k = dof.ok_or_else(|| Failure::Input("--over COORD needed".into()))?;
            let b =
                interpolated_basis_from_sweep(q0, k, &pts, 1..1 + r, m, true).map_err(compute)?;
            let d = format!(
                "{}: s = {}, {what}, modes 2..{} by {how}{no_g}",
                a.method.name(),
                a.over.as_deref().unwrap_or("?"),
                r + 1
            );
            Built {
                saved: SavedModel::interpolated(&d, &scene, mech, &b),
                singular: vec![],
            }
        }
    })
}

/// `MODEL.ron` → `MODEL.<suffix>`.
fn beside(model: &Path, suffix: &str) -> PathBuf {
    let stem = model
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    model.with_file_name(format!("{stem}.{suffix}"))
}

/// Prints the kept relative singular values and writes them (CSV, SVG in %
/// of the sum, log scale) next to the model.
fn report_singular_values(sv: &[SingularValues], model: &Path) -> Result<Vec<PathBuf>, Failure> {
    if sv.is_empty() {
        return Ok(vec![]);
    }
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.4}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for s in sv {
        finite::check("reduce", s.relative.iter().copied(), |i| {
            format!("relative singular value {} of {}", i + 1, s.label)
        })?;
    }
    say!("relative singular values (fraction of their sum):");
    for s in sv {
        let discarded = s
            .relative
            .get(s.kept)
            .map(|x| format!("; largest discarded {x:.4}"))
            .unwrap_or_default();
        say!(
            "  {:<8} kept {} of {}: {}{discarded}",
            s.label,
            s.kept,
            s.relative.len(),
            fmt(&s.relative[..s.kept.min(s.relative.len())])
        );
    }
    let len = sv.iter().map(|s| s.relative.len()).max().unwrap_or(0);
    let mut header = vec!["index".to_string()];
    header.extend(sv.iter().map(|s| s.label.clone()));
    let rows: Vec<Vec<f64>> = (0..len)
        .map(|i| {
            std::iter::once((i + 1) as f64)
                .chain(
                    sv.iter()
                        .map(|s| s.relative.get(i).copied().unwrap_or(f64::NAN)),
                )
                .collect()
        })
        .collect();
    let kept: Vec<String> = sv
        .iter()
        .map(|s| format!("{} {}", s.label, s.kept))
        .collect();
    let csv = beside(model, "singular_values.csv");
    write_csv(
        &csv,
        &[
            format!(
                "relative singular values (fraction of the sum) of {}",
                model.display()
            ),
            format!("kept: {}", kept.join(", ")),
        ],
        &header,
        &rows,
    )
    .map_err(|e| io_err(e, &csv))?;
    let mut plot = Plot::new(
        &format!("singular values of {}", model.display()),
        "singular vector",
        "singular value relative to the sum",
    )
    .log_y()
    .y_unit("%");
    for s in sv {
        let (k, pc): (Vec<f64>, Vec<f64>) = s
            .relative
            .iter()
            .enumerate()
            .filter(|(_, x)| **x > 0.0)
            .map(|(i, x)| ((i + 1) as f64, 100.0 * x))
            .unzip();
        plot.push(Series::points(&s.label, &k, &pc));
    }
    let svg = beside(model, "singular_values.svg");
    let (svg, png) = plot.save_both(&svg).map_err(|e| io_err(e, &svg))?;
    Ok(vec![csv, svg, png])
}

/// `flexmb reduce`.
pub(crate) fn reduce(a: &ReduceArgs) -> Result<(), Failure> {
    check_options(a)?;
    let (scene, mech) = crate::load(&a.scene)?;
    crate::options::writable_file("--out", &a.out)?;
    say!("{}", mech.summary());
    let basis_mech = if a.no_gravity {
        if scene.gravity.is_none() {
            say!("the scene has no gravity: --no-gravity changes nothing");
        }
        let mut s = scene.clone();
        s.gravity = None;
        Arc::new(
            s.build(a.scene.parent())
                .map_err(|e| Failure::Input(e.to_string()))?,
        )
    } else {
        mech.clone()
    };
    // the modes each configuration (or the reference, for modal) needs
    let needed = match a.method {
        Method::Modal => a.modes + a.keep.len(),
        Method::IbmMsi | Method::IbmMac => a.modes + 1,
        _ => a.modes,
    };
    if needed > mech.n_dof() {
        let what = match a.method {
            Method::Modal if a.keep.is_empty() => format!("{needed} modes"),
            Method::Modal => format!("{needed} reduced coordinates with --keep"),
            _ => format!("{needed} modes per configuration"),
        };
        return Err(Failure::Input(format!(
            "--modes {} needs {what} but the scene has {} degrees of freedom",
            a.modes,
            mech.n_dof()
        )));
    }
    let built = build(&basis_mech, a)?;
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| io_err(e, dir))?;
    }
    let mut files = vec![a.out.clone()];
    files.extend(report_singular_values(&built.singular, &a.out)?);
    // the model as `simulate --reduced` will use it: from the saved data, on
    // the scene with its gravity
    let mut red = built
        .saved
        .into_model(mech.clone())
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let nz = red.n_z();
    say!(
        "reduced model: {nz} coordinates (from {}): {}",
        mech.n_dof(),
        built.saved.description
    );
    let z = red.basis().z_reference();
    let reduced = red
        .frequencies_at_rest(0.0, &z)
        .map_err(|e| Failure::Compute(format!("reduced eigenfrequencies: {e}")))?;
    let mut dy = Dynamics::new(mech.clone());
    let lin = dy
        .linearize_at_rest(0.0, &mech.q0())
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let full = undamped_modes(&lin, nz)
        .map_err(|e| Failure::Compute(e.to_string()))?
        .frequencies_hz();
    say!(
        "eigenfrequencies (Hz) at the reference, t = 0 (unreduced: as `flexmb eig`{}):",
        if matches!(built.saved.basis, SavedBasis::Interpolated { .. }) {
            "; the reduced model at its knot nearest to the reference"
        } else {
            ""
        }
    );
    finite::check("reduce", reduced.iter().copied(), |i| {
        format!("the reduced eigenfrequency of mode {}", i + 1)
    })?;
    finite::check("reduce", full.iter().copied(), |i| {
        format!("the unreduced eigenfrequency of mode {}", i + 1)
    })?;
    say!("  mode        reduced       unreduced  difference");
    let mut rows = vec![];
    for (i, f) in reduced.iter().enumerate() {
        let u = full.get(i).copied().unwrap_or(f64::NAN);
        say!(
            "  {:>4} {f:>14.6}  {u:>14.6}  {:>+9.2e}",
            i + 1,
            (f - u) / u
        );
        rows.push(vec![(i + 1) as f64, *f, u]);
    }
    let csv = beside(&a.out, "frequencies.csv");
    write_csv(
        &csv,
        &[
            format!("undamped eigenfrequencies (Hz) of {} at its reference coordinates, t = 0, the scene's loads and gravity (rest linearization (F.7))", a.out.display()),
            format!("unreduced: the first {nz} of {} at the reference configuration (E.6), as `flexmb eig`", a.scene.display()),
        ],
        &["mode".into(), "reduced_hz".into(), "unreduced_hz".into()],
        &rows,
    )
    .map_err(|e| io_err(e, &csv))?;
    files.push(csv);
    built
        .saved
        .save(&a.out)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    say!("wrote {}", names.join(", "));
    Ok(())
}
