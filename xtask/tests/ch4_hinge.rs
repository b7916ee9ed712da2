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
    mechanism, read_solid, scene_text, Comparison, SheetModel, HEAD, HINGE, MODELS,
};

/// Tolerances, from the measured deviations (docs/reproduce.md) and the
/// solid's own error:
/// - M at the solid's angles, 1 %: measured at most 0.70 % (all models);
///   the solid's Newton tolerance leaves its M uncertain by 0.1–0.5 % (two
///   decks through the same ϕ disagree by that much).
/// - secant stiffness ΔM/Δϕ over the 5° intervals, 2.5 %: measured at most
///   1.82 %; the solid's 0.5 % in M over 5° is 1–2 % of the secant.
/// - B's x displacement, 1e-4: measured 8e-6 (it follows from ϕ, matched to
///   1e-7 rad, and the hinge's centre of rotation).
/// - f1, 0.6 %: measured at most 0.46 %; the coarse solid mesh moves the
///   solid's f1 by up to 0.57 % at ±20°.
/// - f2 … f6 of the warping beams, 0.3 %: measured at most 0.19 %
///   (n = 20: 0.14 %); the solid's mesh moves them by at most 0.09 %.
/// - the St-Venant beams' (the mechanism's 3 and 10 per sheet) torsion-laden
///   f6 at 10–20°: 15–35 % low (measured −21.4 % and −30.0 %), the claim of
///   docs/reproduce.md that restrained warping, which they lack, stiffens it.
#[test]
fn the_base_hinge_against_the_solid() {
    let root = xtask::workspace_root();
    let c = Comparison::compute(&root).unwrap();
    let d: Vec<_> = (0..MODELS.len()).map(|k| c.deviations(k)).collect();
    for (m, d) in MODELS.iter().zip(&d) {
        eprintln!("{}: {d:?}", m.label());
        assert!(
            d.moment.abs() <= 0.01,
            "{}: M off by {}",
            m.label(),
            d.moment
        );
        assert!(
            d.slope.abs() <= 0.025,
            "{}: ΔM/Δϕ off by {}",
            m.label(),
            d.slope
        );
        assert!(
            d.shift.abs() <= 1e-4,
            "{}: u_x off by {}",
            m.label(),
            d.shift
        );
        assert!(
            d.freqs[0].abs() <= 0.006,
            "{}: f1 off by {}",
            m.label(),
            d.freqs[0]
        );
    }
    let warping = MODELS
        .iter()
        .position(|m| matches!(m, SheetModel::WarpingBeams(_)))
        .unwrap();
    for (j, f) in d[warping].freqs.iter().enumerate().skip(1) {
        assert!(f.abs() <= 0.003, "warping beams: f{} off by {f}", j + 1);
    }
    for (k, m) in MODELS.iter().enumerate() {
        if k != warping {
            let f6 = d[k].freqs[5];
            assert!(
                (-0.35..=-0.15).contains(&f6),
                "{}: f6 off by {f6}",
                m.label()
            );
        }
    }
    // the solid's mesh study: the stored solid is converged to well within
    // the tolerances above
    let (phi, f) = c.solid.change_to(&c.coarse).unwrap();
    assert!(phi.abs() <= 1e-3, "{phi}");
    assert!(f.iter().all(|v| v.abs() <= 0.006), "{f:?}");
    // the report section and its figures are written
    let mut figs = xtask::report::Figures::default();
    let out = std::env::temp_dir().join(format!("flexmb-ch4-hinge-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let md = c.section(&mut figs, &out).unwrap();
    assert!(md.contains("warping beams, n = 10") && out.join("hinge_f6.svg").exists());
    let _ = std::fs::remove_dir_all(&out);
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

/// What the models are: the mechanism's own is 3 beams per sheet with
/// their elongations free (as `Beams(3)`); the warping model adds one
/// warping coordinate per inner node of each sheet.
#[test]
fn the_models_have_the_expected_degrees_of_freedom() {
    let dofs = |m| mechanism(m, HEAD).unwrap().n_dof();
    let (mech, beams3, warp3) = (
        dofs(SheetModel::Mechanism),
        dofs(SheetModel::Beams(3)),
        dofs(SheetModel::WarpingBeams(3)),
    );
    assert_eq!(beams3, mech);
    assert_eq!(
        warp3 - beams3,
        5 * 2,
        "two inner warping coordinates per sheet"
    );
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
}
