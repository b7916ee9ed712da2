//! Configuration-dependent inertia of custom elements, written once as a
//! kinetic energy T(x, ẋ) over a generic scalar ([`KineticEnergyKernel`]).
//!
//! Everything the layers above need follows from T by dual numbers, as for
//! the deformations of a [`DeformationKernel`](crate::DeformationKernel):
//! * the mass matrix M(x) = ∂²T/∂ẋ² (thesis (3.31) for the built-in
//!   co-rotational elements);
//! * the inertia force of Lagrange's equations,
//!   F = d/dt(∂T/∂ẋ) − ∂T/∂x = M ẍ + h(x, ẋ) (thesis (2.40a), (3.34)),
//!   with the time derivative taken as one directional derivative along
//!   (ẋ, ẍ);
//! * its exact derivatives ∂F/∂x and ∂F/∂ẋ, which the linearization
//!   (Appendix E: the N and C matrices) needs, one direction at a time;
//! * the gravity force f = M(x) ẋ_g with ẋ_g = g on every position slot, the
//!   rule of the built-in elements (exact for rigid motion), and ∂f/∂x.
//!
//! Derivatives are taken one seeded direction at a time
//! (`Dual<f64, 1>`), so that the nested numbers stay small on the stack for
//! the largest element ([`MAX_ELEMENT_COORDS`](crate::MAX_ELEMENT_COORDS)
//! coordinates); a custom element's inertia costs O(n_x²) evaluations of T
//! per derivative matrix.

use flexmb_dual::{Dual, Real};
use std::marker::PhantomData;

/// The kinetic energy of a custom element, written once over a generic scalar.
///
/// `kinetic_energy` must be T = ½ ẋᵀ M(x) ẋ, a quadratic form in ẋ with a
/// symmetric positive semi-definite M(x): M is taken as ∂²T/∂ẋ² and the
/// gravity force as M ẋ_g. x and ẋ are in slot order, as for
/// [`DeformationKernel::eval`](crate::DeformationKernel::eval), and the same
/// rules apply: only the operations of [`Real`], constants lifted with
/// [`Real::cst`].
///
/// ```
/// use flexmb_dual::Real;
/// use flexmb_element::KineticEnergyKernel;
/// /// A point mass m at the offset c from a planar node (x, y, φ), carried
/// /// rigidly by the node's frame.
/// struct Bob { m: f64, c: [f64; 2] }
/// impl KineticEnergyKernel<3> for Bob {
///     fn kinetic_energy<T: Real>(&self, x: &[T; 3], v: &[T; 3]) -> T {
///         let (s, c) = (x[2].sin(), x[2].cos());
///         // ṙ = ṗ + φ̇ R'(φ) c
///         let vx = v[0] - v[2] * (s * self.c[0] + c * self.c[1]);
///         let vy = v[1] + v[2] * (c * self.c[0] - s * self.c[1]);
///         (vx * vx + vy * vy) * (0.5 * self.m)
///     }
/// }
/// let t = Bob { m: 2.0, c: [1.0, 0.0] }.kinetic_energy(&[0.0, 0.0, 0.0], &[0.0, 0.0, 3.0]);
/// assert!((t - 9.0).abs() < 1e-15); // ½ · 2 · (3 · 1)²
/// ```
pub trait KineticEnergyKernel<const NX: usize> {
    /// T(x, ẋ) over the scalar `T`.
    fn kinetic_energy<T: Real>(&self, x: &[T; NX], xd: &[T; NX]) -> T;
}

/// ∂T/∂ẋ at (x, ẋ) over any scalar (one pass with `NX` seeds).
fn momentum<K: KineticEnergyKernel<NX>, T: Real, const NX: usize>(
    k: &K,
    x: &[T; NX],
    xd: &[T; NX],
) -> [T; NX] {
    let xs: [Dual<T, NX>; NX] = std::array::from_fn(|i| Dual::constant(x[i]));
    let vs: [Dual<T, NX>; NX] = std::array::from_fn(|i| Dual::variable(xd[i], i));
    k.kinetic_energy(&xs, &vs).eps
}

/// ∂T/∂x at (x, ẋ) over any scalar.
fn energy_gradient_x<K: KineticEnergyKernel<NX>, T: Real, const NX: usize>(
    k: &K,
    x: &[T; NX],
    xd: &[T; NX],
) -> [T; NX] {
    let xs: [Dual<T, NX>; NX] = std::array::from_fn(|i| Dual::variable(x[i], i));
    let vs: [Dual<T, NX>; NX] = std::array::from_fn(|i| Dual::constant(xd[i]));
    k.kinetic_energy(&xs, &vs).eps
}

/// The inertia force F = d/dt(∂T/∂ẋ) − ∂T/∂x over any scalar: the time
/// derivative of the momentum is its directional derivative along (ẋ, ẍ).
fn force<K: KineticEnergyKernel<NX>, T: Real, const NX: usize>(
    k: &K,
    x: &[T; NX],
    xd: &[T; NX],
    xdd: &[T; NX],
) -> [T; NX] {
    let xs: [Dual<T, 1>; NX] = std::array::from_fn(|i| Dual::new(x[i], [xd[i]]));
    let vs: [Dual<T, 1>; NX] = std::array::from_fn(|i| Dual::new(xd[i], [xdd[i]]));
    let p = momentum(k, &xs, &vs);
    let q = energy_gradient_x(k, x, xd);
    std::array::from_fn(|i| p[i].eps[0] - q[i])
}

