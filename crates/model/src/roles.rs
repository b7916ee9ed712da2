//! Coordinate and deformation roles, and the choice of degrees of freedom
//! (thesis (6.4)): fixed / DOF / prescribed / dependent nodal coordinates and
//! rigid / DOF / prescribed / dependent deformations. Counts and regularity are
//! checked with an SVD of the constraint Jacobian at the reference
//! configuration, which also names redundant equations or undetermined
//! coordinates.

use crate::mechanism::*;
use crate::scene::*;
use crate::ModelError;
use faer::Mat;

/// Resolves a selection to coordinates.
pub(crate) fn resolve(
    mech: &Mechanism,
    s: &Select,
    ctx: &str,
) -> Result<Vec<Coordinate>, ModelError> {
    let unknown_node = |id: &str| ModelError::UnknownId {
        kind: "node",
        id: id.to_string(),
        context: ctx.to_string(),
        hint: String::new(),
    };
    match s {
        Select::Node(id) => {
            let n = mech.node(id).ok_or_else(|| unknown_node(id))?;
            let mut v: Vec<Coordinate> = n.position.iter().map(|i| Coordinate::Node(*i)).collect();
            if let Some(o) = &n.orientation {
                v.extend(o.iter().map(|i| Coordinate::Node(*i)));
            }
            Ok(v)
        }
        Select::Coord(id, c) => {
            let n = mech.node(id).ok_or_else(|| unknown_node(id))?;
            let orient = || {
                n.orientation.clone().ok_or_else(|| {
                    ModelError::invalid(ctx, format!("node '{id}' has no orientation coordinates (no element uses its rotation)"))
                })
            };
            let idx: Vec<usize> = match c {
                Component::X => vec![n.position[0]],
                Component::Y => vec![n.position[1]],
                Component::Z => {
                    if n.position.len() < 3 {
                        return Err(ModelError::invalid(ctx, "Z in a planar scene"));
                    }
                    vec![n.position[2]]
                }
                Component::Position => n.position.clone(),
                Component::Angle => {
                    let o = orient()?;
                    if o.len() != 1 {
                        return Err(ModelError::invalid(
                            ctx,
                            "Angle in a spatial scene: use Lambda(k) or Orientation",
                        ));
                    }
                    o
                }
                Component::Lambda(k) => {
                    let o = orient()?;
                    if o.len() != 4 || *k > 3 {
                        return Err(ModelError::invalid(
                            ctx,
                            format!("Lambda({k}) needs a spatial node and k in 0..=3"),
                        ));
                    }
                    vec![o[*k as usize]]
                }
                Component::Orientation => orient()?,
            };
            Ok(idx.into_iter().map(Coordinate::Node).collect())
        }
        Select::Modes(g) => {
            let (_, idx) = mech
                .mode_groups
                .iter()
                .find(|(n, _)| n == g)
                .ok_or_else(|| ModelError::UnknownId {
                    kind: "mode group",
                    id: g.clone(),
                    context: ctx.to_string(),
                    hint: String::new(),
                })?;
            Ok(idx.iter().map(|i| Coordinate::Node(*i)).collect())
        }
        Select::Def(eid, name) => {
            let members: Vec<&MechElement> = mech
                .elements
                .iter()
                .filter(|e| e.id == *eid || e.group == *eid)
                .collect();
            if members.is_empty() {
                return Err(ModelError::UnknownId {
                    kind: "element",
                    id: eid.clone(),
                    context: ctx.to_string(),
                    hint: String::new(),
                });
            }
            let mut v = vec![];
            for e in members {
                let names = e.element.deformation_names();
                for (k, n) in names.iter().enumerate() {
                    if name == "*" || n == name {
                        v.push(Coordinate::Def(e.eps_offset + k));
                    }
                }
                if name != "*" && !names.iter().any(|n| n == name) && e.element.n_eps() > 0 {
                    return Err(ModelError::invalid(
                        ctx,
                        format!(
                            "element '{}' ({}) has no deformation '{name}'; it has {:?}",
                            e.id,
                            e.element.type_name(),
                            names
                        ),
                    ));
                }
            }
            Ok(v)
        }
    }
}

