//! Chapter 3, §3.5.1 (Figs 3.9–3.11): the short wide sheet flexure
//! (l = h = 40 mm, t = 0.3 mm, steel) deflected over about ±40° by a moment
//! at its end, which carries an L-shaped rigid link with a 0.01 kg mass. Three
//! models of the flexure, as the thesis:
//! - NLB: 4 of the thesis's spatial beams (St-Venant torsion, free warping);
//! - SE-C: 4 superelements with constraint modes only (rigid interfaces, so
//!   the warping is suppressed at l/4, l/2 and 3l/4 too);
//! - SE-CW: 4 superelements with the warping modes of §3.2 (3.4) at both
//!   interfaces, shared between neighbours and suppressed at the two ends.
//!
//! Each superelement comes from a solid FE model of a quarter of the
//! flexure (built-in 20-node hexahedra), as the thesis built its own from
//! Ansys. Along 41 equilibria M = −0.4 … 0.4 N m the first four
//! eigenfrequencies of the rest linearization (E.6) are recorded against
//! the end's rotation ϕ.
//!
//! Layout (the sign of the link's offset and of ϕ are lost with Fig. 3.9;
//! docs/reproduce.md): the flexure along x from the origin, height along y,
//! thickness along z; the link from (0.04, 0, 0) to (0.29, 0, 0) and then
//! to the mass at (0.29, 0, −0.1); the moment about y at the flexure's end.

pub mod component;
pub mod mechanism;
pub mod response;
pub mod veering;

use crate::curves::StoredCurve;
use crate::models::{quasi_static_curve_of, CurvePoint, Model, ModelKind};
use crate::progress::Progress;
use crate::regress::Recomputed;
use flexmb_element::Material;
use flexmb_model::Scene;
use flexmb_superelement::parts;
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// Flexure length, height and thickness (m), Fig. 3.9.
pub const L: f64 = 0.04;
/// Flexure height (m).
pub const H: f64 = 0.04;
/// Flexure thickness (m).
pub const T: f64 = 3e-4;
/// The largest moment (N m).
pub const M_MAX: f64 = 0.4;
/// Segments per flexure (4 beams or 4 superelements).
pub const SEGMENTS: usize = 4;
/// Eigenfrequencies kept per point.
pub const N_FREQ: usize = 4;

/// The steel of §3.5.1: E = 2.1e11 Pa, G = 8e10 Pa, ρ = 7800 kg/m³.
pub fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8e10,
        rho: 7800.0,
    }
}

/// The three models of the flexure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// 4 spatial beams.
    Nlb,
    /// 4 superelements, constraint modes only.
    SeC,
    /// 4 superelements with warping modes shared at the inner interfaces.
    SeCw,
}

impl Kind {
    /// Every model, in the report's order.
    pub const ALL: [Kind; 3] = [Kind::Nlb, Kind::SeC, Kind::SeCw];

    /// The thesis's label.
    pub fn label(self) -> &'static str {
        match self {
            Kind::Nlb => "NLB",
            Kind::SeC => "SE-C",
            Kind::SeCw => "SE-CW",
        }
    }
}

/// Options of the reproduction.
#[derive(Clone, Debug)]
pub struct Ch3Options {
    /// Hexahedra of one quarter-flexure segment along x, y (height), z
    /// (thickness). The thesis: 10 × 40 × 4.
    pub mesh: [usize; 3],
    /// Equilibria from −M_MAX to M_MAX (the thesis: 40 steps, 41 points).
    pub n_moments: usize,
}

impl Default for Ch3Options {
    fn default() -> Self {
        Self {
            mesh: [10, 40, 4],
            n_moments: 41,
        }
    }
}

/// The mesh of the stored curves and of CI: coarser than the thesis's.
pub const CURVE_MESH: [usize; 3] = [4, 16, 2];

