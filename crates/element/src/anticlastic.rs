//! The anticlastic curl of a sheet beam: the Poisson share of a wide strip's
//! weak-axis bending stiffness (issue 22; Searle, Ashwell 1950).
//!
//! A strip of height b and thickness t bent to curvature κ curls across its
//! height to the transverse curvature −νκ when it is free to (the beam, EI),
//! and resists as a plate (D b = EI/(1 − ν²)) when it cannot: near a clamp or
//! a rigid body, whose edge stays straight, and at large κ, where the curl's
//! transverse deflection w meets the membrane strain κw (the transition is
//! governed by Searle's parameter β = b²κ/t).
//!
//! This element is an overlay on a spatial beam with a `Rectangle` section:
//! it shares the beam's nodes and adds the curl w(s, z) = (b²/4)(a₁ g₁(ζ) +
//! a₂ g₂(ζ)), ζ = 2z/b, with g₁″ = 1 and g₂″ = P₂(ζ) (so w_zz = a₁ + a₂ P₂,
//! the first two Legendre polynomials) and ∫g = 0. Its two amplitudes a₁, a₂
//! (1/m; as coordinates η = (b²/4) a) at each node (one two-mode slot per node, shared with the
//! neighbouring element) are linear along the element. Its energy is the
//! plate's bending energy beyond the beam's EI κ²/2, with the beam's
//! curvature κ(s) of the Hermite bending (end rotations θ_p = −ε_bp/l0,
//! θ_q = ε_bq/l0 of the weak plane):
//! * Poisson coupling: (D b/2)(νκ + a₁)² + (D b/10) a₂² (the plate's
//!   D/2 ∫(κ² + 2νκ w_zz + w_zz²) dz minus EI κ²/2, a square since
//!   EI = D b (1 − ν²));
//! * twist of the curl along the sheet: D(1 − ν) ∫ w_sz² dz =
//!   D (1 − ν)(b³/8) a′ᵀ G′ a′;
//! * membrane: (E t/2) ∫ ε² dz with the strain of the fibre at height z,
//!   ε = −κw + ½τ²(z² − b²/12): the curl on the curved sheet (a fibre moved
//!   by w towards the centre of curvature shortens) and the trapeze term of
//!   the twist rate τ = Θ/l0 (Θ the beam's torsion angle). The mean strain is
//!   the beam's elongation, and z² − b²/12 = (b²/2) g₁, so ε = (b²/4)
//!   ((τ² − κa₁) g₁ − κa₂ g₂) and the energy is (E t b⁵/64) vᵀ G v,
//!   v = (τ² − κa₁, −κa₂). In a bent sheet whose curl is held back (β large)
//!   ε is a self-equilibrated stress, tension at the edges, and its product
//!   with the trapeze strain stiffens the twist (Wagner): the Poisson share
//!   of the deflected sheet's torsion-coupled modes. With τ alone it is
//!   Buckley's (E t b⁵/1440) τ⁴;
//!
//! with G, G′ the Gram matrices of g and g′ on ζ ∈ [−1, 1]. Integrated exactly
//! (two and three Gauss points along the element), each term is ½ S ε² of a
//! deformation ε (constant S), so the element's derivatives are exact like
//! every kernel's. For a uniform κ the energy is the two-term Ritz solution of
//! Ashwell's strip (`research/sheet22/anticlastic.py`: its tangent stiffness
//! is within 0.1 % of the converged one for β ≤ 20). The kinetic energy of
//! the curl, (ρ t/2) ∫ ẇ² dz, is a constant mass over the amplitudes.
//!
//! With ν = 0 the curl decouples (its minimum is a = 0 in every untwisted
//! state), and the linearization about such a state is the beam's.
//!
//! The coordinates are η = (b²/4) a (m): the curl's deflection amplitudes,
//! w = η₁ g₁ + η₂ g₂ (scaled so that their stiffness is not 1e-15 of the
//! beam's, which a pivot test would call singular).

use crate::element::{frame_from_axis, Element, Slot};
use crate::kernels::{DeformationKernel, TwoNodeSpatial};
use crate::section::{Material, SectionShape};
use crate::ElementError;
use flexmb_dual::Real;
use nalgebra::DMatrix;

/// Gram matrices of the curl shapes g₁ = ζ²/2 − 1/6, g₂ = ζ⁴/8 − ζ²/4 + 7/120
/// on [−1, 1] (G) and of their derivatives (G′).
const GRAM: [[f64; 2]; 2] = [[2.0 / 45.0, -4.0 / 315.0], [-4.0 / 315.0, 2.0 / 525.0]];
const GRAM_D: [[f64; 2]; 2] = [[2.0 / 3.0, -2.0 / 15.0], [-2.0 / 15.0, 4.0 / 105.0]];

