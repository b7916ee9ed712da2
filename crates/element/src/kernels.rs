//! Deformation functions ε = D(x) of every element, written once over a
//! [`Real`] scalar (thesis (5.3), (5.5), (6.2)), and the drivers that evaluate
//! them with dual numbers to get D,x, D,xx\[a, b\] and Σ wᵢ Dᵢ,xx exactly.

use flexmb_dual::{Dual, Dual2, Real, Vec3};
use flexmb_rotation::generic::{rotation, triad_axis};

/// The deformation functions ε = D(x) of an element with `NX` local nodal
/// coordinates and `NE` deformations, written once over a generic scalar.
///
/// This is the interface every element of the crate implements and the one a
/// user implements to add an element ([`Element::custom`](crate::Element::custom);
/// see `docs/elements.md`, "Writing your own element"). `eval` is called with
/// `T = f64` for the deformations themselves (thesis (2.15), (5.2)), and with
/// the dual numbers of [`flexmb_dual`] to obtain, exactly and without any
/// hand-written derivative,
/// * the first-order geometric transfer function D,x (thesis (5.8a), (6.5)):
///   [`Dual<f64, NX>`](flexmb_dual::Dual) seeded with the identity,
/// * the convective terms D,xx\[a, b\] (thesis (5.8b)) and the third
///   directional derivative D,xxx\[a, b, c\] (thesis (E.5f)): nested
///   one-direction duals,
/// * the weighted Hessian Σᵢ wᵢ Dᵢ,xx of the geometric stiffness (thesis
///   (E.5), σᵀD,xx): `Dual<Dual<f64, NX>, NX>`.
///
/// Rules for `eval`:
/// * Only use the operations of [`Real`] (`+ − × ÷`, with `f64` on the
///   right, `sq`, `sqrt`, `sin`, `cos`, `atan2`) on values derived from `x`;
///   lift constants with [`Real::cst`]. Branching on [`Real::value`] is
///   allowed where the function is smooth across the branch.
/// * x is in slot order (the element's [`Slot`](crate::Slot)s, e.g.
///   (x_p, y_p, x_q, y_q) for two [`Slot::Position2`](crate::Slot)s).
/// * ε must be invariant under rigid motion of the element (thesis §2.2:
///   a rigid translation and rotation of all its nodes leaves every εᵢ
///   unchanged) and zero in the reference configuration for an unstressed
///   element; the kinematics relies on the first, the statics on the second.
///
/// ```
/// use flexmb_dual::Real;
/// use flexmb_element::DeformationKernel;
/// /// A planar rod: ε = l − l0 on x = (x_p, y_p, x_q, y_q).
/// struct Rod { l0: f64 }
/// impl DeformationKernel<4, 1> for Rod {
///     fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
///         let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
///         [(dx * dx + dy * dy).sqrt() - self.l0]
///     }
/// }
/// assert_eq!(Rod { l0: 1.0 }.eval(&[0.0, 0.0, 2.0, 0.0]), [1.0]);
/// ```
pub trait DeformationKernel<const NX: usize, const NE: usize> {
    /// ε = D(x) over the scalar `T`.
    fn eval<T: Real>(&self, x: &[T; NX]) -> [T; NE];
}

/// ε and D,x (row-major `NE × NX`) by one forward pass with `NX` seeds.
pub(crate) fn jacobian<K: DeformationKernel<NX, NE>, const NX: usize, const NE: usize>(
    k: &K,
    x: &[f64; NX],
) -> ([f64; NE], [[f64; NX]; NE]) {
    let xd = Dual::<f64, NX>::seed(x);
    let e = k.eval(&xd);
    (e.map(|v| v.re), e.map(|v| v.eps))
}

/// The directional second derivative D,xx\[a, b\] (and D,x a as by-product).
pub(crate) fn second_directional<K: DeformationKernel<NX, NE>, const NX: usize, const NE: usize>(
    k: &K,
    x: &[f64; NX],
    a: &[f64; NX],
    b: &[f64; NX],
) -> [f64; NE] {
    let xd = Dual2::along2(x, a, b);
    k.eval(&xd).map(|v| v.d2())
}

