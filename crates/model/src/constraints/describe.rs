//! Naming an over-constraint: its equations, its loop of elements, the
//! deformation kind that carries it and the direction of its self-stress.
//!
//! The direction comes from the generalized forces the self-stress y puts on
//! the nodes, element by element: g_e = Σ_{rows r of e} y_r C_r (the
//! element's share of yᵀC = 0). Their position parts are forces f; the
//! Euler-parameter parts are moments m = ½ Λ(λ) g_λ (from ω = 2Λλ̇, thesis
//! (2.14): the power gᵀλ̇ = mᵀω). When the loop's nodes lie in a plane with
//! normal n, the share of Σ (f·n)² + Σ |m × n|² in Σ |f|² + Σ |m|² says how
//! much of the self-stress is out of the plane (forces normal to it, moments
//! about in-plane axes) — the over-constraints a planar mechanism built
//! spatially has (thesis §4.1.3: three per loop).

use super::{Equation, OverConstraint, Weighted};
use crate::roles::R;
use crate::scene::Dimension;
use crate::Mechanism;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use std::collections::BTreeMap;

/// The direction of an over-constraint's self-stress.
#[derive(Clone, Debug, PartialEq)]
pub enum Direction {
    /// A planar scene: every self-stress is in the plane.
    Planar,
    /// The loop's nodes lie in a plane.
    Plane {
        /// Its unit normal.
        normal: [f64; 3],
        /// Share (0…1) of Σ|f|² + Σ|m|² out of the plane: forces along the
        /// normal, moments about in-plane axes.
        out_of_plane: f64,
        /// Share of forces that is along the normal (NaN without forces).
        force_out: f64,
        /// Share of moments that is about in-plane axes (NaN without moments).
        moment_out: f64,
    },
    /// The loop's nodes do not lie in one plane (or lie on a line): the
    /// principal direction of its forces and axis of its moments, where
    /// there are any.
    Spatial {
        /// The unit direction carrying most of Σ f fᵀ.
        force: Option<[f64; 3]>,
        /// The unit axis carrying most of Σ m mᵀ.
        moment: Option<[f64; 3]>,
    },
}

fn fmt_vec(v: &[f64; 3]) -> String {
    let c: Vec<String> = v
        .iter()
        .map(|x| format!("{:.3}", if x.abs() < 5e-4 { 0.0 } else { *x }))
        .collect();
    format!("[{}]", c.join(", "))
}

fn percent(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{:.0} %", 100.0 * x)
    }
}

impl std::fmt::Display for Direction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Direction::Planar => write!(f, "in plane (planar scene)"),
            Direction::Plane {
                normal,
                out_of_plane,
                force_out,
                moment_out,
            } => {
                let verdict = if *out_of_plane >= 0.99 {
                    "out of plane".to_string()
                } else if *out_of_plane <= 0.01 {
                    "in plane".to_string()
                } else {
                    format!("{} out of plane", percent(*out_of_plane))
                };
                write!(
                    f,
                    "{verdict} (loop plane normal {}; out of plane: forces {}, moments {})",
                    fmt_vec(normal),
                    percent(*force_out),
                    percent(*moment_out)
                )
            }
            Direction::Spatial { force, moment } => {
                let mut parts = vec![];
                if let Some(d) = force {
                    parts.push(format!("force along {}", fmt_vec(d)));
                }
                if let Some(a) = moment {
                    parts.push(format!("moment about {}", fmt_vec(a)));
                }
                write!(f, "spatial loop: {}", parts.join(", "))
            }
        }
    }
}

/// Index of the element owning each deformation.
pub(super) fn owners(mech: &Mechanism) -> Vec<usize> {
    let mut o = vec![usize::MAX; mech.n_eps()];
    for (k, e) in mech.elements.iter().enumerate() {
        for j in e.eps_offset..e.eps_offset + e.element.n_eps() {
            o[j] = k;
        }
    }
    o
}

fn is_normalization(mech: &Mechanism, k: usize) -> bool {
    mech.elements[k].element.is_normalization()
}

/// The name and kind label of an equation.
fn name_and_kind(mech: &Mechanism, owner: &[usize], e: Equation) -> (String, String) {
    match e {
        Equation::Def(j) => {
            let el = &mech.elements[owner[j]];
            let name = mech.eps_names[j].clone();
            if el.element.is_normalization() {
                return (name, "Euler-parameter normalization".into());
            }
            let local = name
                .strip_prefix(&format!("{}.", el.id))
                .unwrap_or(&name)
                .to_string();
            let base = local
                .strip_suffix("_p")
                .or_else(|| local.strip_suffix("_q"))
                .unwrap_or(&local);
            (name, format!("{} {base}", el.element.type_name()))
        }
        Equation::Coord(i, R::Input) => (
            format!("{} (prescribed)", mech.x_names[i]),
            "prescribed coordinate".into(),
        ),
        Equation::Coord(i, _) => (
            format!("{} (fixed)", mech.x_names[i]),
            "support (fixed coordinate)".into(),
        ),
    }
}

