//! Ready-made parts for tests and examples, meshed with the built-in 20-node
//! hexahedra, each with suggested build settings (boundary nodes and interface
//! node sets selected geometrically).

use crate::builder::{BuildSettings, PointMass};
use crate::model::NodeSelection;
use crate::solid::{Block, Mesh};
use crate::Error;
use flexmb_element::Material;

/// A meshed part with suggested superelement settings.
#[derive(Clone, Debug)]
pub struct Part {
    /// The mesh.
    pub mesh: Mesh,
    /// Boundary nodes, interfaces (rigid) and rigid ties; no extra modes.
    pub settings: BuildSettings,
}

impl Part {
    /// The same part with its boundary nodes swapped: p becomes q and q
    /// becomes p, with their interfaces (and warping switches). The
    /// superelement built from it has the reversed element direction of thesis
    /// Fig. 2.11: its x axis points the other way (R0's first column is
    /// negated) and its node order in a scene is reversed. `y_axis` is kept,
    /// so R0's y axis is the same and its z axis flips.
    pub fn reversed(mut self) -> Self {
        let s = &mut self.settings;
        std::mem::swap(&mut s.p, &mut s.q);
        std::mem::swap(&mut s.interface_p, &mut s.interface_q);
        std::mem::swap(&mut s.warping_p, &mut s.warping_q);
        self
    }
}

fn plane_normal(point: [f64; 3], axis: usize, scale: f64) -> NodeSelection {
    let mut normal = [0.0; 3];
    normal[axis] = 1.0;
    NodeSelection::NearPlane {
        point,
        normal,
        tolerance: 1e-9 * scale,
    }
}

fn plane_x(x: f64, scale: f64) -> NodeSelection {
    plane_normal([x, 0.0, 0.0], 0, scale)
}

/// A prismatic bar from `p` to `q`, which must differ along one global axis
/// only, with a `by` × `bz` rectangular section centred on the line p–q:
/// `by` along the global axis `up` (0, 1 or 2 for x, y, z; it becomes the
/// element y axis) and `bz` along the remaining axis; `n` elements along the
/// bar, along `up` and along the third axis; interfaces at its end faces.
/// A part for a scene in which it lies along y or z, or runs along −x: a
/// superelement keeps the frame it was built in (docs/scene-format.md,
/// "Placement").
pub fn axis_bar(
    p: [f64; 3],
    q: [f64; 3],
    up: usize,
    by: f64,
    bz: f64,
    n: [usize; 3],
    mat: Material,
) -> Result<Part, Error> {
    let along: Vec<usize> = (0..3).filter(|&d| p[d] != q[d]).collect();
    let axis = match along[..] {
        [a] => a,
        _ => {
            return Err(Error::Spec(format!(
                "a bar from {p:?} to {q:?} must run along one global axis"
            )))
        }
    };
    if up > 2 || up == axis {
        return Err(Error::Spec(format!(
            "the section's axis {up} must be another global axis (0, 1 or 2) than the bar's ({axis})"
        )));
    }
    if n.contains(&0) || !(by > 0.0 && bz > 0.0) {
        return Err(Error::Spec(format!(
            "a bar needs positive section sides and element counts, got {by} × {bz} and {n:?}"
        )));
    }
    let third = 3 - axis - up;
    let len = (q[axis] - p[axis]).abs();
    let (mut min, mut max, mut h) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    min[axis] = p[axis].min(q[axis]);
    max[axis] = p[axis].max(q[axis]);
    h[axis] = len / n[0] as f64;
    for (d, b, k) in [(up, by, n[1]), (third, bz, n[2])] {
        min[d] = p[d] - 0.5 * b;
        max[d] = p[d] + 0.5 * b;
        h[d] = b / k as f64;
    }
    let mesh = Mesh::boxes(
        &[Block {
            min,
            max,
            material: 0,
        }],
        &[mat],
        h,
    )?;
    let s = len.max(by).max(bz);
    let mut settings = BuildSettings::new(p, q, plane_normal(p, axis, s), plane_normal(q, axis, s));
    let mut y = [0.0; 3];
    y[up] = 1.0;
    settings.y_axis = Some(y);
    Ok(Part { mesh, settings })
}

fn bar_like(
    x0: f64,
    len: f64,
    by: f64,
    bz: f64,
    n: [usize; 3],
    mat: Material,
) -> Result<Part, Error> {
    axis_bar([x0, 0.0, 0.0], [x0 + len, 0.0, 0.0], 1, by, bz, n, mat)
}

