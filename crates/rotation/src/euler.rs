//! The `f64` Euler-parameter type with nalgebra matrices for users.

use crate::generic;
use nalgebra::{Matrix3, Matrix4, SMatrix, Unit, Vector3, Vector4};
use serde::{Deserialize, Serialize};

/// A 3×4 matrix (Λ, Λ̄).
pub type Matrix3x4 = SMatrix<f64, 3, 4>;

/// Euler parameters λ = (λ0, λ1, λ2, λ3), λ0 the scalar part, describing the
/// rotation R(λ) (thesis §2.3.1). A unit quaternion when normalized.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EulerParameters(pub [f64; 4]);

impl Default for EulerParameters {
    fn default() -> Self {
        Self::identity()
    }
}

impl EulerParameters {
    /// The identity rotation (1, 0, 0, 0).
    pub const fn identity() -> Self {
        Self([1.0, 0.0, 0.0, 0.0])
    }

    /// From raw components, without normalizing.
    pub const fn from_components(l: [f64; 4]) -> Self {
        Self(l)
    }

    /// The components as a vector.
    pub fn as_vector(&self) -> Vector4<f64> {
        Vector4::from(self.0)
    }

    /// The Euclidean norm |λ|.
    pub fn norm(&self) -> f64 {
        self.0.iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// λ / |λ|. Returns `None` for a (near) zero vector or non-finite input.
    pub fn normalized(&self) -> Option<Self> {
        let n = self.norm();
        if !(n.is_finite() && n > 1e-300) {
            return None;
        }
        Some(Self(self.0.map(|v| v / n)))
    }

    /// R(λ) = Λ Λ̄ᵀ (homogeneous quadratic form; a rotation matrix for unit λ).
    pub fn rotation_matrix(&self) -> Matrix3<f64> {
        let m = generic::rotation(&self.0).0;
        Matrix3::from_fn(|i, j| m[i][j])
    }

    /// Λ(λ), thesis Eq. (2.14).
    pub fn lambda(&self) -> Matrix3x4 {
        let m = generic::lambda_mat(&self.0);
        Matrix3x4::from_fn(|i, j| m[i][j])
    }

    /// Λ̄(λ) = RᵀΛ, thesis Eq. (2.33).
    pub fn lambda_bar(&self) -> Matrix3x4 {
        let m = generic::lambda_bar_mat(&self.0);
        Matrix3x4::from_fn(|i, j| m[i][j])
    }

    /// ω = 2 Λ λ̇, the angular velocity in the inertial frame (thesis Eq. (2.13)).
    pub fn omega(&self, lambda_dot: &[f64; 4]) -> Vector3<f64> {
        self.lambda() * Vector4::from(*lambda_dot) * 2.0
    }

    /// ω̄ = 2 Λ̄ λ̇, the angular velocity in the body frame.
    pub fn omega_body(&self, lambda_dot: &[f64; 4]) -> Vector3<f64> {
        self.lambda_bar() * Vector4::from(*lambda_dot) * 2.0
    }

    /// λ̇ = ½ Λᵀ ω for a unit λ (the inverse of [`omega`](Self::omega) on the
    /// tangent space λᵀλ̇ = 0).
    pub fn lambda_dot_from_omega(&self, omega: &Vector3<f64>) -> [f64; 4] {
        let v = self.lambda().transpose() * omega * 0.5;
        [v[0], v[1], v[2], v[3]]
    }

    /// ∂R/∂λᵢ for i = 0..3 (thesis Eq. (C.3)); each is linear in λ.
    pub fn d_rotation(&self) -> [Matrix3<f64>; 4] {
        let [l0, l1, l2, l3] = self.0;
        let m = |a: [[f64; 3]; 3]| Matrix3::from_fn(|i, j| 2.0 * a[i][j]);
        [
            m([[l0, -l3, l2], [l3, l0, -l1], [-l2, l1, l0]]),
            m([[l1, l2, l3], [l2, -l1, -l0], [l3, l0, -l1]]),
            m([[-l2, l1, l0], [l1, l2, l3], [-l0, l3, -l2]]),
            m([[-l3, -l0, l1], [l0, -l3, l2], [l1, l2, l3]]),
        ]
    }

    /// The constant second derivatives ∂²R/∂λᵢ∂λⱼ (R is quadratic in λ).
    pub fn d2_rotation() -> [[Matrix3<f64>; 4]; 4] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let mut e = [0.0; 4];
                e[j] = 1.0;
                // ∂R/∂λᵢ is linear in λ, so its derivative along eⱼ is ∂R/∂λᵢ at λ = eⱼ.
                EulerParameters(e).d_rotation()[i]
            })
        })
    }

    /// The conjugate (inverse rotation for unit λ).
    pub fn conjugate(&self) -> Self {
        let [a, b, c, d] = self.0;
        Self([a, -b, -c, -d])
    }

    /// Composition: R(self ∘ other) = R(self) R(other).
    pub fn compose(&self, other: &Self) -> Self {
        Self(generic::compose(&self.0, &other.0))
    }

    /// The average frame λr = (λp + λq)/‖λp + λq‖ of thesis Eq. (2.29) (with λq
    /// moved to λp's hemisphere, so that λ and −λ give the same frame).
    pub fn average(p: &Self, q: &Self) -> Self {
        Self(generic::average(&p.0, &q.0))
    }

    /// ∂λr/∂λp and ∂λr/∂λq of thesis Eq. (B.6): (I − λr λrᵀ)/‖λp + λq‖ (times the
    /// hemisphere sign for λq).
    pub fn d_average(p: &Self, q: &Self) -> (Matrix4<f64>, Matrix4<f64>) {
        let s = generic::hemisphere_sign(&p.0, &q.0);
        let sum = p.as_vector() + q.as_vector() * s;
        let n = sum.norm();
        let r = sum / n;
        let d = (Matrix4::identity() - r * r.transpose()) / n;
        (d, d * s)
    }

    /// From a rotation matrix by Shepperd's method: robust at all angles
    /// (chooses the largest of 1 + tr R and the diagonal terms to divide by).
    /// The result has λ0 ≥ 0. The input is orthonormalized implicitly only in
    /// the sense that the result is normalized.
    pub fn from_rotation_matrix(r: &Matrix3<f64>) -> Self {
        let tr = r.trace();
        let cands = [tr, r[(0, 0)], r[(1, 1)], r[(2, 2)]];
        let k = (0..4)
            .max_by(|&a, &b| cands[a].total_cmp(&cands[b]))
            .unwrap_or(0);
        let l = match k {
            0 => {
                let s = (1.0 + tr).max(0.0).sqrt() * 2.0; // 4 λ0
                [
                    0.25 * s,
                    (r[(2, 1)] - r[(1, 2)]) / s,
                    (r[(0, 2)] - r[(2, 0)]) / s,
                    (r[(1, 0)] - r[(0, 1)]) / s,
                ]
            }
            1 => {
                let s = (1.0 + r[(0, 0)] - r[(1, 1)] - r[(2, 2)]).max(0.0).sqrt() * 2.0; // 4 λ1
                [
                    (r[(2, 1)] - r[(1, 2)]) / s,
                    0.25 * s,
                    (r[(0, 1)] + r[(1, 0)]) / s,
                    (r[(0, 2)] + r[(2, 0)]) / s,
                ]
            }
            2 => {
                let s = (1.0 - r[(0, 0)] + r[(1, 1)] - r[(2, 2)]).max(0.0).sqrt() * 2.0; // 4 λ2
                [
                    (r[(0, 2)] - r[(2, 0)]) / s,
                    (r[(0, 1)] + r[(1, 0)]) / s,
                    0.25 * s,
                    (r[(1, 2)] + r[(2, 1)]) / s,
                ]
            }
            _ => {
                let s = (1.0 - r[(0, 0)] - r[(1, 1)] + r[(2, 2)]).max(0.0).sqrt() * 2.0; // 4 λ3
                [
                    (r[(1, 0)] - r[(0, 1)]) / s,
                    (r[(0, 2)] + r[(2, 0)]) / s,
                    (r[(1, 2)] + r[(2, 1)]) / s,
                    0.25 * s,
                ]
            }
        };
        let e = Self(l).normalized().unwrap_or_default();
        if e.0[0] < 0.0 {
            Self(e.0.map(|v| -v))
        } else {
            e
        }
    }

    /// From a unit axis and an angle (radians).
    pub fn from_axis_angle(axis: &Unit<Vector3<f64>>, angle: f64) -> Self {
        let (s, c) = (0.5 * angle).sin_cos();
        Self([c, axis[0] * s, axis[1] * s, axis[2] * s])
    }

    /// The rotation as (unit axis, angle in 0..=π); the axis is x for the identity.
    pub fn to_axis_angle(&self) -> (Unit<Vector3<f64>>, f64) {
        let e = self.normalized().unwrap_or_default();
        let mut l = e.0;
        if l[0] < 0.0 {
            l = l.map(|v| -v);
        }
        let v = Vector3::new(l[1], l[2], l[3]);
        let s = v.norm();
        if s < 1e-300 {
            return (Vector3::x_axis(), 0.0);
        }
        // atan2 keeps full accuracy near 0 and near π.
        let angle = 2.0 * s.atan2(l[0]);
        (Unit::new_unchecked(v / s), angle)
    }

    /// From a rotation vector θ n (exponential map); exact near zero.
    pub fn from_rotation_vector(rv: &Vector3<f64>) -> Self {
        let th = rv.norm();
        let half = 0.5 * th;
        // sin(θ/2)/θ with its series near zero
        let k = if th < 1e-4 {
            0.5 - th * th / 48.0
        } else {
            half.sin() / th
        };
        Self([half.cos(), rv[0] * k, rv[1] * k, rv[2] * k])
    }

    /// The rotation vector θ n with θ ∈ 0..=π (logarithmic map).
    pub fn to_rotation_vector(&self) -> Vector3<f64> {
        let (axis, angle) = self.to_axis_angle();
        axis.into_inner() * angle
    }

    /// From ZYX angles (yaw ψ about z, then pitch θ about the new y, then roll φ
    /// about the new x): R = Rz(ψ) Ry(θ) Rx(φ).
    pub fn from_zyx(yaw: f64, pitch: f64, roll: f64) -> Self {
        let z = Self::from_axis_angle(&Vector3::z_axis(), yaw);
        let y = Self::from_axis_angle(&Vector3::y_axis(), pitch);
        let x = Self::from_axis_angle(&Vector3::x_axis(), roll);
        z.compose(&y).compose(&x)
    }

    /// ZYX angles (yaw, pitch, roll) for output, with pitch in −π/2..=π/2. At
    /// gimbal lock (|pitch| = π/2) the roll is set to zero and the yaw carries
    /// the whole remaining rotation.
    pub fn to_zyx(&self) -> (f64, f64, f64) {
        let r = self.normalized().unwrap_or_default().rotation_matrix();
        let sp = (-r[(2, 0)]).clamp(-1.0, 1.0);
        let pitch = sp.asin();
        if sp.abs() > 1.0 - 1e-12 {
            let yaw = (-r[(0, 1)]).atan2(r[(1, 1)]);
            (yaw, pitch, 0.0)
        } else {
            let yaw = r[(1, 0)].atan2(r[(0, 0)]);
            let roll = r[(2, 1)].atan2(r[(2, 2)]);
            (yaw, pitch, roll)
        }
    }
}
