//! Checks of K and M against each other, against the node coordinates and
//! against the mesh, run by [`crate::build`] before anything is factorized.
//! Each message names the file at fault (K, M, the DOF list or the mesh, as
//! recorded in [`FeModel::sources`]). All checks are O(nnz) (the sparsity
//! check O(nnz log d) for d nodes per row).
//!
//! What is checked, in this order, and why it holds for any K and M of one
//! solid mesh:
//!
//! 1. **Diagonals**: K_ii > 0 and M_ii > 0. K_ii is the energy of a unit
//!    displacement of one DOF, M_ii = ∫ρ N_a² dV for a consistent mass (the
//!    nodal mass for a lumped one); both are positive for every DOF of a solid
//!    element with ρ > 0.
//! 2. **Not swapped**: a free-free stiffness gives every rigid motion r zero
//!    energy, rᵀKr ≈ 0, and a mass gives it its mass, rᵀMr > 0. If the matrix
//!    read as M has the rigid null space and the one read as K does not, the
//!    two are swapped.
//! 3. **K fits the node coordinates**: rᵀKr ≈ 0 for the six rigid motions
//!    built from the node coordinates. Translations do not depend on the
//!    coordinates, rotations do: when only rotations store energy, K comes
//!    from another mesh than the coordinates (or the DOF list from another
//!    model); when translations do, K is not free-free (boundary conditions
//!    or springs to ground).
//! 4. **Sparsity**: a mass matrix, consistent or lumped, couples two nodes
//!    only if they share an element. With the mesh's solid elements known and
//!    no *EQUATION, *MPC, *TIE, *RIGID BODY, *COUPLING or *CONTACT PAIR in the
//!    deck (which couple nodes outside the elements), every node pair M
//!    couples must share a solid element. (Other elements do not matter:
//!    CalculiX expands beams, shells and plane elements into solids on new
//!    nodes, which the reader refuses as nodes without coordinates, and
//!    springs have no mass.) Otherwise every node pair M couples must be
//!    coupled by K (an entry of K in the pair's 3 × 3 block), since K couples
//!    the nodes of every element too. That is exact for files that store the
//!    assembled pattern (CalculiX does, zeros included, and so does the
//!    built-in FE). For files that drop zeros it would fail only if all nine
//!    entries of K's block vanished for two nodes of a common element: for an
//!    isotropic material that needs the symmetric part of ∫ ∇N_a ⊗ ∇N_b dV
//!    summed over their common elements to vanish, which no pair of nodes of
//!    the meshes tested does. M's values are not compared (a lumped mass is
//!    diagonal, a consistent one has negative entries for quadratic
//!    elements).
//! 5. **Rigid-body mass and inertia**: for isoparametric elements the shape
//!    functions interpolate rigid motions exactly, so rᵀMr over the rigid
//!    fields gives ∫ρ dV, ∫ρ x dV and ∫ρ x xᵀ dV over the elements. Where the
//!    densities are known (the deck's *DENSITY, the spec's `density`, the
//!    built-in FE's materials), the mass, the centre of mass and the inertia
//!    from M must equal those of the elements' volume × density (see
//!    [`RIGID_BODY_TOLERANCE`]); with only a volume and a density (Matrix
//!    Market input), the mass must.

use crate::builder::{bbox_diag, centroid, rigid_motions, RigidBodyProperties};
use crate::geometry::{Integrator, Moments};
use crate::model::{sym_mul_add, FeModel};
use crate::Error;
use faer::sparse::SparseColMatRef;
use faer::Mat;
use nalgebra::DMatrix;

/// Relative energy below which a rigid motion counts as stored without
/// energy: rᵀAr ≤ 1e-8 Σ A_ii r_i² (the free-free check of the builder;
/// CalculiX's 14 significant digits give about 1e-14).
pub const RIGID_NULL_TOLERANCE: f64 = 1e-8;