/// The directional third derivative D,xxx\[a, b, c\] (for the linearization of
/// convective terms, (E.5f)).
pub(crate) fn third_directional<K: DeformationKernel<NX, NE>, const NX: usize, const NE: usize>(
    k: &K,
    x: &[f64; NX],
    a: &[f64; NX],
    b: &[f64; NX],
    c: &[f64; NX],
) -> [f64; NE] {
    type D3 = Dual<Dual<Dual<f64, 1>, 1>, 1>;
    let xd: [D3; NX] = std::array::from_fn(|i| {
        // x + ε1 a + ε2 b + ε3 c
        let inner = |v0: f64, v1: f64| Dual::new(v0, [v1]);
        let mid = |r: Dual<f64, 1>, e: Dual<f64, 1>| Dual::new(r, [e]);
        D3::new(
            mid(inner(x[i], c[i]), inner(b[i], 0.0)),
            [mid(inner(a[i], 0.0), inner(0.0, 0.0))],
        )
    });
    k.eval(&xd).map(|v| v.eps[0].eps[0].eps[0])
}

/// The weighted Hessian Σᵢ wᵢ Dᵢ,xx (`NX × NX`).
pub(crate) fn weighted_hessian<K: DeformationKernel<NX, NE>, const NX: usize, const NE: usize>(
    k: &K,
    x: &[f64; NX],
    w: &[f64; NE],
) -> [[f64; NX]; NX] {
    let xd = Dual::<Dual<f64, NX>, NX>::seed2(x);
    let e = k.eval(&xd);
    let mut s = Dual::<Dual<f64, NX>, NX>::constant(Dual::constant(0.0));
    for i in 0..NE {
        if w[i] != 0.0 {
            s += e[i] * w[i];
        }
    }
    std::array::from_fn(|i| std::array::from_fn(|j| s.hess(i, j)))
}

#[inline]
pub(crate) fn vec3<T: Real>(x: &[T], i: usize) -> Vec3<T> {
    Vec3([x[i], x[i + 1], x[i + 2]])
}

#[inline]
pub(crate) fn quat<T: Real>(x: &[T], i: usize) -> [T; 4] {
    [x[i], x[i + 1], x[i + 2], x[i + 3]]
}

/// The six deformations of the spatial two-node beam / superelement, thesis
/// (6.2b) = (2.15b) = (3.14b), on x = (rp, λp, rq, λq):
/// ε1 = l − l0 (+ bowing), ε2 = l0 (ep_z·eq_y − ep_y·eq_z)/2, ε3 = −l0 el·ep_z,
/// ε4 = l0 el·eq_z, ε5 = l0 el·ep_y, ε6 = −l0 el·eq_y.
///
/// With `bowing`, ε1 gains the second-order shortening of the axis due to
/// bending, (2ε3² + ε3ε4 + 2ε4² + 2ε5² + ε5ε6 + 2ε6²)/(30 l0): the spatial
/// counterpart of thesis (5.3a) (Jonker 1989, CMAME 76), with the cross-term sign
/// fixed by these ε definitions (an arc, constant curvature, has ε3 = ε4 and
/// ε5 = ε6 and shortens by l0θ²/6 for end slopes ±θ).
pub(crate) struct TwoNodeSpatial {
    pub l0: f64,
    pub r0: [[f64; 3]; 3],
    pub bowing: bool,
}

