//! The linear FE model the builder reduces: node coordinates, a DOF map
//! (node, direction) → equation and the sparse symmetric stiffness and mass
//! matrices over those equations (3 translational DOFs per node at most; DOFs
//! removed by boundary conditions are simply absent).
//!
//! The matrices are stored as faer CSC matrices holding the upper triangle
//! (with the diagonal); [`FeModel::new`] accepts upper, lower or full storage and
//! canonicalizes it, checking the symmetry of full input.

use crate::geometry::SolidKind;
use crate::Error;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, MatRef};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

const DIR: [&str; 3] = ["ux", "uy", "uz"];

/// The map between (node, direction) and equation numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    eq: Vec<[Option<usize>; 3]>,
    dofs: Vec<(usize, u8)>,
}

impl DofMap {
    /// All three directions of every node, node-major: equation 3 i + d.
    pub fn full(n_nodes: usize) -> Self {
        let eq = (0..n_nodes)
            .map(|i| [Some(3 * i), Some(3 * i + 1), Some(3 * i + 2)])
            .collect();
        let dofs = (0..n_nodes)
            .flat_map(|i| (0..3u8).map(move |d| (i, d)))
            .collect();
        Self { eq, dofs }
    }

    /// From the list of (node index, direction 0..3) in equation order.
    pub fn from_equations(n_nodes: usize, dofs: Vec<(usize, u8)>) -> Result<Self, Error> {
        let mut eq = vec![[None; 3]; n_nodes];
        for (e, &(n, d)) in dofs.iter().enumerate() {
            if n >= n_nodes || d > 2 {
                return Err(Error::SizeMismatch(format!(
                    "equation {e} refers to node index {n} direction {d}, but there are {n_nodes} nodes and 3 directions"
                )));
            }
            if let Some(prev) = eq[n][d as usize] {
                return Err(Error::SizeMismatch(format!(
                    "node index {n} direction {} has two equations, {prev} and {e}",
                    DIR[d as usize]
                )));
            }
            eq[n][d as usize] = Some(e);
        }
        Ok(Self { eq, dofs })
    }

    /// Number of equations.
    pub fn n_eq(&self) -> usize {
        self.dofs.len()
    }
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.eq.len()
    }
    /// The equation of node index `node` in direction `dir` (0, 1, 2), if present.
    pub fn eq(&self, node: usize, dir: usize) -> Option<usize> {
        self.eq.get(node).and_then(|e| e[dir])
    }
    /// The (node index, direction) of equation `e`.
    pub fn dof(&self, e: usize) -> (usize, u8) {
        self.dofs[e]
    }
    /// The equations of a node.
    pub fn node_eqs(&self, node: usize) -> [Option<usize>; 3] {
        self.eq[node]
    }
}

/// Where K, M, the DOF list and the node coordinates were read from, so that
/// a message can name the file at fault (empty when not read from a file).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sources {
    /// The stiffness file.
    pub k: String,
    /// The mass file.
    pub m: String,
    /// The DOF list (CalculiX `.dof` or its Matrix Market counterpart).
    pub dofs: String,
    /// The node coordinates (the `.inp` mesh or the node file).
    pub mesh: String,
}

impl Sources {
    fn name(what: &str, file: &str) -> String {
        if file.is_empty() {
            what.to_string()
        } else {
            format!("{what} ({file})")
        }
    }
    /// "K (job.sti)", or "K".
    pub fn k_name(&self) -> String {
        Self::name("K", &self.k)
    }
    /// "M (job.mas)", or "M".
    pub fn m_name(&self) -> String {
        Self::name("M", &self.m)
    }
    /// "the DOF list (job.dof)", or "the DOF list".
    pub fn dofs_name(&self) -> String {
        Self::name("the DOF list", &self.dofs)
    }
    /// "the mesh (job.inp)", or "the mesh".
    pub fn mesh_name(&self) -> String {
        Self::name("the mesh", &self.mesh)
    }
}

/// The solid elements K and M were assembled on (node indices of the model)
/// with their densities: the sparsity check and the rigid-body check of M
/// compare with them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolidElements {
    /// Element types.
    pub kinds: Vec<SolidKind>,
    /// Node indices (into the model's nodes) per element, in the type's order.
    pub nodes: Vec<Vec<usize>>,
    /// Density (kg/m³) per element, where known.
    pub density: Vec<Option<f64>>,
    /// Where the densities come from (for messages), e.g. "*DENSITY in job.inp".
    pub density_source: String,
    /// Keywords of the deck that couple nodes outside the elements (*EQUATION,
    /// *TIE, …) with their file and line; with any, M may couple nodes that
    /// share no element and the sparsity is checked against K instead.
    pub couplings: Vec<String>,
}

