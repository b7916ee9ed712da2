//! The element abstraction: every element exposes its nodal-coordinate slots, its
//! named deformations ε = D(x) with D,x, D,xx\[a, b\] and Σ wᵢ Dᵢ,xx, its stress
//! σ = Sε + Dε̇ + σ0 (thesis (E.2)), and its inertia (mass matrix, inertia force
//! M ẍ + h and their derivatives). Elements without mass do no inertia work.

use crate::beam_matrices::{
    equivalent_stiffness, planar_a_diag, planar_beam_m_bar, planar_beam_s_bar, spatial_a_diag,
    spatial_beam_m_bar, spatial_beam_s_bar,
};
use crate::custom::{CustomInertia, CustomKind, Erased, MAX_ELEMENT_COORDS};
use crate::inertia::{psd_factor, PlanarInertia, SpatialInertia, VelocityTransform, MAX_MODES};
use crate::initial_orientation::{InitialFrames, MAX_ORIENTATION_SLOTS};
use crate::kernels::{
    jacobian, second_directional, third_directional, weighted_hessian, DeformationKernel,
    NormalizationKernel, PlanarBeamKernel, PlanarHingeKernel, SpatialHingeKernel, TrussKernel,
    TwoNodeSpatial,
};
use crate::kinetic::{ErasedEnergy, KineticEnergyKernel};
use crate::section::{positive, Material, SectionShape};
use crate::superelement::LinearSuperelement;
use crate::warping::warping_beam_matrices;
use crate::ElementError;
use flexmb_dual::{Dual, Real};
use nalgebra::{DMatrix, Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// A group of nodal coordinates an element connects to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Slot {
    /// A planar point (x, y).
    Position2,
    /// A planar orientation angle φ.
    Angle,
    /// A spatial point (x, y, z).
    Position3,
    /// A spatial orientation as Euler parameters (λ0, λ1, λ2, λ3).
    Orientation,
    /// `n` superelement mode amplitudes η̄ (shareable between superelements).
    Modes(usize),
}

impl Slot {
    /// Number of coordinates in the slot.
    pub fn len(&self) -> usize {
        match self {
            Slot::Position2 => 2,
            Slot::Angle => 1,
            Slot::Position3 => 3,
            Slot::Orientation => 4,
            Slot::Modes(n) => *n,
        }
    }
    /// Whether the slot holds no coordinate.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Options of the beam elements.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamOptions {
    /// Second-order elongation terms coupling bending into elongation: the
    /// planar shortening term of (5.3a), and its spatial counterpart ("bowing").
    pub shortening: bool,
    /// Timoshenko (shear-flexible) bending; `false` gives Euler–Bernoulli.
    pub timoshenko: bool,
    /// Distributed mass (consistent, with rotary inertia); `false` for a massless beam.
    pub inertia: bool,
    /// The velocity transformation of the co-rotational inertia.
    pub velocity_transform: VelocityTransform,
    /// Spatial beams only: Vlasov torsion with warping (see `warping.rs`).
    /// The beam gets one warping coordinate w = φ′ (rad/m) per end, as two
    /// one-mode [`Slot::Modes`] slots after (rp, λp, rq, λq), and two more
    /// deformations `warping_p`, `warping_q` = l0 w (rad); its St-Venant
    /// torsion energy becomes that of a cubic Hermite twist, plus the
    /// warping energy EI_w/2 ∫φ″² ds. `false` (the default) is the thesis's
    /// beam exactly.
    #[serde(default)]
    pub warping: bool,
    /// With `warping`: the warping rigidity of an isotropic plate,
    /// EI_w/(1 − ν²) (D = E t³/12(1 − ν²) in I_w = D b³/12 E), ν = E/(2G) − 1.
    /// The sheet option `anticlastic` of a scene sets it (the sheet is then
    /// treated as the isotropic plate it is; the Vlasov closed form with D
    /// matches the ν = 0.3 solid at rest to 0.01 %). `false` (the default)
    /// keeps the section's I_w.
    #[serde(default)]
    pub plate_warping: bool,
}

impl Default for BeamOptions {
    fn default() -> Self {
        Self {
            shortening: true,
            timoshenko: true,
            inertia: true,
            velocity_transform: VelocityTransform::B3,
            warping: false,
            plate_warping: false,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Kind {
    PlanarBeam(PlanarBeamKernel, Option<PlanarInertia>),
    PlanarTruss {
        l0: f64,
        mass: f64,
    },
    PlanarHinge,
    PlanarMass {
        m: f64,
        j: Option<f64>,
    },
    /// Spatial beam or superelement (k extra modes); a beam with warping
    /// has the two warping coordinates as its modes, whose deformations are
    /// l0 × the coordinate.
    TwoNode {
        kernel: TwoNodeSpatial,
        inertia: Option<SpatialInertia>,
        modes: usize,
        warping: bool,
    },
    Truss {
        l0: f64,
        mass: f64,
    },
    Hinge {
        r0: [[f64; 3]; 3],
    },
    PointMass {
        m: f64,
    },
    RigidBody(SpatialInertia),
    Normalization,
    /// A user-defined element ([`Element::custom`]): the only kind behind
    /// dynamic dispatch.
    Custom(CustomKind),
}

impl PartialEq for PlanarBeamKernel {
    fn eq(&self, o: &Self) -> bool {
        self.l0 == o.l0 && self.beta0 == o.beta0 && self.shortening == o.shortening
    }
}
impl std::fmt::Debug for PlanarBeamKernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PlanarBeam(l0 = {}, β0 = {})", self.l0, self.beta0)
    }
}
impl Clone for PlanarBeamKernel {
    fn clone(&self) -> Self {
        Self { ..*self }
    }
}
impl PartialEq for TwoNodeSpatial {
    fn eq(&self, o: &Self) -> bool {
        self.l0 == o.l0 && self.r0 == o.r0 && self.bowing == o.bowing
    }
}
impl std::fmt::Debug for TwoNodeSpatial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TwoNode(l0 = {})", self.l0)
    }
}
impl Clone for TwoNodeSpatial {
    fn clone(&self) -> Self {
        Self { ..*self }
    }
}

/// A non-linear finite element.
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    kind: Kind,
    slots: Vec<Slot>,
    names: Vec<String>,
    stiffness: DMatrix<f64>,
    damping: Option<DMatrix<f64>>,
    sigma0: Option<Vec<f64>>,
    /// The initial orientations of rotated slots, if any
    /// ([`with_initial_orientation`](Self::with_initial_orientation)).
    initial: Option<InitialFrames>,
}

/// An orthonormal frame with x along `axis` and y as close as possible to `up`.
pub fn frame_from_axis(axis: &[f64; 3], up: &[f64; 3]) -> Result<[[f64; 3]; 3], ElementError> {
    let x = Vector3::from(*axis);
    let n = x.norm();
    if !(n.is_finite() && n > 0.0) {
        return Err(ElementError::Geometry(format!(
            "axis {axis:?} has zero or non-finite length"
        )));
    }
    let x = x / n;
    let u = Vector3::from(*up);
    let y = u - x * x.dot(&u);
    let yn = y.norm();
    if !(yn.is_finite() && yn > 1e-9 * u.norm().max(1e-300)) {
        return Err(ElementError::Geometry(format!(
            "the orientation vector {up:?} is parallel to the element axis {axis:?}; give another"
        )));
    }
    let y = y / yn;
    let z = x.cross(&y);
    let m = Matrix3::from_columns(&[x, y, z]);
    Ok(std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)])))
}

fn transpose3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[j][i]))
}

fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn diag(v: &[f64]) -> DMatrix<f64> {
    DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(v))
}

fn dist(p: &[f64], q: &[f64]) -> f64 {
    p.iter()
        .zip(q)
        .map(|(a, b)| (b - a) * (b - a))
        .sum::<f64>()
        .sqrt()
}

/// The deformations of a beam with warping after the six of [`SPATIAL_NAMES`].
const WARPING_NAMES: [&str; 2] = ["warping_p", "warping_q"];

const SPATIAL_NAMES: [&str; 6] = [
    "elongation",
    "torsion",
    "bending_y_p",
    "bending_y_q",
    "bending_z_p",
    "bending_z_q",
];

impl Element {
    fn new(kind: Kind, slots: Vec<Slot>, names: Vec<String>, stiffness: DMatrix<f64>) -> Self {
        Self {
            kind,
            slots,
            names,
            stiffness,
            damping: None,
            sigma0: None,
            initial: None,
        }
    }

    /// A planar beam from p to q (thesis (5.2)–(5.3)) with consistent mass.
    pub fn planar_beam(
        p: [f64; 2],
        q: [f64; 2],
        mat: &Material,
        shape: &SectionShape,
        opts: &BeamOptions,
    ) -> Result<Self, ElementError> {
        mat.validate()?;
        if opts.warping {
            return Err(ElementError::InvalidProperty {
                what: "beam option `warping`".into(),
                value: 1.0,
                why: "a planar beam has no torsion; warping is an option of spatial beams".into(),
            });
        }
        let mut sec = shape.properties(mat.poisson())?;
        if !opts.timoshenko {
            sec = sec.euler_bernoulli();
        }
        let l0 = dist(&p, &q);
        positive("planar beam length", l0)?;
        let beta0 = (q[1] - p[1]).atan2(q[0] - p[0]);
        let s_bar = DMatrix::from_iterator(3, 3, planar_beam_s_bar(mat, &sec, l0).iter().copied());
        let s = equivalent_stiffness(&s_bar, &planar_a_diag(l0));
        let inertia = (opts.inertia && mat.rho > 0.0).then(|| {
            PlanarInertia::new(
                2,
                opts.velocity_transform,
                beta0,
                DMatrix::from_iterator(6, 6, planar_beam_m_bar(mat, &sec, l0).iter().copied()),
            )
        });
        Ok(Self::new(
            Kind::PlanarBeam(
                PlanarBeamKernel {
                    l0,
                    beta0,
                    shortening: opts.shortening,
                },
                inertia,
            ),
            vec![Slot::Position2, Slot::Angle, Slot::Position2, Slot::Angle],
            names(&["elongation", "bending_p", "bending_q"]),
            s,
        ))
    }

