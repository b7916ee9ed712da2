//! Forward-mode dual numbers with `N` derivative directions, nestable.

use crate::Real;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A dual number `re + Σ eps[i] εᵢ` with εᵢ εⱼ = 0, over any [`Real`] `T`.
///
/// With `T = f64` it carries a gradient with respect to `N` seeded variables;
/// with `T` itself a dual number it carries second derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<T, const N: usize> {
    /// The value.
    pub re: T,
    /// The derivative parts, one per seeded direction.
    pub eps: [T; N],
}

/// A dual number with one direction over `f64` (a directional derivative).
pub type Dual1 = Dual<f64, 1>;
/// A hyper-dual number: directional second derivatives d²f\[a, b\].
pub type Dual2 = Dual<Dual<f64, 1>, 1>;

impl<T: Real, const N: usize> Dual<T, N> {
    /// A constant with zero derivative parts.
    #[inline]
    pub fn constant(re: T) -> Self {
        Self {
            re,
            eps: [T::zero(); N],
        }
    }
    /// The `i`-th seeded variable: value `re`, derivative part `eᵢ`.
    #[inline]
    pub fn variable(re: T, i: usize) -> Self {
        let mut eps = [T::zero(); N];
        eps[i] = T::one();
        Self { re, eps }
    }
    /// A value with the given derivative parts.
    #[inline]
    pub fn new(re: T, eps: [T; N]) -> Self {
        Self { re, eps }
    }
    #[inline]
    fn chain(self, f: T, df: T) -> Self {
        let mut eps = self.eps;
        for e in eps.iter_mut() {
            *e *= df;
        }
        Self { re: f, eps }
    }
}

impl<const N: usize> Dual<f64, N> {
    /// Seeds a vector of `f64` as the `N` variables of a gradient computation.
    pub fn seed(x: &[f64; N]) -> [Self; N] {
        std::array::from_fn(|i| Self::variable(x[i], i))
    }
}

impl Dual<f64, 1> {
    /// `x + ε·dx`: a point moving in direction `dx`.
    pub fn along<const M: usize>(x: &[f64; M], dx: &[f64; M]) -> [Self; M] {
        std::array::from_fn(|i| Self::new(x[i], [dx[i]]))
    }
}

impl Dual<Dual<f64, 1>, 1> {
    /// `x + ε₁ a + ε₂ b` (ε₁ε₂ kept): the ε₁ε₂ part of f gives f,xx\[a, b\].
    pub fn along2<const M: usize>(x: &[f64; M], a: &[f64; M], b: &[f64; M]) -> [Self; M] {
        std::array::from_fn(|i| Self::new(Dual::new(x[i], [b[i]]), [Dual::new(a[i], [0.0])]))
    }
    /// The mixed second-derivative part (coefficient of ε₁ε₂).
    #[inline]
    pub fn d2(&self) -> f64 {
        self.eps[0].eps[0]
    }
    /// The first-derivative part along the first direction.
    #[inline]
    pub fn d1(&self) -> f64 {
        self.eps[0].re
    }
}

impl<const N: usize> Dual<Dual<f64, N>, N> {
    /// Seeds `x` for a full Hessian computation.
    pub fn seed2(x: &[f64; N]) -> [Self; N] {
        std::array::from_fn(|i| Self {
            re: Dual::variable(x[i], i),
            eps: std::array::from_fn(|j| {
                if i == j {
                    Dual::constant(1.0)
                } else {
                    Dual::constant(0.0)
                }
            }),
        })
    }
    /// The Hessian entry ∂²f/∂xᵢ∂xⱼ.
    #[inline]
    pub fn hess(&self, i: usize, j: usize) -> f64 {
        self.eps[i].eps[j]
    }
    /// The gradient entry ∂f/∂xᵢ.
    #[inline]
    pub fn grad(&self, i: usize) -> f64 {
        self.eps[i].re
    }
}

