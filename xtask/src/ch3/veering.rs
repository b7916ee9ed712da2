//! Where modes 4 and 5 of §3.5.1's flexure meet (Fig. 3.10b, "start to veer
//! with each other around 2 degrees"): a crossing or a veering.
//!
//! The layout of [`super::scene`] is mirror-symmetric about the sheet's
//! mid-plane y = 0 (the link lies in the plane of bending), so the bending
//! mode (symmetric) and the torsion mode (antisymmetric) cannot couple and
//! their frequencies cross. Fig. 3.9, which fixed the layout, is lost; a
//! link attached off the sheet's mid-height ([`super::scene_with_offset`],
//! the mass at y = e) breaks the symmetry and makes the two modes veer. This
//! module measures both: the closest approach of ω4 and ω5 on ever finer
//! grids ([`refine`]; a crossing's gap goes to zero with the step, a
//! veering's converges to a positive value), and the exchange of the two
//! modes' character across it ([`bending_content`]: the mass-weighted MAC of
//! mode 4 with the symmetric layout's bending mode at the same moment).

use super::{flexure_mechanism, rotation_about, Kind, M_MAX, SEGMENTS};
use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_linearize::mac;
use flexmb_model::Mechanism;
use flexmb_reduction::MechanicalModel;
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// The mass's offsets e along the sheet's height (m) of the report's
/// variants: 0 (the symmetric layout) up to h/2, the link attached at the
/// sheet's top edge.
pub const OFFSETS: [f64; 5] = [0.0, 0.0025, 0.005, 0.01, 0.02];

/// Modes kept per point (ω4 and ω5 and one above).
pub const COUNT: usize = 6;

/// Points per refinement level (over the two grid intervals around the
/// previous level's closest point: the step shrinks tenfold).
pub const PER_LEVEL: usize = 21;

/// One equilibrium with its modes.
pub struct ModalPoint {
    /// The load scale λ (M = λ [`M_MAX`]).
    pub lambda: f64,
    /// The end's rotation ϕ (degrees).
    pub phi: f64,
    /// The lowest eigenfrequencies (Hz), ascending.
    pub freqs: Vec<f64>,
    /// Their mass-normalized mode shapes in q, one column each.
    pub vectors: Mat<f64>,
    /// The mass matrix of the rest linearization (E.6).
    pub mass: Mat<f64>,
}

impl ModalPoint {
    /// ω5 − ω4 (Hz).
    pub fn gap(&self) -> f64 {
        self.freqs[4] - self.freqs[3]
    }
}

/// The equilibria of `mech` at the load scales `lambdas` (continuation from
/// λ = 0) with the lowest [`COUNT`] modes of the rest linearization (E.6)
/// at each.
pub fn modal_points(mech: &Arc<Mechanism>, lambdas: &[f64]) -> Result<Vec<ModalPoint>, String> {
    let phi = rotation_about(mech, &format!("N{SEGMENTS}"), 1)?;
    let mut dy = Dynamics::new(mech.clone());
    let eqs = dy
        .equilibria_over_load_scale(0.0, lambdas, &mut |_| {})
        .map_err(|e| format!("{}: {e}", mech.name))?;
    lambdas
        .iter()
        .zip(eqs)
        .map(|(l, eq)| {
            let at = |e: String| format!("{} at M = {} N m: {e}", mech.name, l * M_MAX);
            dy.set_load_scale(*l);
            dy.kinematics_mut().set_guess(&eq.x);
            let lin = dy
                .linearize_at_rest(0.0, &eq.coordinates)
                .map_err(|e| at(e.to_string()))?;
            let modes = flexmb_linearize::undamped_modes(&lin, COUNT.min(lin.m.nrows()))
                .map_err(|e| at(e.to_string()))?;
            if modes.len() < 5 {
                return Err(at(format!("{} modes, 5 needed", modes.len())));
            }
            Ok(ModalPoint {
                lambda: *l,
                phi: phi(&eq.x),
                freqs: modes.frequencies_hz(),
                vectors: modes.vectors,
                mass: lin.m,
            })
        })
        .collect()
}