    /// A planar truss (rod) with axial stiffness `ea` (N) and mass per length `rho_a` (kg/m).
    pub fn planar_truss(
        p: [f64; 2],
        q: [f64; 2],
        ea: f64,
        rho_a: f64,
    ) -> Result<Self, ElementError> {
        let l0 = dist(&p, &q);
        positive("planar truss length", l0)?;
        positive("truss EA", ea)?;
        crate::section::non_negative("truss mass per length", rho_a)?;
        Ok(Self::new(
            Kind::PlanarTruss {
                l0,
                mass: rho_a * l0,
            },
            vec![Slot::Position2, Slot::Position2],
            names(&["elongation"]),
            diag(&[ea / l0]),
        ))
    }

    /// A planar hinge (thesis (5.5)) with rotational stiffness `k` (N m/rad) (may be 0).
    pub fn planar_hinge(k: f64) -> Result<Self, ElementError> {
        crate::section::non_negative("hinge stiffness", k)?;
        Ok(Self::new(
            Kind::PlanarHinge,
            vec![Slot::Angle, Slot::Angle],
            names(&["rotation"]),
            diag(&[k]),
        ))
    }

    /// A planar point mass, with rotary inertia `j` on an angle slot if given.
    pub fn planar_mass(m: f64, j: Option<f64>) -> Result<Self, ElementError> {
        positive("point mass", m)?;
        let mut slots = vec![Slot::Position2];
        if let Some(j) = j {
            crate::section::non_negative("rotary inertia", j)?;
            slots.push(Slot::Angle);
        }
        Ok(Self::new(
            Kind::PlanarMass { m, j },
            slots,
            vec![],
            DMatrix::zeros(0, 0),
        ))
    }

    /// A spatial beam from p to q (thesis (6.2)); local y is the part of `up`
    /// orthogonal to the axis. Stiffness S = AᵀS̄A (3.20) from Timoshenko theory,
    /// inertia by (2.34) with the 12×12 consistent mass. With
    /// [`BeamOptions::warping`] the slots are (rp, λp, rq, λq, w_p, w_q), the
    /// deformations add `warping_p`, `warping_q` = l0 w, and S̄, M̄ are those of
    /// `warping.rs` (an error if the section has no warping constant).
    pub fn beam(
        p: [f64; 3],
        q: [f64; 3],
        up: [f64; 3],
        mat: &Material,
        shape: &SectionShape,
        opts: &BeamOptions,
    ) -> Result<Self, ElementError> {
        mat.validate()?;
        let mut sec = shape.properties(mat.poisson())?;
        if !opts.timoshenko {
            sec = sec.euler_bernoulli();
        }
        if opts.plate_warping {
            let nu = mat.poisson();
            sec.iw = sec.iw.map(|iw| iw / (1.0 - nu * nu));
        }
        let axis = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let l0 = dist(&p, &q);
        positive("beam length", l0)?;
        let r0 = frame_from_axis(&axis, &up)?;
        let (s_bar, m_bar, modes) = if opts.warping {
            let (s, m) = warping_beam_matrices(mat, &sec, l0)?;
            (s, m, 2)
        } else {
            let s = DMatrix::from_iterator(6, 6, spatial_beam_s_bar(mat, &sec, l0).iter().copied());
            let m =
                DMatrix::from_iterator(12, 12, spatial_beam_m_bar(mat, &sec, l0).iter().copied());
            (s, m, 0)
        };
        let inertia = (opts.inertia && mat.rho > 0.0).then_some(m_bar);
        let mut e = Self::two_node(
            l0,
            r0,
            &s_bar,
            inertia,
            modes,
            opts.shortening,
            opts.velocity_transform,
        );
        if opts.warping {
            if let Kind::TwoNode { warping, .. } = &mut e.kind {
                *warping = true;
            }
            e.names.truncate(6);
            e.names.extend(names(&WARPING_NAMES));
            e.slots.extend([Slot::Modes(1), Slot::Modes(1)]);
        }
        Ok(e)
    }

    fn two_node(
        l0: f64,
        r0: [[f64; 3]; 3],
        s_bar: &DMatrix<f64>,
        m_bar: Option<DMatrix<f64>>,
        modes: usize,
        bowing: bool,
        variant: VelocityTransform,
    ) -> Self {
        let s = equivalent_stiffness(s_bar, &spatial_a_diag(l0));
        let inertia = m_bar.map(|mbar| SpatialInertia::new(2, variant, transpose3(&r0), mbar));
        let mut n = names(&SPATIAL_NAMES);
        n.extend((0..modes).map(|i| format!("mode_{}", i + 1)));
        Self::new(
            Kind::TwoNode {
                kernel: TwoNodeSpatial { l0, r0, bowing },
                inertia,
                modes,
                warping: false,
            },
            vec![
                Slot::Position3,
                Slot::Orientation,
                Slot::Position3,
                Slot::Orientation,
            ],
            n,
            s,
        )
    }

    /// The non-linear two-node superelement (thesis §2.3, §3.3) from linear
    /// superelement data. Its slots are (rp, λp, rq, λq, η̄p, η̄q, η̄f): the
    /// interface-mode slots can be shared with a neighbour's.
    pub fn superelement(
        data: &LinearSuperelement,
        transform: VelocityTransform,
    ) -> Result<Self, ElementError> {
        data.validate()?;
        let k = data.n_modes();
        let m_bar = data.m_bar_matrix();
        let has_mass = m_bar.iter().any(|v| *v != 0.0);
        let mut e = Self::two_node(
            data.l0,
            data.r0,
            &data.s_bar_matrix(),
            has_mass.then_some(m_bar),
            k,
            false,
            transform,
        );
        let (kp, kq, kf) = data.mode_counts();
        e.slots
            .extend([Slot::Modes(kp), Slot::Modes(kq), Slot::Modes(kf)]);
        Ok(e)
    }

    /// A spatial truss (rod) with axial stiffness `ea` and mass per length `rho_a`.
    pub fn truss(p: [f64; 3], q: [f64; 3], ea: f64, rho_a: f64) -> Result<Self, ElementError> {
        let l0 = dist(&p, &q);
        positive("truss length", l0)?;
        positive("truss EA", ea)?;
        crate::section::non_negative("truss mass per length", rho_a)?;
        Ok(Self::new(
            Kind::Truss {
                l0,
                mass: rho_a * l0,
            },
            vec![Slot::Position3, Slot::Position3],
            names(&["elongation"]),
            diag(&[ea / l0]),
        ))
    }

