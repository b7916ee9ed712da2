//! `cargo xtask reproduce ch3`: writes `results/ch3/` (report, curves as
//! CSV, figures as SVG and PNG, the superelement files and scenes) for §3.5:
//! the short sheet flexure of §3.5.1 ([`crate::ch3`]) with the veering of its
//! modes 4 and 5, the component with normal modes of §3.5.2
//! ([`crate::ch3::component`]) and the small compliant mechanism of §3.5.3
//! ([`crate::ch3::mechanism`]), each against a stored CalculiX solid, and a
//! speed-against-error table.

mod component;
mod mechanism;

use crate::ch3::component as comp;
use crate::ch3::mechanism::{self as mech, Files, MechOptions};
use crate::ch3::response as resp;
use crate::ch3::veering as veer;
use crate::ch3::{self, Ch3Options, Kind};
use crate::models::{CurvePoint, Start};
use crate::progress::Progress;
use crate::report::{Figures, Table};
use flexmb_plot::{Plot, Series};
use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

fn io(e: std::io::Error) -> String {
    e.to_string()
}

/// A computation's result with its wall time (s).
pub(crate) struct Timed<T> {
    pub(crate) value: T,
    pub(crate) seconds: f64,
}

fn timed<T>(f: impl FnOnce() -> Result<T, String>) -> Result<Timed<T>, String> {
    let start = Instant::now();
    let value = f()?;
    Ok(Timed {
        value,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Everything §3.5.1 computes.
struct Flexure {
    o: Ch3Options,
    curves: ch3::Curves,
    segments: Vec<ch3::Segment>,
    sweep_seconds: Vec<f64>,
    dofs: Vec<(Kind, usize)>,
    /// SE-C and SE-CW along [`ch3::veering_moments`], six frequencies.
    veering: Vec<(Kind, Vec<CurvePoint>)>,
    /// SE-CW's modes 4 and 5 with the mass off the mirror plane
    /// ([`ch3::veering::measure`]) and its wall time (s).
    asymmetric: Timed<Vec<veer::Variant>>,
}

/// Runs §3.5 on the thesis's meshes and writes the report into `out`; the
/// solid references are read from `root` (`fixtures/curves/solid/`).
pub fn reproduce(root: &Path, out: &Path, pg: &Progress) -> Result<(), String> {
    let start = Instant::now();
    let load = crate::report::load_average_phrase();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let o = Ch3Options::default();
    let mo = MechOptions::default();
    let geometry = comp::Geometry::default();
    // the superelements (and §3.5.1's sweeps), in parallel
    let (flexure, (component, flexures)) = rayon::join(
        || ch3::compute_timed(out, &o, pg),
        || {
            rayon::join(
                || timed(|| comp::compute(out, &geometry, pg)),
                || mech::build_flexures(out, mo.mesh, mo.segments),
            )
        },
    );
    let (curves, segments, sweep_seconds) = flexure?;
    let component = component?;
    let flexures = flexures?;
    let cf6 = component
        .value
        .models
        .iter()
        .find(|m| m.normal_modes == 6)
        .ok_or("no SE-CF6 model")?;
    let files = Files {
        segments: mo.segments,
        flexure_a: flexures[0].file.clone(),
        flexure_b: flexures[1].file.clone(),
        component: cf6.file.clone(),
    };
    // the two time responses with the thesis's integrator take longest: each
    // on a thread of its own while the rest runs
    let adams = resp::simulation_options(mo.t_end, mo.dt, 1e-3);
    let (run_i, run_ii, rest) = std::thread::scope(|sc| {
        let i = sc.spawn(|| resp::run_with_bar(out, &files, Start::Reference, &adams, pg));
        let ii = sc.spawn(|| resp::run_with_bar(out, &files, Start::Equilibrium, &adams, pg));
        let rest = the_rest(root, out, &mo, &geometry, &segments, &files, pg);
        let join = |h: std::thread::ScopedJoinHandle<'_, Result<resp::Run, String>>| {
            h.join()
                .unwrap_or_else(|_| Err("a time response panicked".into()))
        };
        (join(i), join(ii), rest)
    });
    let (run_i, run_ii, rest) = (run_i?, run_ii?, rest?);
    let dofs = Kind::ALL
        .iter()
        .map(|k| {
            let s = flexmb_model::Scene::from_ron_str(&ch3::scene(
                *k,
                ch3::segment_file(*k, &segments),
            ))
            .map_err(|e| e.to_string())?;
            let m = s.build(Some(out)).map_err(|e| e.to_string())?;
            Ok((*k, m.n_dof()))
        })
        .collect::<Result<_, String>>()?;
    let flexure = Flexure {
        o,
        curves,
        segments,
        sweep_seconds,
        dofs,
        veering: rest.veering,
        asymmetric: rest.asymmetric,
    };
    let solid = ch3::read_solid(root)?;
    let veer_solid = read_veering_solid(root)?;
    let cl = resp::response_claims(
        &run_i,
        &run_ii,
        &resp::omega2_of(&rest.sweep.value),
        resp::WINDOW,
    );
    let extreme_phis: Vec<f64> = cl.phi_extremes.iter().take(2).map(|e| e.1).collect();
    let at_extremes = mech::at_rotations(out, &files, true, &extreme_phis)?;
    let dof = mech::mechanism(out, &files, mech::Moment::Static, false)?.n_dof();
    let mechanism = mechanism::Computed {
        options: mo,
        files,
        flexures,
        dof,
        at_extremes,
        sweep: rest.sweep,
        at_solid: rest.at_solid,
        table_3_3: rest.table_3_3,
        solid: mech::read_solid(&root.join(mech::SOLID))?,
        solid_gravity: mech::read_solid(&root.join(mech::SOLID_GRAVITY))?,
        runs: [run_i, run_ii],
        check: rest.check,
    };
    let component_solid = comp::read_solid(root)?;
    let mut figs = Figures::default();
    let mut md = String::new();
    let s1 = flexure_section(out, root, &flexure, &solid, &veer_solid, &mut figs)?;
    let s2 = component::section(&component, &rest.converged, &component_solid);
    let s3 = mechanism::section(out, &mechanism, &mut figs)?;
    let speed = speed_table(&flexure, &solid, &component, &component_solid, &mechanism);
    let drawn = crate::pictures3::draw(
        out,
        ch3::segment_file(Kind::SeCw, &flexure.segments),
        out,
        &mut figs,
    )?;
    let wall = start.elapsed().as_secs_f64();
    let _ = writeln!(
        md,
        "# Chapter 3 (§3.5): superelements with deformable interfaces and normal modes\n"
    );
    let _ = writeln!(
        md,
        "Generated by `cargo xtask reproduce ch3` in {wall:.0} s on this machine ({load}, {} threads; the two time responses of §3.5.3 ran on threads of their own beside everything else, which is the critical path). The CalculiX solids are read from `fixtures/curves/solid/` (their commands and run times are in its README).\n",
        rayon::current_num_threads()
    );
    md.push_str(&s1);
    md.push_str(&crate::pictures3::section(&figs, &drawn));
    md.push_str(&s2);
    md.push_str(&s3);
    md.push_str(&speed);
    let _ = writeln!(md, "## Figures\n");
    let _ = writeln!(md, "{}", figs.markdown(|f| !f.starts_with("mech_")));
    std::fs::write(out.join("report.md"), md).map_err(io)
}

/// What runs beside the time responses.
struct Rest {
    veering: Vec<(Kind, Vec<CurvePoint>)>,
    asymmetric: Timed<Vec<veer::Variant>>,
    sweep: Timed<Vec<CurvePoint>>,
    at_solid: Timed<Vec<mech::AtRotation>>,
    table_3_3: Timed<Vec<mech::AtRotation>>,
    check: Timed<resp::Run>,
    converged: Timed<Vec<f64>>,
}

fn the_rest(
    root: &Path,
    out: &Path,
    mo: &MechOptions,
    geometry: &comp::Geometry,
    segments: &[ch3::Segment],
    files: &Files,
    pg: &Progress,
) -> Result<Rest, String> {
    let lambdas: Vec<f64> = ch3::veering_moments()
        .iter()
        .map(|m| m / ch3::M_MAX)
        .collect();
    let solid_phis: Vec<f64> = mech::read_solid(&root.join(mech::SOLID))?
        .iter()
        .map(|p| p.phi)
        .collect();
    let bar = pg.bar("ch3: sweeps and equilibria", 6);

    let ((veering, sweep), ((at_solid, table_3_3), (check, converged))) = rayon::join(
        || {
            rayon::join(
                || {
                    [Kind::SeC, Kind::SeCw]
                        .iter()
                        .map(|k| {
                            ch3::curve_at(*k, out, ch3::segment_file(*k, segments), &lambdas, 6)
                                .map(|c| (*k, c))
                        })
                        .collect::<Result<Vec<_>, String>>()
                        .and_then(|v| {
                            let file = ch3::segment_file(Kind::SeCw, segments);
                            let a = timed(|| {
                                veer::measure(Kind::SeCw, out, file, &veer::OFFSETS, &lambdas, 5)
                            })?;
                            Ok((v, a))
                        })
                        .map(|v| tick(&bar, v))
                },
                || tick(&bar, timed(|| mech::sweep(out, files, mo.n_moments))),
            )
        },
        || {
            rayon::join(
                || {
                    rayon::join(
                        || {
                            tick(
                                &bar,
                                timed(|| mech::at_rotations(out, files, false, &solid_phis)),
                            )
                        },
                        || {
                            tick(
                                &bar,
                                timed(|| {
                                    mech::at_rotations(out, files, true, &mech::TABLE_3_3_PHI)
                                }),
                            )
                        },
                    )
                },
                || {
                    rayon::join(
                        || {
                            let mut ga = resp::simulation_options(mo.t_end, mo.dt, 1e-5);
                            ga.integrator = flexmb_dynamics::Integrator::GeneralizedAlpha;
                            tick(
                                &bar,
                                timed(|| resp::run(out, files, Start::Equilibrium, &ga, &|_| {})),
                            )
                        },
                        || {
                            tick(
                                &bar,
                                timed(|| comp::full_frequencies(geometry, [2.5e-3; 2], 6)),
                            )
                        },
                    )
                },
            )
        },
    );
    bar.finish();
    let (veering, asymmetric) = veering?;
    Ok(Rest {
        veering,
        asymmetric,
        sweep: sweep?,
        at_solid: at_solid?,
        table_3_3: table_3_3?,
        check: check?,
        converged: converged?,
    })
}

fn tick<T>(bar: &crate::progress::Bar, r: T) -> T {
    bar.inc();
    r
}

/// The stored solid of the flexure at small moments (the veering).
pub const VEERING_SOLID: &str = "fixtures/curves/solid/flexure_ch3_veering_20x20x2.csv";

fn read_veering_solid(root: &Path) -> Result<Vec<ch3::SolidPoint>, String> {
    ch3::read_solid_file(&root.join(VEERING_SOLID))
}

fn of(curves: &[(Kind, Vec<CurvePoint>)], k: Kind) -> &[CurvePoint] {
    curves
        .iter()
        .find(|c| c.0 == k)
        .map(|c| c.1.as_slice())
        .unwrap_or(&[])
}

/// §3.5.1: writes its curves and figures and returns its part of the report.
fn flexure_section(
    out: &Path,
    root: &Path,
    f: &Flexure,
    solid: &[ch3::SolidPoint],
    veer_solid: &[ch3::SolidPoint],
    figs: &mut Figures,
) -> Result<String, String> {
    let (o, curves, segments, dofs) = (&f.o, &f.curves, &f.segments, &f.dofs);
    let cdir = out.join("curves");
    for (k, c) in curves {
        crate::curves::StoredCurve::from_points(k.label(), c, 0, ch3::N_FREQ)
            .write(
                &cdir,
                &[format!(
                    "thesis §3.5.1, {}; x = the end's rotation phi (degrees)",
                    k.label()
                )],
            )
            .map_err(io)?;
    }
    for k in 0..ch3::N_FREQ {
        let mut p = Plot::new(
            &format!("Fig. 3.10: ω{} of the short sheet flexure", k + 1),
            "rotation ϕ of the flexure's end (°)",
            &format!("ω{} (Hz)", k + 1),
        );
        for (kind, c) in curves {
            let (x, y): (Vec<f64>, Vec<f64>) = c
                .iter()
                .filter(|p| p.freqs.len() > k)
                .map(|p| (p.position[0], p.freqs[k]))
                .unzip();
            p.push(Series::line(kind.label(), &x, &y));
        }
        let (x, y): (Vec<f64>, Vec<f64>) = solid
            .iter()
            .filter(|p| p.freqs.len() > k)
            .map(|p| (p.phi, p.freqs[k]))
            .unzip();
        p.push(Series::points("FE (CalculiX solid)", &x, &y));
        figs.save(&p, out, &format!("fig3_10_omega{}", k + 1))
            .map_err(io)?;
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## §3.5.1: the short sheet flexure over ±40° (Figs 3.10, 3.11)\n"
    );
    let _ = writeln!(s, "### Set-up\n");
    let _ = writeln!(s, "* Flexure l = h = {} m, t = {} m, steel E = 2.1e11 Pa, G = 8e10 Pa (ν = E/2G − 1 = 0.3125 in the solid), ρ = 7800 kg/m³ (Fig. 3.9). One end clamped; the other carries an L-shaped massless rigid link, 0.25 m along x and 0.1 m across, with a 0.01 kg point mass at its end.", ch3::L, ch3::T);
    let _ = writeln!(s, "* Layout (lost with Fig. 3.9; our choice): the flexure along x, its height along y, its thickness along z; the link to (0.29, 0, 0) and the mass at (0.29, 0, −0.1). The moment M about y acts at the flexure's end; {} equilibria from M = −{m} to +{m} N m by continuation from M = 0. ϕ is the end's rotation about y.", o.n_moments, m = ch3::M_MAX);
    let _ = writeln!(s, "* Superelements: a quarter of the flexure meshed with {} × {} × {} twenty-node hexahedra (x, height, thickness; the thesis's 1600 Solid186 \"in cubic configuration\", 4 through the thickness), built by flexmb's builder: SE-C with constraint modes only, SE-CW with the warping modes (3.4) at both interfaces, shared at the three inner interfaces and fixed at both ends. Build: {}.", o.mesh[0], o.mesh[1], o.mesh[2], segments.iter().map(|g| format!("`{}` {} equations, {:.1} s", g.file, g.equations, g.seconds)).collect::<Vec<_>>().join("; "));
    let _ = writeln!(
        s,
        "* NLB: 4 of the thesis's spatial beams, Rectangle {} × {} m, elongation free.",
        ch3::H,
        ch3::T
    );
    let mut t = Table::new(&[
        "model",
        "DOF (ours)",
        "DOF (thesis)",
        "ϕ at −0.4 N m (°)",
        "ϕ at +0.4 N m (°)",
    ]);
    for (k, n) in dofs {
        let c = of(curves, *k);
        let phi = |p: Option<&CurvePoint>| {
            p.map(|p| format!("{:+.1}", p.position[0]))
                .unwrap_or_else(|| "–".into())
        };
        t.row(vec![
            k.label().into(),
            n.to_string(),
            match k {
                Kind::SeCw => "27",
                _ => "24",
            }
            .into(),
            phi(c.first()),
            phi(c.last()),
        ]);
    }
    let _ = writeln!(s, "\n{}", t.render());
    let end = |k: Kind| {
        of(curves, k)
            .last()
            .map(|p| p.position[0])
            .unwrap_or(f64::NAN)
    };
    let _ = writeln!(s, "The thesis reaches ±40° (FE). Our superelements turn by ±{:.1}°, the beams by ±{:.1}°: EI = Eht³/12 gives Ml/EI = 48.5° at 0.4 N m, and the solid sheet, as wide as it is long, bends as a plate (E/(1 − ν²) gives 43.8°).\n", end(Kind::SeCw), end(Kind::Nlb));
    let _ = writeln!(
        s,
        "### Eigenfrequencies along the deflection (Figs 3.10a, b)\n"
    );
    let mut header = vec!["M (N m)".to_string()];
    for k in Kind::ALL {
        header.push(format!("{} ϕ (°)", k.label()));
        for j in 1..=ch3::N_FREQ {
            header.push(format!("ω{j}"));
        }
    }
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&hdr);
    let n = of(curves, Kind::Nlb).len();
    let step = (n / 8).max(1);
    for i in (0..n)
        .step_by(step)
        .chain(std::iter::once(n - 1))
        .collect::<std::collections::BTreeSet<_>>()
    {
        let mut row = vec![format!(
            "{:+.3}",
            of(curves, Kind::Nlb)[i].lambda * ch3::M_MAX
        )];
        for k in Kind::ALL {
            let p = &of(curves, k)[i];
            row.push(format!("{:+.1}", p.position[0]));
            for j in 0..ch3::N_FREQ {
                row.push(
                    p.freqs
                        .get(j)
                        .map(|f| format!("{f:.2}"))
                        .unwrap_or_else(|| "–".into()),
                );
            }
        }
        t.row(row);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "Data: `curves/*.csv` (every point). The thesis's curves were lost with its figures; its text keeps the pattern below.\n");
    let _ = writeln!(s, "### The thesis's claims\n");
    let (nlb, sec, secw) = (
        of(curves, Kind::Nlb),
        of(curves, Kind::SeC),
        of(curves, Kind::SeCw),
    );
    let rel = |a: f64, b: f64| a / b - 1.0;
    let worst = |f: &dyn Fn(usize) -> f64| (0..n).map(f).fold(0.0f64, |a, v| a.max(v.abs()));
    let bend_c = worst(&|i| {
        rel(sec[i].freqs[0], secw[i].freqs[0])
            .abs()
            .max(rel(sec[i].freqs[2], secw[i].freqs[2]).abs())
    });
    let rest = n / 2;
    let nu: f64 = 2.1e11 / (2.0 * 8e10) - 1.0;
    let plate = (1.0 / (1.0 - nu * nu)).sqrt();
    let _ = writeln!(s, "* **ω1 and ω3 agree for all models.** SE-C and SE-CW: to {:.1e} at every point (bending modes do not involve the warping). NLB at rest: {:+.2} % (ω1) and {:+.2} % (ω3) from SE-CW; with the plate modulus E/(1 − ν²), a factor {plate:.4} on the frequencies, {:+.2} % and {:+.2} %. The beam has no Poisson term and the wide solid sheet bends as a plate; the thesis's SPACAR beams evidently agreed, so they may have used a plate modulus, which the text does not say.", bend_c,
        100.0 * rel(nlb[rest].freqs[0], secw[rest].freqs[0]), 100.0 * rel(nlb[rest].freqs[2], secw[rest].freqs[2]),
        100.0 * rel(plate * nlb[rest].freqs[0], secw[rest].freqs[0]), 100.0 * rel(plate * nlb[rest].freqs[2], secw[rest].freqs[2]));
    let lo = (0..n)
        .map(|i| nlb[i].freqs[1] / secw[i].freqs[1])
        .fold(f64::INFINITY, f64::min);
    let hi_nlb = (0..n)
        .map(|i| nlb[i].freqs[1] / secw[i].freqs[1])
        .fold(0.0f64, f64::max);
    let lo_c = (0..n)
        .map(|i| sec[i].freqs[1] / secw[i].freqs[1])
        .fold(f64::INFINITY, f64::min);
    let hi_c = (0..n)
        .map(|i| sec[i].freqs[1] / secw[i].freqs[1])
        .fold(0.0f64, f64::max);
    let _ = writeln!(s, "* **ω2 (torsion) is much lower for NLB and much higher for SE-C.** Along the whole range, NLB's ω2 is {:.2}–{:.2} × SE-CW's (free warping at the clamped ends) and SE-C's {:.2}–{:.2} × (warping suppressed at l/4, l/2, 3l/4 too). At rest: NLB {:.2} Hz, SE-CW {:.2} Hz, SE-C {:.2} Hz.", lo, hi_nlb, lo_c, hi_c, nlb[rest].freqs[1], secw[rest].freqs[1], sec[rest].freqs[1]);
    let neg = &secw[0];
    let _ = writeln!(s, "* **Mode 4 is torsion on one side and bending on the other.** Ours: at ϕ = {:+.1}° SE-CW's ω4 is {:.1} Hz against SE-C's {:.1} Hz (a torsion mode, which warping lowers), while for ϕ > 0 SE-C and SE-CW have the same ω4 (a bending mode, {:.1} Hz at the end). The thesis has the torsional ω4 at positive ϕ: with our layout the sign of ϕ is the thesis's reversed (both signs are lost with Fig. 3.9).", neg.position[0], neg.freqs[3], sec[0].freqs[3], secw[n - 1].freqs[3]);
    let _ = writeln!(
        s,
        "* **SE-CW follows the FE reference over the whole range.** See the next section.\n"
    );
    let _ = writeln!(s, "`xtask/tests/ch3_claims.rs` asserts the first three claims on the stored curves' mesh ({:?}).\n", ch3::CURVE_MESH);
    let _ = writeln!(s, "{}", against_solid(curves, solid));
    s.push_str(&veering_section(out, &f.veering, veer_solid, figs)?);
    s.push_str(&asymmetric_section(out, root, &f.asymmetric, figs)?);
    Ok(s)
}

/// The models against the CalculiX solid at the solid's moments.
fn against_solid(curves: &[(Kind, Vec<CurvePoint>)], solid: &[ch3::SolidPoint]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "### Against the CalculiX solid (FE reference)\n");
    let _ = writeln!(s, "`{}`, made by `research/ch3/flexure.py` (C3D20R, the whole flexure; the end face and the mass node one *RIGID BODY; per moment an NLGEOM static step and a *FREQUENCY perturbation step about the prestressed state; command in `fixtures/curves/solid/README.md`). Frequencies in order of frequency; each model at the same moment.\n", ch3::SOLID);
    let mut header = vec!["M (N m)".to_string(), "FE ϕ (°)".into()];
    for j in 1..=ch3::N_FREQ {
        header.push(format!("FE ω{j} (Hz)"));
    }
    for k in Kind::ALL {
        header.push(format!("{} ϕ", k.label()));
        for j in 1..=ch3::N_FREQ {
            header.push(format!("ω{j}"));
        }
    }
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&hdr);
    let mut worst = vec![[0.0f64; ch3::N_FREQ]; Kind::ALL.len()];
    for p in solid {
        let mut row = vec![format!("{:+.2}", p.m), format!("{:+.1}", p.phi)];
        row.extend(p.freqs.iter().take(ch3::N_FREQ).map(|f| format!("{f:.2}")));
        for (ki, k) in Kind::ALL.iter().enumerate() {
            match ch3::at_moment(of(curves, *k), p.m) {
                Some(c) => {
                    row.push(format!("{:+.1}", c.position[0]));
                    for j in 0..ch3::N_FREQ {
                        let e = c.freqs[j] / p.freqs[j] - 1.0;
                        worst[ki][j] = worst[ki][j].max(e.abs());
                        row.push(format!("{:+.1} %", 100.0 * e));
                    }
                }
                None => row.extend(std::iter::repeat_n("–".to_string(), ch3::N_FREQ + 1)),
            }
        }
        t.row(row);
    }
    let _ = writeln!(s, "{}", t.render());
    let mut t = Table::new(&["model", "largest |error| ω1", "ω2", "ω3", "ω4"]);
    for (ki, k) in Kind::ALL.iter().enumerate() {
        let mut row = vec![k.label().to_string()];
        row.extend(worst[ki].iter().map(|w| format!("{:.1} %", 100.0 * w)));
        t.row(row);
    }
    let _ = writeln!(s, "{}", t.render());
    s
}