/// The closest approach of ω4 and ω5 on one grid.
#[derive(Clone, Debug)]
pub struct Closest {
    /// The grid's step in M (N m).
    pub step: f64,
    /// λ of the grid point where ω5 − ω4 is smallest.
    pub lambda: f64,
    /// ϕ there (degrees).
    pub phi: f64,
    /// ω4 and ω5 there (Hz).
    pub f4: f64,
    /// ω5 there (Hz).
    pub f5: f64,
}

impl Closest {
    /// ω5 − ω4 (Hz).
    pub fn gap(&self) -> f64 {
        self.f5 - self.f4
    }
}

fn closest_on(points: &[ModalPoint], step: f64) -> Option<(usize, Closest)> {
    let (i, p) = points
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.gap().total_cmp(&b.1.gap()))?;
    Some((
        i,
        Closest {
            step,
            lambda: p.lambda,
            phi: p.phi,
            f4: p.freqs[3],
            f5: p.freqs[4],
        },
    ))
}

/// The closest approach of ω4 and ω5 on `levels` + 1 ever finer grids: the
/// first is `lambdas` (ascending, evenly spaced), each next one
/// [`PER_LEVEL`] points over the two intervals of the previous grid around
/// its closest point (the step shrinks by (PER_LEVEL − 1)/2 per level).
/// Where the two modes cross, the smallest gap goes to zero with the step;
/// where they veer, it converges to a positive value.
pub fn refine(
    mech: &Arc<Mechanism>,
    lambdas: &[f64],
    levels: usize,
) -> Result<Vec<Closest>, String> {
    if lambdas.len() < 2 {
        return Err("refine: at least two load scales".into());
    }
    let mut grid = lambdas.to_vec();
    let mut out = vec![];
    for _ in 0..=levels {
        let step = (grid[1] - grid[0]) * M_MAX;
        let points = modal_points(mech, &grid)?;
        let (i, c) = closest_on(&points, step).ok_or("refine: an empty grid")?;
        out.push(c);
        let (lo, hi) = (grid[i.saturating_sub(1)], grid[(i + 1).min(grid.len() - 1)]);
        grid = (0..PER_LEVEL)
            .map(|k| lo + (hi - lo) * k as f64 / (PER_LEVEL - 1) as f64)
            .collect();
    }
    Ok(out)
}

/// Which of the symmetric layout's modes 4 and 5 (index 3 or 4) is the
/// bending mode at λ, given where its two frequencies cross (`crossing`):
/// mode 4 on the side of λ = 0, mode 5 beyond.
fn bending_index(lambda: f64, crossing: f64) -> usize {
    if lambda > crossing {
        3
    } else {
        4
    }
}

/// The bending content of mode 4 of `p` (an asymmetric variant): its MAC,
/// weighted by `p`'s mass matrix, with the symmetric layout's bending mode
/// at the same moment (`sym`, whose modes 4 and 5 cross at λ = `crossing`).
/// 1: mode 4 is the bending mode; 0: it is the torsion mode (the symmetric
/// layout's two modes are orthogonal); in between, a mixture.
pub fn bending_content(p: &ModalPoint, sym: &ModalPoint, crossing: f64) -> f64 {
    let b = bending_index(sym.lambda, crossing);
    mac(
        p.vectors.col_as_slice(3),
        sym.vectors.col_as_slice(b),
        Some(&p.mass),
    )
}

/// Half the width (N m) of the zoom around the symmetric layout's crossing
/// on which [`Variant::curve`] is sampled (about ±0.11°).
pub const ZOOM: f64 = 0.001;

/// Points of the zoom: an even number, so that none lies on the crossing
/// itself, where the symmetric layout's two modes are degenerate and its
/// bending mode is not defined.
pub const ZOOM_POINTS: usize = 80;

/// What [`measure`] finds for one offset.
pub struct Variant {
    /// The mass's offset e along the sheet's height (m).
    pub offset: f64,
    /// The zoom around the symmetric layout's crossing (M within ±[`ZOOM`]
    /// of it): M (N m), ϕ (degrees), ω4, ω5 (Hz) and the bending content of
    /// mode 4 ([`bending_content`]) at each point.
    pub curve: Vec<[f64; 5]>,
    /// The closest approach on each refinement level.
    pub levels: Vec<Closest>,
    /// The bending content of mode 4 at the finest level's closest point.
    pub content_at_closest: f64,
}

