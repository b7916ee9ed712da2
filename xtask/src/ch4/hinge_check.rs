//! The independent check of issue 17: one base cross-hinge of Table 4.3 (the
//! mechanism's `hb_x1`, exactly as [`add_hinge`] builds it) with its A side
//! clamped and a rigid link with a point mass on its B side, turned about z
//! to ±20° by a couple, in flexmb models of several refinements, against the
//! CalculiX solid of `research/ch4/hinge.py` stored in
//! `fixtures/curves/solid/` (docs/reproduce.md, "Chapter 4: one base
//! cross-hinge against CalculiX").
//!
//! The flexmb models ([`SheetModel`]) are all made from the one scene that
//! [`add_hinge`] writes, changed only where a model differs: the
//! mechanism's own (3 St-Venant beams per sheet), converged beams (n per
//! sheet) and beams with warping (Vlasov torsion, restrained at both
//! clamps); every deformation of the sheets is free in all of them.
//!
//! Each model is compared at the solid's angles ϕ of the B side: the moment
//! M that holds it there, the rotational stiffness (each model's tangent
//! dM/dϕ; against the solid, the secant ΔM/Δϕ between its angles), B's
//! displacement, and the eigenfrequencies of the rest linearization (E.6)
//! about that equilibrium ([`states_at`]).

use super::layout::{add, Layout, V3, Z};
use super::scene::{add_hinge, boundary_nodes, hinge_sections, SceneText};
use crate::models::NodeProbe;
use crate::report::{pct, sig, Figures, Table};
use crate::solid6::{read_numeric_rows, read_solid_points};
use flexmb_dynamics::Dynamics;
use flexmb_model::{ElementSpec, Mechanism, Scene, WarpingEnd, WarpingSpec};
use flexmb_plot::{Plot, Series};
use flexmb_reduction::MechanicalModel;
use std::fmt::Write;
use std::path::Path;
use std::sync::Arc;

/// The hinge of the check: the base hinge of UpperArmX1, at the origin,
/// UpperArmX1 along +y.
pub const HINGE: &str = "hb_x1";

/// The rigid link and its point mass on the B side: from the boundary node
/// B along the hinge's line (+y) to `reach` from the rotation axis, then
/// down by `drop` (−z) to the point mass (an L, as the link of thesis §3.5.1,
/// so that the mass moves when the B side twists about the hinge's line).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Head {
    /// Distance of the link's corner from the rotation axis, along +y (m).
    pub reach: f64,
    /// Drop of the mass below the corner, along −z (m).
    pub drop: f64,
    /// The point mass (kg).
    pub mass: f64,
}

/// The link of the check (invented, docs/reproduce.md): the first frequency
/// 5.2 Hz at rest, the second (the mass moving in z, on the hinge's
/// out-of-plane support) 559 Hz, below the sheets' own modes (≥ 1065 Hz).
pub const HEAD: Head = Head {
    reach: 0.15,
    drop: 0.05,
    mass: 0.15,
};

/// Where the couple acts on the B side: two points (±x, y, 0) (m), rigidly
/// joined to B, with forces ∓F along y (dead loads). The solid's couple acts
/// at the same points (`research/ch4/hinge.py`).
pub const COUPLE_AT: [f64; 2] = [0.022, 0.06];

/// The couple's moment about z at rest and load scale 1 (N m): 2·0.022·F.
pub const MOMENT: f64 = 1.3;

/// How the five sheets are modelled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SheetModel {
    /// The mechanism's own: [`add_hinge`] unchanged (3 beams per sheet;
    /// the same model as `Beams(3)`).
    Mechanism,
    /// `n` St-Venant beams per sheet.
    Beams(usize),
    /// `n` beams per sheet with warping restrained at both clamps
    /// (docs/scene-format.md, "Beams with warping").
    WarpingBeams(usize),
}

impl SheetModel {
    /// Its name in file names: `mechanism`, `beams10`, `warping_beams10`.
    pub fn slug(self) -> String {
        match self {
            SheetModel::Mechanism => "mechanism".into(),
            SheetModel::Beams(n) => format!("beams{n}"),
            SheetModel::WarpingBeams(n) => format!("warping_beams{n}"),
        }
    }

