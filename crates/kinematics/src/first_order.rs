//! First-order transfer functions F,ξ and E,ξ from one factorization of J
//! (thesis (5.8a), (6.6a)), and the products with them that need no F,ξ
//! matrix.

use crate::Kinematics;
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
        let (n_q, n_u) = (self.n_q, self.n_u);
        let n_xi = n_q + n_u;
        self.rhs.fill(0.0);
        // deformation coordinates in ξ: unit entries on their rows
        for (j, k) in self.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(r)) = (k, self.row_of[j]) {
                self.rhs[(r, *k)] = 1.0;
            }
        }
        // nodal coordinates in ξ: −∂D_c/∂x_i
        let mut rhs = std::mem::replace(&mut self.rhs, Mat::new());
        self.for_each_nodal_xi_entry(|r, k, d| rhs[(r, k)] -= d);
        self.rhs = rhs;
        self.lu.solve_in_place(self.rhs.as_mut());
        // rows of fixed coordinates stay zero and those of ξ stay unit: only
        // the dependent rows change (F and E start as zeros)
        for c in 0..n_xi {
            let src = self.rhs.col_as_slice(c);
            let dst = self.f.col_as_slice_mut(c);
            for (k, &i) in self.mech.dependent.iter().enumerate() {
                dst[i] = src[k];
            }
        }
        for (i, k) in self.xi_of_x.iter().enumerate() {
            if let Some(k) = k {
                self.f[(i, *k)] = 1.0;
            }
        }
        // E,ξ = D,x F,ξ on the deformations that are not constraint rows;
        // exact (zero or unit) on rigid / DOF / input rows
        for (j, k) in self.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(_)) = (k, self.row_of[j]) {
                self.e[(j, *k)] = 1.0;
            }
        }
        for &(ei, a) in &self.free_deformations {
            let e = &self.mech.elements[ei];
            let nx = self.maps[ei].nx;
            let row = &self.jac_local[ei][a * nx..(a + 1) * nx];
            let j = e.eps_offset + a;
            for col in 0..n_xi {
                let fcol = self.f.col_as_slice(col);
                let mut s = 0.0;
                for (c, gi) in e.x_index.iter().enumerate() {
                    s += row[c] * fcol[*gi];
                }
                self.e[(j, col)] = s;
            }
        }
        self.first_order_valid = true;
    }

    /// Visits the entries ∂D_r/∂x_i of the constraint rows r with respect to
    /// the nodal coordinates x_i that belong to ξ (k = ξ index of x_i): the
    /// nodal columns of the right-hand side B of (5.8a), up to sign.
    pub(crate) fn for_each_nodal_xi_entry(&self, mut visit: impl FnMut(usize, usize, f64)) {
        for e in &self.xi_entries {
            visit(e.row, e.col, self.jac_local[e.element][e.local]);
        }
    }

    /// F,ξᵀ y for a vector y over the nodal coordinates, at the last solved
    /// configuration, by one adjoint solve with Jᵀ and without forming F,ξ:
    /// with F,ξ = J⁻¹B on the dependent coordinates (thesis (5.8a)),
    /// F,ξᵀy = y_ξ + Bᵀ(J⁻ᵀ y_dep), B the right-hand side of
    /// [`first_order`](Self::first_order). `out` has n_q + n_u entries.
    pub fn transfer_transpose_times(&mut self, y: &[f64], out: &mut [f64]) {
        self.ensure_lu_at_x();
        let mech = self.mech.clone();
        let mut mu = std::mem::take(&mut self.rhs_vec);
        for (k, &i) in mech.dependent.iter().enumerate() {
            mu[k] = y[i];
        }
        self.lu.solve_transpose_vec(&mut mu);
        out.fill(0.0);
        // nodal coordinates in ξ: their own entry minus Σ μ_r ∂D_r/∂x_i
        for (i, k) in self.xi_of_x.iter().enumerate() {
            if let Some(k) = k {
                out[*k] += y[i];
            }
        }
        self.for_each_nodal_xi_entry(|r, k, d| out[k] -= d * mu[r]);
        // deformation coordinates in ξ: a unit entry on their row
        for (j, k) in self.xi_of_e.iter().enumerate() {
            if let (Some(k), Some(r)) = (k, self.row_of[j]) {
                out[*k] += mu[r];
            }
        }
        self.rhs_vec = mu;
    }

    /// y += D,xᵀ s, the nodal forces of deformation stresses s (all
    /// deformations, at the last solved configuration).
    pub fn add_deformation_forces(&self, s: &[f64], y: &mut [f64]) {
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.maps[ei];
            let jl = &self.jac_local[ei];
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
