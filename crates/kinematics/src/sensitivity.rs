//! The sensitivities of the velocities and accelerations (thesis (5.8a),
//! (5.8b)) to q, X1 = ∂ẋ/∂q and X2 = ∂ẍ/∂q, for the linearization: one
//! solve with J per degree of freedom, with directional second derivatives
//! of the deformations.

use crate::Kinematics;
use faer::Mat;

impl Kinematics {
    /// Sensitivities of the velocities to q at the current state (after
    /// [`velocities`](Self::velocities)): X1 = ∂ẋ/∂q = (F,qq q̇) (n_x × n_q) and
    /// ∂ε̇/∂q (n_ε × n_q). Column k solves J X1_dep = −D_c,xx\[F,q e_k, ẋ\].
    pub fn velocity_sensitivity(&mut self) -> (Mat<f64>, Mat<f64>) {
        self.ensure_lu_at_x();
        self.ensure_first_order();
        let mech = &*self.mech;
        let (n_q, n_x, n_e) = (self.layout.n_q, mech.n_x(), mech.n_eps());
        let n_c = mech.constraint_rows.len();
        // c_k = D,xx[F e_k, ẋ] for every deformation
        let mut c = Mat::<f64>::zeros(n_e, n_q);
        self.directional_second(&mut c);
        let mut rhs = Mat::from_fn(n_c, n_q, |r, k| -c[(mech.constraint_rows[r], k)]);
        self.factorization.lu.solve_in_place(rhs.as_mut());
        let mut x1 = Mat::<f64>::zeros(n_x, n_q);
        for k in 0..n_q {
            for (r, &i) in mech.dependent.iter().enumerate() {
                x1[(i, k)] = rhs[(r, k)];
            }
        }
        // ∂ε̇/∂q = D,xx[F e_k, ẋ] + D,x X1
        let mut ed = c;
        self.add_jacobian_times(&x1, &mut ed);
        for j in 0..n_e {
            if self.layout.row_of[j].is_some() {
                for k in 0..n_q {
                    ed[(j, k)] = 0.0;
                }
            }
        }
        (x1, ed)
    }

    /// X2 = ∂ẍ/∂q (n_x × n_q) at fixed q̇, q̈ for the full accelerations `xdd`,
    /// given X1 from [`velocity_sensitivity`](Self::velocity_sensitivity):
    /// J X2_dep = −(D_c,xx\[F e_k, ẍ\] + D_c,xxx\[F e_k, ẋ, ẋ\] + 2 D_c,xx\[X1 e_k, ẋ\]).
    pub fn acceleration_sensitivity(&mut self, xdd: &[f64], x1: &Mat<f64>) -> Mat<f64> {
        self.ensure_lu_at_x();
        self.ensure_first_order();
        let mech = &*self.mech;
        let (n_q, n_x) = (self.layout.n_q, mech.n_x());
        let n_c = mech.constraint_rows.len();
        let mut rhs = Mat::<f64>::zeros(n_c, n_q);
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut al = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut gl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o1 = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o2 = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o3 = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in mech.elements.iter().enumerate() {
            let m = &self.layout.maps[ei];
            if m.ne == 0 || m.rows.iter().all(|r| r.is_none()) {
                continue;
            }
            for (a, gi) in e.x_index.iter().enumerate() {
                xl[a] = self.config.x[*gi];
                vl[a] = self.rates.xd[*gi];
                al[a] = xdd[*gi];
            }
            for k in 0..n_q {
                let mut any = false;
                for (a, gi) in e.x_index.iter().enumerate() {
                    fl[a] = self.first.f[(*gi, k)];
                    gl[a] = x1[(*gi, k)];
                    any |= fl[a] != 0.0 || gl[a] != 0.0;
                }
                if !any {
                    continue;
                }
                let nx = m.nx;
                e.element.deformation_second_derivative(
                    &xl[..nx],
                    &fl[..nx],
                    &al[..nx],
                    &mut o1[..m.ne],
                );
                e.element.deformation_third_derivative(
                    &xl[..nx],
                    &fl[..nx],
                    &vl[..nx],
                    &vl[..nx],
                    &mut o2[..m.ne],
                );
                e.element.deformation_second_derivative(
                    &xl[..nx],
                    &gl[..nx],
                    &vl[..nx],
                    &mut o3[..m.ne],
                );
                for (a, r) in m.rows.iter().enumerate() {
                    if let Some(r) = r {
                        rhs[(*r, k)] -= o1[a] + o2[a] + 2.0 * o3[a];
                    }
                }
            }
        }
        self.factorization.lu.solve_in_place(rhs.as_mut());
        let mut x2 = Mat::<f64>::zeros(n_x, n_q);
        for k in 0..n_q {
            for (r, &i) in mech.dependent.iter().enumerate() {
                x2[(i, k)] = rhs[(r, k)];
            }
        }
        x2
    }

    /// out(j, k) += Σ D_j,x · cols(:, k) over the elements.
    fn add_jacobian_times(&self, cols: &Mat<f64>, out: &mut Mat<f64>) {
        let n_k = cols.ncols();
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.layout.maps[ei];
            let jl = &self.jac.local[ei];
            for a in 0..m.ne {
                let j = e.eps_offset + a;
                for k in 0..n_k {
                    let mut s = 0.0;
                    for (c, gi) in e.x_index.iter().enumerate() {
                        s += jl[a * m.nx + c] * cols[(*gi, k)];
                    }
                    out[(j, k)] += s;
                }
            }
        }
    }

    /// out(j, k) = D_j,xx\[F,q e_k, ẋ\] for every deformation.
    fn directional_second(&self, out: &mut Mat<f64>) {
        let n_q = self.layout.n_q;
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut o = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in self.mech.elements.iter().enumerate() {
            let m = &self.layout.maps[ei];
            if m.ne == 0 {
                continue;
            }
            let mut moving = false;
            for (a, gi) in e.x_index.iter().enumerate() {
                xl[a] = self.config.x[*gi];
                vl[a] = self.rates.xd[*gi];
                moving |= vl[a] != 0.0;
            }
            if !moving {
                continue;
            }
            for k in 0..n_q {
                let mut any = false;
                for (a, gi) in e.x_index.iter().enumerate() {
                    fl[a] = self.first.f[(*gi, k)];
                    any |= fl[a] != 0.0;
                }
                if !any {
                    continue;
                }
                e.element.deformation_second_derivative(
                    &xl[..m.nx],
                    &fl[..m.nx],
                    &vl[..m.nx],
                    &mut o[..m.ne],
                );
                for a in 0..m.ne {
                    out[(e.eps_offset + a, k)] = o[a];
                }
            }
        }
    }
}
