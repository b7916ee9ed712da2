//! Set-up of [`Kinematics`]: the constraint rows and ξ indices of the
//! mechanism's coordinates, each element's row and column maps into the
//! kinematic Jacobian J of the constraint equations D_c(x) = (0, q_ε, u_ε)
//! (thesis (5.7), (6.5)), the pattern of J and the work buffers.

use crate::jacobian_lu::{JacobianLu, DENSE_UP_TO};
use crate::{ElemMap, Kinematics, NewtonOptions, XiEntry, NO_ENTRY};
use faer::Mat;
use flexmb_model::{Coordinate, ERole, Mechanism, XRole};
use std::sync::Arc;

impl Kinematics {
    /// Prepares the kinematics of a mechanism, starting from its reference
    /// configuration. The kinematic Jacobian is factorized densely up to 200
    /// rows and sparsely above.
    pub fn new(mech: Arc<Mechanism>) -> Self {
        Self::with_dense_limit(mech, DENSE_UP_TO)
    }

    /// As [`new`](Self::new), with the kinematic Jacobian factorized densely
    /// only when it has at most `dense_up_to` rows (sparse otherwise).
    pub fn with_dense_limit(mech: Arc<Mechanism>, dense_up_to: usize) -> Self {
        faer::set_global_parallelism(faer::Par::Seq);
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
        let (xi_entries, dep_rows, dep_entries) = jacobian_entries(&mech, &maps, &xi_of_x);
        let length_scale = characteristic_length(&mech);
        let jac_local = mech
            .elements
            .iter()
            .map(|e| vec![0.0; e.element.n_eps() * e.element.n_x()])
            .collect();
        let n_xi = n_q + n_u;
        let (lu, jpos) = jacobian_pattern(&maps, n_c, dense_up_to);
        let free_deformations = mech
            .elements
            .iter()
            .enumerate()
            .flat_map(|(k, e)| (0..maps[k].ne).map(move |a| (k, a, e.eps_offset + a)))
            .filter(|&(_, _, j)| row_of[j].is_none())
            .map(|(k, a, _)| (k, a))
            .collect();
        let mut s = Self {
            opts: NewtonOptions::default(),
            stop: None,
            maps,
            row_of,
            xi_of_x,
            xi_of_e,
            xi_entries,
            dep_rows,
            dep_entries,
            length_scale,
            n_q,
            n_u,
            t: 0.0,
            xi: vec![0.0; n_xi],
            xi_prev: vec![0.0; n_xi],
            x: mech.x0.clone(),
            eps: vec![0.0; n_eps],
            prev_eps: vec![0.0; n_eps],
            jac_local,
            jac_at_x: false,
            lu,
            jpos,
            free_deformations,
            f: Mat::zeros(n_x, n_xi),
            e: Mat::zeros(n_eps, n_xi),
            first_order_valid: false,
            have_solution: false,
            xid: vec![0.0; n_xi],
            xi_dir: vec![0.0; n_xi],
            block: Mat::zeros(0, 0),
            xd: vec![0.0; n_x],
            epsd: vec![0.0; n_eps],
            xdd0: vec![0.0; n_x],
            epsdd0: vec![0.0; n_eps],
            rhs: Mat::zeros(n_c, n_xi),
            work: vec![0.0; n_c.max(n_x)],
            target: vec![0.0; n_c],
            iterations: 0,
            x_good: mech.x0.clone(),
            x_predicted: mech.x0.clone(),
            xi_good: vec![0.0; n_xi],
            xi_target: vec![0.0; n_xi],
            lu_valid: false,
            lu_at_x: false,
            factorizations: 0,
            refinements: 0,
            extra_refinements: 0,
            continuations: 0,
            dx: vec![0.0; n_c],
            rhs_vec: vec![0.0; n_c],
            last_update: vec![0.0; n_c],
            dxx_vv: vec![0.0; n_eps],
            vel_rhs: vec![0.0; n_c],
            vel_res: vec![0.0; n_c],
            mech,
        };
        s.xi[..n_q].copy_from_slice(&s.mech.q0());
        for (k, inp) in s.mech.inputs.iter().enumerate() {
            if let Coordinate::Node(i) = inp.target {
                s.xi[n_q + k] = s.mech.x0[i];
            }
        }
        s.xi_good.copy_from_slice(&s.xi);
        s.xi_prev.copy_from_slice(&s.xi);
        s.start_from_reference();
        s
    }

    /// Takes the reference configuration as the last solution when it
    /// solves the constraint equations for ξ0 = (q0, u0) (the DOFs and inputs
    /// read off the reference): the first solve then predicts from it and
    /// stays on its branch, as every later solve stays on the branch of the
    /// one before (`branch_jump` in position.rs).
    fn start_from_reference(&mut self) {
        let n_q = self.n_q;
        for (r, j) in self.mech.constraint_rows.iter().enumerate() {
            self.target[r] = match self.mech.e_roles[*j] {
                ERole::Dof(k) => self.xi[k],
                ERole::Input(k) => self.xi[n_q + k],
                _ => 0.0,
            };
        }
        self.eval_elements(true);
        let tol = self.opts.tol * self.length_scale.max(1e-6);
        if self.eps.iter().all(|v| v.is_finite()) && self.residual_norm() <= tol {
            self.prev_eps.copy_from_slice(&self.eps);
            self.have_solution = true;
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
/// [`Kinematics`]).
#[allow(clippy::type_complexity)]
fn jacobian_entries(
    mech: &Mechanism,
    maps: &[ElemMap],
    xi_of_x: &[Option<usize>],
) -> (
    Vec<XiEntry>,
    Vec<(usize, (usize, std::ops::Range<usize>))>,
    Vec<(usize, usize)>,
) {
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