/// The deformations of the overlay: Poisson coupling at two Gauss points
/// (νκ + a₁, a₂ each), the curl's twist (two), membrane at three Gauss
/// points (two each).
pub const ANTICLASTIC_NAMES: [&str; 12] = [
    "curl_1_g1",
    "curl_2_g1",
    "curl_1_g2",
    "curl_2_g2",
    "curl_twist_1",
    "curl_twist_2",
    "curl_membrane_1_g1",
    "curl_membrane_2_g1",
    "curl_membrane_1_g2",
    "curl_membrane_2_g2",
    "curl_membrane_1_g3",
    "curl_membrane_2_g3",
];

/// The type name of the overlay ([`Element::type_name`]).
pub const ANTICLASTIC_TYPE: &str = "anticlastic curl";

/// Upper-triangular R with RᵀR = m (2 × 2, positive definite).
fn cholesky2(m: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let r11 = m[0][0].sqrt();
    let r12 = m[0][1] / r11;
    [[r11, r12], [0.0, (m[1][1] - r12 * r12).sqrt()]]
}

/// Gauss–Legendre points on [0, 1]: two and three.
fn gauss2() -> [f64; 2] {
    let h = 0.5 / 3f64.sqrt();
    [0.5 - h, 0.5 + h]
}
fn gauss3() -> ([f64; 3], [f64; 3]) {
    let h = 0.5 * (0.6f64).sqrt();
    ([0.5 - h, 0.5, 0.5 + h], [5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0])
}

/// ε = D(x) of the overlay over x = (rp, λp, rq, λq, a₁p, a₂p, a₁q, a₂q).
pub(crate) struct AnticlasticKernel {
    beam: TwoNodeSpatial,
    /// Index of the weak plane's first bending deformation (2: about local
    /// y, 4: about local z).
    weak: usize,
    nu: f64,
    /// 4/b²: the curvature amplitudes a over the coordinates η.
    inv_scale: f64,
    twist_r: [[f64; 2]; 2],
    membrane_r: [[f64; 2]; 2],
}

impl AnticlasticKernel {
    /// κ at ξ = s/l0 from the beam's weak-plane bending deformations.
    fn curvature<T: Real>(&self, eb: [T; 2], xi: f64) -> T {
        let l0 = self.beam.l0;
        // θp = −εp/l0, θq = εq/l0; κ = (θp (6ξ − 4) + θq (6ξ − 2))/l0
        eb[0] * (-(6.0 * xi - 4.0) / (l0 * l0)) + eb[1] * ((6.0 * xi - 2.0) / (l0 * l0))
    }
}

fn lerp<T: Real>(p: T, q: T, xi: f64) -> T {
    p * (1.0 - xi) + q * xi
}

impl DeformationKernel<18, 12> for AnticlasticKernel {
    fn eval<T: Real>(&self, x: &[T; 18]) -> [T; 12] {
        let bx: [T; 14] = std::array::from_fn(|i| x[i]);
        let e = self.beam.eval(&bx);
        let eb = [e[self.weak], e[self.weak + 1]];
        // a = η (4/b²): the coordinates are the curl's deflection amplitudes
        let c = self.inv_scale;
        let (a1p, a2p, a1q, a2q) = (x[14] * c, x[15] * c, x[16] * c, x[17] * c);
        let mut out = [T::cst(0.0); 12];
        for (g, xi) in gauss2().into_iter().enumerate() {
            let k = self.curvature(eb, xi);
            out[2 * g] = k * self.nu + lerp(a1p, a1q, xi);
            out[2 * g + 1] = lerp(a2p, a2q, xi);
        }
        let (d1, d2) = (a1q - a1p, a2q - a2p);
        let r = &self.twist_r;
        out[4] = d1 * r[0][0] + d2 * r[0][1];
        out[5] = d2 * r[1][1];
        let m = &self.membrane_r;
        // the twist rate Θ/l0 (Θ = torsion/l0): its trapeze strain ½τ²(z² − b²/12)
        // is (b²/4) τ² g₁
        let l0 = self.beam.l0;
        let tau2 = e[1] * e[1] * (1.0 / (l0 * l0 * l0 * l0));
        for (g, xi) in gauss3().0.into_iter().enumerate() {
            let k = self.curvature(eb, xi);
            let (a1, a2) = (lerp(a1p, a1q, xi), lerp(a2p, a2q, xi));
            // the fibre at normal offset w on the sheet of curvature κ:
            // strain −κw (a₁ ≈ −νκ: tension at the edges)
            let (v1, v2) = (tau2 - k * a1, -(k * a2));
            out[6 + 2 * g] = v1 * m[0][0] + v2 * m[0][1];
            out[7 + 2 * g] = v2 * m[1][1];
        }
        out
    }
}

