//! The fixed layout of a mechanism's kinematics, built once by
//! [`Layout::new`] and never changed: which deformation is which constraint
//! row of D_c(x) = (0, q_ε, u_ε) (thesis (5.7), (6.5)), which coordinate is
//! which entry of ξ = (q, u), each element's row and column maps into the
//! kinematic Jacobian J = ∂D_c/∂x_dep and the positions of its entries in
//! J's values, and the element-Jacobian entries of the products with J and
//! with the right-hand side B of (5.8a). Everything here depends on the
//! mechanism only, not on the configuration; the products read the element
//! Jacobians ([`ElementJacobians`](crate::caches::ElementJacobians)) they are
//! given.

use crate::jacobian_lu::JacobianLu;
use flexmb_model::{Coordinate, ERole, Mechanism, XRole};

/// Marks a local Jacobian entry that is not part of J.
pub(crate) const NO_ENTRY: usize = usize::MAX;

/// One element's maps into J.
pub(crate) struct ElemMap {
    /// local deformation → constraint row
    pub(crate) rows: Vec<Option<usize>>,
    /// local coordinate → dependent column
    pub(crate) cols: Vec<Option<usize>>,
    /// The element's coordinates.
    pub(crate) nx: usize,
    /// The element's deformations.
    pub(crate) ne: usize,
}

/// An entry ∂D_r/∂x_i of a constraint row r with respect to a nodal
/// coordinate x_i in ξ (ξ index `col`): position `local` in the element
/// Jacobian of `element`.
pub(crate) struct XiEntry {
    row: usize,
    col: usize,
    element: usize,
    local: usize,
}

/// The rows of J element by element: (constraint row, (element, range of
/// [`Layout::dep_entries`])).
type DepRow = (usize, (usize, std::ops::Range<usize>));

/// The fixed layout of the kinematics of one mechanism (see the module
/// documentation). Immutable after [`Layout::new`].
pub(crate) struct Layout {
    /// Each element's maps into J.
    pub(crate) maps: Vec<ElemMap>,
    /// global row of each deformation (if it is an equation)
    pub(crate) row_of: Vec<Option<usize>>,
    /// ξ index of each nodal coordinate in ξ (a DOF or an input)
    pub(crate) xi_of_x: Vec<Option<usize>>,
    /// ξ index of each deformation in ξ (a DOF or an input)
    pub(crate) xi_of_e: Vec<Option<usize>>,
    /// The entries of D_c,x_ξ, the nodal columns of the right-hand side B of
    /// (5.8a), element by element (products with directions of ξ).
    xi_entries: Vec<XiEntry>,
    /// The rows of J element by element, with `dep_entries` (dependent
    /// column, position in the element Jacobian): products J v at the
    /// current x.
    dep_rows: Vec<DepRow>,
    dep_entries: Vec<(usize, usize)>,
    /// `jpos[k][a·n_x,e + c]` is the position of element k's local entry
    /// (a, c) in the values of J ([`NO_ENTRY`] when not in J).
    jpos: Vec<Vec<usize>>,
    /// (element, local index) of the deformations that are not constraint rows.
    pub(crate) free_deformations: Vec<(usize, usize)>,
    /// The length unit of the Newton tolerance (mean element length).
    pub(crate) length_scale: f64,
    /// Number of degrees of freedom.
    pub(crate) n_q: usize,
    /// Number of prescribed inputs.
    pub(crate) n_u: usize,
}

