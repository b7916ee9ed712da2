//! First-order transfer functions F,ξ and E,ξ from one factorization of J
//! (thesis (5.8a), (6.6a)), and the products with them that need no F,ξ
//! matrix.

use crate::{Kinematics, KinematicsError};
use faer::Mat;

/// A read-only view of the kinematic state whose F,ξ and E,ξ are of its
/// configuration ([`Kinematics::first_order_view`]). The rates are those of
/// the last [`Kinematics::velocities`] and [`Kinematics::accelerations`].
#[derive(Clone, Copy, Debug)]
pub struct FirstOrderView<'a> {
    /// Nodal coordinates x.
    pub x: &'a [f64],
    /// Deformations ε.
    pub eps: &'a [f64],
    /// ẋ.
    pub xd: &'a [f64],
    /// ε̇.
    pub epsd: &'a [f64],
    /// ẍ for q̈ = 0.
    pub xdd0: &'a [f64],
    /// F,ξ (n_x × (n_q + n_u)).
    pub f: &'a Mat<f64>,
    /// E,ξ (n_ε × (n_q + n_u)).
    pub e: &'a Mat<f64>,
}

impl Kinematics {
    /// F,ξ and E,ξ at the last solved configuration, from the factorization of
    /// the last Newton iteration (thesis (5.8a), (6.6a)).
    pub fn first_order(&mut self) {
        self.ensure_lu_at_x();
        let layout = &self.layout;
        let n_xi = layout.n_xi();
        let (rhs, first) = (&mut self.ws.rhs, &mut self.first);
        rhs.fill(0.0);
        // deformation coordinates in ξ: unit entries on their rows
        for (j, k) in layout.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(r)) = (k, layout.row_of[j]) {
                rhs[(r, *k)] = 1.0;
            }
        }
        // nodal coordinates in ξ: −∂D_c/∂x_i
        layout.for_each_nodal_xi_entry(&self.jac.local, |r, k, d| rhs[(r, k)] -= d);
        self.factorization.lu.solve_in_place(rhs.as_mut());
        // rows of fixed coordinates stay zero and those of ξ stay unit: only
        // the dependent rows change (F and E start as zeros)
        for c in 0..n_xi {
            let src = rhs.col_as_slice(c);
            let dst = first.f.col_as_slice_mut(c);
            for (k, &i) in self.mech.dependent.iter().enumerate() {
                dst[i] = src[k];
            }
        }
        for (i, k) in layout.xi_of_x.iter().enumerate() {
            if let Some(k) = k {
                first.f[(i, *k)] = 1.0;
            }
        }
        // E,ξ = D,x F,ξ on the deformations that are not constraint rows;
        // exact (zero or unit) on rigid / DOF / input rows
        for (j, k) in layout.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(_)) = (k, layout.row_of[j]) {
                first.e[(j, *k)] = 1.0;
            }
        }
        for &(ei, a) in &layout.free_deformations {
            let e = &self.mech.elements[ei];
            let nx = layout.maps[ei].nx;
            let row = &self.jac.local[ei][a * nx..(a + 1) * nx];
            let j = e.eps_offset + a;
            for col in 0..n_xi {
                let fcol = first.f.col_as_slice(col);
                let mut s = 0.0;
                for (c, gi) in e.x_index.iter().enumerate() {
                    s += row[c] * fcol[*gi];
                }
                first.e[(j, col)] = s;
            }
        }
        first.valid = true;
    }

    /// F,ξᵀ y for a vector y over the nodal coordinates, at the last solved
    /// configuration, by one adjoint solve with Jᵀ and without forming F,ξ:
    /// with F,ξ = J⁻¹B on the dependent coordinates (thesis (5.8a)),
    /// F,ξᵀy = y_ξ + Bᵀ(J⁻ᵀ y_dep), B the right-hand side of
    /// [`first_order`](Self::first_order). `out` has n_q + n_u entries.
    pub fn transfer_transpose_times(&mut self, y: &[f64], out: &mut [f64]) {
        self.ensure_lu_at_x();
        let layout = &self.layout;
        let mu = &mut self.ws.dep;
        for (k, &i) in self.mech.dependent.iter().enumerate() {
            mu[k] = y[i];
        }
        self.factorization.lu.solve_transpose_vec(mu);
        out.fill(0.0);
        // nodal coordinates in ξ: their own entry minus Σ μ_r ∂D_r/∂x_i
        for (i, k) in layout.xi_of_x.iter().enumerate() {
            if let Some(k) = k {
                out[*k] += y[i];
            }
        }
        layout.for_each_nodal_xi_entry(&self.jac.local, |r, k, d| out[k] -= d * mu[r]);
        // deformation coordinates in ξ: a unit entry on their row
        for (j, k) in layout.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(r)) = (k, layout.row_of[j]) {
                out[*k] += mu[r];
            }
        }
    }

    /// F,q V into `out` (n_x × k) for k directions of the degrees of
    /// freedom, the columns of V (n_q × k), without F,ξ: one block solve
    /// J Y_dep = B [V; 0] (thesis (5.8a) along each column). With a
    /// reduction basis G,z as V this is the reduced transfer matrix
    /// F,z = F,q G,z of (6.15): k solves instead of the n_q + n_u of F,ξ.
    /// J is factorized at x first if its factorization is of another
    /// configuration (after [`solve_chord`](Self::solve_chord)); the solves
    /// that follow (velocities, accelerations) are then direct too. Refining
    /// the block against the old factorization instead, as the velocities
    /// are ([`velocities_refined`](Self::velocities_refined)), measured 8 %
    /// more instructions per evaluation for MSI-2 of the spatial guidance
    /// (33-row J, k = 2) and 40 % more for a 13-mode basis of it (77 rows).
    /// Allocates only when k changes.
    ///
    /// # Errors
    ///
    /// [`KinematicsError::Length`] when V does not have n_q rows or `out`
    /// is not n_x × k; a singular J as from the position solve.
    pub fn transfer_matrix(
        &mut self,
        v: faer::MatRef<'_, f64>,
        mut out: faer::MatMut<'_, f64>,
    ) -> Result<(), KinematicsError> {
        let (n_q, k) = (self.layout.n_q, v.ncols());
        let n_x = self.mech.n_x();
        self.check_lengths(&[
            ("the rows of V", v.nrows(), n_q),
            ("the rows of F,q V", out.nrows(), n_x),
            ("the columns of F,q V", out.ncols(), k),
        ])?;
        if !(self.factorization.valid && self.factorization.at_x) {
            self.factor_at_x()?;
        }
        let (layout, mech, jac) = (&self.layout, &*self.mech, &self.jac.local);
        let ws = &mut self.ws;
        let n_c = mech.constraint_rows.len();
        if ws.block.ncols() != k || ws.block.nrows() != n_c {
            ws.block = Mat::zeros(n_c, k);
        }
        let dir = &mut ws.xi_dir;
        dir[n_q..].fill(0.0);
        for c in 0..k {
            for (i, d) in dir[..n_q].iter_mut().enumerate() {
                *d = v[(i, c)];
            }
            layout.direction_rhs(mech, jac, None, dir, ws.block.col_as_slice_mut(c));
        }
        self.factorization.lu.solve_in_place(ws.block.as_mut());
        for c in 0..k {
            for (i, d) in dir[..n_q].iter_mut().enumerate() {
                *d = v[(i, c)];
            }
            let dep = ws.block.col_as_slice(c);
            let dst = out.as_mut().col_mut(c);
            match dst.try_as_col_major_mut() {
                Some(d) => layout.scatter_direction(mech, dir, dep, d.as_slice_mut()),
                None => {
                    // (a strided destination: through the work vector)
                    let w = &mut ws.work[..n_x];
                    layout.scatter_direction(mech, dir, dep, w);
                    for (i, x) in w.iter().enumerate() {
                        out[(i, c)] = *x;
                    }
                }
            }
        }
        Ok(())
    }

    /// y += D,xᵀ s, the nodal forces of deformation stresses s (all
    /// deformations, at the last solved configuration).
    pub fn add_deformation_forces(&self, s: &[f64], y: &mut [f64]) {
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.layout.maps[ei];
            let jl = &self.jac.local[ei];
            for a in 0..m.ne {
                let v = s[e.eps_offset + a];
                if v == 0.0 {
                    continue;
                }
                for (c, gi) in e.x_index.iter().enumerate() {
                    y[*gi] += jl[a * m.nx + c] * v;
                }
            }
        }
    }
}
