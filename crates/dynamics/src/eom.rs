//! The equations of motion in independent coordinates (thesis (D.10)):
//! Mq q̈ = F,qᵀ (f − Mx ẍ0 − h) − E,qᵀ σ, with Mq = F,qᵀ Mx F,q assembled
//! element by element, and the residual g(q, q̇, q̈, t) of (E.1).

use crate::DynamicsError;
use faer::linalg::solvers::Solve;
use faer::Mat;
use flexmb_kinematics::Kinematics;
use flexmb_model::{Coordinate, ERole, Load, Mechanism};
use flexmb_rotation::EulerParameters;
use std::sync::Arc;

/// Energies of a state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energies {
    /// Kinetic energy T.
    pub kinetic: f64,
    /// Elastic energy ½εᵀSε (+ σ0ᵀε) of the non-rigid deformations.
    pub elastic: f64,
    /// Gravitational potential of the elements that have an exact one (point
    /// masses); see `gravity_exact`.
    pub gravitational: f64,
    /// True when every massive element contributed an exact potential; else
    /// use the integrated external work for energy balances.
    pub gravity_exact: bool,
}

/// The dynamics of one mechanism: kinematics plus forces; holds all buffers.
pub struct Dynamics {
    pub(crate) kin: Kinematics,
    pub(crate) mech: Arc<Mechanism>,
    pub(crate) f: Vec<f64>,
    pub(crate) sigma: Vec<f64>,
    pub(crate) w: Vec<f64>,
    pub(crate) mf: Mat<f64>,
    pub(crate) mq: Mat<f64>,
    pub(crate) rhs: Vec<f64>,
    /// Factor on loads and gravity (load stepping in statics).
    pub(crate) load_factor: f64,
    /// A persistent scale of the loads (not gravity), e.g. for load sweeps.
    pub(crate) load_scale: f64,
    /// The factorized static tangent of the last static Newton step (chord steps).
    pub(crate) static_factor: Option<crate::statics::StaticFactor>,
    evaluations: u64,
}

impl Dynamics {
    /// Prepares the dynamics of a mechanism.
    pub fn new(mech: Arc<Mechanism>) -> Self {
        let (n_x, n_e, n_q) = (mech.n_x(), mech.n_eps(), mech.n_dof());
        Self {
            kin: Kinematics::new(mech.clone()),
            f: vec![0.0; n_x],
            sigma: vec![0.0; n_e],
            w: vec![0.0; n_x],
            mf: Mat::zeros(n_x, n_q),
            mq: Mat::zeros(n_q, n_q),
            rhs: vec![0.0; n_q],
            load_factor: 1.0,
            load_scale: 1.0,
            static_factor: None,
            evaluations: 0,
            mech,
        }
    }
    /// The mechanism.
    pub fn mechanism(&self) -> &Arc<Mechanism> {
        &self.mech
    }
    /// The kinematics (configuration of the last evaluation).
    pub fn kinematics(&self) -> &Kinematics {
        &self.kin
    }
    /// Mutable access to the kinematics (Newton options, guesses).
    pub fn kinematics_mut(&mut self) -> &mut Kinematics {
        &mut self.kin
    }
    /// Number of degrees of freedom.
    pub fn n_q(&self) -> usize {
        self.mech.n_dof()
    }
    /// Number of equation-of-motion evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Solves the kinematics to first order (and velocities, accelerations if asked).
    pub(crate) fn kinematics_at(
        &mut self,
        t: f64,
        q: &[f64],
        qd: Option<&[f64]>,
    ) -> Result<(), DynamicsError> {
        self.kin
            .solve(q, t)
            .map_err(|e| DynamicsError::Kinematics { t, source: e })?;
        self.kin.first_order();
        if let Some(qd) = qd {
            if let Some(i) = qd.iter().position(|v| !v.is_finite()) {
                return Err(DynamicsError::NonFinite {
                    what: "q̇",
                    index: i,
                    t,
                });
            }
            self.kin.velocities(qd);
            self.kin.accelerations();
        }
        Ok(())
    }

