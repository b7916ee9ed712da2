//! The two-coordinate interpolated basis of the chapter-7 mechanism (issue
//! 18, beyond the thesis) on the small study that CI affords
//! ([`reproduce7xy::ci_options`]: grids 2 × 2, 3 × 3 and 5 × 5, 16 Halton
//! check points over the workspace, 6 on the path (4.1)), and its stored
//! curves (`fixtures/curves/ch7xy`, `cargo xtask regress --chapter ch7xy`).
//! `cargo xtask reproduce ch7xy` runs the full study up to 17 × 17.

use std::sync::OnceLock;
use xtask::ch7;
use xtask::progress::Progress;
use xtask::reproduce7xy::{self, XyResults};

fn study() -> &'static XyResults {
    static R: OnceLock<XyResults> = OnceLock::new();
    R.get_or_init(|| {
        reproduce7xy::compute(
            &xtask::workspace_root(),
            &reproduce7xy::ci_options(),
            &Progress::hidden(),
        )
        .unwrap_or_else(|e| panic!("{e}"))
    })
}

#[test]
fn the_stored_curves_are_reproduced() {
    let curves = reproduce7xy::stored_curves(study());
    assert_eq!(curves.len(), 4, "unreduced and three grids");
    let dir = reproduce7xy::curve_dir(&xtask::workspace_root());
    xtask::regress::reproduced(dir, curves).unwrap_or_else(|e| panic!("{e}"));
}

/// The curse of dimensionality, in small: the errors off the grid shrink
/// as the grid is refined, for every mode, and the finest CI grid keeps
/// ω3–ω8 within what the full study measured for 5 × 5.
#[test]
fn the_errors_off_the_grid_shrink_with_the_grid() {
    let r = study();
    assert_eq!(
        r.models.iter().map(|m| m.n).collect::<Vec<_>>(),
        vec![2, 3, 5]
    );
    for k in 0..ch7::R {
        let e: Vec<f64> = r.models.iter().map(|m| m.worst_error(r, k)).collect();
        assert!(
            e[2] < e[0],
            "ω{}: 5 × 5 {:.2e} against 2 × 2 {:.2e}",
            k + 1,
            e[2],
            e[0]
        );
    }
}