/// A prismatic bar along x from 0 to `l` with a `by` × `bz` rectangular section
/// centred on the x axis, `n` elements along x, y, z; interfaces at its end faces.
pub fn prismatic_bar(
    l: f64,
    by: f64,
    bz: f64,
    n: [usize; 3],
    mat: Material,
) -> Result<Part, Error> {
    bar_like(0.0, l, by, bz, n, mat)
}

/// A segment of the short wide sheet flexure of thesis Fig. 3.9 (l = h =
/// 0.04 m, t = 0.3 mm, steel): x from `x0` to `x0 + len`, height `h` along y,
/// thickness `t` along z; `n` elements along x, y, z; interfaces at its ends.
pub fn sheet_segment(
    x0: f64,
    len: f64,
    h: f64,
    t: f64,
    n: [usize; 3],
    mat: Material,
) -> Result<Part, Error> {
    bar_like(x0, len, h, t, n, mat)
}

/// A thin-walled box arm (rectangular tube) along x: outer width `w` (y),
/// outer height `hz` (z), wall thickness `wall`; `n_len` elements along x, about
/// `n_side` across each side, one element through the wall.
pub fn box_arm(
    l: f64,
    w: f64,
    hz: f64,
    wall: f64,
    n_len: usize,
    n_side: usize,
    mat: Material,
) -> Result<Part, Error> {
    if !(2.0 * wall < w.min(hz)) {
        return Err(Error::Spec(format!(
            "wall {wall} too thick for a {w} × {hz} box"
        )));
    }
    let (y0, y1, z0, z1) = (-0.5 * w, 0.5 * w, -0.5 * hz, 0.5 * hz);
    let blocks = [
        Block {
            min: [0.0, y0, z0],
            max: [l, y1, z0 + wall],
            material: 0,
        },
        Block {
            min: [0.0, y0, z1 - wall],
            max: [l, y1, z1],
            material: 0,
        },
        Block {
            min: [0.0, y0, z0 + wall],
            max: [l, y0 + wall, z1 - wall],
            material: 0,
        },
        Block {
            min: [0.0, y1 - wall, z0 + wall],
            max: [l, y1, z1 - wall],
            material: 0,
        },
    ];
    let hs = (w.max(hz) - 2.0 * wall) / n_side as f64;
    let mesh = Mesh::boxes(&blocks, &[mat], [l / n_len as f64, hs, hs])?;
    let s = l.max(w).max(hz);
    let settings = BuildSettings::new(
        [0.0, 0.0, 0.0],
        [l, 0.0, 0.0],
        plane_x(0.0, s),
        plane_x(l, s),
    );
    Ok(Part { mesh, settings })
}

/// Which half of the unbalanced shaft of thesis Fig. 2.13.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaftHalf {
    /// The rod along the x axis from x = −`rod_len` to 0 and the first half of
    /// the cylinder, x from 0 to l/2.
    First,
    /// The second half of the cylinder, x from l/2 to l, and the rod from l to
    /// l + `rod_len`: the first half turned by π about the y axis through the
    /// shaft's middle (so the cylinder stays at y = +r).
    Second,
}

