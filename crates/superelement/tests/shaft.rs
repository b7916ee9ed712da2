//! The unbalanced-shaft mesher of thesis Table 2.2 (`parts::unbalanced_shaft_half`):
//! the superelement's rigid-body properties against the geometry, computed
//! independently of the FE code.

use flexmb_element::Material;
use flexmb_superelement::parts::ShaftHalf;
use flexmb_superelement::solid::{hex20_shape, Mesh};
use flexmb_superelement::{build, parts, RigidBodyProperties};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

const RHO: f64 = 7800.0;
/// Table 2.2: rod diameter d1, cylinder diameter d2 and length l, eccentricity r.
const D1: f64 = 2.0e-3;
const D2: f64 = 3.0e-2;
const LC: f64 = 7.5e-2;
const R: f64 = 1.1e-2;
/// The rod length (a parameter: not in the thesis text).
const ROD: f64 = 0.05;

fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: RHO,
    }
}

/// Area and second moments (∫y² dA, ∫z² dA about its centre) of a disc of
/// diameter `d` as the mesher builds it with `ns` × `ns` mapped 20-node
/// elements: the boundary is 4·ns quadratic arcs (Lagrange, through a corner,
/// a mid-side and a corner node), all nodes on the circle at the images of
/// the square's boundary under (u, v) ↦ r (u √(1 − v²/2), v √(1 − u²/2)).
/// Computed by Green's theorem along those arcs (4-point Gauss, exact for the
/// polynomial integrands), independently of the FE code.
fn meshed_disc(d: f64, ns: usize) -> (f64, f64, f64) {
    let r = 0.5 * d;
    let map = |u: f64, v: f64| {
        [
            r * u * (1.0 - 0.5 * v * v).sqrt(),
            r * v * (1.0 - 0.5 * u * u).sqrt(),
        ]
    };
    // boundary nodes counter-clockwise, 2·ns intervals per side
    let t = |k: usize| -1.0 + k as f64 / ns as f64;
    let mut pts = Vec::new();
    for k in 0..2 * ns {
        pts.push(map(1.0, t(k)));
    }
    for k in 0..2 * ns {
        pts.push(map(-t(k), 1.0));
    }
    for k in 0..2 * ns {
        pts.push(map(-1.0, -t(k)));
    }
    for k in 0..2 * ns {
        pts.push(map(t(k), -1.0));
    }
    let gauss = [
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    let (mut a, mut syy, mut szz) = (0.0, 0.0, 0.0);
    let n = pts.len();
    for e in (0..n).step_by(2) {
        let (p0, pm, p1) = (pts[e], pts[e + 1], pts[(e + 2) % n]);
        for &(x, w) in &gauss {
            for s in [-1.0, 1.0] {
                let tt = 0.5 * (1.0 + s * x);
                let w = 0.5 * w;
                let (n0, nm, n1) = (
                    (1.0 - tt) * (1.0 - 2.0 * tt),
                    4.0 * tt * (1.0 - tt),
                    tt * (2.0 * tt - 1.0),
                );
                let (d0, dm, d1) = (4.0 * tt - 3.0, 4.0 - 8.0 * tt, 4.0 * tt - 1.0);
                let y = n0 * p0[0] + nm * pm[0] + n1 * p1[0];
                let z = n0 * p0[1] + nm * pm[1] + n1 * p1[1];
                let dy = d0 * p0[0] + dm * pm[0] + d1 * p1[0];
                let dz = d0 * p0[1] + dm * pm[1] + d1 * p1[1];
                // ∫∫dA = ∮ y dz, ∫∫y² dA = ∮ y³/3 dz, ∫∫z² dA = −∮ z³/3 dy
                a += w * y * dz;
                syy += w * y * y * y / 3.0 * dz;
                szz -= w * z * z * z / 3.0 * dy;
            }
        }
    }
    (a, syy, szz)
}

/// A prism along x from `x0` to `x1` with a doubly symmetric section (area
/// `a`, ∫y² dA `syy`, ∫z² dA `szz` about its centre (`yc`, `zc`)): mass, first
/// moment and the second-moment matrix ∫ r rᵀ dm about the origin.
fn prism(
    x0: f64,
    x1: f64,
    (a, syy, szz): (f64, f64, f64),
    yc: f64,
    zc: f64,
) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let len = x1 - x0;
    let m = RHO * a * len;
    let c = Vector3::new(0.5 * (x0 + x1), yc, zc);
    let mut s = m * c * c.transpose();
    // the section's own spread (its product ∫yz dA is zero by symmetry)
    s[(0, 0)] += m * len * len / 12.0;
    s[(1, 1)] += RHO * len * syy;
    s[(2, 2)] += RHO * len * szz;
    (m, m * c, s)
}

