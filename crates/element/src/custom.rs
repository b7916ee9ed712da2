//! User-defined elements: a [`DeformationKernel`] of fixed sizes behind an
//! object-safe trait, so that an [`Element`](crate::Element) can hold one of any
//! type. The built-in elements do not go through this: they are dispatched
//! statically by the element's closed kind.

use crate::inertia::MAX_MODES;
use crate::kernels::{
    jacobian, second_directional, third_directional, weighted_hessian, DeformationKernel,
};
use crate::kinetic::ErasedInertia;
use std::marker::PhantomData;
use std::sync::Arc;

/// The local nodal-coordinate count n_x of every built-in element (planar
/// beam, planar truss, planar hinge, planar mass with rotary inertia, spatial
/// beam, superelement with [`MAX_MODES`] modes, spatial truss, spatial hinge,
/// point mass, rigid body, Euler-parameter normalization).
const BUILTIN_COORDS: [usize; 11] = [6, 4, 2, 3, 14, 14 + MAX_MODES, 6, 8, 3, 7, 4];

const fn max_of(v: &[usize]) -> usize {
    let mut m = 0;
    let mut i = 0;
    while i < v.len() {
        if v[i] > m {
            m = v[i];
        }
        i += 1;
    }
    m
}

/// The largest number of local nodal coordinates (and of deformations) of one
/// element: that of the largest built-in element, the superelement with
/// [`MAX_MODES`] mode amplitudes (14 + 24 = 38).
///
/// The layers above (kinematics, dynamics) gather an element's coordinates,
/// velocities and forces into stack buffers of this length. A custom element
/// ([`Element::custom`](crate::Element::custom)) with more coordinates or
/// deformations is refused when it is built, with
/// [`ElementError::TooLarge`](crate::ElementError::TooLarge).
pub const MAX_ELEMENT_COORDS: usize = max_of(&BUILTIN_COORDS);

// every built-in element fits the buffers, and every deformation count too
// (n_ε ≤ n_x for all of them: 3/6, 1/4, 1/2, 6+k/14+k, 1/6, 3/8, 1/4)
const _: () = {
    let mut i = 0;
    while i < BUILTIN_COORDS.len() {
        assert!(BUILTIN_COORDS[i] <= MAX_ELEMENT_COORDS);
        i += 1;
    }
    assert!(6 + MAX_MODES <= MAX_ELEMENT_COORDS);
};

/// A deformation kernel with its sizes erased (slices in, slices out).
pub(crate) trait ErasedKernel: Send + Sync {
    fn n_x(&self) -> usize;
    fn n_eps(&self) -> usize;
    fn type_name(&self) -> &'static str;
    fn deformations(&self, x: &[f64], eps: &mut [f64]);
    /// ε and D,x (row-major n_ε × n_x).
    fn jacobian(&self, x: &[f64], eps: &mut [f64], jac: &mut [f64]);
    fn second(&self, x: &[f64], a: &[f64], b: &[f64], out: &mut [f64]);
    fn third(&self, x: &[f64], a: &[f64], b: &[f64], c: &[f64], out: &mut [f64]);
    /// Σ wᵢ Dᵢ,xx (row-major n_x × n_x).
    fn weighted_hessian(&self, x: &[f64], w: &[f64], out: &mut [f64]);
}

pub(crate) struct Erased<K, const NX: usize, const NE: usize> {
    pub kernel: K,
    pub name: &'static str,
    pub _sizes: PhantomData<([f64; NX], [f64; NE])>,
}

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    std::array::from_fn(|i| v[i])
}

