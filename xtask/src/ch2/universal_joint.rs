//! Thesis §2.4.2, Figs 2.8–2.12: the spatial spin-up beam on a universal
//! joint (two hinges with axes along global y and z; e1 the spin-up (2.41)
//! with Ω = 4 rad/s, T = 15 s, about y; e2 = 0.01 sin 15t (2.42) on the
//! carried z hinge), L = 8 m, section 0.02 × 0.04 m, elongation rigid,
//! 20 DOF. Beams against superelements B1, B2, B3, and each model with the
//! direction of every element reversed (Fig. 2.11).
//!
//! The text does not fix the section orientation (Fig. 2.8 is lost; see
//! docs/reproduce.md): here the 0.04 m side lies in the spin plane (x–z) so
//! that Δy′ (out of the spin plane) and Δz′ (in it, the lag) are the tip's
//! components in the joint frame R_y(e1) R_z(e2).

use super::chain;
use super::segments::{self, Built, SegmentMesh};
use flexmb_draw::Configuration;
use flexmb_dynamics::Integrator;
use flexmb_element::VelocityTransform;
use std::path::Path;

/// Beam length (m).
pub const L: f64 = 8.0;
/// Section side along global y, out of the spin plane (m).
pub const BY: f64 = 0.02;
/// Section side along global z, in the spin plane (m).
pub const BZ: f64 = 0.04;
/// Elements.
pub const N: usize = 4;
/// The mesh of a 2 m segment: 10 hexahedra per metre, 1 × 2 across.
pub const MESH: SegmentMesh = SegmentMesh {
    per_metre: 10.0,
    across: [1, 2],
};
/// The thesis's maxima of Fig. 2.12 (m): Δy′max, Δz′max (not reproducible
/// from the text, see the module docs).
pub const THESIS_MAX: [f64; 2] = [0.5095, 0.8991];

/// A model of the beam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Non-linear spatial beams (Timoshenko, shortening term, B3 mass).
    Beam,
    /// Superelements with a velocity transformation.
    Superelement(VelocityTransform),
}

impl Kind {
    /// A label for tables.
    pub fn label(&self) -> String {
        match self {
            Kind::Beam => "beams".into(),
            Kind::Superelement(t) => format!("superelements {t:?}"),
        }
    }
}

/// The models compared, in the order of the report.
pub const MODELS: [Kind; 4] = [
    Kind::Beam,
    Kind::Superelement(VelocityTransform::B1),
    Kind::Superelement(VelocityTransform::B2),
    Kind::Superelement(VelocityTransform::B3),
];

/// The scene with `N` elements; superelements of the file `file` (built
/// with p → q along +x, or along −x when `reversed`). `reversed` lists each
/// element's nodes outer end first.
pub fn scene(kind: Kind, reversed: bool, file: &str) -> String {
    scene_with(kind, reversed, file, N)
}