/// Largest relative difference accepted between the rigid-body properties
/// from M and from the elements' volume × density: mass relative to the mass,
/// centre of mass relative to the mesh's bounding-box diagonal, inertia
/// entries relative to the largest diagonal entry of the mesh's inertia.
/// Straight-edged elements agree to rounding (measured ≤ 1e-13 through
/// CalculiX's 14-digit print). Curved ones differ by the exporter's
/// quadrature error against the 4-point rules of [`crate::geometry`]
/// (measured on coarse cylinders: CalculiX C3D10 9.5e-5, C3D20 2.0e-7, the
/// built-in shaft 2.0e-5, all in the inertia). A `.mas` of the same bar meshed
/// with element lengths graded by 1.2 along its axis differs by 0.14 (centre
/// of mass) and 0.15 (inertia).
pub const RIGID_BODY_TOLERANCE: f64 = 1e-3;

/// Runs every check in the order of the module documentation.
pub(crate) fn check_model(model: &FeModel) -> Result<(), Error> {
    check_diagonals(model)?;
    let fields = RigidFields::of(model);
    let rigid = fields.energies(model);
    check_not_swapped(model, &rigid)?;
    check_k_fits_coordinates(model, &rigid, &fields)?;
    check_sparsity(model)?;
    check_rigid_body(model, &fields)
}

/// The diagonal entry of column `j` of an upper-triangle CSC matrix with
/// sorted rows (the diagonal is the last entry), if stored.
fn diagonal(a: SparseColMatRef<'_, usize, f64>, j: usize) -> Option<f64> {
    let rows = a.row_idx_of_col_raw(j);
    match rows.last() {
        Some(&i) if i == j => a.val_of_col(j).last().copied(),
        _ => None,
    }
}

/// Check 1: K_ii > 0 and M_ii > 0 for every equation. The error names the
/// file, the equation (numbered from 1 as in the files), the node and the
/// direction, and how many other equations fail.
fn check_diagonals(model: &FeModel) -> Result<(), Error> {
    let s = &model.sources;
    for (a, name, what) in [
        (model.k(), s.k_name(), "stiffness"),
        (model.m(), s.m_name(), "mass"),
    ] {
        let bad: Vec<(usize, Option<f64>)> = (0..model.n_eq())
            .map(|j| (j, diagonal(a, j)))
            .filter(|&(_, d)| !matches!(d, Some(v) if v > 0.0))
            .collect();
        let Some(&(j, d)) = bad.first() else {
            continue;
        };
        let sym = if what == "mass" { "M" } else { "K" };
        let value = match d {
            None => format!("has no diagonal entry ({sym}_ii = 0)"),
            Some(v) => format!("has the diagonal {sym}_ii = {v:e}"),
        };
        let why = match (what, d) {
            ("stiffness", Some(v)) if v < 0.0 => {
                "< 0: the stiffness is not positive semi-definite".to_string()
            }
            ("stiffness", _) => "; every DOF of a solid element has a positive stiffness".to_string(),
            _ => "; every DOF of a solid element with a density has a positive mass, consistent or lumped"
                .to_string(),
        };
        let more = if bad.len() > 1 {
            format!(" ({} more equation(s) too)", bad.len() - 1)
        } else {
            String::new()
        };
        return Err(Error::Matrix {
            file: name,
            msg: format!("{} {value}{why}{more}", model.describe_eq_long(j)),
        });
    }
    Ok(())
}

/// The energy of one rigid motion r (about the node centroid, rotations of
/// 1/size rad) in K and in M, with the scales Σ A_ii r_i² they are compared
/// with and the equation where K r is largest.
struct RigidEnergy {
    name: &'static str,
    k: f64,
    k_scale: f64,
    k_worst: usize,
    m: f64,
    m_scale: f64,
}

impl RigidEnergy {
    fn k_ratio(&self) -> f64 {
        (self.k / self.k_scale).abs()
    }
    fn m_ratio(&self) -> f64 {
        (self.m / self.m_scale).abs()
    }
    fn k_null(&self) -> bool {
        self.k.abs() <= RIGID_NULL_TOLERANCE * self.k_scale
    }
    fn m_null(&self) -> bool {
        self.m.abs() <= RIGID_NULL_TOLERANCE * self.m_scale
    }
}

/// The six rigid motions about the node centroid `c` (translations, then
/// rotations of 1/`size` rad about x, y, z; `size` the bounding-box
/// diagonal) as the columns of `x`, with K x and M x (one sparse product
/// each).
pub(crate) struct RigidFields {
    c: [f64; 3],
    size: f64,
    x: Mat<f64>,
    kx: Mat<f64>,
    mx: Mat<f64>,
}