/// The refined sweep around the veering of modes 4 and 5 (§3.5.1, "around 2
/// degrees") against the solid at the same moments.
fn veering_section(
    out: &Path,
    veering: &[(Kind, Vec<CurvePoint>)],
    solid: &[ch3::SolidPoint],
    figs: &mut Figures,
) -> Result<String, String> {
    let cdir = out.join("curves");
    for (k, c) in veering {
        crate::curves::StoredCurve::from_points(&format!("veering {}", k.label()), c, 0, 6)
            .write(
                &cdir,
                &[format!(
                    "thesis §3.5.1, {}, M = -0.04 ... 0 N m in steps of 0.0005; x = the end's rotation phi (degrees)",
                    k.label()
                )],
            )
            .map_err(io)?;
    }
    let get = |k: Kind| {
        veering
            .iter()
            .find(|c| c.0 == k)
            .map(|c| c.1.as_slice())
            .unwrap_or(&[])
    };
    let (sec, secw) = (get(Kind::SeC), get(Kind::SeCw));
    let mut p = Plot::new(
        "Fig. 3.10b near the veering: ω4 and ω5 of the short sheet flexure",
        "rotation ϕ of the flexure's end (°)",
        "frequency (Hz)",
    );
    for (j, name) in [(3, "SE-CW ω4"), (4, "SE-CW ω5")] {
        let (x, y): (Vec<f64>, Vec<f64>) = secw.iter().map(|p| (p.position[0], p.freqs[j])).unzip();
        p.push(Series::line(name, &x, &y));
    }
    let (x, y): (Vec<f64>, Vec<f64>) = sec.iter().map(|p| (p.position[0], p.freqs[3])).unzip();
    p.push(Series::dashed("SE-C ω4 (bending)", &x, &y));
    for j in [3, 4] {
        let (x, y): (Vec<f64>, Vec<f64>) = solid
            .iter()
            .filter(|p| p.freqs.len() > j)
            .map(|p| (p.phi, p.freqs[j]))
            .unzip();
        p.push(Series::points(
            &format!("FE (CalculiX solid) ω{}", j + 1),
            &x,
            &y,
        ));
    }
    figs.save(&p, out, "fig3_10b_veering").map_err(io)?;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "### Where modes 4 and 5 meet, near −2° (Figs 3.10b, 3.11)\n"
    );
    let _ = writeln!(s, "The thesis: for negative deflections mode 4 is a bending mode with the torsion mode above it, and the two \"start to veer with each other around 2 degrees deflection\". Refined sweep: M = −0.04 … 0 N m in steps of 0.0005 N m ({} points, `curves/veering_se_c*.csv`), and the CalculiX solid at M = 0, −0.01, −0.015, −0.02, −0.025, −0.03, −0.04 N m (`{VEERING_SOLID}`); figure `fig3_10b_veering`.\n", secw.len());
    if let Some((phi, f4, f5)) = ch3::closest_approach(secw) {
        // SE-CW's ω4 (above the meeting) or ω5 (below) against SE-C's bending ω4
        let worst = |side: f64, j: usize| {
            secw.iter()
                .zip(sec)
                .filter(|(a, _)| side * (a.position[0] - phi) > 0.1)
                .map(|(a, b)| (a.freqs[j] / b.freqs[3] - 1.0).abs())
                .fold(0.0f64, f64::max)
        };
        let (above, below) = (worst(1.0, 3), worst(-1.0, 4));
        let _ = writeln!(s, "* **SE-CW**: ω4 and ω5 come closest at ϕ = {phi:+.2}° ({f4:.1} and {f5:.1} Hz, {:.2} Hz apart on this grid). The thesis's \"around 2 degrees\" (its sign of ϕ is the reverse of ours, see above). From 0.1° above that point SE-CW's ω4 equals SE-C's bending ω4 to {above:.1e}, from 0.1° below it SE-CW's ω5 does, to {below:.1e}: mode 4 changes there from the bending mode to the torsion mode. The bending mode has no warping at all (SE-C has none), so it does not couple with the torsion mode: in our layout the two are of opposite symmetry about the flexure's mid-plane y = 0 (the link's leg lies in the plane of bending, docs/reproduce.md), and their frequencies cross rather than veer.", f5 - f4);
    }
    if let Some(p) = sec
        .iter()
        .min_by(|a, b| (a.freqs[4] - a.freqs[3]).total_cmp(&(b.freqs[4] - b.freqs[3])))
    {
        let _ = writeln!(s, "* **SE-C** keeps its torsion mode far above (smallest ω5 − ω4 = {:.0} Hz, at ϕ = {:+.2}°): its rigid interfaces suppress the warping inside the flexure too.", p.freqs[4] - p.freqs[3], p.position[0]);
    }
    let mut t = Table::new(&[
        "M (N m)",
        "FE ϕ (°)",
        "FE ω4 (Hz)",
        "FE ω5 (Hz)",
        "FE ω5 − ω4",
        "SE-CW ω4",
        "SE-CW ω5",
        "SE-CW ω5 − ω4",
    ]);
    for q in solid.iter().filter(|q| q.freqs.len() >= 5) {
        let near = secw.iter().min_by(|a, b| {
            (a.lambda * ch3::M_MAX - q.m)
                .abs()
                .total_cmp(&(b.lambda * ch3::M_MAX - q.m).abs())
        });
        let mut row = vec![
            format!("{:+.3}", q.m),
            format!("{:+.2}", q.phi),
            format!("{:.1}", q.freqs[3]),
            format!("{:.1}", q.freqs[4]),
            format!("{:.1}", q.freqs[4] - q.freqs[3]),
        ];
        match near {
            Some(c) if (c.lambda * ch3::M_MAX - q.m).abs() < 1e-9 => {
                row.push(format!("{:.1}", c.freqs[3]));
                row.push(format!("{:.1}", c.freqs[4]));
                row.push(format!("{:.1}", c.freqs[4] - c.freqs[3]));
            }
            _ => row.extend(std::iter::repeat_n("–".to_string(), 3)),
        }
        t.row(row);
    }
    let _ = writeln!(s, "\n{}", t.render());
    if let Some(q) = solid
        .iter()
        .filter(|q| q.freqs.len() >= 5)
        .min_by(|a, b| (a.freqs[4] - a.freqs[3]).total_cmp(&(b.freqs[4] - b.freqs[3])))
    {
        let se = ch3::closest_approach(secw).map_or(f64::NAN, |c| c.0);
        let _ = writeln!(s, "The solid's ω5 − ω4 falls from {:.1} Hz at ϕ = 0 to {:.1} Hz at ϕ = {:+.2}° and rises again further out: the same meeting of the two modes, {:.2}° from SE-CW's (the solid's samples are 0.56° apart).\n", solid.iter().find(|q| q.m == 0.0).map_or(f64::NAN, |q| q.freqs[4] - q.freqs[3]), q.freqs[4] - q.freqs[3], q.phi, q.phi - se);
    }
    Ok(s)
}