/// Mass, centre of mass and inertia about it, relative to the point `p`.
fn rigid_body(parts: &[(f64, Vector3<f64>, Matrix3<f64>)], p: Vector3<f64>) -> RigidBodyProperties {
    let m: f64 = parts.iter().map(|x| x.0).sum();
    let first: Vector3<f64> = parts.iter().map(|x| x.1).sum();
    let s: Matrix3<f64> = parts.iter().map(|x| x.2).sum();
    let c = first / m;
    let sc = s - m * c * c.transpose();
    let j = Matrix3::identity() * sc.trace() - sc;
    let cp = c - p;
    RigidBodyProperties {
        mass: m,
        com: [cp[0], cp[1], cp[2]],
        inertia: std::array::from_fn(|i| std::array::from_fn(|k| j[(i, k)])),
    }
}

/// Largest deviation: mass / m, centre of mass / the part's length, inertia /
/// its largest entry.
fn deviation(a: &RigidBodyProperties, b: &RigidBodyProperties) -> [f64; 3] {
    let dm = (a.mass / b.mass - 1.0).abs();
    let dc = (0..3)
        .map(|d| (a.com[d] - b.com[d]).abs())
        .fold(0.0, f64::max)
        / (ROD + 0.5 * LC);
    let js = b
        .inertia
        .iter()
        .flatten()
        .map(|x| x.abs())
        .fold(0.0, f64::max);
    let dj = (0..9)
        .map(|k| (a.inertia[k / 3][k % 3] - b.inertia[k / 3][k % 3]).abs())
        .fold(0.0, f64::max)
        / js;
    [dm, dc, dj]
}

/// Gauss–Legendre rules on [−1, 1]: (points, weights).
const GAUSS3: ([f64; 3], [f64; 3]) = (
    [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4],
    [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0],
);
const GAUSS5: ([f64; 5], [f64; 5]) = (
    [
        -0.906_179_845_938_664,
        -0.538_469_310_105_683_1,
        0.0,
        0.538_469_310_105_683_1,
        0.906_179_845_938_664,
    ],
    [
        0.236_926_885_056_189_1,
        0.478_628_670_499_366_5,
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
    ],
);

/// Mass, first moment and ∫ r rᵀ dm of the mesh's isoparametric geometry,
/// integrated with the `N`-point Gauss rule per direction.
fn mesh_moments<const N: usize>(
    mesh: &Mesh,
    (pts, wts): ([f64; N], [f64; N]),
) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let (mut m, mut first, mut second) = (0.0, Vector3::zeros(), Matrix3::zeros());
    for el in &mesh.elements {
        for a in 0..N {
            for b in 0..N {
                for c in 0..N {
                    let (n, dn) = hex20_shape([pts[a], pts[b], pts[c]]);
                    let mut x = Vector3::zeros();
                    let mut jac = Matrix3::zeros();
                    for k in 0..20 {
                        let xk = Vector3::from(mesh.coords[el[k]]);
                        x += n[k] * xk;
                        jac += xk * Vector3::from(dn[k]).transpose();
                    }
                    let dm = RHO * wts[a] * wts[b] * wts[c] * jac.determinant();
                    m += dm;
                    first += dm * x;
                    second += dm * x * x.transpose();
                }
            }
        }
    }
    (m, first, second)
}

