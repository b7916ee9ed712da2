//! The thesis scenes in fixtures/scenes/ parse and assemble with the thesis's
//! numbers of degrees of freedom.

use flexmb_model::{Coordinate, DofChoice, Scene};
use std::path::Path;

fn scene(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn spatial_straight_guidance_has_44_dofs() {
    let m = scene("straight_guidance_spatial.ron").build(None).unwrap();
    assert_eq!(m.n_dof(), 44, "{}", m.summary());
    assert!(m.dofs.iter().all(|c| matches!(c, Coordinate::Def(_))));
    // with absolute nodal coordinates as DOFs (thesis §6.4.3), still 44
    let mut s = scene("straight_guidance_spatial.ron");
    s.dofs = DofChoice::NodalCoordinates;
    let m = s.build(None).unwrap();
    assert_eq!(m.n_dof(), 44, "{}", m.summary());
    assert!(m.dofs.iter().all(|c| matches!(c, Coordinate::Node(_))));
    // no λ0 is a DOF: the largest Euler parameter at the reference stays dependent
    assert!(m
        .dofs
        .iter()
        .all(|c| !m.coordinate_name(*c).ends_with(".l0")));
}

/// The guidance with warping beams: 2 × 20 × 5 free deformations minus the 6
/// loop-closure conditions, plus the 2 × 19 warping coordinates left free
/// between the restrained ends.
#[test]
fn spatial_straight_guidance_with_warping_has_232_dofs() {
    let m = scene("straight_guidance_spatial_warping.ron")
        .build(None)
        .unwrap();
    assert_eq!(m.n_dof(), 232, "{}", m.summary());
    let names: Vec<&str> = m.dofs.iter().map(|c| m.coordinate_name(*c)).collect();
    // with deformation DOFs, the warping is in the elements' `warping_p` and
    // `warping_q` (l0 w at each end): 19 free per flexure, the two
    // restrained ends not among them
    for f in ["flexure1", "flexure2"] {
        let w: Vec<&&str> = names
            .iter()
            .filter(|n| n.starts_with(&format!("{f}.")) && n.contains(".warping_"))
            .collect();
        assert_eq!(w.len(), 19, "{f}: {w:?}");
        assert!(
            !w.iter()
                .any(|n| **n == format!("{f}.1.warping_p") || **n == format!("{f}.20.warping_q")),
            "{w:?}"
        );
    }
}

#[test]
fn planar_straight_guidance_has_17_dofs() {
    let m = scene("straight_guidance_planar.ron").build(None).unwrap();
    assert_eq!(m.n_dof(), 17, "{}", m.summary());
}

/// Every scene in fixtures/scenes parses under the strict reader (unknown
/// fields and repeated map keys rejected) and assembles.
#[test]
fn every_fixture_scene_parses_strictly_and_builds() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenes");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "ron") {
            let s = Scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
            s.build(p.parent())
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            n += 1;
        }
    }
    assert!(n >= 11, "{n} scenes");
}

/// `build_reporting` names every stage once, in order, and builds the same
/// mechanism as `build`; a scene that fails in the DOF choice has reported
/// the stages before it and no later one.
#[test]
fn the_build_reports_its_stages_in_order() {
    use flexmb_model::BuildStage::*;
    let s = scene("straight_guidance_spatial.ron");
    let mut seen = vec![];
    let m = s.build_reporting(None, &mut |st| seen.push(st)).unwrap();
    assert_eq!(
        seen,
        [
            Nodes,
            Elements,
            Coordinates,
            ReferenceConfiguration,
            DegreesOfFreedom,
            Loads
        ]
    );
    assert_eq!(m.n_dof(), s.build(None).unwrap().n_dof());
    // an unknown node in `fixed` fails in the roles: the stages before it
    // were reported, no later one
    let mut bad = scene("straight_guidance_planar.ron");
    bad.fixed.push(flexmb_model::Select::Node("nowhere".into()));
    let mut seen = vec![];
    let err = bad
        .build_reporting(None, &mut |st| seen.push(st))
        .unwrap_err();
    assert!(err.to_string().contains("nowhere"), "{err}");
    assert_eq!(seen.last(), Some(&DegreesOfFreedom), "{seen:?}");
    assert!(!seen.contains(&Loads));
}
