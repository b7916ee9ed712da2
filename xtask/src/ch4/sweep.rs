//! Eigenfrequencies of the chapter-4 mechanism along the path (4.1) (thesis
//! §4.4, Figs 4.13–4.17): the end-effector's x and y made degrees of
//! freedom and held on the path, every other DOF at its equilibrium
//! (no gravity, as chapter 4), then the rest linearization (E.6) with all
//! DOFs free, (K_q + G_q − ω²M_q)v = 0 (4.2); modes labelled by where their
//! kinetic energy is and tracked by MAC along the path.

use super::path::Path4;
use super::scene::END_EFFECTOR_NODE;
use flexmb_dynamics::Dynamics;
use flexmb_linearize::{sweep_until, SweepOptions, SweepParameter, SweepPoint};
use flexmb_model::{Component, Mechanism, Scene, Select};
use flexmb_rotation::EulerParameters;
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// The frequency up to which modes are kept (Hz), §4.4.
pub const F_MAX: f64 = 200.0;

/// The mechanism of `scene` (the fixture, or one written by
/// `cargo xtask mechanism4`) with the end-effector's x and y as its first
/// two degrees of freedom (the path coordinates), and their DOF indices.
pub fn mechanism(scene: &Path) -> Result<(Arc<Mechanism>, [usize; 2]), String> {
    let s = Scene::load(scene).map_err(|e| format!("{}: {e}", scene.display()))?;
    mechanism_of(s, scene)
}

/// [`mechanism`] of a scene already read (and perhaps changed) from the file
/// `scene` (whose directory holds the part files).
pub fn mechanism_of(mut s: Scene, scene: &Path) -> Result<(Arc<Mechanism>, [usize; 2]), String> {
    for (k, c) in [Component::X, Component::Y].into_iter().enumerate() {
        s.dofs_first
            .insert(k, Select::Coord(END_EFFECTOR_NODE.into(), c));
    }
    let mech = s
        .build(scene.parent())
        .map_err(|e| format!("{}: {e}", scene.display()))?;
    let find = |c: &str| {
        let name = format!("{END_EFFECTOR_NODE}.{c}");
        let i = mech.x_names.iter().position(|n| *n == name);
        i.and_then(|i| {
            mech.dofs
                .iter()
                .position(|d| *d == flexmb_model::Coordinate::Node(i))
        })
        .ok_or_else(|| format!("{name} is not a degree of freedom"))
    };
    let dofs = [find("x")?, find("y")?];
    Ok((Arc::new(mech), dofs))
}

/// `n` values of the arc length, equally spaced over the whole path.
pub fn path_values(n: usize) -> Vec<f64> {
    let l = Path4::new().length();
    (0..n).map(|i| l * i as f64 / (n - 1) as f64).collect()
}

/// The sweep parameter: the end-effector's (x, y) at P(s) from its
/// reference position.
pub fn path_parameter(mech: &Mechanism, dofs: [usize; 2]) -> SweepParameter {
    let q0 = mech.q0();
    let (x0, y0) = (q0[dofs[0]], q0[dofs[1]]);
    let path = Path4::new();
    SweepParameter::Path {
        dofs: dofs.to_vec(),
        path: Box::new(move |s| {
            let (p, _, _) = path.at(s);
            vec![x0 + p[0], y0 + p[1]]
        }),
    }
}