/// Half of the unbalanced rotating shaft of thesis Table 2.2 (rod d1 = 2 mm,
/// eccentric cylinder d2 = 30 mm of length l = 75 mm with its axis offset by
/// r = 11 mm): a rod on the x axis and half of the cylinder, centred at
/// y = r (see [`ShaftHalf`]). The rod length is not given in the thesis
/// text; it is a parameter here. The rod's end face is tied to the cylinder's
/// face by a massless rigid link (the meshes do not conform there). p is the
/// rod's free end, q the shaft axis at mid-cylinder (x = l/2), interface q
/// the whole cylinder section there; [`Part::reversed`] gives the part joined
/// at p instead (thesis Fig. 2.16).
pub fn unbalanced_shaft_half(
    half: ShaftHalf,
    rod_len: f64,
    n_section: usize,
    n_rod: usize,
    n_cyl: usize,
    mat: Material,
) -> Result<Part, Error> {
    let (d1, d2, l, r) = (2.0e-3, 3.0e-2, 7.5e-2, 1.1e-2);
    // x of the rod's free end, of the rod–cylinder face and of the middle
    let (x_end, x_face, x_mid) = match half {
        ShaftHalf::First => (-rod_len, 0.0, 0.5 * l),
        ShaftHalf::Second => (l + rod_len, l, 0.5 * l),
    };
    let rod = Mesh::cylinder_x(x_end.min(x_face), [0.0, 0.0], rod_len, d1, 2, n_rod, mat)?;
    let cyl = Mesh::cylinder_x(
        x_face.min(x_mid),
        [r, 0.0],
        0.5 * l,
        d2,
        n_section,
        n_cyl,
        mat,
    )?;
    let mesh = rod.merge(&cyl, 1e-12);
    let s = rod_len + l;
    let h = d2 / n_section as f64;
    let tie = PointMass {
        name: "rod–cylinder tie".into(),
        mass: 0.0,
        position: [x_face, 0.0, 0.0],
        inertia: None,
        nodes: NodeSelection::Intersection(vec![
            plane_x(x_face, s),
            NodeSelection::NearSegment {
                a: [x_face, 0.0, 0.0],
                b: [x_face, 0.0, 0.0],
                radius: (0.5 * d1).max(0.75 * h) * 1.0001,
            },
        ]),
    };
    let mut settings = BuildSettings::new(
        [x_end, 0.0, 0.0],
        [x_mid, 0.0, 0.0],
        plane_x(x_end, s),
        plane_x(x_mid, s),
    );
    settings.point_masses.push(tie);
    Ok(Part { mesh, settings })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build;

    fn steel() -> Material {
        Material {
            e: 2.1e11,
            g: 8e10,
            rho: 7800.0,
        }
    }

    /// A bar along −y with its section's `by` side along z is the bar along
    /// x turned rigidly: the same S̄ and M̄ in the element frame, warping
    /// modes included (to rounding: the mesh is a rotated copy and Gauss
    /// integration does not see the turn), and R0 with x along −y, y along z.
    #[test]
    fn a_bar_along_minus_y_is_the_x_bar_turned() {
        let (l, by, bz, n) = (0.01, 0.04, 3e-4, [2, 4, 1]);
        let mut x = prismatic_bar(l, by, bz, n, steel()).unwrap();
        let p = [0.02, 0.02, -0.02];
        let q = [0.02, 0.02 - l, -0.02];
        let mut y = axis_bar(p, q, 2, by, bz, n, steel()).unwrap();
        for s in [&mut x.settings, &mut y.settings] {
            s.warping_p = true;
            s.warping_q = true;
        }
        let bx = build(&x.mesh.assemble("x").unwrap(), &x.settings).unwrap();
        let byy = build(&y.mesh.assemble("y").unwrap(), &y.settings).unwrap();
        let (a, b) = (&bx.data, &byy.data);
        assert!((a.l0 - b.l0).abs() < 1e-15);
        let scale = |m: &Vec<Vec<f64>>| m.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
        for (ma, mb) in [(&a.s_bar, &b.s_bar), (&a.m_bar, &b.m_bar)] {
            let s = scale(ma);
            for (ra, rb) in ma.iter().zip(mb) {
                for (u, v) in ra.iter().zip(rb) {
                    assert!((u - v).abs() <= 1e-9 * s, "{u} against {v} (scale {s})");
                }
            }
        }
        // columns of R0: element x, y, z in global axes
        let col = |r: &[[f64; 3]; 3], j: usize| [r[0][j], r[1][j], r[2][j]];
        for (j, e) in [[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]]
            .iter()
            .enumerate()
        {
            let c = col(&b.r0, j);
            assert!(
                (0..3).all(|d| (c[d] - e[d]).abs() < 1e-12),
                "R0 column {j}: {c:?}, expected {e:?}"
            );
        }
    }

    #[test]
    fn a_bar_off_the_axes_or_with_a_bad_section_axis_is_refused() {
        let e = axis_bar([0.0; 3], [0.1, 0.1, 0.0], 2, 0.01, 0.01, [1, 1, 1], steel());
        assert!(e.unwrap_err().to_string().contains("one global axis"));
        let e = axis_bar([0.0; 3], [0.0, 0.1, 0.0], 1, 0.01, 0.01, [1, 1, 1], steel());
        assert!(e.unwrap_err().to_string().contains("another global axis"));
        let e = axis_bar([0.0; 3], [0.0, 0.1, 0.0], 0, 0.01, 0.01, [0, 1, 1], steel());
        assert!(e.unwrap_err().to_string().contains("element counts"));
    }
}
