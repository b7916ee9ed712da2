//! Unit systems of FE exports. A matrix file does not say its units: a
//! deck in mm–t–s writes K in N/mm, M in tonnes and coordinates in mm, and
//! the builder, which works in SI, must be told. [`UnitSystem`] names the
//! common consistent systems; the spec's `stiffness_scale` and `mass_scale`
//! multiply on top (for a stiffness exported from a model with another
//! Young's modulus, for example).

use crate::Error;

/// A consistent unit system: what one file unit of length, mass and force is
/// in SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitSystem {
    /// Its name, as written in a spec.
    pub name: &'static str,
    /// Metres per length unit.
    pub length: f64,
    /// Kilograms per mass unit.
    pub mass: f64,
    /// Newtons per force unit.
    pub force: f64,
}

/// The unit systems a spec can name (`units: Some("mm-t-s")`).
pub const UNIT_SYSTEMS: [UnitSystem; 4] = [
    UnitSystem {
        name: "SI",
        length: 1.0,
        mass: 1.0,
        force: 1.0,
    },
    // mm, tonne, s: N, MPa, t/mm³
    UnitSystem {
        name: "mm-t-s",
        length: 1e-3,
        mass: 1e3,
        force: 1.0,
    },
    // mm, kg, ms: kN, GPa, kg/mm³
    UnitSystem {
        name: "mm-kg-ms",
        length: 1e-3,
        mass: 1.0,
        force: 1e3,
    },
    // mm, kg, s: mN, kPa
    UnitSystem {
        name: "mm-kg-s",
        length: 1e-3,
        mass: 1.0,
        force: 1e-3,
    },
];

impl UnitSystem {
    /// The system named `name` (case-insensitive; "m-kg-s" is SI), or an
    /// error listing the known ones and the nearest.
    pub fn named(name: &str) -> Result<Self, Error> {
        let key = if name.eq_ignore_ascii_case("m-kg-s") {
            "SI"
        } else {
            name
        };
        if let Some(u) = UNIT_SYSTEMS
            .iter()
            .find(|u| u.name.eq_ignore_ascii_case(key))
        {
            return Ok(*u);
        }
        let names: Vec<&str> = UNIT_SYSTEMS.iter().map(|u| u.name).collect();
        let hint = flexmb_input::nearest(name, names.iter().copied())
            .map(|n| format!(" (did you mean \"{n}\"?)"))
            .unwrap_or_default();
        Err(Error::Spec(format!(
            "units: \"{name}\" is not a unit system I know{hint}; use one of {}",
            names
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(", ")
        )))
    }

    /// The factors (length, stiffness, mass) that take a model in these
    /// units to SI, with the extra stiffness and mass scales applied.
    pub fn to_si(&self, stiffness_scale: f64, mass_scale: f64) -> (f64, f64, f64) {
        (
            self.length,
            self.force / self.length * stiffness_scale,
            self.mass * mass_scale,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_systems_convert_steel_to_si() {
        // steel in mm-t-s: E = 210000 MPa, rho = 7.85e-9 t/mm³
        let u = UnitSystem::named("mm-t-s").unwrap();
        let (l, k, m) = u.to_si(1.0, 1.0);
        // a stiffness E·A/L of 1 mm² over 1 mm in N/mm, a mass of 1 mm³
        assert!((210000.0 * k - 2.1e11 * 1e-6 / 1e-3).abs() < 1e-3);
        assert!((7.85e-9 * m - 7850.0 * 1e-9).abs() < 1e-18);
        assert_eq!(l, 1e-3);
        let u = UnitSystem::named("MM-KG-MS").unwrap();
        let (_, k, _) = u.to_si(1.0, 1.0);
        assert!((210.0 * k - 2.1e11 * 1e-6 / 1e-3).abs() < 1e-3); // E = 210 GPa
        assert_eq!(UnitSystem::named("m-kg-s").unwrap().name, "SI");
        let e = UnitSystem::named("mm-ton-s").unwrap_err().to_string();
        assert!(
            e.contains("did you mean \"mm-t-s\"") && e.contains("\"SI\""),
            "{e}"
        );
    }
}
