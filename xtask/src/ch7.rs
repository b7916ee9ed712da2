//! Chapter 7: the two-DOF mechanism of chapter 4 ([`crate::ch4`]) reduced
//! along its path (4.1) by the interpolated basis method with constrained
//! (IBM-c, (7.3)–(7.5)) and unconstrained (IBM-u, (7.6)–(7.11)) eigenvectors,
//! 8 DOF z = (s, η) instead of 664, and its closed-loop time response under
//! the PD controllers (7.12) of Table 7.1 on the actuator hinges of §7.2.1,
//! following five skew-sine moves (7.13) along the path.

use crate::ch4::path::Path4;
use crate::ch4::scene::{ACTUATORS, END_EFFECTOR_NODE};
use crate::ch4::sweep;
use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_linearize::SweepPoint;
use flexmb_model::{ControllerSpec, Mechanism, Scene, Select, TimeFunction};
use flexmb_reduction::{
    constrained_eigenvectors, unconstrained_path_eigenvectors, Basis, CubicSpline,
    InterpolatedBasis, ReducedModel, SubspaceInterpolation,
};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Table 7.1: proportional gains (N m/rad) of the x and y controllers.
pub const KP: [f64; 2] = [5500.0, 2500.0];
/// Table 7.1: derivative gains (N m s/rad).
pub const KD: [f64; 2] = [40.0, 17.0];
/// Table 7.2: the closed-loop modes (frequency Hz, damping ratio).
pub const THESIS_POLES: [(f64, f64); 2] = [(27.34, 0.60), (31.74, 0.70)];
/// Reference configurations along the path (§7.2.1).
pub const N_REFERENCE: usize = 100;
/// Modes kept: up to 200 Hz, the first eight (r = 8, m = 2: 7 vectors).
pub const R: usize = 8;
/// The simulated time (s) and outputs (§7.2.3).
pub const T_END: f64 = 1.5;
/// Output points (1000 equidistant steps).
pub const OUTPUTS: usize = 1001;
/// Each move's duration T (s), (7.13), and the stop after it.
pub const MOVE_TIME: f64 = 0.25;
/// The stop after each move (s).
pub const DWELL: f64 = 0.05;
/// Gravity (m/s²) in −z for the closed loop.
pub const GRAVITY: f64 = 9.81;

/// The two reduced models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// Constrained eigenvectors (7.3)–(7.5).
    Constrained,
    /// Unconstrained eigenvectors (7.6)–(7.11).
    Unconstrained,
}

impl Variant {
    /// The thesis's name.
    pub fn label(self) -> &'static str {
        match self {
            Variant::Constrained => "IBM-c",
            Variant::Unconstrained => "IBM-u",
        }
    }
}

/// The scene with the actuator hinges (`cargo xtask mechanism4`).
pub fn scene_path(root: &Path) -> PathBuf {
    root.join("fixtures")
        .join("scenes")
        .join(crate::ch4::ACTUATED_SCENE_FILE)
}