impl RigidFields {
    fn of(model: &FeModel) -> Self {
        let n = model.n_eq();
        let c = centroid(model.coords());
        let size = bbox_diag(model);
        let mut x = Mat::<f64>::zeros(n, 6);
        for (k, (_, t, th)) in rigid_motions(size).iter().enumerate() {
            for (i, v) in model.rigid_field(*t, *th, c).into_iter().enumerate() {
                x[(i, k)] = v;
            }
        }
        let mut kx = Mat::<f64>::zeros(n, 6);
        let mut mx = Mat::<f64>::zeros(n, 6);
        sym_mul_add(model.k(), x.as_ref(), kx.as_mut());
        sym_mul_add(model.m(), x.as_ref(), mx.as_mut());
        Self { c, size, x, kx, mx }
    }

    /// xₐᵀ (A x)_b for the product `ax` of one of the matrices.
    fn form(&self, ax: &Mat<f64>, a: usize, b: usize) -> f64 {
        (0..self.x.nrows())
            .map(|i| self.x[(i, a)] * ax[(i, b)])
            .sum()
    }

    /// Σ A_ii x_ik² for the diagonal of a matrix.
    fn diagonal_scale(&self, a: SparseColMatRef<'_, usize, f64>, k: usize) -> f64 {
        (0..self.x.nrows())
            .map(|j| diagonal(a, j).unwrap_or(0.0) * self.x[(j, k)] * self.x[(j, k)])
            .sum()
    }

    /// The energies of the six motions in K and M.
    fn energies(&self, model: &FeModel) -> Vec<RigidEnergy> {
        rigid_motions(self.size)
            .iter()
            .enumerate()
            .map(|(k, &(name, _, _))| RigidEnergy {
                name,
                k: self.form(&self.kx, k, k),
                k_scale: self.diagonal_scale(model.k(), k),
                k_worst: (0..self.x.nrows()).fold(0, |w, i| {
                    if self.kx[(i, k)].abs() > self.kx[(w, k)].abs() {
                        i
                    } else {
                        w
                    }
                }),
                m: self.form(&self.mx, k, k),
                m_scale: self.diagonal_scale(model.m(), k),
            })
            .collect()
    }

    /// Mass, centre of mass (about `c`) and inertia from M applied to the
    /// rigid fields (the rotation columns rescaled to 1 rad).
    fn rigid_body_of_m(&self) -> RigidBodyProperties {
        let unit = |a: usize| if a < 3 { 1.0 } else { self.size };
        let m6 = DMatrix::from_fn(6, 6, |a, b| self.form(&self.mx, a, b) * unit(a) * unit(b));
        RigidBodyProperties::from_rigid_mass(&m6)
    }
}

/// Check 2: the matrix read as M must give rigid motions their mass. If it
/// has the rigid null space of a free-free stiffness while the one read as K
/// gives them energy, the files are swapped.
fn check_not_swapped(model: &FeModel, rigid: &[RigidEnergy]) -> Result<(), Error> {
    if !rigid.iter().all(RigidEnergy::m_null) {
        return Ok(());
    }
    let s = &model.sources;
    let m_worst = rigid.iter().map(RigidEnergy::m_ratio).fold(0.0, f64::max);
    if rigid.iter().all(RigidEnergy::k_null) {
        return Err(Error::Mismatch(format!(
            "{} gives the rigid motions no mass (rᵀMr / Σ M_ii r_i² ≤ {m_worst:.1e} for all six), \
             like a free-free stiffness, and so does {}: {} is not a mass matrix",
            s.m_name(),
            s.k_name(),
            s.m_name()
        )));
    }
    let file = |f: &str| {
        if f.is_empty() {
            String::new()
        } else {
            format!(" ({f})")
        }
    };
    Err(Error::Mismatch(format!(
        "K and M look swapped: the matrix read as M{} gives the rigid motions no mass \
         (rᵀMr / Σ M_ii r_i² ≤ {m_worst:.1e} for all six), as a free-free stiffness does, while the one \
         read as K{} gives them energy as a mass does (ratio {:.2} for the rigid translation x); \
         exchange the two files",
        file(&s.m),
        file(&s.k),
        rigid[0].k_ratio()
    )))
}

