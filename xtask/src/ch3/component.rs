//! Chapter 3, §3.5.2 (Table 3.1): a complex-shaped flexible component
//! modelled by one superelement with 0, 1, 2 and 6 fixed-interface normal
//! modes (SE-C, SE-CF1, SE-CF2, SE-CF6), clamped at node 5 and carrying a
//! 0.01 kg mass on a massless rigid link from node 6 to node 7.

use crate::progress::Progress;
use flexmb_dynamics::Dynamics;
use flexmb_element::Material;
use flexmb_model::Scene;
use flexmb_reduction::MechanicalModel;
use flexmb_superelement::solid::{Block, Mesh};
use flexmb_superelement::{BuildSettings, NodeSelection, PointMass};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Node 5 (the clamped interface's centre) of Table 3.2 (m).
pub const NODE5: [f64; 3] = [0.04, 0.0, 0.0];
/// Node 6 (the other interface's centre).
pub const NODE6: [f64; 3] = [0.29, 0.0, 0.0];
/// Node 7 (the mass).
pub const NODE7: [f64; 3] = [0.29, -0.1, 0.0];
/// The mass at node 7 (kg).
pub const MASS: f64 = 0.01;

/// The aluminium of the component (our choice: the thesis's arms are
/// aluminium, §4.2.1; E and ρ as its §5.4 aluminium link, ν = 0.33).
pub fn aluminium() -> Material {
    let e = 7.0e10;
    Material {
        e,
        g: e / (2.0 * 1.33),
        rho: 2700.0,
    }
}

/// The geometry of the designed component (Fig. 3.12 is lost).
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// Outer width along y (m).
    pub width: f64,
    /// Outer height along z (m).
    pub height: f64,
    /// Wall thickness (m).
    pub wall: f64,
    /// Length of the solid end blocks (m).
    pub end_block: f64,
    /// Positions along the tube of the internal ribs (bulkheads), as fractions
    /// of the tube length.
    pub ribs: Vec<f64>,
    /// Largest element size along x and across (m).
    pub h: [f64; 2],
}

impl Default for Geometry {
    fn default() -> Self {
        Self {
            width: 0.03,
            height: 0.0037,
            wall: 1e-3,
            end_block: 0.01,
            ribs: vec![1.0 / 3.0, 2.0 / 3.0],
            h: [5e-3, 5e-3],
        }
    }
}

/// The blocks of the component.
pub fn blocks(g: &Geometry) -> Vec<Block> {
    let (x0, x1) = (NODE5[0], NODE6[0]);
    let (w, h, t) = (0.5 * g.width, 0.5 * g.height, g.wall);
    let b = |min: [f64; 3], max: [f64; 3]| Block {
        min,
        max,
        material: 0,
    };
    let (a0, a1) = (x0 + g.end_block, x1 - g.end_block);
    let mut v = vec![
        b([x0, -w, -h], [a0, w, h]),
        b([a1, -w, -h], [x1, w, h]),
        b([a0, -w, h - t], [a1, w, h]),
        b([a0, -w, -h], [a1, w, -h + t]),
        b([a0, -w, -h + t], [a1, -w + t, h - t]),
        b([a0, w - t, -h + t], [a1, w, h - t]),
    ];
    for f in &g.ribs {
        let xr = a0 + f * (a1 - a0);
        v.push(b(
            [xr - 0.5 * t, -w + t, -h + t],
            [xr + 0.5 * t, w - t, h - t],
        ));
    }
    v
}

