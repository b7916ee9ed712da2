//! The thesis's claims on the unbalanced rotating shaft (§2.4.3, Figs
//! 2.15–2.16, Table 2.2), asserted on our model: two halves built by
//! flexmb's superelement builder from solid FE models, spherical joints of
//! three hinges, the spin-up (2.41) to Ω = 25 rad/s, generalized-α at rtol
//! 1e-6 over 0–20 s (about 1 s per run).

use flexmb_dynamics::Integrator;
use flexmb_element::VelocityTransform::{self, B1, B2, B3};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use xtask::ch2::shaft::{self, Drive, Joined};
use xtask::ch2::shaft_study::{self as study, SpinRun};
use xtask::ch2::spin_up::Integration;

/// Generalized-α at rtol 1e-6, atol 1e-9, as the report's runs.
const GA: Integration = Integration {
    integrator: Integrator::GeneralizedAlpha,
    rtol: 1e-6,
    atol: 1e-9,
};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-shaft-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The halves (default mesh) joined at q and at p, in one directory.
fn halves() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = temp_dir("halves");
        for j in [Joined::AtQ, Joined::AtP] {
            shaft::build_halves(&d, j, shaft::MESH).unwrap();
        }
        d
    })
}

/// The static reference (2.43) with the default mesh, joined at q.
fn reference() -> f64 {
    static DR: OnceLock<f64> = OnceLock::new();
    *DR.get_or_init(|| {
        let s = shaft::scene(B3, Joined::AtQ, Drive::StaticForce);
        shaft::static_reference(&s, halves(), shaft::M_U_THESIS, shaft::OMEGA)
            .unwrap()
            .0
    })
}

/// The six spin-ups (B1, B2, B3 × joined at q, p), run once for all tests.
fn runs() -> &'static [SpinRun] {
    static RUNS: OnceLock<Vec<SpinRun>> = OnceLock::new();
    RUNS.get_or_init(|| {
        let jobs: Vec<(VelocityTransform, Joined)> = [Joined::AtQ, Joined::AtP]
            .iter()
            .flat_map(|&j| [B1, B2, B3].map(|t| (t, j)))
            .collect();
        jobs.par_iter()
            .map(|&(t, j)| {
                study::spin(halves(), t, j, Integrator::GeneralizedAlpha, study::RTOL).unwrap()
            })
            .collect()
    })
}

fn steady(t: VelocityTransform, j: Joined) -> f64 {
    runs()
        .iter()
        .find(|r| r.transform == t && r.joined == j)
        .unwrap()
        .steady()
}

/// Table 2.2's mass check and the static reference:
/// * m_u = ρπd2²/4·l = 0.41351 kg, the 0.4135 kg of (2.43);
/// * Euler–Bernoulli's pinned–guided rods give Δr = 1.36e-3 m;
/// * a half's M̄ has the mass of a rod and half the cylinder within 0.1 %
///   (measured −0.002 %: the mapped discs' area);
/// * our FE static Δr is within 1 % of Euler–Bernoulli's (measured −0.14 %,
///   1.3601e-3 m; the thesis's 1.44e-3 m is 5.9 % above ours, see the
///   report) and the same whichever way the halves are joined (1e-9).
#[test]
fn table_2_2_mass_check_and_the_static_reference() {
    assert!((shaft::cylinder_mass() / 0.4135 - 1.0).abs() < 1e-4);
    let eb = shaft::euler_bernoulli(shaft::M_U_THESIS);
    assert!((eb - 1.36e-3).abs() < 0.005e-3, "Euler–Bernoulli {eb:e}");
    let b = xtask::ch2::segments::shaft_half(
        flexmb_superelement::parts::ShaftHalf::First,
        shaft::L,
        shaft::MESH,
        false,
    )
    .unwrap();
    let m = flexmb_superelement::RigidBodyProperties::from_m_bar(&b.data.m_bar_matrix(), b.data.l0)
        .mass;
    assert!(
        (m / study::half_mass_analytic() - 1.0).abs() < 1e-3,
        "half mass {m} against {}",
        study::half_mass_analytic()
    );
    let dr = reference();
    assert!(
        (dr / eb - 1.0).abs() < 0.03,
        "static Δr {dr:e} against {eb:e}"
    );
    let s = shaft::scene(B3, Joined::AtP, Drive::StaticForce);
    let at_p = shaft::static_reference(&s, halves(), shaft::M_U_THESIS, shaft::OMEGA)
        .unwrap()
        .0;
    assert!(
        (at_p / dr - 1.0).abs() < 1e-9,
        "joined at p {at_p:e}, at q {dr:e}"
    );
}