    /// External nodal forces f (loads, gravity, controllers on nodal
    /// coordinates) and stress resultants σ (with damping and controllers on
    /// deformations; zero on rigid and prescribed deformations) at the current
    /// kinematic state. `with_rates`: include ε̇/ẋ terms (damping, D-action).
    pub(crate) fn forces(&mut self, t: f64, with_rates: bool) {
        let mech = self.mech.clone();
        let x = self.kin.x();
        let eps = self.kin.eps();
        self.f.fill(0.0);
        let lf = self.load_factor * self.load_scale;
        for l in &mech.loads {
            match l {
                Load::Force { index, f, function } => {
                    let s = lf * function.value(t);
                    for (k, i) in index.iter().enumerate() {
                        self.f[*i] += f[k] * s;
                    }
                }
                Load::PlanarMoment { index, m, function } => {
                    self.f[*index] += lf * m * function.value(t)
                }
                Load::SpatialMoment { index, m, function } => {
                    let s = lf * function.value(t);
                    let lam = EulerParameters([x[index[0]], x[index[1]], x[index[2]], x[index[3]]]);
                    let lt = lam.lambda().transpose();
                    for a in 0..4 {
                        self.f[index[a]] +=
                            2.0 * s * (lt[(a, 0)] * m[0] + lt[(a, 1)] * m[1] + lt[(a, 2)] * m[2]);
                    }
                }
            }
        }
        if let Some(g0) = mech.gravity {
            // the load scale of a load sweep does not scale gravity
            let g = g0.map(|v| v * self.load_factor);
            let mut xl = [0.0; 64];
            let mut fl = [0.0; 64];
            for e in &mech.elements {
                if !e.element.has_inertia() {
                    continue;
                }
                let n = e.x_index.len();
                for (k, gi) in e.x_index.iter().enumerate() {
                    xl[k] = x[*gi];
                }
                e.element.gravity_force(&xl[..n], &g, &mut fl[..n]);
                for (k, gi) in e.x_index.iter().enumerate() {
                    self.f[*gi] += fl[k];
                }
            }
        }
        // stresses
        let epsd = self.kin.epsd();
        for e in &mech.elements {
            let ne = e.element.n_eps();
            if ne == 0 {
                continue;
            }
            let o = e.eps_offset;
            let rate = if with_rates && e.element.damping().is_some() {
                Some(&epsd[o..o + ne])
            } else {
                None
            };
            e.element
                .stress(&eps[o..o + ne], rate, &mut self.sigma[o..o + ne]);
        }
        for c in &mech.controllers {
            let (r, rd, _) = c.reference.eval(t);
            match c.on {
                Coordinate::Node(i) => {
                    let v = if with_rates { self.kin.xd()[i] } else { 0.0 };
                    self.f[i] += c.kp * (r - x[i]) + if with_rates { c.kd * (rd - v) } else { 0.0 };
                }
                Coordinate::Def(j) => {
                    let v = if with_rates { epsd[j] } else { 0.0 };
                    self.sigma[j] -=
                        c.kp * (r - eps[j]) + if with_rates { c.kd * (rd - v) } else { 0.0 };
                }
            }
        }
        for (j, r) in mech.e_roles.iter().enumerate() {
            if matches!(r, ERole::Rigid | ERole::Input(_)) {
                self.sigma[j] = 0.0;
            }
        }
    }

