//! The reference-configuration stage ([`BuildStage::ReferenceConfiguration`]):
//! every element undeformed and unflipped at x0, the deformations
//! ε = D(x0) of thesis (5.7) at the reference being zero.

use super::*;

/// Relative tolerance of the reference-strain check: |ε| ≤ 1e-9 l0 for the
/// deformations of beams, trusses and superelements (lengths, or l0 × an
/// angle), |ε| ≤ 1e-9 rad for hinge angles.
const REFERENCE_STRAIN_TOL: f64 = 1e-9;

/// Every element must be undeformed at the reference configuration x0: the
/// initial deformations ε = D(x0) (thesis (5.7) at the reference) are zero and
/// no element has flipped (a chord reversed against its node frames has ε = 0
/// too, [`Element::is_flipped`]). Scenes have no initial stress or prestrain,
/// so an element deformed at x0 would start strained and move the mechanism
/// without any load. Superelements are where this happens: their R0 is the FE
/// part's, and the scene's nodes may point elsewhere.
pub(super) fn check_reference_configuration(
    mech: &Mechanism,
    part_axes: &HashMap<String, PartAxis>,
) -> Result<(), ModelError> {
    let mut xl = vec![];
    let mut eps = vec![];
    for e in &mech.elements {
        xl.resize(e.x_index.len(), 0.0);
        e.gather(&mech.x0, &mut xl);
        eps.resize(e.element.n_eps(), 0.0);
        e.element.deformations(&xl, None, &mut eps);
        let (tol, unit) = match e.element.reference_length() {
            Some(l0) => (REFERENCE_STRAIN_TOL * l0, "m"),
            None => (REFERENCE_STRAIN_TOL, "rad"),
        };
        let strained = eps
            .iter()
            .enumerate()
            .filter(|(_, v)| v.abs() > tol || v.is_nan())
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        let what = match (strained, e.element.is_flipped(&xl)) {
            (Some((i, v)), _) => format!(
                "is deformed at the node positions of the scene ({} = {v:.3e} {unit}, tolerance {tol:.1e} {unit})",
                e.element.deformation_names()[i]
            ),
            (None, true) => format!(
                "is reversed at the node positions of the scene (its chord is turned by {:.1}° against its node frames)",
                e.element.chord_angle(&xl).unwrap_or(f64::NAN).to_degrees()
            ),
            (None, false) => continue,
        };
        let fix = match part_axes.get(&e.id) {
            Some(a) => {
                // rounding-level components printed as 0
                let snap = |v: [f64; 3], scale: f64| v.map(|c| if c.abs() <= 1e-12 * scale { 0.0 } else { c });
                let q: [f64; 3] = std::array::from_fn(|i| a.p.1[i] + a.l0 * a.x[i]);
                let scale = a.l0.max(a.p.1.iter().fold(0.0, |m: f64, c| m.max(c.abs())));
                let d: [f64; 3] = std::array::from_fn(|i| (a.q.1[i] - a.p.1[i]) / a.l0);
                format!(
                    "the scene's '{}' → '{}' points along {:?}, the FE part's p → q along {:?} (R0 of the superelement file). A superelement keeps the orientation it was built in: place '{}' at {:?}, or build the part with its p → q along {:?} (`transform` selects the velocity transformation B1/B2/B3, not a placement)",
                    a.p.0, a.q.0, snap(d, 1.0), snap(a.x, 1.0), a.q.0, snap(q, scale), snap(d, 1.0)
                )
            }
            None => "scenes have no initial stress or prestrain, so every element must be undeformed where its nodes are: correct the node positions".into(),
        };
        return Err(ModelError::invalid(
            format!("element '{}' ({})", e.id, e.element.type_name()),
            format!("{what}: {fix}"),
        ));
    }
    Ok(())
}