impl DeformationKernel<14, 6> for TwoNodeSpatial {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 14]) -> [T; 6] {
        let rp = vec3(x, 0);
        let rq = vec3(x, 7);
        let mp = rotation(&quat(x, 3));
        let mq = rotation(&quat(x, 10));
        let (py, pz) = (triad_axis(&mp, &self.r0, 1), triad_axis(&mp, &self.r0, 2));
        let (qy, qz) = (triad_axis(&mq, &self.r0, 1), triad_axis(&mq, &self.r0, 2));
        let d = rq - rp;
        let l = d.norm();
        let l0 = self.l0;
        let s = T::cst(l0) / l; // l0 el = s d
        let e3 = -(d.dot(&pz) * s);
        let e4 = d.dot(&qz) * s;
        let e5 = d.dot(&py) * s;
        let e6 = -(d.dot(&qy) * s);
        let e2 = (pz.dot(&qy) - py.dot(&qz)) * (0.5 * l0);
        let mut e1 = l - l0;
        if self.bowing {
            let b = (e3 * e3 + e4 * e4 + e5 * e5 + e6 * e6) * 2.0 + e3 * e4 + e5 * e6;
            e1 += b * (1.0 / (30.0 * l0));
        }
        [e1, e2, e3, e4, e5, e6]
    }
}

impl TwoNodeSpatial {
    /// The cosines of the angles between the chord rq − rp and the local x axes
    /// Rp R0 e_x, Rq R0 e_x of the two node frames (primal values only). The
    /// bending deformations (6.2b) are l0 × the sines of such angles, hence
    /// periodic in them: a chord reversed against both frames gives ε = 0.
    pub fn chord_cosines(&self, x: &[f64]) -> [f64; 2] {
        let d = vec3(x, 7) - vec3(x, 0);
        let along = |i: usize| {
            let e = triad_axis(&rotation(&quat(x, i)), &self.r0, 0);
            d.dot(&e) / (d.norm() * e.norm())
        };
        [along(3), along(10)]
    }
}

/// The planar beam of thesis (5.3) on x = (xp, yp, φp, xq, yq, φq):
/// ε1 = l − l0 + (2ε2² + ε2ε3 + 2ε3²)/(30 l0) (the shortening term optional),
/// ε2 = (l0/l)(Δx sin(φp+β0) − Δy cos(φp+β0)), ε3 = −(l0/l)(Δx sin(φq+β0) − Δy cos(φq+β0)).
pub(crate) struct PlanarBeamKernel {
    pub l0: f64,
    pub beta0: f64,
    pub shortening: bool,
}

impl DeformationKernel<6, 3> for PlanarBeamKernel {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 6]) -> [T; 3] {
        let dx = x[3] - x[0];
        let dy = x[4] - x[1];
        let l = (dx * dx + dy * dy).sqrt();
        let s = T::cst(self.l0) / l;
        let ap = x[2] + self.beta0;
        let aq = x[5] + self.beta0;
        let e2 = (dx * ap.sin() - dy * ap.cos()) * s;
        let e3 = -((dx * aq.sin() - dy * aq.cos()) * s);
        let mut e1 = l - self.l0;
        if self.shortening {
            e1 += ((e2 * e2 + e3 * e3) * 2.0 + e2 * e3) * (1.0 / (30.0 * self.l0));
        }
        [e1, e2, e3]
    }
}

impl PlanarBeamKernel {
    /// The cosines of the angles between the chord and the local x axes
    /// (cos(φ + β0), sin(φ + β0)) of the two node frames: (5.3b,c) are
    /// ε2 = l0 sin(φp + β0 − γ), ε3 = −l0 sin(φq + β0 − γ) with γ the chord's
    /// angle, periodic in the angle between chord and frame.
    pub fn chord_cosines(&self, x: &[f64]) -> [f64; 2] {
        let (dx, dy) = (x[3] - x[0], x[4] - x[1]);
        let l = (dx * dx + dy * dy).sqrt();
        let along = |phi: f64| {
            let a = phi + self.beta0;
            (dx * a.cos() + dy * a.sin()) / l
        };
        [along(x[2]), along(x[5])]
    }
}

/// A truss (rod) between two points of dimension `D`: ε = l − l0.
pub(crate) struct TrussKernel {
    pub l0: f64,
}

impl DeformationKernel<4, 1> for TrussKernel {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
        let dx = x[2] - x[0];
        let dy = x[3] - x[1];
        [(dx * dx + dy * dy).sqrt() - self.l0]
    }
}