    /// A spatial hinge between two orientation nodes with its axis along `axis`
    /// (in the initial configuration), rotational stiffness `k` about it and
    /// stiffness `k_bend` for the two small bending deformations.
    pub fn hinge(axis: [f64; 3], k: f64, k_bend: f64) -> Result<Self, ElementError> {
        crate::section::non_negative("hinge stiffness", k)?;
        crate::section::non_negative("hinge bending stiffness", k_bend)?;
        let up = if axis[0].abs() < 0.9 * dist(&[0.0; 3], &axis) {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let r0 = frame_from_axis(&axis, &up)?;
        Ok(Self::new(
            Kind::Hinge { r0 },
            vec![Slot::Orientation, Slot::Orientation],
            names(&["rotation", "bending_y", "bending_z"]),
            diag(&[k, k_bend, k_bend]),
        ))
    }

    /// A spatial point mass.
    pub fn point_mass(m: f64) -> Result<Self, ElementError> {
        positive("point mass", m)?;
        Ok(Self::new(
            Kind::PointMass { m },
            vec![Slot::Position3],
            vec![],
            DMatrix::zeros(0, 0),
        ))
    }

    /// A rigid body on a position + orientation node: mass `m`, centre of mass
    /// `c` and inertia tensor `j` about the centre of mass, both in the body frame
    /// `r0` (columns: body axes in the global frame at the initial configuration).
    pub fn rigid_body(
        m: f64,
        c: [f64; 3],
        j: [[f64; 3]; 3],
        r0: [[f64; 3]; 3],
    ) -> Result<Self, ElementError> {
        positive("rigid body mass", m)?;
        let jm = Matrix3::from_fn(|a, b| j[a][b]);
        if (jm - jm.transpose()).norm() > 1e-12 * jm.norm()
            || jm.symmetric_eigenvalues().min() < 0.0
        {
            return Err(ElementError::InvalidProperty {
                what: "rigid body inertia tensor".into(),
                value: jm.symmetric_eigenvalues().min(),
                why: "must be symmetric positive semi-definite".into(),
            });
        }
        // a real mass distribution has principal moments that satisfy the
        // triangle inequality J_a + J_b ≥ J_c (equality for a flat plate)
        let ev = jm.symmetric_eigenvalues();
        let (lo, hi) = (ev.min(), ev.max());
        let sum = ev.sum();
        if sum - hi < hi * (1.0 - 1e-9) && hi > 0.0 {
            return Err(ElementError::InvalidProperty {
                what: "rigid body inertia tensor".into(),
                value: hi,
                why: format!(
                    "its principal moments ({:.6e}, {:.6e}, {:.6e}) break the triangle inequality: the largest ({hi:.6e}) exceeds the sum of the other two ({:.6e}); no mass distribution has such an inertia (is it given about the centre of mass, in kg m²?)",
                    lo,
                    sum - lo - hi,
                    hi,
                    sum - hi
                ),
            });
        }
        let cx = Matrix3::new(0.0, -c[2], c[1], c[2], 0.0, -c[0], -c[1], c[0], 0.0);
        let mut mbar = DMatrix::zeros(6, 6);
        let top_right = -cx * m;
        let bottom = jm - cx * cx * m;
        for a in 0..3 {
            mbar[(a, a)] = m;
            for b in 0..3 {
                mbar[(a, 3 + b)] = top_right[(a, b)];
                mbar[(3 + b, a)] = top_right[(a, b)];
                mbar[(3 + a, 3 + b)] = bottom[(a, b)];
            }
        }
        Ok(Self::new(
            Kind::RigidBody(SpatialInertia::new(
                1,
                VelocityTransform::B1,
                transpose3(&r0),
                mbar,
            )),
            vec![Slot::Position3, Slot::Orientation],
            vec![],
            DMatrix::zeros(0, 0),
        ))
    }

    /// The Euler-parameter normalization (λᵀλ − 1)/2 = 0 as a one-deformation
    /// element on an orientation node: a rigid condition for the kinematics.
    pub fn normalization() -> Self {
        Self::new(
            Kind::Normalization,
            vec![Slot::Orientation],
            names(&["normalization"]),
            DMatrix::zeros(1, 1),
        )
    }

    /// A user-defined element from its deformation functions ε = D(x)
    /// (thesis (2.15), (5.2)), written once over a generic scalar in a
    /// [`DeformationKernel`]: D,x, D,xx\[a, b\], D,xxx\[a, b, c\] and Σ wᵢ Dᵢ,xx
    /// follow exactly by dual numbers, as for the built-in elements.
    ///
    /// * `slots`: the nodal-coordinate slots, in the order of the kernel's x;
    ///   their lengths must add up to `NX`.
    /// * `deformation_names`: one name per deformation (`NE`), unique; they
    ///   name the deformations in scenes and outputs (`ID.name`).
    /// * `stiffness`: S in deformation space (`NE × NE`, finite), σ = Sε
    ///   (+ Dε̇ + σ0, see [`with_damping`](Self::with_damping) and
    ///   [`with_initial_stress`](Self::with_initial_stress)); the elastic
    ///   energy is ½ εᵀSε (thesis (E.2)).
    /// * `type_name`: a short name for messages and summaries.
    ///
    /// The element is massless unless [`with_mass_matrix`](Self::with_mass_matrix)
    /// gives it a constant mass matrix or
    /// [`with_kinetic_energy`](Self::with_kinetic_energy) a configuration-dependent
    /// one. Errors: sizes that disagree, a
    /// non-finite stiffness, and `NX` or `NE` above [`MAX_ELEMENT_COORDS`]
    /// ([`ElementError::TooLarge`]).
    ///
    /// To place it in a mechanism, see `flexmb_model::Scene::build_with_elements`.
    ///
    /// ```
    /// use flexmb_dual::Real;
    /// use flexmb_element::{DeformationKernel, Element, Slot};
    /// use nalgebra::DMatrix;
    /// /// A planar torsion spring between two angles: ε = φq − φp (5.5).
    /// struct Spring;
    /// impl DeformationKernel<2, 1> for Spring {
    ///     fn eval<T: Real>(&self, x: &[T; 2]) -> [T; 1] {
    ///         [x[1] - x[0]]
    ///     }
    /// }
    /// let e = Element::custom("spring", Spring, &[Slot::Angle, Slot::Angle], &["rotation"],
    ///                         DMatrix::from_element(1, 1, 5.0)).unwrap();
    /// let (mut eps, mut jac) = ([0.0], [0.0; 2]);
    /// e.deformations_and_jacobian(&[0.1, 0.4], None, &mut eps, &mut jac);
    /// assert!((eps[0] - 0.3).abs() < 1e-15 && jac == [-1.0, 1.0]);
    /// ```
    pub fn custom<K, const NX: usize, const NE: usize>(
        type_name: &'static str,
        kernel: K,
        slots: &[Slot],
        deformation_names: &[&str],
        stiffness: DMatrix<f64>,
    ) -> Result<Self, ElementError>
    where
        K: DeformationKernel<NX, NE> + Send + Sync + 'static,
    {
        for (what, n) in [("nodal coordinates", NX), ("deformations", NE)] {
            if n > MAX_ELEMENT_COORDS {
                return Err(ElementError::TooLarge {
                    element: type_name.to_string(),
                    what,
                    n,
                    max: MAX_ELEMENT_COORDS,
                });
            }
        }
        let bad = |what: &str, why: String| ElementError::InvalidProperty {
            what: format!("custom element '{type_name}' {what}"),
            value: f64::NAN,
            why,
        };
        let n_slots: usize = slots.iter().map(|s| s.len()).sum();
        if n_slots != NX {
            return Err(bad(
                "slots",
                format!("{slots:?} hold {n_slots} coordinates, the kernel takes NX = {NX}"),
            ));
        }
        if deformation_names.len() != NE {
            return Err(bad(
                "deformation names",
                format!(
                    "{} names given, the kernel has NE = {NE} deformations",
                    deformation_names.len()
                ),
            ));
        }
        for (i, a) in deformation_names.iter().enumerate() {
            if a.is_empty() || deformation_names[..i].contains(a) {
                return Err(bad(
                    "deformation names",
                    format!("'{a}' is empty or given twice; give each deformation its own name"),
                ));
            }
        }
        let e = Self::new(
            Kind::Custom(CustomKind {
                kernel: std::sync::Arc::new(Erased::<K, NX, NE> {
                    kernel,
                    name: type_name,
                    _sizes: std::marker::PhantomData,
                }),
                inertia: None,
                periodic: vec![],
            }),
            slots.to_vec(),
            names(deformation_names),
            DMatrix::zeros(NE, NE),
        );
        e.with_stiffness(stiffness)
    }

    /// Declares deformation `index` of a custom element ([`custom`](Self::custom))
    /// periodic with `period`: an angle that the kernel computes from an
    /// `atan2`, say, is in (−π, π] and jumps by 2π where it passes π.
    /// [`deformations`](Self::deformations) and
    /// [`deformations_and_jacobian`](Self::deformations_and_jacobian) then
    /// continue it from the previous deformations they are given (`prev`, as
    /// the kinematics passes the last converged solution), adding the
    /// multiple of `period` that puts it closest there, so that a hinge
    /// written as a custom element turns through any number of revolutions
    /// as the built-in ones do. Its derivatives are those of the kernel.
    /// Errors: not a custom element, an index beyond its deformations, a
    /// period that is not positive and finite.
    pub fn with_periodic_deformation(
        mut self,
        index: usize,
        period: f64,
    ) -> Result<Self, ElementError> {
        let n = self.n_eps();
        let name = self.type_name().to_string();
        let Kind::Custom(c) = &mut self.kind else {
            return Err(ElementError::InvalidProperty {
                what: "periodic deformation".into(),
                value: index as f64,
                why: format!("only a custom element takes one, not a {name}"),
            });
        };
        if index >= n {
            return Err(ElementError::InvalidProperty {
                what: format!("custom element '{name}' periodic deformation index"),
                value: index as f64,
                why: format!(
                    "the element has {n} deformations (0 … {})",
                    n.saturating_sub(1)
                ),
            });
        }
        if !(period.is_finite() && period > 0.0) {
            return Err(ElementError::InvalidProperty {
                what: format!("custom element '{name}' period of deformation {index}"),
                value: period,
                why: "must be positive and finite (2π for an angle)".into(),
            });
        }
        c.periodic.retain(|(i, _)| *i != index);
        c.periodic.push((index, period));
        Ok(self)
    }

    /// Gives a custom element ([`custom`](Self::custom)) a constant mass
    /// matrix M (n_x × n_x, symmetric positive semi-definite) over its local
    /// coordinates: kinetic energy T = ½ ẋᵀMẋ, inertia force M ẍ (h = 0),
    /// gravity force M ẋ_g with ẋ_g = g on every position slot. This is the
    /// inertia of trusses and point masses; for a mass that depends on the
    /// configuration see [`with_kinetic_energy`](Self::with_kinetic_energy).
    pub fn with_mass_matrix(mut self, m: DMatrix<f64>) -> Result<Self, ElementError> {
        let n = self.n_x();
        let bad = |why: String| ElementError::InvalidProperty {
            what: "mass matrix".into(),
            value: m.nrows() as f64,
            why,
        };
        let Kind::Custom(c) = &mut self.kind else {
            return Err(bad(format!(
                "only a custom element takes a mass matrix, not a {}",
                self.type_name()
            )));
        };
        if m.nrows() != n || m.ncols() != n || m.iter().any(|v| !v.is_finite()) {
            return Err(bad(format!("must be a finite {n} × {n} matrix")));
        }
        let rm: Vec<f64> = (0..n * n).map(|k| m[(k / n, k % n)]).collect();
        let asym = (0..n * n)
            .map(|k| (rm[k] - rm[(k % n) * n + k / n]).abs())
            .fold(0.0, f64::max);
        if asym > 1e-12 * m.amax() || psd_factor(&rm, n).is_none() {
            return Err(bad("must be symmetric positive semi-definite".into()));
        }
        c.inertia = rm
            .iter()
            .any(|v| *v != 0.0)
            .then_some(CustomInertia::Constant(rm));
        Ok(self)
    }

    /// Gives a custom element ([`custom`](Self::custom)) the inertia of a
    /// kinetic energy T(x, ẋ) = ½ ẋᵀM(x)ẋ written once over a generic scalar
    /// ([`KineticEnergyKernel`]): a mass matrix that depends on the
    /// configuration, such as a rigid body carried by a node's frame or a
    /// co-rotational element. The mass matrix M = ∂²T/∂ẋ², the inertia force
    /// F = d/dt(∂T/∂ẋ) − ∂T/∂x of Lagrange's equations, their derivatives
    /// and the gravity force M ẋ_g (ẋ_g = g on every position slot) follow
    /// exactly by dual numbers. `NX` must be the element's n_x.
    ///
    /// ```
    /// use flexmb_dual::Real;
    /// use flexmb_element::{DeformationKernel, Element, KineticEnergyKernel, Slot};
    /// use nalgebra::DMatrix;
    /// /// No deformation: a body carried by one planar node.
    /// struct Carried;
    /// impl DeformationKernel<3, 0> for Carried {
    ///     fn eval<T: Real>(&self, _x: &[T; 3]) -> [T; 0] { [] }
    /// }
    /// /// A point mass 2 kg at 1 m along the node's x axis.
    /// struct Bob;
    /// impl KineticEnergyKernel<3> for Bob {
    ///     fn kinetic_energy<T: Real>(&self, x: &[T; 3], v: &[T; 3]) -> T {
    ///         let vx = v[0] - v[2] * x[2].sin();
    ///         let vy = v[1] + v[2] * x[2].cos();
    ///         (vx * vx + vy * vy) * 1.0
    ///     }
    /// }
    /// let e = Element::custom("bob", Carried, &[Slot::Position2, Slot::Angle], &[],
    ///                         DMatrix::zeros(0, 0)).unwrap()
    ///     .with_kinetic_energy(Bob).unwrap();
    /// // turned by 90°: the bob's x velocity is −φ̇, so M[0][2] = −2
    /// let mut m = [0.0; 9];
    /// e.mass_matrix(&[0.0, 0.0, std::f64::consts::FRAC_PI_2], &mut m);
    /// assert!((m[2] + 2.0).abs() < 1e-12 && (m[8] - 2.0).abs() < 1e-12);
    /// ```
    pub fn with_kinetic_energy<K, const NX: usize>(
        mut self,
        kernel: K,
    ) -> Result<Self, ElementError>
    where
        K: KineticEnergyKernel<NX> + Send + Sync + 'static,
    {
        let n = self.n_x();
        let name = self.type_name().to_string();
        let Kind::Custom(c) = &mut self.kind else {
            return Err(ElementError::InvalidProperty {
                what: "kinetic-energy kernel".into(),
                value: NX as f64,
                why: format!("only a custom element takes a kinetic-energy kernel, not a {name}"),
            });
        };
        if NX != n {
            return Err(ElementError::InvalidProperty {
                what: format!("custom element '{name}' kinetic-energy kernel"),
                value: NX as f64,
                why: format!("the kernel takes NX = {NX} coordinates, the element has n_x = {n}"),
            });
        }
        c.inertia = Some(CustomInertia::Energy(std::sync::Arc::new(ErasedEnergy::<
            K,
            NX,
        > {
            kernel,
            _size: std::marker::PhantomData,
        })));
        Ok(self)
    }

    /// Sets the damping matrix in deformation space (n_ε × n_ε).
    pub fn with_damping(mut self, d: DMatrix<f64>) -> Result<Self, ElementError> {
        let n = self.n_eps();
        if d.nrows() != n || d.ncols() != n || d.iter().any(|v| !v.is_finite()) {
            return Err(ElementError::InvalidProperty {
                what: "damping matrix".into(),
                value: d.nrows() as f64,
                why: format!("must be a finite {n} × {n} matrix"),
            });
        }
        self.damping = Some(d);
        Ok(self)
    }

    /// Starts orientation slot `slot` (an index into [`slots`](Self::slots))
    /// rotated: `value` is the planar angle φ₀ (one value, rad) of an
    /// [`Slot::Angle`] or the Euler parameters λ₀ (four values, unit within
    /// 1e-9, then normalized) of an [`Slot::Orientation`]. The element is
    /// then undeformed when that node's orientation is λ₀ (or φ₀) rather
    /// than the identity: it sees the rotation since the start, λ ∘ λ₀*
    /// (φ − φ₀), and all its derivatives follow by the chain rule exactly
    /// (see `initial_orientation.rs`). Built-in and custom elements alike.
    ///
    /// Errors name the slot: not an orientation slot, a wrong number of
    /// values, a non-finite or non-unit λ₀, or a slot given twice.
    pub fn with_initial_orientation(
        mut self,
        slot: usize,
        value: &[f64],
    ) -> Result<Self, ElementError> {
        let bad = |why: String| {
            ElementError::Geometry(format!("initial orientation of slot {slot}: {why}"))
        };
        let kind = *self
            .slots
            .get(slot)
            .ok_or_else(|| bad(format!("the element has {} slots", self.slots.len())))?;
        let at: usize = self.slots[..slot].iter().map(Slot::len).sum();
        let frames = self.initial.get_or_insert_with(InitialFrames::new);
        if frames.has(at) {
            return Err(bad("given twice".into()));
        }
        if value.iter().any(|v| !v.is_finite()) {
            return Err(bad(format!("{value:?} is not finite")));
        }
        match (kind, value.len()) {
            (Slot::Angle, 1) => frames.push_angle(at, value[0]),
            (Slot::Orientation, 4) => {
                let norm = value.iter().map(|v| v * v).sum::<f64>().sqrt();
                if (norm - 1.0).abs() > 1e-9 {
                    return Err(bad(format!(
                        "the Euler parameters {value:?} have norm {norm}, not 1"
                    )));
                }
                frames.push_euler(at, std::array::from_fn(|k| value[k] / norm));
            }
            (Slot::Angle, n) => return Err(bad(format!("an angle slot takes 1 value, not {n}"))),
            (Slot::Orientation, n) => {
                return Err(bad(format!(
                    "an Euler-parameter slot takes 4 values, not {n}"
                )))
            }
            (other, _) => return Err(bad(format!("a {other:?} slot has no orientation"))),
        }
        Ok(self)
    }

    /// Whether some orientation slot starts rotated
    /// ([`with_initial_orientation`](Self::with_initial_orientation)).
    pub fn has_initial_orientation(&self) -> bool {
        self.initial.as_ref().is_some_and(|f| !f.is_empty())
    }

    /// Sets the initial stress resultants σ0.
    pub fn with_initial_stress(mut self, s0: Vec<f64>) -> Result<Self, ElementError> {
        if s0.len() != self.n_eps() || s0.iter().any(|v| !v.is_finite()) {
            return Err(ElementError::InvalidProperty {
                what: "initial stress".into(),
                value: s0.len() as f64,
                why: format!("must hold {} finite values", self.n_eps()),
            });
        }
        self.sigma0 = Some(s0);
        Ok(self)
    }

    /// Replaces the stiffness matrix in deformation space (n_ε × n_ε).
    pub fn with_stiffness(mut self, s: DMatrix<f64>) -> Result<Self, ElementError> {
        let n = self.n_eps();
        if s.nrows() != n || s.ncols() != n || s.iter().any(|v| !v.is_finite()) {
            return Err(ElementError::InvalidProperty {
                what: "stiffness matrix".into(),
                value: s.nrows() as f64,
                why: format!("must be a finite {n} × {n} matrix"),
            });
        }
        self.stiffness = s;
        Ok(self)
    }

    /// The nodal-coordinate slots in local order.
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }
    /// Number of local nodal coordinates.
    pub fn n_x(&self) -> usize {
        self.slots.iter().map(|s| s.len()).sum()
    }
    /// Number of deformations.
    pub fn n_eps(&self) -> usize {
        self.names.len()
    }
    /// Names of the deformations.
    pub fn deformation_names(&self) -> &[String] {
        &self.names
    }
    /// Stiffness S in deformation space.
    pub fn stiffness(&self) -> &DMatrix<f64> {
        &self.stiffness
    }
    /// Damping D in deformation space, if any.
    pub fn damping(&self) -> Option<&DMatrix<f64>> {
        self.damping.as_ref()
    }
    /// True for the Euler-parameter normalization λᵀλ − 1 of a node.
    pub fn is_normalization(&self) -> bool {
        matches!(self.kind, Kind::Normalization)
    }
    /// A short name of the element type.
    pub fn type_name(&self) -> &'static str {
        match &self.kind {
            Kind::PlanarBeam(..) => "planar beam",
            Kind::PlanarTruss { .. } => "planar truss",
            Kind::PlanarHinge => "planar hinge",
            Kind::PlanarMass { .. } => "planar mass",
            Kind::TwoNode { modes, warping, .. } => {
                if !*warping && (*modes > 0 || self.slots.len() > 4) {
                    "superelement"
                } else {
                    "beam"
                }
            }
            Kind::Truss { .. } => "truss",
            Kind::Hinge { .. } => "hinge",
            Kind::PointMass { .. } => "point mass",
            Kind::RigidBody(_) => "rigid body",
            Kind::Normalization => "Euler-parameter normalization",
            Kind::Custom(c) => c.kernel.type_name(),
        }
    }

    /// Whether the element has inertia (a massless element does no inertia work).
    pub fn has_inertia(&self) -> bool {
        match &self.kind {
            Kind::PlanarBeam(_, i) => i.is_some(),
            Kind::PlanarTruss { mass, .. } | Kind::Truss { mass, .. } => *mass > 0.0,
            Kind::PlanarMass { .. } | Kind::PointMass { .. } | Kind::RigidBody(_) => true,
            Kind::TwoNode { inertia, .. } => inertia.is_some(),
            Kind::PlanarHinge | Kind::Hinge { .. } | Kind::Normalization => false,
            Kind::Custom(c) => c.inertia.is_some(),
        }
    }

    /// The stress resultants σ = Sε + Dε̇ + σ0 (thesis (E.2)).
    pub fn stress(&self, eps: &[f64], eps_dot: Option<&[f64]>, sigma: &mut [f64]) {
        let n = self.n_eps();
        for i in 0..n {
            let mut s = self.sigma0.as_ref().map_or(0.0, |s0| s0[i]);
            for j in 0..n {
                s += self.stiffness[(i, j)] * eps[j];
            }
            if let (Some(d), Some(ed)) = (&self.damping, eps_dot) {
                for j in 0..n {
                    s += d[(i, j)] * ed[j];
                }
            }
            sigma[i] = s;
        }
    }

    /// Elastic energy ½ εᵀ S ε (+ σ0ᵀ ε).
    pub fn elastic_energy(&self, eps: &[f64]) -> f64 {
        let n = self.n_eps();
        let mut e = 0.0;
        for i in 0..n {
            for j in 0..n {
                e += 0.5 * eps[i] * self.stiffness[(i, j)] * eps[j];
            }
            if let Some(s0) = &self.sigma0 {
                e += s0[i] * eps[i];
            }
        }
        e
    }
}

