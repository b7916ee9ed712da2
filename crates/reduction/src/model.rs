//! The reduced equations of motion (thesis (6.15)) over any basis.

use crate::{Basis, ReductionError};
use faer::linalg::solvers::Solve;
use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_model::Mechanism;
use flexmb_ode::{OdeSystem, RhsError};
use std::sync::Arc;

/// A reduced model: the unreduced dynamics constrained by q = G(z).
pub struct ReducedModel {
    dy: Dynamics,
    basis: Box<dyn Basis>,
    q: Vec<f64>,
    qd: Vec<f64>,
    gz: Mat<f64>,
    conv: Vec<f64>,
}

impl ReducedModel {
    /// A reduced model of `mech` with the given basis.
    pub fn new(mech: Arc<Mechanism>, basis: Box<dyn Basis>) -> Self {
        let (nq, nz) = (basis.n_q(), basis.n_z());
        Self {
            dy: Dynamics::new(mech),
            q: vec![0.0; nq],
            qd: vec![0.0; nq],
            gz: Mat::zeros(nq, nz),
            conv: vec![0.0; nq],
            basis,
        }
    }
    /// Number of reduced coordinates.
    pub fn n_z(&self) -> usize {
        self.basis.n_z()
    }
    /// Scales the scene's loads (see `Dynamics::set_load_scale`).
    pub fn set_load_scale(&mut self, s: f64) {
        self.dy.set_load_scale(s);
    }
    /// The unreduced dynamics (configuration of the last evaluation).
    pub fn dynamics(&self) -> &Dynamics {
        &self.dy
    }
    /// q = G(z).
    pub fn full_coordinates(&mut self, z: &[f64]) -> Vec<f64> {
        let zd = vec![0.0; z.len()];
        self.basis
            .eval(z, &zd, &mut self.q, &mut self.gz, &mut self.conv);
        self.q.clone()
    }

    /// z̈ from (6.15): Mz z̈ = G,zᵀ(rhs_q − Mq (G,zz ż)ż), Mz = G,zᵀ Mq G,z.
    pub fn accelerations(
        &mut self,
        t: f64,
        z: &[f64],
        zd: &[f64],
        zdd: &mut [f64],
    ) -> Result<(), ReductionError> {
        let nz = self.basis.n_z();
        self.basis
            .eval(z, zd, &mut self.q, &mut self.gz, &mut self.conv);
        for (i, v) in self.qd.iter_mut().enumerate() {
            *v = (0..nz).map(|k| self.gz[(i, k)] * zd[k]).sum();
        }
        let (mq, rhs) = self.dy.mass_and_force(t, &self.q, &self.qd)?;
        let mut r: Vec<f64> = rhs.to_vec();
        if self.conv.iter().any(|c| *c != 0.0) {
            for (i, ri) in r.iter_mut().enumerate() {
                *ri -= (0..self.conv.len())
                    .map(|j| mq[(i, j)] * self.conv[j])
                    .sum::<f64>();
            }
        }
        let mg = mq * &self.gz;
        let mz = self.gz.transpose() * &mg;
        let mut fz = Mat::from_fn(nz, 1, |k, _| {
            (0..r.len()).map(|i| self.gz[(i, k)] * r[i]).sum::<f64>()
        });
        let llt = mz
            .llt(faer::Side::Lower)
            .map_err(|_| ReductionError::SingularMass)?;
        llt.solve_in_place(fz.as_mut());
        for (k, v) in zdd.iter_mut().enumerate() {
            *v = fz[(k, 0)];
        }
        Ok(())
    }
}

impl ReducedModel {
    /// The reduced rest linearization (thesis (F.7)) at z with ż = 0:
    /// Mz = G,zᵀ Mq G,z and Kz = G,zᵀ(K + G + N)G,z + G,zzᵀ(−F,qᵀf + E,qᵀσ).
    pub fn linearize_at_rest(
        &mut self,
        t: f64,
        z: &[f64],
    ) -> Result<(Mat<f64>, Mat<f64>), ReductionError> {
        let nz = self.basis.n_z();
        self.basis
            .eval(z, &vec![0.0; nz], &mut self.q, &mut self.gz, &mut self.conv);
        let q = self.q.clone();
        let lin = self.dy.linearize_at_rest(t, &q)?;
        let (r, _) = self.dy.static_tangent(t, &q)?;
        let mz = self.gz.transpose() * &lin.m * &self.gz;
        let mut kz = self.gz.transpose() * lin.stiffness_total() * &self.gz;
        kz += &self.basis.hessian_contraction(z, &r);
        Ok((mz, kz))
    }
}

impl OdeSystem for ReducedModel {
    fn dim(&self) -> usize {
        2 * self.basis.n_z()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.basis.n_z();
        let (z, zd) = y.split_at(n);
        let mut zdd = vec![0.0; n];
        self.accelerations(t, z, zd, &mut zdd)
            .map_err(|e| match e {
                ReductionError::Dynamics(flexmb_dynamics::DynamicsError::Kinematics { .. }) => {
                    RhsError::recoverable(e.to_string())
                }
                _ => RhsError::new(e.to_string()),
            })?;
        dy[..n].copy_from_slice(zd);
        dy[n..].copy_from_slice(&zdd);
        Ok(())
    }
}
