//! Volume moments of solid elements over their isoparametric geometry:
//! ∫ dV, ∫ (x − c) dV and ∫ (x − c)(x − c)ᵀ dV, for the rigid-body check of a
//! mass matrix against its mesh (a consistent mass applied to rigid fields
//! gives ρ times exactly these integrals, because the shape functions
//! interpolate rigid fields exactly).
//!
//! Node orders are those of Abaqus and CalculiX (C3D4, C3D10, C3D8, C3D20,
//! C3D6, C3D15). Quadrature: 4 Gauss–Legendre points per direction on the
//! hexahedron, and on the collapsed (Duffy) coordinates of the tetrahedron
//! and of the wedge's triangle. That is exact for straight-edged elements (the
//! integrands are then polynomials of degree ≤ 4 per direction) and accurate
//! to the quadrature error for curved ones.

use crate::solid::hex20_shape;

/// A solid element type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SolidKind {
    /// 4-node tetrahedron (C3D4).
    Tet4,
    /// 10-node tetrahedron (C3D10).
    Tet10,
    /// 8-node hexahedron (C3D8, C3D8R, C3D8I).
    Hex8,
    /// 20-node hexahedron (C3D20, C3D20R).
    Hex20,
    /// 6-node wedge (C3D6).
    Wedge6,
    /// 15-node wedge (C3D15).
    Wedge15,
}

impl SolidKind {
    /// The kind of an Abaqus/CalculiX element type name (C3D10, C3D20R, …;
    /// longest prefix first, so C3D10 is not taken for C3D1); `None` for other
    /// types.
    pub fn from_type(ty: &str) -> Option<Self> {
        let t = ty.to_ascii_uppercase();
        [
            ("C3D10", SolidKind::Tet10),
            ("C3D15", SolidKind::Wedge15),
            ("C3D20", SolidKind::Hex20),
            ("C3D4", SolidKind::Tet4),
            ("C3D6", SolidKind::Wedge6),
            ("C3D8", SolidKind::Hex8),
        ]
        .iter()
        .find(|(p, _)| t.starts_with(p))
        .map(|&(_, k)| k)
    }

    /// Number of nodes.
    pub fn n_nodes(self) -> usize {
        match self {
            SolidKind::Tet4 => 4,
            SolidKind::Tet10 => 10,
            SolidKind::Hex8 => 8,
            SolidKind::Hex20 => 20,
            SolidKind::Wedge6 => 6,
            SolidKind::Wedge15 => 15,
        }
    }

    /// The VTK cell type of this kind; its nodes in VTK's order are
    /// [`vtk_order`](Self::vtk_order).
    pub fn vtk_type(self) -> u8 {
        match self {
            SolidKind::Tet4 => 10,
            SolidKind::Tet10 => 24,
            SolidKind::Hex8 => 12,
            SolidKind::Hex20 => 25,
            SolidKind::Wedge6 => 13,
            SolidKind::Wedge15 => 26,
        }
    }
}

/// The edges of the midside nodes of the quadratic kinds in the
/// Abaqus/CalculiX order: midside node `corners + k` lies on the edge
/// between the corners `midside_edges()[k]`.
const TET10_EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)];
const HEX20_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (1, 2),
    (2, 3),
    (3, 0),
    (4, 5),
    (5, 6),
    (6, 7),
    (7, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];
const WEDGE15_EDGES: [(usize, usize); 9] = [
    (0, 1),
    (1, 2),
    (2, 0),
    (3, 4),
    (4, 5),
    (5, 3),
    (0, 3),
    (1, 4),
    (2, 5),
];

impl SolidKind {
    /// Every kind.
    pub const ALL: [SolidKind; 6] = [
        SolidKind::Tet4,
        SolidKind::Tet10,
        SolidKind::Hex8,
        SolidKind::Hex20,
        SolidKind::Wedge6,
        SolidKind::Wedge15,
    ];

