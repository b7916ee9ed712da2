//! Chapter 4: the two-DOF large-stroke compliant positioning mechanism
//! (thesis §4.1–4.4), as a documented substitute built from the text's
//! topology and Tables 4.1–4.3 (`layout`), its FE-built member and sheet
//! superelements (`parts`) and its scene (`scene`), written to
//! `fixtures/scenes/two_dof_mechanism.ron` with the part files in
//! `fixtures/scenes/two_dof_mechanism/` by `cargo xtask mechanism4`.

pub mod hinge_check;
pub mod layout;
pub mod parts;
pub mod path;
pub mod scene;
pub mod sweep;

use layout::{HingeKind, Layout, Member};
use rayon::prelude::*;
use std::path::Path;

/// What writing the model did: per part file its FE size and build time.
#[derive(Clone, Debug)]
pub struct PartBuild {
    /// The file, relative to the scene.
    pub file: String,
    /// What it is.
    pub what: String,
    /// Solid elements of its FE model.
    pub elements: usize,
    /// Mass of the superelement (kg), from M̄'s translational block.
    pub mass: f64,
    /// Build wall time (s).
    pub seconds: f64,
}

/// The scene's file name.
pub const SCENE_FILE: &str = "two_dof_mechanism.ron";
/// The scene with chapter 7's actuator hinges.
pub const ACTUATED_SCENE_FILE: &str = "two_dof_mechanism_actuated.ron";
/// The skeleton with the releases (exactly constrained).
pub const SKELETON_FILE: &str = "two_dof_skeleton.ron";
/// The skeleton without the releases (nine times over-constrained), in
/// `refused/`, where the scenes that every fixture test must build are
/// not.
pub const SKELETON_RIGID_FILE: &str = "refused/two_dof_skeleton_no_releases.ron";

/// Builds every part, writes them and the scenes into `dir` (the scene
/// directory; parts in `dir/two_dof_mechanism/`), in parallel; `progress`
/// gets each finished part's name.
pub fn write_model(dir: &Path, progress: &(dyn Fn(&str) + Sync)) -> Result<Vec<PartBuild>, String> {
    let layout = Layout::new();
    let placements = layout.members();
    // one file per distinct part; LowerArmX2 uses LowerArmX1's
    let members: Vec<Member> = Member::ALL
        .into_iter()
        .filter(|m| *m != Member::LowerArmX2)
        .collect();
    let member_builds: Vec<Result<PartBuild, String>> = members
        .par_iter()
        .map(|&m| {
            let t = std::time::Instant::now();
            let (se, elements, mass) = parts::build_member(m)?;
            let (_, p, q) = placements
                .iter()
                .find(|(mm, _, _)| *mm == m)
                .expect("every member is placed");
            let se = parts::placed_in_plane(se, layout::sub(*q, *p));
            let file = scene::member_file(m);
            crate::ch2::segments::write(dir, &file, &se)?;
            progress(m.name());
            Ok(PartBuild {
                what: format!("member {}", m.name()),
                mass,
                file,
                elements,
                seconds: t.elapsed().as_secs_f64(),
            })
        })
        .collect();
    let sheet_builds: Vec<Result<PartBuild, String>> = [
        ("he_x1", HingeKind::ElbowX),
        ("he_y", HingeKind::ElbowY),
        ("hc_1", HingeKind::WireSheet),
    ]
    .par_iter()
    .map(|&(hinge, kind)| {
        let t = std::time::Instant::now();
        let (se, mass) = parts::build_sheet_third(kind)?;
        let (s1, _) = layout.hinge(hinge).sheet_directions();
        let se = parts::placed_sheet(se, s1);
        let file = scene::sheet_file(kind);
        crate::ch2::segments::write(dir, &file, &se)?;
        progress(kind.tag());
        let [a, b, c] = parts::SHEET_MESH;
        Ok(PartBuild {
            what: format!("a third of the {} hinges' main sheet", kind.tag()),
            mass,
            file,
            elements: a * b * c,
            seconds: t.elapsed().as_secs_f64(),
        })
    })
    .collect();
    let builds: Vec<PartBuild> = member_builds
        .into_iter()
        .chain(sheet_builds)
        .collect::<Result<_, _>>()?;
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("{name}: {e}"))?;
        }
        std::fs::write(path, text).map_err(|e| format!("{name}: {e}"))
    };
    write(SCENE_FILE, scene::full_scene(&layout))?;
    write(ACTUATED_SCENE_FILE, scene::actuated_scene(&layout))?;
    write(
        SKELETON_FILE,
        scene::skeleton(&layout, scene::Releases::ALL),
    )?;
    write(
        SKELETON_RIGID_FILE,
        scene::skeleton(&layout, scene::Releases::NONE),
    )?;
    Ok(builds)
}

/// The directory of the committed model: `fixtures/scenes`.
pub fn fixture_dir() -> std::path::PathBuf {
    crate::workspace_root().join("fixtures").join("scenes")
}