impl DeformationKernel<6, 1> for TrussKernel {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 6]) -> [T; 1] {
        let d = vec3(x, 3) - vec3(x, 0);
        [d.norm() - self.l0]
    }
}

/// The planar hinge of thesis (5.5): ε = φq − φp.
pub(crate) struct PlanarHingeKernel;

impl DeformationKernel<2, 1> for PlanarHingeKernel {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 2]) -> [T; 1] {
        [x[1] - x[0]]
    }
}

/// The spatial hinge on x = (λp, λq) with its axis along the local x-axis of R0:
/// ε1 = θ, the relative rotation about the axis, continuous over any number of
/// turns (atan2 of the triad products plus `turns` · 2π chosen against the
/// previous value); ε2 = a·m_y and ε3 = a·m_z the small relative rotations about
/// the other two axes (normally rigid), with a = ep_x × eq_x the misalignment of
/// the two axes and m the frame halfway between the nodes about the axis,
/// m_y = (R_p(θ/2) ep_y + R_q(−θ/2) eq_y)/2 (likewise m_z). For small rotations
/// ε2, ε3 are the SPACAR measures (ep_x·eq_z − ep_z·eq_x)/2 and
/// (ep_y·eq_x − ep_x·eq_y)/2, but those lose the tilt as θ reaches π: their
/// derivative with respect to a tilt is (1 + cos θ)/2, so a hinge with free
/// bending was singular at half a turn. Measured in the half-way frame the
/// tilt's derivative is a rotation by θ/2 for every θ; swapping p and q still
/// negates all three (θ ↦ −θ keeps m, a ↦ −a).
pub(crate) struct SpatialHingeKernel {
    pub r0: [[f64; 3]; 3],
    /// 2πk added to ε1 (a constant: it does not change derivatives).
    pub offset: f64,
}

impl SpatialHingeKernel {
    /// The angle in (−π, π] from primal values only.
    pub fn principal_angle(r0: &[[f64; 3]; 3], x: &[f64; 8]) -> f64 {
        let k = SpatialHingeKernel {
            r0: *r0,
            offset: 0.0,
        };
        k.eval(x)[0]
    }
    /// The 2πk that puts the principal angle `a` closest to `prev`.
    pub fn unwrap_offset(a: f64, prev: f64) -> f64 {
        let two_pi = 2.0 * std::f64::consts::PI;
        ((prev - a) / two_pi).round() * two_pi
    }
}

impl DeformationKernel<8, 3> for SpatialHingeKernel {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 8]) -> [T; 3] {
        let mp = rotation(&quat(x, 0));
        let mq = rotation(&quat(x, 4));
        let p: [Vec3<T>; 3] = std::array::from_fn(|j| triad_axis(&mp, &self.r0, j));
        let q: [Vec3<T>; 3] = std::array::from_fn(|j| triad_axis(&mq, &self.r0, j));
        let s = p[2].dot(&q[1]) - p[1].dot(&q[2]);
        let c = p[1].dot(&q[1]) + p[2].dot(&q[2]);
        let e1 = s.atan2(c) + self.offset;
        let half = e1 * 0.5;
        // half of cos(θ/2), sin(θ/2): R_p(θ/2) and R_q(−θ/2) of the y and z
        // axes, averaged
        let (ch, sh) = (half.cos() * 0.5, half.sin() * 0.5);
        let my = p[1].scale(ch) + p[2].scale(sh) + q[1].scale(ch) - q[2].scale(sh);
        let mz = p[2].scale(ch) - p[1].scale(sh) + q[2].scale(ch) + q[1].scale(sh);
        let a = p[0].cross(&q[0]);
        [e1, a.dot(&my), a.dot(&mz)]
    }
}

/// The Euler-parameter normalization as a rigid deformation: ε = (λᵀλ − 1)/2.
pub(crate) struct NormalizationKernel;

impl DeformationKernel<4, 1> for NormalizationKernel {
    #[inline]
    fn eval<T: Real>(&self, x: &[T; 4]) -> [T; 1] {
        [(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3] - 1.0) * 0.5]
    }
}
