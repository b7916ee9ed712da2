//! Thesis §2.4.3, Figs 2.13–2.16, Table 2.2: the unbalanced rotating shaft.
//! A rigid-looking steel cylinder (d2 = 30 mm, l = 75 mm) whose axis is
//! offset by r = 11 mm from the rotation axis x, between two rods
//! (d1 = 2 mm, l = 75 mm each) on that axis. Two superelements, each a rod
//! and half the cylinder (`flexmb_superelement::parts::unbalanced_shaft_half`,
//! 20-node hexahedra), share the middle node M on the axis; spherical
//! joints, three hinges in series with axes along x, y, z, at both rod ends;
//! the end at x = −l is fixed (the "normal support"), the end at x = 2l
//! slides along x only (the "rolling support"); the x hinge of the fixed end
//! is driven by the spin-up (2.41) to Ω = 25 rad/s over T = 15 s. No
//! gravity, no damping.
//!
//! Joined at q (Fig. 2.15) both superelements have q at M; joined at p
//! (Fig. 2.16) both have p at M. The measured deflection Δr(t) is M's
//! distance from the x axis (M starts on it). The static reference (2.43)
//! applies F_c = m_u Ω² (r + Δr) at M along y to the same superelements and
//! iterates Δr to equilibrium.
//!
//! Choices the text does not make (docs/reproduce.md): the elongation of
//! both superelements and the torsion of the half at the rolling end are
//! rigid. Left free they are the model's highest modes (the rod ends'
//! axial and torsional vibration, 10–65 kHz, carried by a few grams of rod)
//! and they set the step of any integrator; the rolling support takes no
//! axial force and its x hinge no moment, so they carry no load.

use super::chain;
use super::segments::{self, Built, ShaftMesh};
use super::spin_up::Integration;
use flexmb_dynamics::{Dynamics, StaticOptions};
use flexmb_element::VelocityTransform;
use flexmb_model::{Mechanism, Scene};
use flexmb_superelement::parts::ShaftHalf;
use std::path::Path;
use std::sync::Arc;

/// Rod diameter d1 (m), Table 2.2.
pub const D1: f64 = 2.0e-3;
/// Cylinder diameter d2 (m), Table 2.2.
pub const D2: f64 = 3.0e-2;
/// Length l of the cylinder and of each rod (m), Table 2.2.
pub const L: f64 = 7.5e-2;
/// Eccentric offset r of the cylinder's axis (m), Table 2.2.
pub const R: f64 = 1.1e-2;
/// Final angular velocity Ω (rad/s) of the spin-up (2.41).
pub const OMEGA: f64 = 25.0;
/// Spin-up time T (s).
pub const T_SPIN: f64 = 15.0;
/// The unbalanced mass m_u of (2.43): the cylinder, ρ π d2²/4 l (kg).
pub const M_U_THESIS: f64 = 0.4135;
/// The thesis's static deflection (2.43) (m).
pub const THESIS_DR: f64 = 1.44e-3;
/// The default mesh of a half: 8 × 8 across the cylinder, 32 along the rod
/// (2 × 2 across it), 8 along the half cylinder. The rod's length division
/// sets the static deflection's convergence (the report's mesh study); the
/// superelement has 12 coordinates whatever the mesh, so a fine mesh costs
/// only its build (about 2 s).
pub const MESH: ShaftMesh = ShaftMesh {
    section: 8,
    rod: 32,
    cylinder: 8,
};

/// Which boundary nodes the two halves share (thesis Figs 2.15b, 2.16b).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Joined {
    /// Both halves have their q node at the middle (Fig. 2.15).
    AtQ,
    /// Both halves have their p node at the middle (Fig. 2.16).
    AtP,
}

impl Joined {
    /// For labels and file names.
    pub fn label(self) -> &'static str {
        match self {
            Joined::AtQ => "q",
            Joined::AtP => "p",
        }
    }
}

/// The superelement file of one half.
pub fn file(half: ShaftHalf, joined: Joined) -> String {
    let h = match half {
        ShaftHalf::First => 1,
        ShaftHalf::Second => 2,
    };
    format!("shaft_half{h}_{}.ron", joined.label())
}

/// Builds both halves for `joined` with `mesh` and writes their files to
/// `dir`; returns the first half (its mesh description).
pub fn build_halves(dir: &Path, joined: Joined, mesh: ShaftMesh) -> Result<Built, String> {
    let mut first = None;
    for half in [ShaftHalf::First, ShaftHalf::Second] {
        let b = segments::shaft_half(half, L, mesh, joined == Joined::AtP)?;
        segments::write(dir, &file(half, joined), &b.data)?;
        if half == ShaftHalf::First {
            first = Some(b);
        }
    }
    first.ok_or_else(|| "no first half".into())
}

/// What drives the shaft in a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The spin-up (2.41) to `omega` (rad/s) over [`T_SPIN`] on the fixed
    /// end's x hinge.
    SpinUp {
        /// Final angular velocity (rad/s); the thesis's is [`OMEGA`].
        omega: f64,
    },
    /// The x hinge held at zero and a unit force along y at M (the static
    /// reference (2.43), scaled by the load scale).
    StaticForce,
}

