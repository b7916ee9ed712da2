//! The linearized equations of motion (thesis Appendix E): about any state
//! (q, q̇, q̈, t) the matrices of g,q̈ δq̈ + g,q̇ δq̇ + g,q δq = 0 with
//! g,q̈ = M, g,q̇ = D + C, g,q = K + G + N (E.4)–(E.5), all exact: built from the
//! element derivatives, the transfer-function solves and their sensitivities
//! (X1 = ∂ẋ/∂q, X2 = ∂ẍ/∂q, ∂ε̇/∂q). No finite differences.

use crate::{Dynamics, DynamicsError};
use faer::Mat;
use flexmb_model::{Coordinate, ERole, Load, Mechanism};
use flexmb_rotation::EulerParameters;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The linearized matrices of (E.5) (or their rest form (E.6)).
#[derive(Clone, Debug)]
pub struct Linearization {
    /// Mass matrix Mq (E.5a).
    pub m: Mat<f64>,
    /// Damping Dq = E,qᵀ D E,q plus controller gains kd (E.5b).
    pub d: Mat<f64>,
    /// Velocity sensitivity Cq (E.5c): Coriolis and gyroscopic terms.
    pub c: Mat<f64>,
    /// Structural stiffness Kq = E,qᵀ S E,q plus controller gains kp (E.5d).
    pub k: Mat<f64>,
    /// Geometric stiffness Gq = F,qqᵀ(Mxẍ − f) + E,qqᵀσ (E.5e).
    pub g: Mat<f64>,
    /// Dynamic stiffness Nq (E.5f), including −F,qᵀ f,x F,q for
    /// position-dependent loads (consistent gravity on rotating elements,
    /// moments on Euler parameters), which (E.6) assumes absent.
    pub n: Mat<f64>,
    /// Where it was made: the mechanism whose DOFs index the matrices and
    /// the configuration, for the messages of analyses that fail on them.
    pub at: LinearizedAt,
}

/// The mechanism and configuration of a [`Linearization`], to name the
/// culprit when an analysis of its matrices fails.
#[derive(Clone)]
pub struct LinearizedAt {
    /// The mechanism; its DOFs index the matrices.
    pub mechanism: Arc<Mechanism>,
    /// Time.
    pub t: f64,
    /// The degrees of freedom.
    pub q: Vec<f64>,
    /// The scale of the nodal loads ([`Dynamics::set_load_scale`]).
    pub load_scale: f64,
}

impl std::fmt::Debug for LinearizedAt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinearizedAt")
            .field("mechanism", &self.mechanism.name)
            .field("t", &self.t)
            .field("q", &self.q)
            .field("load_scale", &self.load_scale)
            .finish()
    }
}

/// At most this many DOFs are given when a configuration is described.
const DESCRIBED_DOFS: usize = 3;

impl LinearizedAt {
    /// The configuration for messages: "at t = 0 s, the reference
    /// configuration", or with the DOFs furthest from their reference values
    /// ("at t = 0 s, load scale 0.5, where DOF q3 = S.x (node S) is 0.512
    /// (reference 0.5), …").
    pub fn describe(&self) -> String {
        let mut s = format!("at t = {} s", self.t);
        if self.load_scale != 1.0 {
            s += &format!(", load scale {}", self.load_scale);
        }
        let q0 = self.mechanism.q0();
        let mut moved: Vec<usize> = (0..self.q.len().min(q0.len()))
            .filter(|k| self.q[*k] != q0[*k])
            .collect();
        if moved.is_empty() {
            return s + ", the reference configuration";
        }
        let change = |k: &usize| (self.q[*k] - q0[*k]).abs();
        moved.sort_by(|a, b| change(b).total_cmp(&change(a)));
        let listed: Vec<String> = moved
            .iter()
            .take(DESCRIBED_DOFS)
            .map(|k| {
                format!(
                    "{} is {} (reference {})",
                    self.mechanism.dof_label(*k),
                    crate::short_number(self.q[*k]),
                    crate::short_number(q0[*k])
                )
            })
            .collect();
        let more = match moved.len().saturating_sub(DESCRIBED_DOFS) {
            0 => String::new(),
            m => format!(" and {m} more DOFs differ from the reference"),
        };
        format!("{s}, where {}{more}", listed.join(", "))
    }
}

impl Linearization {
    /// K + G + N = g,q.
    pub fn stiffness_total(&self) -> Mat<f64> {
        let mut s = self.k.clone();
        s += &self.g;
        s += &self.n;
        s
    }
    /// D + C = g,q̇.
    pub fn damping_total(&self) -> Mat<f64> {
        let mut s = self.d.clone();
        s += &self.c;
        s
    }
}

