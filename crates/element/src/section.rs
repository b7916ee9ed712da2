//! Materials and cross-section properties of beams.
//!
//! Local beam axes: x along the beam (from node p to node q), y and z the
//! principal axes of the cross-section. Bending "about z" deflects in the xy-plane
//! and uses `iz` and the shear factor `ky` (shear in y).

use crate::ElementError;
use serde::{Deserialize, Serialize};

/// A linear elastic isotropic material.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub e: f64,
    /// Shear modulus G (Pa).
    pub g: f64,
    /// Density ρ (kg/m³).
    pub rho: f64,
}

impl Material {
    /// From E, Poisson's ratio ν and ρ (G = E / (2(1 + ν))).
    pub fn from_poisson(e: f64, nu: f64, rho: f64) -> Self {
        Self {
            e,
            g: e / (2.0 * (1.0 + nu)),
            rho,
        }
    }
    /// Poisson's ratio implied by E and G.
    pub fn poisson(&self) -> f64 {
        self.e / (2.0 * self.g) - 1.0
    }
    /// Checks that E, G are positive and ρ non-negative, all finite, and that
    /// the Poisson's ratio E/(2G) − 1 they imply lies in (−1, 0.5), the range
    /// of an isotropic elastic material (G > E/3).
    pub fn validate(&self) -> Result<(), ElementError> {
        positive("Young's modulus E", self.e)?;
        positive("shear modulus G", self.g)?;
        non_negative("density rho", self.rho)?;
        let nu = self.poisson();
        if !(nu > -1.0 && nu < 0.5) {
            return Err(ElementError::InvalidProperty {
                what: "shear modulus G".into(),
                value: self.g,
                why: format!(
                    "implies Poisson's ratio E/(2G) − 1 = {nu:.4}, outside (−1, 0.5) (G must exceed E/3)"
                ),
            });
        }
        Ok(())
    }
}

/// Cross-section properties used by the beam elements.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SectionProperties {
    /// Area A (m²).
    pub area: f64,
    /// Second moment of area about local y, Iy (m⁴) (bending in the xz-plane).
    pub iy: f64,
    /// Second moment of area about local z, Iz (m⁴) (bending in the xy-plane).
    pub iz: f64,
    /// Torsion constant J (m⁴) (St Venant).
    pub j: f64,
    /// Shear correction factor for shear in y (κy); `f64::INFINITY` gives Euler–Bernoulli.
    pub ky: f64,
    /// Shear correction factor for shear in z (κz); `f64::INFINITY` gives Euler–Bernoulli.
    pub kz: f64,
    /// Warping constant I_w (m⁶) of Vlasov torsion, used only by beams with
    /// warping ([`BeamOptions::warping`](crate::BeamOptions)); `None` if the
    /// section does not give one (a `User` section without `iw`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iw: Option<f64>,
}

impl SectionProperties {
    /// Polar second moment of area Iy + Iz (rotary inertia about the axis).
    pub fn polar(&self) -> f64 {
        self.iy + self.iz
    }
    /// Checks positivity and finiteness (shear factors may be infinite), and
    /// the bounds every real cross-section obeys: the torsion constant J is at
    /// most the polar moment Iy + Iz (equal for a circle or a circular tube),
    /// and a finite shear correction factor is at most 1 (5/6 for a rectangle).
    pub fn validate(&self) -> Result<(), ElementError> {
        positive("section area `area`", self.area)?;
        positive("section second moment `iy`", self.iy)?;
        positive("section second moment `iz`", self.iz)?;
        positive("section torsion constant `j`", self.j)?;
        if let Some(iw) = self.iw {
            non_negative("section warping constant `iw`", iw)?;
        }
        for (n, v) in [
            ("shear factor `ky`", self.ky),
            ("shear factor `kz`", self.kz),
        ] {
            if v.is_nan() || v <= 0.0 || (v.is_finite() && v > 1.0) {
                return Err(ElementError::InvalidProperty {
                    what: n.into(),
                    value: v,
                    why: "must lie in (0, 1] (about 5/6 for a rectangle; use inf for Euler–Bernoulli)".into(),
                });
            }
        }
        let polar = self.polar();
        if self.j > polar * (1.0 + 1e-9) {
            return Err(ElementError::InvalidProperty {
                what: "section torsion constant `j`".into(),
                value: self.j,
                why: format!(
                    "exceeds the polar moment Iy + Iz = {polar:e}, which bounds it for every cross-section"
                ),
            });
        }
        Ok(())
    }
    /// The same section without shear flexibility (Euler–Bernoulli bending).
    pub fn euler_bernoulli(mut self) -> Self {
        self.ky = f64::INFINITY;
        self.kz = f64::INFINITY;
        self
    }
}