/// The largest angle between an element's chord and the local x axis of one
/// of its node frames that the deformation functions can tell apart: π/2.
///
/// The bending deformations of the beams and superelements are l0 × the sine
/// of that angle ((5.3b,c), (6.2b), (3.14b)): beyond π/2 they fold back, and a
/// chord reversed against both frames (angle π) has zero bending and zero
/// elongation, an undeformed-looking state that satisfies every equation. An
/// element beyond this angle has flipped (see [`Element::is_flipped`]).
pub const FLIP_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

impl Element {
    /// [`Self::chord_cosines`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn chord_cosines_local(&self, x: &[f64]) -> Option<[f64; 2]> {
        match &self.kind {
            Kind::PlanarBeam(k, _) => Some(k.chord_cosines(x)),
            Kind::TwoNode { kernel, .. } => Some(kernel.chord_cosines(x)),
            _ => None,
        }
    }

    /// The larger of the two angles (rad, in \[0, π\]) between the chord and
    /// the node frames' x axes of [`chord_cosines`](Self::chord_cosines).
    pub fn chord_angle(&self, x: &[f64]) -> Option<f64> {
        self.chord_cosines(x)
            .map(|[a, b]| a.min(b).clamp(-1.0, 1.0).acos())
    }

    /// Whether the element has flipped at x: its chord turned by more than
    /// [`FLIP_ANGLE`] = π/2 against one of its node frames (a non-finite
    /// chord counts as flipped). Such a configuration is on a spurious branch
    /// of the periodic deformation functions, not a physical deformation of
    /// the element. Cheap (no trigonometry for spatial elements, two cosines
    /// for planar ones), for a check per Newton iterate.
    pub fn is_flipped(&self, x: &[f64]) -> bool {
        self.chord_cosines(x)
            .is_some_and(|[a, b]| !(a > 0.0 && b > 0.0))
    }

    /// The length that the element's deformations are measured in: l0 for
    /// beams, trusses and superelements (elongation, and bending as
    /// l0 × an angle, (5.3), (6.2b)); `None` for elements whose deformations
    /// are angles (hinges) or dimensionless (the normalization).
    pub fn reference_length(&self) -> Option<f64> {
        match &self.kind {
            Kind::PlanarBeam(k, _) => Some(k.l0),
            Kind::TwoNode { kernel, .. } => Some(kernel.l0),
            Kind::PlanarTruss { l0, .. } | Kind::Truss { l0, .. } => Some(*l0),
            _ => None,
        }
    }

    fn mode_count(&self) -> usize {
        match &self.kind {
            Kind::TwoNode { modes, .. } => *modes,
            _ => 0,
        }
    }

    /// ∂ε/∂x of a mode deformation: l0 for the warping coordinates of a beam
    /// (ε = l0 w), 1 for a superelement's modes (ε = η̄).
    fn mode_scale(&self) -> f64 {
        match &self.kind {
            Kind::TwoNode {
                warping: true,
                kernel,
                ..
            } => kernel.l0,
            _ => 1.0,
        }
    }

    /// [`Self::deformations`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn deformations_local(&self, x: &[f64], prev: Option<&[f64]>, eps: &mut [f64]) {
        macro_rules! go {
            ($k:expr, $nx:literal, $ne:literal) => {{
                let xa: [f64; $nx] = std::array::from_fn(|i| x[i]);
                let e = DeformationKernel::<$nx, $ne>::eval($k, &xa);
                eps[..$ne].copy_from_slice(&e);
            }};
        }
        if let Kind::Custom(c) = &self.kind {
            c.kernel.deformations(x, eps);
            return c.continue_from(prev, eps);
        }
        self.dispatch_def(x, prev, |k| each_kernel!(k, go));
        self.copy_modes(x, eps);
    }

    fn copy_modes(&self, x: &[f64], eps: &mut [f64]) {
        let k = self.mode_count();
        let c = self.mode_scale();
        for i in 0..k {
            eps[6 + i] = c * x[14 + i];
        }
    }

    fn dispatch_def(&self, x: &[f64], prev: Option<&[f64]>, f: impl FnOnce(KRef<'_>)) {
        match &self.kind {
            Kind::PlanarBeam(k, _) => f(KRef::Planar(k)),
            Kind::PlanarTruss { l0, .. } => f(KRef::Truss2(&TrussKernel { l0: *l0 })),
            Kind::PlanarHinge => f(KRef::Hinge2(&PlanarHingeKernel)),
            Kind::TwoNode { kernel, .. } => f(KRef::TwoNode(kernel)),
            Kind::Truss { l0, .. } => f(KRef::Truss3(&TrussKernel { l0: *l0 })),
            Kind::Hinge { r0 } => {
                let xa: [f64; 8] = std::array::from_fn(|i| x[i]);
                let a = SpatialHingeKernel::principal_angle(r0, &xa);
                let offset = prev.map_or(0.0, |p| SpatialHingeKernel::unwrap_offset(a, p[0]));
                f(KRef::Hinge3(&SpatialHingeKernel { r0: *r0, offset }))
            }
            Kind::Normalization => f(KRef::Norm(&NormalizationKernel)),
            Kind::PlanarMass { .. }
            | Kind::PointMass { .. }
            | Kind::RigidBody(_)
            | Kind::Custom(_) => {}
        }
    }

    /// [`Self::deformations_and_jacobian`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn deformations_and_jacobian_local(
        &self,
        x: &[f64],
        prev: Option<&[f64]>,
        eps: &mut [f64],
        jac: &mut [f64],
    ) {
        let nx = self.n_x();
        macro_rules! go {
            ($k:expr, $nx:literal, $ne:literal) => {{
                let xa: [f64; $nx] = std::array::from_fn(|i| x[i]);
                let (e, j) = jacobian::<_, $nx, $ne>($k, &xa);
                eps[..$ne].copy_from_slice(&e);
                for r in 0..$ne {
                    jac[r * nx..r * nx + nx].fill(0.0);
                    jac[r * nx..r * nx + $nx].copy_from_slice(&j[r]);
                }
            }};
        }
        if let Kind::Custom(c) = &self.kind {
            c.kernel.jacobian(x, eps, jac);
            return c.continue_from(prev, eps);
        }
        self.dispatch_def(x, prev, |k| each_kernel!(k, go));
        let k = self.mode_count();
        if k > 0 {
            self.copy_modes(x, eps);
            for r in 0..k {
                let row = &mut jac[(6 + r) * nx..(7 + r) * nx];
                row.fill(0.0);
                row[14 + r] = self.mode_scale();
            }
        }
    }

    /// [`Self::deformation_second_derivative`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn deformation_second_derivative_local(
        &self,
        x: &[f64],
        a: &[f64],
        b: &[f64],
        out: &mut [f64],
    ) {
        macro_rules! go {
            ($k:expr, $nx:literal, $ne:literal) => {{
                let xa: [f64; $nx] = std::array::from_fn(|i| x[i]);
                let aa: [f64; $nx] = std::array::from_fn(|i| a[i]);
                let ba: [f64; $nx] = std::array::from_fn(|i| b[i]);
                let d = second_directional::<_, $nx, $ne>($k, &xa, &aa, &ba);
                out[..$ne].copy_from_slice(&d);
            }};
        }
        if let Kind::Custom(c) = &self.kind {
            return c.kernel.second(x, a, b, out);
        }
        self.dispatch_def(x, None, |k| each_kernel!(k, go));
        let k = self.mode_count();
        if k > 0 {
            out[6..6 + k].fill(0.0);
        }
    }

    /// [`Self::deformation_third_derivative`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn deformation_third_derivative_local(
        &self,
        x: &[f64],
        a: &[f64],
        b: &[f64],
        c: &[f64],
        out: &mut [f64],
    ) {
        macro_rules! go {
            ($k:expr, $nx:literal, $ne:literal) => {{
                let f = |v: &[f64]| -> [f64; $nx] { std::array::from_fn(|i| v[i]) };
                let d = third_directional::<_, $nx, $ne>($k, &f(x), &f(a), &f(b), &f(c));
                out[..$ne].copy_from_slice(&d);
            }};
        }
        if let Kind::Custom(k) = &self.kind {
            return k.kernel.third(x, a, b, c, out);
        }
        self.dispatch_def(x, None, |k| each_kernel!(k, go));
        let k = self.mode_count();
        if k > 0 {
            out[6..6 + k].fill(0.0);
        }
    }

    /// [`Self::deformation_weighted_hessian`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn deformation_weighted_hessian_local(&self, x: &[f64], w: &[f64], out: &mut [f64]) {
        let nx = self.n_x();
        out[..nx * nx].fill(0.0);
        macro_rules! go {
            ($k:expr, $nx:literal, $ne:literal) => {{
                let xa: [f64; $nx] = std::array::from_fn(|i| x[i]);
                let wa: [f64; $ne] = std::array::from_fn(|i| w[i]);
                let h = weighted_hessian::<_, $nx, $ne>($k, &xa, &wa);
                for r in 0..$nx {
                    out[r * nx..r * nx + $nx].copy_from_slice(&h[r]);
                }
            }};
        }
        if let Kind::Custom(c) = &self.kind {
            return c.kernel.weighted_hessian(x, w, out);
        }
        self.dispatch_def(x, None, |k| each_kernel!(k, go));
    }
}