    /// Assembles w = f − Mx ẍ0 − h and, if `mass`, Mf = Mx F,q and Mq = F,qᵀ Mx F,q.
    pub(crate) fn inertia(&mut self, mass: bool) {
        let mech = self.mech.clone();
        let n_q = mech.n_dof();
        let x = self.kin.x();
        let xd = self.kin.xd();
        let xdd0 = self.kin.xdd0();
        let fq = self.kin.f_xi();
        self.w.copy_from_slice(&self.f);
        if mass {
            self.mf.fill(0.0);
        }
        let mut xl = [0.0; 64];
        let mut vl = [0.0; 64];
        let mut al = [0.0; 64];
        let mut fl = [0.0; 64];
        let mut ml = [0.0; 64 * 64];
        for e in &mech.elements {
            if !e.element.has_inertia() {
                continue;
            }
            let n = e.x_index.len();
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = x[*gi];
                vl[k] = xd[*gi];
                al[k] = xdd0[*gi];
            }
            e.element
                .inertia_force(&xl[..n], &vl[..n], &al[..n], &mut fl[..n]);
            for (k, gi) in e.x_index.iter().enumerate() {
                self.w[*gi] -= fl[k];
            }
            if mass {
                e.element.mass_matrix(&xl[..n], &mut ml[..n * n]);
                // Mf[x_index, :] += M_e F_e, column by column (contiguous)
                for c in 0..n_q {
                    let fcol = fq.col_as_slice(c);
                    let mut any = false;
                    for (b, gb) in e.x_index.iter().enumerate() {
                        fl[b] = fcol[*gb];
                        any |= fl[b] != 0.0;
                    }
                    if !any {
                        continue;
                    }
                    let mcol = self.mf.col_as_slice_mut(c);
                    for (a, ga) in e.x_index.iter().enumerate() {
                        let row = &ml[a * n..a * n + n];
                        let mut s = 0.0;
                        for b in 0..n {
                            s += row[b] * fl[b];
                        }
                        mcol[*ga] += s;
                    }
                }
            }
        }
        if mass {
            let f = fq.subcols(0, n_q);
            faer::linalg::matmul::matmul(
                self.mq.as_mut(),
                faer::Accum::Replace,
                f.transpose(),
                self.mf.as_ref(),
                1.0,
                faer::Par::Seq,
            );
        }
    }

    /// rhs = F,qᵀ w − E,qᵀ σ.
    pub(crate) fn generalized_force(&mut self) {
        let n_q = self.mech.n_dof();
        let fq = self.kin.f_xi();
        let eq = self.kin.e_xi();
        for c in 0..n_q {
            let a: f64 = fq
                .col_as_slice(c)
                .iter()
                .zip(&self.w)
                .map(|(f, w)| f * w)
                .sum();
            let b: f64 = eq
                .col_as_slice(c)
                .iter()
                .zip(&self.sigma)
                .map(|(e, s)| e * s)
                .sum();
            self.rhs[c] = a - b;
        }
    }

    /// The equations of motion (D.10) solved for q̈ at (t, q, q̇).
    pub fn accelerations(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.evaluations += 1;
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        self.generalized_force();
        let llt = self
            .mq
            .llt(faer::Side::Lower)
            .map_err(|_| self.singular_mass())?;
        let mut r = Mat::from_fn(self.rhs.len(), 1, |i, _| self.rhs[i]);
        llt.solve_in_place(r.as_mut());
        for (i, v) in qdd.iter_mut().enumerate() {
            *v = r[(i, 0)];
            if !v.is_finite() {
                return Err(DynamicsError::NonFinite {
                    what: "q̈",
                    index: i,
                    t,
                });
            }
        }
        Ok(())
    }

    fn singular_mass(&self) -> DynamicsError {
        // the DOF with the smallest diagonal mass relative to the largest
        let n = self.mq.nrows();
        let diag: Vec<f64> = (0..n).map(|i| self.mq[(i, i)]).collect();
        let mx = diag.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let names: Vec<String> = diag
            .iter()
            .enumerate()
            .filter(|(_, v)| **v <= 1e-12 * mx)
            .map(|(i, _)| self.mech.coordinate_name(self.mech.dofs[i]).to_string())
            .collect();
        DynamicsError::SingularMass { dofs: names }
    }

    /// The residual g(q, q̇, q̈, t) = F,qᵀ(Mx ẍ − f) + E,qᵀσ of (E.1).
    pub fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        g: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        self.generalized_force();
        let n_q = g.len();
        for r in 0..n_q {
            let mut s = -self.rhs[r];
            for c in 0..n_q {
                s += self.mq[(r, c)] * qdd[c];
            }
            g[r] = s;
        }
        Ok(())
    }

    /// Scales the nodal loads (not gravity) by `s` in every later evaluation,
    /// statics and linearization: the parameter of a load sweep.
    pub fn set_load_scale(&mut self, s: f64) {
        self.load_scale = s;
    }

    /// Mq and the generalized force F,qᵀ(f − Mx ẍ0 − h) − E,qᵀσ at (t, q, q̇)
    /// with ẍ0 the accelerations for q̈ = 0: the pieces of (D.10) that a
    /// reduced model q = G(z) projects (thesis (6.15)).
    pub fn mass_and_force(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(&Mat<f64>, &[f64]), DynamicsError> {
        self.evaluations += 1;
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        self.generalized_force();
        Ok((&self.mq, &self.rhs))
    }

    /// The mass matrix Mq of the last evaluation.
    pub fn mass_matrix(&self) -> &Mat<f64> {
        &self.mq
    }

    /// Energies at (q, q̇, t).
    pub fn energies(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<Energies, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        let mech = self.mech.clone();
        let (x, xd, eps) = (self.kin.x(), self.kin.xd(), self.kin.eps());
        let mut en = Energies {
            gravity_exact: true,
            ..Default::default()
        };
        let mut xl = [0.0; 64];
        let mut vl = [0.0; 64];
        for e in &mech.elements {
            let n = e.x_index.len();
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = x[*gi];
                vl[k] = xd[*gi];
            }
            if e.element.has_inertia() {
                en.kinetic += e.element.kinetic_energy(&xl[..n], &vl[..n]);
                if let Some(g) = mech.gravity {
                    match e.element.gravity_potential(&xl[..n], &g) {
                        Some(v) => en.gravitational += v,
                        None => en.gravity_exact = false,
                    }
                }
            }
            let ne = e.element.n_eps();
            if ne > 0 {
                let o = e.eps_offset;
                let rigid = (0..ne).all(|k| mech.e_roles[o + k] == ERole::Rigid);
                if !rigid {
                    en.elastic += e.element.elastic_energy(&eps[o..o + ne]);
                }
            }
        }
        Ok(en)
    }

    /// Initial q̇ from the scene's initial nodal velocities (rigid-body fields),
    /// by least squares on F,q q̇ = ẋ0 − F,u u̇ at the configuration q0.
    pub fn initial_qd(&mut self, t: f64, q0: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let n_q = self.n_q();
        self.kinematics_at(t, q0, None)?;
        self.kin.velocities(&vec![0.0; n_q]);
        let f = self.kin.f_xi();
        let target: Vec<f64> = self
            .mech
            .initial_xd
            .iter()
            .zip(self.kin.xd())
            .map(|(a, b)| a - b)
            .collect();
        let a = Mat::from_fn(n_q, n_q, |r, c| {
            f.col_as_slice(r)
                .iter()
                .zip(f.col_as_slice(c))
                .map(|(x, y)| x * y)
                .sum::<f64>()
        });
        let mut b = Mat::from_fn(n_q, 1, |r, _| {
            f.col_as_slice(r)
                .iter()
                .zip(&target)
                .map(|(x, y)| x * y)
                .sum::<f64>()
        });
        if n_q > 0 {
            let llt = a
                .llt(faer::Side::Lower)
                .map_err(|_| DynamicsError::Invalid("F,q is rank deficient".into()))?;
            llt.solve_in_place(b.as_mut());
        }
        Ok((0..n_q).map(|i| b[(i, 0)]).collect())
    }

    /// Power of the external forces (loads, gravity, controllers) at (q, q̇, t):
    /// P = fᵀẋ − σ_cᵀε̇_c, whose time integral is the external work.
    pub fn external_power(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<f64, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        let mech = self.mech.clone();
        // forces without element stresses: recompute and subtract the elastic part
        self.forces(t, true);
        let xd = self.kin.xd();
        let epsd = self.kin.epsd();
        let eps = self.kin.eps();
        let mut p: f64 = self.f.iter().zip(xd).map(|(a, b)| a * b).sum();
        // controller stresses on deformations do work; elastic/damping stresses are internal
        for c in &mech.controllers {
            if let Coordinate::Def(j) = c.on {
                let (r, rd, _) = c.reference.eval(t);
                p += (c.kp * (r - eps[j]) + c.kd * (rd - epsd[j])) * epsd[j];
            }
        }
        // inputs do work too (prescribed motion): their reaction is not known
        // here; report only the applied forces
        Ok(p)
    }
}