/// A cross-section shape from which [`SectionProperties`] follow.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SectionShape {
    /// A solid rectangle with side `by` along local y and `bz` along local z.
    Rectangle {
        /// Side along local y (m).
        by: f64,
        /// Side along local z (m).
        bz: f64,
    },
    /// A solid circle.
    Circle {
        /// Diameter (m).
        d: f64,
    },
    /// A circular tube.
    Tube {
        /// Outer diameter (m).
        d_outer: f64,
        /// Inner diameter (m).
        d_inner: f64,
    },
    /// Properties given directly.
    User(SectionProperties),
}

impl SectionShape {
    /// The section properties; shear factors from Cowper (1966), which depend on
    /// Poisson's ratio ν: rectangle 10(1+ν)/(12+11ν), solid circle
    /// 6(1+ν)/(7+6ν), tube (general hollow circle formula of Cowper with
    /// m = d_inner/d_outer).
    pub fn properties(&self, nu: f64) -> Result<SectionProperties, ElementError> {
        let p = match *self {
            SectionShape::Rectangle { by, bz } => {
                positive("rectangle side `by`", by)?;
                positive("rectangle side `bz`", bz)?;
                let k = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
                SectionProperties {
                    area: by * bz,
                    iy: by * bz.powi(3) / 12.0,
                    iz: bz * by.powi(3) / 12.0,
                    j: rectangle_torsion_constant(by, bz),
                    ky: k,
                    kz: k,
                    iw: Some(rectangle_warping_constant(by, bz)),
                }
            }
            SectionShape::Circle { d } => {
                positive("circle diameter `d`", d)?;
                let i = std::f64::consts::PI * d.powi(4) / 64.0;
                let k = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
                SectionProperties {
                    area: std::f64::consts::PI * d * d / 4.0,
                    iy: i,
                    iz: i,
                    j: 2.0 * i,
                    ky: k,
                    kz: k,
                    iw: Some(0.0),
                }
            }
            SectionShape::Tube { d_outer, d_inner } => {
                positive("tube outer diameter `d_outer`", d_outer)?;
                non_negative("tube inner diameter `d_inner`", d_inner)?;
                if d_inner >= d_outer {
                    return Err(ElementError::InvalidProperty {
                        what: "tube inner diameter `d_inner`".into(),
                        value: d_inner,
                        why: format!("must be smaller than the outer diameter `d_outer` = {d_outer} (a wall thickness between 0 and half the outer diameter)"),
                    });
                }
                let pi = std::f64::consts::PI;
                let i = pi * (d_outer.powi(4) - d_inner.powi(4)) / 64.0;
                let m = d_inner / d_outer;
                let m2 = m * m;
                let k = 6.0 * (1.0 + nu) * (1.0 + m2).powi(2)
                    / ((7.0 + 6.0 * nu) * (1.0 + m2).powi(2) + (20.0 + 12.0 * nu) * m2);
                SectionProperties {
                    area: pi * (d_outer * d_outer - d_inner * d_inner) / 4.0,
                    iy: i,
                    iz: i,
                    j: 2.0 * i,
                    ky: k,
                    kz: k,
                    iw: Some(0.0),
                }
            }
            SectionShape::User(p) => p,
        };
        p.validate()?;
        Ok(p)
    }
}

/// St Venant torsion constant of a solid rectangle a × b from the standard
/// series (Timoshenko & Goodier, *Theory of Elasticity*, §109):
/// J = (a b³/3) (1 − (192/π⁵)(b/a) Σ_{n odd} tanh(nπa/(2b))/n⁵), a ≥ b.
/// Summed until the terms are below 1e-17 relative.
pub fn rectangle_torsion_constant(s1: f64, s2: f64) -> f64 {
    let (a, b) = if s1 >= s2 { (s1, s2) } else { (s2, s1) };
    let pi = std::f64::consts::PI;
    let mut sum = 0.0;
    let mut n = 1.0f64;
    loop {
        let t = (n * pi * a / (2.0 * b)).tanh() / n.powi(5);
        sum += t;
        if t < 1e-17 * sum {
            break;
        }
        n += 2.0;
    }
    a * b.powi(3) / 3.0 * (1.0 - 192.0 / pi.powi(5) * (b / a) * sum)
}

