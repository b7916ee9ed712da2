//! Chapter 3 §3.5.1's claims on the short sheet flexure (Figs 3.10–3.11),
//! on the stored curves' mesh (`xtask::ch3::CURVE_MESH`):
//! - ω1 and ω3 agree for SE-C and SE-CW, and for NLB once its beam has the
//!   wide sheet's plate modulus;
//! - ω2 (torsion) is far too low for NLB (free warping at the clamped ends)
//!   and far too high for SE-C (warping suppressed at every interface),
//!   with SE-CW between them;
//! - the flexure turns by about ±40° at ±0.4 N m.

use xtask::ch3::{compute, Ch3Options, Kind, CURVE_MESH};
use xtask::progress::Progress;

#[test]
fn the_short_sheet_flexure_shows_the_thesis_pattern() {
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-claims-{}", std::process::id()));
    let o = Ch3Options {
        mesh: CURVE_MESH,
        n_moments: 11,
    };
    let r = compute(&dir, &o, &Progress::hidden());
    let _ = std::fs::remove_dir_all(&dir);
    let (curves, _) = r.unwrap();
    let get = |k: Kind| &curves.iter().find(|c| c.0 == k).unwrap().1;
    let (nlb, sec, secw) = (get(Kind::Nlb), get(Kind::SeC), get(Kind::SeCw));
    for i in 0..nlb.len() {
        eprintln!(
            "phi {:+6.1}° ({:+6.1}, {:+6.1}): NLB {:?}, SE-C {:?}, SE-CW {:?}",
            nlb[i].position[0],
            sec[i].position[0],
            secw[i].position[0],
            nlb[i].freqs,
            sec[i].freqs,
            secw[i].freqs
        );
    }
    let rel = |a: f64, b: f64| (a / b - 1.0).abs();
    // ±0.4 N m turns the superelement flexure by about ±43° (the thesis
    // ±40°; EI of the beam alone gives 48.5°)
    for i in [0, nlb.len() - 1] {
        let phi = secw[i].position[0].abs();
        assert!((38.0..46.0).contains(&phi), "phi = {phi}°");
    }
    // the bending modes ω1 and ω3 do not involve warping: SE-C and SE-CW agree
    for i in 0..nlb.len() {
        for k in [0, 2] {
            assert!(
                rel(sec[i].freqs[k], secw[i].freqs[k]) < 1e-6,
                "point {i}, ω{}: SE-C {}, SE-CW {}",
                k + 1,
                sec[i].freqs[k],
                secw[i].freqs[k]
            );
        }
    }
    // the beam agrees with them at rest once given the plate modulus of the
    // wide sheet, E/(1 − ν²) with ν = E/2G − 1 (the solid has the Poisson
    // term, the beam has none): a factor √(1/(1 − ν²)) on ω1 and ω3
    let nu: f64 = 2.1e11 / (2.0 * 8e10) - 1.0;
    let plate = (1.0 / (1.0 - nu * nu)).sqrt();
    let rest = nlb.len() / 2;
    for k in [0, 2] {
        let f = nlb[rest].freqs[k] * plate;
        assert!(
            rel(f, secw[rest].freqs[k]) < 0.01
                && rel(nlb[rest].freqs[k], secw[rest].freqs[k]) > 0.03,
            "ω{} at rest: NLB × plate factor {f}, SE-CW {}",
            k + 1,
            secw[rest].freqs[k]
        );
    }
    // ω2, the torsion mode: far too low for NLB, far too high for SE-C
    for i in 0..nlb.len() {
        let w2 = [nlb[i].freqs[1], secw[i].freqs[1], sec[i].freqs[1]];
        assert!(
            w2[0] < 0.9 * w2[1] && w2[2] > 1.5 * w2[1],
            "point {i}, ω2 NLB, SE-CW, SE-C: {w2:?}"
        );
    }
}

