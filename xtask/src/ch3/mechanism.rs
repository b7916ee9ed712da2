//! Chapter 3, §3.5.3 (Figs 3.13–3.16, Tables 3.2, 3.3): the small compliant
//! mechanism. Two short sheet flexures of §3.5.1 (each 4 superelements with
//! warping modes, SE-CW) form a cross-hinge with its axis along z; rigid
//! beams join their ends (nodes 2 and 4) to node 5, where the component of
//! §3.5.2 (one superelement with six normal modes, SE-CF6) begins; a
//! massless rigid beam from its end (node 6) carries the 0.01 kg mass at
//! node 7. Nodes 1 and 3 are clamped, the warping is suppressed at nodes 1,
//! 2, 3 and 4, and a moment M about z at node 5 turns the mechanism by ϕ.
//!
//! * Fig. 3.14: the first six eigenfrequencies at 61 equilibria
//!   M = −0.6 … 0.6 N m, without gravity;
//! * Table 3.3: node 7's static z-displacement under gravity with node 5
//!   turned to ϕ = 0 and ±30° (M found by a secant iteration);
//! * Figs 3.15, 3.16: the time responses to the pulse (3.38) with gravity,
//!   from the undeflected configuration and from the gravity equilibrium
//!   ([`super::response`]).

use super::component::{NODE5, NODE6, NODE7};
use super::{rotation_about, steel, H, L, T};
use crate::models::{quasi_static_curve_of, CurvePoint, Model, ModelKind};
use flexmb_dynamics::StaticOptions;
use flexmb_model::{Mechanism, Scene};
use flexmb_reduction::{Equilibrium, MechanicalModel};
use flexmb_superelement::parts;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Node coordinates of Table 3.2 (m), nodes 1 … 7.
pub const NODES: [[f64; 3]; 7] = [
    [0.02, 0.02, -0.02],
    [0.02, -0.02, -0.02],
    [0.0, 0.0, 0.02],
    [0.04, 0.0, 0.02],
    NODE5,
    NODE6,
    NODE7,
];

/// The largest moment of the sweep (N m).
pub const M_MAX: f64 = 0.6;
/// Eigenfrequencies of Fig. 3.14.
pub const N_FREQ: usize = 6;
/// The pulse (3.38): M_max (N m) and T (s).
pub const PULSE: (f64, f64) = (0.5, 0.1);
/// Gravity (m/s²), along −z.
pub const G: f64 = 9.81;
/// The deflections of Table 3.3 (degrees).
pub const TABLE_3_3_PHI: [f64; 3] = [0.0, -30.0, 30.0];
/// Table 3.3 (m): FE-Ansys and the thesis's SE model at ϕ = 0, −30°, +30°.
pub const TABLE_3_3: [[f64; 3]; 2] = [
    [-1.54e-4, -5.30e-4, -3.70e-4],
    [-1.47e-4, -5.06e-4, -3.32e-4],
];

/// The superelement files of the mechanism (in one directory).
#[derive(Clone, Debug)]
pub struct Files {
    /// Superelements per flexure (the thesis: 4).
    pub segments: usize,
    /// One segment of flexure A (from node 1 towards node 2, along −y).
    pub flexure_a: String,
    /// One segment of flexure B (from node 3 towards node 4, along +x).
    pub flexure_b: String,
    /// The component with six normal modes (SE-CF6 of §3.5.2).
    pub component: String,
}

/// A flexure segment built by [`build_flexures`].
#[derive(Clone, Debug)]
pub struct BuiltSegment {
    /// The superelement file.
    pub file: String,
    /// Equations of its FE model.
    pub equations: usize,
    /// Build wall time (s).
    pub seconds: f64,
}

/// Builds one segment (1/`segments` of the length) of each flexure with
/// warping modes at both interfaces (`mesh`: elements along the segment,
/// the height and the thickness) into `dir`: flexure A's, then B's.
pub fn build_flexures(
    dir: &Path,
    mesh: [usize; 3],
    segments: usize,
) -> Result<[BuiltSegment; 2], String> {
    let dl = L / segments as f64;
    let (n1, n3) = (NODES[0], NODES[2]);
    // flexure A runs along −y with its thickness along x, B along +x with
    // its thickness along y; both have their height along z
    let build = |name: char, p: [f64; 3], q: [f64; 3]| -> Result<BuiltSegment, String> {
        let start = Instant::now();
        let file = format!("flexure_{name}_{segments}seg_cw.se.ron");
        let mut part =
            parts::axis_bar(p, q, 2, H, T, mesh, steel()).map_err(|e| format!("{file}: {e}"))?;
        part.settings.warping_p = true;
        part.settings.warping_q = true;
        let model = part
            .mesh
            .assemble(&file)
            .map_err(|e| format!("{file}: {e}"))?;
        let r = flexmb_superelement::build(&model, &part.settings)
            .map_err(|e| format!("{file}: {e}"))?;
        crate::ch2::segments::write(dir, &file, &r.data)?;
        Ok(BuiltSegment {
            file,
            equations: model.n_eq(),
            seconds: start.elapsed().as_secs_f64(),
        })
    };
    let (a, b) = rayon::join(
        || build('a', n1, [n1[0], n1[1] - dl, n1[2]]),
        || build('b', n3, [n3[0] + dl, n3[1], n3[2]]),
    );
    Ok([a?, b?])
}

