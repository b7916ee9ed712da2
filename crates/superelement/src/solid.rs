//! A small built-in linear solid FE so that tests and examples need no external
//! package: 20-node serendipity hexahedra (quadratic, full 3 × 3 × 3 Gauss
//! integration for stiffness and consistent mass) and a structured mesher for
//! parts made of axis-aligned boxes (a tensor grid with a cell mask, so unions of
//! boxes are conforming) and mapped blocks such as cylinders.
//!
//! Choice: the 20-node hexahedron rather than the 8-node one with incompatible
//! modes, because it represents bending and torsion well with one or two
//! elements through a thin wall, has a consistent mass that is exact for rigid
//! motions, and places mid-side nodes on curved boundaries.

use crate::geometry::{shape, SolidKind};
use crate::model::{DofMap, FeModel, SolidElements};
use crate::Error;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use flexmb_element::Material;
use std::collections::HashMap;

/// Natural coordinates of the 20 nodes: indices (a, b, c) ∈ {0, 1, 2}³ of the
/// quadratic grid of the element with at most one index equal to 1; the
/// natural coordinate is index − 1.
pub const HEX20_LOCAL: [[usize; 3]; 20] = [
    [0, 0, 0],
    [2, 0, 0],
    [2, 2, 0],
    [0, 2, 0],
    [0, 0, 2],
    [2, 0, 2],
    [2, 2, 2],
    [0, 2, 2],
    [1, 0, 0],
    [2, 1, 0],
    [1, 2, 0],
    [0, 1, 0],
    [1, 0, 2],
    [2, 1, 2],
    [1, 2, 2],
    [0, 1, 2],
    [0, 0, 1],
    [2, 0, 1],
    [2, 2, 1],
    [0, 2, 1],
];

/// Shape functions and their natural derivatives at (ξ, η, ζ).
pub fn hex20_shape(xi: [f64; 3]) -> ([f64; 20], [[f64; 3]; 20]) {
    let mut n = [0.0; 20];
    let mut dn = [[0.0; 3]; 20];
    for (k, loc) in HEX20_LOCAL.iter().enumerate() {
        let c = [
            loc[0] as f64 - 1.0,
            loc[1] as f64 - 1.0,
            loc[2] as f64 - 1.0,
        ];
        let zero = c.iter().position(|v| *v == 0.0);
        match zero {
            None => {
                let a = [1.0 + xi[0] * c[0], 1.0 + xi[1] * c[1], 1.0 + xi[2] * c[2]];
                let s = xi[0] * c[0] + xi[1] * c[1] + xi[2] * c[2] - 2.0;
                n[k] = 0.125 * a[0] * a[1] * a[2] * s;
                for d in 0..3 {
                    let (o1, o2) = ((d + 1) % 3, (d + 2) % 3);
                    dn[k][d] = 0.125 * c[d] * a[o1] * a[o2] * (s + a[d]);
                }
            }
            Some(z) => {
                let (o1, o2) = ((z + 1) % 3, (z + 2) % 3);
                let q = 1.0 - xi[z] * xi[z];
                let a1 = 1.0 + xi[o1] * c[o1];
                let a2 = 1.0 + xi[o2] * c[o2];
                n[k] = 0.25 * q * a1 * a2;
                dn[k][z] = 0.25 * (-2.0 * xi[z]) * a1 * a2;
                dn[k][o1] = 0.25 * q * c[o1] * a2;
                dn[k][o2] = 0.25 * q * a1 * c[o2];
            }
        }
    }
    (n, dn)
}

/// Element matrices of a 20-node hexahedron: stiffness 60 × 60 (row-major,
/// DOF 3a + d), the scalar consistent mass 20 × 20 (M_e = m ⊗ I3) and the
/// element volume; [`solid_matrices`] for this kind.
pub fn hex20_matrices(x: &[[f64; 3]; 20], mat: &Material) -> Result<ElementMatrices, String> {
    solid_matrices(SolidKind::Hex20, x, mat)
}

