//! Vlasov torsion with warping for the spatial beam: one warping coordinate
//! w (the twist rate φ′, rad/m) at each end, and the twist φ(s) the cubic
//! Hermite polynomial with φ(0) = 0, φ(l) = Θ, φ′(0) = w_p, φ′(l) = w_q,
//! where Θ is the beam's torsion angle (the torsion deformation / l0).
//!
//! With η = l w (rad, the element's deformations `warping_p`, `warping_q`) the
//! energy U = GJ/2 ∫φ′² ds + EI_w/2 ∫φ″² ds is ½ µᵀ K µ over µ = (Θ, η_p, η_q):
//! * St-Venant part GJ/(30 l) ((36, −3, −3), (−3, 4, −1), (−3, −1, 4)),
//! * warping part EI_w/l³ ((12, −6, −6), (−6, 4, 2), (−6, 2, 4)).
//!
//! For w_p = w_q = Θ/l the twist is linear, U = GJΘ²/(2l) and the warping
//! part vanishes: the St-Venant beam. The warping inertia is Vlasov's
//! ρI_w/2 ∫φ̇′² ds over the w-parts of the interpolation,
//! ρ I_w l ((2/15, −1/30), (−1/30, 2/15)) over (ẇ_p, ẇ_q); the rotary inertia
//! of the twist stays the beam's (linear in s).

use crate::beam_matrices::{spatial_beam_m_bar, spatial_beam_s_bar};
use crate::section::{Material, SectionProperties};
use crate::ElementError;
use nalgebra::DMatrix;

/// The 3 × 3 torsion–warping stiffness over (Θ, η_p, η_q), η = l w: St-Venant
/// GJ ∫φ′² and Vlasov EI_w ∫φ″² of the cubic Hermite twist (module docs).
pub fn torsion_warping_block(gj: f64, eiw: f64, l: f64) -> [[f64; 3]; 3] {
    let t = gj / (30.0 * l);
    let w = eiw / (l * l * l);
    let st = [[36.0, -3.0, -3.0], [-3.0, 4.0, -1.0], [-3.0, -1.0, 4.0]];
    let vl = [[12.0, -6.0, -6.0], [-6.0, 4.0, 2.0], [-6.0, 2.0, 4.0]];
    std::array::from_fn(|i| std::array::from_fn(|j| t * st[i][j] + w * vl[i][j]))
}

/// The 2 × 2 warping mass ρ I_w l ((2/15, −1/30), (−1/30, 2/15)) over (ẇ_p, ẇ_q).
pub fn warping_mass_block(rho_iw: f64, l: f64) -> [[f64; 2]; 2] {
    let c = rho_iw * l;
    [[c * 2.0 / 15.0, -c / 30.0], [-c / 30.0, c * 2.0 / 15.0]]
}

/// The section's warping constant, or an error that says how to give one.
pub(crate) fn warping_constant(sec: &SectionProperties) -> Result<f64, ElementError> {
    sec.iw.ok_or_else(|| ElementError::MissingProperty {
        what: "section warping constant `iw`".into(),
        why: "a beam with warping needs I_w (m⁶): a Rectangle section gives it (h³t³/144), a User section must list `iw`".into(),
    })
}