/// Check 3: the six rigid motions of the node coordinates store no energy in
/// K. Translations that store energy mean boundary conditions or springs to
/// ground; rotations alone mean K and the coordinates (or the DOF list) are
/// from different meshes.
fn check_k_fits_coordinates(
    model: &FeModel,
    rigid: &[RigidEnergy],
    fields: &RigidFields,
) -> Result<(), Error> {
    let Some(bad) = rigid.iter().find(|r| !r.k_null()) else {
        return Ok(());
    };
    let s = &model.sources;
    let at = model.describe_eq(bad.k_worst);
    if rigid[..3].iter().any(|r| !r.k_null()) {
        return Err(Error::NotPositiveSemiDefinite(format!(
            "{} is not free-free: the rigid {} stores energy (ratio {:.1e}); remove boundary conditions and \
             springs to ground from the export. The largest residual force is at {at}",
            s.k_name(),
            bad.name,
            bad.k_ratio()
        )));
    }
    // who is the odd one out: M fitting the coordinates (its rigid-body
    // properties match the mesh) blames K; M fitting K (same pattern) blames
    // the coordinates or the DOF list
    let m_fits_mesh = compare_with(model, fields).map(|c| c.worst() <= RIGID_BODY_TOLERANCE);
    let m_fits_k = node_pairs_outside(model, model.m(), &node_pattern(model, model.k())).0 == 0;
    let odd = match (m_fits_mesh, m_fits_k) {
        (Some(true), _) => format!(
            "{} fits the node coordinates (its rigid-body mass, centre of mass and inertia match the mesh's), so {} \
             is from another mesh",
            s.m_name(),
            s.k_name()
        ),
        (_, true) => format!(
            "{} fits K (it couples only nodes that K couples){}, so the odd one out is {} or {}",
            s.m_name(),
            if m_fits_mesh == Some(false) {
                " but not the mesh's rigid-body properties"
            } else {
                ""
            },
            s.mesh_name(),
            s.dofs_name()
        ),
        (_, false) => format!("{} does not fit K either", s.m_name()),
    };
    Err(Error::Mismatch(format!(
        "{} does not fit the node coordinates of {}: the rigid translations store no energy, but the rigid {} does (ratio {:.1e}, \
         the largest residual force at {at}). A free-free stiffness has the rigid rotations of its own mesh \
         in its null space, so K and the coordinates come from different meshes (or {} is from another \
         model); {odd}",
        s.k_name(),
        s.mesh_name(),
        bad.name,
        bad.k_ratio(),
        s.dofs_name()
    )))
}

/// Sorted neighbour lists per node: the nodes each node shares an element
/// with (itself included).
fn element_adjacency(n_nodes: usize, elements: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let mut adj: Vec<Vec<usize>> = (0..n_nodes).map(|i| vec![i]).collect();
    for e in elements {
        for &a in e {
            if a < n_nodes {
                adj[a].extend(e.iter().copied().filter(|&b| b < n_nodes));
            }
        }
    }
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
    }
    adj
}

/// Sorted neighbour lists per node: the nodes whose 3 × 3 block of `a` has a
/// stored entry (zeros included).
fn node_pattern(model: &FeModel, a: SparseColMatRef<'_, usize, f64>) -> Vec<Vec<usize>> {
    let mut adj: Vec<Vec<usize>> = (0..model.n_nodes()).map(|i| vec![i]).collect();
    let node = |e: usize| model.dofs().dof(e).0;
    for j in 0..a.ncols() {
        for &i in a.row_idx_of_col_raw(j) {
            let (p, q) = (node(i), node(j));
            adj[p].push(q);
            adj[q].push(p);
        }
    }
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
    }
    adj
}

/// The number of non-zero entries of `a` whose nodes are not neighbours in
/// `adj`, and the first one (row, column).
fn node_pairs_outside(
    model: &FeModel,
    a: SparseColMatRef<'_, usize, f64>,
    adj: &[Vec<usize>],
) -> (usize, Option<(usize, usize)>) {
    let node = |e: usize| model.dofs().dof(e).0;
    let mut count = 0;
    let mut first = None;
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if v != 0.0 && adj[node(j)].binary_search(&node(i)).is_err() {
                count += 1;
                first.get_or_insert((i, j));
            }
        }
    }
    (count, first)
}