/// Element matrices of a solid element of any [`SolidKind`] with nodes `x`
/// in the Abaqus/CalculiX order: stiffness 3n × 3n (row-major, DOF 3a + d),
/// the scalar consistent mass n × n (M_e = m ⊗ I3) and the volume, with the
/// quadrature of [`stiffness_rule`]. For many elements use an
/// [`ElementIntegrator`], which evaluates the shape functions once per kind.
pub fn solid_matrices(
    kind: SolidKind,
    x: &[[f64; 3]],
    mat: &Material,
) -> Result<ElementMatrices, String> {
    ElementIntegrator::default().matrices(kind, x, mat)
}

/// The quadrature rule (natural coordinates, weights) of the built-in
/// elements' stiffness, CalculiX's (measured against `ccx` 2.20 on single
/// distorted elements: K and M equal to 1e-14), so that the built-in FE and
/// `--solver calculix` give the same matrices on one mesh: 3 × 3 × 3 Gauss
/// points on the 20-node hexahedron, 2 × 2 × 2 on the 8-node one, the
/// 4-point rule (a = 0.5854…, b = 0.1382…) on the 10-node tetrahedron, the
/// centroid on the 4-node one, the 3-point triangle rule (1/6, 1/6, 2/3)
/// × 3 Gauss points on the 15-node wedge and the centroid × 2 Gauss points
/// on the 6-node one. The mass takes the same rule (so does CalculiX),
/// except on the 4-node tetrahedron and the 6-node wedge, whose one point
/// in the triangle would lose the rigid-body inertia even of an undistorted
/// element: there the 4-point rule and the 3-point triangle rule × 2 Gauss
/// points (exact for the mass of affine elements, as the other rules are).
pub fn stiffness_rule(kind: SolidKind) -> Vec<([f64; 3], f64)> {
    let g2 = 1.0 / 3f64.sqrt();
    let g3 = (0.6f64).sqrt();
    let gauss3 = [(-g3, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g3, 5.0 / 9.0)];
    let tri3 = [
        [1.0 / 6.0, 1.0 / 6.0],
        [2.0 / 3.0, 1.0 / 6.0],
        [1.0 / 6.0, 2.0 / 3.0],
    ];
    let mut out = Vec::new();
    match kind {
        SolidKind::Hex20 => {
            for &(a, wa) in &gauss3 {
                for &(b, wb) in &gauss3 {
                    for &(c, wc) in &gauss3 {
                        out.push(([a, b, c], wa * wb * wc));
                    }
                }
            }
        }
        SolidKind::Hex8 => {
            for c in [-g2, g2] {
                for b in [-g2, g2] {
                    for a in [-g2, g2] {
                        out.push(([a, b, c], 1.0));
                    }
                }
            }
        }
        SolidKind::Tet10 => out = tet4_point_rule(),
        SolidKind::Tet4 => out.push(([0.25; 3], 1.0 / 6.0)),
        SolidKind::Wedge15 => {
            for &(c, wc) in &gauss3 {
                for p in tri3 {
                    out.push(([p[0], p[1], c], wc / 6.0));
                }
            }
        }
        SolidKind::Wedge6 => {
            for c in [-g2, g2] {
                out.push(([1.0 / 3.0, 1.0 / 3.0, c], 0.5));
            }
        }
    }
    out
}

/// The 4-point rule on the unit tetrahedron (exact to degree 2).
fn tet4_point_rule() -> Vec<([f64; 3], f64)> {
    let a = 0.585_410_196_624_968_5;
    let b = 0.138_196_601_125_010_5;
    [[b, b, b], [a, b, b], [b, a, b], [b, b, a]]
        .into_iter()
        .map(|p| (p, 1.0 / 24.0))
        .collect()
}

/// The mass rule (see [`stiffness_rule`]).
fn mass_rule(kind: SolidKind) -> Vec<([f64; 3], f64)> {
    match kind {
        SolidKind::Tet4 => tet4_point_rule(),
        SolidKind::Wedge6 => {
            let g2 = 1.0 / 3f64.sqrt();
            let tri3 = [
                [1.0 / 6.0, 1.0 / 6.0],
                [2.0 / 3.0, 1.0 / 6.0],
                [1.0 / 6.0, 2.0 / 3.0],
            ];
            [-g2, g2]
                .iter()
                .flat_map(|&c| tri3.map(|p| ([p[0], p[1], c], 1.0 / 6.0)))
                .collect()
        }
        k => stiffness_rule(k),
    }
}

