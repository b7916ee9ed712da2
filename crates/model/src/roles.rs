//! Coordinate and deformation roles, and the choice of degrees of freedom
//! (thesis (6.4)): fixed / DOF / prescribed / dependent nodal coordinates and
//! rigid / DOF / prescribed / dependent deformations. Counts and regularity are
//! checked with an SVD of the constraint Jacobian at the reference
//! configuration, which also names redundant equations or undetermined
//! coordinates.

use crate::local_span::{LocalSpan, Verdict};
use crate::mechanism::*;
use crate::scene::*;
use crate::ModelError;
use faer::Mat;

mod dense;
mod local;
mod memory;
mod selection;
mod sparse;
#[cfg(test)]
mod tests;

pub(crate) use dense::RANK_TOL;
use dense::{choose_dense, names_in, null_spaces};
use local::regular_by_local_bounds;
use memory::dense_bytes;
pub(crate) use memory::{check_dense, human_bytes, physical_memory};
pub(crate) use selection::resolve;
use sparse::{choose_sparse, Blocks};

/// A sparse matrix by rows: each row's nonzero entries (column, value).
pub(crate) type SparseRows = Vec<Vec<(usize, f64)>>;

/// The global deformation Jacobian D,x at x, sparse: for every deformation its
/// nonzero entries (global nodal index, value), sorted by index. Entries of one
/// index are summed in element order, as a dense assembly would.
pub(crate) fn sparse_jacobian(mech: &Mechanism, x: &[f64]) -> SparseRows {
    let mut rows: Vec<Vec<(usize, f64)>> = vec![vec![]; mech.n_eps()];
    let mut xl = vec![];
    let mut eps = vec![];
    let mut jl = vec![];
    for e in &mech.elements {
        let (ne, nx) = (e.element.n_eps(), e.element.n_x());
        if ne == 0 {
            continue;
        }
        xl.clear();
        xl.extend(e.x_index.iter().map(|i| x[*i]));
        eps.clear();
        eps.resize(ne, 0.0);
        jl.clear();
        jl.resize(ne * nx, 0.0);
        e.element
            .deformations_and_jacobian(&xl, None, &mut eps, &mut jl);
        for r in 0..ne {
            let row = &mut rows[e.eps_offset + r];
            for (c, gi) in e.x_index.iter().enumerate() {
                row.push((*gi, jl[r * nx + c]));
            }
        }
    }
    for row in &mut rows {
        // stable: equal indices keep element order, so the sums are those of
        // the dense assembly `0.0 + v1 + v2 + ...`
        row.sort_by_key(|(i, _)| *i);
        let mut merged: Vec<(usize, f64)> = Vec::with_capacity(row.len());
        for (i, v) in row.drain(..) {
            match merged.last_mut() {
                Some((j, s)) if *j == i => *s += v,
                _ => merged.push((i, 0.0 + v)),
            }
        }
        *row = merged;
    }
    rows
}

/// Role of a coordinate or deformation while the roles are assigned.
#[derive(Clone, Copy, PartialEq, Debug)]
pub(crate) enum R {
    Free,
    Fixed,
    Rigid,
    Input,
}

/// How the degrees of freedom are chosen.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Method {
    /// Dense below [`DENSE_MAX_FREE`] free coordinates, sparse above.
    Auto,
    /// One SVD of the whole constraint Jacobian (the original method).
    Dense,
    /// Local bounds ([`crate::local_span`]), and where they do not decide,
    /// connected blocks, eliminated as they become determined (forced: also
    /// the final regularity check, which `Auto` does with an SVD up to
    /// [`DENSE_MAX_DEPENDENT`] dependent coordinates).
    Sparse,
    /// `Sparse` without the local bounds: the blocks alone (tests).
    #[cfg_attr(not(test), allow(dead_code))]
    Blocks,
}

/// Up to this many free coordinates the dense SVD is used: it takes
/// milliseconds there.
pub(crate) const DENSE_MAX_FREE: usize = 300;