/// A named set of nodes of a model: a gmsh physical group (surface, curve,
/// point) or an Abaqus/CalculiX *NSET, for interfaces by name
/// ([`NodeSelection::Set`]).
#[derive(Clone, Debug, PartialEq)]
pub struct NodeSet {
    /// Its name (a gmsh physical group without a name is called by its
    /// tag, e.g. "7").
    pub name: String,
    /// What it is, for messages: "physical surface", "node set", ….
    pub what: String,
    /// The gmsh physical tag, if it is a physical group.
    pub tag: Option<i64>,
    /// Node indices into the model, sorted.
    pub nodes: Vec<usize>,
}

/// A mass the part must have (from a given volume and density).
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceMass {
    /// Mass (kg).
    pub mass: f64,
    /// Where it comes from, e.g. "volume 1e-5 m³ × density 7800 kg/m³ of the spec".
    pub what: String,
}

/// A linear FE model of a part.
#[derive(Clone, Debug)]
pub struct FeModel {
    /// A name (used in messages and provenance).
    pub name: String,
    node_ids: Vec<u64>,
    coords: Vec<[f64; 3]>,
    index_of: HashMap<u64, usize>,
    dofs: DofMap,
    k: SparseColMat<usize, f64>,
    m: SparseColMat<usize, f64>,
    /// The mesh volume (m³), if known (used for the density plausibility check).
    pub volume: Option<f64>,
    /// The files the model was read from (for messages).
    pub sources: Sources,
    /// The solid elements, if known (sparsity and rigid-body checks).
    pub solid: Option<SolidElements>,
    /// A mass the part must have, if known without elements (Matrix Market
    /// input with a volume and a density).
    pub reference_mass: Option<ReferenceMass>,
    /// Named node sets (gmsh physical groups, *NSET of a deck).
    pub node_sets: Vec<NodeSet>,
}

impl FeModel {
    /// Builds a model. `k` and `m` are square over the equations of `dofs`, in
    /// upper, lower or full symmetric storage. Node labels must be unique.
    pub fn new(
        name: &str,
        node_ids: Vec<u64>,
        coords: Vec<[f64; 3]>,
        dofs: DofMap,
        k: SparseColMatRef<'_, usize, f64>,
        m: SparseColMatRef<'_, usize, f64>,
    ) -> Result<Self, Error> {
        if node_ids.len() != coords.len() {
            return Err(Error::SizeMismatch(format!(
                "model {name}: {} node labels but {} coordinate rows",
                node_ids.len(),
                coords.len()
            )));
        }
        if dofs.n_nodes() != coords.len() {
            return Err(Error::SizeMismatch(format!(
                "model {name}: the DOF map has {} nodes but there are {} coordinate rows",
                dofs.n_nodes(),
                coords.len()
            )));
        }
        let n = dofs.n_eq();
        for (what, a) in [("stiffness K", &k), ("mass M", &m)] {
            if a.nrows() != n || a.ncols() != n {
                return Err(Error::SizeMismatch(format!(
                    "model {name}: {what} is {} × {} but the DOF map has {n} equations",
                    a.nrows(),
                    a.ncols()
                )));
            }
        }
        let mut index_of = HashMap::with_capacity(node_ids.len());
        for (i, &id) in node_ids.iter().enumerate() {
            if index_of.insert(id, i).is_some() {
                return Err(Error::SizeMismatch(format!(
                    "model {name}: node label {id} appears twice"
                )));
            }
        }
        for (i, c) in coords.iter().enumerate() {
            if c.iter().any(|v| !v.is_finite()) {
                return Err(Error::SizeMismatch(format!(
                    "model {name}: node {} has non-finite coordinates {c:?}",
                    node_ids[i]
                )));
            }
        }
        let describe = |e: usize| {
            let (nd, d) = dofs.dof(e);
            format!("node {} {}", node_ids[nd], DIR[d as usize])
        };
        let k = canonical_upper(k, &format!("model {name}: stiffness K"), &describe)?;
        let m = canonical_upper(m, &format!("model {name}: mass M"), &describe)?;
        Ok(Self {
            name: name.to_string(),
            node_ids,
            coords,
            index_of,
            dofs,
            k,
            m,
            volume: None,
            sources: Sources::default(),
            solid: None,
            reference_mass: None,
            node_sets: Vec::new(),
        })
    }

