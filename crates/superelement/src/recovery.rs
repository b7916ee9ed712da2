//! The FE node positions of a superelement at a configuration of its two
//! nodes and mode amplitudes, from the [`FeMesh`] the builder wrote (issue 21).
//!
//! The builder's coordinates (thesis §3.2): the FE displacement is V µ̄ + W η̄
//! over the boundary coordinates µ̄ = (ū^p, φ̄^p, ū^q, φ̄^q) in the element frame.
//! In a frame with its origin at node p, its x axis along the chord p→q and
//! its twist following node p, the boundary coordinates that are not in µ̄e
//! (ū^p, φ̄^p_x, ū^q_y, ū^q_z) vanish, so the deformation in that frame is
//! Φ ζ, ζ = (µ̄e, η̄) = (A ε, η̄) with ε the element's deformations (6.2b),
//! A = diag(1, 1/l0, −1/l0, 1/l0, −1/l0, 1/l0) (thesis (3.20)) and Φ the
//! recovery of [`FeMesh`]. A node at X (reference element frame) is at
//!
//! x = r_p + R (X + Φ ζ),  R = [e_x e_y e_z],
//!
//! e_x = (r_q − r_p)/|r_q − r_p|, e_y the y axis R(λp) R0 e_y of node p made
//! normal to e_x, e_z = e_x × e_y. A rigid motion of both nodes has ε = 0 and
//! moves the mesh rigidly; to first order R is node p's frame turned onto the
//! chord, the frame the constraint modes are defined in.

use crate::Error;
use flexmb_element::{spatial_a_diag, Element, FeMesh, LinearSuperelement, VelocityTransform};
use flexmb_rotation::generic::rotation;

/// The superelement's FE mesh and what places it.
pub struct MeshRecovery<'a> {
    data: &'a LinearSuperelement,
    mesh: &'a FeMesh,
    element: Element,
    eps: Vec<f64>,
    zeta: Vec<f64>,
}

impl<'a> MeshRecovery<'a> {
    /// The recovery of `data`; an error when the file has no `fe_mesh`.
    pub fn new(data: &'a LinearSuperelement) -> Result<Self, Error> {
        let mesh = data.fe_mesh.as_ref().ok_or_else(|| {
            Error::Spec(
                "the superelement data have no fe_mesh section (built with fe_mesh: false, or \
                 written before issue 21): rebuild it to draw its FE mesh"
                    .into(),
            )
        })?;
        let element = Element::superelement(data, VelocityTransform::B3)?;
        let n = 6 + data.n_modes();
        Ok(Self {
            data,
            mesh,
            element,
            eps: vec![0.0; n],
            zeta: vec![0.0; n],
        })
    }

    /// The mesh.
    pub fn mesh(&self) -> &FeMesh {
        self.mesh
    }

    /// The element coordinates (r_p, λp, r_q, λq, η̄) this recovery takes: 14 + k.
    pub fn n_coords(&self) -> usize {
        14 + self.data.n_modes()
    }

    /// The FE node positions (global) at the element coordinates
    /// `x` = (r_p, λp, r_q, λq, η̄) (λ the Euler parameters of the node
    /// frames, the triads R(λ) R0), into `out` (one entry per mesh node).
    pub fn positions(&mut self, x: &[f64], out: &mut [[f64; 3]]) -> Result<(), Error> {
        let n_x = self.n_coords();
        if x.len() != n_x || out.len() != self.mesh.nodes.len() {
            return Err(Error::SizeMismatch(format!(
                "mesh recovery: {} element coordinates and {} output nodes given, expected {n_x} and {}",
                x.len(),
                out.len(),
                self.mesh.nodes.len()
            )));
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::Spec(
                "mesh recovery: a non-finite element coordinate".into(),
            ));
        }
        self.element.deformations(x, None, &mut self.eps);
        let a = spatial_a_diag(self.data.l0);
        for (i, (z, e)) in self.zeta.iter_mut().zip(&self.eps).enumerate() {
            *z = if i < 6 { a[i] * e } else { *e };
        }
        let frame = chord_frame(x, &self.data.r0)?;
        let rp = [x[0], x[1], x[2]];
        for ((o, xi), phi) in out
            .iter_mut()
            .zip(&self.mesh.nodes)
            .zip(&self.mesh.recovery)
        {
            let mut loc = *xi;
            for (c, z) in self.zeta.iter().enumerate() {
                for d in 0..3 {
                    loc[d] += phi[3 * c + d] * z;
                }
            }
            *o = std::array::from_fn(|r| rp[r] + (0..3).map(|j| frame[j][r] * loc[j]).sum::<f64>());
        }
        Ok(())
    }
}

/// The axes (e_x, e_y, e_z) of the co-rotated frame: chord, node p's y axis
/// made normal to it, their cross product.
fn chord_frame(x: &[f64], r0: &[[f64; 3]; 3]) -> Result<[[f64; 3]; 3], Error> {
    let d: [f64; 3] = std::array::from_fn(|i| x[7 + i] - x[i]);
    let l = norm3(d);
    let lam = [x[3], x[4], x[5], x[6]];
    let ln = lam.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(l > 0.0 && ln > 0.0) {
        return Err(Error::Spec(
            "mesh recovery: nodes p and q coincide, or λp is zero".into(),
        ));
    }
    let ex = d.map(|v| v / l);
    let rp = rotation(&lam.map(|v| v / ln)).0;
    let py: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| rp[i][j] * r0[j][1]).sum());
    let along: f64 = (0..3).map(|i| py[i] * ex[i]).sum();
    let ny: [f64; 3] = std::array::from_fn(|i| py[i] - along * ex[i]);
    let n = norm3(ny);
    if !(n > 1e-12) {
        return Err(Error::Spec(
            "mesh recovery: node p's y axis is along the chord (a bending angle of 90°)".into(),
        ));
    }
    let ey = ny.map(|v| v / n);
    let ez = [
        ex[1] * ey[2] - ex[2] * ey[1],
        ex[2] * ey[0] - ex[0] * ey[2],
        ex[0] * ey[1] - ex[1] * ey[0],
    ];
    Ok([ex, ey, ez])
}

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}