/// The actuated mechanism with the end-effector's x and y as its first
/// degrees of freedom (the path coordinates, which IBM-c needs as DOFs),
/// with gravity along −z if `gravity`, and with the PD controllers (7.12)
/// following `references` (φx, φy) if given. The DOFs are the same in every
/// variant, so one basis serves them all.
pub fn mechanism(
    root: &Path,
    gravity: bool,
    references: Option<&[TimeFunction; 2]>,
) -> Result<(Arc<Mechanism>, [usize; 2]), String> {
    let path = scene_path(root);
    let mut s = Scene::load(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    if gravity {
        s.gravity = Some(vec![0.0, 0.0, -GRAVITY]);
    }
    if let Some(r) = references {
        for (k, (hinge, _, _)) in ACTUATORS.iter().enumerate() {
            s.controllers.push(ControllerSpec {
                on: Select::Def(hinge.to_string(), "rotation".into()),
                kp: KP[k],
                kd: KD[k],
                reference: r[k].clone(),
            });
        }
    }
    sweep::mechanism_of(s, &path)
}

/// The arc lengths of the reference configurations: `n` equally spaced over
/// the path.
pub fn reference_values(n: usize) -> Vec<f64> {
    let l = Path4::new().length();
    (0..n).map(|i| l * i as f64 / (n - 1) as f64).collect()
}

/// The path direction in the DOFs at `s`: P,s(s) on the end-effector's x
/// and y, zero elsewhere (thesis (7.3): the path coordinates are DOFs).
fn path_direction(n_q: usize, dofs: [usize; 2], s: f64) -> Vec<f64> {
    let (_, t, _) = Path4::new().at(s);
    let mut v = vec![0.0; n_q];
    v[dofs[0]] = t[0];
    v[dofs[1]] = t[1];
    v
}

/// The reduced vectors of one reference configuration: IBM-u's V = [V_b,
/// V_a] from the first R unconstrained eigenvectors (7.6)–(7.11), or IBM-c's
/// 7 constrained eigenvectors (7.5) from the rest linearization there.
fn vectors(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    p: &SweepPoint,
    variant: Variant,
    r: usize,
) -> Result<Mat<f64>, String> {
    let n_q = mech.n_dof();
    let dir = path_direction(n_q, dofs, p.s);
    match variant {
        Variant::Unconstrained => {
            let v = p.modes.as_ref().ok_or("the sweep kept no mode shapes")?;
            if v.ncols() < r {
                return Err(format!(
                    "the sweep kept {} mode shapes, {r} are needed",
                    v.ncols()
                ));
            }
            let vu = v.subcols(0, r).to_owned();
            // the path coordinates are DOFs: their rows of F,q are unit rows
            let f_p = Mat::from_fn(2, n_q, |i, j| if j == dofs[i] { 1.0 } else { 0.0 });
            let p_s = [dir[dofs[0]], dir[dofs[1]]];
            unconstrained_path_eigenvectors(&vu, &f_p, &p_s).map_err(|e| e.to_string())
        }
        Variant::Constrained => {
            let mut dy = Dynamics::new(mech.clone());
            dy.kinematics_mut().set_guess(&p.x);
            let lin = dy.linearize_at_rest(0.0, &p.q).map_err(|e| e.to_string())?;
            constrained_eigenvectors(&lin.stiffness_total(), &lin.m, &dir, r - 1)
                .map(|(v, _)| v)
                .map_err(|e| e.to_string())
        }
    }
}

/// The interpolated basis (6.23) of `variant` along the arc length s from
/// the reference configurations `points` (their q, mode shapes and masses):
/// Q(s) through the equilibria, V(s) by MSI with the mass normalization
/// (6.26). z = (s, η), 8 coordinates.
pub fn basis(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    points: &[SweepPoint],
    variant: Variant,
    r: usize,
) -> Result<InterpolatedBasis, String> {
    let vecs = points
        .par_iter()
        .map(|p| vectors(mech, dofs, p, variant, r))
        .collect::<Result<Vec<_>, String>>()?;
    let masses: Vec<Mat<f64>> = points
        .iter()
        .map(|p| p.mass.clone().ok_or("the sweep kept no mass matrices"))
        .collect::<Result<_, _>>()?;
    let s: Vec<f64> = points.iter().map(|p| p.s).collect();
    let qs: Vec<Vec<f64>> = points.iter().map(|p| p.q.clone()).collect();
    InterpolatedBasis::new(
        mech.q0(),
        s,
        &qs,
        &vecs,
        Some(&masses),
        SubspaceInterpolation::Msi,
    )
    .map_err(|e| e.to_string())
}

/// ∂q/∂(x, y) (n_q × 2) at each of the held equilibria `points` of the
/// end-effector's DOFs `dofs`: the static modes of the held DOFs from the
/// tangent stiffness there ([`flexmb_reduction::equilibrium_tangents`]), in
/// parallel.
pub fn held_tangents(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    points: &[SweepPoint],
) -> Result<Vec<Mat<f64>>, String> {
    points
        .par_iter()
        .map_init(
            || Dynamics::new(mech.clone()),
            |dy, p| {
                dy.kinematics_mut().set_guess(&p.x);
                let lin = dy.linearize_at_rest(0.0, &p.q).map_err(|e| e.to_string())?;
                flexmb_reduction::equilibrium_tangents(lin.stiffness_total().as_ref(), &dofs)
                    .map_err(|e| format!("the equilibrium at s = {}: {e}", p.s))
            },
        )
        .collect()
}

/// The equilibrium path's tangents dq/ds at the path equilibria `points`
/// (held on the path (4.1)): [`held_tangents`] times the path's unit tangent
/// dP/ds. Given to [`InterpolatedBasis::with_tangents`], Q,s at every
/// reference is the path's own tangent.
pub fn path_tangents(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    points: &[SweepPoint],
) -> Result<Vec<Vec<f64>>, String> {
    let path = Path4::new();
    Ok(held_tangents(mech, dofs, points)?
        .iter()
        .zip(points)
        .map(|(t, p)| {
            let (_, d, _) = path.at(p.s);
            (0..t.nrows())
                .map(|i| t[(i, 0)] * d[0] + t[(i, 1)] * d[1])
                .collect()
        })
        .collect())
}

/// The reduced model of `basis` on `mech` (its DOFs are the basis's).
pub fn reduced<B: Basis + Clone + 'static>(
    mech: &Arc<Mechanism>,
    basis: &B,
) -> Result<ReducedModel, String> {
    ReducedModel::new(mech.clone(), Box::new(basis.clone())).map_err(|e| e.to_string())
}