/// Up to this many dependent coordinates the final regularity check is an SVD.
const DENSE_MAX_DEPENDENT: usize = 1000;

thread_local! {
    /// The method `assign` uses (tests compare the two).
    pub(crate) static METHOD: std::cell::Cell<Method> = const { std::cell::Cell::new(Method::Auto) };
    /// How often the local bounds did not decide and the blocks were used
    /// (tests check that a chain needs them nowhere).
    pub(crate) static BLOCK_FALLBACKS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

fn count_fallback() {
    BLOCK_FALLBACKS.with(|c| c.set(c.get() + 1));
}

/// What the choice of DOFs works on: the roles given by the scene and the
/// constraint Jacobian at the reference configuration.
struct Problem<'a> {
    mech: &'a Mechanism,
    xr: &'a [R],
    er: &'a [R],
    /// Free nodal coordinates (global indices), ascending.
    free: Vec<usize>,
    /// Position of a nodal coordinate in `free` (usize::MAX if not free).
    free_pos: Vec<usize>,
    /// Rigid and prescribed deformations: the equations.
    crow: Vec<usize>,
    /// Sparse D,x at the reference configuration.
    rows: Vec<Vec<(usize, f64)>>,
}

impl Problem<'_> {
    /// Norm of deformation row j over the free coordinates.
    fn free_norm(&self, j: usize) -> f64 {
        self.rows[j]
            .iter()
            .filter(|(i, _)| self.free_pos[*i] != usize::MAX)
            .map(|(_, v)| v.powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Row j over the free coordinates (indices into `free`), divided by `nrm`.
    fn free_row(&self, j: usize, nrm: f64) -> Vec<(usize, f64)> {
        self.rows[j]
            .iter()
            .filter(|(i, _)| self.free_pos[*i] != usize::MAX)
            .map(|(i, v)| (self.free_pos[*i], v / nrm))
            .collect()
    }

    /// A candidate as a unit-norm row over the free coordinates.
    fn candidate(&self, c: Coordinate) -> Vec<(usize, f64)> {
        match c {
            Coordinate::Node(i) => vec![(self.free_pos[i], 1.0)],
            Coordinate::Def(j) => self.free_row(j, self.free_norm(j).max(1e-300)),
        }
    }

    /// An equation row, normalized (a zero row stays zero).
    fn equation(&self, j: usize) -> Vec<(usize, f64)> {
        let nrm = self.free_norm(j);
        if nrm > 0.0 {
            self.free_row(j, nrm)
        } else {
            vec![]
        }
    }

    fn fits_dense(&self) -> bool {
        let (m, n) = (self.mech.n_eps(), self.mech.n_x());
        let (c, f) = (self.crow.len(), self.free.len());
        // D,x; C; its SVD (U, V, a copy of C); the null space
        let b = dense_bytes(m, n, 1)
            + dense_bytes(c, f, 2)
            + dense_bytes(c, c, 1)
            + dense_bytes(f, f, 2);
        b <= (physical_memory() / 4) as f64
    }
}

/// Decides whether a candidate adds a direction to the motions the chosen
/// equations leave free.
trait Oracle {
    fn accept(&mut self, c: Coordinate) -> bool;
}

/// The acceptance rule: residual `nr` against the norm `n0` of the candidate's
/// projection on the motions the equations leave free (needed only near the
/// threshold, so computed on demand).
fn accepted(nr: f64, n0: impl FnOnce() -> f64) -> bool {
    if nr > 1e-6 {
        return true; // n0 ≤ 1 for a unit candidate, so the threshold is ≤ 1e-6
    }
    if nr <= 1e-9 {
        return false; // the threshold is ≥ 1e-9
    }
    let n0 = n0();
    n0 >= 1e-12 && nr > 1e-6 * n0.max(1e-3)
}

/// The greedy choice: `dofs_first`, then the scene's choice, each candidate
/// kept when the oracle finds a new direction; stops at `d`.
fn greedy(
    scene: &Scene,
    p: &Problem,
    d: usize,
    oracle: &mut dyn Oracle,
) -> Result<Vec<Coordinate>, ModelError> {
    let (mech, xr, er) = (p.mech, p.xr, p.er);
    let mut chosen: Vec<Coordinate> = vec![];
    let nodal_candidates = || -> Vec<usize> {
        // node by node: a planar angle first (a pinned link is best described by
        // its angle), then the position, then Euler parameters with the largest
        // reference value last (it becomes the dependent one); so a free body's
        // motion is described by one node's position and orientation rather than
        // by positions of other nodes (which become singular at 90°). Then modes.
        let mut v = vec![];
        for n in &mech.nodes {
            match &n.orientation {
                Some(o) if o.len() == 1 => {
                    v.push(o[0]);
                    v.extend(n.position.iter().copied());
                }
                Some(o) => {
                    v.extend(n.position.iter().copied());
                    let mut o = o.clone();
                    o.sort_by(|a, b| mech.x0[*a].abs().total_cmp(&mech.x0[*b].abs()));
                    v.extend(o);
                }
                None => v.extend(n.position.iter().copied()),
            }
        }
        for (_, g) in &mech.mode_groups {
            v.extend(g.iter().copied());
        }
        v.into_iter().filter(|i| xr[*i] == R::Free).collect()
    };
    let free_role = |c: Coordinate| match c {
        Coordinate::Node(i) => (xr[i] == R::Free, mech.x_names[i].clone()),
        Coordinate::Def(j) => (er[j] == R::Free, mech.eps_names[j].clone()),
    };
    for s in &scene.dofs_first {
        for c in resolve(mech, s, "dofs_first")? {
            let (ok, name) = free_role(c);
            if !ok {
                return Err(ModelError::Role {
                    name,
                    message: "is fixed, rigid or prescribed and cannot be a degree of freedom"
                        .into(),
                });
            }
            if !oracle.accept(c) {
                return Err(ModelError::OverConstrained {
                    redundant: vec![format!("{name} (as a degree of freedom)")],
                });
            }
            chosen.push(c);
        }
    }
    let already: std::collections::HashSet<Coordinate> = chosen.iter().copied().collect();
    match &scene.dofs {
        DofChoice::Deformations | DofChoice::NodalCoordinates => {
            if scene.dofs == DofChoice::Deformations {
                let mut real = vec![false; mech.n_eps()];
                for e in &mech.elements {
                    // the anticlastic overlay's deformations are energy
                    // measures of its curl amplitudes (which become nodal
                    // DOFs below), not a description of the motion
                    let t = e.element.type_name();
                    if t != "Euler-parameter normalization" && t != flexmb_element::ANTICLASTIC_TYPE
                    {
                        for r in &mut real[e.eps_offset..e.eps_offset + e.element.n_eps()] {
                            *r = true;
                        }
                    }
                }
                for j in 0..mech.n_eps() {
                    if chosen.len() == d {
                        break;
                    }
                    if er[j] == R::Free && real[j] && oracle.accept(Coordinate::Def(j)) {
                        chosen.push(Coordinate::Def(j));
                    }
                }
            }
            for i in nodal_candidates() {
                if chosen.len() == d {
                    break;
                }
                if !already.contains(&Coordinate::Node(i)) && oracle.accept(Coordinate::Node(i)) {
                    chosen.push(Coordinate::Node(i));
                }
            }
        }
        DofChoice::Explicit(list) => {
            let mut redundant = vec![];
            for s in list {
                for c in resolve(mech, s, "dofs")? {
                    let (ok, name) = free_role(c);
                    if !ok {
                        return Err(ModelError::Role {
                            name,
                            message:
                                "is fixed, rigid or prescribed and cannot be a degree of freedom"
                                    .into(),
                        });
                    }
                    if oracle.accept(c) {
                        chosen.push(c);
                    } else {
                        redundant.push(name);
                    }
                }
            }
            if !redundant.is_empty() {
                return Err(ModelError::OverConstrained {
                    redundant: redundant
                        .into_iter()
                        .map(|n| format!("{n} (as a degree of freedom)"))
                        .collect(),
                });
            }
        }
    }
    Ok(chosen)
}

/// The roles the scene gives (thesis (6.4)): fixed and prescribed nodal
/// coordinates, rigid and prescribed deformations (the Euler-parameter
/// normalizations rigid unless the whole orientation is fixed); every other
/// entry [`R::Free`]. Records the inputs and their roles in `mech`.
pub(crate) fn mark(scene: &Scene, mech: &mut Mechanism) -> Result<(Vec<R>, Vec<R>), ModelError> {
    let n_x = mech.n_x();
    let n_eps = mech.n_eps();
    let mut xr = vec![R::Free; n_x];
    let mut er = vec![R::Free; n_eps];
    let set = |v: &mut Vec<R>, i: usize, r: R, name: &str| -> Result<(), ModelError> {
        if v[i] != R::Free && v[i] != r {
            return Err(ModelError::Role {
                name: name.to_string(),
                message: "is given two roles (fixed/rigid and prescribed); give it one".into(),
            });
        }
        v[i] = r;
        Ok(())
    };
    for e in &mech.elements {
        if e.element.type_name() == "Euler-parameter normalization" {
            er[e.eps_offset] = R::Rigid;
        }
    }
    for s in &scene.fixed {
        for c in resolve(mech, s, "fixed")? {
            match c {
                Coordinate::Node(i) => set(&mut xr, i, R::Fixed, &mech.x_names[i])?,
                Coordinate::Def(j) => {
                    return Err(ModelError::Role {
                        name: mech.eps_names[j].clone(),
                        message: "a deformation cannot be fixed; list it under `rigid`".into(),
                    })
                }
            }
        }
    }
    // a fixed orientation means all four Euler parameters fixed: its
    // normalization is then an identity, not an equation
    for e in &mech.elements {
        if e.element.type_name() == "Euler-parameter normalization"
            && e.x_index.iter().all(|i| xr[*i] == R::Fixed)
        {
            er[e.eps_offset] = R::Free;
            mech.e_roles[e.eps_offset] = ERole::Dependent;
        }
    }
    for s in &scene.rigid {
        for c in resolve(mech, s, "rigid")? {
            match c {
                Coordinate::Def(j) => set(&mut er, j, R::Rigid, &mech.eps_names[j])?,
                Coordinate::Node(i) => {
                    return Err(ModelError::Role {
                        name: mech.x_names[i].clone(),
                        message: "a nodal coordinate cannot be rigid; list it under `fixed`".into(),
                    })
                }
            }
        }
    }
    for p in &scene.prescribed {
        let cs = resolve(mech, &p.what, "prescribed")?;
        if cs.len() != 1 {
            return Err(ModelError::invalid(
                "prescribed",
                format!(
                    "{:?} selects {} coordinates; prescribe exactly one per entry",
                    p.what,
                    cs.len()
                ),
            ));
        }
        crate::build::check_function(&format!("prescribed {:?}", p.what), &p.function)?;
        let k = mech.inputs.len();
        match cs[0] {
            Coordinate::Node(i) => {
                set(&mut xr, i, R::Input, &mech.x_names[i])?;
                mech.x_roles[i] = XRole::Input(k);
            }
            Coordinate::Def(j) => {
                set(&mut er, j, R::Input, &mech.eps_names[j])?;
                mech.e_roles[j] = ERole::Input(k);
            }
        }
        mech.inputs.push(Input {
            target: cs[0],
            function: p.function.clone(),
        });
    }
    Ok((xr, er))
}

/// The roles of every coordinate and deformation of `mech` (thesis (6.4),
/// (D.3)), in three stages: the roles the scene states ([`mark`]), the
/// choice of the DOFs among the free ones ([`choose_dofs`]) with the
/// dependent coordinates and constraint rows that follow ([`apply_roles`]),
/// and the check that the equations determine the dependent coordinates
/// ([`check_dependent_regular`]).
pub(crate) fn assign(scene: &Scene, mech: &mut Mechanism) -> Result<(), ModelError> {
    let (mut xr, mut er) = mark(scene, mech)?;
    let (chosen, rows, method) = choose_dofs(scene, mech, &xr, &er)?;
    apply_roles(mech, chosen, &mut xr, &mut er)?;
    check_dependent_regular(mech, &rows, method)
}

/// The DOFs chosen among the free coordinates at the reference
/// configuration (the greedy of the module docs, dense or sparse by size),
/// with the sparse constraint Jacobian there and the method used.
fn choose_dofs(
    scene: &Scene,
    mech: &Mechanism,
    xr: &[R],
    er: &[R],
) -> Result<(Vec<Coordinate>, SparseRows, Method), ModelError> {
    let n_x = mech.n_x();
    let n_eps = mech.n_eps();
    let free: Vec<usize> = (0..n_x).filter(|i| xr[*i] == R::Free).collect();
    let mut free_pos = vec![usize::MAX; n_x];
    for (k, i) in free.iter().enumerate() {
        free_pos[*i] = k;
    }
    let crow: Vec<usize> = (0..n_eps)
        .filter(|j| matches!(er[*j], R::Rigid | R::Input))
        .collect();
    let problem = Problem {
        mech,
        xr,
        er,
        free,
        free_pos,
        crow,
        rows: sparse_jacobian(mech, &mech.x0),
    };
    let method = match METHOD.with(|m| m.get()) {
        Method::Auto if problem.free.len() <= DENSE_MAX_FREE => Method::Dense,
        Method::Auto => Method::Sparse,
        m => m,
    };
    let chosen = match method {
        Method::Sparse | Method::Blocks => choose_sparse(scene, &problem, method)?,
        _ => choose_dense(scene, &problem)?,
    };
    Ok((chosen, problem.rows, method))
}

/// Gives the chosen DOFs their roles, the remaining free coordinates the
/// dependent ones and the rigid, DOF and prescribed deformations the
/// constraint rows; as many equations as dependent coordinates, or an
/// error.
fn apply_roles(
    mech: &mut Mechanism,
    chosen: Vec<Coordinate>,
    xr: &mut [R],
    er: &mut [R],
) -> Result<(), ModelError> {
    let n_x = mech.n_x();
    let n_eps = mech.n_eps();
    for (k, c) in chosen.iter().enumerate() {
        match *c {
            Coordinate::Node(i) => xr[i] = R::Rigid, // marker: DOF
            Coordinate::Def(j) => er[j] = R::Input,  // marker handled below
        }
        match *c {
            Coordinate::Node(i) => mech.x_roles[i] = XRole::Dof(k),
            Coordinate::Def(j) => mech.e_roles[j] = ERole::Dof(k),
        }
    }
    mech.dofs = chosen;
    let mut dep = vec![];
    for i in 0..n_x {
        match (xr[i], mech.x_roles[i]) {
            (R::Fixed, _) => mech.x_roles[i] = XRole::Fixed,
            (R::Free, _) => {
                mech.x_roles[i] = XRole::Dependent(dep.len());
                dep.push(i);
            }
            _ => {}
        }
    }
    for j in 0..n_eps {
        if er[j] == R::Rigid {
            mech.e_roles[j] = ERole::Rigid;
        }
    }
    mech.constraint_rows = (0..n_eps)
        .filter(|j| {
            matches!(
                mech.e_roles[*j],
                ERole::Rigid | ERole::Dof(_) | ERole::Input(_)
            )
        })
        .collect();
    mech.dependent = dep;
    if mech.constraint_rows.len() != mech.dependent.len() {
        return Err(ModelError::invalid(
            "coordinate roles",
            format!(
                "{} equations (rigid, DOF and prescribed deformations) for {} dependent coordinates",
                mech.constraint_rows.len(),
                mech.dependent.len()
            ),
        ));
    }
    Ok(())
}

/// The final regularity check of the Jacobian of the equations w.r.t. the
/// dependent coordinates (`rows`: the sparse constraint Jacobian at the
/// reference). The sparse method implies it: the equations and the chosen
/// DOFs are n_free independent rows over the free coordinates (every one
/// accepted with a residual), and the DOFs among the nodal coordinates are
/// unit rows, so the rest is regular on the dependent ones. In exact
/// arithmetic, that is: numerically the check still finds an equation that
/// depends on the free coordinates only through rounding errors (its
/// normalized row is noise). Up to DENSE_MAX_DEPENDENT the SVD does it,
/// above Gram–Schmidt on the blocks of the unnormalized rows.
fn check_dependent_regular(
    mech: &Mechanism,
    rows: &[Vec<(usize, f64)>],
    method: Method,
) -> Result<(), ModelError> {
    let n_x = mech.n_x();
    let nd = mech.dependent.len();
    let mut dep_pos = vec![usize::MAX; n_x];
    for (k, i) in mech.dependent.iter().enumerate() {
        dep_pos[*i] = k;
    }
    let forced = matches!(METHOD.with(|m| m.get()), Method::Sparse | Method::Blocks);
    if method != Method::Dense && (nd > DENSE_MAX_DEPENDENT || forced) {
        // in the greedy's order (equations, then the chosen deformations), in
        // which the blocks stay small
        let mut order: Vec<usize> = mech
            .constraint_rows
            .iter()
            .copied()
            .filter(|j| !matches!(mech.e_roles[*j], ERole::Dof(_)))
            .collect();
        order.extend(mech.dofs.iter().filter_map(|c| match c {
            Coordinate::Def(j) => Some(*j),
            Coordinate::Node(_) => None,
        }));
        let dep_rows: Vec<Vec<(usize, f64)>> = order
            .iter()
            .map(|j| {
                rows[*j]
                    .iter()
                    .filter(|(i, _)| dep_pos[*i] != usize::MAX)
                    .map(|(i, v)| (dep_pos[*i], *v))
                    .collect()
            })
            .collect();
        let norm = |r: &[(usize, f64)]| r.iter().map(|(_, v)| v * v).sum::<f64>().sqrt();
        let max = dep_rows.iter().map(|r| norm(r)).fold(0.0f64, f64::max);
        let tol = RANK_TOL * max.max(1e-300);
        if method == Method::Sparse && regular_by_local_bounds(&dep_rows, nd, tol) {
            return Ok(());
        }
        let mut blocks = Blocks::new(nd);
        let mut deficient = 0;
        for r in &dep_rows {
            let nr = blocks.residual(r);
            if nr > tol {
                blocks.commit(nr);
            } else {
                deficient += 1;
            }
        }
        if deficient > 0 {
            return Err(ModelError::UnderConstrained {
                count: deficient,
                undetermined: blocks
                    .undetermined()
                    .into_iter()
                    .map(|k| mech.x_names[mech.dependent[k]].clone())
                    .collect(),
            });
        }
        return Ok(());
    }
    check_dense("the Jacobian of the equations", nd, nd, 4)?;
    let mut jd = Mat::<f64>::zeros(mech.constraint_rows.len(), nd);
    for (r, j) in mech.constraint_rows.iter().enumerate() {
        for (i, v) in &rows[*j] {
            if dep_pos[*i] != usize::MAX {
                jd[(r, dep_pos[*i])] = *v;
            }
        }
    }
    let (rank, left, right) = null_spaces(
        &jd,
        "the Jacobian of the equations on the dependent coordinates",
    )?;
    if rank < mech.dependent.len() {
        let rn: Vec<String> = mech
            .constraint_rows
            .iter()
            .map(|j| mech.eps_names[*j].clone())
            .collect();
        let cn: Vec<String> = mech
            .dependent
            .iter()
            .map(|i| mech.x_names[*i].clone())
            .collect();
        let _ = names_in(&left, &rn);
        return Err(ModelError::UnderConstrained {
            count: mech.dependent.len() - rank,
            undetermined: names_in(&right, &cn),
        });
    }
    Ok(())
}
