//! Euler parameters (unit quaternions) for flexible multibody dynamics.
//!
//! Implements the rotation kinematics of the thesis "Model reduction for flexible
//! multibody systems" (equation numbers refer to it): the rotation matrix R(λ), the
//! matrices Λ(λ) (2.14) and Λ̄ = RᵀΛ (2.33), angular velocities ω = 2Λλ̇ and
//! ω̄ = 2Λ̄λ̇, the derivatives ∂R/∂λ (C.3), the average frame λr (2.29) with its
//! derivative (B.6), composition, and robust conversions (rotation matrix,
//! axis–angle, rotation vector, ZYX angles).
//!
//! Two layers:
//! * [`EulerParameters`]: an `f64` type with nalgebra matrices, for users;
//! * [`generic`]: the same kinematics over any [`flexmb_dual::Real`] scalar, so
//!   that element functions built on them can be differentiated exactly.
//!
//! ```
//! use flexmb_rotation::EulerParameters;
//! use nalgebra::Vector3;
//! let l = EulerParameters::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
//! let r = l.rotation_matrix();
//! assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
//! // ω = 2Λλ̇ for a spin about z at 3 rad/s
//! let ld = l.lambda_dot_from_omega(&Vector3::new(0.0, 0.0, 3.0));
//! assert!((l.omega(&ld) - Vector3::new(0.0, 0.0, 3.0)).norm() < 1e-14);
//! ```
#![warn(missing_docs)]

mod euler;
pub mod generic;

pub use euler::{EulerParameters, Matrix3x4};