    /// Converts a model read in other units to SI: coordinates × `length`
    /// (m per file unit), K × `stiffness` (N/m per file unit), M × `mass` (kg
    /// per file unit); the volume and the element densities follow. Every
    /// factor must be positive and finite.
    pub fn rescale(&mut self, length: f64, stiffness: f64, mass: f64) -> Result<(), Error> {
        for (what, f) in [("length", length), ("stiffness", stiffness), ("mass", mass)] {
            if !(f > 0.0 && f.is_finite()) {
                return Err(Error::Spec(format!(
                    "model {}: a {what} scale of {f} (it must be positive and finite)",
                    self.name
                )));
            }
        }
        for c in &mut self.coords {
            for x in c.iter_mut() {
                *x *= length;
            }
        }
        for v in self.k.val_mut() {
            *v *= stiffness;
        }
        for v in self.m.val_mut() {
            *v *= mass;
        }
        let l3 = length.powi(3);
        if let Some(v) = &mut self.volume {
            *v *= l3;
        }
        if let Some(solid) = &mut self.solid {
            for rho in solid.density.iter_mut().flatten() {
                *rho *= mass / l3;
            }
        }
        Ok(())
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.coords.len()
    }
    /// Number of equations.
    pub fn n_eq(&self) -> usize {
        self.dofs.n_eq()
    }
    /// Node labels.
    pub fn node_ids(&self) -> &[u64] {
        &self.node_ids
    }
    /// Node coordinates (m).
    pub fn coords(&self) -> &[[f64; 3]] {
        &self.coords
    }
    /// The index of the node with label `id`.
    pub fn node_index(&self, id: u64) -> Option<usize> {
        self.index_of.get(&id).copied()
    }
    /// The node set called `name` (a gmsh physical group by name or by
    /// tag, an *NSET; case-insensitive); an error listing the sets there are
    /// when there is none of that name.
    pub fn node_set(&self, name: &str) -> Result<&NodeSet, Error> {
        // gmsh tags and names are per dimension: a surface first, as
        // interfaces are surfaces
        let surface_first = |s: &&NodeSet| !s.what.contains("surface");
        let by_name = self
            .node_sets
            .iter()
            .filter(|s| s.name == name)
            .min_by_key(surface_first)
            .or_else(|| {
                self.node_sets
                    .iter()
                    .filter(|s| s.name.eq_ignore_ascii_case(name))
                    .min_by_key(surface_first)
            });
        let by_tag = || {
            let t: i64 = name.trim().parse().ok()?;
            self.node_sets
                .iter()
                .filter(|s| s.tag == Some(t))
                .min_by_key(surface_first)
        };
        by_name.or_else(by_tag).ok_or_else(|| {
            let there = if self.node_sets.is_empty() {
                "it has no named node sets (a gmsh mesh has them for its physical groups, a deck for its *NSET)"
                    .to_string()
            } else {
                let names: Vec<String> = self.node_sets.iter().map(NodeSet::describe).collect();
                let names_only: Vec<&str> = self.node_sets.iter().map(|s| s.name.as_str()).collect();
                let hint = flexmb_input::nearest(name, names_only.iter())
                    .map(|n| format!(" (did you mean '{n}'?)"))
                    .unwrap_or_default();
                format!("it has {}{hint}", names.join(", "))
            };
            Error::Selection(format!(
                "model {} has no node set '{name}': {there}",
                self.name
            ))
        })
    }
    /// The DOF map.
    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }
    /// Stiffness, upper triangle.
    pub fn k(&self) -> SparseColMatRef<'_, usize, f64> {
        self.k.as_ref()
    }
    /// Mass, upper triangle.
    pub fn m(&self) -> SparseColMatRef<'_, usize, f64> {
        self.m.as_ref()
    }
    /// "node N uy" for equation e.
    pub fn describe_eq(&self, e: usize) -> String {
        let (nd, d) = self.dofs.dof(e);
        format!("node {} {}", self.node_ids[nd], DIR[d as usize])
    }
    /// "equation 13 (node N uy)" for equation e (numbered from 1, as in the
    /// files).
    pub fn describe_eq_long(&self, e: usize) -> String {
        format!("equation {} ({})", e + 1, self.describe_eq(e))
    }

    /// Checks K and M against each other, the node coordinates and the mesh
    /// (diagonals, swapped files, rigid null space, sparsity, rigid-body mass
    /// and inertia; see the `consistency` checks in the crate documentation).
    /// [`crate::build`] runs this first; the error names the file at fault.
    pub fn check_consistency(&self) -> Result<(), Error> {
        crate::consistency::check_model(self)
    }

    /// M's rigid-body mass, centre of mass and inertia against those of the
    /// solid elements' volume × density (the last of the consistency
    /// checks); `None` unless the elements and all their densities are known.
    pub fn compare_rigid_body(&self) -> Option<crate::consistency::RigidBodyComparison> {
        crate::consistency::compare_rigid_body(self)
    }

    /// The mass for a unit rigid translation along each global axis, uᵀ M u.
    pub fn translational_mass(&self) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (d, o) in out.iter_mut().enumerate() {
            let u: Vec<f64> = (0..self.n_eq())
                .map(|e| {
                    if self.dofs.dof(e).1 as usize == d {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect();
            *o = sym_quad(self.m(), &u, &u);
        }
        out
    }

    /// The displacement vector (over the equations) of the rigid motion with
    /// translation `t` and small rotation `theta` about the point `c`.
    pub fn rigid_field(&self, t: [f64; 3], theta: [f64; 3], c: [f64; 3]) -> Vec<f64> {
        (0..self.n_eq())
            .map(|e| {
                let (nd, d) = self.dofs.dof(e);
                let r = sub(self.coords[nd], c);
                let w = cross(theta, r);
                t[d as usize] + w[d as usize]
            })
            .collect()
    }
}

/// Canonicalizes a symmetric matrix given in upper, lower or full storage to
/// sorted upper-triangle CSC; full input is checked for symmetry.
fn canonical_upper(
    a: SparseColMatRef<'_, usize, f64>,
    what: &str,
    describe: &dyn Fn(usize) -> String,
) -> Result<SparseColMat<usize, f64>, Error> {
    let n = a.ncols();
    let mut upper: Vec<(usize, usize, f64)> = Vec::with_capacity(a.compute_nnz());
    let mut lower: Vec<(usize, usize, f64)> = Vec::new();
    let mut scale = 0.0f64;
    for j in 0..n {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if !v.is_finite() {
                return Err(Error::SizeMismatch(format!(
                    "{what} has a non-finite entry {v} at ({}, {})",
                    describe(i),
                    describe(j)
                )));
            }
            scale = scale.max(v.abs());
            if i <= j {
                upper.push((i, j, v));
            } else {
                lower.push((j, i, v));
            }
        }
    }
    let upper_off = upper.iter().any(|&(i, j, v)| i != j && v != 0.0);
    let lower_off = lower.iter().any(|&(_, _, v)| v != 0.0);
    let entries = if lower_off && !upper_off {
        // lower storage: transpose, keep the diagonal
        upper.retain(|&(i, j, _)| i == j);
        upper.extend(lower);
        upper
    } else if lower_off && upper_off {
        // full storage: check symmetry
        let key = |&(i, j, _): &(usize, usize, f64)| (j, i);
        let mut u: Vec<_> = upper.iter().filter(|t| t.0 != t.1).copied().collect();
        u.sort_by_key(key);
        lower.sort_by_key(key);
        let mut mu: HashMap<(usize, usize), f64> = HashMap::new();
        for (i, j, v) in u {
            *mu.entry((i, j)).or_default() += v;
        }
        let mut ml: HashMap<(usize, usize), f64> = HashMap::new();
        for (i, j, v) in lower {
            *ml.entry((i, j)).or_default() += v;
        }
        let tol = 1e-9 * scale;
        for (key, &v) in mu.iter().chain(ml.iter()) {
            let a1 = mu.get(key).copied().unwrap_or(0.0);
            let a2 = ml.get(key).copied().unwrap_or(0.0);
            if (a1 - a2).abs() > tol.max(1e-9 * v.abs()) {
                return Err(Error::NotSymmetric(format!(
                    "{what}: entry ({}, {}) = {a1:e} but its transpose = {a2:e}",
                    describe(key.0),
                    describe(key.1)
                )));
            }
        }
        upper
    } else {
        upper
    };
    build_upper(n, entries)
}

