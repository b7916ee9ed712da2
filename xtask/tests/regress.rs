//! The CI regression: the eigenfrequency curves of chapters 2, 3, 5 and 6 (unreduced
//! and every reduced model) are recomputed and compared with those stored in
//! `fixtures/curves/` (`cargo xtask regress --update` stores them).

use xtask::progress::Progress;
use xtask::regress::{check, recompute_ch2, recompute_ch5, recompute_ch6, RTOL};

/// Asserts that the recomputed curves of `models` models agree with the stored ones.
fn assert_matches_fixtures(r: &xtask::regress::Recomputed, models: usize) {
    assert_eq!(r.curves.len(), models, "unreduced and every reduced model");
    let d = check(r);
    assert!(
        d.is_empty(),
        "{} differences (tolerance {RTOL:e}):\n{}",
        d.len(),
        d.join("\n")
    );
}

#[test]
fn chapter_2_curves_match_the_stored_ones() {
    let root = xtask::workspace_root();
    assert_matches_fixtures(&recompute_ch2(&root, &Progress::hidden()).unwrap(), 2);
}

#[test]
fn chapter_3_curves_match_the_stored_ones() {
    let root = xtask::workspace_root();
    // NLB, SE-C, SE-CW; the component's four superelements; the mechanism
    assert_matches_fixtures(
        &xtask::ch3::recompute(&root, &Progress::hidden()).unwrap(),
        8,
    );
}

#[test]
fn chapter_4_curves_match_the_stored_ones() {
    let root = xtask::workspace_root();
    assert_matches_fixtures(
        &xtask::reproduce4::recompute(&root, &Progress::hidden()).unwrap(),
        1,
    );
}

#[test]
fn chapter_5_curves_match_the_stored_ones() {
    let root = xtask::workspace_root();
    assert_matches_fixtures(&recompute_ch5(&root, &Progress::hidden()).unwrap(), 5);
}

#[test]
fn chapter_6_curves_match_the_stored_ones() {
    let root = xtask::workspace_root();
    assert_matches_fixtures(&recompute_ch6(&root, &Progress::hidden()).unwrap(), 8);
}

/// A change of the model must fail the comparison. A density change of 1e-4
/// leaves the static configurations alone (no gravity in chapter 5) and moves
/// every eigenfrequency by about 5e-5: each stored eigenfrequency flags it.
/// A stiffness change of 1e-4 moves the configurations as well.
#[test]
fn a_perturbed_model_fails_the_regression() {
    let root = xtask::workspace_root();
    let scene = flexmb_model::Scene::load(&root.join(xtask::ch5::GUIDANCE)).unwrap();
    let mut heavier = scene.clone();
    for m in heavier.materials.values_mut() {
        m.rho *= 1.0 + 1e-4;
    }
    let d = check(&xtask::ch5::recompute_curves_from(&root, heavier).unwrap());
    let freq_lines = d.iter().filter(|l| l.contains("Hz stored")).count();
    let points = xtask::ch5::N_CURVE;
    assert!(
        freq_lines >= 5 * points * 2,
        "a 1e-4 change of the density must move the stored eigenfrequencies beyond {RTOL:e}: {freq_lines} of {} flagged",
        5 * points * 3
    );
    assert!(
        d.iter().all(|l| !l.contains(": x ")),
        "the configurations do not move: {d:?}"
    );
    let mut stiffer = scene;
    for m in stiffer.materials.values_mut() {
        m.e *= 1.0 + 1e-4;
    }
    let d = check(&xtask::ch5::recompute_curves_from(&root, stiffer).unwrap());
    assert!(
        d.len() >= 5 * points,
        "a 1e-4 change of E: {} differences",
        d.len()
    );
}