impl Variant {
    /// The smallest gap on the finest grid (Hz).
    pub fn gap(&self) -> f64 {
        self.levels.last().map_or(f64::NAN, Closest::gap)
    }
}

/// Measures the meeting of modes 4 and 5 of `kind` (superelement file
/// `file` in `dir`) for each of `offsets`: [`refine`] from the grid
/// `lambdas` (ascending, evenly spaced) with `levels` refinements, and the
/// [`ZOOM`] around the symmetric layout's crossing; the offsets in
/// parallel. The symmetric layout (offset 0) is always computed: its modes
/// are the reference shapes of [`bending_content`].
pub fn measure(
    kind: Kind,
    dir: &Path,
    file: &str,
    offsets: &[f64],
    lambdas: &[f64],
    levels: usize,
) -> Result<Vec<Variant>, String> {
    let sym_mech = flexure_mechanism(kind, dir, file, 0.0)?;
    let sym_levels = refine(&sym_mech, lambdas, levels)?;
    let crossing = sym_levels.last().map_or(f64::NAN, |c| c.lambda);
    let zoom: Vec<f64> = (0..ZOOM_POINTS)
        .map(|k| crossing + (2.0 * k as f64 / (ZOOM_POINTS - 1) as f64 - 1.0) * ZOOM / M_MAX)
        .collect();
    let sym = modal_points(&sym_mech, &zoom)?;
    offsets
        .par_iter()
        .map(|e| {
            let m = flexure_mechanism(kind, dir, file, *e)?;
            let (points, levels) = if *e == 0.0 {
                (None, sym_levels.clone())
            } else {
                (Some(modal_points(&m, &zoom)?), refine(&m, lambdas, levels)?)
            };
            let points = points.as_deref().unwrap_or(&sym);
            let curve = points
                .iter()
                .zip(&sym)
                .map(|(p, s)| {
                    [
                        p.lambda * M_MAX,
                        p.phi,
                        p.freqs[3],
                        p.freqs[4],
                        bending_content(p, s, crossing),
                    ]
                })
                .collect();
            // the shapes at the finest grid's closest point
            let c = levels.last().ok_or("no refinement level")?;
            let at = modal_points(&m, &[c.lambda])?;
            let s = modal_points(&sym_mech, &[c.lambda])?;
            Ok(Variant {
                offset: *e,
                curve,
                levels,
                content_at_closest: bending_content(&at[0], &s[0], crossing),
            })
        })
        .collect()
}

/// A stored pair of CalculiX solids of the flexure (C3D20R), each refined
/// around where its modes 4 and 5 meet (`research/ch3/flexure.py --refine`):
/// the symmetric layout and the mass lifted by [`SOLID_OFFSET_E`].
pub struct SolidPair {
    /// The mesh (length × height × thickness).
    pub mesh: &'static str,
    /// The symmetric layout's file.
    pub symmetric: &'static str,
    /// The asymmetric layout's file (`--offset 0.02`).
    pub offset: &'static str,
}

/// The stored solids, coarse to fine.
pub const SOLIDS: [SolidPair; 2] = [
    SolidPair {
        mesh: "8 × 8 × 1",
        symmetric: "fixtures/curves/solid/flexure_ch3_veering_refined_8x8x1.csv",
        offset: "fixtures/curves/solid/flexure_ch3_veering_offset20mm_8x8x1.csv",
    },
    SolidPair {
        mesh: "16 × 16 × 1",
        symmetric: "fixtures/curves/solid/flexure_ch3_veering_refined_16x16x1.csv",
        offset: "fixtures/curves/solid/flexure_ch3_veering_offset20mm_16x16x1.csv",
    },
];

/// The mass's offset of [`SolidPair::offset`] (m): h/2.
pub const SOLID_OFFSET_E: f64 = 0.02;

/// The sample of a solid where ω5 − ω4 is smallest.
pub fn solid_closest(points: &[super::SolidPoint]) -> Option<&super::SolidPoint> {
    points
        .iter()
        .filter(|p| p.freqs.len() >= 5)
        .min_by(|a, b| (a.freqs[4] - a.freqs[3]).total_cmp(&(b.freqs[4] - b.freqs[3])))
}