/// The asymmetric variant of §3.5.1's layout (the mass lifted off the
/// mirror plane): SE-CW's modes 4 and 5 veer; against the CalculiX solid.
fn asymmetric_section(
    out: &Path,
    root: &Path,
    a: &Timed<Vec<veer::Variant>>,
    figs: &mut Figures,
) -> Result<String, String> {
    let v = &a.value;
    let sym = v.first().ok_or("no symmetric layout")?;
    let cross = sym.levels.last().ok_or("no refinement")?;
    let mut csv = String::from(
        "# thesis §3.5.1, SE-CW with the mass at y = offset; M within ±0.001 N m of the symmetric layout's crossing; content = MAC of mode 4 with the symmetric layout's bending mode\noffset_m,M,phi_deg,f4_Hz,f5_Hz,bending_content_4\n",
    );
    let mut gap_plot = Plot::new(
        "Modes 4 and 5 near their meeting: ω5 − ω4 with the mass off the mirror plane by e",
        "ϕ − ϕ× (°), ϕ× the symmetric layout's crossing",
        "ω5 − ω4 (Hz)",
    );
    let mut content_plot = Plot::new(
        "Mode 4's bending content (MAC with the symmetric layout's bending mode)",
        "ϕ − ϕ× (°)",
        "MAC",
    );
    for w in v {
        for p in &w.curve {
            let _ = writeln!(
                csv,
                "{},{:.9e},{:.9},{:.9},{:.9},{:.6}",
                w.offset, p[0], p[1], p[2], p[3], p[4]
            );
        }
        let name = format!("e = {} mm", 1e3 * w.offset);
        let x: Vec<f64> = w.curve.iter().map(|p| p[1] - cross.phi).collect();
        let g: Vec<f64> = w.curve.iter().map(|p| p[3] - p[2]).collect();
        let c: Vec<f64> = w.curve.iter().map(|p| p[4]).collect();
        gap_plot.push(Series::line(&name, &x, &g));
        content_plot.push(Series::line(&name, &x, &c));
    }
    std::fs::create_dir_all(out.join("curves")).map_err(io)?;
    std::fs::write(out.join("curves/veering_offsets.csv"), csv).map_err(io)?;
    figs.save(&gap_plot, out, "fig3_10c_veering_gap")
        .map_err(io)?;
    figs.save(&content_plot, out, "fig3_10d_veering_content")
        .map_err(io)?;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "#### A layout that breaks the mirror symmetry: the modes veer\n"
    );
    let _ = writeln!(s, "Fig. 3.9 is lost, and a link attached off the sheet's mid-height is as plausible a reading of it as ours. SE-CW (the same superelements) with the link's tip and the mass lifted by e along the sheet's height, to (0.29, e, −0.1) (`ch3::scene_with_offset`; e = 20 mm = h/2 is the link attached at the sheet's top edge). The link is massless and there is no gravity, so the equilibria are those of e = 0 and only the inertia changes. For each e the smallest ω5 − ω4 on grids refined around it ({} points over the two intervals around the previous grid's closest point, the step shrinking tenfold per level from 0.0005 N m), and, on ±{} N m around the symmetric crossing ({} points, `curves/veering_offsets.csv`, figures `fig3_10c_veering_gap`, `fig3_10d_veering_content`), mode 4's bending content: its MAC (weighted by the mass matrix) with the symmetric layout's bending mode at the same moment. {:.1} s for the five layouts.\n", veer::PER_LEVEL, veer::ZOOM, veer::ZOOM_POINTS, a.seconds);
    let mut header = vec!["e (mm)".to_string()];
    header.extend(
        sym.levels
            .iter()
            .map(|c| format!("gap (Hz), step {:.0e} N m", c.step)),
    );
    header.extend([
        "ϕ at the closest (°)".into(),
        "gap / e (Hz/m)".into(),
        "bending content of mode 4 there".into(),
    ]);
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&hdr);
    for w in v {
        let mut row = vec![format!("{}", 1e3 * w.offset)];
        row.extend(w.levels.iter().map(|c| format!("{:.3e}", c.gap())));
        let last = w.levels.last().map_or(f64::NAN, |c| c.phi);
        row.push(format!("{last:+.4}"));
        row.push(if w.offset > 0.0 {
            format!("{:.2}", w.gap() / w.offset)
        } else {
            "–".into()
        });
        // at the symmetric layout's own crossing its bending mode is not
        // defined (the two modes are degenerate there)
        row.push(if w.offset > 0.0 {
            format!("{:.3}", w.content_at_closest)
        } else {
            "–".into()
        });
        t.row(row);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "* **e = 0 crosses**: the smallest gap falls with the step (at most the slope, about 2e3 Hz per N m, times the step), to {:.1e} Hz at ϕ = {:+.4}°, and mode 4 is purely one mode or the other on either side.", cross.gap(), cross.phi);
    let _ = writeln!(s, "* **e > 0 veers**: the smallest gap settles at a positive value on the finer grids, about in proportion to e (the coupling is the offset mass's inertia between the torsion and the bending motion), and mode 4 goes from the bending mode (content → 1 towards ϕ = 0) to the torsion mode (→ 0) through a half-and-half mixture at the closest point: the modes exchange their shapes instead of passing each other. The veering is narrow (the gap is a few hundredths of a per cent of ω4): the 0.01 kg mass barely moves in these modes, whose energy is in the flexure.");
    let se_variant = v.iter().find(|w| w.offset == veer::SOLID_OFFSET_E);
    let se = se_variant.map_or(f64::NAN, veer::Variant::gap);
    let (f4, phi_se) = se_variant
        .and_then(|w| w.levels.last())
        .map_or((f64::NAN, f64::NAN), |c| (c.f4, c.phi));
    let finest = veer::SOLIDS.last().ok_or("no solid")?;
    let phi_solid = veer::solid_closest(&ch3::read_solid_file(&root.join(finest.offset))?)
        .map_or(f64::NAN, |p| p.phi);
    let _ = writeln!(s, "* **The CalculiX solid** (`research/ch3/flexure.py --refine`, the moments refined around the closest sample; its frequencies are printed to 0.001 Hz) veers too where the mass is off the mirror plane, and crosses where it is not. SE-CW's gap for the same e = {} mm is {se:.3} Hz, {:.2} % of its ω4 there: a little over half the solid's (table), a small quantity set by the point mass's small share in two modes dominated by the flexure, at meetings {:.1}° apart (the solid's meeting lies further out, as at e = 0).\n", 1e3 * veer::SOLID_OFFSET_E, 100.0 * se / f4, (phi_solid - phi_se).abs());
    let mut t = Table::new(&[
        "solid mesh",
        "decks (e = 0, e = 20 mm)",
        "e = 0: smallest ω5 − ω4 (Hz)",
        "at ϕ (°)",
        "e = 20 mm: smallest ω5 − ω4 (Hz)",
        "at ϕ (°)",
        "SE-CW's gap / the solid's",
    ]);
    for pair in &veer::SOLIDS {
        let read = |f: &str| ch3::read_solid_file(&root.join(f));
        let (ssym, soff) = (read(pair.symmetric)?, read(pair.offset)?);
        if let (Some(cs), Some(co)) = (veer::solid_closest(&ssym), veer::solid_closest(&soff)) {
            let g = co.freqs[4] - co.freqs[3];
            t.row(vec![
                pair.mesh.into(),
                format!("{}, {}", ssym.len(), soff.len()),
                format!("{:.3}", cs.freqs[4] - cs.freqs[3]),
                format!("{:+.3}", cs.phi),
                format!("{g:.3}"),
                format!("{:+.3}", co.phi),
                format!("{:.2}", se / g),
            ]);
        }
    }
    let _ = writeln!(s, "{}", t.render());
    Ok(s)
}

