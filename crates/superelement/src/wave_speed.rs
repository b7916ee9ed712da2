//! The material of an FE model inferred from its matrices: the strain
//! energies of linear displacement fields, which every conforming or
//! patch-test-passing solid element reproduces exactly, give the volume
//! integrals of the elastic moduli, and with the rigid-body mass the bar
//! wave speed c = √(E/ρ), which needs neither the volume nor the density.
//!
//! For a part of one homogeneous isotropic material (Lamé λ, μ, volume V):
//! the field u_d = x_d (a uniform strain ε_dd = 1, the other strains zero)
//! has uᵀKu = (λ + 2μ) V; the field u_d = x_e (e ≠ d, engineering shear 1)
//! has uᵀKu = μ V. Hence λV, μV, E V = μV (3λV + 2μV)/(λV + μV),
//! ν = λ/(2(λ + μ)) and c² = E V / m with m = uᵀMu of a unit translation.
//! A factor k on the stiffness multiplies c by √k, so c tells a stiffness
//! off by 100 (c 10 × too small) from a plausible one (steel, aluminium and
//! titanium all have c ≈ 5000 m/s), and coordinates and matrices in other
//! length units give c in those units.

use crate::model::{sub, sym_quad};
use crate::FeModel;

/// The material of a model from its linear-field energies.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InferredMaterial {
    /// (λ + 2μ) V: the mean of the three uniform normal strains' 2 × energy.
    pub constrained_times_volume: f64,
    /// μ V: the mean of the six uniform shears' 2 × energy.
    pub shear_times_volume: f64,
    /// The largest relative deviation of the nine energies from their means
    /// (0 for an isotropic homogeneous part; large for an anisotropic or
    /// mixed-material part, where E and ν below are averages only).
    pub anisotropy: f64,
    /// The rigid-body mass uᵀMu (mean of the three directions).
    pub mass: f64,
    /// Young's modulus times the volume, E V.
    pub young_times_volume: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// The bar wave speed √(E/ρ) = √(E V / m).
    pub wave_speed: f64,
}

impl InferredMaterial {
    /// Young's modulus for the mesh volume `volume`.
    pub fn young(&self, volume: f64) -> f64 {
        self.young_times_volume / volume
    }
}

/// The material inferred from `model`'s K and M, or `None` where the fields
/// cannot be applied: a node without all three translational DOFs (a
/// support removes energy the field would have), no mass, or energies that
/// are not those of an elastic solid (negative or zero).
pub fn infer_material(model: &FeModel) -> Option<InferredMaterial> {
    let n = model.n_nodes();
    let dofs = model.dofs();
    if n == 0 || (0..n).any(|i| dofs.node_eqs(i).iter().any(|e| e.is_none())) {
        return None;
    }
    // about the centroid of the nodes, to keep the rounding small
    let c = model.coords().iter().fold([0.0; 3], |a, p| {
        std::array::from_fn(|d| a[d] + p[d] / n as f64)
    });
    // the field u_d = x_e
    let field = |d: usize, e: usize| -> Vec<f64> {
        (0..model.n_eq())
            .map(|q| {
                let (nd, dir) = dofs.dof(q);
                if dir as usize == d {
                    sub(model.coords()[nd], c)[e]
                } else {
                    0.0
                }
            })
            .collect()
    };
    let energy = |d: usize, e: usize| {
        let u = field(d, e);
        sym_quad(model.k(), &u, &u)
    };
    let normal: Vec<f64> = (0..3).map(|d| energy(d, d)).collect();
    let shear: Vec<f64> = (0..3)
        .flat_map(|d| (0..3).filter(move |e| *e != d).map(move |e| (d, e)))
        .map(|(d, e)| energy(d, e))
        .collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (cv, mv) = (mean(&normal), mean(&shear));
    let tm = model.translational_mass();
    let mass = (tm[0] + tm[1] + tm[2]) / 3.0;
    let lv = cv - 2.0 * mv;
    if !(cv > 0.0 && mv > 0.0 && mass > 0.0 && lv + mv > 0.0) {
        return None;
    }
    let spread = |v: &[f64], m: f64| v.iter().map(|x| (x / m - 1.0).abs()).fold(0.0, f64::max);
    let ev = mv * (3.0 * lv + 2.0 * mv) / (lv + mv);
    Some(InferredMaterial {
        constrained_times_volume: cv,
        shear_times_volume: mv,
        anisotropy: spread(&normal, cv).max(spread(&shear, mv)),
        mass,
        young_times_volume: ev,
        poisson: lv / (2.0 * (lv + mv)),
        wave_speed: (ev / mass).sqrt(),
    })
}

