//! Euler-parameter kinematics written once over any [`Real`] scalar, so that the
//! element library can differentiate them exactly with dual numbers.
//!
//! Conventions (thesis §2.3.1): λ = (λ0, λ1, λ2, λ3) with λ0 the scalar part.

use flexmb_dual::{Mat3, Real, Vec3};

/// Λ(λ) of thesis Eq. (2.14): ω = 2 Λ λ̇ is the angular velocity in the inertial frame.
///
/// Linear in λ; Λ λ = 0 and Λ Λᵀ = |λ|² I for any λ.
#[inline]
pub fn lambda_mat<T: Real>(l: &[T; 4]) -> [[T; 4]; 3] {
    let [l0, l1, l2, l3] = *l;
    [[-l1, l0, -l3, l2], [-l2, l3, l0, -l1], [-l3, -l2, l1, l0]]
}

/// Λ̄(λ) = RᵀΛ of thesis Eq. (2.33) (on the unit sphere): ω̄ = 2 Λ̄ λ̇ is the
/// angular velocity expressed in the rotated (body) frame.
///
/// Implemented as its linear form, which equals RᵀΛ for unit λ.
#[inline]
pub fn lambda_bar_mat<T: Real>(l: &[T; 4]) -> [[T; 4]; 3] {
    let [l0, l1, l2, l3] = *l;
    [[-l1, l0, l3, -l2], [-l2, -l3, l0, l1], [-l3, l2, -l1, l0]]
}

/// R(λ) = Λ Λ̄ᵀ, the homogeneous quadratic form of the rotation matrix
/// (R = |λ|² × a rotation for any λ ≠ 0; thesis Eq. (2.9), derivatives (C.3)).
#[inline]
pub fn rotation<T: Real>(l: &[T; 4]) -> Mat3<T> {
    let [l0, l1, l2, l3] = *l;
    let (a, b, c, d) = (l0 * l0, l1 * l1, l2 * l2, l3 * l3);
    let two = |x: T| x * 2.0;
    Mat3([
        [
            a + b - c - d,
            two(l1 * l2 - l0 * l3),
            two(l1 * l3 + l0 * l2),
        ],
        [
            two(l1 * l2 + l0 * l3),
            a - b + c - d,
            two(l2 * l3 - l0 * l1),
        ],
        [
            two(l1 * l3 - l0 * l2),
            two(l2 * l3 + l0 * l1),
            a - b - c + d,
        ],
    ])
}

/// `R(λ) R0 e_j`: column `j` of the node triad of thesis Eq. (2.9), without
/// forming the full product when only some columns are needed.
#[inline]
pub fn triad_axis<T: Real>(r: &Mat3<T>, r0: &[[f64; 3]; 3], j: usize) -> Vec3<T> {
    let c = Vec3::<T>::cst([r0[0][j], r0[1][j], r0[2][j]]);
    r.mul_vec(&c)
}

/// 2 Λ λ̇: the angular velocity in the inertial frame.
#[inline]
pub fn omega<T: Real>(l: &[T; 4], ld: &[T; 4]) -> Vec3<T> {
    mat34_vec(&lambda_mat(l), ld).scale(T::cst(2.0))
}

/// 2 Λ̄ λ̇: the angular velocity in the body frame.
#[inline]
pub fn omega_body<T: Real>(l: &[T; 4], ld: &[T; 4]) -> Vec3<T> {
    mat34_vec(&lambda_bar_mat(l), ld).scale(T::cst(2.0))
}

/// A 3×4 matrix times a 4-vector.
#[inline]
pub fn mat34_vec<T: Real>(m: &[[T; 4]; 3], v: &[T; 4]) -> Vec3<T> {
    let r = |i: usize| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] + m[i][3] * v[3];
    Vec3([r(0), r(1), r(2)])
}

/// The transposed product `mᵀ w` of a 3×4 matrix with a 3-vector.
#[inline]
pub fn mat34_tr_vec<T: Real>(m: &[[T; 4]; 3], w: &Vec3<T>) -> [T; 4] {
    std::array::from_fn(|j| m[0][j] * w.0[0] + m[1][j] * w.0[1] + m[2][j] * w.0[2])
}

/// The sign s ∈ {+1, −1} that puts λq in the hemisphere of λp (λp·(s λq) ≥ 0).
///
/// λ and −λ describe the same rotation; the average frame must not depend on
/// which one a node carries. The sign is decided on primal values, so it is a
/// constant for differentiation.
#[inline]
pub fn hemisphere_sign<T: Real>(lp: &[T; 4], lq: &[T; 4]) -> f64 {
    let d: f64 = (0..4).map(|i| lp[i].value() * lq[i].value()).sum();
    if d < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// The average orientation λr = (λp + λq)/‖λp + λq‖ of thesis Eq. (2.29), with λq
/// moved to λp's hemisphere first (see [`hemisphere_sign`]).
#[inline]
pub fn average<T: Real>(lp: &[T; 4], lq: &[T; 4]) -> [T; 4] {
    let s = hemisphere_sign(lp, lq);
    let sum: [T; 4] = std::array::from_fn(|i| lp[i] + lq[i] * s);
    let n = (sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2] + sum[3] * sum[3]).sqrt();
    let inv = T::one() / n;
    sum.map(|v| v * inv)
}

/// Quaternion product a ⊗ b, so that R(a ⊗ b) = R(a) R(b).
#[inline]
pub fn compose<T: Real>(a: &[T; 4], b: &[T; 4]) -> [T; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}