/// The meshed component and its build settings (interfaces: the end faces;
/// no extra modes).
pub fn part(g: &Geometry) -> Result<(Mesh, BuildSettings), String> {
    let mesh = Mesh::boxes(&blocks(g), &[aluminium()], [g.h[0], g.h[1], g.h[1]])
        .map_err(|e| e.to_string())?;
    let plane = |x: f64| NodeSelection::NearPlane {
        point: [x, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
        tolerance: 1e-9,
    };
    let s = BuildSettings::new(NODE5, NODE6, plane(NODE5[0]), plane(NODE6[0]));
    Ok((mesh, s))
}

/// The mass at node 7 as a point mass of the FE model on interface q (for
/// the full FE reference inside flexmb).
pub fn tip_mass() -> PointMass {
    PointMass {
        name: "node 7".into(),
        mass: MASS,
        position: NODE7,
        inertia: None,
        nodes: NodeSelection::NearPlane {
            point: NODE6,
            normal: [1.0, 0.0, 0.0],
            tolerance: 1e-9,
        },
    }
}

/// The models of Table 3.1: the thesis's label and the number of
/// fixed-interface normal modes.
pub const MODELS: [(&str, usize); 4] = [("SE-C", 0), ("SE-CF1", 1), ("SE-CF2", 2), ("SE-CF6", 6)];

/// The frequencies Table 3.1 lists per model.
pub const N_FREQ: usize = 6;

/// Table 3.1 of the thesis (Hz): per mode, FE Ansys, SE-C, SE-CF1, SE-CF2,
/// SE-CF6 (`None`: "–", the model has no such mode).
pub const THESIS: [[Option<f64>; 5]; N_FREQ] = [
    [Some(41.4), Some(41.4), Some(41.4), Some(41.4), Some(41.4)],
    [
        Some(199.4),
        Some(199.5),
        Some(199.5),
        Some(199.5),
        Some(199.4),
    ],
    [
        Some(389.2),
        Some(395.3),
        Some(395.3),
        Some(395.3),
        Some(389.5),
    ],
    [Some(438.6), None, Some(438.6), Some(438.6), Some(438.6)],
    [Some(948.8), None, None, Some(949.7), Some(949.6)],
    [
        Some(1080.4),
        Some(1132.5),
        Some(1132.6),
        Some(1139.0),
        Some(1128.5),
    ],
];

/// The stored CalculiX reference (`research/ch3/component.py`).
pub const SOLID: &str = "fixtures/curves/solid/component_ch3_h5mm.csv";

/// A frequency of a model counts as FE mode k's when it lies within this
/// fraction of it (Table 3.1's dashes: no frequency of the model near the
/// mode). The thesis's largest deviation of a listed value is 5.4 % (SE-CF2,
/// mode 6).
pub const MATCH: f64 = 0.10;

/// One superelement model of the component.
#[derive(Clone, Debug)]
pub struct ComponentModel {
    /// The thesis's label.
    pub name: String,
    /// Fixed-interface normal modes kept.
    pub normal_modes: usize,
    /// The superelement file (in the run's directory).
    pub file: String,
    /// Degrees of freedom of the scene (6 + normal modes).
    pub dof: usize,
    /// All its eigenfrequencies at rest (Hz), ascending.
    pub freqs: Vec<f64>,
    /// The normal modes' own frequencies, both interfaces clamped (Hz).
    pub normal_hz: Vec<f64>,
    /// Build time of the superelement (s).
    pub build_seconds: f64,
    /// Time of the eigen-analysis of the scene (s).
    pub eigen_seconds: f64,
}

/// The models and flexmb's own full FE solution of the same mesh.
#[derive(Clone, Debug)]
pub struct Component {
    /// The geometry.
    pub geometry: Geometry,
    /// FE equations and elements.
    pub n_eq: usize,
    /// Hexahedra.
    pub n_elements: usize,
    /// FE mass without the point mass (kg).
    pub fe_mass: f64,
    /// SE-C, SE-CF1, SE-CF2, SE-CF6.
    pub models: Vec<ComponentModel>,
    /// The full FE model's lowest frequencies (Hz), interface p clamped,
    /// interface q rigid with the mass: flexmb's solve of the reference.
    pub full: Vec<f64>,
    /// Its wall time (s).
    pub full_seconds: f64,
}

/// The superelement file of the component with `k` normal modes.
pub fn file_of(k: usize) -> String {
    format!("component_cf{k}.se.ron")
}

/// The scene: the superelement from node 5 (clamped) to node 6, a massless
/// rigid beam to node 7 and the point mass there.
pub fn scene(file: &str) -> String {
    let at = |p: [f64; 3]| format!("[{:e}, {:e}, {:e}]", p[0], p[1], p[2]);
    format!(
        r#"(
    name: "Complex-shaped component (thesis §3.5.2), {file}",
    dimension: Spatial,
    materials: {{ "aluminium": (e: {e:e}, nu: 0.33, rho: 2700.0) }},
    sections: {{ "link": Rectangle(by: 0.01, bz: 0.01) }},
    nodes: [ (id: "N5", at: {n5}), (id: "N6", at: {n6}), (id: "N7", at: {n7}) ],
    elements: [
        (id: "arm", type: Superelement(nodes: ("N5", "N6"), file: "{file}", transform: B3)),
        (id: "link", type: Beam((nodes: ("N6", "N7"), material: "aluminium", section: "link", mass: false, up: Some([0.0, 0.0, 1.0])))),
        (id: "mass", type: PointMass(node: "N7", mass: {MASS:e})),
    ],
    fixed: [ Node("N5") ],
    rigid: [ Def("link", "*") ],
    dofs: Deformations,
)"#,
        e = aluminium().e,
        n5 = at(NODE5),
        n6 = at(NODE6),
        n7 = at(NODE7),
    )
}