/// Quadrature weight, shape function values and natural derivatives at one
/// point of a rule.
type RulePoint = (f64, Vec<f64>, Vec<[f64; 3]>);

/// Element matrices with the shape functions at the quadrature points
/// evaluated once per element kind.
#[derive(Default)]
pub struct ElementIntegrator {
    tables: Vec<(SolidKind, Vec<RulePoint>, Vec<RulePoint>)>,
}

impl ElementIntegrator {
    fn tables(&mut self, kind: SolidKind) -> (&[RulePoint], &[RulePoint]) {
        let i = match self.tables.iter().position(|(k, _, _)| *k == kind) {
            Some(i) => i,
            None => {
                let eval = |rule: Vec<([f64; 3], f64)>| -> Vec<RulePoint> {
                    rule.into_iter()
                        .map(|(p, w)| {
                            let (n, dn) = shape(kind, p);
                            (w, n, dn)
                        })
                        .collect()
                };
                self.tables
                    .push((kind, eval(stiffness_rule(kind)), eval(mass_rule(kind))));
                self.tables.len() - 1
            }
        };
        let (_, k, m) = &self.tables[i];
        (k, m)
    }

    /// See [`solid_matrices`]. Errors: a wrong node count, a non-positive
    /// Jacobian determinant (an inverted or degenerate element).
    pub fn matrices(
        &mut self,
        kind: SolidKind,
        x: &[[f64; 3]],
        mat: &Material,
    ) -> Result<ElementMatrices, String> {
        let n = kind.n_nodes();
        if x.len() != n {
            return Err(format!("{} nodes given, a {kind:?} has {n}", x.len()));
        }
        let nu = mat.poisson();
        let lam = mat.e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = mat.g;
        let (k_rule, m_rule) = self.tables(kind);
        let mut k = vec![0.0; 9 * n * n];
        let mut m = vec![0.0; n * n];
        let mut vol = 0.0;
        let mut g = vec![[0.0; 3]; n];
        for (w, _, dn) in k_rule {
            let (jac, det) = jacobian(x, dn)?;
            let inv = inv3(&jac, det);
            // g_p = J⁻ᵀ dN_p: ∂N/∂x_r = Σ_s ∂N/∂ξ_s ∂ξ_s/∂x_r = Σ_s dn[s] inv[s][r]
            for p in 0..n {
                for r in 0..3 {
                    g[p][r] = (0..3).map(|s| dn[p][s] * inv[s][r]).sum();
                }
            }
            let wd = w * det;
            vol += wd;
            for p in 0..n {
                for q in 0..n {
                    let gg = g[p][0] * g[q][0] + g[p][1] * g[q][1] + g[p][2] * g[q][2];
                    for r in 0..3 {
                        for s in 0..3 {
                            let mut v = lam * g[p][r] * g[q][s] + mu * g[p][s] * g[q][r];
                            if r == s {
                                v += mu * gg;
                            }
                            k[(3 * p + r) * 3 * n + 3 * q + s] += wd * v;
                        }
                    }
                }
            }
        }
        for (w, sh, dn) in m_rule {
            let (_, det) = jacobian(x, dn)?;
            let wd = w * det;
            for p in 0..n {
                for q in 0..n {
                    m[p * n + q] += wd * mat.rho * sh[p] * sh[q];
                }
            }
        }
        Ok((k, m, vol))
    }
}

/// The Jacobian ∂x_r/∂ξ_s of nodes `x` with natural derivatives `dn` and its
/// determinant, which must be positive.
fn jacobian(x: &[[f64; 3]], dn: &[[f64; 3]]) -> Result<([[f64; 3]; 3], f64), String> {
    let mut jac = [[0.0; 3]; 3];
    for (xp, dp) in x.iter().zip(dn) {
        for r in 0..3 {
            for s in 0..3 {
                jac[r][s] += xp[r] * dp[s];
            }
        }
    }
    let det = jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1])
        - jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0])
        + jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]);
    if !(det > 0.0) {
        return Err(format!(
            "non-positive Jacobian determinant {det:e} at a quadrature point (an inverted or degenerate element)"
        ));
    }
    Ok((jac, det))
}

