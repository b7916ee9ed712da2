//! A superelement built from FE matrices made in code: a 200 mm steel bar,
//! 10 mm × 10 mm, meshed with 10 × 2 × 2 twenty-node hexahedra (the built-in
//! solid FE of `flexmb-superelement`), its stiffness and mass assembled,
//! reduced by Craig–Bampton with rigid end faces and four fixed-interface
//! normal modes, written as a superelement file and used in a scene: the bar
//! clamped at P, free at Q. The mechanism's six lowest eigenfrequencies must
//! lie within 1 % above the full FE model's own clamped-free frequencies
//! (a Ritz reduction never lowers them).
//!
//! `cargo run --release -p flexmb --example superelement_from_fe`

use flexmb::prelude::*;
use flexmb::superelement::{build, full_model_clamped_free_frequencies, parts, spec};
use std::process::ExitCode;
use std::sync::Arc;

/// The bar as a two-node superelement between P (clamped) and Q.
const SCENE: &str = r#"(
    name: "bar superelement, clamped-free",
    dimension: Spatial,
    materials: {},
    sections: {},
    nodes: [ (id: "P", at: [0.0, 0.0, 0.0]), (id: "Q", at: [0.2, 0.0, 0.0]) ],
    elements: [ (id: "bar", type: Superelement(nodes: ("P", "Q"), file: "bar.se.ron")) ],
    fixed: [ Node("P") ],
)"#;

fn main() -> ExitCode {
    let steel = Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    };
    // the FE model: mesh, then K and M (sparse, translational DOFs)
    let part = parts::prismatic_bar(0.2, 0.01, 0.01, [10, 2, 2], steel).expect("the mesh");
    let fe = part.mesh.assemble("bar").expect("K and M");
    let mut settings = part.settings.clone();
    settings.normal_modes = 4;
    let se = build(&fe, &settings).expect("the superelement builds");
    let f_fe = full_model_clamped_free_frequencies(&fe, &part.settings, 6).expect("FE modes");

    // the superelement file next to the scene, the scene from a string
    let dir = std::env::temp_dir().join(format!("flexmb-example-se-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    spec::write_ron(&dir.join("bar.se.ron"), &se.data).expect("the superelement file");
    let scene = Scene::from_ron_str(SCENE).expect("the scene parses");
    let mech = scene.build(Some(&dir));
    let _ = std::fs::remove_dir_all(&dir);
    let mech = Arc::new(mech.expect("the scene builds"));

    let mut model = Dynamics::new(mech.clone());
    let q0 = model.reference_coordinates();
    let f = model
        .eigenfrequencies(0.0, &q0, 6)
        .expect("the eigenfrequencies");
    println!("{} degrees of freedom", mech.n_dof());
    println!(
        "{:>4} {:>14} {:>14} {:>9}",
        "mode", "flexmb (Hz)", "FE (Hz)", "diff"
    );
    let mut ok = f.len() == 6;
    for (k, (a, b)) in f.iter().zip(&f_fe).enumerate() {
        let r = a / b - 1.0;
        println!("{:>4} {a:>14.3} {b:>14.3} {:>8.3} %", k + 1, 100.0 * r);
        ok &= (-1e-6..1e-2).contains(&r);
    }
    if !ok {
        eprintln!("the superelement's frequencies are not within 1 % above the FE model's");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