    /// The corner pairs of the midside nodes, in the Abaqus/CalculiX order
    /// (empty for the linear kinds): node `n_nodes() − len + k` is the
    /// middle of edge k.
    pub fn midside_edges(self) -> &'static [(usize, usize)] {
        match self {
            SolidKind::Tet10 => &TET10_EDGES,
            SolidKind::Hex20 => &HEX20_EDGES,
            SolidKind::Wedge15 => &WEDGE15_EDGES,
            _ => &[],
        }
    }
}

/// Abaqus C3D6 → VTK_WEDGE: VTK's base triangle (0, 1, 2) turns the other
/// way (its right-hand normal points away from the top face (3, 4, 5),
/// vtkWedge's documentation and face table), Abaqus's 1-2-3 towards it.
const WEDGE6_TO_VTK: [usize; 6] = [0, 2, 1, 3, 5, 4];
/// Abaqus C3D15 → VTK_QUADRATIC_WEDGE: the corners turned as for the
/// wedge, then VTK's midsides on its edges (0,1), (1,2), (2,0), (3,4),
/// (4,5), (5,3), (0,3), (1,4), (2,5).
const WEDGE15_TO_VTK: [usize; 15] = [0, 2, 1, 3, 5, 4, 8, 7, 6, 11, 10, 9, 12, 14, 13];
const IDENTITY: [usize; 20] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19,
];

impl SolidKind {
    /// The node order of the VTK cell ([`vtk_type`](Self::vtk_type)): VTK
    /// node i is node `vtk_order()[i]` of the Abaqus/CalculiX order. The
    /// tetrahedra and hexahedra have the same order in both (corners, then
    /// the edge midsides in the same edge order); the wedges do not: VTK's
    /// base triangle turns the other way.
    pub fn vtk_order(self) -> &'static [usize] {
        match self {
            SolidKind::Wedge6 => &WEDGE6_TO_VTK,
            SolidKind::Wedge15 => &WEDGE15_TO_VTK,
            k => &IDENTITY[..k.n_nodes()],
        }
    }
}

/// Volume moments about a point c: ∫ dV, ∫ (x − c) dV, ∫ (x − c)(x − c)ᵀ dV.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// Volume (m³), or mass when weighted by a density.
    pub volume: f64,
    /// First moment about c.
    pub first: [f64; 3],
    /// Second moment about c (symmetric).
    pub second: [[f64; 3]; 3],
}

impl Moments {
    /// Adds `w` times `other`.
    pub fn add_scaled(&mut self, other: &Moments, w: f64) {
        self.volume += w * other.volume;
        for i in 0..3 {
            self.first[i] += w * other.first[i];
            for j in 0..3 {
                self.second[i][j] += w * other.second[i][j];
            }
        }
    }

    /// Mass, centre of mass (relative to c) and the inertia tensor about the
    /// centre of mass of a body whose mass moments these are.
    pub fn rigid_body(&self) -> (f64, [f64; 3], [[f64; 3]; 3]) {
        let m = self.volume;
        let com: [f64; 3] = std::array::from_fn(|i| self.first[i] / m);
        // second moment about the centre of mass, then J = tr(S) I − S
        let s: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| self.second[i][j] - m * com[i] * com[j])
        });
        let tr = s[0][0] + s[1][1] + s[2][2];
        let j = std::array::from_fn(|i| {
            std::array::from_fn(|k| if i == k { tr - s[i][k] } else { -s[i][k] })
        });
        (m, com, j)
    }
}

/// 4-point Gauss–Legendre rule on [−1, 1].
const GAUSS4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

/// The same rule mapped to [0, 1] (points, weights).
fn gauss01() -> [(f64, f64); 4] {
    GAUSS4.map(|(p, w)| (0.5 * (1.0 + p), 0.5 * w))
}