/// Check 4: M couples only nodes that share a solid element (elements known,
/// no constraints in the deck), else only nodes that K couples.
fn check_sparsity(model: &FeModel) -> Result<(), Error> {
    let s = &model.sources;
    let m = model.m();
    let nnz = m.compute_nnz();
    let solid = model
        .solid
        .as_ref()
        .filter(|sol| sol.couplings.is_empty() && !sol.nodes.is_empty());
    let (adj, against) = match solid {
        Some(sol) => (
            element_adjacency(model.n_nodes(), &sol.nodes),
            format!("which share no solid element of {}", s.mesh_name()),
        ),
        None => (
            node_pattern(model, model.k()),
            format!("between which {} has no entry", s.k_name()),
        ),
    };
    let (count, first) = node_pairs_outside(model, m, &adj);
    let Some((i, j)) = first else {
        return Ok(());
    };
    let value = m.val_of_col(j)[m
        .row_idx_of_col_raw(j)
        .iter()
        .position(|&r| r == i)
        .unwrap_or(0)];
    Err(Error::Mismatch(format!(
        "{} couples {} and {} (M = {value:e}), {against}; a mass couples only nodes of a common element. \
         {count} of its {nnz} non-zero entries (upper triangle) do so: M is from another mesh{}",
        s.m_name(),
        model.describe_eq_long(i),
        model.describe_eq_long(j),
        if solid.is_some() {
            format!(
                " (K fits the node coordinates of {}: its rigid rotations store no energy)",
                s.mesh_name()
            )
        } else {
            String::new()
        }
    )))
}

/// The mass moments of the solid elements about `c` (Σ ρ_e ∫_e …), if every
/// element has a density and a valid node count.
fn element_mass_moments(model: &FeModel, c: [f64; 3]) -> Option<Moments> {
    let sol = model.solid.as_ref()?;
    if sol.nodes.is_empty() {
        return None;
    }
    let mut total = Moments::default();
    let mut integrator = Integrator::default();
    let mut x = Vec::with_capacity(20);
    for ((kind, nodes), rho) in sol.kinds.iter().zip(&sol.nodes).zip(&sol.density) {
        let rho = (*rho)?;
        x.clear();
        for &i in nodes {
            x.push(*model.coords().get(i)?);
        }
        total.add_scaled(&integrator.moments(*kind, &x, c)?, rho);
    }
    Some(total)
}

/// A hint when a mass ratio is close to a power of 1000 (mm vs m, t vs kg).
fn units_hint(ratio: f64) -> String {
    let k = (ratio.log10() / 3.0).round();
    if k != 0.0 && (ratio.log10() - 3.0 * k).abs() < 0.5 {
        format!(
            " (a factor {ratio:.3e}: are the units consistent, m and kg? Files in other units are converted by the \
             spec's `units:` (\"mm-t-s\", \"mm-kg-ms\", \"mm-kg-s\") or `mass_scale:`)"
        )
    } else {
        String::new()
    }
}

/// The rigid-body properties of M against those of the elements' volume ×
/// density (see [`FeModel::compare_rigid_body`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidBodyComparison {
    /// From M applied to the rigid fields.
    pub from_m: RigidBodyProperties,
    /// From the elements (mass, centre of mass, inertia about it).
    pub from_mesh: RigidBodyProperties,
    /// Relative differences: mass (of the mesh's mass), centre of mass (of
    /// the bounding-box diagonal), inertia entries (of the largest diagonal
    /// entry of the mesh's inertia).
    pub difference: [f64; 3],
    /// M is diagonal (a lumped mass, as ANSYS and Abaqus write for many
    /// element types). Lumping keeps the mass and the centre of mass exact but
    /// moves the inertia by O(h²) (the rotor of `fixtures/fe-exports`: 10 %),
    /// so the inertia difference is reported but not checked.
    pub lumped: bool,
}

impl RigidBodyComparison {
    /// The largest of the relative differences that are checked (the inertia
    /// only for a consistent mass).
    pub fn worst(&self) -> f64 {
        let n = if self.lumped { 2 } else { 3 };
        self.difference[..n].iter().copied().fold(0.0, f64::max)
    }
}

/// Compares M's rigid-body properties with those of the solid elements
/// (centres of mass in the model's coordinates); `None` unless every element
/// has a density.
pub(crate) fn compare_rigid_body(model: &FeModel) -> Option<RigidBodyComparison> {
    compare_with(model, &RigidFields::of(model))
}