fn inv3(a: &[[f64; 3]; 3], det: f64) -> [[f64; 3]; 3] {
    let mut r = [[0.0; 3]; 3];
    r[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / det;
    r[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
    r[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
    r[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / det;
    r[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
    r[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
    r[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / det;
    r[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
    r[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
    r
}

/// Element stiffness (3n × 3n, row-major, DOF 3a + d), scalar consistent
/// mass (n × n) and volume.
pub type ElementMatrices = (Vec<f64>, Vec<f64>, f64);

/// An axis-aligned box of one material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    /// Lower corner (m).
    pub min: [f64; 3],
    /// Upper corner (m).
    pub max: [f64; 3],
    /// Index into the mesh's materials.
    pub material: usize,
}

/// A 20-node hexahedral mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Node coordinates (m); node labels are index + 1.
    pub coords: Vec<[f64; 3]>,
    /// Element connectivity (node indices) in [`HEX20_LOCAL`] order.
    pub elements: Vec<[usize; 20]>,
    /// Element material indices.
    pub element_material: Vec<usize>,
    /// Materials.
    pub materials: Vec<Material>,
}

impl Mesh {
    /// Meshes the union of axis-aligned boxes on one tensor grid: grid lines at
    /// every box bound, each interval divided into elements no longer than
    /// `h[axis]`. A cell belongs to the first box containing its centre.
    pub fn boxes(blocks: &[Block], materials: &[Material], h: [f64; 3]) -> Result<Self, Error> {
        if blocks.is_empty() {
            return Err(Error::Spec("no boxes to mesh".into()));
        }
        for b in blocks {
            if (0..3).any(|d| !(b.max[d] > b.min[d])) || b.material >= materials.len() {
                return Err(Error::Spec(format!(
                    "invalid box {b:?} ({} materials)",
                    materials.len()
                )));
            }
        }
        if h.iter().any(|v| !(*v > 0.0)) {
            return Err(Error::Spec(format!(
                "element sizes must be positive, got {h:?}"
            )));
        }
        let lines: Vec<Vec<f64>> = (0..3)
            .map(|d| {
                let mut b: Vec<f64> = blocks
                    .iter()
                    .flat_map(|bl| [bl.min[d], bl.max[d]])
                    .collect();
                b.sort_by(f64::total_cmp);
                let span = b[b.len() - 1] - b[0];
                b.dedup_by(|x, y| (*x - *y).abs() <= 1e-12 * span);
                let mut out = vec![b[0]];
                for w in b.windows(2) {
                    let n = ((w[1] - w[0]) / h[d] - 1e-9).ceil().max(1.0) as usize;
                    for i in 1..=n {
                        out.push(w[0] + (w[1] - w[0]) * i as f64 / n as f64);
                    }
                }
                out
            })
            .collect();
        let nc = [lines[0].len() - 1, lines[1].len() - 1, lines[2].len() - 1];
        let mut cells = Vec::new();
        for k in 0..nc[2] {
            for j in 0..nc[1] {
                for i in 0..nc[0] {
                    let c = [
                        0.5 * (lines[0][i] + lines[0][i + 1]),
                        0.5 * (lines[1][j] + lines[1][j + 1]),
                        0.5 * (lines[2][k] + lines[2][k + 1]),
                    ];
                    if let Some(b) = blocks
                        .iter()
                        .find(|b| (0..3).all(|d| c[d] > b.min[d] && c[d] < b.max[d]))
                    {
                        cells.push(([i, j, k], b.material));
                    }
                }
            }
        }
        let coord = |d: usize, qi: usize| {
            let i = qi / 2;
            if qi % 2 == 0 {
                lines[d][i]
            } else {
                0.5 * (lines[d][i] + lines[d][i + 1])
            }
        };
        let mut index: HashMap<[usize; 3], usize> = HashMap::new();
        let mut mesh = Mesh {
            materials: materials.to_vec(),
            ..Default::default()
        };
        // number nodes in lexicographic (z, y, x) order for a tidy numbering
        let mut keys: Vec<[usize; 3]> = Vec::new();
        for (c, _) in &cells {
            for loc in HEX20_LOCAL {
                keys.push([2 * c[0] + loc[0], 2 * c[1] + loc[1], 2 * c[2] + loc[2]]);
            }
        }
        keys.sort_by_key(|q| (q[2], q[1], q[0]));
        keys.dedup();
        for q in keys {
            index.insert(q, mesh.coords.len());
            mesh.coords
                .push([coord(0, q[0]), coord(1, q[1]), coord(2, q[2])]);
        }
        for (c, m) in cells {
            let el = std::array::from_fn(|a| {
                let loc = HEX20_LOCAL[a];
                index[&[2 * c[0] + loc[0], 2 * c[1] + loc[1], 2 * c[2] + loc[2]]]
            });
            mesh.elements.push(el);
            mesh.element_material.push(m);
        }
        Ok(mesh)
    }

    /// A structured block of `n[0] × n[1] × n[2]` elements whose nodes are the
    /// image of the unit cube's quadratic grid under `map` (e.g. a cylinder).
    pub fn mapped(
        n: [usize; 3],
        map: impl Fn([f64; 3]) -> [f64; 3],
        material: Material,
    ) -> Result<Self, Error> {
        if n.contains(&0) {
            return Err(Error::Spec(format!(
                "element counts must be positive, got {n:?}"
            )));
        }
        let mut mesh = Mesh {
            materials: vec![material],
            ..Default::default()
        };
        let nq = [2 * n[0] + 1, 2 * n[1] + 1, 2 * n[2] + 1];
        let mut index = HashMap::new();
        for k in 0..nq[2] {
            for j in 0..nq[1] {
                for i in 0..nq[0] {
                    let ones = [i % 2, j % 2, k % 2].iter().filter(|v| **v == 1).count();
                    if ones >= 2 {
                        continue;
                    }
                    index.insert([i, j, k], mesh.coords.len());
                    mesh.coords.push(map([
                        i as f64 / (nq[0] - 1) as f64,
                        j as f64 / (nq[1] - 1) as f64,
                        k as f64 / (nq[2] - 1) as f64,
                    ]));
                }
            }
        }
        for k in 0..n[2] {
            for j in 0..n[1] {
                for i in 0..n[0] {
                    let el = std::array::from_fn(|a| {
                        let loc = HEX20_LOCAL[a];
                        index[&[2 * i + loc[0], 2 * j + loc[1], 2 * k + loc[2]]]
                    });
                    mesh.elements.push(el);
                    mesh.element_material.push(0);
                }
            }
        }
        Ok(mesh)
    }

    /// A solid cylinder along the global x axis: axis through (x0, yc, zc),
    /// length `len`, diameter `d`; the cross-section square [−1, 1]² is mapped to
    /// the disc by (u, v) ↦ (u √(1 − v²/2), v √(1 − u²/2)).
    pub fn cylinder_x(
        x0: f64,
        center: [f64; 2],
        len: f64,
        d: f64,
        n_section: usize,
        n_len: usize,
        material: Material,
    ) -> Result<Self, Error> {
        let r = 0.5 * d;
        Self::mapped(
            [n_len, n_section, n_section],
            |p| {
                let u = 2.0 * p[1] - 1.0;
                let v = 2.0 * p[2] - 1.0;
                [
                    x0 + len * p[0],
                    center[0] + r * u * (1.0 - 0.5 * v * v).sqrt(),
                    center[1] + r * v * (1.0 - 0.5 * u * u).sqrt(),
                ]
            },
            material,
        )
    }

    /// Appends another mesh, merging nodes closer than `tol`.
    pub fn merge(mut self, other: &Mesh, tol: f64) -> Self {
        let key =
            |p: &[f64; 3]| -> [i64; 3] { std::array::from_fn(|d| (p[d] / tol).floor() as i64) };
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, p) in self.coords.iter().enumerate() {
            grid.entry(key(p)).or_default().push(i);
        }
        let mut map = Vec::with_capacity(other.coords.len());
        for p in &other.coords {
            let k = key(p);
            let mut found = None;
            'outer: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(v) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            for &i in v {
                                let q = self.coords[i];
                                if (0..3).all(|d| (q[d] - p[d]).abs() <= tol) {
                                    found = Some(i);
                                    break 'outer;
                                }
                            }
                        }
                    }
                }
            }
            let idx = found.unwrap_or_else(|| {
                self.coords.push(*p);
                let i = self.coords.len() - 1;
                grid.entry(k).or_default().push(i);
                i
            });
            map.push(idx);
        }
        let m0 = self.materials.len();
        self.materials.extend(other.materials.iter().copied());
        for (e, &m) in other.elements.iter().zip(&other.element_material) {
            self.elements.push(std::array::from_fn(|a| map[e[a]]));
            self.element_material.push(m0 + m);
        }
        self
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.coords.len()
    }

    /// Assembles K and M (consistent) into an [`FeModel`] with all 3 DOFs per
    /// node (node-major equations) and the mesh volume set
    /// ([`SolidMesh::assemble`]).
    pub fn assemble(&self, name: &str) -> Result<FeModel, Error> {
        SolidMesh {
            ids: (1..=self.coords.len() as u64).collect(),
            coords: self.coords.clone(),
            kinds: vec![SolidKind::Hex20; self.elements.len()],
            elements: self.elements.iter().map(|e| e.to_vec()).collect(),
            element_ids: (1..=self.elements.len() as u64).collect(),
            element_material: self.element_material.clone(),
            materials: self.materials.clone(),
        }
        .assemble(name, "the materials of the built-in mesh")
    }
}

/// A mesh of solid elements of any [`SolidKind`] (nodes in the
/// Abaqus/CalculiX order), one material per element, for the built-in FE.
#[derive(Clone, Debug, Default)]
pub struct SolidMesh {
    /// Node labels (for messages and the model's node ids).
    pub ids: Vec<u64>,
    /// Node coordinates (m).
    pub coords: Vec<[f64; 3]>,
    /// Element kinds.
    pub kinds: Vec<SolidKind>,
    /// Element nodes (indices into `coords`), in the kind's order.
    pub elements: Vec<Vec<usize>>,
    /// Element labels (for messages).
    pub element_ids: Vec<u64>,
    /// Material index of each element.
    pub element_material: Vec<usize>,
    /// Materials.
    pub materials: Vec<Material>,
}

impl SolidMesh {
    /// Assembles K and M (consistent, [`solid_matrices`]) into an
    /// [`FeModel`] with all 3 DOFs of every node (node-major equations), the
    /// mesh volume and the solid elements with their densities (for the
    /// checks of the build; `density_source` says where the densities come
    /// from in messages). Every node must belong to an element.
    pub fn assemble(&self, name: &str, density_source: &str) -> Result<FeModel, Error> {
        let nn = self.coords.len();
        let ne = self.elements.len();
        if self.ids.len() != nn
            || self.kinds.len() != ne
            || self.element_ids.len() != ne
            || self.element_material.len() != ne
        {
            return Err(Error::SizeMismatch(format!(
                "mesh {name}: {nn} nodes with {} labels, {ne} elements with {} kinds, {} labels and {} materials",
                self.ids.len(),
                self.kinds.len(),
                self.element_ids.len(),
                self.element_material.len()
            )));
        }
        for m in &self.materials {
            m.validate()?;
            let nu = m.poisson();
            if !(nu > -1.0 && nu < 0.5) {
                return Err(Error::Spec(format!(
                    "material {m:?} has Poisson's ratio {nu}, outside (−1, 0.5)"
                )));
            }
        }
        for (e, nodes) in self.elements.iter().enumerate() {
            let bad = if nodes.len() != self.kinds[e].n_nodes() {
                Some(format!(
                    "has {} nodes, a {:?} has {}",
                    nodes.len(),
                    self.kinds[e],
                    self.kinds[e].n_nodes()
                ))
            } else if let Some(&i) = nodes.iter().find(|&&i| i >= nn) {
                Some(format!(
                    "refers to node index {i}, but there are {nn} nodes"
                ))
            } else if self.element_material[e] >= self.materials.len() {
                Some(format!(
                    "has material {} of {}",
                    self.element_material[e],
                    self.materials.len()
                ))
            } else {
                None
            };
            if let Some(msg) = bad {
                return Err(Error::Spec(format!(
                    "mesh {name}: element {} {msg}",
                    self.element_ids[e]
                )));
            }
        }
        // node adjacency
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); nn];
        for e in &self.elements {
            for &a in e {
                adj[a].extend_from_slice(e);
            }
        }
        for (a, list) in adj.iter_mut().enumerate() {
            if list.is_empty() {
                return Err(Error::Spec(format!(
                    "mesh {name}: node {} belongs to no element (it would have no stiffness)",
                    self.ids[a]
                )));
            }
            list.sort_unstable();
            list.dedup();
        }
        // upper CSC pattern over eq 3 n + d
        let neq = 3 * nn;
        let mut col_ptr = Vec::with_capacity(neq + 1);
        col_ptr.push(0usize);
        let mut row_idx = Vec::new();
        for b in 0..nn {
            for db in 0..3 {
                let col = 3 * b + db;
                for &a in &adj[b] {
                    if a > b {
                        break;
                    }
                    for da in 0..3 {
                        let row = 3 * a + da;
                        if row <= col {
                            row_idx.push(row);
                        }
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        let mut kv = vec![0.0; row_idx.len()];
        let mut mv = vec![0.0; row_idx.len()];
        // structured meshes repeat elements: their matrices are computed once
        let mut cache: HashMap<(Vec<i64>, SolidKind, usize), ElementMatrices> = HashMap::new();
        let mut integrator = ElementIntegrator::default();
        let mut volume = 0.0;
        for (ei, e) in self.elements.iter().enumerate() {
            let kind = self.kinds[ei];
            let x: Vec<[f64; 3]> = e.iter().map(|&a| self.coords[a]).collect();
            let scale = (0..3)
                .map(|d| {
                    let (lo, hi) = x
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                            (lo.min(p[d]), hi.max(p[d]))
                        });
                    hi - lo
                })
                .fold(0.0, f64::max)
                .max(1e-300);
            let x0 = x[0];
            let key: Vec<i64> = x
                .iter()
                .flat_map(|p| {
                    (0..3).map(move |d| ((p[d] - x0[d]) / (scale * 1e-10)).round() as i64)
                })
                .chain(std::iter::once(scale.to_bits() as i64 >> 20))
                .collect();
            let mat = self.element_material[ei];
            let entry = match cache.get(&(key.clone(), kind, mat)) {
                Some(v) => v,
                None => {
                    let v = integrator
                        .matrices(kind, &x, &self.materials[mat])
                        .map_err(|s| {
                            Error::Spec(format!(
                                "mesh {name}: element {} ({kind:?}) is invalid: {s}",
                                self.element_ids[ei]
                            ))
                        })?;
                    cache.entry((key, kind, mat)).or_insert(v)
                }
            };
            let (ke, me, vol) = entry;
            volume += vol;
            let n = e.len();
            for p in 0..n {
                for q in 0..n {
                    let (a, b) = (e[p], e[q]);
                    if a > b {
                        continue;
                    }
                    for dq in 0..3 {
                        let col = 3 * b + dq;
                        let rows = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                        for dp in 0..3 {
                            let row = 3 * a + dp;
                            if row > col {
                                continue;
                            }
                            let pos = col_ptr[col] + rows.binary_search(&row).expect("pattern");
                            let kval = ke[(3 * p + dp) * 3 * n + 3 * q + dq];
                            let mval = if dp == dq { me[p * n + q] } else { 0.0 };
                            kv[pos] += kval;
                            mv[pos] += mval;
                        }
                    }
                }
            }
        }
        let sym = SymbolicSparseColMat::new_checked(neq, neq, col_ptr, None, row_idx);
        let k = SparseColMat::new(sym.clone(), kv);
        let m = SparseColMat::new(sym, mv);
        let mut model = FeModel::new(
            name,
            self.ids.clone(),
            self.coords.clone(),
            DofMap::full(nn),
            k.as_ref(),
            m.as_ref(),
        )?;
        model.volume = Some(volume);
        model.solid = Some(SolidElements {
            kinds: self.kinds.clone(),
            nodes: self.elements.clone(),
            density: self
                .element_material
                .iter()
                .map(|&m| Some(self.materials[m].rho))
                .collect(),
            density_source: density_source.to_string(),
            couplings: Vec::new(),
        });
        Ok(model)
    }
}