/// Quadrature points (natural coordinates) and weights on the reference
/// element of `kind`: [−1, 1]³ for hexahedra, the unit tetrahedron
/// (ξ, η, ζ ≥ 0, ξ + η + ζ ≤ 1), the unit triangle × [−1, 1] for wedges.
fn rule(kind: SolidKind) -> Vec<([f64; 3], f64)> {
    let mut out = Vec::with_capacity(64);
    match kind {
        SolidKind::Hex8 | SolidKind::Hex20 => {
            for &(a, wa) in &GAUSS4 {
                for &(b, wb) in &GAUSS4 {
                    for &(c, wc) in &GAUSS4 {
                        out.push(([a, b, c], wa * wb * wc));
                    }
                }
            }
        }
        SolidKind::Tet4 | SolidKind::Tet10 => {
            // ξ = u, η = (1 − u) v, ζ = (1 − u)(1 − v) w; Jacobian (1 − u)² (1 − v)
            for &(u, wu) in &gauss01() {
                for &(v, wv) in &gauss01() {
                    for &(w, ww) in &gauss01() {
                        let p = [u, (1.0 - u) * v, (1.0 - u) * (1.0 - v) * w];
                        out.push((p, wu * wv * ww * (1.0 - u) * (1.0 - u) * (1.0 - v)));
                    }
                }
            }
        }
        SolidKind::Wedge6 | SolidKind::Wedge15 => {
            // ξ = u, η = (1 − u) v; Jacobian (1 − u); ζ ∈ [−1, 1]
            for &(u, wu) in &gauss01() {
                for &(v, wv) in &gauss01() {
                    for &(z, wz) in &GAUSS4 {
                        out.push(([u, (1.0 - u) * v, z], wu * wv * wz * (1.0 - u)));
                    }
                }
            }
        }
    }
    out
}

/// A number with its gradient in the three natural coordinates (forward-mode
/// differentiation of the shape functions).
#[derive(Clone, Copy, Debug)]
struct D {
    v: f64,
    g: [f64; 3],
}

impl D {
    fn c(v: f64) -> Self {
        D { v, g: [0.0; 3] }
    }
    fn var(v: f64, k: usize) -> Self {
        let mut g = [0.0; 3];
        g[k] = 1.0;
        D { v, g }
    }
}

impl std::ops::Add for D {
    type Output = D;
    fn add(self, o: D) -> D {
        D {
            v: self.v + o.v,
            g: std::array::from_fn(|k| self.g[k] + o.g[k]),
        }
    }
}

impl std::ops::Sub for D {
    type Output = D;
    fn sub(self, o: D) -> D {
        D {
            v: self.v - o.v,
            g: std::array::from_fn(|k| self.g[k] - o.g[k]),
        }
    }
}

impl std::ops::Mul for D {
    type Output = D;
    // the product rule: (a b)' = a' b + a b'
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, o: D) -> D {
        D {
            v: self.v * o.v,
            g: std::array::from_fn(|k| self.g[k] * o.v + self.v * o.g[k]),
        }
    }
}

impl std::ops::Mul<D> for f64 {
    type Output = D;
    fn mul(self, o: D) -> D {
        D {
            v: self * o.v,
            g: o.g.map(|x| self * x),
        }
    }
}