/// Runs the local macro `$go!(kernel, NX, NE)` with the fixed sizes of the
/// kernel behind a [`KRef`].
macro_rules! each_kernel {
    ($kref:expr, $go:ident) => {
        match $kref {
            KRef::Planar(k) => $go!(k, 6, 3),
            KRef::Truss2(k) => $go!(k, 4, 1),
            KRef::Hinge2(k) => $go!(k, 2, 1),
            KRef::TwoNode(k) => $go!(k, 14, 6),
            KRef::Truss3(k) => $go!(k, 6, 1),
            KRef::Hinge3(k) => $go!(k, 8, 3),
            KRef::Norm(k) => $go!(k, 4, 1),
        }
    };
}
use each_kernel;

enum KRef<'a> {
    Planar(&'a PlanarBeamKernel),
    Truss2(&'a TrussKernel),
    Hinge2(&'a PlanarHingeKernel),
    TwoNode(&'a TwoNodeSpatial),
    Truss3(&'a TrussKernel),
    Hinge3(&'a SpatialHingeKernel),
    Norm(&'a NormalizationKernel),
}

/// The inertia force written over a [`Real`] scalar.
trait InertiaForce {
    fn force_generic<T: Real>(&self, x: &[T], xd: &[T], xdd: &[T], out: &mut [T]);
}
impl InertiaForce for SpatialInertia {
    fn force_generic<T: Real>(&self, x: &[T], xd: &[T], xdd: &[T], out: &mut [T]) {
        self.force(x, xd, xdd, out)
    }
}
impl InertiaForce for PlanarInertia {
    fn force_generic<T: Real>(&self, x: &[T], xd: &[T], xdd: &[T], out: &mut [T]) {
        self.force(x, xd, xdd, out)
    }
}

/// ∂F/∂x and ∂F/∂ẋ (row-major n × n) of F = M ẍ + h: the `N` node coordinates by
/// one dual pass each, the mode-amplitude velocities by one directional pass each.
fn force_derivatives<I: InertiaForce, const N: usize>(
    inertia: &I,
    n: usize,
    x: &[f64],
    xd: &[f64],
    xdd: &[f64],
    dfdx: &mut [f64],
    dfdxd: &mut [f64],
) {
    dfdx[..n * n].fill(0.0);
    dfdxd[..n * n].fill(0.0);
    let mut out = [Dual::<f64, N>::constant(0.0); 14 + MAX_MODES];
    let cst = |v: &[f64]| -> [Dual<f64, N>; 14 + MAX_MODES] {
        std::array::from_fn(|i| Dual::constant(if i < n { v[i] } else { 0.0 }))
    };
    let seeded = |v: &[f64]| -> [Dual<f64, N>; 14 + MAX_MODES] {
        std::array::from_fn(|i| {
            if i < N {
                Dual::variable(v[i], i)
            } else {
                Dual::constant(if i < n { v[i] } else { 0.0 })
            }
        })
    };
    // with respect to x (modes do not enter F)
    inertia.force_generic(&seeded(x), &cst(xd), &cst(xdd), &mut out);
    for r in 0..n {
        dfdx[r * n..r * n + N].copy_from_slice(&out[r].eps);
    }
    // with respect to ẋ, node part
    inertia.force_generic(&cst(x), &seeded(xd), &cst(xdd), &mut out);
    for r in 0..n {
        dfdxd[r * n..r * n + N].copy_from_slice(&out[r].eps);
    }
    // with respect to η̄̇
    let mut o1 = [Dual::<f64, 1>::constant(0.0); 14 + MAX_MODES];
    for c in N..n {
        let x1: [Dual<f64, 1>; 14 + MAX_MODES] =
            std::array::from_fn(|i| Dual::constant(if i < n { x[i] } else { 0.0 }));
        let xdd1: [Dual<f64, 1>; 14 + MAX_MODES] =
            std::array::from_fn(|i| Dual::constant(if i < n { xdd[i] } else { 0.0 }));
        let xd1: [Dual<f64, 1>; 14 + MAX_MODES] = std::array::from_fn(|i| {
            Dual::new(
                if i < n { xd[i] } else { 0.0 },
                [if i == c { 1.0 } else { 0.0 }],
            )
        });
        inertia.force_generic(&x1, &xd1, &xdd1, &mut o1);
        for r in 0..n {
            dfdxd[r * n + c] = o1[r].eps[0];
        }
    }
}

impl Element {
    /// [`Self::mass_matrix`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn mass_matrix_local(&self, x: &[f64], out: &mut [f64]) {
        let n = self.n_x();
        out[..n * n].fill(0.0);
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => i.mass(x, out),
            Kind::TwoNode {
                inertia: Some(i), ..
            }
            | Kind::RigidBody(i) => i.mass(x, out),
            Kind::PlanarTruss { mass, .. } | Kind::Truss { mass, .. } => {
                let d = n / 2;
                for a in 0..d {
                    out[a * n + a] = mass / 3.0;
                    out[(a + d) * n + a + d] = mass / 3.0;
                    out[a * n + a + d] = mass / 6.0;
                    out[(a + d) * n + a] = mass / 6.0;
                }
            }
            Kind::PlanarMass { m, j } => {
                out[0] = *m;
                out[n + 1] = *m;
                if let Some(j) = j {
                    out[2 * n + 2] = *j;
                }
            }
            Kind::PointMass { m } => {
                for a in 0..3 {
                    out[a * n + a] = *m;
                }
            }
            Kind::Custom(c) => match &c.inertia {
                Some(CustomInertia::Constant(m)) => out[..n * n].copy_from_slice(m),
                Some(CustomInertia::Energy(k)) => k.mass(x, out),
                None => {}
            },
            _ => {}
        }
    }

    /// [`Self::mass_matrix_with_bases`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn mass_matrix_with_bases_local(
        &self,
        x: &[f64],
        bases: &[Option<[[f64; 3]; 4]>],
        out: &mut [f64],
    ) -> Option<usize> {
        match &self.kind {
            Kind::TwoNode {
                inertia: Some(i), ..
            }
            | Kind::RigidBody(i) => Some(i.mass_with_bases(x, bases, out)),
            _ => None,
        }
    }

    /// [`Self::mass_factor`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn mass_factor_local(&self, x: &[f64], out: &mut [f64]) -> Option<usize> {
        let n = self.n_x();
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => i.mass_factor(x, out),
            Kind::TwoNode {
                inertia: Some(i), ..
            }
            | Kind::RigidBody(i) => i.mass_factor(x, out),
            Kind::PlanarTruss { .. }
            | Kind::Truss { .. }
            | Kind::PlanarMass { .. }
            | Kind::PointMass { .. } => {
                // constant and at most 6 × 6
                let mut m = [0.0; 36];
                self.mass_matrix_local(x, &mut m);
                let u = psd_factor(&m[..n * n], n)?;
                out[..n * n].copy_from_slice(&u);
                Some(n)
            }
            Kind::Custom(CustomKind {
                inertia: Some(inertia),
                ..
            }) => {
                let u = match inertia {
                    CustomInertia::Constant(m) => psd_factor(m, n)?,
                    CustomInertia::Energy(k) => {
                        let mut m = [0.0; MAX_ELEMENT_COORDS * MAX_ELEMENT_COORDS];
                        k.mass(x, &mut m);
                        psd_factor(&m[..n * n], n)?
                    }
                };
                out[..n * n].copy_from_slice(&u);
                Some(n)
            }
            _ => Some(0),
        }
    }

    /// [`Self::inertia_force`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn inertia_force_local(&self, x: &[f64], xd: &[f64], xdd: &[f64], out: &mut [f64]) {
        let n = self.n_x();
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => i.force(x, xd, xdd, out),
            Kind::TwoNode {
                inertia: Some(i), ..
            }
            | Kind::RigidBody(i) => i.force(x, xd, xdd, out),
            Kind::PlanarTruss { .. }
            | Kind::Truss { .. }
            | Kind::PlanarMass { .. }
            | Kind::PointMass { .. } => {
                // constant mass matrix: h = 0
                let mut m = [0.0; 36];
                self.mass_matrix_local(x, &mut m);
                for r in 0..n {
                    out[r] = (0..n).map(|c| m[r * n + c] * xdd[c]).sum();
                }
            }
            Kind::Custom(CustomKind {
                inertia: Some(CustomInertia::Constant(m)),
                ..
            }) => {
                for r in 0..n {
                    out[r] = (0..n).map(|c| m[r * n + c] * xdd[c]).sum();
                }
            }
            Kind::Custom(CustomKind {
                inertia: Some(CustomInertia::Energy(k)),
                ..
            }) => k.force(x, xd, xdd, out),
            _ => out[..n].fill(0.0),
        }
    }

    /// The velocity-quadratic inertia force h(x, ẋ) = F(x, ẋ, 0).
    pub fn inertia_h(&self, x: &[f64], xd: &[f64], out: &mut [f64]) {
        let zero = [0.0; MAX_ELEMENT_COORDS];
        self.inertia_force(x, xd, &zero[..self.n_x()], out)
    }

    /// [`Self::inertia_force_derivatives`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn inertia_force_derivatives_local(
        &self,
        x: &[f64],
        xd: &[f64],
        xdd: &[f64],
        dfdx: &mut [f64],
        dfdxd: &mut [f64],
    ) {
        let n = self.n_x();
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => {
                force_derivatives::<_, 6>(i, n, x, xd, xdd, dfdx, dfdxd)
            }
            Kind::TwoNode {
                inertia: Some(i), ..
            } => force_derivatives::<_, 14>(i, n, x, xd, xdd, dfdx, dfdxd),
            Kind::RigidBody(i) => force_derivatives::<_, 7>(i, n, x, xd, xdd, dfdx, dfdxd),
            Kind::Custom(CustomKind {
                inertia: Some(CustomInertia::Energy(k)),
                ..
            }) => k.force_derivatives(x, xd, xdd, dfdx, dfdxd),
            _ => {
                dfdx[..n * n].fill(0.0);
                dfdxd[..n * n].fill(0.0);
            }
        }
    }

    /// [`Self::gravity_potential`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn gravity_potential_local(&self, x: &[f64], g: &[f64; 3]) -> Option<f64> {
        match &self.kind {
            Kind::PointMass { m } => Some(-m * (g[0] * x[0] + g[1] * x[1] + g[2] * x[2])),
            Kind::PlanarMass { m, .. } => Some(-m * (g[0] * x[0] + g[1] * x[1])),
            _ if !self.has_inertia() => Some(0.0),
            _ => None,
        }
    }

    /// [`Self::kinetic_energy`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn kinetic_energy_local(&self, x: &[f64], xd: &[f64]) -> f64 {
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => i.kinetic_energy(x, xd),
            Kind::TwoNode {
                inertia: Some(i), ..
            }
            | Kind::RigidBody(i) => i.kinetic_energy(x, xd),
            Kind::PlanarTruss { .. }
            | Kind::Truss { .. }
            | Kind::PlanarMass { .. }
            | Kind::PointMass { .. } => {
                let n = self.n_x();
                let mut m = [0.0; 36];
                self.mass_matrix_local(x, &mut m);
                let mut e = 0.0;
                for r in 0..n {
                    for c in 0..n {
                        e += 0.5 * xd[r] * m[r * n + c] * xd[c];
                    }
                }
                e
            }
            Kind::Custom(CustomKind {
                inertia: Some(CustomInertia::Energy(k)),
                ..
            }) => k.kinetic_energy(x, xd),
            Kind::Custom(CustomKind {
                inertia: Some(CustomInertia::Constant(m)),
                ..
            }) => {
                let n = self.n_x();
                let mut e = 0.0;
                for r in 0..n {
                    for c in 0..n {
                        e += 0.5 * xd[r] * m[r * n + c] * xd[c];
                    }
                }
                e
            }
            _ => 0.0,
        }
    }

    /// [`Self::gravity_force`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn gravity_force_local(&self, x: &[f64], g: &[f64; 3], out: &mut [f64]) {
        let n = self.n_x();
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => i.gravity(x, g, out),
            Kind::TwoNode {
                inertia: Some(i), ..
            }
            | Kind::RigidBody(i) => i.gravity(x, g, out),
            Kind::PlanarTruss { .. }
            | Kind::Truss { .. }
            | Kind::PlanarMass { .. }
            | Kind::PointMass { .. } => {
                let mut xg = [0.0; 6];
                let dim = if matches!(self.kind, Kind::Truss { .. } | Kind::PointMass { .. }) {
                    3
                } else {
                    2
                };
                let mut i = 0;
                for s in &self.slots {
                    if matches!(s, Slot::Position2 | Slot::Position3) {
                        xg[i..i + dim].copy_from_slice(&g[..dim]);
                    }
                    i += s.len();
                }
                let zero = [0.0; 6];
                self.inertia_force_local(x, &zero, &xg, out);
            }
            Kind::Custom(CustomKind {
                inertia: Some(inertia),
                ..
            }) => {
                let xg = self.gravity_velocity(g);
                match inertia {
                    CustomInertia::Energy(k) => k.gravity(x, &xg[..n], out),
                    CustomInertia::Constant(_) => {
                        let zero = [0.0; MAX_ELEMENT_COORDS];
                        self.inertia_force_local(x, &zero[..n], &xg[..n], out);
                    }
                }
            }
            _ => out[..n].fill(0.0),
        }
    }

    /// [`Self::gravity_force_derivative`] in the element's own coordinates, where every
    /// orientation slot starts at the identity.
    fn gravity_force_derivative_local(&self, x: &[f64], g: &[f64; 3], out: &mut [f64]) {
        let n = self.n_x();
        out[..n * n].fill(0.0);
        macro_rules! go {
            ($i:expr, $N:literal) => {{
                let xs: [Dual<f64, $N>; 14 + MAX_MODES] = std::array::from_fn(|k| {
                    if k < $N {
                        Dual::variable(x[k], k)
                    } else {
                        Dual::constant(if k < n { x[k] } else { 0.0 })
                    }
                });
                let mut o = [Dual::<f64, $N>::constant(0.0); 14 + MAX_MODES];
                $i.gravity(&xs, g, &mut o);
                for r in 0..n {
                    out[r * n..r * n + $N].copy_from_slice(&o[r].eps);
                }
            }};
        }
        match &self.kind {
            Kind::PlanarBeam(_, Some(i)) => go!(i, 6),
            Kind::TwoNode {
                inertia: Some(i), ..
            } => go!(i, 14),
            Kind::RigidBody(i) => go!(i, 7),
            Kind::Custom(CustomKind {
                inertia: Some(CustomInertia::Energy(k)),
                ..
            }) => k.gravity_derivative(x, &self.gravity_velocity(g)[..n], out),
            _ => {}
        }
    }

    /// ẋ_g: the uniform acceleration `g` on every position slot, zero on
    /// the other coordinates (the gravity force of a custom element is
    /// M(x) ẋ_g).
    fn gravity_velocity(&self, g: &[f64; 3]) -> [f64; MAX_ELEMENT_COORDS] {
        let mut xg = [0.0; MAX_ELEMENT_COORDS];
        let mut i = 0;
        for s in &self.slots {
            match s {
                Slot::Position2 => xg[i..i + 2].copy_from_slice(&g[..2]),
                Slot::Position3 => xg[i..i + 3].copy_from_slice(g),
                _ => {}
            }
            i += s.len();
        }
        xg
    }
}

