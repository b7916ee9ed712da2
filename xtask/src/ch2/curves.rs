//! Chapter 2's stored eigenfrequency curves (`fixtures/curves/ch2`): the
//! spin-up beam at rest, clamped at its root, bent far by a tip force along
//! y (up to 10 N, a tip deflection of about a quarter of its length), as 4
//! beams and as 4 superelements B3. Along the static path the
//! eigenfrequencies of the rest linearization (E.6) are recorded: the
//! superelements' geometric non-linearity (their stress stiffening and the
//! large rotation of their frames) is what the curve checks.

use super::segments;
use super::spin_up;
use crate::curves::StoredCurve;
use crate::models::{quasi_static_curve, CurvePoint, Model, ModelKind};
use crate::regress::Recomputed;
use flexmb_element::VelocityTransform::B3;
use flexmb_model::Scene;
use std::path::Path;
use std::sync::Arc;

/// The tip force at load scale 1 (N).
pub const TIP_FORCE: f64 = 10.0;
/// Points of each curve.
pub const N_CURVE: usize = 21;
/// Eigenfrequencies stored per point.
pub const N_FREQ: usize = 4;

/// `scene` with the tip force `force` (N) along y on node T.
pub fn with_tip_force(scene: &str, force: f64, spatial: bool) -> String {
    let f = if spatial {
        format!("[0.0, {force:e}, 0.0]")
    } else {
        format!("[0.0, {force:e}]")
    };
    scene.replacen(
        "    outputs: [Position(\"T\")],",
        &format!("    loads: [ (node: \"T\", force: Some({f}), function: Some(Constant(1.0))) ],\n    outputs: [Position(\"T\")],"),
        1,
    )
}

/// The two curves: 4 beams (ε1 = l − l0) and 4 superelements B3 (built into
/// `dir`), with the tip's y displacement as the probed coordinate.
pub fn compute(dir: &Path) -> Result<Vec<(String, Vec<CurvePoint>)>, String> {
    let se = spin_up::segment(4, spin_up::MESH, 0)?;
    segments::write(dir, "curve_segment.se.ron", &se.data)?;
    let scenes = [
        (
            "4 beams",
            with_tip_force(&spin_up::beam_scene(4, false), TIP_FORCE, false),
        ),
        (
            "4 superelements B3",
            with_tip_force(
                &spin_up::superelement_scene(4, "curve_segment.se.ron", B3),
                TIP_FORCE,
                true,
            ),
        ),
    ];
    let lambdas: Vec<f64> = (0..N_CURVE)
        .map(|i| i as f64 / (N_CURVE - 1) as f64)
        .collect();
    scenes
        .iter()
        .map(|(name, text)| {
            let scene = Scene::from_ron_str(text).map_err(|e| format!("{name}: {e}"))?;
            let mech = Arc::new(scene.build(Some(dir)).map_err(|e| format!("{name}: {e}"))?);
            let model = Model::new(name, &mech, ModelKind::Unreduced);
            Ok((
                name.to_string(),
                quasi_static_curve(&model, 0.0, &lambdas, "T", N_FREQ)?,
            ))
        })
        .collect()
}

/// Where the chapter's fixtures live.
pub fn fixture_dir(root: &Path) -> std::path::PathBuf {
    root.join("fixtures/curves/ch2")
}

/// Recomputes the stored curves (superelements built in a temporary
/// directory).
pub fn recompute(root: &Path) -> Result<Recomputed, String> {
    let dir = std::env::temp_dir().join(format!("flexmb-ch2-curves-{}", std::process::id()));
    let c = compute(&dir);
    let _ = std::fs::remove_dir_all(&dir);
    let c = c?;
    Ok(Recomputed {
        dir: fixture_dir(root),
        curves: c
            .iter()
            .map(|(n, p)| StoredCurve::from_points(n, p, 1, N_FREQ))
            .collect(),
        provenance: vec![
            format!("produced by `cargo xtask regress --update` (flexmb {})", env!("CARGO_PKG_VERSION")),
            format!("the spin-up beam of thesis §2.4.1 at rest (spin angle 0), clamped at its root, elongation rigid, under a tip force of lambda x {TIP_FORCE} N along y, lambda in [0, 1] ({N_CURVE} points), continuation from lambda = 0"),
            format!("superelements: 2 m segments, {} hexahedra per metre, {:?} across, constraint modes only; x = tip y-displacement (m); f_k = undamped eigenfrequencies of the rest linearization (E.6) in Hz", spin_up::MESH.per_metre, spin_up::MESH.across),
        ],
    })
}