/// The first `count` eigenfrequencies of the reduced model at rest at the
/// equilibria `points` of a path sweep (their s, η = 0; the rest
/// linearization (F.7)), in parallel. Each is linearized as the unreduced
/// one was: its holding force a dead load on the path DOFs `dofs` (else
/// the path's curvature turns it into stiffness along s, −G,ssᵀ f), and its
/// position solve starts from the equilibrium's own nodal coordinates
/// (from another configuration Newton may converge to another branch:
/// measured, from the start of the path the solves beyond s ≈ 0.19 m did).
pub fn reduced_frequencies(
    mech: &Arc<Mechanism>,
    basis: &InterpolatedBasis,
    points: &[SweepPoint],
    dofs: [usize; 2],
    count: usize,
) -> Result<Vec<Vec<f64>>, String> {
    let n_z = 1 + basis.r();
    let z_of = |p: &SweepPoint| {
        let mut z = vec![0.0; n_z];
        z[0] = p.s;
        z
    };
    reduced_frequencies_at(mech, basis, points, &z_of, dofs, count)
}

/// [`reduced_frequencies`] of any basis, each equilibrium `p` at the
/// reduced coordinates `z_of(p)` (the grid model: its held x and y).
pub fn reduced_frequencies_at<B: Basis + Clone + Sync + 'static>(
    mech: &Arc<Mechanism>,
    basis: &B,
    points: &[SweepPoint],
    z_of: &(dyn Fn(&SweepPoint) -> Vec<f64> + Sync),
    dofs: [usize; 2],
    count: usize,
) -> Result<Vec<Vec<f64>>, String> {
    let chunk = points
        .len()
        .div_ceil(rayon::current_num_threads().max(1))
        .max(1);
    let n_q = mech.n_dof();
    let blocks: Vec<Result<Vec<Vec<f64>>, String>> = points
        .par_chunks(chunk)
        .map(|block| {
            let mut m = reduced(mech, basis)?;
            let mut load = vec![0.0; n_q];
            block
                .iter()
                .map(|p| {
                    let z = z_of(p);
                    m.dynamics_mut().kinematics_mut().set_guess(&p.x);
                    load[dofs[0]] = p.holding[0];
                    load[dofs[1]] = p.holding[1];
                    let (mz, kz) = m
                        .linearize_at_rest_loaded(0.0, &z, Some(&load))
                        .map_err(|e| format!("the reduced model at z = {z:?}: {e}"))?;
                    let mut f = flexmb_linearize::generalized_symmetric(&kz, &mz, mz.nrows())
                        .map_err(|e| e.to_string())?
                        .frequencies_hz();
                    f.truncate(count);
                    Ok(f)
                })
                .collect()
        })
        .collect();
    let mut out = vec![];
    for b in blocks {
        out.extend(b?);
    }
    Ok(out)
}

/// The reference motion s(t) of §7.2.3: five skew-sine moves (7.13) of
/// T = 0.25 s from stop to stop, each followed by 0.05 s at rest, to the
/// marks s1–s5 of the path (the start of the circle and every quarter turn;
/// Fig. 7.1 with the thesis's stops is lost), over 1.5 s.
pub fn reference_motion() -> TimeFunction {
    skew_sine_moves(&Path4::new().marks())
}

/// Skew-sine moves (7.13) from s = 0 to each of `marks` in turn, each of
/// T = [`MOVE_TIME`] followed by [`DWELL`] at rest (§7.2.3's timing).
pub fn skew_sine_moves(marks: &[f64]) -> TimeFunction {
    let mut prev = 0.0;
    let moves = marks
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let d = m - prev;
            prev = *m;
            (i as f64 * (MOVE_TIME + DWELL), MOVE_TIME, d)
        })
        .collect();
    TimeFunction::SkewSineMoves { start: 0.0, moves }
}

/// The angle references φx(t), φy(t) of the controllers: the actuator
/// hinges' rotations along IBM-u's kinematics with η ≡ 0 (§7.2.3: "the
/// equations of motion do not need to be time integrated"), q = Q(s(t)):
/// the rotations at `samples` arc lengths, a cubic spline in s, and then,
/// with s(t) of [`reference_motion`], C¹ cubic pieces in t every millisecond
/// (value and rate exact at the breaks) as [`TimeFunction::Hermite`].
pub fn angle_references(
    model: &mut ReducedModel,
    samples: usize,
) -> Result<[TimeFunction; 2], String> {
    let n_z = model.n_z();
    let z_of = |s: f64| {
        let mut z = vec![0.0; n_z];
        z[0] = s;
        z
    };
    angle_references_along(
        model,
        samples,
        Path4::new().length(),
        &reference_motion(),
        &z_of,
    )
}

