//! Thesis §2.4.1, Table 2.1: the planar spin-up beam (L = 8 m, aluminium,
//! section 0.03675 × 0.001986 m bending in the plane of rotation, spin-up
//! (2.41) with Ω = 4 rad/s, T = 15 s, elongation rigid), as non-linear
//! beams and as two-node superelements B1, B2, B3 built from solid FE models
//! of the beam segments. The measured quantity is the maximum tip deflection
//! Δy′ in the frame rotating with the root over 0–20 s.

use super::chain;
use super::segments::{self, Built, SegmentMesh};
use flexmb_draw::Configuration;
use flexmb_dynamics::Integrator;
use flexmb_element::VelocityTransform;
use std::path::Path;

/// Beam length (m).
pub const L: f64 = 8.0;
/// Section depth in the plane of rotation (m).
pub const DEPTH: f64 = 0.03675;
/// Section thickness out of the plane (m).
pub const THICKNESS: f64 = 0.001986;
/// Simulated time (s): the ramp (T = 15 s) and 5 s at constant speed.
pub const T_END: f64 = 20.0;
/// Output points over 0–T_END.
pub const OUTPUTS: usize = 4001;
/// Table 2.1 (SPACAR): non-linear beams, superelements B1, B2/B3 (m).
pub const THESIS: [(&str, f64); 3] = [
    ("non-linear beams", 0.5388),
    ("superelements B1", 0.53751),
    ("superelements B2/B3", 0.53754),
];
/// The default mesh of a segment: 10 hexahedra per metre, 2 across the
/// depth, 1 through the thickness (20 × 2 × 1 for a 2 m segment).
pub const MESH: SegmentMesh = SegmentMesh {
    per_metre: 10.0,
    across: [2, 1],
};

/// A model of the beam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Planar non-linear beams; `shortening` adds the second-order term (5.3a)
    /// to ε1 = l − l0.
    Beam {
        /// Second-order shortening term.
        shortening: bool,
    },
    /// Superelements with a velocity transformation.
    Superelement(VelocityTransform),
}

impl Kind {
    /// A label for tables.
    pub fn label(&self) -> String {
        match self {
            Kind::Beam { shortening: false } => "beams, ε1 = l − l0".into(),
            Kind::Beam { shortening: true } => "beams with shortening (5.3a)".into(),
            Kind::Superelement(t) => format!("superelements {t:?}"),
        }
    }
}

/// The models of Table 2.1, in the order of the report.
pub const TABLE_MODELS: [Kind; 5] = [
    Kind::Beam { shortening: false },
    Kind::Beam { shortening: true },
    Kind::Superelement(VelocityTransform::B1),
    Kind::Superelement(VelocityTransform::B2),
    Kind::Superelement(VelocityTransform::B3),
];

/// The planar beam scene with `n` beams.
pub fn beam_scene(n: usize, shortening: bool) -> String {
    format!(
        r#"(
    name: "Planar spin-up beam, {n} beams (thesis §2.4.1)",
    dimension: Planar,
    materials: {{ "aluminium": (e: 6.895e10, nu: 0.3, rho: 2766.67) }},
    sections: {{ "beam": Rectangle(by: {DEPTH}, bz: {THICKNESS}) }},
    nodes: [ (id: "O", at: [0.0, 0.0]), (id: "T", at: [{L}, 0.0]) ],
    elements: [
        (id: "beam", type: Beam((nodes: ("O", "T"), material: "aluminium", section: "beam", n: {n}, timoshenko: false, shortening: {shortening}))),
    ],
    fixed: [Coord("O", Position)],
    rigid: [Def("beam", "elongation")],
    prescribed: [ (what: Coord("O", Angle), function: SpinUp(omega: 4.0, duration: 15.0)) ],
    outputs: [Position("T")],
)"#
    )
}