    /// Its name in the tables.
    pub fn label(self) -> String {
        match self {
            SheetModel::Mechanism => "mechanism's (3 beams)".into(),
            SheetModel::Beams(n) => format!("beams, n = {n}"),
            SheetModel::WarpingBeams(n) => format!("warping beams, n = {n}"),
        }
    }
}

/// The id of the B-side boundary node.
pub fn b_node() -> String {
    boundary_nodes(Layout::new().hinge(HINGE)).1
}

/// The scene text of the check with the mechanism's own hinge: the hinge
/// of [`add_hinge`], its A node fixed, the link of `head` (massless rigid
/// beams) on its B node with the point mass at its end, and the couple of
/// [`COUPLE_AT`] and [`MOMENT`] on rigid beams from B.
pub fn scene_text(head: Head) -> String {
    let layout = Layout::new();
    let h = layout.hinge(HINGE);
    let mut st = SceneText::default();
    hinge_sections(&mut st);
    add_hinge(&mut st, h);
    let (a, b) = boundary_nodes(h);
    st.fix(format!(r#"Node("{a}")"#));
    let corner: V3 = add(h.axis_point, head.reach, h.u_out);
    st.node("link.K", corner);
    st.node("link.E", add(corner, -head.drop, Z));
    st.rigid_beam("link.1", &b, "link.K");
    st.rigid_beam("link.2", "link.K", "link.E");
    st.element(format!(
        r#"(id: "link.mass", type: PointMass(node: "link.E", mass: {:?}))"#,
        head.mass
    ));
    let [cx, cy] = COUPLE_AT;
    let f = MOMENT / (2.0 * cx);
    let mut loads = vec![];
    for (id, x, fy) in [("couple.P", cx, f), ("couple.N", -cx, -f)] {
        st.node(id, [x, cy, 0.0]);
        st.rigid_beam(&format!("{id}.arm"), &b, id);
        loads.push(format!(
            r#"(node: "{id}", force: Some([0.0, {fy:?}, 0.0]), function: Some(Constant(1.0)))"#
        ));
    }
    st.finish(
        "One base cross-hinge of thesis Table 4.3 with a rigid link and a point mass (issue 17's independent check)",
        &format!(
            "    dofs: Deformations,\n    loads: [{}],\n    outputs: [Rotation(\"{b}\"), Position(\"{b}\")],\n",
            loads.join(", ")
        ),
    )
}

/// Whether a scene element is one of the five sheets' beam chains.
fn is_sheet(e: &flexmb_model::ElementEntry) -> bool {
    matches!(&e.kind, ElementSpec::Beam(b) if b.section != "rigid") && e.id.starts_with(HINGE)
}

/// The scene of the check with the sheets modelled as `model`.
pub fn scene(model: SheetModel, head: Head) -> Result<Scene, String> {
    let mut s = Scene::from_ron_str(&scene_text(head)).map_err(|e| e.to_string())?;
    let (n, warping) = match model {
        SheetModel::Mechanism => return Ok(s),
        SheetModel::Beams(n) => (n, false),
        SheetModel::WarpingBeams(n) => (n, true),
    };
    let mut sheets = 0;
    for e in &mut s.elements {
        if !is_sheet(e) {
            continue;
        }
        sheets += 1;
        if let ElementSpec::Beam(b) = &mut e.kind {
            b.n = n;
            if warping {
                b.warping = Some(WarpingSpec {
                    p: WarpingEnd::Restrained,
                    q: WarpingEnd::Restrained,
                });
            }
        }
    }
    if sheets != 5 {
        return Err(format!("expected five sheets in {HINGE}, found {sheets}"));
    }
    Ok(s)
}

/// The mechanism of a model.
pub fn mechanism(model: SheetModel, head: Head) -> Result<Arc<Mechanism>, String> {
    scene(model, head)?
        .build(None)
        .map(Arc::new)
        .map_err(|e| format!("{}: {e}", model.label()))
}

/// One state of the hinge: the B side turned by `phi` about z.
#[derive(Clone, Debug, PartialEq)]
pub struct HingeState {
    /// The B side's rotation about z (rad).
    pub phi: f64,
    /// The couple's moment about z in this configuration (N m).
    pub m: f64,
    /// B's displacement in x and y (m).
    pub u: [f64; 2],
}

/// A flexmb model at the solid's angles.
#[derive(Clone, Debug)]
pub struct ModelStates {
    /// Which model.
    pub model: SheetModel,
    /// Its degrees of freedom.
    pub dofs: usize,
    /// Per angle: the state, the slope dM/dϕ (N m/rad) and the lowest
    /// eigenfrequencies (Hz).
    pub points: Vec<(HingeState, f64, Vec<f64>)>,
    /// Wall time of the static solves and eigen analyses (s).
    pub seconds: f64,
}

/// Reads a state from the nodal coordinates of an equilibrium at load
/// scale λ: B's rotation 2 atan2(λ3, λ0) (it turns about z only: the
/// hinge is symmetric about its mid-plane and the couple acts in it), the
/// couple's moment λ F (x_P − x_N) with the couple's points where they are,
/// and B's displacement.
struct Reader {
    orientation: Vec<usize>,
    b: NodeProbe,
    p: NodeProbe,
    n: NodeProbe,
}

impl Reader {
    fn new(mech: &Arc<Mechanism>) -> Result<Self, String> {
        let id = b_node();
        let orientation = mech
            .node(&id)
            .and_then(|n| n.orientation.clone())
            .ok_or_else(|| format!("node {id} has no orientation coordinates"))?;
        Ok(Self {
            orientation,
            b: NodeProbe::new(mech, &id)?,
            p: NodeProbe::new(mech, "couple.P")?,
            n: NodeProbe::new(mech, "couple.N")?,
        })
    }

    fn state(&self, lambda: f64, x: &[f64]) -> HingeState {
        let o = &self.orientation;
        let phi = 2.0 * x[o[3]].atan2(x[o[0]]);
        let [cx, _] = COUPLE_AT;
        let (up, un) = (self.p.displacement_in(x), self.n.displacement_in(x));
        let arm = 2.0 * cx + up[0] - un[0];
        let ub = self.b.displacement_in(x);
        HingeState {
            phi,
            m: lambda * MOMENT / (2.0 * cx) * arm,
            u: [ub[0], ub[1]],
        }
    }
}

/// How closely a model is brought to each of the solid's angles (rad),
/// 1e-6 of 5°: the static equilibria's tolerance leaves ϕ uncertain by
/// about 1e-8 rad, below which the secant method stalls.
pub const ANGLE_TOLERANCE: f64 = 1e-7;

/// The relative step of the load scale for the slope dM/dϕ by central
/// differences, at least 0.01 in λ: the truncation error, h² times the
/// relative change of the slope over the range (a few per cent), is about
/// 1e-6, and the equilibria's 1e-8 rad of noise over steps of 1e-3 rad or
/// more gives 1e-5.
pub const SLOPE_STEP: f64 = 1e-2;

/// Model `model` at the solid's states `at`: the load scale that turns it
/// to each state's angle ϕ (to [`ANGLE_TOLERANCE`]), by Newton's method
/// from the solid's own load (its couple is this scene's, so the solid's M
/// and ϕ give its force), every pass one continuation of static equilibria
/// from λ = 0 through the load scales and their neighbours at ±h (which
/// give dϕ/dλ, and the slope dM/dϕ by central differences); then the
/// lowest `modes` eigenfrequencies at each.
pub fn states_at(
    model: SheetModel,
    at: &[HingeState],
    modes: usize,
) -> Result<ModelStates, String> {
    let start = std::time::Instant::now();
    let mech = mechanism(model, HEAD)?;
    let reader = Reader::new(&mech)?;
    let mut dy = Dynamics::new(mech.clone());
    let ctx = |e: flexmb_reduction::ReductionError| format!("{}: {e}", model.label());
    // the solid's force: M = F·2x cos ϕ for a couple at (±x, y) turned by ϕ
    let mut lam: Vec<f64> = at.iter().map(|s| s.m / (MOMENT * s.phi.cos())).collect();
    let mut worst = f64::INFINITY;
    for _ in 0..MAX_PASSES {
        let mut all = Vec::with_capacity(3 * lam.len());
        for l in &lam {
            let h = SLOPE_STEP * l.abs().max(1.0);
            all.extend([l - h, *l, l + h]);
        }
        let eqs = dy
            .equilibria_over_load_scale(0.0, &all, &mut |_| {})
            .map_err(ctx)?;
        let states: Vec<HingeState> = all
            .iter()
            .zip(&eqs)
            .map(|(l, e)| reader.state(*l, &e.x))
            .collect();
        worst = 0.0;
        for (k, s) in at.iter().enumerate() {
            let (lo, mid, hi) = (&states[3 * k], &states[3 * k + 1], &states[3 * k + 2]);
            let dphi = (hi.phi - lo.phi) / (all[3 * k + 2] - all[3 * k]);
            let miss = s.phi - mid.phi;
            worst = worst.max(miss.abs());
            if miss.abs() > ANGLE_TOLERANCE {
                lam[k] += miss / dphi;
            }
        }
        if worst <= ANGLE_TOLERANCE {
            let mut points = vec![];
            for k in 0..at.len() {
                let (lo, mid, hi) = (&states[3 * k], &states[3 * k + 1], &states[3 * k + 2]);
                let slope = (hi.m - lo.m) / (hi.phi - lo.phi);
                let eq = &eqs[3 * k + 1];
                dy.set_load_scale(lam[k]);
                dy.kinematics_mut().set_guess(&eq.x);
                let f = dy
                    .eigenfrequencies(0.0, &eq.coordinates, modes)
                    .map_err(ctx)?;
                points.push((mid.clone(), slope, f));
            }
            return Ok(ModelStates {
                model,
                dofs: mech.n_dof(),
                points,
                seconds: start.elapsed().as_secs_f64(),
            });
        }
    }
    Err(format!(
        "{}: the load scales of the solid's angles did not converge in {MAX_PASSES} passes ({worst:e} rad)",
        model.label()
    ))
}

/// Newton passes of [`states_at`]: two or three are needed.
pub const MAX_PASSES: usize = 6;

/// The stored solid reference, without the extension: `STEM.csv` (states
/// and frequencies) and `STEM_curve.csv` (every load increment).
pub const SOLID: &str = "fixtures/curves/solid/hinge_base_nu0_25x16x8x5x2";

/// The same solid on a coarser mesh (12 × 8/4/3 × 2 elements: along the
/// length; the main, cross and outer sheets' heights; the thickness), at
/// the same moments: the stored solid's own discretization error.
pub const COARSE: &str = "fixtures/curves/solid/hinge_base_nu0_12x8x4x3x2";

/// The solid: per deck its state and frequencies, and the states of every
/// load increment (the moment–angle curve), sorted by ϕ.
#[derive(Clone, Debug)]
pub struct SolidHinge {
    /// Per deck (sorted by ϕ): its final state and eigenfrequencies (Hz).
    pub points: Vec<(HingeState, Vec<f64>)>,
    /// Every increment of every deck, sorted by ϕ.
    pub curve: Vec<HingeState>,
}

fn state_of(r: &[f64]) -> HingeState {
    HingeState {
        m: r[0],
        phi: r[1].to_radians(),
        u: [r[2], r[3]],
    }
}

/// Reads a solid written by `research/ch4/hinge.py` (`stem` relative to
/// `root`).
pub fn read_solid(root: &Path, stem: &str) -> Result<SolidHinge, String> {
    let columns = ["M", "phi_deg", "ux", "uy"];
    let p = root.join(format!("{stem}.csv"));
    let mut points: Vec<(HingeState, Vec<f64>)> = read_solid_points(&p, &columns)?
        .into_iter()
        .map(|(c, f)| (state_of(&c), f))
        .collect();
    points.sort_by(|a, b| a.0.phi.total_cmp(&b.0.phi));
    let p = root.join(format!("{stem}_curve.csv"));
    let mut curve: Vec<HingeState> = read_numeric_rows(&p, &columns)?
        .iter()
        .map(|r| state_of(r))
        .collect();
    curve.sort_by(|a, b| a.phi.total_cmp(&b.phi));
    Ok(SolidHinge { points, curve })
}

impl SolidHinge {
    /// The largest relative change from `self` to `other` (the same decks on
    /// another mesh) of ϕ (away from 0) and of f1 … f[`MODES`]: (ϕ, per mode).
    pub fn change_to(&self, other: &SolidHinge) -> Result<(f64, Vec<f64>), String> {
        if self.points.len() != other.points.len() {
            return Err("the two solids have different decks".into());
        }
        let pairs = || self.points.iter().zip(&other.points);
        let phi = largest(
            pairs()
                .filter(|(a, _)| a.0.phi.abs() > 1e-6)
                .map(|(a, b)| b.0.phi / a.0.phi - 1.0),
        );
        let f = (0..MODES)
            .map(|j| largest(pairs().map(|(a, b)| b.1[j] / a.1[j] - 1.0)))
            .collect();
        Ok((phi, f))
    }

    /// The secant stiffness ΔM/Δϕ (N m/rad) between consecutive decks'
    /// final states, with the interval's mid-angle (rad). The solid's
    /// increment-to-increment slopes are no stiffness measure: its Newton
    /// tolerance leaves M uncertain by about 0.1–0.5 % (two decks through
    /// the same ϕ disagree by that much), which over one 1.25° increment is
    /// ±10 % of the slope (docs/reproduce.md).
    pub fn secants(&self) -> Vec<(f64, f64)> {
        secants(self.points.iter().map(|p| &p.0))
    }
}

/// [`SolidHinge::secants`] of any states sorted by ϕ.
fn secants<'a>(states: impl Iterator<Item = &'a HingeState>) -> Vec<(f64, f64)> {
    let v: Vec<&HingeState> = states.collect();
    v.windows(2)
        .map(|w| {
            (
                0.5 * (w[0].phi + w[1].phi),
                (w[1].m - w[0].m) / (w[1].phi - w[0].phi),
            )
        })
        .collect()
}

impl ModelStates {
    /// The secant stiffness between its consecutive states, as
    /// [`SolidHinge::secants`] (the states are at the solid's angles).
    pub fn secants(&self) -> Vec<(f64, f64)> {
        secants(self.points.iter().map(|p| &p.0))
    }
}

/// The frequencies compared: f1 … f6 (issue 17), in order of frequency.
pub const MODES: usize = 6;

/// The flexmb models of the comparison: the mechanism's own, converged
/// St-Venant beams and beams with warping (docs/reproduce.md gives their
/// convergence).
pub const MODELS: [SheetModel; 3] = [
    SheetModel::Mechanism,
    SheetModel::Beams(10),
    SheetModel::WarpingBeams(10),
];

/// The solid and the flexmb models at its angles.
pub struct Comparison {
    /// The stored solid.
    pub solid: SolidHinge,
    /// The same on the coarser mesh ([`COARSE`]).
    pub coarse: SolidHinge,
    /// Each model at the solid's angles.
    pub models: Vec<ModelStates>,
}

/// The largest deviations of a model from the solid over its angles
/// (relative, model/solid − 1, signed as found; the moment and B's x
/// displacement away from ϕ = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Deviations {
    /// Of the moment M at the same ϕ.
    pub moment: f64,
    /// Of the secant stiffness ΔM/Δϕ between consecutive angles
    /// ([`SolidHinge::secants`]).
    pub slope: f64,
    /// Of B's x displacement.
    pub shift: f64,
    /// Of f1 … f6.
    pub freqs: Vec<f64>,
}