impl Dynamics {
    /// Adds Σ_e W_e · cols\[x_index, :\] into out\[x_index, :\] for element-level
    /// square matrices W_e (row-major, given by `local`).
    fn scatter_products(&self, local: &[Option<Vec<f64>>], cols: &Mat<f64>, out: &mut Mat<f64>) {
        let n_k = cols.ncols();
        for (e, w) in self.mech.elements.iter().zip(local) {
            let Some(w) = w else { continue };
            let n = e.x_index.len();
            for k in 0..n_k {
                let c = cols.col_as_slice(k);
                let o = out.col_as_slice_mut(k);
                for (a, ga) in e.x_index.iter().enumerate() {
                    let mut s = 0.0;
                    for (b, gb) in e.x_index.iter().enumerate() {
                        s += w[a * n + b] * c[*gb];
                    }
                    o[*ga] += s;
                }
            }
        }
    }

    /// The linearized matrices about (q, q̇, q̈) at time t, thesis (E.5).
    pub fn linearize(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Result<Linearization, DynamicsError> {
        let mech = self.mech.clone();
        let n_q = mech.n_dof();
        let n_x = mech.n_x();
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        let m = self.mq.clone();
        // full accelerations ẍ = F,q q̈ + ẍ0
        let fq = self.kin.f_xi().subcols(0, n_q).to_owned();
        let mut xdd = self.kin.xdd0().to_vec();
        for (k, v) in qdd.iter().enumerate() {
            if *v != 0.0 {
                for (o, f) in xdd.iter_mut().zip(fq.col_as_slice(k)) {
                    *o += f * v;
                }
            }
        }
        // element derivatives of w' = Mx ẍ + h − f
        let x = self.kin.x().to_vec();
        let xd = self.kin.xd().to_vec();
        let mut mass_local: Vec<Option<Vec<f64>>> = vec![];
        let mut wx_local: Vec<Option<Vec<f64>>> = vec![];
        let mut wxd_local: Vec<Option<Vec<f64>>> = vec![];
        let mut wprime = vec![0.0; n_x];
        for e in &mech.elements {
            let n = e.x_index.len();
            let xl: Vec<f64> = e.x_index.iter().map(|i| x[*i]).collect();
            if !e.element.has_inertia() {
                mass_local.push(None);
                wx_local.push(None);
                wxd_local.push(None);
                continue;
            }
            let vl: Vec<f64> = e.x_index.iter().map(|i| xd[*i]).collect();
            let al: Vec<f64> = e.x_index.iter().map(|i| xdd[*i]).collect();
            let mut ml = vec![0.0; n * n];
            e.element.mass_matrix(&xl, &mut ml);
            let mut fl = vec![0.0; n];
            e.element.inertia_force(&xl, &vl, &al, &mut fl);
            for (a, gi) in e.x_index.iter().enumerate() {
                wprime[*gi] += fl[a];
            }
            let mut dx = vec![0.0; n * n];
            let mut dxd = vec![0.0; n * n];
            e.element
                .inertia_force_derivatives(&xl, &vl, &al, &mut dx, &mut dxd);
            if let Some(g) = mech.gravity {
                let mut dg = vec![0.0; n * n];
                e.element.gravity_force_derivative(&xl, &g, &mut dg);
                for (a, b) in dx.iter_mut().zip(&dg) {
                    *a -= b;
                }
            }
            mass_local.push(Some(ml));
            wx_local.push(Some(dx));
            wxd_local.push(Some(dxd));
        }
        for (o, f) in wprime.iter_mut().zip(&self.f) {
            *o -= f;
        }
        // moments on Euler parameters: f_λ = 2 s Λᵀ m, ∂f/∂λ constant in λ
        let mut moment_local: Vec<(Vec<usize>, Vec<f64>)> = vec![];
        for ld in &mech.loads {
            if let Load::SpatialMoment {
                index,
                m: mv,
                function,
            } = ld
            {
                let s = self.load_factor * self.load_scale * function.value(t);
                let mut d = vec![0.0; 16];
                for b in 0..4 {
                    let mut e = [0.0; 4];
                    e[b] = 1.0;
                    let lt = EulerParameters(e).lambda().transpose();
                    for a in 0..4 {
                        d[a * 4 + b] = -2.0
                            * s
                            * (lt[(a, 0)] * mv[0] + lt[(a, 1)] * mv[1] + lt[(a, 2)] * mv[2]);
                    }
                }
                moment_local.push((index.to_vec(), d));
            }
        }
        // kinematic sensitivities
        let (x1, edq) = self.kin.velocity_sensitivity();
        let x2 = self.kin.acceleration_sensitivity(&xdd, &x1);
        // C = F,qᵀ (W_ẋ F,q + 2 Mx X1)
        let mut a = Mat::<f64>::zeros(n_x, n_q);
        self.scatter_products(&wxd_local, &fq, &mut a);
        let mut two_x1 = x1.clone();
        for v in two_x1.col_iter_mut() {
            for e in v.iter_mut() {
                *e *= 2.0;
            }
        }
        self.scatter_products(&mass_local, &two_x1, &mut a);
        let c = fq.transpose() * &a;
        // N = F,qᵀ (W_x F,q + W_ẋ X1 + Mx X2) + E,qᵀ D_eff ∂ε̇/∂q  (+ controllers on nodal rates)
        let mut b = Mat::<f64>::zeros(n_x, n_q);
        self.scatter_products(&wx_local, &fq, &mut b);
        self.scatter_products(&wxd_local, &x1, &mut b);
        self.scatter_products(&mass_local, &x2, &mut b);
        for (idx, d) in &moment_local {
            for k in 0..n_q {
                for (p, gp) in idx.iter().enumerate() {
                    let s: f64 = (0..4).map(|r| d[p * 4 + r] * fq[(idx[r], k)]).sum();
                    b[(*gp, k)] += s;
                }
            }
        }
        for ctl in &mech.controllers {
            if let Coordinate::Node(i) = ctl.on {
                for k in 0..n_q {
                    b[(i, k)] += ctl.kd * x1[(i, k)];
                }
            }
        }
        let mut n = fq.transpose() * &b;
        let e = self.kin.e_xi().subcols(0, n_q).to_owned();
        // damping in deformation space (elements and controllers)
        let mut ded = Mat::<f64>::zeros(mech.n_eps(), n_q);
        for el in &mech.elements {
            let Some(dm) = el.element.damping() else {
                continue;
            };
            let ne = el.element.n_eps();
            let o = el.eps_offset;
            for a_ in 0..ne {
                for b_ in 0..ne {
                    if dm[(a_, b_)] != 0.0 {
                        for k in 0..n_q {
                            ded[(o + a_, k)] += dm[(a_, b_)] * edq[(o + b_, k)];
                        }
                    }
                }
            }
        }
        for ctl in &mech.controllers {
            if let Coordinate::Def(j) = ctl.on {
                for k in 0..n_q {
                    ded[(j, k)] += ctl.kd * edq[(j, k)];
                }
            }
        }
        for (j, r) in mech.e_roles.iter().enumerate() {
            if matches!(r, ERole::Rigid | ERole::Input(_)) {
                for k in 0..n_q {
                    ded[(j, k)] = 0.0;
                }
            }
        }
        n += e.transpose() * &ded;
        let sigma = self.sigma.clone();
        let g = self.kin.second_order_contraction(&wprime, &sigma);
        let k = self.structural_stiffness();
        let d = self.damping_matrix();
        let at = self.linearized_at(t, q);
        Ok(Linearization {
            m,
            d,
            c,
            k,
            g,
            n,
            at,
        })
    }

    /// The rest form (E.6) at an equilibrium (q̇ = 0, q̈ = 0): M, D, K, G, with
    /// C = 0 and N = −F,qᵀ f,x F,q (zero for position-independent loads).
    /// No inertia forces or velocity sensitivities are computed.
    pub fn linearize_at_rest(&mut self, t: f64, q: &[f64]) -> Result<Linearization, DynamicsError> {
        self.linearize_at_rest_until(t, q, None)
    }

    /// [`linearize_at_rest`](Self::linearize_at_rest) that ends with
    /// [`DynamicsError::Interrupted`] when `stop` is set: it is read between
    /// the position solve and the assembly of each matrix, and inside that of
    /// the geometric stiffness (for the 1440-DOF flexure chain no part takes
    /// more than about 0.1 s, of 0.4 s in all).
    pub fn linearize_at_rest_until(
        &mut self,
        t: f64,
        q: &[f64],
        stop: Option<&AtomicBool>,
    ) -> Result<Linearization, DynamicsError> {
        let check = || crate::simulate::check_stop(stop);
        let n_q = self.mech.n_dof();
        check()?;
        self.kinematics_at(t, q, Some(&vec![0.0; n_q]))?;
        check()?;
        self.forces(t, false);
        self.inertia_until(stop)?;
        check()?;
        let m = self.mq.clone();
        let neg_f: Vec<f64> = self.f.iter().map(|v| -v).collect();
        let sigma = self.sigma.clone();
        let g = self
            .kin
            .second_order_contraction_until(&neg_f, &sigma, stop)
            .ok_or(DynamicsError::Interrupted)?;
        check()?;
        let k = self.structural_stiffness();
        let d = self.damping_matrix();
        check()?;
        let mut n = self.load_stiffness(t);
        for v in n.col_iter_mut() {
            for e in v.iter_mut() {
                *e = -*e;
            }
        }
        Ok(Linearization {
            m,
            d,
            c: Mat::zeros(n_q, n_q),
            k,
            g,
            n,
            at: self.linearized_at(t, q),
        })
    }

    /// The mechanism and configuration of a linearization at (t, q).
    fn linearized_at(&self, t: f64, q: &[f64]) -> LinearizedAt {
        LinearizedAt {
            mechanism: self.mech.clone(),
            t,
            q: q.to_vec(),
            load_scale: self.load_scale,
        }
    }
}