/// The public evaluation functions: each maps the local coordinates through
/// the element's initial orientations, if it has any (see
/// `initial_orientation.rs`), and evaluates the element in its own
/// coordinates.
impl Element {
    /// The cosines of the angles between the element's chord p → q and the
    /// local x axes of its p and q node frames at x, for the elements whose
    /// deformations are periodic in them (planar and spatial beams,
    /// superelements); `None` for the others (trusses have no frames, hinge
    /// angles are unwrapped over turns, masses have no deformations).
    pub fn chord_cosines(&self, x: &[f64]) -> Option<[f64; 2]> {
        match &self.initial {
            None => self.chord_cosines_local(x),
            Some(f) => self.chord_cosines_local(&f.point(x)),
        }
    }

    /// The local coordinates `x` as the element measures them, into `out`
    /// (same length): each slot with an initial orientation λ0
    /// ([`with_initial_orientation`](Self::with_initial_orientation)) holds
    /// λ ∘ λ0* (planar φ − φ0), the rotation since the start; the other
    /// entries are copied. What a superelement's mesh recovery takes.
    pub fn measured_coordinates(&self, x: &[f64], out: &mut [f64]) {
        match &self.initial {
            None => out.copy_from_slice(x),
            Some(f) => out.copy_from_slice(&f.point(x)),
        }
    }