impl Layout {
    /// The layout of `mech`, and J's factorization set up for its pattern
    /// (dense up to `dense_up_to` rows).
    pub(crate) fn new(mech: &Mechanism, dense_up_to: usize) -> (Self, JacobianLu) {
        let n_x = mech.n_x();
        let n_eps = mech.n_eps();
        let n_c = mech.constraint_rows.len();
        let mut row_of = vec![None; n_eps];
        for (r, j) in mech.constraint_rows.iter().enumerate() {
            row_of[*j] = Some(r);
        }
        let n_q = mech.n_dof();
        let n_u = mech.inputs.len();
        let mut xi_of_x = vec![None; n_x];
        let mut xi_of_e = vec![None; n_eps];
        for (k, c) in mech.dofs.iter().enumerate() {
            match c {
                Coordinate::Node(i) => xi_of_x[*i] = Some(k),
                Coordinate::Def(j) => xi_of_e[*j] = Some(k),
            }
        }
        for (k, inp) in mech.inputs.iter().enumerate() {
            match inp.target {
                Coordinate::Node(i) => xi_of_x[i] = Some(n_q + k),
                Coordinate::Def(j) => xi_of_e[j] = Some(n_q + k),
            }
        }
        let maps: Vec<ElemMap> = mech
            .elements
            .iter()
            .map(|e| {
                let ne = e.element.n_eps();
                ElemMap {
                    rows: (0..ne).map(|k| row_of[e.eps_offset + k]).collect(),
                    cols: e
                        .x_index
                        .iter()
                        .map(|i| match mech.x_roles[*i] {
                            XRole::Dependent(k) => Some(k),
                            _ => None,
                        })
                        .collect(),
                    nx: e.element.n_x(),
                    ne,
                }
            })
            .collect();
        let (xi_entries, dep_rows, dep_entries) = jacobian_entries(mech, &maps, &xi_of_x);
        let (lu, jpos) = jacobian_pattern(&maps, n_c, dense_up_to);
        let free_deformations = mech
            .elements
            .iter()
            .enumerate()
            .flat_map(|(k, e)| (0..maps[k].ne).map(move |a| (k, a, e.eps_offset + a)))
            .filter(|&(_, _, j)| row_of[j].is_none())
            .map(|(k, a, _)| (k, a))
            .collect();
        let layout = Self {
            maps,
            row_of,
            xi_of_x,
            xi_of_e,
            xi_entries,
            dep_rows,
            dep_entries,
            jpos,
            free_deformations,
            length_scale: characteristic_length(mech),
            n_q,
            n_u,
        };
        (layout, lu)
    }

    /// n_q + n_u, the length of ξ.
    pub(crate) fn n_xi(&self) -> usize {
        self.n_q + self.n_u
    }

    /// Visits the entries ∂D_r/∂x_i of the constraint rows r with respect to
    /// the nodal coordinates x_i that belong to ξ (k = ξ index of x_i), read
    /// from the element Jacobians `jac`: the nodal columns of the
    /// right-hand side B of (5.8a), up to sign.
    pub(crate) fn for_each_nodal_xi_entry(
        &self,
        jac: &[Vec<f64>],
        mut visit: impl FnMut(usize, usize, f64),
    ) {
        for e in &self.xi_entries {
            visit(e.row, e.col, jac[e.element][e.local]);
        }
    }

    /// Scatters the element Jacobians `jac` into `values`, the values of J
    /// in the order of its pattern.
    pub(crate) fn assemble_jacobian(&self, jac: &[Vec<f64>], values: &mut [f64]) {
        values.fill(0.0);
        for (jl, pos) in jac.iter().zip(&self.jpos) {
            for (v, &p) in jl.iter().zip(pos) {
                if p != NO_ENTRY {
                    values[p] += v;
                }
            }
        }
    }

    /// out −= J v, J = ∂D_c/∂x_dep from the element Jacobians `jac`.
    pub(crate) fn sub_jacobian_times(&self, jac: &[Vec<f64>], v: &[f64], out: &mut [f64]) {
        for (r, (element, entries)) in &self.dep_rows {
            let jl = &jac[*element];
            let s: f64 = self.dep_entries[entries.clone()]
                .iter()
                .map(|(k, local)| jl[*local] * v[*k])
                .sum();
            out[*r] -= s;
        }
    }

    /// The right-hand side B dir of J y_dep = B dir for a direction `dir`
    /// of ξ (thesis (5.8a)): `dir`'s entry on the rows of degree-of-freedom
    /// and prescribed deformations, minus D_c,x_i dir_i over the nodal
    /// coordinates x_i in ξ (from the element Jacobians `jac`); started from
    /// −D_c,xx\[ẋ, ẋ\] when `convective` holds D,xx\[ẋ, ẋ\] of every
    /// deformation (the second time derivative (5.8b)).
    pub(crate) fn direction_rhs(
        &self,
        mech: &Mechanism,
        jac: &[Vec<f64>],
        convective: Option<&[f64]>,
        dir: &[f64],
        rhs: &mut [f64],
    ) {
        let n_q = self.n_q;
        for (r, j) in mech.constraint_rows.iter().enumerate() {
            rhs[r] = convective.map_or(0.0, |c| -c[*j]);
            match mech.e_roles[*j] {
                ERole::Dof(k) => rhs[r] += dir[k],
                ERole::Input(k) => rhs[r] += dir[n_q + k],
                _ => {}
            }
        }
        self.for_each_nodal_xi_entry(jac, |r, k, d| rhs[r] -= d * dir[k]);
    }