/// A built segment: the file it is written to, and the build time (s).
pub struct Segment {
    /// The superelement file (in the run's directory).
    pub file: String,
    /// Equations of its FE model.
    pub equations: usize,
    /// Build wall time (s).
    pub seconds: f64,
}

/// Builds the quarter-flexure superelement with or without warping modes
/// and writes it to `dir/file`.
pub fn build_segment(dir: &Path, mesh: [usize; 3], warping: bool) -> Result<Segment, String> {
    let start = std::time::Instant::now();
    let file = if warping {
        "sheet_quarter_cw.se.ron"
    } else {
        "sheet_quarter_c.se.ron"
    };
    let mut part = parts::sheet_segment(0.0, L / SEGMENTS as f64, H, T, mesh, steel())
        .map_err(|e| format!("{file}: {e}"))?;
    part.settings.warping_p = warping;
    part.settings.warping_q = warping;
    let model = part
        .mesh
        .assemble(file)
        .map_err(|e| format!("{file}: {e}"))?;
    let r =
        flexmb_superelement::build(&model, &part.settings).map_err(|e| format!("{file}: {e}"))?;
    crate::ch2::segments::write(dir, file, &r.data)?;
    Ok(Segment {
        file: file.into(),
        equations: model.n_eq(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The scene of one model; `file` is the superelement file for SE-C and
/// SE-CW.
pub fn scene(kind: Kind, file: &str) -> String {
    scene_with_offset(kind, file, 0.0)
}

/// [`scene`] with the link's tip and its mass lifted by `offset` (m) along
/// the sheet's height y, out of the flexure's mirror plane y = 0: the link's
/// corner K at (0.29, offset, 0), the mass at (0.29, offset, −0.1). 0 is
/// [`scene`]'s mirror-symmetric layout; the asymmetric variants are
/// [`veering`]'s. The link is rigid and massless and there is no gravity, so
/// the offset moves the inertia only, not the static states.
pub fn scene_with_offset(kind: Kind, file: &str, offset: f64) -> String {
    let dx = L / SEGMENTS as f64;
    let mut nodes: Vec<String> = (0..=SEGMENTS)
        .map(|i| format!(r#"(id: "N{i}", at: [{:e}, 0.0, 0.0])"#, i as f64 * dx))
        .collect();
    nodes.push(format!(
        r#"(id: "K", at: [{:e}, {offset:e}, 0.0])"#,
        L + 0.25
    ));
    nodes.push(format!(
        r#"(id: "E", at: [{:e}, {offset:e}, -0.1])"#,
        L + 0.25
    ));
    let mut elements = vec![];
    let mut fixed = vec![r#"Node("N0")"#.to_string()];
    for i in 0..SEGMENTS {
        let (p, q) = (format!("N{i}"), format!("N{}", i + 1));
        elements.push(match kind {
            Kind::Nlb => format!(
                r#"(id: "s{i}", type: Beam((nodes: ("{p}", "{q}"), material: "steel", section: "sheet", up: Some([0.0, 1.0, 0.0]))))"#
            ),
            Kind::SeC => format!(
                r#"(id: "s{i}", type: Superelement(nodes: ("{p}", "{q}"), file: "{file}", transform: B3))"#
            ),
            Kind::SeCw => format!(
                r#"(id: "s{i}", type: Superelement(nodes: ("{p}", "{q}"), file: "{file}", transform: B3, share: (Some("w{i}"), Some("w{}"))))"#,
                i + 1
            ),
        });
    }
    if kind == Kind::SeCw {
        fixed.push(r#"Modes("w0")"#.into());
        fixed.push(format!(r#"Modes("w{SEGMENTS}")"#));
    }
    elements.push(format!(
        r#"(id: "link1", type: Beam((nodes: ("N{SEGMENTS}", "K"), material: "steel", section: "link", mass: false)))"#
    ));
    elements.push(
        r#"(id: "link2", type: Beam((nodes: ("K", "E"), material: "steel", section: "link", mass: false)))"#
            .into(),
    );
    elements.push(r#"(id: "mass", type: PointMass(node: "E", mass: 0.01))"#.into());
    format!(
        r#"(
    name: "Short sheet flexure, {} (thesis §3.5.1)",
    dimension: Spatial,
    materials: {{ "steel": (e: 2.1e11, nu: 0.3125, rho: 7800.0) }},
    sections: {{ "sheet": Rectangle(by: {H:e}, bz: {T:e}), "link": Rectangle(by: 0.01, bz: 0.01) }},
    nodes: [ {} ],
    elements: [ {} ],
    fixed: [ {} ],
    rigid: [ Def("link1", "*"), Def("link2", "*") ],
    dofs: Deformations,
    loads: [ (node: "N{SEGMENTS}", moment: Some([0.0, {M_MAX:e}, 0.0]), function: Some(Constant(1.0))) ],
    outputs: [Rotation("N{SEGMENTS}")],
)"#,
        kind.label(),
        nodes.join(",\n        "),
        elements.join(",\n        "),
        fixed.join(", ")
    )
}

/// The rotation (degrees) of `node` about the global axis `axis` (0, 1, 2
/// for x, y, z), from its Euler parameters in x: 2 atan2(λ_axis+1, λ0) for a
/// turn about that axis (thesis (2.3) conventions, λ = (λ0, λ1, λ2, λ3)).
pub fn rotation_about(
    mech: &flexmb_model::Mechanism,
    node: &str,
    axis: usize,
) -> Result<impl Fn(&[f64]) -> f64 + Send + Sync + 'static, String> {
    let o = mech
        .node(node)
        .and_then(|n| n.orientation.clone())
        .ok_or_else(|| format!("node {node} has no orientation coordinates"))?;
    Ok(move |x: &[f64]| (2.0 * x[o[axis + 1]].atan2(x[o[0]])).to_degrees())
}

/// The curve of one model: ϕ and f1 … f4 along the moments.
pub fn curve(
    kind: Kind,
    dir: &Path,
    file: &str,
    n_moments: usize,
) -> Result<Vec<CurvePoint>, String> {
    let lambdas: Vec<f64> = (0..n_moments)
        .map(|i| -1.0 + 2.0 * i as f64 / (n_moments - 1) as f64)
        .collect();
    curve_at(kind, dir, file, &lambdas, N_FREQ)
}

/// The mechanism of one model with the mass's `offset`
/// ([`scene_with_offset`]), its superelement files read from `dir`.
pub fn flexure_mechanism(
    kind: Kind,
    dir: &Path,
    file: &str,
    offset: f64,
) -> Result<Arc<flexmb_model::Mechanism>, String> {
    let text = scene_with_offset(kind, file, offset);
    let s = Scene::from_ron_str(&text).map_err(|e| format!("{}: {e}", kind.label()))?;
    Ok(Arc::new(
        s.build(Some(dir))
            .map_err(|e| format!("{}: {e}", kind.label()))?,
    ))
}

/// ϕ and the first `count` eigenfrequencies of one model at the moments
/// `lambdas` × [`M_MAX`] (continuation from M = 0).
pub fn curve_at(
    kind: Kind,
    dir: &Path,
    file: &str,
    lambdas: &[f64],
    count: usize,
) -> Result<Vec<CurvePoint>, String> {
    let mech = flexure_mechanism(kind, dir, file, 0.0)?;
    let phi = rotation_about(&mech, &format!("N{SEGMENTS}"), 1)?;
    let model = Model::new(kind.label(), &mech, ModelKind::Unreduced);
    quasi_static_curve_of(&model, 0.0, lambdas, count, &|x| vec![phi(x)])
}

/// Each model's curve.
pub type Curves = Vec<(Kind, Vec<CurvePoint>)>;

/// The three models' curves, and the superelements built into `dir` (SE-C's,
/// then SE-CW's).
pub fn compute(
    dir: &Path,
    o: &Ch3Options,
    pg: &Progress,
) -> Result<(Curves, Vec<Segment>), String> {
    compute_timed(dir, o, pg).map(|(c, s, _)| (c, s))
}

/// [`compute`] with each curve's wall time (s), in the order of [`Kind::ALL`]
/// (the three sweeps run in parallel).
pub fn compute_timed(
    dir: &Path,
    o: &Ch3Options,
    pg: &Progress,
) -> Result<(Curves, Vec<Segment>, Vec<f64>), String> {
    let bar = pg.bar("ch3: superelements", 2);
    let segments: Result<Vec<Segment>, String> = [false, true]
        .par_iter()
        .map(|w| {
            let s = build_segment(dir, o.mesh, *w);
            bar.inc();
            s
        })
        .collect();
    bar.finish();
    let segments = segments?;
    let bar = pg.bar("ch3: curves", Kind::ALL.len() as u64);
    let curves: Result<Vec<_>, String> = Kind::ALL
        .par_iter()
        .map(|k| {
            let start = std::time::Instant::now();
            let c = curve(*k, dir, segment_file(*k, &segments), o.n_moments)
                .map(|c| ((*k, c), start.elapsed().as_secs_f64()));
            bar.inc();
            c
        })
        .collect();
    bar.finish();
    let (curves, seconds) = curves?.into_iter().unzip();
    Ok((curves, segments, seconds))
}

/// The superelement file of a model among `segments` (SE-C's, then
/// SE-CW's); none for the beams.
pub fn segment_file(kind: Kind, segments: &[Segment]) -> &str {
    match kind {
        Kind::Nlb => "",
        Kind::SeC => &segments[0].file,
        Kind::SeCw => &segments[1].file,
    }
}

/// The moments (N m) of the refined sweep around where modes 4 and 5 meet
/// (Fig. 3.10b, "around 2 degrees"): −0.04 … 0 N m in steps of 0.0005.
pub fn veering_moments() -> Vec<f64> {
    (0..=80).map(|i| -0.04 + 0.0005 * i as f64).collect()
}

/// The closest approach of modes 4 and 5 along a curve with at least five
/// frequencies per point: (ϕ, ω4, ω5) where ω5 − ω4 is smallest.
pub fn closest_approach(c: &[CurvePoint]) -> Option<(f64, f64, f64)> {
    c.iter()
        .filter(|p| p.freqs.len() >= 5)
        .map(|p| (p.position[0], p.freqs[3], p.freqs[4]))
        .min_by(|a, b| (a.2 - a.1).total_cmp(&(b.2 - b.1)))
}

/// The stored CalculiX solid reference of the whole flexure
/// (`research/ch3/flexure.py`, `fixtures/curves/solid/`).
pub const SOLID: &str = "fixtures/curves/solid/flexure_ch3_20x20x2.csv";

/// One point of the solid reference: M (N m), ϕ (degrees), ω1 … (Hz).
#[derive(Clone, Debug, PartialEq)]
pub struct SolidPoint {
    /// The moment.
    pub m: f64,
    /// The end's rotation.
    pub phi: f64,
    /// The frequencies in order.
    pub freqs: Vec<f64>,
}

/// Reads the solid reference, sorted by M.
pub fn read_solid(root: &Path) -> Result<Vec<SolidPoint>, String> {
    read_solid_file(&root.join(SOLID))
}

/// Reads a solid of the flexure written by `research/ch3/flexure.py` (rows
/// `case, M, phi_deg, mode, f_Hz`), sorted by M.
pub fn read_solid_file(p: &Path) -> Result<Vec<SolidPoint>, String> {
    let mut v: Vec<SolidPoint> = crate::solid6::read_solid_points(p, &["M", "phi_deg"])?
        .into_iter()
        .map(|(c, freqs)| SolidPoint {
            m: c[0],
            phi: c[1],
            freqs,
        })
        .collect();
    v.sort_by(|a, b| a.m.total_cmp(&b.m));
    Ok(v)
}

/// The point of a model's curve at moment `m` (N m), if the curve has it.
pub fn at_moment(c: &[CurvePoint], m: f64) -> Option<&CurvePoint> {
    c.iter().find(|p| (p.lambda * M_MAX - m).abs() < 1e-9)
}

/// Where the chapter's fixtures live.
pub fn fixture_dir(root: &Path) -> std::path::PathBuf {
    root.join("fixtures/curves/ch3")
}

/// Recomputes the stored curves on [`CURVE_MESH`] (superelements built in a
/// temporary directory): §3.5.1's three models, §3.5.2's four superelements
/// (one point each, at rest) and §3.5.3's mechanism along its moments.
pub fn recompute(root: &Path, pg: &Progress) -> Result<Recomputed, String> {
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-curves-{}", std::process::id()));
    let o = Ch3Options {
        mesh: CURVE_MESH,
        ..Ch3Options::default()
    };
    let mo = mechanism::MechOptions {
        mesh: CURVE_MESH,
        ..Default::default()
    };
    let c = (|| {
        let (flexure, (comp, flexures)) = rayon::join(
            || compute(&dir, &o, pg),
            || {
                rayon::join(
                    || component::compute(&dir, &component::Geometry::default(), pg),
                    || mechanism::build_flexures(&dir, mo.mesh, mo.segments),
                )
            },
        );
        let ((flexure, _), comp, flexures) = (flexure?, comp?, flexures?);
        let files = mechanism::Files {
            segments: mo.segments,
            flexure_a: flexures[0].file.clone(),
            flexure_b: flexures[1].file.clone(),
            component: component::file_of(6),
        };
        let sweep = mechanism::sweep(&dir, &files, mo.n_moments)?;
        Ok::<_, String>((flexure, comp, sweep))
    })();
    let _ = std::fs::remove_dir_all(&dir);
    let (c, comp, sweep) = c?;
    let mut curves: Vec<StoredCurve> = c
        .iter()
        .map(|(k, p)| StoredCurve::from_points(k.label(), p, 0, N_FREQ))
        .collect();
    curves.extend(comp.models.iter().map(|m| StoredCurve {
        model: format!("component {}", m.name),
        lambda: vec![0.0],
        x: vec![0.0],
        freqs: vec![m.freqs.clone()],
    }));
    curves.push(StoredCurve::from_points(
        "mechanism",
        &sweep,
        0,
        mechanism::N_FREQ,
    ));
    Ok(Recomputed {
        dir: fixture_dir(root),
        curves,
        provenance: vec![
            format!("produced by `cargo xtask regress --update` (flexmb {})", env!("CARGO_PKG_VERSION")),
            format!("NLB, SE-C, SE-CW: the short sheet flexure of thesis §3.5.1 (l = h = {L} m, t = {T} m, steel E = 2.1e11, G = 8e10, rho = 7800), 4 beams or 4 superelements, L-shaped massless rigid link with 0.01 kg, moment lambda x {M_MAX} N m about y at the flexure's end, lambda in [-1, 1] ({} points), continuation from lambda = 0; x = the end's rotation phi (degrees)", o.n_moments),
            "component SE-C ... SE-CF6: thesis §3.5.2, our designed component (xtask/src/ch3/component.rs, 5 mm hexahedra) clamped at node 5 with 0.01 kg at node 7 on a rigid link, 0/1/2/6 normal modes; one point: all eigenfrequencies at rest".into(),
            format!("mechanism: thesis §3.5.3 (60 DOF), moment lambda x {} N m about z at node 5, lambda in [-1, 1] ({} points), no gravity; x = node 5's rotation phi about z (degrees)", mechanism::M_MAX, mo.n_moments),
            format!("flexure superelements: a quarter of the flexure, {:?} hexahedra (along, height, thickness); f_k = undamped eigenfrequencies of the rest linearization (E.6) in Hz", CURVE_MESH),
        ],
    })
}