impl<T: Real, const N: usize> Add for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self.re += o.re;
        for i in 0..N {
            self.eps[i] += o.eps[i];
        }
        self
    }
}
impl<T: Real, const N: usize> Sub for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self.re -= o.re;
        for i in 0..N {
            self.eps[i] -= o.eps[i];
        }
        self
    }
}
impl<T: Real, const N: usize> Mul for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut eps = [T::zero(); N];
        for (i, e) in eps.iter_mut().enumerate() {
            *e = self.eps[i] * o.re + self.re * o.eps[i];
        }
        Self {
            re: self.re * o.re,
            eps,
        }
    }
}
impl<T: Real, const N: usize> Div for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        // the value divided, not multiplied by the reciprocal: the value
        // part is then exactly the f64 evaluation's (the position solve
        // mixes plain and dual evaluations of the same deformations)
        let inv = T::one() / o.re;
        let re = self.re / o.re;
        let mut eps = [T::zero(); N];
        for (i, e) in eps.iter_mut().enumerate() {
            *e = (self.eps[i] - re * o.eps[i]) * inv;
        }
        Self { re, eps }
    }
}
impl<T: Real, const N: usize> Neg for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn neg(mut self) -> Self {
        self.re = -self.re;
        for e in self.eps.iter_mut() {
            *e = -*e;
        }
        self
    }
}
impl<T: Real, const N: usize> AddAssign for Dual<T, N> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<T: Real, const N: usize> SubAssign for Dual<T, N> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<T: Real, const N: usize> MulAssign for Dual<T, N> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}
impl<T: Real, const N: usize> Add<f64> for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: f64) -> Self {
        self.re = self.re + o;
        self
    }
}
impl<T: Real, const N: usize> Sub<f64> for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: f64) -> Self {
        self.re = self.re - o;
        self
    }
}
impl<T: Real, const N: usize> Mul<f64> for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn mul(mut self, o: f64) -> Self {
        self.re = self.re * o;
        for e in self.eps.iter_mut() {
            *e = *e * o;
        }
        self
    }
}
impl<T: Real, const N: usize> Div<f64> for Dual<T, N> {
    type Output = Self;
    #[inline]
    fn div(mut self, o: f64) -> Self {
        // the value exactly as an f64 division (see `Div for Dual`)
        let inv = 1.0 / o;
        self.re = self.re / o;
        for e in self.eps.iter_mut() {
            *e = *e * inv;
        }
        self
    }
}

impl<T: Real, const N: usize> Real for Dual<T, N> {
    #[inline]
    fn cst(v: f64) -> Self {
        Self::constant(T::cst(v))
    }
    #[inline]
    fn value(&self) -> f64 {
        self.re.value()
    }
    #[inline]
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, T::one() / (s * 2.0))
    }
    #[inline]
    fn sin(self) -> Self {
        self.chain(self.re.sin(), self.re.cos())
    }
    #[inline]
    fn cos(self) -> Self {
        self.chain(self.re.cos(), -self.re.sin())
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        // d atan2(y, x) = (x dy − y dx) / (x² + y²)
        let r2 = self.re * self.re + x.re * x.re;
        let inv = T::one() / r2;
        let mut eps = [T::zero(); N];
        for (i, e) in eps.iter_mut().enumerate() {
            *e = (x.re * self.eps[i] - self.re * x.eps[i]) * inv;
        }
        Self {
            re: self.re.atan2(x.re),
            eps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f<T: Real>(x: T, y: T) -> T {
        (x * y).sin() + (x * x + y * y).sqrt() / (y + 2.0) + y.atan2(x) * x.cos()
    }

    #[test]
    fn gradient_matches_central_differences() {
        let (x0, y0) = (0.7, -0.3);
        let [x, y] = Dual::<f64, 2>::seed(&[x0, y0]);
        let r = f(x, y);
        let h = 1e-6;
        let gx = (f(x0 + h, y0) - f(x0 - h, y0)) / (2.0 * h);
        let gy = (f(x0, y0 + h) - f(x0, y0 - h)) / (2.0 * h);
        assert!((r.eps[0] - gx).abs() < 1e-8, "{} {}", r.eps[0], gx);
        assert!((r.eps[1] - gy).abs() < 1e-8);
        assert_eq!(r.re, f(x0, y0));
    }

    #[test]
    fn hessian_and_directional_second_derivative() {
        let p = [0.7, -0.3];
        let [x, y] = Dual::<Dual<f64, 2>, 2>::seed2(&p);
        let r = f(x, y);
        let h = 1e-4;
        let fd = |i: usize, j: usize| {
            let e = |k: usize, s: f64| {
                let mut q = p;
                q[k] += s;
                q
            };
            let g = |q: [f64; 2]| f(q[0], q[1]);
            let mut pp = e(i, h);
            pp[j] += h;
            let mut pm = e(i, h);
            pm[j] -= h;
            let mut mp = e(i, -h);
            mp[j] += h;
            let mut mm = e(i, -h);
            mm[j] -= h;
            (g(pp) - g(pm) - g(mp) + g(mm)) / (4.0 * h * h)
        };
        for i in 0..2 {
            for j in 0..2 {
                assert!((r.hess(i, j) - fd(i, j)).abs() < 1e-6);
            }
        }
        // directional: a = (1, 2), b = (−1, 0.5) gives aᵀ H b
        let a = [1.0, 2.0];
        let b = [-1.0, 0.5];
        let [x, y] = Dual2::along2(&p, &a, &b);
        let d = f(x, y);
        let expect: f64 = (0..2)
            .map(|i| (0..2).map(|j| a[i] * r.hess(i, j) * b[j]).sum::<f64>())
            .sum();
        assert!((d.d2() - expect).abs() < 1e-12);
        assert!((d.d1() - (a[0] * r.grad(0) + a[1] * r.grad(1))).abs() < 1e-12);
    }
}