/// The spatial scene with `n` superelements of the file `file` in series
/// along x, driven by a hinge about z and kept in the plane: torsion and
/// bending about the element y axis (out of the plane) rigid, like the
/// elongation.
pub fn superelement_scene(n: usize, file: &str, t: VelocityTransform) -> String {
    let (chain_nodes, links) = chain::links(n, L);
    let mut nodes = vec![
        r#"(id: "G", at: [0.0, 0.0, 0.0])"#.to_string(),
        r#"(id: "N0", at: [0.0, 0.0, 0.0])"#.to_string(),
    ];
    nodes.extend(chain_nodes);
    let mut elements = vec![
        r#"(id: "drive", type: Hinge(nodes: ("G", "N0"), axis: Some([0.0, 0.0, 1.0])))"#
            .to_string(),
    ];
    let mut rigid = vec![
        r#"Def("drive", "bending_y")"#.to_string(),
        r#"Def("drive", "bending_z")"#.to_string(),
    ];
    for chain::Link { k, from, to } in links {
        elements.push(format!(
            r#"(id: "se{k}", type: Superelement(nodes: ("{from}", "{to}"), file: "{file}", transform: {t:?}))"#
        ));
        for d in ["elongation", "torsion", "bending_y_p", "bending_y_q"] {
            rigid.push(format!(r#"Def("se{k}", "{d}")"#));
        }
    }
    format!(
        r#"(
    name: "Spin-up beam, {n} superelements {t:?} (thesis §2.4.1)",
    dimension: Spatial,
    nodes: [ {} ],
    elements: [ {} ],
    fixed: [Node("G"), Coord("N0", Position)],
    rigid: [ {} ],
    prescribed: [ (what: Def("drive", "rotation"), function: SpinUp(omega: 4.0, duration: 15.0)) ],
    outputs: [Position("T")],
)"#,
        nodes.join(",\n        "),
        elements.join(",\n        "),
        rigid.join(", ")
    )
}

/// The superelement of one of `n` equal segments.
pub fn segment(n: usize, mesh: SegmentMesh, fe_modes: usize) -> Result<Built, String> {
    segments::beam_segment(L / n as f64, DEPTH, THICKNESS, mesh, false, fe_modes)
}

/// The tip deflection history of one run.
#[derive(Clone, Debug)]
pub struct TipHistory {
    /// Output times (s).
    pub t: Vec<f64>,
    /// Δy′ (m) at each output time.
    pub dy: Vec<f64>,
    /// Right-hand-side evaluations.
    pub evaluations: u64,
    /// Wall time of the integration (s).
    pub wall_time: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// The configuration at the output of the largest |Δy′|, to draw.
    pub at_max: Configuration,
}

impl TipHistory {
    /// max |Δy′| (m).
    pub fn max(&self) -> f64 {
        self.dy.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }
}

/// How a run is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integration {
    /// The integrator.
    pub integrator: Integrator,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (m, rad).
    pub atol: f64,
}

impl Integration {
    /// DOPRI5 (ode45-like) at rtol, atol = rtol/1000: Table 2.1.
    pub fn table(rtol: f64) -> Self {
        Self {
            integrator: Integrator::Dopri5,
            rtol,
            atol: 1e-3 * rtol,
        }
    }
    /// For tables.
    pub fn label(&self) -> String {
        format!(
            "{} rtol {:.0e} atol {:.0e}",
            integrator_name(self.integrator),
            self.rtol,
            self.atol
        )
    }
}

/// An integrator's name for reports.
pub fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::Dopri5 => "DOPRI5",
        Integrator::Adams => "Adams",
        Integrator::GeneralizedAlpha => "generalized-α",
    }
}

/// Integrates a spin-up scene (superelement files in `dir`) from rest in the
/// reference configuration over 0–T_END and returns Δy′ = −sin e x_T +
/// cos e y_T, e the prescribed spin angle (2.41).
pub fn run(scene: &str, dir: &Path, how: Integration) -> Result<TipHistory, String> {
    let r = chain::run_from_rest(
        scene,
        dir,
        how.integrator,
        how.rtol,
        how.atol,
        T_END,
        OUTPUTS,
    )?;
    let tip = r.position_of("T")?;
    let spin = r
        .mech
        .inputs
        .first()
        .ok_or("the scene has no prescribed spin")?
        .function
        .clone();
    let tr = &r.trajectory;
    let dy: Vec<f64> =
        tr.t.iter()
            .zip(&tr.x)
            .map(|(t, x)| {
                let e = spin.value(*t);
                -e.sin() * x[tip[0]] + e.cos() * x[tip[1]]
            })
            .collect();
    let at_max = r.configuration(chain::index_of_largest(&dy, |d| d.abs()));
    Ok(TipHistory {
        t: tr.t.clone(),
        dy,
        at_max,
        evaluations: tr.stats.rhs_evals as u64,
        wall_time: tr.wall_time,
        dof: r.mech.n_dof(),
    })
}

/// Order of convergence and Richardson extrapolation from three values at
/// n, 2n, 4n elements: p = log2((a − b)/(b − c)), c + (c − b)/(2^p − 1).
/// `None` when the differences do not shrink monotonically.
pub fn richardson(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    let r = (a - b) / (b - c);
    if !(r.is_finite() && r > 1.0) {
        return None;
    }
    let p = r.log2();
    Some((p, c + (c - b) / (r - 1.0)))
}