fn fmt(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The half shaft (rod along the axis, x ∈ [−ROD, 0], meshed 2 × 2 across;
/// eccentric cylinder x ∈ [0, l/2] centred at y = r, `ns` × `ns` across, tied
/// to the rod by a massless rigid link) as a superelement:
/// * M̄'s mass, centre of mass and inertia equal those of the meshed geometry
///   (circles replaced by the mesh's quadratic arcs, computed above without
///   the FE code) to 1e-10: the consistent mass is exact for rigid motions,
///   the mapped elements tile the section and the tie adds no mass;
/// * the meshed geometry converges to the true cylinders as `ns` grows, and so
///   do the superelement's properties: its deviations from the analytic
///   cylinder + rod decrease with every refinement.
#[test]
fn unbalanced_shaft_rigid_body_properties_match_the_geometry() {
    let p = Vector3::new(-ROD, 0.0, 0.0);
    let exact_disc = |d: f64| {
        let r = 0.5 * d;
        (PI * r * r, PI * r.powi(4) / 4.0, PI * r.powi(4) / 4.0)
    };
    let analytic = rigid_body(
        &[
            prism(-ROD, 0.0, exact_disc(D1), 0.0, 0.0),
            prism(0.0, 0.5 * LC, exact_disc(D2), R, 0.0),
        ],
        p,
    );
    // the unbalance: the centre of mass is off the axis
    assert!(analytic.com[1] > 0.01 && analytic.com[1] < R);
    let mut previous: Option<([f64; 3], f64)> = None;
    for ns in [2, 4, 8] {
        let part = parts::unbalanced_shaft_half(ShaftHalf::First, ROD, ns, 10, 4, steel()).unwrap();
        let model = part.mesh.assemble("shaft").unwrap();
        let se = build(&model, &part.settings).unwrap();
        assert!((se.data.l0 - (ROD + 0.5 * LC)).abs() < 1e-15);
        let rb = RigidBodyProperties::from_m_bar(&se.data.m_bar_matrix(), se.data.l0);
        let disc = meshed_disc(D2, ns);
        let geometry = rigid_body(
            &[
                prism(-ROD, 0.0, meshed_disc(D1, 2), 0.0, 0.0),
                prism(0.0, 0.5 * LC, disc, R, 0.0),
            ],
            p,
        );
        let d_geo = deviation(&rb, &geometry);
        let d_true = deviation(&rb, &analytic);
        let d_quad3 = deviation(&rb, &rigid_body(&[mesh_moments(&part.mesh, GAUSS3)], p));
        let d_mesh = deviation(
            &rigid_body(&[mesh_moments(&part.mesh, GAUSS5)], p),
            &geometry,
        );
        let area_err = (disc.0 / exact_disc(D2).0 - 1.0).abs();
        println!(
            "ns {ns}: {} equations; (mass, com, inertia) of M̄ vs the meshed geometry {}, \
             vs the mesh integrated 3 × 3 × 3 {}; mesh integrated 5 × 5 × 5 vs the geometry {}; \
             M̄ vs analytic cylinders {}; section area error {area_err:.2e}",
            model.n_eq(),
            fmt(&d_geo),
            fmt(&d_quad3),
            fmt(&d_mesh),
            fmt(&d_true)
        );
        // M̄'s rigid-body part is the FE model's (3 × 3 × 3 Gauss) mass
        // distribution, the massless rigid link changing nothing
        for (what, e) in ["mass", "centre of mass", "inertia"].iter().zip(d_quad3) {
            assert!(
                e < 1e-10,
                "ns {ns}: M̄ {what} differs from the FE mass by {e:.2e}"
            );
        }
        // the mesh is the intended geometry: integrated accurately, it has the
        // mass, centre and inertia of the quadratic-arc sections. The
        // consistent mass integrates ρ·det J (exact with 3 points) for mass and
        // centre, but ρ r rᵀ det J (degree 7 on curved elements) is not exact
        // with 3 points: the inertia differs from the geometry by the
        // quadrature error (measured 2.0e-5, 4.3e-7, 8.4e-9 for ns 2, 4, 8).
        for (what, e) in ["mass", "centre of mass", "inertia"].iter().zip(d_mesh) {
            assert!(
                e < 1e-10,
                "ns {ns}: the mesh's {what} differs from the geometry by {e:.2e}"
            );
        }
        assert!(d_geo[0] < 1e-10 && d_geo[1] < 1e-10, "ns {ns}: {d_geo:?}");
        // M̄ vs the true cylinders, measured (mass, com, inertia): ns 2 (1.4e-3,
        // 3.8e-14, 1.8e-3), 4 (1.4e-4, 3.8e-6, 2.6e-4), 8 (1.8e-5, 4.1e-6,
        // 1.1e-4). The rod keeps its 2 × 2 section (area error 1.4e-3), which
        // sets floors: centre of mass 1.4e-3 × (rod 0.59 % of the mass) ×
        // (43 mm from the centre) / 87.5 mm = 4.1e-6 of the length, inertia
        // 1.4e-3 × (rod ≈ 6.5 % of I_yy, I_zz) ≈ 9e-5. Mass and inertia decrease
        // with each refinement towards them; the section's area error drops at
        // least 4× per refinement (measured 11×, 13×: quadratic arcs).
        if let Some((d_prev, a_prev)) = previous {
            assert!(
                d_true[0] < d_prev[0] && d_true[2] < d_prev[2],
                "ns {ns}: {d_true:?} not below {d_prev:?}"
            );
            assert!(
                area_err < 0.25 * a_prev,
                "area error {area_err} vs {a_prev}"
            );
        }
        assert!(
            d_true[1] < 5e-6,
            "centre of mass off by {:.2e} of the length (rod floor 4.1e-6)",
            d_true[1]
        );
        previous = Some((d_true, area_err));
    }
}

/// The second half (thesis Fig. 2.13: the first turned by π about the y axis
/// through the middle) and the first half joined at p (`Part::reversed`,
/// Fig. 2.16) as superelements. In its own frame (origin p, x̄ towards q) the
/// second half is the first: the same l0, S̄ and M̄ to rounding, R0 =
/// diag(−1, 1, −1). The reversed first half has R0 = diag(−1, 1, −1) too, its
/// centre of mass at l0 − x̄c along x̄ and the same mass and stiffness
/// invariants (the trace of S̄, the inertia about its centre).
#[test]
fn the_second_and_the_reversed_half_are_the_first_seen_from_its_other_end() {
    let first =
        build_half(parts::unbalanced_shaft_half(ShaftHalf::First, ROD, 2, 6, 2, steel()).unwrap());
    let second =
        build_half(parts::unbalanced_shaft_half(ShaftHalf::Second, ROD, 2, 6, 2, steel()).unwrap());
    let reversed = build_half(
        parts::unbalanced_shaft_half(ShaftHalf::First, ROD, 2, 6, 2, steel())
            .unwrap()
            .reversed(),
    );
    let flip = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];
    let max_abs = |m: &nalgebra::DMatrix<f64>| m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for (name, se) in [("second", &second), ("reversed", &reversed)] {
        assert!((se.l0 - first.l0).abs() < 1e-15, "{name}: l0 {}", se.l0);
        for i in 0..3 {
            for k in 0..3 {
                assert!(
                    (se.r0[i][k] - flip[i][k]).abs() < 1e-12,
                    "{name}: R0 {:?}",
                    se.r0
                );
            }
        }
    }
    let (s1, s2) = (first.s_bar_matrix(), second.s_bar_matrix());
    let (m1, m2) = (first.m_bar_matrix(), second.m_bar_matrix());
    let ds = max_abs(&(&s2 - &s1)) / max_abs(&s1);
    let dm = max_abs(&(&m2 - &m1)) / max_abs(&m1);
    assert!(
        ds < 1e-9 && dm < 1e-9,
        "second half: S̄ {ds:.1e}, M̄ {dm:.1e} from the first"
    );
    let a = RigidBodyProperties::from_m_bar(&m1, first.l0);
    let b = RigidBodyProperties::from_m_bar(&reversed.m_bar_matrix(), reversed.l0);
    assert!((b.mass / a.mass - 1.0).abs() < 1e-12);
    // seen from the other end: x̄c ↦ l0 − x̄c, ȳ kept (R0's y axis), z̄ ↦ −z̄
    let expect = [first.l0 - a.com[0], a.com[1], -a.com[2]];
    for d in 0..3 {
        assert!(
            (b.com[d] - expect[d]).abs() < 1e-12 * first.l0,
            "reversed centre of mass {:?}, expected {expect:?}",
            b.com
        );
    }
    let trace = |m: &nalgebra::DMatrix<f64>| (0..m.nrows()).map(|i| m[(i, i)]).sum::<f64>();
    let sr = reversed.s_bar_matrix();
    assert!((trace(&sr) / trace(&s1) - 1.0).abs() < 1e-9);
    assert!(a.com[1] > 0.005, "the unbalance is on +y: {:?}", a.com);
}

fn build_half(part: parts::Part) -> flexmb_element::LinearSuperelement {
    let model = part.mesh.assemble("shaft").unwrap();
    build(&model, &part.settings).unwrap().data
}
