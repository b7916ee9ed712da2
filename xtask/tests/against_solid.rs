//! Issue 22's regression: the chapter-6 guidance with warping beams
//! (fixtures/scenes/straight_guidance_spatial_warping.ron) within 2 % of the
//! stored CalculiX solid's f2 and f3 (fixtures/curves/solid) at every stored
//! stroke, where the thesis's beam, converged (n = 20), is more than 10 %
//! below it.

use xtask::progress::Progress;
use xtask::solid6::{run, stored_solids, strokes, BeamModel};

/// Two guidance scenes (`(name, fixture, n)`) swept in parallel through the
/// strokes `xs`.
fn run_pair(
    xs: &[f64],
    a: (&str, &str, Option<usize>),
    b: (&str, &str, Option<usize>),
) -> (BeamModel, BeamModel) {
    let root = xtask::workspace_root();
    let pg = Progress::hidden();
    let (ra, rb) = rayon::join(
        || run(&root, a.0, a.1, a.2, xs, &pg),
        || run(&root, b.0, b.1, b.2, xs, &pg),
    );
    (ra.unwrap(), rb.unwrap())
}

#[test]
fn the_warping_guidance_holds_the_solid_curves_within_2_percent() {
    let root = xtask::workspace_root();
    let (solid, _) = stored_solids(&root).unwrap();
    let xs = strokes(&solid);
    assert!(xs.len() >= 5 && xs.last() > Some(&0.08), "{xs:?}");
    let (plain, warped) = run_pair(
        &xs,
        ("beams n = 20", "straight_guidance_spatial.ron", Some(20)),
        ("warping", "straight_guidance_spatial_warping.ron", None),
    );
    let mut worst = [0.0f64; 2];
    let mut worst_plain = [0.0f64; 2];
    for (i, (x, s)) in solid.points.iter().enumerate() {
        let gap = |f: &[f64], k: usize| f[k] / s[k] - 1.0;
        eprintln!(
            "x_S = {x}: solid f2 {:.3}, f3 {:.3} Hz; beam − solid: St-Venant {:+.2} %, {:+.2} %; warping {:+.2} %, {:+.2} %",
            s[1],
            s[2],
            100.0 * gap(&plain.freqs[i], 1),
            100.0 * gap(&plain.freqs[i], 2),
            100.0 * gap(&warped.freqs[i], 1),
            100.0 * gap(&warped.freqs[i], 2),
        );
        for k in 0..2 {
            worst[k] = worst[k].max(gap(&warped.freqs[i], k + 1).abs());
            worst_plain[k] = worst_plain[k].max(gap(&plain.freqs[i], k + 1).abs());
        }
    }
    eprintln!("largest gaps, f2 and f3: St-Venant {worst_plain:?}, warping {worst:?}");
    assert_eq!(warped.dofs, 232);
    for k in 0..2 {
        assert!(
            worst[k] < 0.02 && worst_plain[k] > 0.1,
            "f{}: warping {worst:?}, St-Venant {worst_plain:?}",
            k + 2
        );
    }
}

/// The Poisson share (ν = 0.3 solid): the warping beams with the sheets'
/// anticlastic curl (fixtures/scenes/straight_guidance_spatial_anticlastic.ron)
/// hold the physical solid's f1–f4 within 2 % at every stored stroke (measured
/// ≤ 1.51 %, f3 at 0.0834 m), where the warping beams alone fall 4.1 % below
/// its f1 and 4.0 % below its f3.
#[test]
fn the_anticlastic_guidance_holds_the_physical_solid_within_2_percent() {
    let root = xtask::workspace_root();
    let (_, physical) = stored_solids(&root).unwrap();
    let solid = physical.expect("fixtures/curves/solid/solid_guidance_nu03_50x8x2.csv");
    let xs = strokes(&solid);
    assert!(xs.len() >= 5 && xs.last() > Some(&0.08), "{xs:?}");
    let (warped, curled) = run_pair(
        &xs,
        ("warping", "straight_guidance_spatial_warping.ron", None),
        (
            "anticlastic",
            "straight_guidance_spatial_anticlastic.ron",
            None,
        ),
    );
    assert_eq!(curled.dofs, 308);
    let (mut worst, mut worst_warped) = (0.0f64, 0.0f64);
    for (i, (x, s)) in solid.points.iter().enumerate() {
        let gap = |f: &[f64], k: usize| f[k] / s[k] - 1.0;
        let g: Vec<f64> = (0..4).map(|k| 100.0 * gap(&curled.freqs[i], k)).collect();
        let w: Vec<f64> = (0..4).map(|k| 100.0 * gap(&warped.freqs[i], k)).collect();
        eprintln!(
            "x_S = {x}: model − ν = 0.3 solid, f1 … f4: warping {:+.2} {:+.2} {:+.2} {:+.2} %; anticlastic {:+.2} {:+.2} {:+.2} {:+.2} %",
            w[0], w[1], w[2], w[3], g[0], g[1], g[2], g[3],
        );
        for k in 0..4 {
            worst = worst.max(g[k].abs());
            worst_warped = worst_warped.max(w[k].abs());
        }
    }
    eprintln!(
        "largest gap in f1 … f4 (%): anticlastic {worst:.3}, warping alone {worst_warped:.3}"
    );
    assert!(worst < 2.0 && worst_warped > 3.0, "{worst} {worst_warped}");
}