/// The global deformation Jacobian D,x at x (dense, n_ε × n_x).
pub(crate) fn global_jacobian(mech: &Mechanism, x: &[f64]) -> Mat<f64> {
    let mut j = Mat::<f64>::zeros(mech.n_eps(), mech.n_x());
    for e in &mech.elements {
        let (ne, nx) = (e.element.n_eps(), e.element.n_x());
        if ne == 0 {
            continue;
        }
        let xl: Vec<f64> = e.x_index.iter().map(|i| x[*i]).collect();
        let mut eps = vec![0.0; ne];
        let mut jl = vec![0.0; ne * nx];
        e.element
            .deformations_and_jacobian(&xl, None, &mut eps, &mut jl);
        for r in 0..ne {
            for (c, gi) in e.x_index.iter().enumerate() {
                j[(e.eps_offset + r, *gi)] += jl[r * nx + c];
            }
        }
    }
    j
}

const RANK_TOL: f64 = 1e-9;

/// Rank and null spaces of a (row-normalized) matrix: (rank, left null
/// vectors as columns, right null space as columns).
fn null_spaces(a: &Mat<f64>) -> (usize, Mat<f64>, Mat<f64>) {
    let (m, n) = (a.nrows(), a.ncols());
    if m == 0 {
        return (0, Mat::zeros(0, 0), Mat::identity(n, n));
    }
    if n == 0 {
        return (0, Mat::identity(m, m), Mat::zeros(0, 0));
    }
    let svd = a.svd().expect("SVD converges");
    let s = svd.S().column_vector();
    let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0f64, f64::max);
    let r = (0..s.nrows())
        .filter(|&i| s[i] > RANK_TOL * smax.max(1e-300))
        .count();
    let u = svd.U();
    let v = svd.V();
    let left = Mat::from_fn(m, m - r, |i, j| u[(i, r + j)]);
    let right = Mat::from_fn(n, n - r, |i, j| v[(i, r + j)]);
    (r, left, right)
}

fn names_in(vectors: &Mat<f64>, names: &[String]) -> Vec<String> {
    let mut out = vec![];
    for j in 0..vectors.ncols() {
        let mx = (0..vectors.nrows())
            .map(|i| vectors[(i, j)].abs())
            .fold(0.0f64, f64::max);
        for i in 0..vectors.nrows() {
            if vectors[(i, j)].abs() > 0.2 * mx && !out.contains(&names[i]) {
                out.push(names[i].clone());
            }
        }
    }
    out
}