/// Shape functions of the tetrahedra and wedges (and the 8-node hexahedron)
/// with their natural derivatives, node order of Abaqus/CalculiX.
fn shape_d(kind: SolidKind, p: [f64; 3]) -> Vec<D> {
    let (x, y, z) = (D::var(p[0], 0), D::var(p[1], 1), D::var(p[2], 2));
    let one = D::c(1.0);
    match kind {
        SolidKind::Tet4 | SolidKind::Tet10 => {
            let l = [one - x - y - z, x, y, z];
            if kind == SolidKind::Tet4 {
                return l.to_vec();
            }
            let mut n: Vec<D> = l.iter().map(|&li| li * (2.0 * li - one)).collect();
            // mid-side nodes 5–10 on the edges 1-2, 2-3, 3-1, 1-4, 2-4, 3-4
            for (a, b) in [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)] {
                n.push(4.0 * (l[a] * l[b]));
            }
            n
        }
        SolidKind::Wedge6 | SolidKind::Wedge15 => {
            let l = [one - x - y, x, y];
            let (lo, hi) = (0.5 * (one - z), 0.5 * (one + z));
            if kind == SolidKind::Wedge6 {
                return l
                    .iter()
                    .map(|&li| li * lo)
                    .chain(l.iter().map(|&li| li * hi))
                    .collect();
            }
            let bubble = one - z * z;
            let mut n = Vec::with_capacity(15);
            // corners 1–3 at ζ = −1, 4–6 at ζ = +1
            for h in [lo, hi] {
                for &li in &l {
                    n.push(li * (2.0 * li - one) * h - 0.5 * (li * bubble));
                }
            }
            // mid-side nodes 7–9 (bottom edges 1-2, 2-3, 3-1), 10–12 (top), 13–15 (vertical)
            for h in [lo, hi] {
                for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                    n.push(4.0 * (l[a] * l[b] * h));
                }
            }
            for &li in &l {
                n.push(li * bubble);
            }
            n
        }
        SolidKind::Hex8 | SolidKind::Hex20 => {
            // corners in the order (−,−,−), (+,−,−), (+,+,−), (−,+,−), then ζ = +1
            let s = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
            let mut n = Vec::with_capacity(8);
            for c in [-1.0, 1.0] {
                for [a, b] in s {
                    n.push(0.125 * ((one + a * x) * (one + b * y) * (one + c * z)));
                }
            }
            n
        }
    }
}

impl std::ops::Mul<f64> for D {
    type Output = D;
    fn mul(self, o: f64) -> D {
        o * self
    }
}

/// Shape function values and natural derivatives at `p`.
pub(crate) fn shape(kind: SolidKind, p: [f64; 3]) -> (Vec<f64>, Vec<[f64; 3]>) {
    if kind == SolidKind::Hex20 {
        let (n, dn) = hex20_shape(p);
        return (n.to_vec(), dn.to_vec());
    }
    let d = shape_d(kind, p);
    (
        d.iter().map(|s| s.v).collect(),
        d.iter().map(|s| s.g).collect(),
    )
}

/// The volume moments of one element with node coordinates `x` (in the node
/// order of `kind`) about `c`, integrated over its isoparametric geometry with
/// |det J| (so that the orientation of the node numbering does not matter).
/// `None` if `x` has the wrong number of nodes. For many elements use an
/// [`Integrator`], which evaluates the shape functions once per type.
pub fn element_moments(kind: SolidKind, x: &[[f64; 3]], c: [f64; 3]) -> Option<Moments> {
    Integrator::default().moments(kind, x, c)
}

/// Quadrature weight, shape function values and natural derivatives at one
/// point of a rule.
type Point = (f64, Vec<f64>, Vec<[f64; 3]>);

/// Integrates [`element_moments`] with the shape functions at the quadrature
/// points evaluated once per element type.
#[derive(Default)]
pub struct Integrator {
    tables: Vec<(SolidKind, Vec<Point>)>,
}

impl Integrator {
    fn table(&mut self, kind: SolidKind) -> &[Point] {
        let i = match self.tables.iter().position(|(k, _)| *k == kind) {
            Some(i) => i,
            None => {
                let pts = rule(kind)
                    .into_iter()
                    .map(|(p, w)| {
                        let (n, dn) = shape(kind, p);
                        (w, n, dn)
                    })
                    .collect();
                self.tables.push((kind, pts));
                self.tables.len() - 1
            }
        };
        &self.tables[i].1
    }