/// Builds a sorted upper CSC matrix from (row ≤ col) triplets, summing duplicates.
pub(crate) fn build_upper(
    n: usize,
    mut entries: Vec<(usize, usize, f64)>,
) -> Result<SparseColMat<usize, f64>, Error> {
    entries.sort_unstable_by_key(|&(i, j, _)| (j, i));
    let mut col_ptr = vec![0usize; n + 1];
    let mut row_idx = Vec::with_capacity(entries.len());
    let mut val = Vec::with_capacity(entries.len());
    let mut last: Option<(usize, usize)> = None;
    for (i, j, v) in entries {
        debug_assert!(i <= j);
        if last == Some((i, j)) {
            *val.last_mut().unwrap() += v;
        } else {
            row_idx.push(i);
            val.push(v);
            col_ptr[j + 1] += 1;
            last = Some((i, j));
        }
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Ok(SparseColMat::new(sym, val))
}

/// y += A x for a symmetric A stored as its upper triangle.
pub(crate) fn sym_mul_add(
    a: SparseColMatRef<'_, usize, f64>,
    x: MatRef<'_, f64>,
    mut y: MatMut<'_, f64>,
) {
    let k = x.ncols();
    for j in 0..a.ncols() {
        let rows = a.row_idx_of_col_raw(j);
        let vals = a.val_of_col(j);
        for c in 0..k {
            let xj = x[(j, c)];
            let mut acc = 0.0;
            for (&i, &v) in rows.iter().zip(vals) {
                if i == j {
                    acc += v * x[(i, c)];
                } else {
                    y[(i, c)] += v * xj;
                    acc += v * x[(i, c)];
                }
            }
            y[(j, c)] += acc;
        }
    }
}

/// uᵀ A v for a symmetric A stored as its upper triangle.
pub(crate) fn sym_quad(a: SparseColMatRef<'_, usize, f64>, u: &[f64], v: &[f64]) -> f64 {
    let mut s = 0.0;
    for j in 0..a.ncols() {
        for (&i, &x) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if i == j {
                s += u[i] * x * v[j];
            } else {
                s += x * (u[i] * v[j] + u[j] * v[i]);
            }
        }
    }
    s
}

