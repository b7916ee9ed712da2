//! The eigenfrequency sweep of the spatial straight guidance (44 degrees of
//! freedom, thesis §6.4, Fig. 6.9): static equilibria under the scene's
//! x-force at t = 0.05 s scaled by λ (gravity on, continuation from λ = 0)
//! and the four lowest undamped eigenfrequencies of the rest linearization at
//! each. Every sixth load scale of the stored curve
//! `fixtures/curves/ch6/unreduced.csv` (made by `cargo xtask regress
//! --update`) is recomputed and must agree with it to 1e-6 (relative), as
//! must the displacement of the node S.
//!
//! `cargo run --release -p flexmb --example guidance_sweep`

use flexmb::plot::read_csv;
use flexmb::prelude::*;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene = Scene::load(&root.join("fixtures/scenes/straight_guidance_spatial.ron"))
        .expect("the guidance scene loads");
    let mech = Arc::new(scene.build(None).expect("the guidance builds"));
    let (header, stored) =
        read_csv(&root.join("fixtures/curves/ch6/unreduced.csv")).expect("the stored curve reads");
    assert_eq!(header[..3], ["lambda", "x", "f1_hz"]);
    let rows: Vec<&Vec<f64>> = stored.iter().step_by(6).collect();
    let lambdas: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let s_node = mech.node("S").expect("node S");
    let (xs, x_ref) = (s_node.position[0], s_node.at[0]);

    let mut model = Dynamics::new(mech.clone());
    let points = model
        .frequency_sweep(0.05, &lambdas, 4, &mut |_| Control::Continue)
        .expect("the sweep converges");
    let mut worst = 0.0f64;
    println!(
        "{:>10} {:>12} {:>10} {:>10} {:>10} {:>10}",
        "λ", "x_S (m)", "f1 (Hz)", "f2", "f3", "f4"
    );
    for (p, row) in points.iter().zip(&rows) {
        let x = p.equilibrium.x[xs] - x_ref;
        println!(
            "{:>10.4} {:>12.4e} {:>10.4} {:>10.4} {:>10.4} {:>10.4}",
            p.load_scale, x, p.frequencies[0], p.frequencies[1], p.frequencies[2], p.frequencies[3]
        );
        worst = worst.max(((x - row[1]) / row[1].abs().max(1e-3)).abs());
        for (f, s) in p.frequencies.iter().zip(&row[2..]) {
            worst = worst.max((f / s - 1.0).abs());
        }
    }
    println!(
        "{} load scales, largest relative difference from the stored curve {worst:.1e}",
        points.len()
    );
    if points.len() != lambdas.len() || worst > 1e-6 {
        eprintln!("the sweep differs from fixtures/curves/ch6/unreduced.csv by {worst:.1e} (more than 1e-6)");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