/// How the moment at node 5 acts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Moment {
    /// A static moment [`M_MAX`] about z, scaled by the load scale.
    Static,
    /// The pulse (3.38) of [`PULSE`].
    Pulse,
}

fn at(p: [f64; 3]) -> String {
    format!("[{:e}, {:e}, {:e}]", p[0], p[1], p[2])
}

/// The scene of the mechanism (Fig. 3.13): nodes N1 … N7 of Table 3.2 and
/// the flexures' inner nodes A1, A2, … and B1, B2, ….
pub fn scene(files: &Files, moment: Moment, gravity: bool) -> String {
    let n = files.segments;
    let dl = L / n as f64;
    let mut nodes: Vec<String> = NODES
        .iter()
        .enumerate()
        .map(|(i, p)| format!(r#"(id: "N{}", at: {})"#, i + 1, at(*p)))
        .collect();
    let mut elements = vec![];
    let mut fixed = vec![r#"Node("N1")"#.to_string(), r#"Node("N3")"#.to_string()];
    for (name, from, to, dir, file) in [
        ('a', 1, 2, [0.0, -1.0, 0.0], &files.flexure_a),
        ('b', 3, 4, [1.0, 0.0, 0.0], &files.flexure_b),
    ] {
        // the chain's nodes: N{from}, a1, …, a{n-1}, N{to}
        let id = |i: usize| match i {
            0 => format!("N{from}"),
            i if i == n => format!("N{to}"),
            i => format!("{}{i}", name.to_ascii_uppercase()),
        };
        let origin = NODES[from - 1];
        for i in 1..n {
            let d = i as f64 * dl;
            let p = std::array::from_fn(|k| origin[k] + d * dir[k]);
            nodes.push(format!(r#"(id: "{}", at: {})"#, id(i), at(p)));
        }
        for i in 0..n {
            elements.push(format!(
                r#"(id: "{name}{i}", type: Superelement(nodes: ("{}", "{}"), file: "{file}", transform: B3, share: (Some("w{name}{i}"), Some("w{name}{}"))))"#,
                id(i),
                id(i + 1),
                i + 1
            ));
        }
        // warping suppressed at nodes 1, 2, 3 and 4
        fixed.push(format!(r#"Modes("w{name}0")"#));
        fixed.push(format!(r#"Modes("w{name}{n}")"#));
    }
    for (id, a, b) in [("r25", 2, 5), ("r45", 4, 5), ("r67", 6, 7)] {
        elements.push(format!(
            r#"(id: "{id}", type: Beam((nodes: ("N{a}", "N{b}"), material: "steel", section: "link", mass: false, up: Some([1.0, 0.0, 0.0]))))"#
        ));
    }
    elements.push(format!(
        r#"(id: "arm", type: Superelement(nodes: ("N5", "N6"), file: "{}", transform: B3))"#,
        files.component
    ));
    elements.push(format!(
        r#"(id: "mass", type: PointMass(node: "N7", mass: {:e}))"#,
        super::component::MASS
    ));
    let load = match moment {
        Moment::Static => format!(
            r#"(node: "N5", moment: Some([0.0, 0.0, {M_MAX:e}]), function: Some(Constant(1.0)))"#
        ),
        Moment::Pulse => format!(
            r#"(node: "N5", moment: Some([0.0, 0.0, 1.0]), function: Some(RaisedCosinePulse(amplitude: {:e}, duration: {:e})))"#,
            PULSE.0, PULSE.1
        ),
    };
    let gravity = if gravity {
        format!("Some([0.0, 0.0, {:e}])", -G)
    } else {
        "None".into()
    };
    format!(
        r#"(
    name: "Small compliant mechanism (thesis §3.5.3, Fig. 3.13)",
    dimension: Spatial,
    gravity: {gravity},
    materials: {{ "steel": (e: 2.1e11, nu: 0.3125, rho: 7800.0) }},
    sections: {{ "link": Rectangle(by: 0.01, bz: 0.01) }},
    nodes: [ {} ],
    elements: [ {} ],
    fixed: [ {} ],
    rigid: [ Def("r25", "*"), Def("r45", "*"), Def("r67", "*") ],
    dofs: Deformations,
    loads: [ {load} ],
    outputs: [Rotation("N5"), Position("N7")],
)"#,
        nodes.join(",\n        "),
        elements.join(",\n        "),
        fixed.join(", ")
    )
}

/// The mechanism built from its scene, with the superelement files in `dir`.
pub fn mechanism(
    dir: &Path,
    files: &Files,
    moment: Moment,
    gravity: bool,
) -> Result<Arc<Mechanism>, String> {
    let s = Scene::from_ron_str(&scene(files, moment, gravity)).map_err(|e| e.to_string())?;
    Ok(Arc::new(s.build(Some(dir)).map_err(|e| e.to_string())?))
}

/// ϕ, node 5's rotation about z (degrees), from the nodal coordinates.
pub fn phi_of(mech: &Mechanism) -> Result<impl Fn(&[f64]) -> f64 + Send + Sync + 'static, String> {
    rotation_about(mech, "N5", 2)
}

/// Node 7's z (m) from the nodal coordinates (its reference z is 0).
pub fn z7_of(mech: &Mechanism) -> Result<impl Fn(&[f64]) -> f64 + Send + Sync + 'static, String> {
    let i = mech.node("N7").map(|n| n.position[2]).ok_or("no node N7")?;
    Ok(move |x: &[f64]| x[i])
}

/// Fig. 3.14: at `n_moments` equilibria M = −M_MAX … M_MAX (no gravity), ϕ
/// and the first [`N_FREQ`] eigenfrequencies.
pub fn sweep(dir: &Path, files: &Files, n_moments: usize) -> Result<Vec<CurvePoint>, String> {
    let mech = mechanism(dir, files, Moment::Static, false)?;
    let phi = phi_of(&mech)?;
    let model = Model::new("SE", &mech, ModelKind::Unreduced);
    let lambdas: Vec<f64> = (0..n_moments)
        .map(|i| -1.0 + 2.0 * i as f64 / (n_moments - 1) as f64)
        .collect();
    quasi_static_curve_of(&model, 0.0, &lambdas, N_FREQ, &|x| vec![phi(x)])
}

/// A static equilibrium with node 5 turned to a given ϕ.
#[derive(Clone, Debug)]
pub struct AtRotation {
    /// The ϕ asked for (degrees).
    pub target: f64,
    /// The moment that holds it (N m).
    pub moment: f64,
    /// ϕ reached (degrees).
    pub phi: f64,
    /// Node 7's z (m).
    pub z7: f64,
    /// The first [`N_FREQ`] eigenfrequencies there (Hz).
    pub freqs: Vec<f64>,
    /// Static solves the secant iteration took.
    pub solves: usize,
}

/// The static equilibria with node 5 turned to each of `targets` (degrees),
/// with or without gravity: the moment by a secant iteration on the load
/// scale, each solve continued from the nearest equilibrium found so far
/// (to |Δϕ| < 1e-7°), then the eigenfrequencies there.
pub fn at_rotations(
    dir: &Path,
    files: &Files,
    gravity: bool,
    targets: &[f64],
) -> Result<Vec<AtRotation>, String> {
    let mech = mechanism(dir, files, Moment::Static, gravity)?;
    let (phi, z7) = (phi_of(&mech)?, z7_of(&mech)?);
    let model = Model::new("SE", &mech, ModelKind::Unreduced);
    let mut m = model.instance()?;
    let err = |e: flexmb_reduction::ReductionError| e.to_string();
    let reference = m.reference_coordinates();
    m.set_load_scale(0.0);
    let zero = m
        .static_equilibrium(0.0, &reference, &StaticOptions::default())
        .map_err(err)?;
    // (load scale, equilibrium, ϕ) of every solve
    let mut solved: Vec<(f64, Equilibrium, f64)> = vec![(0.0, zero.clone(), phi(&zero.x))];
    let mut out = vec![];
    for &target in targets {
        let mut solves = 0;
        let mut solve = |m: &mut Box<dyn MechanicalModel>,
                         solved: &mut Vec<(f64, Equilibrium, f64)>,
                         l: f64|
         -> Result<f64, String> {
            let (l0, from, _) = solved
                .iter()
                .min_by(|a, b| (a.0 - l).abs().total_cmp(&(b.0 - l).abs()))
                .cloned()
                .ok_or("no equilibrium")?;
            m.set_load_scale(l);
            m.dynamics_mut().kinematics_mut().set_guess(&from.x);
            let opts = StaticOptions {
                ramp_loads: false,
                load_scale_from: Some(l0),
                ..Default::default()
            };
            let e = m
                .static_equilibrium(0.0, &from.coordinates, &opts)
                .map_err(|e| format!("ϕ = {target}°, load scale {l}: {e}"))?;
            let p = phi(&e.x);
            solved.push((l, e, p));
            solves += 1;
            Ok(p)
        };
        // secant from the solve nearest the target in ϕ and the next nearest
        // of another load and ϕ (two solves at one load would divide 0 by 0)
        let mut near: Vec<(f64, f64)> = solved.iter().map(|s| (s.0, s.2)).collect();
        near.sort_by(|a, b| (a.1 - target).abs().total_cmp(&(b.1 - target).abs()));
        let p = *near.first().ok_or("no equilibrium")?;
        let (mut a, mut b) = match near.iter().find(|q| q.0 != p.0 && q.1 != p.1) {
            Some(&q) => (q, p),
            None => {
                // about 50° per M_MAX-scaled unit of load: a first guess
                let l = p.0 + (target - p.1) / 50.0;
                (p, (l, solve(&mut m, &mut solved, l)?))
            }
        };
        for _ in 0..40 {
            if (b.1 - target).abs() < 1e-7 {
                break;
            }
            if b.0 == a.0 || b.1 == a.1 {
                return Err(format!(
                    "ϕ = {target}°: the secant iteration stalled at load scale {} (ϕ = {}°)",
                    b.0, b.1
                ));
            }
            let l = b.0 + (target - b.1) * (b.0 - a.0) / (b.1 - a.1);
            let p = solve(&mut m, &mut solved, l)?;
            (a, b) = (b, (l, p));
        }
        if (b.1 - target).abs() >= 1e-7 {
            return Err(format!(
                "ϕ = {target}°: the secant iteration reached {}°",
                b.1
            ));
        }
        let e = solved
            .iter()
            .find(|s| s.0 == b.0)
            .map(|s| s.1.clone())
            .ok_or("lost an equilibrium")?;
        m.set_load_scale(b.0);
        m.dynamics_mut().kinematics_mut().set_guess(&e.x);
        let freqs = m
            .eigenfrequencies(0.0, &e.coordinates, N_FREQ)
            .map_err(err)?;
        out.push(AtRotation {
            target,
            moment: b.0 * M_MAX,
            phi: b.1,
            z7: z7(&e.x),
            freqs,
            solves,
        });
    }
    Ok(out)
}

/// The stored CalculiX solid of the mechanism without gravity
/// (`research/ch3/mechanism.py`): the points of Fig. 3.14.
pub const SOLID: &str = "fixtures/curves/solid/mechanism_ch3_20x20x2.csv";
/// The same with gravity at ϕ = 0, ±30°: Table 3.3.
pub const SOLID_GRAVITY: &str = "fixtures/curves/solid/mechanism_ch3_gravity_20x20x2.csv";

/// One deck of the solid mechanism.
#[derive(Clone, Debug, PartialEq)]
pub struct SolidPoint {
    /// ϕ held (degrees).
    pub phi: f64,
    /// The moment that holds it (N m).
    pub moment: f64,
    /// Node 7's z-displacement (m).
    pub z7: f64,
    /// Frequencies (Hz) in order, the rotation released.
    pub freqs: Vec<f64>,
}

/// Reads a stored solid of the mechanism (rows `case, gravity, phi_set, M,
/// phi_deg, z7, mode, f_Hz`), sorted by ϕ.
pub fn read_solid(path: &Path) -> Result<Vec<SolidPoint>, String> {
    let cols = ["gravity", "phi_set", "M", "phi_deg", "z7"];
    let mut v: Vec<SolidPoint> = crate::solid6::read_solid_points(path, &cols)?
        .into_iter()
        .map(|(c, freqs)| SolidPoint {
            phi: c[1],
            moment: c[2],
            z7: c[4],
            freqs,
        })
        .collect();
    v.sort_by(|a, b| a.phi.total_cmp(&b.phi));
    Ok(v)
}

/// The options of the mechanism's computations.
#[derive(Clone, Debug)]
pub struct MechOptions {
    /// Hexahedra of one flexure segment (along it, its height, its
    /// thickness); the thesis's quarter mesh 10 × 40 × 4.
    pub mesh: [usize; 3],
    /// Superelements per flexure (the thesis: 4).
    pub segments: usize,
    /// Equilibria of the sweep (the thesis: 61).
    pub n_moments: usize,
    /// Simulated time (s).
    pub t_end: f64,
    /// Output interval (s).
    pub dt: f64,
}

impl Default for MechOptions {
    fn default() -> Self {
        Self {
            mesh: [10, 40, 4],
            segments: 4,
            n_moments: 61,
            t_end: 0.3,
            dt: 5e-4,
        }
    }
}