/// A set of nodes chosen by label or by geometry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum NodeSelection {
    /// Nodes by label.
    Ids(Vec<u64>),
    /// Nodes within `tolerance` of the plane through `point` with normal `normal`.
    NearPlane {
        /// A point of the plane (m).
        point: [f64; 3],
        /// Its normal (need not be unit).
        normal: [f64; 3],
        /// Distance tolerance (m).
        tolerance: f64,
    },
    /// Nodes inside an axis-aligned box (bounds inclusive).
    InBox {
        /// Lower corner (m).
        min: [f64; 3],
        /// Upper corner (m).
        max: [f64; 3],
    },
    /// Nodes within `radius` of the segment from `a` to `b`.
    NearSegment {
        /// Start (m).
        a: [f64; 3],
        /// End (m).
        b: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
    /// The nodes of a named node set of the model ([`FeModel::node_sets`]:
    /// a gmsh physical surface, curve or point group by name or tag, an
    /// *NSET of a deck; names compared without regard to case).
    Set(String),
    /// Nodes in any of the selections.
    Union(Vec<NodeSelection>),
    /// Nodes in all of the selections.
    Intersection(Vec<NodeSelection>),
}

impl NodeSet {
    /// "physical surface 'left' (tag 2, 25 nodes)".
    pub fn describe(&self) -> String {
        let tag = match self.tag {
            Some(t) if t.to_string() != self.name => format!("tag {t}, "),
            _ => String::new(),
        };
        format!(
            "{} '{}' ({tag}{} nodes)",
            self.what,
            self.name,
            self.nodes.len()
        )
    }
}

impl NodeSelection {
    /// The sorted node indices selected in `model`; an error if a label is
    /// unknown or the selection is empty.
    pub fn resolve(&self, model: &FeModel, what: &str) -> Result<Vec<usize>, Error> {
        let mut v = self.resolve_inner(model)?;
        v.sort_unstable();
        v.dedup();
        if v.is_empty() {
            return Err(Error::Selection(format!(
                "{what}: {self:?} selects no node of model {}",
                model.name
            )));
        }
        Ok(v)
    }

