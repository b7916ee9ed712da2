//! Beyond the thesis (its recommendation 3, issue 18): the chapter-7
//! mechanism reduced over **two configuration coordinates**, the
//! end-effector's x and y over the whole 100 × 100 mm workspace, with the
//! interpolated basis on a tensor grid ([`GridBasis`]): z = (x, y, η),
//! q = Q(x, y) + V(x, y)η + q0.
//!
//! V spans, at each grid point, the unconstrained eigenvectors of the
//! mechanism held there (no gravity, as the one-coordinate IBM-u) up to
//! 200 Hz, the first eight, orthonormalized (7.6), without the first two:
//! those are the mechanism modes, the motion of the end-effector in the
//! plane, which the two configuration coordinates carry through Q,x and
//! Q,y (with one coordinate, IBM-u keeps the combination across the path,
//! V_b of (7.6); with both coordinates free nothing is left of V_p). So
//! n_z = 2 + 6 = 8, as the one-coordinate models.

use crate::ch4::path::{Path4, RADIUS};
use crate::ch7;
use faer::Mat;
use flexmb_dynamics::{Dynamics, StaticOptions};
use flexmb_linearize::{undamped_modes, SweepPoint};
use flexmb_model::{Mechanism, TimeFunction};
use flexmb_reduction::{orthonormalize, GridBasis};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// The half width of the square workspace about the undeflected position
/// (m): 100 × 100 mm, which the path's circle (4.1b) fills.
pub const HALF_WIDTH: f64 = RADIUS;

/// The grid lines of an n × n grid over the workspace: n equally spaced
/// offsets from the undeflected position in [−50, 50] mm.
pub fn grid_lines(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| -HALF_WIDTH + 2.0 * HALF_WIDTH * i as f64 / (n - 1) as f64)
        .collect()
}

/// `count` check points over the workspace, off every grid line of
/// [`grid_lines`]: the Halton sequence in bases 2 and 3 (from its second
/// point on) shifted by the fractional parts (√5 − 1)/2 and √2 − 1 modulo 1
/// (unshifted, its dyadic x values put the second point on the grid line
/// x = 0 of every odd grid, where the interpolation along x is exact),
/// scaled to the workspace and inset by 1 % of its width.
pub fn halton_points(count: usize) -> Vec<[f64; 2]> {
    let radical_inverse = |mut i: usize, base: usize| {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    };
    let shift = [0.5 * (5.0f64.sqrt() - 1.0), 2.0f64.sqrt() - 1.0];
    let w = 2.0 * HALF_WIDTH * 0.98;
    (1..=count)
        .map(|i| {
            let u = [
                (radical_inverse(i, 2) + shift[0]).fract(),
                (radical_inverse(i, 3) + shift[1]).fract(),
            ];
            [-0.5 * w + w * u[0], -0.5 * w + w * u[1]]
        })
        .collect()
}

/// The longest step (m) between consecutive equilibria of
/// [`held_equilibria`]'s continuation: longer legs get intermediate
/// equilibria (without modes). Measured: with steps
/// up to 25 mm, some solves failed at once (from the undeflected position
/// to (0, −25) mm or (−16.7, −16.7) mm: "element hf_x1.main.clamp_b has
/// flipped" at the smallest load increment) while others of 50 mm
/// converged; with 5 mm steps all did. 6.5 mm: one step per cell of the
/// 17 × 17 grid (6.25 mm), about the path sweep's 4.3 mm of chapter 7.
pub const MAX_STEP: f64 = 0.0065;

/// A polyline from the undeflected position through the end-effector
/// offsets `points`, and the sweep values (arc lengths) that walk along it
/// in steps of at most [`MAX_STEP`]: the first at the undeflected position
/// itself, and for each point the index of its value.
struct Polyline {
    nodes: Vec<[f64; 2]>,
    arc: Vec<f64>,
    values: Vec<f64>,
    of_point: Vec<usize>,
}

impl Polyline {
    fn new(points: &[[f64; 2]]) -> Self {
        let mut nodes = vec![[0.0, 0.0]];
        nodes.extend_from_slice(points);
        let mut arc = vec![0.0];
        let (mut values, mut of_point) = (vec![0.0], vec![]);
        for w in nodes.windows(2) {
            let a0 = arc.last().copied().unwrap_or(0.0);
            let d = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
            let steps = (d / MAX_STEP).ceil().max(1.0) as usize;
            values.extend((1..=steps).map(|k| a0 + d * k as f64 / steps as f64));
            of_point.push(values.len() - 1);
            arc.push(a0 + d);
        }
        Self {
            nodes,
            arc,
            values,
            of_point,
        }
    }

