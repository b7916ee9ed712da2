//! Issue 17's independent check: one base cross-hinge of the chapter-4
//! mechanism (Table 4.3) against the stored CalculiX solid
//! (`fixtures/curves/solid/hinge_base_*`, `research/ch4/hinge.py`): the
//! moment that holds it at each of the solid's angles (±20°), the
//! rotational stiffness dM/dϕ, B's displacement and f1 … f6 with the rigid
//! link and its point mass, for the mechanism's own model (3 beams per
//! sheet), converged St-Venant beams and beams with warping. The
//! tolerances and where they come from are in docs/reproduce.md ("Chapter
//! 4: one base cross-hinge against CalculiX").

use xtask::ch4::hinge_check::{
    mechanism, read_solid, scene_text, Comparison, SheetModel, HEAD, HINGE, MODELS, SOLID,
};

/// The solid's own discretization error, from its mesh study (coarse
/// 12 × 8/4/3 × 2 against the stored 25 × 16/8/5 × 2 elements).
const COARSE: &str = "fixtures/curves/solid/hinge_base_nu0_12x8x4x3x2";

#[test]
fn the_base_hinge_against_the_solid() {
    let root = xtask::workspace_root();
    let c = Comparison::compute(&root).unwrap();
    let mut figs = xtask::report::Figures::default();
    let out = std::env::temp_dir().join(format!("flexmb-ch4-hinge-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    eprintln!("{}", c.section(&mut figs, &out).unwrap());
    let _ = std::fs::remove_dir_all(&out);
    let d: Vec<_> = (0..MODELS.len()).map(|k| c.deviations(k)).collect();
    for (m, d) in MODELS.iter().zip(&d) {
        eprintln!("{}: {d:?}", m.label());
    }
    todo!("tolerances from the measured numbers");
}

/// The check's hinge is the mechanism's `hb_x1`: every node of the hinge
/// in the check's scene is at the same place as in the full mechanism's
/// scene.
#[test]
fn the_hinge_is_the_mechanisms_own() {
    let layout = xtask::ch4::layout::Layout::new();
    let full = flexmb_model::Scene::from_ron_str(&xtask::ch4::scene::full_scene(&layout)).unwrap();
    let check = flexmb_model::Scene::from_ron_str(&scene_text(HEAD)).unwrap();
    let mut n = 0;
    for node in check.nodes.iter().filter(|n| n.id.starts_with(HINGE)) {
        let twin = full.nodes.iter().find(|m| m.id == node.id).unwrap();
        assert_eq!(node.at, twin.at, "{}", node.id);
        n += 1;
    }
    // A, B and both ends of the five sheets
    assert_eq!(n, 12);
    let sheets = |s: &flexmb_model::Scene| {
        s.elements
            .iter()
            .filter(|e| e.id.starts_with(HINGE))
            .map(|e| format!("{e:?}"))
            .collect::<Vec<_>>()
    };
    assert_eq!(sheets(&check), sheets(&full));
}

/// What the models are: the mechanism's own keeps the rigid elongations
/// of the main and cross sheets, the converged and warping models free
/// them; the warping model adds one coordinate per inner node.
#[test]
fn the_models_have_the_expected_degrees_of_freedom() {
    let dofs = |m| mechanism(m, HEAD).unwrap().n_dof();
    let (mech, beams3, warp3) = (
        dofs(SheetModel::Mechanism),
        dofs(SheetModel::Beams(3)),
        dofs(SheetModel::WarpingBeams(3)),
    );
    // the main and two cross sheets' rigid elongations, 3 beams each (the
    // outer sheets keep theirs free: coplanar with the main sheet, rigid
    // ones would over-constrain the hinge)
    assert_eq!(beams3 - mech, 9);
    assert_eq!(warp3 - beams3, 5 * 2, "two inner warping coordinates per sheet");
}

/// A solid file with a malformed row is refused with its name and line.
#[test]
fn a_malformed_solid_is_refused_naming_the_file_and_line() {
    let dir = std::env::temp_dir().join(format!("flexmb-ch4-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("bad.csv"),
        "# how it was made\ncase,M,phi_deg,ux,uy,mode,f_Hz\nsolid,0,0,0,0,1,5.2\nsolid,0.3,5,x,0,1,5.3\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad_curve.csv"), "h\nsolid,0,0,0,0\n").unwrap();
    let e = read_solid(&dir, "bad").unwrap_err();
    assert!(e.contains("bad.csv:4:"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = (COARSE, SOLID);
}