/// Names and describes the over-constraint `v` (equation index, weight).
pub(super) fn over_constraint(
    mech: &Mechanism,
    eqs: &[Equation],
    rows: &[Vec<(usize, f64)>],
    v: &[(usize, f64)],
) -> OverConstraint {
    let owner = owners(mech);
    let mut kinds: BTreeMap<String, f64> = BTreeMap::new();
    let mut equations = vec![];
    for (r, w) in v {
        let (name, kind) = name_and_kind(mech, &owner, eqs[*r]);
        *kinds.entry(kind).or_default() += w * w;
        equations.push(Weighted { name, weight: *w });
    }
    let total: f64 = kinds.values().sum();
    let dominant = kinds
        .into_iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, s)| (k, s / total.max(f64::MIN_POSITIVE)))
        .unwrap_or_default();
    // generalized forces per owner (element index, usize::MAX: the supports)
    let mut forces: BTreeMap<usize, BTreeMap<usize, f64>> = BTreeMap::new();
    for (r, w) in v {
        let key = match eqs[*r] {
            Equation::Def(j) => owner[j],
            Equation::Coord(..) => usize::MAX,
        };
        let g = forces.entry(key).or_default();
        for (c, x) in &rows[*r] {
            *g.entry(*c).or_default() += w * x;
        }
    }
    let fixed: Vec<usize> = eqs
        .iter()
        .filter_map(|e| match e {
            Equation::Coord(i, _) => Some(*i),
            Equation::Def(_) => None,
        })
        .collect();
    let involved: Vec<usize> = forces
        .keys()
        .copied()
        .filter(|k| *k != usize::MAX && !is_normalization(mech, *k))
        .collect();
    OverConstraint {
        equations,
        loop_elements: walk(mech, &involved, forces.contains_key(&usize::MAX), &fixed),
        dominant,
        direction: direction(mech, &forces, &involved),
    }
}

/// The loop in walking order: from the ground (if the loop runs through the
/// supports) or its first element, each step to the unvisited element that
/// shares the most coordinates with the last one visited (else with the
/// latest one that has a neighbour left); ties in scene order.
fn walk(mech: &Mechanism, involved: &[usize], ground: bool, fixed: &[usize]) -> Vec<String> {
    let coords = |k: usize| -> &[usize] { &mech.elements[k].x_index };
    // None stands for the ground
    let shared = |a: Option<usize>, b: usize| -> usize {
        match a {
            None => coords(b).iter().filter(|c| fixed.contains(c)).count(),
            Some(a) => coords(a).iter().filter(|c| coords(b).contains(c)).count(),
        }
    };
    let mut order: Vec<Option<usize>> = vec![];
    let mut left: Vec<usize> = involved.to_vec();
    if ground {
        order.push(None);
    } else if !left.is_empty() {
        order.push(Some(left.remove(0)));
    }
    while !left.is_empty() {
        let next = order
            .iter()
            .rev()
            .find_map(|v| {
                let (mut best, mut at) = (0, None);
                for (k, b) in left.iter().enumerate() {
                    let s = shared(*v, *b);
                    if s > best {
                        (best, at) = (s, Some(k));
                    }
                }
                at
            })
            .unwrap_or(0);
        order.push(Some(left.remove(next)));
    }
    let mut names: Vec<String> = order
        .into_iter()
        .map(|v| v.map_or("ground".to_string(), |k| mech.elements[k].group.clone()))
        .collect();
    names.dedup();
    names
}

/// Forces and moments per owner and node (see the module documentation).
fn nodal_loads(
    mech: &Mechanism,
    forces: &BTreeMap<usize, BTreeMap<usize, f64>>,
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let (mut fs, mut ms) = (vec![], vec![]);
    for g in forces.values() {
        let val = |i: &usize| g.get(i).copied().unwrap_or(0.0);
        let mut seen_positions = vec![];
        for n in &mech.nodes {
            if !seen_positions.contains(&n.position[0]) {
                seen_positions.push(n.position[0]);
                let mut f = Vector3::zeros();
                for (k, i) in n.position.iter().enumerate() {
                    f[k] = val(i);
                }
                if f.norm() > 0.0 {
                    fs.push(f);
                }
            }
            let Some(o) = &n.orientation else { continue };
            let m = if o.len() == 4 {
                let l = [mech.x0[o[0]], mech.x0[o[1]], mech.x0[o[2]], mech.x0[o[3]]];
                let lam = flexmb_rotation::generic::lambda_mat(&l);
                Vector3::from_fn(|k, _| 0.5 * (0..4).map(|q| lam[k][q] * val(&o[q])).sum::<f64>())
            } else {
                Vector3::new(0.0, 0.0, val(&o[0]))
            };
            if m.norm() > 0.0 {
                ms.push(m);
            }
        }
    }
    (fs, ms)
}

/// The unit eigenvector of the largest eigenvalue of Σ v vᵀ.
fn principal(vs: &[Vector3<f64>]) -> Option<[f64; 3]> {
    if vs.is_empty() {
        return None;
    }
    let s: Matrix3<f64> = vs.iter().map(|v| v * v.transpose()).sum();
    let e = SymmetricEigen::new(s);
    let k = e.eigenvalues.imax();
    let mut d = e.eigenvectors.column(k).into_owned();
    // a sign convention: the largest component positive
    if d[d.iamax()] < 0.0 {
        d = -d;
    }
    Some([d[0], d[1], d[2]])
}