/// The sweep along the path at `values`, `modes` modes per point (their
/// shapes and the mass kept for MAC), with `progress(done, total)`.
pub fn run(
    mech: &Arc<Mechanism>,
    dofs: [usize; 2],
    values: &[f64],
    modes: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<SweepPoint>, String> {
    let opts = SweepOptions {
        values: values.to_vec(),
        modes,
        t: 0.0,
        keep_vectors: true,
    };
    let o = sweep_until(mech, &path_parameter(mech, dofs), &opts, progress, None)
        .map_err(|e| e.to_string())?;
    Ok(o.points)
}

/// Where a mode's kinetic energy is: its share in each body group (the
/// member superelements by name, the hinges by kind), and the share of the
/// out-of-plane motion (z translations and rotations about in-plane axes).
#[derive(Clone, Debug)]
pub struct ModeFeatures {
    /// (group, share), largest first.
    pub groups: Vec<(String, f64)>,
    /// Out-of-plane share of the kinetic energy.
    pub out_of_plane: f64,
    /// Frequency (Hz).
    pub frequency: f64,
}

impl ModeFeatures {
    /// A label in the thesis's terms: "actuator", "CrossBar twist" (the
    /// internal mode of §4.1.3), "out of plane", "in plane", with the body
    /// group that has most of its kinetic energy.
    pub fn label(&self) -> String {
        let (top, share) = self.groups.first().cloned().unwrap_or_default();
        let kind = if top == "CrossBar" && share > 0.5 {
            return "CrossBar twist".into();
        } else if self.out_of_plane > 0.6 {
            "out of plane"
        } else if self.frequency < 20.0 {
            "actuator"
        } else {
            "in plane"
        };
        format!("{kind} ({top})")
    }
}

/// The body group of an element: a member superelement's name, or the kind
/// of hinge a hinge element belongs to.
fn group_of(id: &str) -> String {
    let kind = |p: &str| match p {
        "hb" => Some("base hinges"),
        "he" => Some("elbow hinges"),
        "hf" => Some("end-effector hinges"),
        "hc" => Some("CrossBar hinges"),
        _ => None,
    };
    let head = id.split(['.', '_']).next().unwrap_or(id);
    match kind(head) {
        Some(k) => k.into(),
        None if id.starts_with("crossbar_link") => "UpperArmX1/X2".into(),
        None if id.starts_with("ee_link") => "EndEffector".into(),
        None => id.split('.').next().unwrap_or(id).into(),
    }
}

/// The features of the modes of a sweep point.
pub fn features(mech: &Arc<Mechanism>, p: &SweepPoint) -> Result<Vec<ModeFeatures>, String> {
    let vectors = p.modes.as_ref().ok_or("the sweep kept no mode shapes")?;
    let frequencies = &p.frequencies_hz;
    let mut dy = Dynamics::new(mech.clone());
    dy.kinematics_mut().set_guess(&p.x);
    dy.kinematics_mut()
        .solve(&p.q, 0.0)
        .map_err(|e| e.to_string())?;
    let x = dy.kinematics().x().to_vec();
    let shapes = flexmb_linearize::nodal_mode_shapes(&mut dy, vectors);
    let mut out = vec![];
    for (k, f) in frequencies.iter().enumerate().take(vectors.ncols()) {
        let u: Vec<f64> = (0..shapes.nrows()).map(|i| shapes[(i, k)]).collect();
        let (u_in, u_out) = split_in_out_of_plane(mech, &x, &u);
        let mut by_group: std::collections::BTreeMap<String, f64> = Default::default();
        let (mut t_in, mut t_out) = (0.0, 0.0);
        let (mut xl, mut ul) = (vec![], vec![]);
        for e in &mech.elements {
            if !e.element.has_inertia() {
                continue;
            }
            let n = e.x_index.len();
            xl.resize(n, 0.0);
            ul.resize(n, 0.0);
            e.gather(&x, &mut xl);
            e.gather(&u, &mut ul);
            let t = e.element.kinetic_energy(&xl, &ul);
            *by_group.entry(group_of(&e.id)).or_default() += t;
            e.gather(&u_in, &mut ul);
            t_in += e.element.kinetic_energy(&xl, &ul);
            e.gather(&u_out, &mut ul);
            t_out += e.element.kinetic_energy(&xl, &ul);
        }
        let total: f64 = by_group.values().sum();
        let mut groups: Vec<(String, f64)> =
            by_group.into_iter().map(|(g, t)| (g, t / total)).collect();
        groups.sort_by(|a, b| b.1.total_cmp(&a.1));
        out.push(ModeFeatures {
            groups,
            out_of_plane: t_out / (t_in + t_out),
            frequency: *f,
        });
    }
    Ok(out)
}

/// A nodal displacement `u` at `x` split into its in-plane part (x, y
/// translations, rotations about z) and its out-of-plane part (z
/// translations, rotations about in-plane axes); other coordinates (mode
/// amplitudes) go to neither.
fn split_in_out_of_plane(mech: &Mechanism, x: &[f64], u: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut u_in = vec![0.0; u.len()];
    let mut u_out = vec![0.0; u.len()];
    for n in &mech.nodes {
        if let [a, b, c] = n.position[..] {
            u_in[a] = u[a];
            u_in[b] = u[b];
            u_out[c] = u[c];
        }
        if let Some(o) = &n.orientation {
            if o.len() != 4 {
                continue;
            }
            let l = EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]);
            let w = l.omega(&[u[o[0]], u[o[1]], u[o[2]], u[o[3]]]);
            let w_in = nalgebra::Vector3::new(0.0, 0.0, w[2]);
            let w_out = nalgebra::Vector3::new(w[0], w[1], 0.0);
            let (li, lo) = (
                l.lambda_dot_from_omega(&w_in),
                l.lambda_dot_from_omega(&w_out),
            );
            for k in 0..4 {
                u_in[o[k]] = li[k];
                u_out[o[k]] = lo[k];
            }
        }
    }
    (u_in, u_out)
}

/// The eigenfrequencies at each point's equilibrium without the geometric
/// stiffness G_q ((K_q + N_q − ω²M_q)v = 0): its effect, which the thesis
/// finds small on ω1, ω2 and negligible above (§4.4). In parallel.
pub fn without_gq(
    mech: &Arc<Mechanism>,
    points: &[SweepPoint],
    modes: usize,
) -> Result<Vec<Vec<f64>>, String> {
    points
        .par_iter()
        .map(|p| {
            let mut dy = Dynamics::new(mech.clone());
            // from the equilibrium's own configuration: from the reference
            // one the position solve can land on another branch
            dy.kinematics_mut().set_guess(&p.x);
            let lin = dy.linearize_at_rest(0.0, &p.q).map_err(|e| e.to_string())?;
            let mut k = lin.k.clone();
            k += &lin.n;
            let m = flexmb_linearize::generalized_symmetric(&k, &lin.m, modes)
                .map_err(|e| e.to_string())?;
            Ok(m.frequencies_hz())
        })
        .collect()
}