impl<K, const NX: usize, const NE: usize> ErasedKernel for Erased<K, NX, NE>
where
    K: DeformationKernel<NX, NE> + Send + Sync,
{
    fn n_x(&self) -> usize {
        NX
    }
    fn n_eps(&self) -> usize {
        NE
    }
    fn type_name(&self) -> &'static str {
        self.name
    }
    fn deformations(&self, x: &[f64], eps: &mut [f64]) {
        eps[..NE].copy_from_slice(&self.kernel.eval(&arr::<NX>(x)));
    }
    fn jacobian(&self, x: &[f64], eps: &mut [f64], jac: &mut [f64]) {
        let (e, j) = jacobian::<K, NX, NE>(&self.kernel, &arr(x));
        eps[..NE].copy_from_slice(&e);
        for (r, row) in j.iter().enumerate() {
            jac[r * NX..(r + 1) * NX].copy_from_slice(row);
        }
    }
    fn second(&self, x: &[f64], a: &[f64], b: &[f64], out: &mut [f64]) {
        let d = second_directional::<K, NX, NE>(&self.kernel, &arr(x), &arr(a), &arr(b));
        out[..NE].copy_from_slice(&d);
    }
    fn third(&self, x: &[f64], a: &[f64], b: &[f64], c: &[f64], out: &mut [f64]) {
        let d = third_directional::<K, NX, NE>(&self.kernel, &arr(x), &arr(a), &arr(b), &arr(c));
        out[..NE].copy_from_slice(&d);
    }
    fn weighted_hessian(&self, x: &[f64], w: &[f64], out: &mut [f64]) {
        let h = weighted_hessian::<K, NX, NE>(&self.kernel, &arr(x), &arr(w));
        for (r, row) in h.iter().enumerate() {
            out[r * NX..(r + 1) * NX].copy_from_slice(row);
        }
    }
}

/// The inertia of a custom element.
#[derive(Clone)]
pub(crate) enum CustomInertia {
    /// A constant mass matrix (row-major n_x × n_x), T = ½ ẋᵀMẋ.
    Constant(Vec<f64>),
    /// A configuration-dependent mass from a kinetic-energy kernel.
    Energy(Arc<dyn ErasedInertia>),
}

/// A custom element's kernel and its inertia, if any.
#[derive(Clone)]
pub(crate) struct CustomKind {
    pub kernel: Arc<dyn ErasedKernel>,
    pub inertia: Option<CustomInertia>,
    /// The periodic deformations (index, period), e.g. an angle from atan2
    /// (period 2π): continued from the previous deformations
    /// ([`Element::with_periodic_deformation`](crate::Element::with_periodic_deformation)).
    pub periodic: Vec<(usize, f64)>,
}

impl CustomKind {
    /// Moves each periodic deformation of `eps` by the multiple of its
    /// period that puts it closest to its previous value `prev` (the
    /// derivatives are unchanged): a hinge angle stays continuous over many
    /// turns, as the built-in spatial hinge's does.
    pub(crate) fn continue_from(&self, prev: Option<&[f64]>, eps: &mut [f64]) {
        let Some(prev) = prev else {
            return;
        };
        for &(i, period) in &self.periodic {
            if let (Some(e), Some(p)) = (eps.get(i).copied(), prev.get(i)) {
                eps[i] = e + ((p - e) / period).round() * period;
            }
        }
    }
}

impl std::fmt::Debug for CustomKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Custom({}, n_x = {}, n_ε = {}, inertia: {})",
            self.kernel.type_name(),
            self.kernel.n_x(),
            self.kernel.n_eps(),
            match self.inertia {
                None => "none",
                Some(CustomInertia::Constant(_)) => "constant mass matrix",
                Some(CustomInertia::Energy(_)) => "kinetic-energy kernel",
            }
        )
    }
}

impl PartialEq for CustomKind {
    /// The same kernel objects (kernels are not comparable) and the same
    /// constant mass.
    fn eq(&self, o: &Self) -> bool {
        Arc::ptr_eq(&self.kernel, &o.kernel)
            && self.periodic == o.periodic
            && match (&self.inertia, &o.inertia) {
                (None, None) => true,
                (Some(CustomInertia::Constant(a)), Some(CustomInertia::Constant(b))) => a == b,
                (Some(CustomInertia::Energy(a)), Some(CustomInertia::Energy(b))) => {
                    Arc::ptr_eq(a, b)
                }
                _ => false,
            }
    }
}
