//! The scalar trait that element functions are written against.

use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real scalar: `f64` or a (nested) dual number.
///
/// Only the operations the element library needs are required. The primal value
/// is available through [`Real::value`], which is what branch decisions (for
/// example unwrapping a hinge angle) must use so that every nesting level takes
/// the same branch.
pub trait Real:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + 'static
{
    /// A constant (all derivative parts zero).
    fn cst(v: f64) -> Self;
    /// The primal (undifferentiated) value.
    fn value(&self) -> f64;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Four-quadrant arc tangent of `self / x`.
    fn atan2(self, x: Self) -> Self;
    /// Zero.
    #[inline]
    fn zero() -> Self {
        Self::cst(0.0)
    }
    /// One.
    #[inline]
    fn one() -> Self {
        Self::cst(1.0)
    }
    /// Square.
    #[inline]
    fn sq(self) -> Self {
        self * self
    }
}

impl Real for f64 {
    #[inline]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline]
    fn value(&self) -> f64 {
        *self
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn sin(self) -> Self {
        f64::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        f64::cos(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
}