/// Fig. 2.15, joined at q: only B3 converges to the static reference (within
/// 1 %, measured +0.055 %);
/// B1 and B2 have large steady-state errors (more than 10 %, measured
/// −41.7 % and −22.0 %), B1's the largest.
#[test]
fn joined_at_q_only_b3_is_right_and_b1_errs_most() {
    let dr = reference();
    let e = |t| steady(t, Joined::AtQ) / dr - 1.0;
    eprintln!(
        "joined at q: B1 {:+.3e}, B2 {:+.3e}, B3 {:+.3e}",
        e(B1),
        e(B2),
        e(B3)
    );
    assert!(e(B3).abs() < 0.01, "B3: {:+.2e}", e(B3));
    assert!(e(B2).abs() > 0.1, "B2: {:+.2e}", e(B2));
    assert!(
        e(B1).abs() > e(B2).abs(),
        "B1 {:+.2e} against B2 {:+.2e}",
        e(B1),
        e(B2)
    );
}

/// Fig. 2.16, joined at p: B1 becomes right (within 1 %, measured +0.042 %);
/// "exchanging the p- and q-nodes has no effect" on B2 and B3: their steady
/// states equal those joined at q to 1e-5 (the integration tolerance is
/// 1e-6; measured 1e-10 and 3e-14), so B2 stays wrong and B3 right.
#[test]
fn joined_at_p_b1_becomes_right_and_b2_and_b3_do_not_change() {
    let dr = reference();
    let e = |t| steady(t, Joined::AtP) / dr - 1.0;
    eprintln!(
        "joined at p: B1 {:+.3e}, B2 {:+.3e}, B3 {:+.3e}",
        e(B1),
        e(B2),
        e(B3)
    );
    assert!(e(B1).abs() < 0.01, "B1: {:+.2e}", e(B1));
    assert!(e(B2).abs() > 0.1, "B2: {:+.2e}", e(B2));
    assert!(e(B3).abs() < 0.01, "B3: {:+.2e}", e(B3));
    for t in [B2, B3] {
        let (p, q) = (steady(t, Joined::AtP), steady(t, Joined::AtQ));
        assert!((p / q - 1.0).abs() < 1e-5, "{t:?}: at p {p:e}, at q {q:e}");
    }
}

/// "The energy balance ... remains zero within the simulation error
/// tolerances for all three cases": |T + V − W| over the run, W the drive
/// moment's work, below 1e-5 of the largest T + V in all six runs (rtol
/// 1e-6; measured at most 2.9e-7); and it is no identity: the drive does
/// work (T + V reaches 0.03 J).
#[test]
fn the_energy_balance_holds_for_every_transformation() {
    for r in runs() {
        let (err, scale) = r.response.energy_balance();
        assert!(
            scale > 0.01,
            "{:?} at {}: T + V only {scale:e} J",
            r.transform,
            r.joined.label()
        );
        assert!(
            err < 1e-5 * scale,
            "{:?} joined at {}: |T + V − W| {err:e} J of {scale:e} J",
            r.transform,
            r.joined.label()
        );
    }
}