/// Bar wave speeds √(E/ρ) of engineering solids (m/s): polymers from about
/// 1000, lead 1200, steel, aluminium and titanium about 5000, beryllium
/// 12 900.
pub const PLAUSIBLE_WAVE_SPEED: [f64; 2] = [1000.0, 13000.0];

impl InferredMaterial {
    /// What to set in a spec when the wave speed is outside
    /// [`PLAUSIBLE_WAVE_SPEED`]: the unit systems whose velocity unit
    /// (length/time = √(length · force / mass)) brings it in (files in
    /// mm–t–s or mm–kg–s read as SI give a speed 1000 × too large; mm–kg–ms
    /// has the velocity unit m/s and is not told by it), and the power-of-ten
    /// factor on the stiffness (as built, so on top of a spec's
    /// `stiffness_scale`) that brings it nearest to a metal's 5000 m/s;
    /// `None` when it is plausible.
    pub fn advice(&self) -> Option<String> {
        let [lo, hi] = PLAUSIBLE_WAVE_SPEED;
        let c = self.wave_speed;
        if (lo..=hi).contains(&c) {
            return None;
        }
        let systems: Vec<&str> = crate::units::UNIT_SYSTEMS
            .iter()
            .filter(|u| {
                let velocity = (u.length * u.force / u.mass).sqrt();
                u.name != "SI" && (lo..=hi).contains(&(c * velocity))
            })
            .map(|u| u.name)
            .collect();
        let scale = 10f64.powi((2.0 * (5000.0 / c).log10()).round() as i32);
        let mut s = format!(
            "the stiffness and mass give a wave speed √(E/ρ) = {c:.4e} m/s (E V = {:.4e}, ν = {:.3}, \
             mass {:.4e}), outside the {lo}..{hi} m/s of engineering solids",
            self.young_times_volume, self.poisson, self.mass
        );
        if !systems.is_empty() {
            s += &format!(
                "; if the files are in those units, set `units: Some(\"{}\")`",
                systems.join("\" or \"")
            );
        }
        s += &format!(
            "; if the stiffness came from a model with another Young's modulus, the stiffness \
             × {scale:e} (`stiffness_scale: Some({scale:e})` where none is set, else the spec's \
             scale × {scale:e}) gives {:.4e} m/s",
            c * scale.sqrt()
        );
        Some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::InferredMaterial;

    fn with_speed(c: f64) -> InferredMaterial {
        InferredMaterial {
            constrained_times_volume: 1.0,
            shear_times_volume: 1.0,
            anisotropy: 0.0,
            mass: 1.0,
            young_times_volume: c * c,
            poisson: 0.3,
            wave_speed: c,
        }
    }

    #[test]
    fn the_advice_names_the_unit_systems_with_a_millimetre_per_second_speed() {
        assert_eq!(with_speed(5172.0).advice(), None);
        // steel in mm–t–s read as SI: 5.172e6 mm/s
        let a = with_speed(5.172e6).advice().unwrap();
        assert!(a.contains("units: Some(\"mm-t-s\" or \"mm-kg-s\")"), "{a}");
        assert!(!a.contains("mm-kg-ms"), "{a}");
        assert!(a.contains("stiffness_scale: Some(1e-6)"), "{a}");
        let a = with_speed(517.2).advice().unwrap();
        assert!(
            !a.contains("units:") && a.contains("stiffness_scale: Some(1e2)"),
            "{a}"
        );
    }
}