/// [`angle_references`] along any path of arc length `length` that the
/// reduced model describes with η ≡ 0 by z = `z_of(s)` (the one-coordinate
/// models: z = (s, 0); the grid model: z = (x(s), y(s), 0)), followed with
/// the arc length `motion` s(t).
pub fn angle_references_along(
    model: &mut ReducedModel,
    samples: usize,
    length: f64,
    motion: &TimeFunction,
    z_of: &dyn Fn(f64) -> Vec<f64>,
) -> Result<[TimeFunction; 2], String> {
    let mech = model.dynamics().mechanism().clone();
    let eps_index = |hinge: &str| {
        let name = format!("{hinge}.rotation");
        mech.eps_names
            .iter()
            .position(|n| *n == name)
            .ok_or_else(|| format!("no deformation {name}"))
    };
    let idx = [eps_index(ACTUATORS[0].0)?, eps_index(ACTUATORS[1].0)?];
    let l = length;
    let s: Vec<f64> = (0..samples)
        .map(|i| l * i as f64 / (samples - 1) as f64)
        .collect();
    let mut values = vec![];
    for si in &s {
        let q = model.full_coordinates(&z_of(*si));
        let dy = model.dynamics_mut();
        dy.kinematics_mut()
            .solve(&q, 0.0)
            .map_err(|e| format!("the reference kinematics at s = {si}: {e}"))?;
        let eps = dy.kinematics().eps();
        values.push(vec![eps[idx[0]], eps[idx[1]]]);
    }
    let spline = CubicSpline::new(s, values).map_err(|e| e.to_string())?;
    let pieces = (T_END * 1000.0).round() as usize;
    let breaks: Vec<f64> = (0..=pieces)
        .map(|i| T_END * i as f64 / pieces as f64)
        .collect();
    let mut out = [[vec![], vec![]], [vec![], vec![]]];
    let mut work: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; 2]);
    for t in &breaks {
        let (sv, sd, _) = motion.eval(*t);
        spline.eval(sv.clamp(0.0, l), &mut work);
        for k in 0..2 {
            out[k][0].push(work[0][k]);
            out[k][1].push(work[1][k] * sd);
        }
    }
    Ok(std::array::from_fn(|k| TimeFunction::Hermite {
        t: breaks.clone(),
        value: std::mem::take(&mut out[k][0]),
        rate: std::mem::take(&mut out[k][1]),
    }))
}

/// The end-effector node's (x, y, z) in nodal coordinates `x`.
pub fn end_effector(mech: &Mechanism, x: &[f64]) -> [f64; 3] {
    let n = mech.node(END_EFFECTOR_NODE).expect("the end-effector node");
    [x[n.position[0]], x[n.position[1]], x[n.position[2]]]
}

/// The single-sided amplitude spectrum of `y` sampled at `dt` (no window):
/// (frequencies in Hz, amplitudes), DC included.
pub fn amplitude_spectrum(y: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    use rustfft::{num_complex::Complex, FftPlanner};
    let n = y.len();
    let mut buf: Vec<Complex<f64>> = y.iter().map(|v| Complex::new(*v, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let half = n / 2 + 1;
    let f: Vec<f64> = (0..half).map(|k| k as f64 / (n as f64 * dt)).collect();
    let a: Vec<f64> = (0..half)
        .map(|k| {
            let m = buf[k].norm() / n as f64;
            if k == 0 || (n % 2 == 0 && k == n / 2) {
                m
            } else {
                2.0 * m
            }
        })
        .collect();
    (f, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_motion_stops_at_the_marks() {
        let f = reference_motion();
        let marks = Path4::new().marks();
        for (i, m) in marks.iter().enumerate() {
            let t = (i + 1) as f64 * (MOVE_TIME + DWELL) - 0.5 * DWELL;
            let (s, sd, _) = f.eval(t);
            assert!((s - m).abs() < 1e-12 && sd.abs() < 1e-12, "{i}: {s} {sd}");
        }
        // peak speed 2Δs/T of the first move
        let (_, sd, _) = f.eval(0.5 * MOVE_TIME);
        assert!((sd - 2.0 * marks[0] / MOVE_TIME).abs() < 1e-12);
    }

    #[test]
    fn the_spectrum_finds_a_sine() {
        let dt = 1.5 / 1000.0;
        let y: Vec<f64> = (0..1000)
            .map(|i| 0.3 * (2.0 * std::f64::consts::PI * 40.0 * i as f64 * dt).sin())
            .collect();
        let (f, a) = amplitude_spectrum(&y, dt);
        let k = (0..a.len()).max_by(|i, j| a[*i].total_cmp(&a[*j])).unwrap();
        assert!(
            (f[k] - 40.0).abs() < 1.0 && (a[k] - 0.3).abs() < 0.01,
            "{} {}",
            f[k],
            a[k]
        );
    }
}
