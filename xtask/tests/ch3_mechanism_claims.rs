//! Chapter 3 §3.5.3's claims on the small compliant mechanism (Figs
//! 3.13–3.16, Tables 3.2, 3.3), with the flexures on the thesis's quarter
//! mesh (10 × 40 × 4, as `cargo xtask reproduce ch3`: the stored curves'
//! coarse mesh is 1.6 % stiffer in the hinge's moment) and the component of
//! §3.5.2 with six normal modes:
//! - 60 DOF; ±0.6 N m turn it by about ±30°; ω2 ≈ 40 Hz at rest;
//! - its frequencies and moments along ±30° follow the stored CalculiX
//!   solid of the same mechanism;
//! - under gravity node 7 sags most at one end of the stroke and least at
//!   rest (Table 3.3), as the solid does;
//! - in the time response, node 7's z from the undeflected configuration
//!   oscillates about the run from the gravity equilibrium at ω2, and the
//!   latter's z departs at the extremes of ϕ, near 0.12 and 0.26 s.

use std::path::PathBuf;
use xtask::ch3::component as comp;
use xtask::ch3::mechanism::{self as mech, Files, Moment};
use xtask::ch3::response as resp;
use xtask::models::Start;

/// The superelements of the mechanism, built once per test binary.
fn built() -> &'static (PathBuf, Files) {
    static BUILT: std::sync::OnceLock<(PathBuf, Files)> = std::sync::OnceLock::new();
    BUILT.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("flexmb-ch3-mechanism-{}", std::process::id()));
        let (mesh, settings) = comp::part(&comp::Geometry::default()).unwrap();
        let model = mesh.assemble("component").unwrap();
        let mut s = settings;
        s.normal_modes = 6;
        let r = flexmb_superelement::build(&model, &s).unwrap();
        std::fs::create_dir_all(&dir).unwrap();
        flexmb_superelement::spec::write_ron(&dir.join(comp::file_of(6)), &r.data).unwrap();
        let o = mech::MechOptions::default();
        let f = mech::build_flexures(&dir, o.mesh, o.segments).unwrap();
        let files = Files {
            segments: o.segments,
            flexure_a: f[0].file.clone(),
            flexure_b: f[1].file.clone(),
            component: comp::file_of(6),
        };
        (dir, files)
    })
}

#[test]
fn the_mechanism_has_60_dofs_turns_30_degrees_and_has_omega2_near_40_hz() {
    let (dir, files) = built();
    let m = mech::mechanism(dir, files, Moment::Static, false).unwrap();
    assert_eq!(m.n_dof(), 60, "thesis: 60");
    let c = mech::sweep(dir, files, 21).unwrap();
    let (first, last) = (&c[0], &c[20]);
    // ±0.6 N m: ±31.0° (the thesis: ±30°)
    for p in [first, last] {
        assert!(
            (28.0..34.0).contains(&p.position[0].abs()),
            "{}°",
            p.position[0]
        );
    }
    assert!(
        (first.position[0] + last.position[0]).abs() < 1e-6,
        "the layout's turn is even in M"
    );
    let rest = &c[10];
    assert_eq!(rest.lambda, 0.0);
    // ω2 = 41.2 Hz (the thesis: "about 40 Hz")
    assert!((rest.freqs[1] / 40.0 - 1.0).abs() < 0.1, "{:?}", rest.freqs);
}

/// Along ±30°, against the stored solid at its ϕ: ω2 … ω6 within 3 % and
/// the holding moment within 2 %; ω1 within 7 %. ω1 is the hinge's rotation
/// on its tangent stiffness, which rises with ϕ faster in the superelement
/// model than in the solid (5.8 % apart at 30°, 1 % at rest), with 4 and 8
/// superelements per flexure alike; the secant (the moment) agrees to 1 %.
#[test]
fn the_mechanism_follows_the_solid_along_the_stroke() {
    let root = xtask::workspace_root();
    let solid = mech::read_solid(&root.join(mech::SOLID)).unwrap();
    for phi in [0.0, 10.0, -10.0, 20.0, -20.0, 30.0, -30.0] {
        assert!(
            solid.iter().any(|p| p.phi == phi),
            "the stored solid has no point at ϕ = {phi}°"
        );
    }
    let phis: Vec<f64> = solid.iter().map(|p| p.phi).collect();
    let (dir, files) = built();
    let se = mech::at_rotations(dir, files, false, &phis).unwrap();
    for (p, q) in se.iter().zip(&solid) {
        eprintln!(
            "ϕ {}°: M {} / {}; {:?} / {:?}",
            q.phi, p.moment, q.moment, p.freqs, q.freqs
        );
        assert!((p.phi - q.phi).abs() < 1e-6);
        if q.phi != 0.0 {
            assert!(
                (p.moment / q.moment - 1.0).abs() < 0.02,
                "ϕ = {}°: M {} against {}",
                q.phi,
                p.moment,
                q.moment
            );
        }
        for k in 0..mech::N_FREQ {
            let e = (p.freqs[k] / q.freqs[k] - 1.0).abs();
            let tol = if k == 0 { 0.07 } else { 0.03 };
            assert!(
                e < tol,
                "ϕ = {}°, ω{}: {} against {}",
                q.phi,
                k + 1,
                p.freqs[k],
                q.freqs[k]
            );
        }
    }
}