/// "SE-CW is correct over the full range of motion": on the thesis's
/// quarter mesh (10 × 40 × 4), SE-CW is within 5 % of the stored CalculiX
/// solid (20 × 20 × 2, the whole flexure) on ω1–ω4 at every stored moment,
/// while NLB and SE-C are off by more than 40 % on the torsion modes. 5 %:
/// the solid itself moves by up to 3.4 % between its 8 × 8 × 1 and
/// 20 × 20 × 2 meshes (fixtures/curves/solid), so a tighter bound would test
/// the reference's mesh more than the superelement.
#[test]
fn se_cw_follows_the_solid_over_the_whole_range() {
    let root = xtask::workspace_root();
    let solid = xtask::ch3::read_solid(&root).unwrap();
    assert_eq!(solid.len(), 9, "M = 0, ±0.1 … ±0.4 N m");
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-solid-{}", std::process::id()));
    let r = compute(&dir, &Ch3Options::default(), &Progress::hidden());
    let _ = std::fs::remove_dir_all(&dir);
    let (curves, _) = r.unwrap();
    let get = |k: Kind| &curves.iter().find(|c| c.0 == k).unwrap().1;
    let mut worst = [[0.0f64; 4]; 3];
    for p in &solid {
        for (ki, k) in Kind::ALL.iter().enumerate() {
            let c = xtask::ch3::at_moment(get(*k), p.m).unwrap();
            for j in 0..4 {
                worst[ki][j] = worst[ki][j].max((c.freqs[j] / p.freqs[j] - 1.0).abs());
            }
        }
        // the same rotation to 1°
        let c = xtask::ch3::at_moment(get(Kind::SeCw), p.m).unwrap();
        assert!(
            (c.position[0] - p.phi).abs() < 1.0,
            "M = {}: ϕ {} against {}",
            p.m,
            c.position[0],
            p.phi
        );
    }
    eprintln!("largest errors against the solid (NLB, SE-C, SE-CW; ω1–ω4): {worst:?}");
    assert!(worst[2].iter().all(|w| *w < 0.05), "SE-CW: {:?}", worst[2]);
    assert!(
        worst[0][1] > 0.4 && worst[1][1] > 0.4 && worst[1][3] > 0.4,
        "{worst:?}"
    );
}

/// Where modes 4 and 5 of the flexure meet (the thesis: "start to veer …
/// around 2 degrees"), on the stored curves' mesh along the refined moments
/// −0.04 … 0 N m: SE-CW's ω4 and ω5 come closest between −3° and −1.5°
/// (our sign of ϕ, the thesis's reversed), within a tenth of their distance
/// at rest; on either side SE-CW's bending mode is SE-C's exactly (it has no
/// warping), in fourth place above and fifth below; SE-C's torsion mode stays
/// far above. The stored solid's ω4 and ω5 come closest among its samples
/// within 1° of SE-CW's point.
#[test]
fn modes_4_and_5_of_the_flexure_meet_near_minus_2_degrees() {
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-meet-{}", std::process::id()));
    let segments: Vec<xtask::ch3::Segment> = [false, true]
        .iter()
        .map(|w| xtask::ch3::build_segment(&dir, CURVE_MESH, *w).unwrap())
        .collect();
    let lambdas: Vec<f64> = xtask::ch3::veering_moments()
        .iter()
        .map(|m| m / xtask::ch3::M_MAX)
        .collect();
    let get = |k: Kind| {
        xtask::ch3::curve_at(k, &dir, xtask::ch3::segment_file(k, &segments), &lambdas, 6).unwrap()
    };
    let (sec, secw) = (get(Kind::SeC), get(Kind::SeCw));
    let _ = std::fs::remove_dir_all(&dir);
    let (phi, f4, f5) = xtask::ch3::closest_approach(&secw).unwrap();
    let rest = secw.last().unwrap();
    assert!(rest.lambda == 0.0);
    eprintln!(
        "SE-CW: closest at phi = {phi}°: {f4} and {f5} Hz; at rest {:?}",
        rest.freqs
    );
    assert!((-3.0..-1.5).contains(&phi), "phi = {phi}°");
    assert!(
        f5 - f4 < 0.1 * (rest.freqs[4] - rest.freqs[3]),
        "{f4}, {f5} against {:?} at rest",
        rest.freqs
    );
    for (a, b) in secw.iter().zip(&sec) {
        let d = a.position[0] - phi;
        let j = if d > 0.1 {
            3
        } else if d < -0.1 {
            4
        } else {
            continue;
        };
        let e = (a.freqs[j] / b.freqs[3] - 1.0).abs();
        assert!(
            e < 1e-9,
            "phi = {}°: SE-CW ω{} {} against SE-C's bending ω4 {}",
            a.position[0],
            j + 1,
            a.freqs[j],
            b.freqs[3]
        );
    }
    for p in &sec {
        assert!(
            p.freqs[4] > 1.3 * p.freqs[3],
            "SE-C at {}°: {:?}",
            p.position[0],
            p.freqs
        );
    }
    let root = xtask::workspace_root();
    let solid = xtask::ch3::read_solid_file(&root.join(xtask::reproduce3::VEERING_SOLID)).unwrap();
    let q = solid
        .iter()
        .min_by(|a, b| (a.freqs[4] - a.freqs[3]).total_cmp(&(b.freqs[4] - b.freqs[3])))
        .unwrap();
    eprintln!("solid: closest sample at {}°: {:?}", q.phi, q.freqs);
    assert!((q.phi - phi).abs() < 1.0, "solid {}°, SE-CW {phi}°", q.phi);
}