/// M(x) ẏ = ∂²T/∂ẋ² ẏ over any scalar: the momentum at velocity ẏ (T is
/// quadratic in ẋ, so the momentum is linear in it).
fn mass_times<K: KineticEnergyKernel<NX>, T: Real, const NX: usize>(
    k: &K,
    x: &[T; NX],
    y: &[f64; NX],
) -> [T; NX] {
    momentum(k, x, &y.map(T::cst))
}

/// A kinetic-energy kernel with its size erased (slices in, slices out).
pub(crate) trait ErasedInertia: Send + Sync {
    /// M(x), row-major n_x × n_x.
    fn mass(&self, x: &[f64], out: &mut [f64]);
    /// M ẍ + h(x, ẋ).
    fn force(&self, x: &[f64], xd: &[f64], xdd: &[f64], out: &mut [f64]);
    /// ∂F/∂x and ∂F/∂ẋ, row-major n_x × n_x each.
    fn force_derivatives(
        &self,
        x: &[f64],
        xd: &[f64],
        xdd: &[f64],
        dfdx: &mut [f64],
        dfdxd: &mut [f64],
    );
    /// T(x, ẋ).
    fn kinetic_energy(&self, x: &[f64], xd: &[f64]) -> f64;
    /// f = M(x) ẋ_g.
    fn gravity(&self, x: &[f64], xg: &[f64], out: &mut [f64]);
    /// ∂f/∂x for f = M(x) ẋ_g, row-major n_x × n_x.
    fn gravity_derivative(&self, x: &[f64], xg: &[f64], out: &mut [f64]);
}

pub(crate) struct ErasedEnergy<K, const NX: usize> {
    pub kernel: K,
    pub _size: PhantomData<[f64; NX]>,
}

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    std::array::from_fn(|i| v[i])
}

/// x + ε eⱼ (one seeded direction) and the other arguments as constants.
fn seeded<const NX: usize>(x: &[f64; NX], j: usize) -> [Dual<f64, 1>; NX] {
    std::array::from_fn(|i| Dual::new(x[i], [if i == j { 1.0 } else { 0.0 }]))
}

fn constants<const NX: usize>(x: &[f64; NX]) -> [Dual<f64, 1>; NX] {
    x.map(Dual::constant)
}

impl<K, const NX: usize> ErasedInertia for ErasedEnergy<K, NX>
where
    K: KineticEnergyKernel<NX> + Send + Sync,
{
    fn mass(&self, x: &[f64], out: &mut [f64]) {
        let x = arr::<NX>(x);
        for j in 0..NX {
            let mut e = [0.0; NX];
            e[j] = 1.0;
            let col = mass_times(&self.kernel, &x, &e);
            for (i, v) in col.iter().enumerate() {
                out[i * NX + j] = *v;
            }
        }
    }
    fn force(&self, x: &[f64], xd: &[f64], xdd: &[f64], out: &mut [f64]) {
        let f = force(&self.kernel, &arr::<NX>(x), &arr(xd), &arr(xdd));
        out[..NX].copy_from_slice(&f);
    }
    fn force_derivatives(
        &self,
        x: &[f64],
        xd: &[f64],
        xdd: &[f64],
        dfdx: &mut [f64],
        dfdxd: &mut [f64],
    ) {
        let (x, xd, xdd) = (arr::<NX>(x), arr::<NX>(xd), arr::<NX>(xdd));
        for j in 0..NX {
            let by_x = force(
                &self.kernel,
                &seeded(&x, j),
                &constants(&xd),
                &constants(&xdd),
            );
            let by_xd = force(
                &self.kernel,
                &constants(&x),
                &seeded(&xd, j),
                &constants(&xdd),
            );
            for i in 0..NX {
                dfdx[i * NX + j] = by_x[i].eps[0];
                dfdxd[i * NX + j] = by_xd[i].eps[0];
            }
        }
    }
    fn kinetic_energy(&self, x: &[f64], xd: &[f64]) -> f64 {
        self.kernel.kinetic_energy(&arr::<NX>(x), &arr::<NX>(xd))
    }
    fn gravity(&self, x: &[f64], xg: &[f64], out: &mut [f64]) {
        let f = mass_times(&self.kernel, &arr::<NX>(x), &arr::<NX>(xg));
        out[..NX].copy_from_slice(&f);
    }
    fn gravity_derivative(&self, x: &[f64], xg: &[f64], out: &mut [f64]) {
        let (x, xg) = (arr::<NX>(x), arr::<NX>(xg));
        for j in 0..NX {
            let col = mass_times(&self.kernel, &seeded(&x, j), &xg);
            for (i, v) in col.iter().enumerate() {
                out[i * NX + j] = v.eps[0];
            }
        }
    }
}