/// Speed against error for the whole chapter: each model's cost (DOF, wall
/// time, equilibria and eigen-analyses or evaluations) against its largest
/// error with respect to the CalculiX solid.
fn speed_table(
    f: &Flexure,
    solid: &[ch3::SolidPoint],
    component: &Timed<comp::Component>,
    component_solid: &[f64],
    m: &mechanism::Computed,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## Speed against error\n");
    let _ = writeln!(s, "Wall times on this machine (the §3.5.1 sweeps ran three at a time, so each time is that of a shared core; the load at the start is in the header). For a sweep, \"work\" counts its equilibria (each a Newton solve by continuation) and eigen-analyses; for a time response, the right-hand-side (or residual) evaluations. Errors are the largest relative deviations from the CalculiX solid over the frequencies named, at the solid's points (§3.5.1: M = 0, ±0.1 … ±0.4 N m; §3.5.3: ϕ = {}°).\n", m.solid.iter().map(|q| format!("{:+.0}", q.phi)).collect::<Vec<_>>().join(", "));
    let mut t = Table::new(&[
        "§",
        "model",
        "DOF",
        "what",
        "work",
        "wall time (s)",
        "largest error w.r.t. the solid",
    ]);
    for ((k, c), secs) in f.curves.iter().zip(&f.sweep_seconds) {
        let mut w = [0.0f64; ch3::N_FREQ];
        for p in solid {
            if let Some(q) = ch3::at_moment(c, p.m) {
                for j in 0..ch3::N_FREQ {
                    w[j] = w[j].max((q.freqs[j] / p.freqs[j] - 1.0).abs());
                }
            }
        }
        let dof = f.dofs.iter().find(|d| d.0 == *k).map_or(0, |d| d.1);
        t.row(vec![
            "3.5.1".into(),
            k.label().into(),
            dof.to_string(),
            format!("sweep, {} points", c.len()),
            format!("{} + {}", c.len(), c.len()),
            format!("{secs:.2}"),
            w.iter()
                .enumerate()
                .map(|(j, e)| format!("ω{} {:.1} %", j + 1, 100.0 * e))
                .collect::<Vec<_>>()
                .join(", "),
        ]);
    }
    let a = component::assigned(&component.value, component_solid);
    for (mdl, asg) in component.value.models.iter().zip(&a) {
        let missing: Vec<String> = (0..comp::N_FREQ)
            .filter(|k| asg[*k].is_none())
            .map(|k| (k + 1).to_string())
            .collect();
        let worst = (0..comp::N_FREQ)
            .filter_map(|k| asg[k].map(|v| (v / component_solid[k] - 1.0).abs()))
            .fold(0.0f64, f64::max);
        t.row(vec![
            "3.5.2".into(),
            mdl.name.clone(),
            mdl.dof.to_string(),
            "build + eigen-analysis at rest".into(),
            "1".into(),
            format!("{:.2} + {:.3}", mdl.build_seconds, mdl.eigen_seconds),
            format!(
                "{:.2} % on the modes it has{}",
                100.0 * worst,
                if missing.is_empty() {
                    String::new()
                } else {
                    format!("; no mode {}", missing.join(", "))
                }
            ),
        ]);
    }
    let w = mechanism::worst_against_solid(m);
    let worst = w
        .iter()
        .enumerate()
        .map(|(j, e)| format!("ω{} {:.1} %", j + 1, 100.0 * e))
        .collect::<Vec<_>>()
        .join(", ");
    t.row(vec![
        "3.5.3".into(),
        "SE".into(),
        m.dof.to_string(),
        format!("sweep, {} points", m.sweep.value.len()),
        format!("{0} + {0}", m.sweep.value.len()),
        format!("{:.2}", m.sweep.seconds),
        worst,
    ]);
    t.row(vec![
        "3.5.3".into(),
        "SE".into(),
        m.dof.to_string(),
        format!("at the solid's {} ϕ (secant on M)", m.at_solid.value.len()),
        format!(
            "{} + {}",
            m.at_solid.value.iter().map(|p| p.solves).sum::<usize>(),
            m.at_solid.value.len()
        ),
        format!("{:.2}", m.at_solid.seconds),
        "(the same points)".into(),
    ]);
    let (dz, dp) = mechanism::integrator_difference(m);
    for (name, r) in [
        ("run (i), Adams", &m.runs[0]),
        ("run (ii), Adams", &m.runs[1]),
        ("run (ii), generalized-α", &m.check.value),
    ] {
        t.row(vec![
            "3.5.3".into(),
            "SE".into(),
            m.dof.to_string(),
            format!("time response {name}, {} s", m.options.t_end),
            r.evaluations.to_string(),
            format!("{:.1}", r.wall_time),
            if name.contains("generalized") {
                format!(
                    "z7 {:.2} % of its range, ϕ {:.3}° from Adams",
                    100.0 * dz,
                    dp
                )
            } else if name.starts_with("run (ii)") {
                "(reference of the line below)".into()
            } else {
                "–".into()
            },
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "The CalculiX solids cost minutes per point (fixtures/curves/solid/README.md: the flexure 1–11 min per moment on 20 × 20 × 2, the mechanism 1.4–18.5 min per ϕ without gravity and up to 46 min with it, on one shared core); the superelement models give a whole sweep in seconds.\n");
    s
}