/// The eigenfrequencies (Hz) at rest of the scene with superelement `file`
/// in `dir`, all of them, and the number of DOFs.
pub fn scene_frequencies(dir: &Path, file: &str) -> Result<(usize, Vec<f64>), String> {
    let s = Scene::from_ron_str(&scene(file)).map_err(|e| format!("{file}: {e}"))?;
    let mech = Arc::new(s.build(Some(dir)).map_err(|e| format!("{file}: {e}"))?);
    let n = mech.n_dof();
    let mut d = Dynamics::new(mech);
    let q0 = d.reference_coordinates();
    let f = d
        .eigenfrequencies(0.0, &q0, n)
        .map_err(|e| format!("{file}: {e}"))?;
    Ok((n, f))
}

/// Builds the four superelements into `dir` (one FE assembly), computes
/// their scenes' frequencies, and flexmb's full FE frequencies.
pub fn compute(dir: &Path, g: &Geometry, pg: &Progress) -> Result<Component, String> {
    let (mesh, settings) = part(g)?;
    let model = mesh.assemble("component").map_err(|e| e.to_string())?;
    let bar = pg.bar("ch3: component", MODELS.len() as u64 + 1);
    let models = MODELS
        .par_iter()
        .map(|(name, k)| {
            let start = Instant::now();
            let mut s = settings.clone();
            s.normal_modes = *k;
            let r = flexmb_superelement::build(&model, &s).map_err(|e| format!("{name}: {e}"))?;
            let file = file_of(*k);
            crate::ch2::segments::write(dir, &file, &r.data)?;
            let build_seconds = start.elapsed().as_secs_f64();
            let start = Instant::now();
            let (dof, freqs) = scene_frequencies(dir, &file)?;
            bar.inc();
            Ok(ComponentModel {
                name: name.to_string(),
                normal_modes: *k,
                file,
                dof,
                freqs,
                normal_hz: r.report.normal_frequencies_hz.clone(),
                build_seconds,
                eigen_seconds: start.elapsed().as_secs_f64(),
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    let start = Instant::now();
    let full = full_model_frequencies(&model, settings, 10)?;
    bar.inc();
    bar.finish();
    Ok(Component {
        geometry: g.clone(),
        n_eq: model.n_eq(),
        n_elements: mesh.elements.len(),
        fe_mass: model.translational_mass()[0],
        models,
        full,
        full_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The `n` lowest frequencies (Hz) of the full FE model of the component
/// with interface p clamped and interface q rigid, carrying the mass at node
/// 7 (the reference the superelements approximate), by flexmb's sparse
/// shift-invert solve.
fn full_model_frequencies(
    model: &flexmb_superelement::FeModel,
    mut settings: BuildSettings,
    n: usize,
) -> Result<Vec<f64>, String> {
    settings.point_masses.push(tip_mass());
    flexmb_superelement::full_model_clamped_free_frequencies(model, &settings, n)
        .map_err(|e| format!("full FE model: {e}"))
}

/// The first `n` frequencies (Hz) of the full FE model (interface p
/// clamped, q rigid with the mass at node 7) of the part meshed at element
/// size `h` (along x, across): the mesh-convergence check.
pub fn full_frequencies(g: &Geometry, h: [f64; 2], n: usize) -> Result<Vec<f64>, String> {
    let g = Geometry { h, ..g.clone() };
    let (mesh, settings) = part(&g)?;
    let model = mesh.assemble("component").map_err(|e| e.to_string())?;
    full_model_frequencies(&model, settings, n)
}

/// The stored CalculiX frequencies (Hz), in order.
pub fn read_solid(root: &Path) -> Result<Vec<f64>, String> {
    // rows `case, h, mode, f_Hz`: one mesh size, all modes
    let c = crate::solid6::read_solid_keyed(&root.join(SOLID), "solid", &["h"], 0)?;
    match &c.points[..] {
        [(_, f)] => Ok(f.clone()),
        p => Err(format!("{SOLID}: {} cases, 1 expected", p.len())),
    }
}

/// The frequencies of a model assigned to FE modes 1 … n (`None`: the model
/// has none within [`MATCH`]): pairs (FE mode, model frequency) are taken in
/// order of their relative distance, each frequency and each mode once.
pub fn assign(fe: &[f64], model: &[f64]) -> Vec<Option<f64>> {
    let mut pairs: Vec<(f64, usize, usize)> = fe
        .iter()
        .enumerate()
        .flat_map(|(k, f)| {
            model
                .iter()
                .enumerate()
                .map(move |(j, m)| ((m / f - 1.0).abs(), k, j))
        })
        .filter(|p| p.0 <= MATCH)
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = vec![None; fe.len()];
    let mut used = vec![false; model.len()];
    for (_, k, j) in pairs {
        if out[k].is_none() && !used[j] {
            out[k] = Some(model[j]);
            used[j] = true;
        }
    }
    out
}