/// The shaft scene: superelement files named by [`file()`] in the run's directory.
pub fn scene(t: VelocityTransform, joined: Joined, drive: Drive) -> String {
    let (x0, xm, x1) = (-L, 0.5 * L, 2.0 * L);
    let at = |x: f64| format!("[{x:.15}, 0.0, 0.0]");
    let mut nodes = vec![];
    for (id, x) in [
        ("G", x0),
        ("A0", x0),
        ("B0", x0),
        ("E0", x0),
        ("M", xm),
        ("E1", x1),
        ("B1", x1),
        ("A1", x1),
        ("S", x1),
    ] {
        nodes.push(format!(r#"(id: "{id}", at: {})"#, at(x)));
    }
    let hinge = |id: &str, a: &str, b: &str, axis: &str| {
        format!(r#"(id: "{id}", type: Hinge(nodes: ("{a}", "{b}"), axis: Some({axis})))"#)
    };
    let (ex, ey, ez) = ("[1.0, 0.0, 0.0]", "[0.0, 1.0, 0.0]", "[0.0, 0.0, 1.0]");
    let se = |id: &str, end: &str, half: ShaftHalf| {
        let (a, b) = match joined {
            Joined::AtQ => (end, "M"),
            Joined::AtP => ("M", end),
        };
        format!(
            r#"(id: "{id}", type: Superelement(nodes: ("{a}", "{b}"), file: "{}", transform: {t:?}))"#,
            file(half, joined)
        )
    };
    let elements = [
        hinge("jx0", "G", "A0", ex),
        hinge("jy0", "A0", "B0", ey),
        hinge("jz0", "B0", "E0", ez),
        se("se1", "E0", ShaftHalf::First),
        se("se2", "E1", ShaftHalf::Second),
        hinge("jx1", "S", "A1", ex),
        hinge("jy1", "A1", "B1", ey),
        hinge("jz1", "B1", "E1", ez),
    ];
    let mut rigid = vec![];
    for j in ["jx0", "jy0", "jz0", "jx1", "jy1", "jz1"] {
        for d in ["bending_y", "bending_z"] {
            rigid.push(format!(r#"Def("{j}", "{d}")"#));
        }
    }
    for d in [
        ("se1", "elongation"),
        ("se2", "elongation"),
        ("se2", "torsion"),
    ] {
        rigid.push(format!(r#"Def("{}", "{}")"#, d.0, d.1));
    }
    let (drive_fn, loads, what) = match drive {
        Drive::SpinUp { omega } => (
            format!("SpinUp(omega: {omega:?}, duration: {T_SPIN:?})"),
            String::new(),
            "spin-up (2.41)",
        ),
        Drive::StaticForce => (
            "Constant(0.0)".to_string(),
            r#"loads: [ (node: "M", force: Some([0.0, 1.0, 0.0])) ],"#.to_string(),
            "static force at M",
        ),
    };
    format!(
        r#"(
    name: "Unbalanced shaft, superelements {t:?} joined at {} (thesis §2.4.3), {what}",
    dimension: Spatial,
    nodes: [
        {}
    ],
    elements: [
        {}
    ],
    fixed: [
        Node("G"), Node("S"), Coord("E0", Position), Coord("E1", Y), Coord("E1", Z),
        Coord("A0", Position), Coord("B0", Position), Coord("A1", Position), Coord("B1", Position),
    ],
    rigid: [ {} ],
    prescribed: [ (what: Def("jx0", "rotation"), function: {drive_fn}) ],
    {loads}
    outputs: [Position("M"), Energies],
)"#,
        joined.label(),
        nodes.join(",\n        "),
        elements.join(",\n        "),
        rigid.join(", "),
    )
}

/// Builds the mechanism of `scene` (superelement files in `dir`).
pub fn mechanism(scene: &str, dir: &Path) -> Result<Arc<Mechanism>, String> {
    let scene = Scene::from_ron_str(scene).map_err(|e| e.to_string())?;
    Ok(Arc::new(scene.build(Some(dir)).map_err(|e| e.to_string())?))
}

/// The response of one run.
#[derive(Clone, Debug)]
pub struct ShaftResponse {
    /// Output times (s).
    pub t: Vec<f64>,
    /// Δr (m): M's distance from the x axis.
    pub dr: Vec<f64>,
    /// Kinetic energy (J).
    pub kinetic: Vec<f64>,
    /// Strain energy (J).
    pub elastic: Vec<f64>,
    /// Work of the drive moment since t = 0 (J), trapezoidal over the
    /// outputs of the power τ ė.
    pub work: Vec<f64>,
    /// Right-hand-side evaluations.
    pub evaluations: u64,
    /// Integrator steps.
    pub steps: u64,
    /// Wall time of the integration (s).
    pub wall_time: f64,
    /// Degrees of freedom.
    pub dof: usize,
}

impl ShaftResponse {
    /// The mean of Δr over the outputs with t ≥ `from` (the steady state).
    pub fn mean_after(&self, from: f64) -> f64 {
        let v: Vec<f64> = self
            .t
            .iter()
            .zip(&self.dr)
            .filter(|(t, _)| **t >= from)
            .map(|(_, d)| *d)
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }

    /// The largest |T + V − W| over the run, against the largest T + V.
    pub fn energy_balance(&self) -> (f64, f64) {
        let mut err = 0.0f64;
        let mut scale = 0.0f64;
        for k in 0..self.t.len() {
            let e = self.kinetic[k] + self.elastic[k];
            err = err.max((e - self.work[k]).abs());
            scale = scale.max(e.abs());
        }
        (err, scale)
    }
}

/// Integrates the spin-up scene (superelement files in `dir`) from rest
/// over 0–`t_end` with `outputs` outputs.
pub fn run(
    scene: &str,
    dir: &Path,
    how: Integration,
    t_end: f64,
    outputs: usize,
) -> Result<ShaftResponse, String> {
    let r = chain::run_from_rest(
        scene,
        dir,
        how.integrator,
        how.rtol,
        how.atol,
        t_end,
        outputs,
    )?;
    let mech = r.mech.clone();
    let m = r.position_of("M")?;
    let g = mech
        .nodes
        .iter()
        .position(|n| n.id == "G")
        .ok_or("the shaft scene has no node G")?;
    let spin = mech
        .inputs
        .first()
        .ok_or("the scene has no prescribed spin")?
        .function
        .clone();
    let tr = &r.trajectory;
    let mut dy = Dynamics::new(mech.clone());
    let n = tr.t.len();
    let (mut kinetic, mut elastic, mut power) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut qdd = vec![0.0; mech.n_dof()];
    for k in 0..n {
        let (t, q, qd) = (tr.t[k], &tr.q[k], &tr.qd[k]);
        let en = dy.energies(t, q, qd).map_err(|e| e.to_string())?;
        kinetic[k] = en.kinetic;
        elastic[k] = en.elastic;
        dy.accelerations(t, q, qd, &mut qdd)
            .map_err(|e| e.to_string())?;
        let rs = dy
            .nodal_reactions(t, q, qd, &qdd)
            .map_err(|e| e.to_string())?;
        // the ground's support moment about x balances the drive's moment
        // on the shaft
        let (_, moment) = dy.node_reaction(&rs, g);
        power[k] = moment[0] * spin.eval(t).1;
    }
    let mut work = vec![0.0; n];
    for k in 1..n {
        work[k] = work[k - 1] + 0.5 * (power[k] + power[k - 1]) * (tr.t[k] - tr.t[k - 1]);
    }
    let dr = tr.x.iter().map(|x| x[m[1]].hypot(x[m[2]])).collect();
    Ok(ShaftResponse {
        t: tr.t.clone(),
        dr,
        kinetic,
        elastic,
        work,
        evaluations: tr.stats.rhs_evals as u64,
        steps: tr.stats.steps_accepted as u64,
        wall_time: tr.wall_time,
        dof: mech.n_dof(),
    })
}

/// The static reference (2.43): the y deflection of M under
/// F_c = m_u Ω² (r + Δr) along y (`scene` with [`Drive::StaticForce`]),
/// iterated from Δr = 0 until it changes by less than 1e-12 m; returns Δr
/// and the iterations.
pub fn static_reference(
    scene: &str,
    dir: &Path,
    m_u: f64,
    omega: f64,
) -> Result<(f64, usize), String> {
    let mech = mechanism(scene, dir)?;
    let m = mech
        .node("M")
        .ok_or("the shaft scene has no node M")?
        .position
        .clone();
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let opts = StaticOptions::default();
    let mut dr = 0.0;
    for it in 1..=50 {
        dy.set_load_scale(m_u * omega * omega * (R + dr));
        let s = dy
            .static_equilibrium(0.0, &q0, &opts)
            .map_err(|e| format!("static reference: {e}"))?;
        let next = s.x[m[1]];
        if (next - dr).abs() < 1e-12 {
            return Ok((next, it));
        }
        dr = next;
    }
    Err(format!(
        "static reference: Δr did not settle in 50 iterations (last {dr:e} m)"
    ))
}

/// The Euler–Bernoulli estimate of (2.43): two rods of length l, pinned at
/// the supports and guided at the rigid cylinder, k = 2 · 3EI/l³ with
/// I = π d1⁴/64, and Δr = m_u Ω² r / (k − m_u Ω²) at Ω = [`OMEGA`].
pub fn euler_bernoulli(m_u: f64) -> f64 {
    let e = segments::steel().e;
    let i = std::f64::consts::PI * D1.powi(4) / 64.0;
    let k = 2.0 * 3.0 * e * i / L.powi(3);
    let f = m_u * OMEGA * OMEGA;
    f * R / (k - f)
}

/// The cylinder's mass ρ π d2²/4 l (kg): m_u of (2.43).
pub fn cylinder_mass() -> f64 {
    segments::steel().rho * std::f64::consts::PI * D2 * D2 / 4.0 * L
}