    /// ε = D(x). `prev` (the previous deformations) keeps hinge angles continuous
    /// over many turns; pass `None` for the principal value.
    pub fn deformations(&self, x: &[f64], prev: Option<&[f64]>, eps: &mut [f64]) {
        match &self.initial {
            None => self.deformations_local(x, prev, eps),
            Some(f) => self.deformations_local(&f.point(x), prev, eps),
        }
    }

    /// ε = D(x) and D,x (row-major n_ε × n_x).
    pub fn deformations_and_jacobian(
        &self,
        x: &[f64],
        prev: Option<&[f64]>,
        eps: &mut [f64],
        jac: &mut [f64],
    ) {
        match &self.initial {
            None => self.deformations_and_jacobian_local(x, prev, eps, jac),
            Some(f) => {
                self.deformations_and_jacobian_local(&f.point(x), prev, eps, jac);
                f.right(jac, self.n_eps(), self.n_x());
            }
        }
    }

    /// The directional second derivative D,xx\[a, b\] (length n_ε): the
    /// convective term with a = b = ẋ.
    pub fn deformation_second_derivative(&self, x: &[f64], a: &[f64], b: &[f64], out: &mut [f64]) {
        match &self.initial {
            None => self.deformation_second_derivative_local(x, a, b, out),
            Some(f) => {
                let n = self.n_x();
                let (a, b) = (f.direction(&a[..n]), f.direction(&b[..n]));
                self.deformation_second_derivative_local(&f.point(x), &a, &b, out)
            }
        }
    }

