//! Saved models: a model written and read back is the same model (the same
//! reduced eigenfrequencies and configurations, fixed and interpolated), and
//! a model applied to a mechanism with other degrees of freedom is refused
//! with the first differing DOF named.

use flexmb_linearize::{sweep, SweepOptions, SweepParameter};
use flexmb_model::{Component, DofChoice, Mechanism, Scene, Select};
use flexmb_reduction::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn scene() -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_planar.ron");
    Scene::load(&p).unwrap()
}

/// The planar guidance with absolute nodal DOFs, x of S first (the IBM's s).
fn nodal() -> Arc<Mechanism> {
    let mut s = scene();
    s.dofs = DofChoice::NodalCoordinates;
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    Arc::new(s.build(None).unwrap())
}

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("flexmb-saved-{}-{name}", std::process::id()))
}

fn same(a: &[f64], b: &[f64], rel: f64) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= rel * x.abs().max(y.abs()))
}

#[test]
fn fixed_model_round_trip_keeps_frequencies_and_refuses_other_dofs() {
    let mech = Arc::new(scene().build(None).unwrap());
    let b = modal_basis(&mech, 0.0, &mech.q0(), 3, None).unwrap();
    let saved = SavedModel::fixed("MODAL-3", "planar", &mech, &b);
    let path = temp("fixed.ron");
    saved.save(&path).unwrap();
    let loaded = SavedModel::load(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let mut before = ReducedModel::new(mech.clone(), Box::new(b)).unwrap();
    let mut after = loaded.into_model(mech.clone()).unwrap();
    let f0 = before.frequencies_at_rest(0.0, &[0.0; 3]).unwrap();
    let f1 = after.frequencies_at_rest(0.0, &[0.0; 3]).unwrap();
    assert!(same(&f0, &f1, 1e-14), "{f0:?} vs {f1:?}");
    // the nodal variant has other DOFs: the first one differs
    let e = loaded
        .into_model(nodal())
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("DOF 1 is `"), "{e}");
    assert!(e.contains("`S.x` in the scene"), "{e}");
}

#[test]
fn interpolated_model_round_trip_keeps_configurations_and_frequencies() {
    let mech = nodal();
    let x0 = mech.q0()[0];
    let pts = sweep(
        &mech,
        &SweepParameter::Dof(0),
        &SweepOptions {
            values: (0..5).map(|k| x0 - 0.04 + 0.02 * k as f64).collect(),
            modes: 3,
            t: 0.0,
            keep_vectors: true,
        },
        &|_, _| {},
    )
    .unwrap();
    let b =
        interpolated_basis_from_sweep(mech.q0(), 0, &pts, 1..3, SubspaceInterpolation::Msi, true)
            .unwrap();
    let saved = SavedModel::interpolated("MSI-3", "planar nodal", &mech, &b);
    let path = temp("ibm.ron");
    saved.save(&path).unwrap();
    let loaded = SavedModel::load(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let mut before = ReducedModel::new(mech.clone(), Box::new(b)).unwrap();
    let mut after = loaded.into_model(mech.clone()).unwrap();
    let z_ref = after.basis().z_reference();
    assert_eq!(z_ref, before.basis().z_reference());
    assert!(
        (z_ref[0] - x0).abs() < 1e-12,
        "the middle knot is the reference"
    );
    // between knots too
    let z = [x0 + 0.013, 1e-4, -2e-4];
    assert!(same(
        &before.full_coordinates(&z),
        &after.full_coordinates(&z),
        1e-14
    ));
    let f0 = before.frequencies_at_rest(0.0, &z_ref).unwrap();
    let f1 = after.frequencies_at_rest(0.0, &z_ref).unwrap();
    assert!(same(&f0, &f1, 1e-12), "{f0:?} vs {f1:?}");
    // modes 2 and 3 are in the basis at a knot: exact there (Rayleigh–Ritz)
    assert!(
        same(&f1[1..], &pts[2].frequencies_hz[1..3], 1e-7),
        "{f1:?} vs {:?}",
        pts[2].frequencies_hz
    );
}

#[test]
fn a_damaged_file_is_refused_with_its_position() {
    let path = temp("bad.ron");
    std::fs::write(&path, "(format: 1, description: \"x\",\n scene: 3)").unwrap();
    let e = SavedModel::load(&path).unwrap_err().to_string();
    std::fs::remove_file(&path).ok();
    assert!(
        e.contains("not a reduced model") && e.contains(":2:"),
        "{e}"
    );
}

/// Issue 14.1: a misspelt field of a saved model (here of a basis variant)
/// used to be ignored; it is refused with its position and the nearest name.
#[test]
fn a_misspelt_field_is_refused_with_the_nearest_name() {
    let path = temp("typo.ron");
    std::fs::write(
        &path,
        "(format: 1, description: \"x\", scene: \"s\", dofs: [],\n basis: Fixed(q0: [], vector: []))",
    )
    .unwrap();
    let e = SavedModel::load(&path).unwrap_err().to_string();
    std::fs::remove_file(&path).ok();
    assert!(
        e.contains(":2:") && e.contains("`vector`") && e.contains("did you mean `vectors`?"),
        "{e}"
    );
}