    fn resolve_inner(&self, model: &FeModel) -> Result<Vec<usize>, Error> {
        let all = || 0..model.n_nodes();
        let c = model.coords();
        Ok(match self {
            NodeSelection::Ids(ids) => ids
                .iter()
                .map(|&id| {
                    model.node_index(id).ok_or_else(|| {
                        Error::Selection(format!("node label {id} is not in model {}", model.name))
                    })
                })
                .collect::<Result<_, _>>()?,
            NodeSelection::NearPlane {
                point,
                normal,
                tolerance,
            } => {
                let nn = norm(*normal);
                if !(nn > 0.0) || !(*tolerance >= 0.0) {
                    return Err(Error::Selection(format!(
                        "NearPlane needs a non-zero normal and a non-negative tolerance, got {normal:?}, {tolerance}"
                    )));
                }
                all()
                    .filter(|&i| (dot(sub(c[i], *point), *normal) / nn).abs() <= *tolerance)
                    .collect()
            }
            NodeSelection::Set(name) => model.node_set(name)?.nodes.clone(),
            NodeSelection::InBox { min, max } => all()
                .filter(|&i| (0..3).all(|d| c[i][d] >= min[d] && c[i][d] <= max[d]))
                .collect(),
            NodeSelection::NearSegment { a, b, radius } => {
                let ab = sub(*b, *a);
                let l2 = dot(ab, ab);
                all()
                    .filter(|&i| {
                        let ap = sub(c[i], *a);
                        let t = if l2 > 0.0 {
                            (dot(ap, ab) / l2).clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        let d = sub(ap, [ab[0] * t, ab[1] * t, ab[2] * t]);
                        norm(d) <= *radius
                    })
                    .collect()
            }
            NodeSelection::Union(v) => {
                let mut out = Vec::new();
                for s in v {
                    out.extend(s.resolve_inner(model)?);
                }
                out
            }
            NodeSelection::Intersection(v) => {
                let mut sets = v.iter().map(|s| {
                    s.resolve_inner(model)
                        .map(|x| x.into_iter().collect::<std::collections::HashSet<_>>())
                });
                let Some(first) = sets.next() else {
                    return Ok(Vec::new());
                };
                let mut acc = first?;
                for s in sets {
                    let s = s?;
                    acc.retain(|i| s.contains(i));
                }
                acc.into_iter().collect()
            }
        })
    }
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// Named node sets: by name (then without regard to case), by tag, a
    /// surface before a volume of the same name or tag (gmsh numbers each
    /// dimension apart), and an unknown name listing the sets with the
    /// nearest.
    #[test]
    fn node_sets_are_found_by_name_or_tag_surfaces_first() {
        let eye: Vec<Triplet<usize, usize, f64>> =
            (0..6).map(|i| Triplet::new(i, i, 1.0)).collect();
        let a = SparseColMat::try_new_from_triplets(6, 6, &eye).unwrap();
        let mut m = FeModel::new(
            "part",
            vec![1, 2],
            vec![[0.0; 3], [1.0, 0.0, 0.0]],
            DofMap::full(2),
            a.as_ref(),
            a.as_ref(),
        )
        .unwrap();
        let set = |name: &str, what: &str, tag: Option<i64>, nodes: Vec<usize>| NodeSet {
            name: name.into(),
            what: what.into(),
            tag,
            nodes,
        };
        m.node_sets = vec![
            set("7", "physical volume", Some(7), vec![0, 1]),
            set("7", "physical surface", Some(7), vec![1]),
            set("Left", "physical surface", Some(2), vec![0]),
            set("END", "node set", None, vec![1]),
        ];
        assert_eq!(m.node_set("7").unwrap().what, "physical surface");
        assert_eq!(m.node_set("left").unwrap().nodes, vec![0]);
        assert_eq!(m.node_set("2").unwrap().name, "Left");
        assert_eq!(m.node_set("end").unwrap().name, "END");
        let e = m.node_set("lef").unwrap_err().to_string();
        assert!(
            e.contains("no node set 'lef'") && e.contains("did you mean 'Left'"),
            "{e}"
        );
        assert!(
            e.contains("physical surface 'Left' (tag 2, 1 nodes)"),
            "{e}"
        );
        assert_eq!(
            NodeSelection::Set("END".into())
                .resolve(&m, "interface q")
                .unwrap(),
            vec![1]
        );
    }
}