/// The value of largest magnitude.
fn largest(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |w: f64, x| if x.abs() > w.abs() { x } else { w })
}

impl Comparison {
    /// Reads the stored solid ([`SOLID`]) and computes [`MODELS`] at its
    /// angles, in parallel.
    pub fn compute(root: &Path) -> Result<Self, String> {
        use rayon::prelude::*;
        let solid = read_solid(root, SOLID)?;
        let coarse = read_solid(root, COARSE)?;
        let at: Vec<HingeState> = solid.points.iter().map(|p| p.0.clone()).collect();
        let models = MODELS
            .par_iter()
            .map(|m| states_at(*m, &at, MODES))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            solid,
            coarse,
            models,
        })
    }

    /// The deviations of model `k`.
    pub fn deviations(&self, k: usize) -> Deviations {
        let m = &self.models[k];
        let pairs = || m.points.iter().zip(&self.solid.points);
        let away = || pairs().filter(|(_, (s, _))| s.phi.abs() > 1e-6);
        let rel = |a: f64, b: f64| a / b - 1.0;
        Deviations {
            moment: largest(away().map(|((f, _, _), (s, _))| rel(f.m, s.m))),
            slope: largest(
                m.secants()
                    .iter()
                    .zip(self.solid.secants())
                    .map(|(k, ks)| rel(k.1, ks.1)),
            ),
            shift: largest(away().map(|((f, _, _), (s, _))| rel(f.u[0], s.u[0]))),
            freqs: (0..MODES)
                .map(|j| largest(pairs().map(|((_, _, f), (_, fs))| rel(f[j], fs[j]))))
                .collect(),
        }
    }

    /// The report section: the solid, the models' sizes and largest
    /// deviations, the moment, slope and frequencies at every angle, and
    /// figures of M and f1 … f6 against ϕ saved in `out`.
    pub fn section(&self, figs: &mut Figures, out: &Path) -> std::io::Result<String> {
        let mut s = String::new();
        let _ = writeln!(s, "## One base cross-hinge against CalculiX (issue 17)\n");
        let _ = writeln!(s, "The base hinge `{HINGE}` of the mechanism (Table 4.3: five sheets L = 50 mm, t = 0.5 mm, heights 10/15/33/15/10 mm), side A clamped, side B carrying a massless L-shaped link with {} kg at {} m along the hinge's line and {} m below, turned about z by a couple. The solid is `{SOLID}.csv` (`research/ch4/hinge.py`: CalculiX C3D20R, NLGEOM static steps, then a *FREQUENCY perturbation step at each angle). Each flexmb model is brought to the solid's angles ϕ; M is the moment that holds it there, dM/dϕ the rotational stiffness (each model's tangent from central differences; against the solid, the secant ΔM/Δϕ between its angles), u_x B's displacement; frequencies in order of frequency.\n", HEAD.mass, HEAD.reach, HEAD.drop);
        let mut t = Table::new(&[
            "model", "DOF", "time (s)", "M", "ΔM/Δϕ", "u_x", "f1", "f2", "f3", "f4", "f5", "f6",
        ]);
        for (k, m) in self.models.iter().enumerate() {
            let d = self.deviations(k);
            let mut row = vec![
                m.model.label(),
                m.dofs.to_string(),
                format!("{:.1}", m.seconds),
            ];
            row.extend([d.moment, d.slope, d.shift].iter().map(|v| pct(*v)));
            row.extend(d.freqs.iter().map(|v| pct(*v)));
            t.row(row);
        }
        let _ = writeln!(
            s,
            "Largest deviation from the solid over ±20° (model/solid − 1):\n\n{}",
            t.render()
        );
        if let Ok((phi, f)) = self.solid.change_to(&self.coarse) {
            let fs: Vec<String> = f.iter().map(|v| pct(*v)).collect();
            let _ = writeln!(
                s,
                "The solid's own discretization error: on the coarser mesh `{COARSE}` (528 instead of 2100 C3D20R) ϕ at the same moments changes by at most {} and f1 … f6 by at most {}.\n",
                pct(phi),
                fs.join(", ")
            );
        }
        let mut header = vec!["ϕ (°)".to_string(), "M solid (N m)".into()];
        for m in &self.models {
            header.push(format!("M, {}", m.model.label()));
            header.push(format!("dM/dϕ (N m/rad), {}", m.model.label()));
        }
        let refs: Vec<&str> = header.iter().map(|h| h.as_str()).collect();
        let mut t = Table::new(&refs);
        for (i, (st, _)) in self.solid.points.iter().enumerate() {
            let mut row = vec![format!("{:.3}", st.phi.to_degrees()), sig(st.m)];
            for m in &self.models {
                let (f, k, _) = &m.points[i];
                row.push(if st.phi.abs() > 1e-6 {
                    pct(f.m / st.m - 1.0)
                } else {
                    "–".into()
                });
                row.push(sig(*k));
            }
            t.row(row);
        }
        let _ = writeln!(
            s,
            "The moment at the solid's angles (model/solid − 1) and each model's tangent stiffness dM/dϕ (central differences of its equilibria):\n\n{}",
            t.render()
        );
        let mut header = vec!["ϕ interval (°)".to_string(), "ΔM/Δϕ solid (N m/rad)".into()];
        header.extend(self.models.iter().map(|m| m.model.label()));
        let refs: Vec<&str> = header.iter().map(|h| h.as_str()).collect();
        let mut t = Table::new(&refs);
        let secants: Vec<_> = self.models.iter().map(|m| m.secants()).collect();
        for (i, (_, ks)) in self.solid.secants().iter().enumerate() {
            let (a, b) = (&self.solid.points[i].0, &self.solid.points[i + 1].0);
            let mut row = vec![
                format!("{:.2} … {:.2}", a.phi.to_degrees(), b.phi.to_degrees()),
                sig(*ks),
            ];
            row.extend(secants.iter().map(|k| pct(k[i].1 / ks - 1.0)));
            t.row(row);
        }
        let _ = writeln!(
            s,
            "The secant stiffness ΔM/Δϕ between the solid's angles (model/solid − 1):\n\n{}",
            t.render()
        );
        for (j, name) in (0..MODES).map(|j| (j, format!("f{}", j + 1))) {
            let mut header = vec!["ϕ (°)".to_string(), format!("{name} solid (Hz)")];
            header.extend(self.models.iter().map(|m| m.model.label()));
            let refs: Vec<&str> = header.iter().map(|h| h.as_str()).collect();
            let mut t = Table::new(&refs);
            for (i, (st, fs)) in self.solid.points.iter().enumerate() {
                let mut row = vec![
                    format!("{:.3}", st.phi.to_degrees()),
                    format!("{:.3}", fs[j]),
                ];
                row.extend(
                    self.models
                        .iter()
                        .map(|m| pct(m.points[i].2[j] / fs[j] - 1.0)),
                );
                t.row(row);
            }
            let _ = writeln!(s, "{name}, model/solid − 1:\n\n{}", t.render());
        }
        // figures: M and each frequency against ϕ
        let deg = |v: &[f64]| v.iter().map(|p| p.to_degrees()).collect::<Vec<_>>();
        let curve_phi: Vec<f64> = self.solid.curve.iter().map(|c| c.phi).collect();
        let curve_m: Vec<f64> = self.solid.curve.iter().map(|c| c.m).collect();
        let mut p = Plot::new(
            "Moment against rotation of the base cross-hinge",
            "rotation of B about z (°)",
            "moment (N m)",
        );
        p.push(Series::points(
            "solid (every load increment)",
            &deg(&curve_phi),
            &curve_m,
        ));
        for m in &self.models {
            let phi: Vec<f64> = m.points.iter().map(|p| p.0.phi).collect();
            let mm: Vec<f64> = m.points.iter().map(|p| p.0.m).collect();
            p.push(Series::line(&m.model.label(), &deg(&phi), &mm));
        }
        figs.save(&p, out, "hinge_moment")?;
        let mut p = Plot::new(
            "Rotational stiffness of the base cross-hinge",
            "rotation of B about z (°)",
            "stiffness (N m/rad)",
        );
        let (mid, ks): (Vec<f64>, Vec<f64>) = self.solid.secants().into_iter().unzip();
        p.push(Series::points(
            "solid, ΔM/Δϕ between its angles",
            &deg(&mid),
            &ks,
        ));
        for m in &self.models {
            let phi: Vec<f64> = m.points.iter().map(|p| p.0.phi).collect();
            let k: Vec<f64> = m.points.iter().map(|p| p.1).collect();
            p.push(Series::line(
                &format!("{}, dM/dϕ", m.model.label()),
                &deg(&phi),
                &k,
            ));
        }
        figs.save(&p, out, "hinge_stiffness")?;
        let phi_s: Vec<f64> = self.solid.points.iter().map(|p| p.0.phi).collect();
        for j in 0..MODES {
            let mut p = Plot::new(
                &format!("f{} of the base cross-hinge with its link", j + 1),
                "rotation of B about z (°)",
                &format!("f{} (Hz)", j + 1),
            );
            let fs: Vec<f64> = self.solid.points.iter().map(|p| p.1[j]).collect();
            p.push(Series::points("solid", &deg(&phi_s), &fs));
            for m in &self.models {
                let f: Vec<f64> = m.points.iter().map(|p| p.2[j]).collect();
                p.push(Series::line(&m.model.label(), &deg(&phi_s), &f));
            }
            figs.save(&p, out, &format!("hinge_f{}", j + 1))?;
        }
        let _ = writeln!(s, "{}", figs.markdown(|f| f.starts_with("hinge_")));
        Ok(s)
    }

    /// The models' states as CSV: model, ϕ (°), M (N m), dM/dϕ (N m/rad),
    /// u_x, u_y (m), f1 … f6 (Hz), with the solid's rows first.
    pub fn csv(&self) -> String {
        let mut s = String::from("model,phi_deg,M,dM_dphi,ux,uy");
        for j in 0..MODES {
            let _ = write!(s, ",f{}", j + 1);
        }
        s.push('\n');
        let mut row = |name: &str, st: &HingeState, k: Option<f64>, f: &[f64]| {
            let _ = write!(
                s,
                "{name},{:.9},{:.9e},{},{:.9e},{:.9e}",
                st.phi.to_degrees(),
                st.m,
                k.map(|k| format!("{k:.9e}")).unwrap_or_default(),
                st.u[0],
                st.u[1]
            );
            for v in f.iter().take(MODES) {
                let _ = write!(s, ",{v:.6}");
            }
            s.push('\n');
        };
        for (st, f) in &self.solid.points {
            row("solid", st, None, f);
        }
        for m in &self.models {
            for (st, k, f) in &m.points {
                row(&m.model.label().replace(',', ""), st, Some(*k), f);
            }
        }
        s
    }
}

/// `cargo xtask hinge4`: the comparison with the stored solid written to
/// `out`: `report.md` (the section), `hinge.csv` ([`Comparison::csv`]),
/// the figures, and each model's scene (`scene_*.ron`, for `flexmb`).
pub fn write_report(root: &Path, out: &Path) -> Result<(), String> {
    let io = |e: std::io::Error| format!("{}: {e}", out.display());
    std::fs::create_dir_all(out).map_err(io)?;
    let t = std::time::Instant::now();
    let c = Comparison::compute(root)?;
    let mut figs = Figures::default();
    let mut md = c.section(&mut figs, out).map_err(io)?;
    let _ = writeln!(
        md,
        "All models in {:.1} s (wall time, {} models in parallel).",
        t.elapsed().as_secs_f64(),
        c.models.len()
    );
    std::fs::write(out.join("report.md"), md).map_err(io)?;
    std::fs::write(out.join("hinge.csv"), c.csv()).map_err(io)?;
    for m in MODELS {
        let text = scene(m, HEAD)?.to_ron();
        std::fs::write(out.join(format!("scene_{}.ron", m.slug())), text).map_err(io)?;
    }
    println!(
        "wrote {} in {:.0} s",
        out.join("report.md").display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