    /// The offset at arc length s.
    fn at(&self, s: f64) -> [f64; 2] {
        let arc = &self.arc;
        let k = arc.partition_point(|a| *a <= s).clamp(1, arc.len() - 1);
        let t = if arc[k] > arc[k - 1] {
            ((s - arc[k - 1]) / (arc[k] - arc[k - 1])).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (a, b) = (self.nodes[k - 1], self.nodes[k]);
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    }
}

/// The equilibria of the mechanism (no gravity) with the end-effector held
/// at the offsets `points` from its undeflected position, with `modes`
/// modes each (shapes and masses kept), in the order given. Phase 1: one
/// continuation along the polyline through them from the undeflected
/// position, in steps of at most [`MAX_STEP`] (so consecutive points
/// should be near each other: a grid is visited row by row, back and
/// forth), each static solve from the last equilibrium. Phase 2: the rest
/// linearization (E.6) and the modes of the requested points only, in
/// parallel (rayon), each from its equilibrium's own configuration. The
/// points' `s` is their arc length along the polyline.
/// `progress(done, total)` counts the intermediate equilibria too. An
/// error names the point whose equilibrium failed, and a static solve that
/// switched an Euler chart or the dependent coordinates (the points would
/// be in other DOFs; not met in the workspace).
pub fn held_equilibria(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    points: &[[f64; 2]],
    modes: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<SweepPoint>, String> {
    let line = Polyline::new(points);
    let q0 = mech.q0();
    let (x0, y0) = (q0[dofs[0]], q0[dofs[1]]);
    let total = line.values.len() + points.len();
    let mut dy = Dynamics::new(mech.clone());
    let mut q = q0.clone();
    let mut found = Vec::with_capacity(points.len());
    for (i, s) in line.values.iter().enumerate() {
        let p = line.at(*s);
        let so = StaticOptions {
            ramp_loads: i == 0,
            held: vec![(dofs[0], x0 + p[0]), (dofs[1], y0 + p[1])],
            ..Default::default()
        };
        let at = || format!("({:.2}, {:.2}) mm", 1e3 * p[0], 1e3 * p[1]);
        let sol = dy
            .static_equilibrium(0.0, &q, &so)
            .map_err(|e| format!("the end-effector held at {}: {e}", at()))?;
        if !sol.chart_switches.is_empty() || !sol.partition_switches.is_empty() {
            return Err(format!(
                "the end-effector held at {}: the static solve changed the DOFs (an Euler \
                 chart or the dependent coordinates)",
                at()
            ));
        }
        q = sol.q;
        if line.of_point.get(found.len()) == Some(&i) {
            found.push((*s, q.clone(), sol.x, sol.reactions));
        }
        progress(i + 1, total);
    }
    let done = AtomicUsize::new(line.values.len());
    found
        .par_iter()
        .map_init(
            || Dynamics::new(mech.clone()),
            |dy, (s, q, x, holding)| {
                dy.kinematics_mut().set_guess(x);
                let lin = dy.linearize_at_rest(0.0, q).map_err(|e| e.to_string())?;
                let m = undamped_modes(&lin, modes).map_err(|e| e.to_string())?;
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                Ok(SweepPoint {
                    s: *s,
                    q: q.clone(),
                    holding: holding.clone(),
                    x: x.clone(),
                    frequencies_hz: m.frequencies_hz(),
                    modes: Some(m.vectors),
                    mass: Some(lin.m),
                })
            },
        )
        .collect()
}

/// The grid points of an n × n grid in the order index i + n j (x
/// fastest), and the order in which a continuation visits them (row by
/// row, every other row backwards).
pub fn serpentine(n: usize) -> (Vec<[f64; 2]>, Vec<usize>) {
    let g = grid_lines(n);
    let points = (0..n * n).map(|k| [g[k % n], g[k / n]]).collect();
    let order = (0..n)
        .flat_map(|j| {
            (0..n).map(move |i| {
                let i = if j % 2 == 0 { i } else { n - 1 - i };
                i + n * j
            })
        })
        .collect();
    (points, order)
}

/// The equilibria at the n × n grid points, in the grid's order (i + n j).
pub fn grid_equilibria(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    n: usize,
    modes: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<SweepPoint>, String> {
    let (points, order) = serpentine(n);
    let visited: Vec<[f64; 2]> = order.iter().map(|k| points[*k]).collect();
    let swept = held_equilibria(mech, dofs, &visited, modes, progress)?;
    let mut out: Vec<Option<SweepPoint>> = vec![None; n * n];
    for (p, k) in swept.into_iter().zip(&order) {
        out[*k] = Some(p);
    }
    out.into_iter()
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| "the grid sweep stopped early".into())
}

/// The sub-grid of every `step`-th grid line of an n × n grid's points
/// (grid order), n − 1 divisible by `step`: the coarser grids of one sweep.
pub fn sub_grid<T: Clone>(points: &[T], n: usize, step: usize) -> Vec<T> {
    let m = (n - 1) / step + 1;
    (0..m * m)
        .map(|k| points[(k % m) * step + n * ((k / m) * step)].clone())
        .collect()
}

/// The base vectors at one grid point: its first [`ch7::R`] unconstrained
/// eigenvectors orthonormalized (7.6), without the two mechanism modes
/// (n_q × 6; see the module documentation).
pub fn grid_vectors(p: &SweepPoint) -> Result<Mat<f64>, String> {
    let v = p.modes.as_ref().ok_or("the sweep kept no mode shapes")?;
    if v.ncols() < ch7::R {
        return Err(format!(
            "the sweep kept {} mode shapes, {} are needed",
            v.ncols(),
            ch7::R
        ));
    }
    let o = orthonormalize(&v.subcols(0, ch7::R).to_owned());
    Ok(o.subcols(2, ch7::R - 2).to_owned())
}

/// The equilibrium surface's tangents ∂q/∂x and ∂q/∂y at each of `points`
/// (held equilibria of the end-effector's DOFs `dofs`;
/// [`ch7::held_tangents`]).
pub fn grid_tangents(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    points: &[SweepPoint],
) -> Result<Vec<[Vec<f64>; 2]>, String> {
    Ok(ch7::held_tangents(mech, dofs, points)?
        .iter()
        .map(|t| [t.col_as_slice(0).to_vec(), t.col_as_slice(1).to_vec()])
        .collect())
}

/// The grid basis over the n × n grid of `points` (grid order, from
/// [`grid_equilibria`] or [`sub_grid`]): Q through the equilibria (the
/// bicubic Hermite interpolant when their `tangents` from
/// [`grid_tangents`] are given, else the natural bicubic spline), V by MSI
/// over the grid with the mass normalization (6.26).
pub fn basis(
    mech: &Arc<Mechanism>,
    points: &[SweepPoint],
    n: usize,
    tangents: Option<&[[Vec<f64>; 2]]>,
) -> Result<GridBasis, String> {
    let vecs = points
        .iter()
        .map(grid_vectors)
        .collect::<Result<Vec<_>, _>>()?;
    let masses: Vec<Mat<f64>> = points
        .iter()
        .map(|p| p.mass.clone().ok_or("the sweep kept no mass matrices"))
        .collect::<Result<_, _>>()?;
    let qs: Vec<Vec<f64>> = points.iter().map(|p| p.q.clone()).collect();
    let g = grid_lines(n);
    match tangents {
        Some(t) => GridBasis::with_tangents(mech.q0(), g.clone(), g, &qs, t, &vecs, Some(&masses)),
        None => GridBasis::new(mech.q0(), g.clone(), g, &qs, &vecs, Some(&masses)),
    }
    .map_err(|e| e.to_string())
}

/// The reduced coordinates of an equilibrium of `mech` held at the
/// end-effector offset (x, y): z = (x − x0, y − y0, 0).
pub fn z_at(mech: &Mechanism, dofs: [usize; 2], p: &SweepPoint) -> Vec<f64> {
    let q0 = mech.q0();
    let mut z = vec![0.0; ch7::R];
    z[0] = p.q[dofs[0]] - q0[dofs[0]];
    z[1] = p.q[dofs[1]] - q0[dofs[1]];
    z
}

/// A path that the one-coordinate models were not built for: a circle of
/// radius 25 mm about (−15, 15) mm from the undeflected position,
/// counter-clockwise from its point nearest +x, reached by a straight line
/// from the undeflected position (where the closed loop starts), by arc
/// length. It stays inside the workspace (x ∈ [−40, 10] mm, y ∈ [−10,
/// 40] mm) and crosses the path (4.1) nowhere along a common tangent.
#[derive(Clone, Copy, Debug)]
pub struct OffCentreCircle;

impl OffCentreCircle {
    /// The circle's centre (m, from the undeflected position).
    pub const CENTRE: [f64; 2] = [-0.015, 0.015];
    /// Its radius (m).
    pub const RADIUS: f64 = 0.025;

    fn start() -> [f64; 2] {
        [Self::CENTRE[0] + Self::RADIUS, Self::CENTRE[1]]
    }

    /// The length of the straight lead-in (m).
    pub fn lead_in(&self) -> f64 {
        let s = Self::start();
        s[0].hypot(s[1])
    }

    /// The whole length (m).
    pub fn length(&self) -> f64 {
        self.lead_in() + 2.0 * PI * Self::RADIUS
    }

    /// The end-effector offset at arc length s (clamped to the path).
    pub fn at(&self, s: f64) -> [f64; 2] {
        let s = s.clamp(0.0, self.length());
        let l = self.lead_in();
        if s <= l {
            let a = Self::start();
            [a[0] * s / l, a[1] * s / l]
        } else {
            let phi = (s - l) / Self::RADIUS;
            [
                Self::CENTRE[0] + Self::RADIUS * phi.cos(),
                Self::CENTRE[1] + Self::RADIUS * phi.sin(),
            ]
        }
    }

    /// The five stops: the end of the lead-in, then every quarter turn.
    pub fn marks(&self) -> [f64; 5] {
        let q = 0.5 * PI * Self::RADIUS;
        std::array::from_fn(|k| self.lead_in() + k as f64 * q)
    }

    /// The reference motion s(t): five skew-sine moves (7.13) to the marks,
    /// timed as chapter 7's ([`ch7::reference_motion`]).
    pub fn motion(&self) -> TimeFunction {
        ch7::skew_sine_moves(&self.marks())
    }

    /// The reduced coordinates of the grid model with η ≡ 0 at arc length s.
    pub fn z(&self, s: f64) -> Vec<f64> {
        let p = self.at(s);
        let mut z = vec![0.0; ch7::R];
        z[..2].copy_from_slice(&p);
        z
    }
}

/// The unreduced equilibria along the off-centre circle at `n` equally
/// spaced arc lengths (lead-in included), modes kept.
pub fn circle_equilibria(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    n: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<SweepPoint>, String> {
    let c = OffCentreCircle;
    let pts: Vec<[f64; 2]> = (1..=n)
        .map(|i| c.at(c.length() * i as f64 / n as f64))
        .collect();
    held_equilibria(mech, dofs, &pts, ch7::R, progress)
}

/// Equilibria on the path (4.1) at `n` arc lengths halfway between n + 1
/// equally spaced ones (off the ch7 references), reached along the chords
/// between them.
pub fn path_equilibria(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    n: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<SweepPoint>, String> {
    let path = Path4::new();
    let l = path.length();
    let pts: Vec<[f64; 2]> = (0..n)
        .map(|i| path.at(l * (i as f64 + 0.5) / n as f64).0)
        .collect();
    held_equilibria(mech, dofs, &pts, ch7::R, progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sub_grids_and_the_serpentine_visit_the_grid() {
        let (pts, order) = serpentine(5);
        let mut seen = order.clone();
        seen.sort();
        assert_eq!(seen, (0..25).collect::<Vec<_>>());
        // consecutive points are neighbours
        for w in order.windows(2) {
            let (a, b) = (pts[w[0]], pts[w[1]]);
            assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 0.0251);
        }
        let coarse = sub_grid(&pts, 5, 2);
        assert_eq!(coarse, serpentine(3).0);
        assert_eq!(sub_grid(&pts, 5, 4), serpentine(2).0);
    }

    #[test]
    fn the_check_points_are_inside_and_off_the_grids() {
        let h = halton_points(64);
        for p in &h {
            for n in [2, 3, 5, 9, 17] {
                for g in grid_lines(n) {
                    assert!(
                        (p[0] - g).abs() > 1e-5 && (p[1] - g).abs() > 1e-5,
                        "{p:?} on the grid line {g} of {n} × {n}"
                    );
                }
            }
            assert!(p[0].abs() < HALF_WIDTH && p[1].abs() < HALF_WIDTH);
        }
    }

    #[test]
    fn the_off_centre_circle_is_continuous_and_in_the_workspace() {
        let c = OffCentreCircle;
        let n = 2000;
        let mut prev = c.at(0.0);
        assert_eq!(prev, [0.0, 0.0]);
        for i in 1..=n {
            let p = c.at(c.length() * i as f64 / n as f64);
            let d = (p[0] - prev[0]).hypot(p[1] - prev[1]);
            assert!(d <= c.length() / n as f64 * (1.0 + 1e-9));
            assert!(p[0].abs() <= HALF_WIDTH && p[1].abs() <= HALF_WIDTH);
            prev = p;
        }
        let m = c.marks();
        let end = c.at(m[4]);
        assert!((end[0] - c.at(m[0])[0]).abs() < 1e-12);
    }
}