    /// See [`element_moments`].
    pub fn moments(&mut self, kind: SolidKind, x: &[[f64; 3]], c: [f64; 3]) -> Option<Moments> {
        if x.len() != kind.n_nodes() {
            return None;
        }
        let mut out = Moments::default();
        for (w, n, dn) in self.table(kind) {
            let mut pos = [0.0; 3];
            let mut jac = [[0.0; 3]; 3];
            for a in 0..x.len() {
                for r in 0..3 {
                    let xr = x[a][r] - c[r];
                    pos[r] += n[a] * xr;
                    for s in 0..3 {
                        jac[r][s] += xr * dn[a][s];
                    }
                }
            }
            let det = jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1])
                - jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0])
                + jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]);
            let dv = w * det.abs();
            out.volume += dv;
            for r in 0..3 {
                out.first[r] += dv * pos[r];
                for s in 0..3 {
                    out.second[r][s] += dv * pos[r] * pos[s];
                }
            }
        }
        Some(out)
    }
}

/// Shape functions of a face (3- or 6-node triangle, 4- or 8-node
/// quadrilateral, nodes in the order of `flexmb_element::fe_faces`: corners,
/// then the midside nodes of the edges from corner i to i + 1) and their
/// derivatives in the face's two natural coordinates (a dual number's first
/// two components). The triangle is the unit triangle, the quadrilateral
/// [−1, 1]².
fn face_shape(n: usize, p: [f64; 2]) -> Option<Vec<D>> {
    let (x, y) = (D::var(p[0], 0), D::var(p[1], 1));
    let one = D::c(1.0);
    Some(match n {
        3 => vec![one - x - y, x, y],
        6 => {
            let l = [one - x - y, x, y];
            let mut s: Vec<D> = l.iter().map(|&li| li * (2.0 * li - one)).collect();
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                s.push(4.0 * (l[a] * l[b]));
            }
            s
        }
        4 | 8 => {
            let c = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
            let mut s: Vec<D> = c
                .iter()
                .map(|&[a, b]| 0.25 * ((one + a * x) * (one + b * y)))
                .collect();
            if n == 8 {
                for (i, si) in s.iter_mut().enumerate() {
                    let [a, b] = c[i];
                    *si = *si * (a * x + b * y - one);
                }
                // midsides of the edges 0-1 (y = −1), 1-2 (x = 1), 2-3 (y = 1), 3-0 (x = −1)
                s.push(0.5 * ((one - x * x) * (one - y)));
                s.push(0.5 * ((one + x) * (one - y * y)));
                s.push(0.5 * ((one - x * x) * (one + y)));
                s.push(0.5 * ((one - x) * (one - y * y)));
            }
            s
        }
        _ => return None,
    })
}