/// Warping constant of a thin rectangle h × t (h the larger side):
/// I_w = h³t³/144, Vlasov's value for a thin strip, whose warping
/// u = −y z φ′ (y across the thickness, z along the height) costs the plate
/// bending energy of the strip's out-of-plane displacement z φ, D h³/12 per
/// unit φ″² with D = E t³/12 (ν = 0 in the plate stiffness). It is the
/// thin-strip limit: measured against a solid it holds to 0.04 % at h/t = 30
/// and 60, and is about 0.7 % off at h/t = 5–10
/// (research/sheet22/README.md). For the plate stiffness of an isotropic
/// sheet, D = E t³/(12(1 − ν²)), give a `User` section with
/// iw = h³t³/(144(1 − ν²)).
pub fn rectangle_warping_constant(s1: f64, s2: f64) -> f64 {
    let (h, t) = if s1 >= s2 { (s1, s2) } else { (s2, s1) };
    (h * t).powi(3) / 144.0
}

pub(crate) fn positive(what: &str, v: f64) -> Result<(), ElementError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ElementError::InvalidProperty {
            what: what.into(),
            value: v,
            why: "must be positive and finite".into(),
        })
    }
}

pub(crate) fn non_negative(what: &str, v: f64) -> Result<(), ElementError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(ElementError::InvalidProperty {
            what: what.into(),
            value: v,
            why: "must be non-negative and finite".into(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_torsion_constant_matches_tabulated_value() {
        // Roark / Timoshenko: square a = b: J = 0.1406 a⁴ (0.140577...)
        let j = rectangle_torsion_constant(1.0, 1.0);
        assert!((j - 0.140_577).abs() < 2e-6, "{j}");
        // thin strip: J → a b³/3 (1 − 0.630 b/a)
        let j = rectangle_torsion_constant(0.03, 0.001);
        let approx = 0.03 * 1e-9 / 3.0 * (1.0 - 0.630_2 * 0.001 / 0.03);
        assert!((j / approx - 1.0).abs() < 1e-4);
    }

    #[test]
    fn invalid_sections_are_rejected_with_a_name() {
        let e = SectionShape::Rectangle { by: 0.0, bz: 1.0 }
            .properties(0.3)
            .unwrap_err();
        assert!(e.to_string().contains("rectangle side `by`"));
        let e = SectionShape::Tube {
            d_outer: 1.0,
            d_inner: 2.0,
        }
        .properties(0.3)
        .unwrap_err();
        assert!(e.to_string().contains("inner diameter"));
        assert!(Material {
            e: f64::NAN,
            g: 1.0,
            rho: 1.0
        }
        .validate()
        .is_err());
    }

    #[test]
    fn unphysical_properties_are_rejected_with_the_field() {
        let ok = SectionProperties {
            area: 1e-4,
            iy: 1e-9,
            iz: 2e-9,
            j: 1e-9,
            ky: 5.0 / 6.0,
            kz: f64::INFINITY,
            iw: None,
        };
        assert!(ok.validate().is_ok());
        // J is bounded by the polar moment Iy + Iz for every section
        let e = SectionProperties { j: 4e-9, ..ok }.validate().unwrap_err();
        assert!(
            e.to_string().contains("`j`") && e.to_string().contains("polar moment"),
            "{e}"
        );
        // a finite shear correction factor is at most 1
        let e = SectionProperties { ky: 1.2, ..ok }.validate().unwrap_err();
        assert!(e.to_string().contains("`ky`"), "{e}");
        let e = SectionProperties {
            iw: Some(-1e-18),
            ..ok
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("`iw`"), "{e}");
        // G = E/3 would mean ν = 0.5; G below it, ν > 0.5
        let e = Material {
            e: 3.0,
            g: 0.9,
            rho: 1.0,
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("Poisson"), "{e}");
        assert!(Material::from_poisson(2.1e11, 0.3, 7800.0)
            .validate()
            .is_ok());
    }
}