    /// The directional third derivative D,xxx\[a, b, c\] (length n_ε), needed by
    /// the linearization of the convective terms (thesis (E.5f)).
    pub fn deformation_third_derivative(
        &self,
        x: &[f64],
        a: &[f64],
        b: &[f64],
        c: &[f64],
        out: &mut [f64],
    ) {
        match &self.initial {
            None => self.deformation_third_derivative_local(x, a, b, c, out),
            Some(f) => {
                let n = self.n_x();
                let (a, b, c) = (
                    f.direction(&a[..n]),
                    f.direction(&b[..n]),
                    f.direction(&c[..n]),
                );
                self.deformation_third_derivative_local(&f.point(x), &a, &b, &c, out)
            }
        }
    }

    /// The weighted Hessian Σᵢ wᵢ Dᵢ,xx (row-major n_x × n_x): the element's
    /// contribution to the geometric stiffness.
    pub fn deformation_weighted_hessian(&self, x: &[f64], w: &[f64], out: &mut [f64]) {
        match &self.initial {
            None => self.deformation_weighted_hessian_local(x, w, out),
            Some(f) => {
                self.deformation_weighted_hessian_local(&f.point(x), w, out);
                f.congruence(out, self.n_x());
            }
        }
    }

    /// The mass matrix over the local nodal coordinates (row-major n_x × n_x);
    /// zero for massless elements.
    pub fn mass_matrix(&self, x: &[f64], out: &mut [f64]) {
        match &self.initial {
            None => self.mass_matrix_local(x, out),
            Some(f) => {
                self.mass_matrix_local(&f.point(x), out);
                f.congruence(out, self.n_x());
            }
        }
    }

    /// TᵀM(x)T for the local coordinates in which the Euler parameters of
    /// orientation slot k (in slot order) are replaced through
    /// `bases[k] = Some(P)` (λ̇ = P a with P 4 × 3, e.g. Λᵀ(λ), whose
    /// columns span the tangent space of the normalization), row-major in
    /// the reduced coordinates (slot order, three per replaced orientation).
    /// Returns the order of the result; `None` for elements without
    /// co-rotational spatial inertia (apply T to
    /// [`mass_matrix`](Self::mass_matrix) then).
    pub fn mass_matrix_with_bases(
        &self,
        x: &[f64],
        bases: &[Option<[[f64; 3]; 4]>],
        out: &mut [f64],
    ) -> Option<usize> {
        match &self.initial {
            None => self.mass_matrix_with_bases_local(x, bases, out),
            Some(f) => {
                let mut mapped = [None; MAX_ORIENTATION_SLOTS];
                let n = f.bases(bases, &self.slots, &mut mapped);
                self.mass_matrix_with_bases_local(&f.point(x), &mapped[..n], out)
            }
        }
    }

    /// A factor R of the mass matrix, M = RᵀR (row-major m × n_x with
    /// m ≤ n_x), written to `out`; returns m (0 for massless elements). For
    /// co-rotational inertia R = Ū B̂ with the constant M̄ = ŪᵀŪ, so that
    /// Fᵀ M F = (R F)ᵀ(R F) needs no n_x × n_x product (thesis (3.31), (D.10)).
    /// `None` if M has no such factor (an indefinite M̄); use
    /// [`mass_matrix`](Self::mass_matrix) then.
    pub fn mass_factor(&self, x: &[f64], out: &mut [f64]) -> Option<usize> {
        match &self.initial {
            None => self.mass_factor_local(x, out),
            Some(f) => {
                let m = self.mass_factor_local(&f.point(x), out)?;
                f.right(out, m, self.n_x());
                Some(m)
            }
        }
    }

    /// The inertia force M ẍ + h(x, ẋ) (thesis (2.40a), (3.34)).
    pub fn inertia_force(&self, x: &[f64], xd: &[f64], xdd: &[f64], out: &mut [f64]) {
        match &self.initial {
            None => self.inertia_force_local(x, xd, xdd, out),
            Some(f) => {
                let n = self.n_x();
                let (xd, xdd) = (f.direction(&xd[..n]), f.direction(&xdd[..n]));
                self.inertia_force_local(&f.point(x), &xd, &xdd, out);
                f.left_transposed(&mut out[..n], 1);
            }
        }
    }

    /// ∂(M ẍ + h)/∂x and ∂h/∂ẋ (row-major n_x × n_x each), exact (Appendix E
    /// needs them for the N and C matrices). ∂/∂ẍ is the mass matrix.
    pub fn inertia_force_derivatives(
        &self,
        x: &[f64],
        xd: &[f64],
        xdd: &[f64],
        dfdx: &mut [f64],
        dfdxd: &mut [f64],
    ) {
        match &self.initial {
            None => self.inertia_force_derivatives_local(x, xd, xdd, dfdx, dfdxd),
            Some(f) => {
                let n = self.n_x();
                let (xd, xdd) = (f.direction(&xd[..n]), f.direction(&xdd[..n]));
                self.inertia_force_derivatives_local(&f.point(x), &xd, &xdd, dfdx, dfdxd);
                f.congruence(dfdx, n);
                f.congruence(dfdxd, n);
            }
        }
    }

    /// The exact gravitational potential −m g·r_c where the element's centre
    /// of mass follows from its coordinates exactly (point masses); `None` for
    /// elements whose consistent gravity force has no closed-form potential here.
    pub fn gravity_potential(&self, x: &[f64], g: &[f64; 3]) -> Option<f64> {
        match &self.initial {
            None => self.gravity_potential_local(x, g),
            Some(f) => self.gravity_potential_local(&f.point(x), g),
        }
    }

    /// Kinetic energy T(x, ẋ).
    pub fn kinetic_energy(&self, x: &[f64], xd: &[f64]) -> f64 {
        match &self.initial {
            None => self.kinetic_energy_local(x, xd),
            Some(f) => {
                let xd = f.direction(&xd[..self.n_x()]);
                self.kinetic_energy_local(&f.point(x), &xd)
            }
        }
    }

    /// The generalized force of gravity `g` (a uniform acceleration field),
    /// f = M(x) ẋ_g with ẋ_g = g on every position coordinate: exact for rigid
    /// motion of the element, including centre-of-mass offsets.
    pub fn gravity_force(&self, x: &[f64], g: &[f64; 3], out: &mut [f64]) {
        match &self.initial {
            None => self.gravity_force_local(x, g, out),
            Some(f) => {
                // ẋ_g has no orientation part: T ẋ_g = ẋ_g
                self.gravity_force_local(&f.point(x), g, out);
                f.left_transposed(&mut out[..self.n_x()], 1);
            }
        }
    }

    /// ∂f_gravity/∂x (row-major n_x × n_x): nonzero where the gravity force
    /// depends on orientations.
    pub fn gravity_force_derivative(&self, x: &[f64], g: &[f64; 3], out: &mut [f64]) {
        match &self.initial {
            None => self.gravity_force_derivative_local(x, g, out),
            Some(f) => {
                self.gravity_force_derivative_local(&f.point(x), g, out);
                f.congruence(out, self.n_x());
            }
        }
    }
}