/// The anticlastic overlay of the spatial beam from p to q with local y the
/// part of `up` orthogonal to the axis (the beam's own frame; module docs).
/// Slots (rp, λp, rq, λq, η_p, η_q), the η's two-mode slots (η₁, η₂) of
/// the curl in m (η = (b²/4) a). The section must be a `Rectangle`: its thinner side is
/// the thickness t, the other the height b, and the weak plane is that of
/// bending about the axis along b. `inertia` adds the curl's kinetic energy.
pub fn anticlastic_overlay(
    p: [f64; 3],
    q: [f64; 3],
    up: [f64; 3],
    mat: &Material,
    shape: &SectionShape,
    inertia: bool,
) -> Result<Element, ElementError> {
    mat.validate()?;
    let SectionShape::Rectangle { by, bz } = *shape else {
        return Err(ElementError::MissingProperty {
            what: "a Rectangle section for `anticlastic`".into(),
            why: format!("the anticlastic curl is that of a sheet (height and thickness); {shape:?} is not one"),
        });
    };
    // bending about local y (iy = by bz³/12) is weak when bz is the thickness
    let (b, t, weak) = if bz <= by { (by, bz, 2) } else { (bz, by, 4) };
    if !(t > 0.0 && b.is_finite()) {
        return Err(ElementError::InvalidProperty {
            what: "Rectangle side".into(),
            value: t,
            why: "must be positive and finite".into(),
        });
    }
    let axis = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    let l0 = axis.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(l0.is_finite() && l0 > 0.0) {
        return Err(ElementError::Geometry(format!(
            "anticlastic overlay from {p:?} to {q:?} has no length"
        )));
    }
    let r0 = frame_from_axis(&axis, &up)?;
    let nu = mat.poisson();
    let d = mat.e * t.powi(3) / (12.0 * (1.0 - nu * nu));
    let kernel = AnticlasticKernel {
        beam: TwoNodeSpatial {
            l0,
            r0,
            bowing: false,
        },
        weak,
        nu,
        inv_scale: 4.0 / (b * b),
        twist_r: cholesky2(GRAM_D),
        membrane_r: cholesky2(GRAM),
    };
    let mut s = vec![0.0; 12];
    for g in 0..2 {
        s[2 * g] = d * b * l0 * 0.5;
        s[2 * g + 1] = d * b / 5.0 * l0 * 0.5;
    }
    let twist = d * (1.0 - nu) * b.powi(3) / (4.0 * l0);
    s[4] = twist;
    s[5] = twist;
    let (_, w3) = gauss3();
    for g in 0..3 {
        let m = mat.e * t * b.powi(5) / 32.0 * l0 * w3[g];
        s[6 + 2 * g] = m;
        s[7 + 2 * g] = m;
    }
    let slots = [
        Slot::Position3,
        Slot::Orientation,
        Slot::Position3,
        Slot::Orientation,
        Slot::Modes(2),
        Slot::Modes(2),
    ];
    let el = Element::custom::<_, 18, 12>(
        ANTICLASTIC_TYPE,
        kernel,
        &slots,
        &ANTICLASTIC_NAMES,
        DMatrix::from_diagonal(&nalgebra::DVector::from_vec(s)),
    )?;
    if !(inertia && mat.rho > 0.0) {
        return Ok(el);
    }
    // ½ ȧᵀ (ρ t b⁵/32 G) ȧ per length, linear along the element, a = η 4/b²
    let c = mat.rho * t * b / 2.0 * l0;
    let mut m = DMatrix::zeros(18, 18);
    for (np, wp) in [(14, 0), (16, 1)] {
        for (nq, wq) in [(14, 0), (16, 1)] {
            let w = if wp == wq { 1.0 / 3.0 } else { 1.0 / 6.0 };
            for i in 0..2 {
                for j in 0..2 {
                    m[(np + i, nq + j)] = c * w * GRAM[i][j];
                }
            }
        }
    }
    el.with_mass_matrix(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grams_are_those_of_the_shapes() {
        // g₁ = ζ²/2 − 1/6, g₂ = ζ⁴/8 − ζ²/4 + 7/120 by 5-point Gauss
        let a = (5.0 - 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0;
        let bq = (5.0 + 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0;
        let wa = (322.0 + 13.0 * 70f64.sqrt()) / 900.0;
        let wb = (322.0 - 13.0 * 70f64.sqrt()) / 900.0;
        let pts = [(0.0, 128.0 / 225.0), (a, wa), (-a, wa), (bq, wb), (-bq, wb)];
        let g = |z: f64| {
            [
                z * z / 2.0 - 1.0 / 6.0,
                z.powi(4) / 8.0 - z * z / 4.0 + 7.0 / 120.0,
            ]
        };
        let dg = |z: f64| [z, z.powi(3) / 2.0 - z / 2.0];
        for i in 0..2 {
            for j in 0..2 {
                let gi: f64 = pts.iter().map(|(z, w)| w * g(*z)[i] * g(*z)[j]).sum();
                let di: f64 = pts.iter().map(|(z, w)| w * dg(*z)[i] * dg(*z)[j]).sum();
                assert!((gi - GRAM[i][j]).abs() < 1e-15, "{gi}");
                assert!((di - GRAM_D[i][j]).abs() < 1e-15, "{di}");
            }
            let mean: f64 = pts.iter().map(|(z, w)| w * g(*z)[i]).sum();
            assert!(mean.abs() < 1e-15);
        }
        let r = cholesky2(GRAM);
        assert!((r[0][0] * r[0][1] - GRAM[0][1]).abs() < 1e-16);
        assert!((r[0][1].powi(2) + r[1][1].powi(2) - GRAM[1][1]).abs() < 1e-16);
    }
}