    /// A direction over all nodal coordinates from its ξ part `dir` and the
    /// solved dependent part `dep` (zero on fixed coordinates).
    pub(crate) fn scatter_direction(
        &self,
        mech: &Mechanism,
        dir: &[f64],
        dep: &[f64],
        out: &mut [f64],
    ) {
        let n_q = self.n_q;
        for (i, r) in mech.x_roles.iter().enumerate() {
            out[i] = match r {
                XRole::Fixed => 0.0,
                XRole::Dof(k) => dir[*k],
                XRole::Input(k) => dir[n_q + k],
                XRole::Dependent(k) => dep[*k],
            };
        }
    }
}

/// The pattern of J (constraint rows × dependent coordinates) from the
/// elements' row and column maps, and each element's scatter positions.
fn jacobian_pattern(
    maps: &[ElemMap],
    n_c: usize,
    dense_up_to: usize,
) -> (JacobianLu, Vec<Vec<usize>>) {
    let mut entries = vec![];
    let mut owner = vec![];
    for (k, m) in maps.iter().enumerate() {
        for (a, r) in m.rows.iter().enumerate() {
            let Some(r) = r else { continue };
            for (c, col) in m.cols.iter().enumerate() {
                if let Some(col) = col {
                    entries.push((*r, *col));
                    owner.push((k, a * m.nx + c));
                }
            }
        }
    }
    let (lu, positions) = JacobianLu::with_dense_limit(n_c, &entries, dense_up_to);
    let mut jpos: Vec<Vec<usize>> = maps.iter().map(|m| vec![NO_ENTRY; m.ne * m.nx]).collect();
    for ((k, local), p) in owner.into_iter().zip(positions) {
        jpos[k][local] = p;
    }
    (lu, jpos)
}

/// The entries of the constraint rows with respect to the nodal coordinates
/// in ξ, and the rows of J with their dependent columns, element by element
/// (see the fields `xi_entries`, `dep_rows` and `dep_entries` of
/// [`Layout`]).
fn jacobian_entries(
    mech: &Mechanism,
    maps: &[ElemMap],
    xi_of_x: &[Option<usize>],
) -> (Vec<XiEntry>, Vec<DepRow>, Vec<(usize, usize)>) {
    let mut xi_entries = vec![];
    let (mut dep_rows, mut dep_entries) = (vec![], vec![]);
    for (ei, (e, m)) in mech.elements.iter().zip(maps).enumerate() {
        for (c, gi) in e.x_index.iter().enumerate() {
            let Some(col) = xi_of_x[*gi] else { continue };
            for (a, r) in m.rows.iter().enumerate() {
                if let Some(row) = r {
                    xi_entries.push(XiEntry {
                        row: *row,
                        col,
                        element: ei,
                        local: a * m.nx + c,
                    });
                }
            }
        }
        for (a, r) in m.rows.iter().enumerate() {
            let Some(r) = r else { continue };
            let start = dep_entries.len();
            for (c, col) in m.cols.iter().enumerate() {
                if let Some(k) = col {
                    dep_entries.push((*k, a * m.nx + c));
                }
            }
            dep_rows.push((*r, (ei, start..dep_entries.len())));
        }
    }
    (xi_entries, dep_rows, dep_entries)
}

/// Mean distance between the first two position slots of the elements that
/// have two nodes: the length unit of the Newton tolerance.
fn characteristic_length(mech: &Mechanism) -> f64 {
    use flexmb_element::Slot;
    let mut sum = 0.0;
    let mut n = 0usize;
    for e in &mech.elements {
        let slots = e.element.slots();
        let mut starts = vec![];
        let mut off = 0;
        for s in slots {
            if matches!(s, Slot::Position2 | Slot::Position3) {
                starts.push((off, s.len()));
            }
            off += s.len();
        }
        if starts.len() >= 2 {
            let ((a, k), (b, _)) = (starts[0], starts[1]);
            let d: f64 = (0..k)
                .map(|c| (mech.x0[e.x_index[b + c]] - mech.x0[e.x_index[a + c]]).powi(2))
                .sum::<f64>()
                .sqrt();
            if d > 0.0 {
                sum += d;
                n += 1;
            }
        }
    }
    if n == 0 {
        1.0
    } else {
        sum / n as f64
    }
}