/// [`scene`] with `n` elements (superelements from [`segment_with`] of the
/// same `n`).
pub fn scene_with(kind: Kind, reversed: bool, file: &str, n: usize) -> String {
    let mut nodes = vec![
        r#"(id: "G", at: [0.0, 0.0, 0.0])"#.to_string(),
        r#"(id: "U", at: [0.0, 0.0, 0.0])"#.to_string(),
        r#"(id: "N0", at: [0.0, 0.0, 0.0])"#.to_string(),
    ];
    let mut elements = vec![
        r#"(id: "joint1", type: Hinge(nodes: ("G", "U"), axis: Some([0.0, 1.0, 0.0])))"#
            .to_string(),
        r#"(id: "joint2", type: Hinge(nodes: ("U", "N0"), axis: Some([0.0, 0.0, 1.0])))"#
            .to_string(),
    ];
    let mut rigid: Vec<String> = ["joint1", "joint2"]
        .iter()
        .flat_map(|j| {
            [
                format!(r#"Def("{j}", "bending_y")"#),
                format!(r#"Def("{j}", "bending_z")"#),
            ]
        })
        .collect();
    let (chain_nodes, links) = chain::links(n, L);
    nodes.extend(chain_nodes);
    for chain::Link { k, from, to } in links {
        let (a, b) = if reversed { (&to, &from) } else { (&from, &to) };
        elements.push(match kind {
            // local y along global z: the 0.04 m side in the spin plane
            Kind::Beam => format!(
                r#"(id: "e{k}", type: Beam((nodes: ("{a}", "{b}"), material: "aluminium", section: "beam", up: Some([0.0, 0.0, 1.0]))))"#
            ),
            Kind::Superelement(t) => format!(
                r#"(id: "e{k}", type: Superelement(nodes: ("{a}", "{b}"), file: "{file}", transform: {t:?}))"#
            ),
        });
        rigid.push(format!(r#"Def("e{k}", "elongation")"#));
    }
    format!(
        r#"(
    name: "Spin-up beam on a universal joint, {} (thesis §2.4.2){}",
    dimension: Spatial,
    materials: {{ "aluminium": (e: 6.895e10, nu: 0.3, rho: 2766.67) }},
    sections: {{ "beam": Rectangle(by: {BZ}, bz: {BY}) }},
    nodes: [ {} ],
    elements: [ {} ],
    fixed: [Node("G"), Coord("U", Position), Coord("N0", Position)],
    rigid: [ {} ],
    prescribed: [
        (what: Def("joint1", "rotation"), function: SpinUp(omega: 4.0, duration: 15.0)),
        (what: Def("joint2", "rotation"), function: Sine(amplitude: 0.01, omega: 15.0, phase: 0.0)),
    ],
    outputs: [Position("T")],
)"#,
        kind.label(),
        if reversed { ", elements reversed" } else { "" },
        nodes.join(",\n        "),
        elements.join(",\n        "),
        rigid.join(", ")
    )
}

/// The superelement of a segment, built with p → q along +x or, reversed,
/// along −x.
pub fn segment(reversed: bool) -> Result<Built, String> {
    segment_with(reversed, N)
}

/// The superelement of one of `n` segments.
pub fn segment_with(reversed: bool, n: usize) -> Result<Built, String> {
    segments::beam_segment(L / n as f64, BY, BZ, MESH, reversed, 0)
}

/// The tip response of one run.
#[derive(Clone, Debug)]
pub struct TipResponse {
    /// Output times (s).
    pub t: Vec<f64>,
    /// Δy′, Δz′ (m): the tip's y and z in the joint frame R_y(e1) R_z(e2).
    pub d: Vec<[f64; 2]>,
    /// Right-hand-side evaluations.
    pub evaluations: u64,
    /// Wall time (s).
    pub wall_time: f64,
    /// The configuration at the output of the largest |Δz′| (the lag in
    /// the spin plane), to draw.
    pub at_max: Configuration,
}

impl TipResponse {
    /// max |Δy′|, max |Δz′| (m).
    pub fn max(&self) -> [f64; 2] {
        let mut m = [0.0f64; 2];
        for d in &self.d {
            for k in 0..2 {
                m[k] = m[k].max(d[k].abs());
            }
        }
        m
    }

    /// The largest difference from `other` of Δy′ and of Δz′ (same output
    /// times).
    pub fn max_difference(&self, other: &TipResponse) -> [f64; 2] {
        let mut m = [0.0f64; 2];
        for (a, b) in self.d.iter().zip(&other.d) {
            for k in 0..2 {
                m[k] = m[k].max((a[k] - b[k]).abs());
            }
        }
        m
    }
}

/// Integrates a scene (superelement files in `dir`) from rest over 0–t_end
/// with DOPRI5 at `rtol` (atol = rtol/1000 m), `outputs` output points.
pub fn run(
    scene: &str,
    dir: &Path,
    t_end: f64,
    outputs: usize,
    rtol: f64,
) -> Result<TipResponse, String> {
    let r = chain::run_from_rest(
        scene,
        dir,
        Integrator::Dopri5,
        rtol,
        rtol * 1e-3,
        t_end,
        outputs,
    )?;
    let tip = r.position_of("T")?;
    let (e1, e2) = match r.mech.inputs.as_slice() {
        [a, b] => (a.function.clone(), b.function.clone()),
        _ => return Err("the scene needs the two joint inputs".into()),
    };
    let tr = &r.trajectory;
    let d: Vec<[f64; 2]> =
        tr.t.iter()
            .zip(&tr.x)
            .map(|(t, x)| {
                let (a, b) = (e1.value(*t), e2.value(*t));
                let r = [x[tip[0]], x[tip[1]], x[tip[2]]];
                // Rᵀ r with R = R_y(a) R_z(b): first R_y(a)ᵀ, then R_z(b)ᵀ
                let (ca, sa) = (a.cos(), a.sin());
                let u = [ca * r[0] - sa * r[2], r[1], sa * r[0] + ca * r[2]];
                let (cb, sb) = (b.cos(), b.sin());
                [-sb * u[0] + cb * u[1], u[2]]
            })
            .collect();
    let at_max = r.configuration(chain::index_of_largest(&d, |d| d[1].abs()));
    Ok(TipResponse {
        t: tr.t.clone(),
        d,
        at_max,
        evaluations: tr.stats.rhs_evals as u64,
        wall_time: tr.wall_time,
    })
}