/// S̄ (8 × 8, over µ̄e of (2.3c) then η_p, η_q) and M̄ (14 × 14, over v̄ of
/// (2.6b) then ẇ_p, ẇ_q) of the spatial beam with warping: the beam's, with
/// its St-Venant torsion replaced by [`torsion_warping_block`] and the
/// warping mass added.
pub(crate) fn warping_beam_matrices(
    mat: &Material,
    sec: &SectionProperties,
    l: f64,
) -> Result<(DMatrix<f64>, DMatrix<f64>), ElementError> {
    let iw = warping_constant(sec)?;
    let s6 = spatial_beam_s_bar(mat, sec, l);
    let mut s = DMatrix::zeros(8, 8);
    for i in 0..6 {
        for j in 0..6 {
            s[(i, j)] = s6[(i, j)];
        }
    }
    let k = torsion_warping_block(mat.g * sec.j, mat.e * iw, l);
    let at = [1, 6, 7];
    for a in 0..3 {
        for b in 0..3 {
            s[(at[a], at[b])] = k[a][b];
        }
    }
    let m12 = spatial_beam_m_bar(mat, sec, l);
    let mut m = DMatrix::zeros(14, 14);
    for i in 0..12 {
        for j in 0..12 {
            m[(i, j)] = m12[(i, j)];
        }
    }
    let mw = warping_mass_block(mat.rho * iw, l);
    for a in 0..2 {
        for b in 0..2 {
            m[(12 + a, 12 + b)] = mw[a][b];
        }
    }
    Ok((s, m))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// φ(ξ) of the Hermite twist and its derivatives in s, at ξ = s/l.
    fn twist(theta: f64, wp: f64, wq: f64, l: f64, xi: f64) -> (f64, f64, f64) {
        let (x2, x3) = (xi * xi, xi * xi * xi);
        let phi =
            theta * (3.0 * x2 - 2.0 * x3) + l * wp * (xi - 2.0 * x2 + x3) + l * wq * (x3 - x2);
        let d1 = (theta * (6.0 * xi - 6.0 * x2) / l)
            + wp * (1.0 - 4.0 * xi + 3.0 * x2)
            + wq * (3.0 * x2 - 2.0 * xi);
        let d2 = (theta * (6.0 - 12.0 * xi) / (l * l))
            + wp * (-4.0 + 6.0 * xi) / l
            + wq * (6.0 * xi - 2.0) / l;
        (phi, d1, d2)
    }

    /// Gauss–Legendre with 4 points on [0, 1]: exact for degree 7, so for
    /// the squares of the cubic's first and second derivatives.
    fn integrate(f: impl Fn(f64) -> f64) -> f64 {
        let a = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
        let b = (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
        let wa = (18.0 + 30.0f64.sqrt()) / 36.0;
        let wb = (18.0 - 30.0f64.sqrt()) / 36.0;
        [(-a, wa), (a, wa), (-b, wb), (b, wb)]
            .iter()
            .map(|(x, w)| 0.5 * w * f(0.5 * (1.0 + x)))
            .sum()
    }

    fn quad(k: &[[f64; 3]; 3], u: &[f64; 3]) -> f64 {
        (0..3)
            .map(|i| (0..3).map(|j| 0.5 * u[i] * k[i][j] * u[j]).sum::<f64>())
            .sum()
    }

    #[test]
    fn block_is_the_energy_of_the_hermite_twist() {
        let (gj, eiw, l) = (0.7, 0.013, 0.04);
        for (theta, wp, wq) in [(0.1, 0.3, -2.0), (-0.02, 5.0, 1.0), (0.3, 0.0, 0.0)] {
            let end = twist(theta, wp, wq, l, 1.0).0;
            assert!((end - theta).abs() < 1e-15 && twist(theta, wp, wq, l, 0.0).0 == 0.0);
            let ut = 0.5 * gj * l * integrate(|x| twist(theta, wp, wq, l, x).1.powi(2));
            let uw = 0.5 * eiw * l * integrate(|x| twist(theta, wp, wq, l, x).2.powi(2));
            let u = [theta, l * wp, l * wq];
            let k_t = torsion_warping_block(gj, 0.0, l);
            let k_w = torsion_warping_block(0.0, eiw, l);
            assert!(
                (quad(&k_t, &u) / ut - 1.0).abs() < 1e-12,
                "{} {ut}",
                quad(&k_t, &u)
            );
            assert!(
                (quad(&k_w, &u) / uw - 1.0).abs() < 1e-12,
                "{} {uw}",
                quad(&k_w, &u)
            );
        }
    }

    #[test]
    fn uniform_twist_rate_is_the_st_venant_beam() {
        let (gj, eiw, l, theta) = (0.7, 0.013, 0.04, 0.05);
        let k = torsion_warping_block(gj, eiw, l);
        let u = [theta, theta, theta]; // η = l w = Θ
        let e = quad(&k, &u);
        assert!(
            (e / (gj * theta * theta / (2.0 * l)) - 1.0).abs() < 1e-13,
            "{e}"
        );
    }

    #[test]
    fn warping_mass_is_the_vlasov_inertia_of_the_w_parts() {
        let (rho_iw, l, wp, wq) = (3.0e-12, 0.05, 0.7, -1.3);
        let t = 0.5 * rho_iw * l * integrate(|x| twist(0.0, wp, wq, l, x).1.powi(2));
        let m = warping_mass_block(rho_iw, l);
        let q = 0.5 * (m[0][0] * wp * wp + 2.0 * m[0][1] * wp * wq + m[1][1] * wq * wq);
        assert!((q / t - 1.0).abs() < 1e-12, "{q} {t}");
    }
}