pub(crate) fn assign(scene: &Scene, mech: &mut Mechanism) -> Result<(), ModelError> {
    let n_x = mech.n_x();
    let n_eps = mech.n_eps();
    #[derive(Clone, Copy, PartialEq)]
    enum R {
        Free,
        Fixed,
        Rigid,
        Input,
    }
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
    // ---- the constraint Jacobian at the reference configuration
    let free: Vec<usize> = (0..n_x).filter(|i| xr[*i] == R::Free).collect();
    let crow: Vec<usize> = (0..n_eps)
        .filter(|j| matches!(er[*j], R::Rigid | R::Input))
        .collect();
    let jac = global_jacobian(mech, &mech.x0);
    let row_normalized = |rows: &[usize]| {
        Mat::from_fn(rows.len(), free.len(), |r, c| {
            let nrm = free
                .iter()
                .map(|fc| jac[(rows[r], *fc)].powi(2))
                .sum::<f64>()
                .sqrt();
            if nrm > 0.0 {
                jac[(rows[r], free[c])] / nrm
            } else {
                0.0
            }
        })
    };
    let c = row_normalized(&crow);
    let (rank, left, null) = null_spaces(&c);
    if rank < crow.len() {
        let names: Vec<String> = crow.iter().map(|j| mech.eps_names[*j].clone()).collect();
        return Err(ModelError::OverConstrained {
            redundant: names_in(&left, &names),
        });
    }
    let d = null.ncols();
    // ---- choose the DOFs: greedy selection of candidates whose projection on
    // the free motion space adds a new direction (Gram–Schmidt)
    let mut basis: Vec<Vec<f64>> = vec![];
    let accept = |g: Vec<f64>, basis: &mut Vec<Vec<f64>>| -> bool {
        let n0 = g.iter().map(|v| v * v).sum::<f64>().sqrt();
        if n0 < 1e-12 {
            return false;
        }
        let mut r = g;
        for _ in 0..2 {
            for b in basis.iter() {
                let p: f64 = r.iter().zip(b).map(|(a, c)| a * c).sum();
                for (ri, bi) in r.iter_mut().zip(b) {
                    *ri -= p * bi;
                }
            }
        }
        let nr = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if nr > 1e-6 * n0.max(1e-3) {
            basis.push(r.into_iter().map(|v| v / nr).collect());
            true
        } else {
            false
        }
    };
    let project_def = |j: usize| -> Vec<f64> {
        let nrm = free
            .iter()
            .map(|fc| jac[(j, *fc)].powi(2))
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        (0..d)
            .map(|k| {
                (0..free.len())
                    .map(|c| jac[(j, free[c])] / nrm * null[(c, k)])
                    .sum()
            })
            .collect()
    };
    let free_pos: std::collections::HashMap<usize, usize> =
        free.iter().enumerate().map(|(k, i)| (*i, k)).collect();
    let project_x = |i: usize| -> Vec<f64> { (0..d).map(|k| null[(free_pos[&i], k)]).collect() };
    let mut chosen: Vec<Coordinate> = vec![];
    let nodal_candidates = |mech: &Mechanism| -> Vec<usize> {
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
    for s in &scene.dofs_first {
        for c in resolve(mech, s, "dofs_first")? {
            let (ok, name) = match c {
                Coordinate::Node(i) => (xr[i] == R::Free, mech.x_names[i].clone()),
                Coordinate::Def(j) => (er[j] == R::Free, mech.eps_names[j].clone()),
            };
            if !ok {
                return Err(ModelError::Role {
                    name,
                    message: "is fixed, rigid or prescribed and cannot be a degree of freedom"
                        .into(),
                });
            }
            let g = match c {
                Coordinate::Node(i) => project_x(i),
                Coordinate::Def(j) => project_def(j),
            };
            if !accept(g, &mut basis) {
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
                for j in 0..n_eps {
                    if chosen.len() == d {
                        break;
                    }
                    if er[j] == R::Free
                        && mech.elements.iter().any(|e| {
                            e.eps_offset <= j
                                && j < e.eps_offset + e.element.n_eps()
                                && e.element.type_name() != "Euler-parameter normalization"
                        })
                        && accept(project_def(j), &mut basis)
                    {
                        chosen.push(Coordinate::Def(j));
                    }
                }
            }
            for i in nodal_candidates(mech) {
                if chosen.len() == d {
                    break;
                }
                if !already.contains(&Coordinate::Node(i)) && accept(project_x(i), &mut basis) {
                    chosen.push(Coordinate::Node(i));
                }
            }
        }
        DofChoice::Explicit(list) => {
            let mut redundant = vec![];
            for s in list {
                for c in resolve(mech, s, "dofs")? {
                    let (ok, name) = match c {
                        Coordinate::Node(i) => (xr[i] == R::Free, mech.x_names[i].clone()),
                        Coordinate::Def(j) => (er[j] == R::Free, mech.eps_names[j].clone()),
                    };
                    if !ok {
                        return Err(ModelError::Role {
                            name,
                            message:
                                "is fixed, rigid or prescribed and cannot be a degree of freedom"
                                    .into(),
                        });
                    }
                    let g = match c {
                        Coordinate::Node(i) => project_x(i),
                        Coordinate::Def(j) => project_def(j),
                    };
                    if accept(g, &mut basis) {
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
    if chosen.len() < d {
        // directions of the free motion space not reached by the DOFs
        let mut rest = vec![];
        for k in 0..d {
            let mut e = vec![0.0; d];
            e[k] = 1.0;
            let before = basis.len();
            if accept(e, &mut basis) {
                rest.push(basis[before].clone());
            }
        }
        let m = Mat::from_fn(free.len(), rest.len(), |i, j| {
            (0..d).map(|k| null[(i, k)] * rest[j][k]).sum()
        });
        let names: Vec<String> = free.iter().map(|i| mech.x_names[*i].clone()).collect();
        return Err(ModelError::UnderConstrained {
            count: d - chosen.len(),
            undetermined: names_in(&m, &names),
        });
    }
    // ---- roles
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
    // ---- final regularity check of the Jacobian of the equations w.r.t. the dependent coordinates
    let jd = Mat::from_fn(mech.constraint_rows.len(), mech.dependent.len(), |r, c| {
        jac[(mech.constraint_rows[r], mech.dependent[c])]
    });
    let (rank, left, right) = null_spaces(&jd);
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
