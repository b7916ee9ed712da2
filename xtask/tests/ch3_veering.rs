//! Where modes 4 and 5 of §3.5.1's flexure meet, on the stored curves' mesh
//! (`xtask::ch3::CURVE_MESH`): in the mirror-symmetric layout the bending
//! and torsion modes cross (the smallest ω5 − ω4 goes to zero as the grid is
//! refined around it); with the link's mass lifted off the mirror plane by
//! e (`xtask::ch3::veering`) they veer: the smallest gap converges to a
//! positive value that grows with e, and mode 4 changes from the bending
//! mode to the torsion mode across it, a half-and-half mixture at the
//! closest point.

use xtask::ch3::veering::{measure, Variant};
use xtask::ch3::{build_segment, segment_file, veering_moments, Kind, CURVE_MESH, M_MAX};

fn print(v: &Variant) {
    eprintln!("offset {} m:", v.offset);
    for c in &v.levels {
        eprintln!(
            "  step {:.2e} N m: closest at phi {:+.5}° (M {:+.7}), {:.4} and {:.4} Hz, gap {:.3e}",
            c.step,
            c.phi,
            c.lambda * M_MAX,
            c.f4,
            c.f5,
            c.gap()
        );
    }
    eprintln!(
        "  bending content of mode 4 at the closest point {:.4}",
        v.content_at_closest
    );
    let (first, last) = (v.curve.first().unwrap(), v.curve.last().unwrap());
    eprintln!(
        "  content at phi {:+.2}°: {:.4}; at {:+.2}°: {:.4}",
        first[0], first[3], last[0], last[3]
    );
}

/// Offsets of the mass off the mirror plane (m); 0.02 = h/2, the link
/// attached at the sheet's top edge.
const OFFSETS: [f64; 5] = [0.0, 0.0025, 0.005, 0.01, 0.02];

#[test]
fn modes_4_and_5_cross_when_symmetric_and_veer_when_the_mass_is_off_the_mirror_plane() {
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-veer-{}", std::process::id()));
    let seg = [
        build_segment(&dir, CURVE_MESH, false).unwrap(),
        build_segment(&dir, CURVE_MESH, true).unwrap(),
    ];
    let lambdas: Vec<f64> = veering_moments().iter().map(|m| m / M_MAX).collect();
    let r = measure(
        Kind::SeCw,
        &dir,
        segment_file(Kind::SeCw, &seg),
        &OFFSETS,
        &lambdas,
        5,
    );
    let _ = std::fs::remove_dir_all(&dir);
    let r = r.unwrap();
    for v in &r {
        print(v);
    }
    // the symmetric layout: the smallest gap falls with the grid's step
    // (a crossing: at most its slope, about 2e3 Hz per N m, times the
    // step), from 0.19 Hz on the 5e-4 N m grid to below 1e-4 Hz on the
    // 5e-9 N m one
    let sym = &r[0];
    let (coarse, fine) = (&sym.levels[0], sym.levels.last().unwrap());
    assert!(
        (-3.0..-1.5).contains(&fine.phi),
        "crossing at {}°",
        fine.phi
    );
    assert!(
        fine.step < 1e-8 && fine.gap() < 1e-4 && fine.gap() < 1e-3 * coarse.gap(),
        "{:?}",
        sym.levels
    );
    // (a level may keep the previous closest point: the same gap to the
    // eigensolver's 1e-9 relative, 1e-6 Hz)
    for w in sym.levels.windows(2) {
        assert!(w[1].gap() <= w[0].gap() + 1e-6, "{:?}", sym.levels);
    }
    for v in &r[1..] {
        // a veering: the smallest gap is the same on the last three grids
        // (to 1 %) and far above the crossing's
        let n = v.levels.len();
        let g = v.gap();
        for c in &v.levels[n - 3..] {
            assert!(
                (c.gap() / g - 1.0).abs() < 0.01,
                "offset {}: {:?}",
                v.offset,
                v.levels
            );
        }
        assert!(
            g > 100.0 * fine.gap() && g > 0.01,
            "offset {}: gap {g} Hz",
            v.offset
        );
        // where the symmetric layout's modes cross (to 0.05°)
        let phi = v.levels[n - 1].phi;
        assert!(
            (phi - fine.phi).abs() < 0.05,
            "offset {}: {phi}° against {}°",
            v.offset,
            fine.phi
        );
        // mode 4 is the bending mode at rest, the torsion mode at −4.3°, and
        // half of each where the two come closest
        let (first, last) = (v.curve.first().unwrap(), v.curve.last().unwrap());
        assert!(
            first[3] < 0.01 && last[3] > 0.99,
            "offset {}: {first:?}, {last:?}",
            v.offset
        );
        assert!(
            (0.3..0.7).contains(&v.content_at_closest),
            "offset {}: {}",
            v.offset,
            v.content_at_closest
        );
    }
    // the gap grows with the asymmetry, about in proportion to it (each
    // offset doubles the one before)
    for w in r[1..].windows(2) {
        let ratio = w[1].gap() / w[0].gap();
        assert!(
            (1.5..2.5).contains(&ratio),
            "offsets {} and {}: ratio {ratio}",
            w[0].offset,
            w[1].offset
        );
    }
}