/// True if every stored entry of `a` is on its diagonal.
fn is_diagonal(a: faer::sparse::SparseColMatRef<'_, usize, f64>) -> bool {
    (0..a.ncols()).all(|j| {
        a.col_range(j)
            .all(|p| a.symbolic().row_idx()[p] == j || a.val()[p] == 0.0)
    })
}

/// [`compare_rigid_body`] with the rigid fields already multiplied by M.
fn compare_with(model: &FeModel, fields: &RigidFields) -> Option<RigidBodyComparison> {
    let c = fields.c;
    let (mass, com, inertia) = element_mass_moments(model, c)?.rigid_body();
    let mut from_m = fields.rigid_body_of_m();
    let size = fields.size;
    let j_scale = (0..3).map(|i| inertia[i][i].abs()).fold(0.0, f64::max);
    let d_mass = (from_m.mass - mass).abs() / mass;
    let d_com = (0..3)
        .map(|i| (from_m.com[i] - com[i]).abs())
        .fold(0.0, f64::max)
        / size;
    let d_j = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| (from_m.inertia[i][j] - inertia[i][j]).abs())
        .fold(0.0, f64::max)
        / j_scale;
    for i in 0..3 {
        from_m.com[i] += c[i];
    }
    Some(RigidBodyComparison {
        from_m,
        from_mesh: RigidBodyProperties {
            mass,
            com: std::array::from_fn(|i| com[i] + c[i]),
            inertia,
        },
        difference: [d_mass, d_com, d_j],
        lumped: is_diagonal(model.m()),
    })
}

/// Check 5: the rigid-body mass, centre of mass and inertia of M equal those
/// of the elements' volume × density; with only a reference mass, the mass.
fn check_rigid_body(model: &FeModel, fields: &RigidFields) -> Result<(), Error> {
    let s = &model.sources;
    if let Some(cmp) = compare_with(model, fields) {
        if !(cmp.worst() <= RIGID_BODY_TOLERANCE) {
            let sol = model
                .solid
                .as_ref()
                .map(|x| x.density_source.as_str())
                .unwrap_or("");
            let (a, b) = (&cmp.from_m, &cmp.from_mesh);
            let v3 = |x: [f64; 3]| format!("({:.6e}, {:.6e}, {:.6e})", x[0], x[1], x[2]);
            let diag = |j: &[[f64; 3]; 3]| v3([j[0][0], j[1][1], j[2][2]]);
            let [d_mass, d_com, d_j] = cmp.difference;
            return Err(Error::Mismatch(format!(
                "{} does not fit the elements of {} and their densities ({sol}): from M the mass is {:.6e} kg, the \
                 centre of mass {} m, the inertia diagonal (about the centre of mass, global axes) {} kg m²; \
                 from the elements' volume × density {:.6e} kg, {} m, {} kg m² (relative differences: mass \
                 {d_mass:.1e}, centre of mass {d_com:.1e} of the part's size, inertia {d_j:.1e}; tolerance \
                 {RIGID_BODY_TOLERANCE:.0e}){}. {} fits these coordinates (its rigid rotations store no \
                 energy), so M is from another mesh or material, or the density is not the one M was computed \
                 with",
                s.m_name(),
                s.mesh_name(),
                a.mass,
                v3(a.com),
                diag(&a.inertia),
                b.mass,
                v3(b.com),
                diag(&b.inertia),
                units_hint(a.mass / b.mass),
                s.k_name()
            )));
        }
        return Ok(());
    }
    if let Some(reference) = &model.reference_mass {
        let from_m = fields.rigid_body_of_m().mass;
        let d = (from_m - reference.mass).abs() / reference.mass;
        if !(d <= RIGID_BODY_TOLERANCE) {
            return Err(Error::Mismatch(format!(
                "{} gives the part a rigid-body mass of {from_m:.6e} kg, but {} is {:.6e} kg (relative \
                 difference {d:.1e}, tolerance {RIGID_BODY_TOLERANCE:.0e}){}: M is from another model or \
                 material, or the volume or density is wrong",
                s.m_name(),
                reference.what,
                reference.mass,
                units_hint(from_m / reference.mass)
            )));
        }
    }
    Ok(())
}
