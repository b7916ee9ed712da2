//! The pictures of the chapter-3 report (issue 23), on the stored curves'
//! mesh: SE-CW at rest and at ∓0.4 N m and its modes 2 and 4 there, saved
//! as SVG and PNG, each equilibrium where the stored curve has it (the end's
//! rotation ϕ) and each mode drawn at the stored curve's frequency.

use xtask::ch3::{build_segment, fixture_dir, CURVE_MESH};
use xtask::curves::StoredCurve;
use xtask::pictures3::{draw, MODES, MOMENTS};
use xtask::report::Figures;

#[test]
fn the_flexure_pictures_show_the_stored_curves_equilibria_and_modes() {
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-pictures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let seg = build_segment(&dir, CURVE_MESH, true).unwrap();
    let mut figs = Figures::default();
    let drawn = draw(&dir, &seg.file, &dir, &mut figs).unwrap();
    let stored = StoredCurve::read(&fixture_dir(&xtask::workspace_root()), "SE-CW").unwrap();
    assert_eq!(drawn.len(), MOMENTS.len());
    for (m, phi, f) in &drawn {
        let lambda = m / xtask::ch3::M_MAX;
        let i = stored
            .lambda
            .iter()
            .position(|l| (l - lambda).abs() < 1e-9)
            .unwrap();
        println!(
            "M = {m:+.1} N m: ϕ {phi:.4}° (stored {:.4}°), ω {f:?} (stored {:?})",
            stored.x[i], stored.freqs[i]
        );
        assert!(
            (phi - stored.x[i]).abs() < 1e-6,
            "ϕ {phi} against {}",
            stored.x[i]
        );
        for (k, hz) in MODES.iter().zip(f) {
            let want = stored.freqs[i][k - 1];
            assert!(
                (hz / want - 1.0).abs() < 1e-6,
                "mode {k} at M = {m}: {hz} Hz against {want}"
            );
        }
    }
    let mut stems = vec!["mech_deflected".to_string(), "mech_flexure".into()];
    for tag in ["rest", "neg", "pos"] {
        for k in MODES {
            stems.push(format!("mech_mode{k}_{tag}"));
        }
    }
    for s in &stems {
        for ext in ["svg", "png"] {
            let p = dir.join(format!("{s}.{ext}"));
            let size = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
            assert!(size > 10_000, "{} has {size} bytes", p.display());
        }
    }
    let md = figs.markdown(|f| f.starts_with("mech_"));
    assert_eq!(md.matches("![").count(), stems.len());
    let _ = std::fs::remove_dir_all(&dir);
}
