//! A minimal generic 3-vector and 3×3 matrix over [`Real`].

use crate::Real;
use std::ops::{Add, Mul, Neg, Sub};

/// A 3-vector over a [`Real`] scalar.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3<T>(pub [T; 3]);

/// A 3×3 matrix over a [`Real`] scalar, stored by rows: `m.0[i][j]` is row i, column j.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat3<T>(pub [[T; 3]; 3]);

impl<T: Real> Vec3<T> {
    /// From components.
    #[inline]
    pub fn new(x: T, y: T, z: T) -> Self {
        Self([x, y, z])
    }
    /// From constant `f64` components.
    #[inline]
    pub fn cst(v: [f64; 3]) -> Self {
        Self([T::cst(v[0]), T::cst(v[1]), T::cst(v[2])])
    }
    /// The zero vector.
    #[inline]
    pub fn zero() -> Self {
        Self([T::zero(); 3])
    }
    /// Dot product.
    #[inline]
    pub fn dot(&self, o: &Self) -> T {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    /// Cross product.
    #[inline]
    pub fn cross(&self, o: &Self) -> Self {
        let a = &self.0;
        let b = &o.0;
        Self([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ])
    }
    /// Euclidean norm.
    #[inline]
    pub fn norm(&self) -> T {
        self.dot(self).sqrt()
    }
    /// Multiplication by a scalar.
    #[inline]
    pub fn scale(&self, s: T) -> Self {
        Self([self.0[0] * s, self.0[1] * s, self.0[2] * s])
    }
    /// Primal values.
    #[inline]
    pub fn value(&self) -> [f64; 3] {
        [self.0[0].value(), self.0[1].value(), self.0[2].value()]
    }
}

impl<T: Real> Add for Vec3<T> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}
impl<T: Real> Sub for Vec3<T> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}
impl<T: Real> Neg for Vec3<T> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self([-self.0[0], -self.0[1], -self.0[2]])
    }
}
impl<T: Real> Mul<T> for Vec3<T> {
    type Output = Self;
    #[inline]
    fn mul(self, s: T) -> Self {
        self.scale(s)
    }
}

impl<T: Real> Mat3<T> {
    /// The identity.
    pub fn identity() -> Self {
        let (o, z) = (T::one(), T::zero());
        Self([[o, z, z], [z, o, z], [z, z, o]])
    }
    /// From constant `f64` rows.
    pub fn cst(m: [[f64; 3]; 3]) -> Self {
        Self(m.map(|r| r.map(T::cst)))
    }
    /// Column `j`.
    #[inline]
    pub fn col(&self, j: usize) -> Vec3<T> {
        Vec3([self.0[0][j], self.0[1][j], self.0[2][j]])
    }
    /// Row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> Vec3<T> {
        Vec3(self.0[i])
    }
    /// Transpose.
    #[inline]
    pub fn transpose(&self) -> Self {
        let m = &self.0;
        Self([
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ])
    }
    /// Matrix–vector product.
    #[inline]
    pub fn mul_vec(&self, v: &Vec3<T>) -> Vec3<T> {
        Vec3([self.row(0).dot(v), self.row(1).dot(v), self.row(2).dot(v)])
    }
    /// Transposed matrix–vector product `Mᵀ v`.
    #[inline]
    pub fn tr_mul_vec(&self, v: &Vec3<T>) -> Vec3<T> {
        Vec3([self.col(0).dot(v), self.col(1).dot(v), self.col(2).dot(v)])
    }
    /// Matrix product.
    pub fn mul_mat(&self, o: &Self) -> Self {
        let mut r = [[T::zero(); 3]; 3];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.0[i][0] * o.0[0][j] + self.0[i][1] * o.0[1][j] + self.0[i][2] * o.0[2][j];
            }
        }
        Self(r)
    }
    /// Primal values.
    pub fn value(&self) -> [[f64; 3]; 3] {
        self.0.map(|r| r.map(|v| v.value()))
    }
}