fn direction(
    mech: &Mechanism,
    forces: &BTreeMap<usize, BTreeMap<usize, f64>>,
    involved: &[usize],
) -> Direction {
    if mech.dimension == Dimension::Planar {
        return Direction::Planar;
    }
    let (fs, ms) = nodal_loads(mech, forces);
    // the loop's nodes: those whose position an involved element uses
    let mut points: Vec<Vector3<f64>> = vec![];
    for n in &mech.nodes {
        if involved.iter().any(|k| {
            let xi = &mech.elements[*k].x_index;
            n.position.iter().any(|i| xi.contains(i))
                || n.orientation.iter().flatten().any(|i| xi.contains(i))
        }) {
            let p = Vector3::new(n.at[0], n.at[1], n.at[2]);
            if !points.iter().any(|q| (q - p).norm() == 0.0) {
                points.push(p);
            }
        }
    }
    let spatial = || Direction::Spatial {
        force: principal(&fs),
        moment: principal(&ms),
    };
    if points.len() < 3 {
        return spatial();
    }
    let c: Vector3<f64> = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let cov: Matrix3<f64> = points.iter().map(|p| (p - c) * (p - c).transpose()).sum();
    let e = SymmetricEigen::new(cov);
    let mut ev: Vec<(f64, usize)> = (0..3).map(|k| (e.eigenvalues[k], k)).collect();
    ev.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (small, mid, big) = (ev[0].0.max(0.0), ev[1].0.max(0.0), ev[2].0);
    // extents: planar when the thinnest is 1e-6 of the largest, not a line
    if !(small.sqrt() <= 1e-6 * big.sqrt() && mid.sqrt() > 1e-6 * big.sqrt()) {
        return spatial();
    }
    let n = e.eigenvectors.column(ev[0].1).into_owned();
    let n = if n[n.iamax()] < 0.0 { -n } else { n };
    let ff: f64 = fs.iter().map(|f| f.norm_squared()).sum();
    let fo: f64 = fs.iter().map(|f| f.dot(&n).powi(2)).sum();
    let mm: f64 = ms.iter().map(|m| m.norm_squared()).sum();
    let mo: f64 = ms.iter().map(|m| m.cross(&n).norm_squared()).sum();
    let share = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
    Direction::Plane {
        normal: [n[0], n[1], n[2]],
        out_of_plane: share(fo + mo, ff + mm),
        force_out: share(fo, ff),
        moment_out: share(mo, mm),
    }
}

impl std::fmt::Display for super::ConstraintDiagnosis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "constraints: {} equations (rigid and prescribed deformations, Euler-parameter normalizations, fixed and prescribed coordinates) on {} nodal coordinates; mobility {}",
            self.n_equations, self.n_coordinates, self.mobility
        )?;
        writeln!(
            f,
            "  {} equations in closed loops; largest block decomposed by a dense SVD: {} equations",
            self.core_equations, self.largest_block
        )?;
        if self.largest_block > super::null::BALL_MAX_ROWS {
            writeln!(
                f,
                "  note: the largest block ({} equations) is above {}: its basis is localized by reduced row echelon form and pairwise reduction only, not by balls, and its dense SVD takes time cubic in its size",
                self.largest_block,
                super::null::BALL_MAX_ROWS
            )?;
        }
        if self.is_exact() {
            write!(f, "no over- or under-constraints")?;
            if !self.under_checked {
                write!(
                    f,
                    " (the degrees of freedom are chosen automatically: the {} motions the equations leave free)",
                    self.mobility
                )?;
            }
            return Ok(());
        }
        writeln!(
            f,
            "{} over-constraint(s), {} under-constraint(s)",
            self.over.len(),
            self.under.len()
        )?;
        const SHOWN: usize = 8;
        let list = |f: &mut std::fmt::Formatter<'_>, ws: &[Weighted]| -> std::fmt::Result {
            for w in ws.iter().take(SHOWN) {
                writeln!(f, "    {:+.3}  {}", w.weight, w.name)?;
            }
            if ws.len() > SHOWN {
                writeln!(f, "    … and {} more", ws.len() - SHOWN)?;
            }
            Ok(())
        };
        for (k, o) in self.over.iter().enumerate() {
            writeln!(
                f,
                "over-constraint {}: loop {}",
                k + 1,
                o.loop_elements.join(" – ")
            )?;
            writeln!(f, "  direction: {}", o.direction)?;
            writeln!(
                f,
                "  mostly {} ({} of Σ weight²); {} equations:",
                o.dominant.0,
                percent(o.dominant.1),
                o.equations.len()
            )?;
            list(f, &o.equations)?;
        }
        for (k, u) in self.under.iter().enumerate() {
            writeln!(
                f,
                "under-constraint {}: a motion of {} coordinates that nothing determines:",
                k + 1,
                u.coordinates.len()
            )?;
            list(f, &u.coordinates)?;
        }
        Ok(())
    }
}