/// The area of a face with node positions `x` (3, 4, 6 or 8 nodes, in the
/// order of `flexmb_element::fe_faces`) and its first moment ∫ x dA, over its isoparametric
/// geometry (4 × 4 Gauss points, on the collapsed coordinates of the
/// triangle: exact for flat faces with straight edges). `None` for another
/// node count.
pub fn face_moments(x: &[[f64; 3]]) -> Option<(f64, [f64; 3])> {
    let tri = matches!(x.len(), 3 | 6);
    let mut area = 0.0;
    let mut first = [0.0; 3];
    for &(u, wu) in &GAUSS4 {
        for &(v, wv) in &GAUSS4 {
            let (p, w) = if tri {
                // ξ = a, η = (1 − a) b on [0, 1]²; Jacobian (1 − a)
                let (a, b) = (0.5 * (1.0 + u), 0.5 * (1.0 + v));
                ([a, (1.0 - a) * b], 0.25 * wu * wv * (1.0 - a))
            } else {
                ([u, v], wu * wv)
            };
            let s = face_shape(x.len(), p)?;
            let mut pos = [0.0; 3];
            let mut t = [[0.0; 3]; 2];
            for (si, xi) in s.iter().zip(x) {
                for r in 0..3 {
                    pos[r] += si.v * xi[r];
                    t[0][r] += si.g[0] * xi[r];
                    t[1][r] += si.g[1] * xi[r];
                }
            }
            let n = [
                t[0][1] * t[1][2] - t[0][2] * t[1][1],
                t[0][2] * t[1][0] - t[0][0] * t[1][2],
                t[0][0] * t[1][1] - t[0][1] * t[1][0],
            ];
            let da = w * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            area += da;
            for r in 0..3 {
                first[r] += da * pos[r];
            }
        }
    }
    Some((area, first))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A brick [0, a] × [0, b] × [0, d] as each element type (hexahedra
    /// directly, 6 tetrahedra or 2 wedges), with mid-side nodes at the edge
    /// midpoints, gives the brick's exact volume, centroid and second moments.
    #[test]
    fn straight_elements_integrate_exactly() {
        let (a, b, d) = (0.3, 0.2, 0.7);
        let corner = |i: usize| -> [f64; 3] {
            // (−,−,−), (+,−,−), (+,+,−), (−,+,−), then top
            let s = [[0.0, 0.0], [a, 0.0], [a, b], [0.0, b]];
            [s[i % 4][0], s[i % 4][1], if i < 4 { 0.0 } else { d }]
        };
        let mid =
            |p: [f64; 3], q: [f64; 3]| -> [f64; 3] { std::array::from_fn(|k| 0.5 * (p[k] + q[k])) };
        let c = [0.1, -0.3, 0.2];
        let exact = {
            let v = a * b * d;
            let lo = [-c[0], -c[1], -c[2]];
            let hi = [a - c[0], b - c[1], d - c[2]];
            let m1: [f64; 3] = std::array::from_fn(|k| 0.5 * (hi[k] * hi[k] - lo[k] * lo[k]));
            let m2: [f64; 3] = std::array::from_fn(|k| (hi[k].powi(3) - lo[k].powi(3)) / 3.0);
            let len = [a, b, d];
            let second = std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    if i == j {
                        m2[i] * v / len[i]
                    } else {
                        m1[i] * m1[j] * v / (len[i] * len[j])
                    }
                })
            });
            Moments {
                volume: v,
                first: std::array::from_fn(|k| m1[k] * v / len[k]),
                second,
            }
        };
        let check = |name: &str, m: Moments| {
            let e = (m.volume - exact.volume).abs() / exact.volume;
            assert!(e < 1e-14, "{name}: volume {} vs {}", m.volume, exact.volume);
            for i in 0..3 {
                assert!(
                    (m.first[i] - exact.first[i]).abs() < 1e-14,
                    "{name}: first {m:?}"
                );
                for j in 0..3 {
                    assert!(
                        (m.second[i][j] - exact.second[i][j]).abs() < 1e-14,
                        "{name}: second {m:?}"
                    );
                }
            }
        };
        // hexahedra
        let x8: Vec<[f64; 3]> = (0..8).map(corner).collect();
        check("C3D8", element_moments(SolidKind::Hex8, &x8, c).unwrap());
        let mut x20 = x8.clone();
        for &(p, q) in SolidKind::Hex20.midside_edges() {
            x20.push(mid(corner(p), corner(q)));
        }
        check("C3D20", element_moments(SolidKind::Hex20, &x20, c).unwrap());
        // six tetrahedra around the diagonal 0–6
        let mut t4 = Moments::default();
        let mut t10 = Moments::default();
        for q in [
            [0, 1, 2, 6],
            [0, 2, 3, 6],
            [0, 3, 7, 6],
            [0, 7, 4, 6],
            [0, 4, 5, 6],
            [0, 5, 1, 6],
        ] {
            let x: Vec<[f64; 3]> = q.iter().map(|&i| corner(i)).collect();
            t4.add_scaled(&element_moments(SolidKind::Tet4, &x, c).unwrap(), 1.0);
            let mut x10 = x.clone();
            for (p, r) in [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)] {
                x10.push(mid(x[p], x[r]));
            }
            t10.add_scaled(&element_moments(SolidKind::Tet10, &x10, c).unwrap(), 1.0);
        }
        check("C3D4", t4);
        check("C3D10", t10);
        // two wedges: triangles (0, 1, 2) and (0, 2, 3) extruded in z
        let mut w6 = Moments::default();
        let mut w15 = Moments::default();
        for tri in [[0, 1, 2], [0, 2, 3]] {
            let x: Vec<[f64; 3]> = tri
                .iter()
                .map(|&i| corner(i))
                .chain(tri.iter().map(|&i| corner(i + 4)))
                .collect();
            w6.add_scaled(&element_moments(SolidKind::Wedge6, &x, c).unwrap(), 1.0);
            let mut x15 = x.clone();
            for &(p, r) in SolidKind::Wedge15.midside_edges() {
                x15.push(mid(x[p], x[r]));
            }
            w15.add_scaled(&element_moments(SolidKind::Wedge15, &x15, c).unwrap(), 1.0);
        }
        check("C3D6", w6);
        check("C3D15", w15);
    }

    /// The shape functions of every kind and their derivatives sum to 1 and 0
    /// at every quadrature point.
    #[test]
    fn shape_functions_are_a_partition_of_unity() {
        for kind in SolidKind::ALL {
            for (p, _) in rule(kind) {
                let (n, dn) = shape(kind, p);
                assert_eq!(n.len(), kind.n_nodes());
                let s: f64 = n.iter().sum();
                assert!((s - 1.0).abs() < 1e-14, "{kind:?}: Σ N = {s}");
                for k in 0..3 {
                    let g: f64 = dn.iter().map(|d| d[k]).sum();
                    assert!(g.abs() < 1e-13, "{kind:?}: Σ dN/dξ{k} = {g}");
                }
            }
        }
    }

    /// Faces integrate exactly where they are flat with straight edges: a
    /// triangle and a quadrilateral (linear and quadratic, midside nodes at
    /// the middle) have their polygon's area and centroid; a quadratic
    /// quarter-circle edge gives the area of the curved face to the
    /// quadrature error.
    #[test]
    fn faces_give_their_area_and_centroid() {
        let mid =
            |a: [f64; 3], b: [f64; 3]| -> [f64; 3] { std::array::from_fn(|d| 0.5 * (a[d] + b[d])) };
        let t = [[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 3.0, 1.0]];
        let q = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let t6 = [
            t[0],
            t[1],
            t[2],
            mid(t[0], t[1]),
            mid(t[1], t[2]),
            mid(t[2], t[0]),
        ];
        let q8 = [
            q[0],
            q[1],
            q[2],
            q[3],
            mid(q[0], q[1]),
            mid(q[1], q[2]),
            mid(q[2], q[3]),
            mid(q[3], q[0]),
        ];
        for x in [&t[..], &t6[..]] {
            let (a, f) = face_moments(x).unwrap();
            assert!((a - 3.0).abs() < 1e-14, "{a}");
            let c = [f[0] / a, f[1] / a, f[2] / a];
            assert!(
                (c[0] - 2.0 / 3.0).abs() < 1e-14
                    && (c[1] - 1.0).abs() < 1e-14
                    && (c[2] - 1.0).abs() < 1e-14
            );
        }
        for x in [&q[..], &q8[..]] {
            let (a, f) = face_moments(x).unwrap();
            assert!((a - 2.0 * 2f64.sqrt()).abs() < 1e-14, "{a}");
            assert!((f[0] / a - 1.0).abs() < 1e-14 && (f[1] / a - 0.5).abs() < 1e-14);
        }
        // a quarter disc of radius 1 as one 6-node triangle, its arc's
        // midside node on the circle: the straight triangle (1/2) plus the
        // parabolic segment over the chord, 2/3 × chord × the midside node's
        // distance from the chord, √2 (s − 1/2) (planar: the area element
        // is a polynomial, integrated exactly)
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let disc = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.0, 0.0],
            [s, s, 0.0],
            [0.0, 0.5, 0.0],
        ];
        let (a, _) = face_moments(&disc).unwrap();
        let exact = 0.5 + 2.0 / 3.0 * 2f64.sqrt() * (2f64.sqrt() * (s - 0.5));
        assert!((a - exact).abs() < 1e-14, "{a} against {exact}");
        assert!(face_moments(&[[0.0; 3]; 5]).is_none());
    }
}
