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
    // with tangents (central differences of the knots' DOFs): they are
    // saved and restored, Q differs from the natural spline's between knots
    let tangents: Vec<Vec<f64>> = (0..pts.len())
        .map(|i| {
            let (a, c) = (i.saturating_sub(1), (i + 1).min(pts.len() - 1));
            (0..pts[i].q.len())
                .map(|j| (pts[c].q[j] - pts[a].q[j]) / (pts[c].s - pts[a].s))
                .collect()
        })
        .collect();
    let bt =
        interpolated_basis_from_sweep(mech.q0(), 0, &pts, 1..3, SubspaceInterpolation::Msi, true)
            .unwrap()
            .with_tangents(tangents.clone())
            .unwrap();
    let saved = SavedModel::interpolated("MSI-3 + tangents", "planar nodal", &mech, &bt);
    let path = temp("ibm_t.ron");
    saved.save(&path).unwrap();
    let loaded = SavedModel::load(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let mut with_t = ReducedModel::new(mech.clone(), Box::new(bt)).unwrap();
    let mut restored = loaded.into_model(mech.clone()).unwrap();
    let qt = with_t.full_coordinates(&z);
    assert!(same(&qt, &restored.full_coordinates(&z), 1e-14));
    assert!(
        !same(&qt, &before.full_coordinates(&z), 1e-12),
        "the tangents changed nothing"
    );
    // a wrong count of tangents is refused
    let b2 =
        interpolated_basis_from_sweep(mech.q0(), 0, &pts, 1..3, SubspaceInterpolation::Msi, true)
            .unwrap();
    let e = b2
        .with_tangents(tangents[1..].to_vec())
        .unwrap_err()
        .to_string();
    assert!(e.contains("4 tangents") && e.contains("5 knots"), "{e}");
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

/// A grid basis (two configuration coordinates), natural and with the
/// tangents, written and read back: the same configurations and G,z between
/// the grid points; a grid whose data do not fill it is refused by name.
#[test]
fn grid_model_round_trip_keeps_configurations_in_both_forms() {
    let mech = Arc::new(scene().build(None).unwrap());
    let q0 = mech.q0();
    let n = q0.len();
    let (s1, s2) = (vec![-0.01, 0.0, 0.012], vec![-0.02, 0.0, 0.01, 0.03]);
    let pts: Vec<(f64, f64)> = s2
        .iter()
        .flat_map(|b| s1.iter().map(move |a| (*a, *b)))
        .collect();
    let q: Vec<Vec<f64>> = pts
        .iter()
        .map(|(a, b)| {
            (0..n)
                .map(|i| q0[i] + 1e-3 * ((i as f64 + 1.0) * a).sin() + 1e-3 * a * b)
                .collect()
        })
        .collect();
    let t: Vec<[Vec<f64>; 2]> = pts
        .iter()
        .map(|(a, b)| {
            [
                (0..n)
                    .map(|i| 1e-3 * (i as f64 + 1.0) * ((i as f64 + 1.0) * a).cos() + 1e-3 * b)
                    .collect(),
                (0..n).map(|_| 1e-3 * a).collect(),
            ]
        })
        .collect();
    let v: Vec<faer::Mat<f64>> = pts
        .iter()
        .map(|(a, b)| faer::Mat::from_fn(n, 2, |i, j| ((i + 3 * j) as f64 + a - b).cos()))
        .collect();
    for tangents in [None, Some(&t[..])] {
        let b = match tangents {
            None => GridBasis::new(q0.clone(), s1.clone(), s2.clone(), &q, &v, None),
            Some(t) => {
                GridBasis::with_tangents(q0.clone(), s1.clone(), s2.clone(), &q, t, &v, None)
            }
        }
        .unwrap();
        let saved = SavedModel::grid("grid", "planar", &mech, &b);
        assert_eq!(saved.basis.configuration_coordinates(), 2);
        let path = temp("grid.ron");
        saved.save(&path).unwrap();
        let loaded = SavedModel::load(&path).unwrap();
        std::fs::remove_file(&path).ok();
        let after = loaded.basis_for(&mech).unwrap();
        let z = [0.004, 0.017, 1e-4, -2e-4];
        let (mut qa, mut qb) = (vec![0.0; n], vec![0.0; n]);
        let (mut ga, mut gb) = (faer::Mat::zeros(n, 4), faer::Mat::zeros(n, 4));
        let (mut ca, mut cb) = (vec![0.0; n], vec![0.0; n]);
        b.eval(&z, &[0.1, -0.2, 0.3, 0.0], &mut qa, &mut ga, &mut ca);
        after.eval(&z, &[0.1, -0.2, 0.3, 0.0], &mut qb, &mut gb, &mut cb);
        assert!(same(&qa, &qb, 1e-15) && same(&ca, &cb, 1e-15));
        assert!((0..n).all(|i| (0..4).all(|k| ga[(i, k)] == gb[(i, k)])));
        if tangents.is_some() {
            // the tangents came back: Q,s1 at a grid point is the tangent
            after.eval(&[0.0, 0.0, 0.0, 0.0], &[0.0; 4], &mut qb, &mut gb, &mut cb);
            let k = 1 + 3; // point (1, 1)
            assert!((0..n).all(|i| (gb[(i, 0)] - t[k][0][i]).abs() < 1e-15));
        }
    }
    // one configuration short: refused when applied, with the sizes named
    let b = GridBasis::new(q0.clone(), s1.clone(), s2.clone(), &q, &v, None).unwrap();
    let mut saved = SavedModel::grid("grid", "planar", &mech, &b);
    if let SavedBasis::Grid { q, .. } = &mut saved.basis {
        q.pop();
    }
    let e = saved.basis_for(&mech).err().expect("refused").to_string();
    assert!(
        e.contains("grid basis") && e.contains("inconsistent sizes"),
        "{e}"
    );
}