/// Table 3.3: node 7's static z under gravity at ϕ = 0 and ±30° (ours; the
/// thesis's ϕ is reversed). It sags least at rest and most at +30°, as in
/// the stored solid. At rest within 1 % of the solid (0.06 % measured). What
/// the deflection adds, z(±30°) − z(0), is the deflected sheets' torsion and
/// out-of-plane compliance: within 10 % of the solid's (6.2 % and 7.5 %
/// measured), as SE-CW has the sheet's torsion frequency within 3.5 % of the
/// solid along §3.5.1's ±40°, i.e. its stiffness within 7 %.
#[test]
fn node_7_sags_most_at_one_end_of_the_stroke() {
    let root = xtask::workspace_root();
    let solid = mech::read_solid(&root.join(mech::SOLID_GRAVITY)).unwrap();
    let (dir, files) = built();
    let se = mech::at_rotations(dir, files, true, &[0.0, -30.0, 30.0]).unwrap();
    let z: Vec<f64> = se.iter().map(|p| p.z7).collect();
    let fe: Vec<f64> = se
        .iter()
        .map(|p| {
            solid
                .iter()
                .find(|q| q.phi == p.target)
                .expect("a solid point at each ϕ")
                .z7
        })
        .collect();
    eprintln!("z7 at 0, -30, +30°: {z:?}, solid {fe:?}");
    assert!(z[2] < z[1] && z[1] < z[0] && z[0] < 0.0, "{z:?}");
    assert!(fe[2] < fe[1] && fe[1] < fe[0] && fe[0] < 0.0, "{fe:?}");
    assert!(
        (z[0] / fe[0] - 1.0).abs() < 0.01,
        "at rest: {} against {}",
        z[0],
        fe[0]
    );
    for k in [1, 2] {
        let (a, b) = (z[k] - z[0], fe[k] - fe[0]);
        assert!(
            (a / b - 1.0).abs() < 0.1,
            "ϕ = {}°: the deflection adds {a}, in the solid {b}",
            se[k].target
        );
    }
}

/// The time responses. Run (ii), from the gravity equilibrium, over 0.3 s
/// with generalized-α (0.02 % of z's range from Adams in the reproduction):
/// ϕ has its first extremes near the thesis's 0.12 and 0.26 s, and z7 there
/// departs from the rest sag, further at ϕ > 0. Run (i), from the undeflected
/// configuration, with Adams over the first 0.05 s: z7 oscillates about run
/// (ii) at ω2 of the configurations it passes (to 2 %).
#[test]
fn the_time_responses_show_the_40_hz_oscillation_and_the_periodic_difference() {
    let (dir, files) = built();
    let mut ga = resp::simulation_options(0.3, 5e-4, 1e-5);
    ga.integrator = flexmb_dynamics::Integrator::GeneralizedAlpha;
    let ii = resp::run(dir, files, Start::Equilibrium, &ga, &|_| {}).unwrap();
    let ext = resp::extremes(&ii.t, &ii.phi);
    eprintln!("run (ii): extremes of ϕ {ext:?}");
    assert!(ext.len() >= 2);
    let (max, min) = (ext[0], ext[1]);
    assert_eq!((max.2, min.2), (1, -1));
    assert!(
        (0.10..0.14).contains(&max.0) && (0.24..0.28).contains(&min.0),
        "{ext:?}"
    );
    assert!(
        (25.0..31.0).contains(&max.1) && (-31.0..-25.0).contains(&min.1),
        "{ext:?}"
    );
    let z = |t: f64| xtask::report::interpolate(&ii.t, &ii.z7, t);
    let rest = ii.z7[0];
    assert!(
        z(max.0) < z(min.0) && z(min.0) < 1.5 * rest,
        "z7 {} at rest, {} at ϕ max, {} at ϕ min",
        rest,
        z(max.0),
        z(min.0)
    );
    // run (i), the first 0.05 s with the thesis's integrator
    let adams = resp::simulation_options(resp::WINDOW, 5e-4, 1e-3);
    let i = resp::run(dir, files, Start::Reference, &adams, &|_| {}).unwrap();
    let sweep = mech::sweep(dir, files, 41).unwrap();
    let c = resp::response_claims(&i, &ii, &resp::omega2_of(&sweep), resp::WINDOW);
    let w = c.windows[0];
    eprintln!("run (i) - run (ii): {c:?}");
    assert!(
        (w.2 / w.3 - 1.0).abs() < 0.02,
        "{} Hz against ω2 {} Hz",
        w.2,
        w.3
    );
    assert!(c.mean_difference.abs() < 0.1 * c.amplitude, "{c:?}");
    assert!(
        c.amplitude > 0.5 * rest.abs(),
        "the sudden gravity's oscillation is of the size of the sag: {c:?}"
    );
}