/// A case the thesis never ran: spun up to 40 rad/s (0.53 of the first
/// critical speed, Δr three times larger), B3 still settles on the static
/// reference at that speed (within 1 %).
#[test]
fn b3_follows_the_static_reference_at_a_higher_speed() {
    let omega = 40.0;
    let s = shaft::scene(B3, Joined::AtQ, Drive::StaticForce);
    let (dr, _) = shaft::static_reference(&s, halves(), shaft::M_U_THESIS, omega).unwrap();
    let spin = shaft::scene(B3, Joined::AtQ, Drive::SpinUp { omega });
    let r = shaft::run(&spin, halves(), GA, 20.0, 2001).unwrap();
    let steady = r.mean_after(study::STEADY_FROM);
    eprintln!("Ω = 40 rad/s: static {dr:e}, B3 {steady:e}");
    assert!(dr > 2.0 * reference(), "static {dr:e}");
    assert!(
        (steady / dr - 1.0).abs() < 0.01,
        "B3 {steady:e} against {dr:e}"
    );
}

/// Input a user gets wrong: a scene naming a superelement file that is not
/// there fails with an error naming the file, in statics and dynamics.
#[test]
fn a_missing_superelement_file_is_named() {
    let d = temp_dir("missing");
    let s = shaft::scene(B3, Joined::AtQ, Drive::StaticForce);
    let e = shaft::static_reference(&s, &d, shaft::M_U_THESIS, shaft::OMEGA).unwrap_err();
    assert!(e.contains("shaft_half1_q.ron"), "{e}");
    let s = shaft::scene(B1, Joined::AtP, Drive::SpinUp { omega: 25.0 });
    let e = shaft::run(&s, &d, GA, 1.0, 11).unwrap_err();
    assert!(e.contains("shaft_half1_p.ron"), "{e}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The report's section from the six runs: the thesis's numbers beside
/// ours, each run's row, and Figs 2.15a/2.16a as CSV, SVG and PNG whose
/// data are the runs' Δr.
#[test]
fn the_report_section_puts_the_thesis_beside_the_runs() {
    let out = temp_dir("report");
    let r = study::ShaftResults {
        statics: vec![study::StaticRow {
            mesh: shaft::MESH,
            description: "default".into(),
            half_mass: study::half_mass_analytic(),
            dr: reference(),
            iterations: 1,
        }],
        runs: runs().to_vec(),
    };
    let mut md = String::new();
    let mut figs = xtask::report::Figures::default();
    xtask::ch2::shaft_report::section(&out, &r, &mut md, &mut figs).unwrap();
    assert!(md.contains("## Unbalanced shaft (Table 2.2)"));
    assert!(md.contains("1.440e-3"), "the thesis's static Δr");
    assert!(
        md.contains(&format!("{:.4e}", reference())),
        "our static Δr"
    );
    for run in runs() {
        assert!(
            md.contains(&format!("{:.4e}", run.steady())),
            "{:?} at {}: no row",
            run.transform,
            run.joined.label()
        );
    }
    for stem in ["fig2_15a_shaft_joined_q", "fig2_16a_shaft_joined_p"] {
        for ext in ["svg", "png"] {
            let f = out.join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&f)
                    .map(|m| m.len() > 1000)
                    .unwrap_or(false),
                "{}",
                f.display()
            );
        }
        let csv = std::fs::read_to_string(out.join(format!("{stem}.csv"))).unwrap();
        let header = csv.lines().find(|l| !l.starts_with('#')).unwrap();
        assert!(
            header.contains("B1") && header.contains("B3") && header.contains("static"),
            "{header}"
        );
        // the last row's B1 column is that run's last Δr
        let joined = if stem.ends_with('q') {
            Joined::AtQ
        } else {
            Joined::AtP
        };
        let b1 = runs()
            .iter()
            .find(|x| x.transform == B1 && x.joined == joined)
            .unwrap();
        let last: Vec<f64> = csv
            .lines()
            .last()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        let want = *b1.response.dr.last().unwrap();
        assert!(
            (last[1] - want).abs() <= 1e-9 * want,
            "{} against {want}",
            last[1]
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}
