//! The geometry of an interface node set: the centroid of the surface it
//! covers (where p and q of a one-command build go), its best-fit plane and
//! how far the nodes lie off it, and the angle between that plane's normal
//! and the p → q axis, which the warping modes (3.4) assume to be zero
//! ([`check_warping_plane`]).

use crate::geometry::face_moments;
use crate::model::{dot, norm, sub, FeModel};
use crate::Error;
use flexmb_element::fe_faces::boundary_faces;
use flexmb_element::FeCell;
use nalgebra::{Matrix3, SymmetricEigen};

/// Above this angle (degrees) between an interface's plane normal and the
/// p → q axis a warping mode is refused: the mode (3.4) frees the interface
/// along the axis, not along its normal, and twists it about the axis, so
/// the error it makes grows with the angle.
pub const WARPING_ANGLE_LIMIT_DEG: f64 = 1.0;
/// Above this angle (degrees), and up to [`WARPING_ANGLE_LIMIT_DEG`], a
/// warping mode is built with a warning naming the angle.
pub const WARPING_ANGLE_WARN_DEG: f64 = 1e-3;
/// Nodes farther than this fraction of the interface's size from its
/// best-fit plane make it curved: no warping mode.
pub const PLANARITY_TOLERANCE: f64 = 1e-3;

/// Where an interface lies.
#[derive(Clone, Debug, PartialEq)]
pub struct InterfaceGeometry {
    /// Number of nodes.
    pub nodes: usize,
    /// The centroid (m) of the boundary faces all of whose nodes are in the
    /// set (area-weighted), or of the nodes when there are none.
    pub centroid: [f64; 3],
    /// The area of those faces (m²); `None` when the nodes cover no face.
    pub area: Option<f64>,
    /// Unit normal of the nodes' best-fit plane (least squares).
    pub normal: [f64; 3],
    /// The largest distance of a node from that plane (m).
    pub out_of_plane: f64,
    /// The largest distance of a node from the centroid (m).
    pub size: f64,
}

impl InterfaceGeometry {
    /// The angle (rad, 0 … π/2) between the plane's normal and `axis`.
    pub fn angle_to(&self, axis: [f64; 3]) -> f64 {
        let c = (dot(self.normal, axis) / norm(axis)).abs().min(1.0);
        c.acos()
    }
    /// Whether the nodes lie in their plane ([`PLANARITY_TOLERANCE`]).
    pub fn is_planar(&self) -> bool {
        self.out_of_plane <= PLANARITY_TOLERANCE * self.size
    }
}

/// The geometry of the interface made of `nodes` (indices into `model`).
pub fn interface_geometry(model: &FeModel, nodes: &[usize]) -> InterfaceGeometry {
    let c = model.coords();
    let n = nodes.len().max(1) as f64;
    let mean: [f64; 3] = std::array::from_fn(|d| nodes.iter().map(|&i| c[i][d]).sum::<f64>() / n);
    let (mut area, mut first) = (0.0, [0.0; 3]);
    if let Some(solid) = &model.solid {
        let mut inside = vec![false; model.n_nodes()];
        for &i in nodes {
            inside[i] = true;
        }
        let cells: Vec<FeCell> = solid
            .kinds
            .iter()
            .zip(&solid.nodes)
            .map(|(k, e)| FeCell {
                vtk_type: k.vtk_type(),
                nodes: k
                    .vtk_order()
                    .iter()
                    .filter_map(|&i| e.get(i).copied())
                    .collect(),
            })
            .collect();
        for face in boundary_faces(&cells) {
            if face.iter().all(|&i| inside[i]) {
                // about the mean, for accuracy far from the origin
                let x: Vec<[f64; 3]> = face.iter().map(|&i| sub(c[i], mean)).collect();
                if let Some((a, f)) = face_moments(&x) {
                    area += a;
                    for d in 0..3 {
                        first[d] += f[d];
                    }
                }
            }
        }
    }
    let (centroid, area) = if area > 0.0 {
        (
            std::array::from_fn(|d| mean[d] + first[d] / area),
            Some(area),
        )
    } else {
        (mean, None)
    };
    let mut cov = Matrix3::<f64>::zeros();
    for &i in nodes {
        let r = sub(c[i], mean);
        for a in 0..3 {
            for b in 0..3 {
                cov[(a, b)] += r[a] * r[b];
            }
        }
    }
    let eig = SymmetricEigen::new(cov);
    let k = eig.eigenvalues.imin();
    let v = eig.eigenvectors.column(k);
    let normal = [v[0], v[1], v[2]];
    let (mut out_of_plane, mut size) = (0.0f64, 0.0f64);
    for &i in nodes {
        out_of_plane = out_of_plane.max(dot(sub(c[i], mean), normal).abs());
        size = size.max(norm(sub(c[i], centroid)));
    }
    InterfaceGeometry {
        nodes: nodes.len(),
        centroid,
        area,
        normal,
        out_of_plane,
        size,
    }
}

/// Checks that interface `side` ("p" or "q") can have a warping mode about
/// the p → q `axis`: planar and normal to the axis within
/// [`WARPING_ANGLE_LIMIT_DEG`]. Above it, or curved, an error naming the
/// angle (or the distance off the plane); between
/// [`WARPING_ANGLE_WARN_DEG`] and the limit, `Ok` with a warning.
pub fn check_warping_plane(
    side: &str,
    g: &InterfaceGeometry,
    axis: [f64; 3],
) -> Result<Option<String>, Error> {
    if !g.is_planar() {
        return Err(Error::interface(
            side,
            format!(
                "its nodes are not in one plane (up to {:.3e} m from their best-fit plane, {:.2} % of its size \
                 {:.3e} m): a warping mode (3.4) needs a planar interface normal to the p → q axis; drop warping_{side} \
                 (--warping)",
                g.out_of_plane,
                100.0 * g.out_of_plane / g.size,
                g.size
            ),
        ));
    }
    let deg = g.angle_to(axis).to_degrees();
    let a = norm(axis);
    let axis_text = format!(
        "[{:.4}, {:.4}, {:.4}]",
        axis[0] / a,
        axis[1] / a,
        axis[2] / a
    );
    let normal_text = format!(
        "[{:.4}, {:.4}, {:.4}]",
        g.normal[0], g.normal[1], g.normal[2]
    );
    if deg > WARPING_ANGLE_LIMIT_DEG {
        return Err(Error::interface(
            side,
            format!(
                "its plane (normal {normal_text}) is at {deg:.3}° from normal to the p → q axis {axis_text}; warping \
                 modes assume interfaces normal to it (within {WARPING_ANGLE_LIMIT_DEG}°): drop warping_{side} \
                 (--warping), or choose p and q so that p → q is normal to the interface"
            ),
        ));
    }
    Ok((deg > WARPING_ANGLE_WARN_DEG).then(|| {
        format!(
            "interface {side}: its plane (normal {normal_text}) is at {deg:.4}° from normal to the p → q axis \
             {axis_text}; its warping mode frees it along the axis, not its normal (an error of the order of the \
             angle; refused above {WARPING_ANGLE_LIMIT_DEG}°)"
        )
    }))
}
