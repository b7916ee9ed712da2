//! Initial orientations of nodes (`orientation:` in a scene): validated,
//! turned into the reference values of the node's orientation coordinates,
//! and given to the elements on the node so that they start undeformed.

use crate::scene::{Dimension, OrientationSpec};
use crate::ModelError;
use flexmb_rotation::EulerParameters;
use nalgebra::{Unit, Vector3};

/// The reference values of a node's orientation coordinates for `spec`:
/// one planar angle, or four unit Euler parameters. Errors name the node.
pub(crate) fn reference_values(
    node: &str,
    spec: &OrientationSpec,
    dim: Dimension,
) -> Result<Vec<f64>, ModelError> {
    let ctx = format!("node '{node}' orientation");
    let finite = |v: &[f64]| -> Result<(), ModelError> {
        match v.iter().find(|x| !x.is_finite()) {
            Some(x) => Err(ModelError::invalid(
                &ctx,
                format!("contains a non-finite value {x}"),
            )),
            None => Ok(()),
        }
    };
    let three = |what: &str, v: &[f64]| -> Result<Vector3<f64>, ModelError> {
        if v.len() != 3 {
            return Err(ModelError::invalid(
                &ctx,
                format!("{what} has {} components, needs 3", v.len()),
            ));
        }
        finite(v)?;
        Ok(Vector3::new(v[0], v[1], v[2]))
    };
    let spatial_only = |form: &str| -> Result<(), ModelError> {
        match dim {
            Dimension::Spatial => Ok(()),
            Dimension::Planar => Err(ModelError::invalid(
                &ctx,
                format!("{form} is for spatial scenes; a planar node takes Angle(φ)"),
            )),
        }
    };
    match spec {
        OrientationSpec::Angle(phi) => {
            if dim == Dimension::Spatial {
                return Err(ModelError::invalid(
                    &ctx,
                    "Angle(φ) is for planar scenes; a spatial node takes AxisAngle, RotationVector or EulerParameters",
                ));
            }
            finite(&[*phi])?;
            Ok(vec![*phi])
        }
        OrientationSpec::AxisAngle { axis, angle } => {
            spatial_only("AxisAngle")?;
            let a = three("the axis", axis)?;
            finite(&[*angle])?;
            if a.norm() == 0.0 {
                return Err(ModelError::invalid(&ctx, "the axis has zero length"));
            }
            Ok(
                EulerParameters::from_axis_angle(&Unit::new_normalize(a), *angle)
                    .0
                    .to_vec(),
            )
        }
        OrientationSpec::RotationVector(v) => {
            spatial_only("RotationVector")?;
            let v = three("the rotation vector", v)?;
            Ok(EulerParameters::from_rotation_vector(&v).0.to_vec())
        }
        OrientationSpec::EulerParameters(l) => {
            spatial_only("EulerParameters")?;
            if l.len() != 4 {
                return Err(ModelError::invalid(
                    &ctx,
                    format!("Euler parameters have 4 components, not {}", l.len()),
                ));
            }
            finite(l)?;
            let n = l.iter().map(|v| v * v).sum::<f64>().sqrt();
            if (n - 1.0).abs() > 1e-9 {
                return Err(ModelError::invalid(
                    &ctx,
                    format!("the Euler parameters {l:?} have norm {n}, not 1 (within 1e-9)"),
                ));
            }
            Ok(l.iter().map(|v| v / n).collect())
        }
    }
}

/// Whether `values` are those of the identity (no map needed).
pub(crate) fn is_identity(values: &[f64]) -> bool {
    match values {
        [phi] => *phi == 0.0,
        [l0, rest @ ..] => *l0 == 1.0 && rest.iter().all(|v| *v == 0.0),
        [] => true,
    }
}
