//! The reduced equations of motion (thesis (6.15)) over any basis.

use crate::{Basis, ReductionError};
use faer::linalg::solvers::Solve;
use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_model::{Coordinate, Mechanism};
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
    /// Work space of the equations of motion (no allocation per
    /// evaluation): Mz and its Cholesky factor in place with the factor's
    /// scratch memory, and the full-mass reference's G,zᵀ rhs and Mq G,z.
    mz: Mat<f64>,
    llt_mem: faer::dyn_stack::MemBuffer,
    r: Vec<f64>,
    mg: Mat<f64>,
    /// The chart checks of a running simulation.
    watch: ChartWatch,
}

impl ReducedModel {
    /// A reduced model of `mech` with the given basis.
    ///
    /// # Errors
    ///
    /// [`ReductionError::Invalid`] when the basis does not fit the mechanism:
    /// its n_q differs from the mechanism's number of DOFs, it has no reduced
    /// coordinate, or more reduced coordinates than full ones (then Mz (6.15)
    /// is singular).
    pub fn new(mech: Arc<Mechanism>, basis: Box<dyn Basis>) -> Result<Self, ReductionError> {
        let (nq, nz) = (basis.n_q(), basis.n_z());
        if nq != mech.n_dof() {
            return Err(ReductionError::Invalid(format!(
                "the basis maps to {nq} full coordinates but the mechanism has {} degrees of freedom",
                mech.n_dof()
            )));
        }
        if nz == 0 || nz > nq {
            return Err(ReductionError::Invalid(format!(
                "the basis has {nz} reduced coordinates; a reduced model needs between 1 and n_q = {nq}"
            )));
        }
        Ok(Self {
            dy: Dynamics::new(mech),
            q: vec![0.0; nq],
            qd: vec![0.0; nq],
            gz: Mat::zeros(nq, nz),
            conv: vec![0.0; nq],
            r: vec![0.0; nq],
            mg: Mat::zeros(nq, nz),
            mz: Mat::zeros(nz, nz),
            llt_mem: faer::dyn_stack::MemBuffer::new(
                faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
                    nz,
                    faer::Par::Seq,
                    Default::default(),
                )
                .or(
                    faer::linalg::cholesky::llt::solve::solve_in_place_scratch::<f64>(
                        nz,
                        1,
                        faer::Par::Seq,
                    ),
                ),
            ),
            watch: ChartWatch::default(),
            basis,
        })
    }
    /// Number of reduced coordinates.
    pub fn n_z(&self) -> usize {
        self.basis.n_z()
    }
    /// `Ok` if every named slice argument has n_z entries: the length rule of
    /// the public API (docs/ARCHITECTURE.md) for functions returning a
    /// `Result`.
    fn check_reduced(&self, args: &[(&str, usize)]) -> Result<(), ReductionError> {
        let nz = self.basis.n_z();
        match args.iter().find(|(_, len)| *len != nz) {
            None => Ok(()),
            Some((what, len)) => Err(ReductionError::Invalid(format!(
                "{what} has {len} entries, but the reduced model has {nz} coordinates"
            ))),
        }
    }
    /// Panics with a message naming `function` unless every slice has n_z
    /// entries: the length rule for functions without a `Result`.
    fn assert_reduced(&self, function: &str, args: &[(&str, usize)]) {
        if let Err(e) = self.check_reduced(args) {
            panic!("ReducedModel::{function}: {e}");
        }
    }
    /// Scales the scene's loads (see `Dynamics::set_load_scale`).
    pub fn set_load_scale(&mut self, s: f64) {
        self.dy.set_load_scale(s);
    }
    /// The unreduced dynamics (configuration of the last evaluation).
    pub fn dynamics(&self) -> &Dynamics {
        &self.dy
    }
    /// The unreduced dynamics, mutable (e.g. to tighten the position solve).
    pub fn dynamics_mut(&mut self) -> &mut Dynamics {
        &mut self.dy
    }
    /// q = G(z).
    ///
    /// # Panics
    ///
    /// If `z` does not have [`n_z`](Self::n_z) entries.
    pub fn full_coordinates(&mut self, z: &[f64]) -> Vec<f64> {
        self.assert_reduced("full_coordinates", &[("z", z.len())]);
        let zd = vec![0.0; z.len()];
        self.basis
            .eval(z, &zd, &mut self.q, &mut self.gz, &mut self.conv);
        self.q.clone()
    }

    /// q = G(z) and q̇ = G,z ż: the unreduced state of a reduced state, e.g.
    /// to record the scene's outputs along a reduced trajectory.
    ///
    /// # Panics
    ///
    /// If `z` or `zd` does not have [`n_z`](Self::n_z) entries.
    pub fn full_state(&mut self, z: &[f64], zd: &[f64]) -> (Vec<f64>, Vec<f64>) {
        self.assert_reduced("full_state", &[("z", z.len()), ("ż", zd.len())]);
        self.basis
            .eval(z, zd, &mut self.q, &mut self.gz, &mut self.conv);
        let qd = (0..self.q.len())
            .map(|i| (0..zd.len()).map(|k| self.gz[(i, k)] * zd[k]).sum())
            .collect();
        (self.q.clone(), qd)
    }

    /// The reduced velocities ż whose q̇ = G,z ż is closest to `qd` in the
    /// kinetic-energy norm at q = G(z): ż = Mz⁻¹ G,zᵀ Mq q̇ with
    /// Mz = G,zᵀ Mq G,z (exact when `qd` lies in the range of G,z, zero for
    /// `qd` = 0). Starts a reduced model from the scene's initial velocities.
    pub fn project_velocities(
        &mut self,
        t: f64,
        z: &[f64],
        qd: &[f64],
    ) -> Result<Vec<f64>, ReductionError> {
        let nz = self.basis.n_z();
        if z.len() != nz || qd.len() != self.basis.n_q() {
            return Err(ReductionError::Invalid(format!(
                "velocity projection: {} reduced and {} full coordinates for a {nz} × {} basis",
                z.len(),
                qd.len(),
                self.basis.n_q()
            )));
        }
        if qd.iter().all(|v| *v == 0.0) {
            return Ok(vec![0.0; nz]);
        }
        self.basis
            .eval(z, &vec![0.0; nz], &mut self.q, &mut self.gz, &mut self.conv);
        let zero = vec![0.0; qd.len()];
        let (mq, _) = self.dy.mass_and_force(t, &self.q, &zero)?;
        let mq = mq.to_owned();
        let mg = &mq * &self.gz;
        let mz = self.gz.transpose() * &mg;
        let mut b = Mat::from_fn(nz, 1, |k, _| {
            (0..qd.len()).map(|i| mg[(i, k)] * qd[i]).sum::<f64>()
        });
        mz.llt(faer::Side::Lower)
            .map_err(|_| ReductionError::SingularMass)?
            .solve_in_place(b.as_mut());
        Ok((0..nz).map(|k| b[(k, 0)]).collect())
    }

    /// z̈ from the reduced equations of motion (6.15):
    /// Mz z̈ = G,zᵀ(F,qᵀ(f − Mx ẍ0 − h) − E,qᵀσ − Mq (G,zz ż)ż),
    /// Mz = G,zᵀ Mq G,z, at q = G(z), q̇ = G,z ż.
    ///
    /// Evaluated with the reduced transfer matrix F,z = F,q G,z (n_z solves
    /// with the kinematic Jacobian) as Mz = F,zᵀ Mx F,z by element blocks
    /// and the right-hand side F,zᵀ(f − Mx ẍ_c − h) − E,zᵀσ with
    /// ẍ_c = ẍ0 + F,q (G,zz ż)ż from one more solve
    /// ([`Dynamics::projected_mass_and_force`]): no n_q × n_q matrix, and
    /// no allocation per evaluation. The cost grows with n_z (besides the
    /// element loops and the position solve over the whole mechanism), not
    /// with n_q. [`accelerations_from_full_mass`](Self::accelerations_from_full_mass)
    /// gives the same z̈ from the unreduced Mq.
    pub fn accelerations(
        &mut self,
        t: f64,
        z: &[f64],
        zd: &[f64],
        zdd: &mut [f64],
    ) -> Result<(), ReductionError> {
        self.full_motion_at(z, zd, zdd)?;
        let (mz, rhs) =
            self.dy
                .projected_mass_and_force(t, &self.q, self.gz.as_ref(), zd, &self.conv)?;
        self.mz.copy_from(mz);
        zdd.copy_from_slice(rhs);
        self.solve_reduced_mass(zdd)
    }

    /// z̈ of (6.15) as the unreduced model's pieces give it: Mq and the
    /// generalized force of (D.10) at q = G(z), q̇ = G,z ż
    /// ([`Dynamics::mass_and_force`], n_q + n_u solves for F,ξ and
    /// O(n_x n_q²) for Mq), projected: Mz = G,zᵀ Mq G,z and
    /// G,zᵀ(rhs_q − Mq (G,zz ż)ż). The reference that
    /// [`accelerations`](Self::accelerations) is tested against; it does not
    /// count an evaluation of the reduced model but one of the unreduced.
    pub fn accelerations_from_full_mass(
        &mut self,
        t: f64,
        z: &[f64],
        zd: &[f64],
        zdd: &mut [f64],
    ) -> Result<(), ReductionError> {
        self.full_motion_at(z, zd, zdd)?;
        let (mq, rhs) = self.dy.mass_and_force(t, &self.q, &self.qd)?;
        let (r, gz, conv) = (&mut self.r, &self.gz, &self.conv);
        r.copy_from_slice(rhs);
        if conv.iter().any(|c| *c != 0.0) {
            for (i, ri) in r.iter_mut().enumerate() {
                *ri -= (0..conv.len()).map(|j| mq[(i, j)] * conv[j]).sum::<f64>();
            }
        }
        use faer::linalg::matmul::matmul;
        matmul(
            self.mg.as_mut(),
            faer::Accum::Replace,
            mq,
            gz,
            1.0,
            faer::Par::Seq,
        );
        matmul(
            self.mz.as_mut(),
            faer::Accum::Replace,
            gz.transpose(),
            &self.mg,
            1.0,
            faer::Par::Seq,
        );
        for (k, v) in zdd.iter_mut().enumerate() {
            *v = gz
                .col_as_slice(k)
                .iter()
                .zip(r.iter())
                .map(|(g, v)| g * v)
                .sum();
        }
        self.solve_reduced_mass(zdd)
    }

    /// Checks the lengths of z, ż and z̈ and evaluates the basis there:
    /// q = G(z), G,z, (G,zz ż)ż and q̇ = G,z ż in the model's buffers.
    fn full_motion_at(&mut self, z: &[f64], zd: &[f64], zdd: &[f64]) -> Result<(), ReductionError> {
        self.check_reduced(&[("z", z.len()), ("ż", zd.len()), ("z̈", zdd.len())])?;
        self.basis
            .eval(z, zd, &mut self.q, &mut self.gz, &mut self.conv);
        for (i, v) in self.qd.iter_mut().enumerate() {
            *v = (0..zd.len()).map(|k| self.gz[(i, k)] * zd[k]).sum();
        }
        Ok(())
    }

    /// Solves Mz z̈ = b in place (b given in `zdd`) with the Cholesky factor
    /// of the lower triangle of `self.mz`, factorized in place in
    /// preallocated memory.
    fn solve_reduced_mass(&mut self, zdd: &mut [f64]) -> Result<(), ReductionError> {
        use faer::dyn_stack::MemStack;
        use faer::linalg::cholesky::llt;
        let n = zdd.len();
        llt::factor::cholesky_in_place(
            self.mz.as_mut(),
            Default::default(),
            faer::Par::Seq,
            MemStack::new(&mut self.llt_mem),
            Default::default(),
        )
        .map_err(|_| ReductionError::SingularMass)?;
        llt::solve::solve_in_place(
            self.mz.as_ref(),
            faer::MatMut::from_column_major_slice_mut(zdd, n, 1),
            faer::Par::Seq,
            MemStack::new(&mut self.llt_mem),
        );
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
        self.check_reduced(&[("z", z.len())])?;
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

impl ReducedModel {
    /// The basis.
    pub fn basis(&self) -> &dyn Basis {
        self.basis.as_ref()
    }

    /// The reduced static out-of-balance R = G,zᵀ g_s(G(z)) and its tangent
    /// R,z = G,zᵀ(Kq + Gq − F,qᵀ f,x F,q)G,z + G,zzᵀ g_s (the static part of
    /// (F.7)), with g_s = E,qᵀσ − F,qᵀf the unreduced out-of-balance.
    pub fn static_tangent(
        &mut self,
        t: f64,
        z: &[f64],
    ) -> Result<(Vec<f64>, Mat<f64>), ReductionError> {
        self.check_reduced(&[("z", z.len())])?;
        let nz = self.basis.n_z();
        self.basis
            .eval(z, &vec![0.0; nz], &mut self.q, &mut self.gz, &mut self.conv);
        let (g, tq) = self.dy.static_tangent(t, &self.q)?;
        let r: Vec<f64> = (0..nz)
            .map(|k| (0..g.len()).map(|i| self.gz[(i, k)] * g[i]).sum())
            .collect();
        let mut kz = self.gz.transpose() * &tq * &self.gz;
        kz += &self.basis.hessian_contraction(z, &g);
        Ok((r, kz))
    }

    /// Static equilibrium of the reduced model at time `t` by Newton from
    /// `z0`, with the reduced coordinates listed in `held` kept at their
    /// values in `z0`. Converged when ‖Δz‖∞ ≤ 1e-10 (1 + ‖z‖∞); fails after 30
    /// iterations with the remaining out-of-balance. Continuation in a load
    /// parameter is the caller's ([`set_load_scale`](Self::set_load_scale)
    /// in small steps, each starting from the previous equilibrium). The
    /// model-independent form, with the signature of the unreduced solver,
    /// is [`MechanicalModel::static_equilibrium`](crate::MechanicalModel::static_equilibrium).
    pub fn newton_equilibrium(
        &mut self,
        t: f64,
        z0: &[f64],
        held: &[usize],
    ) -> Result<Vec<f64>, ReductionError> {
        let nz = self.basis.n_z();
        if z0.len() != nz || held.iter().any(|h| *h >= nz) {
            return Err(ReductionError::Invalid(format!(
                "reduced equilibrium: {} start values and held indices {held:?} for {nz} reduced coordinates",
                z0.len()
            )));
        }
        let free: Vec<usize> = (0..nz).filter(|k| !held.contains(k)).collect();
        let norm = |r: &[f64]| free.iter().fold(0.0f64, |m, k| m.max(r[*k].abs()));
        let mut z = z0.to_vec();
        let (mut r, mut kz) = self.static_tangent(t, &z)?;
        let mut last = f64::INFINITY;
        for _ in 0..30 {
            let kf = Mat::from_fn(free.len(), free.len(), |a, b| kz[(free[a], free[b])]);
            let mut dz = Mat::from_fn(free.len(), 1, |a, _| -r[free[a]]);
            kf.partial_piv_lu().solve_in_place(dz.as_mut());
            if (0..free.len()).any(|a| !dz[(a, 0)].is_finite()) {
                return Err(ReductionError::Invalid(
                    "reduced equilibrium: singular reduced stiffness (the basis cannot carry the loads, or the configuration is unstable)".into(),
                ));
            }
            // damped step: halve while the configuration cannot be assembled
            // or the out-of-balance grows a lot
            let mut alpha = 1.0;
            let mut err = None;
            let (z_new, r_new, k_new) = loop {
                let mut zt = z.clone();
                for (a, &k) in free.iter().enumerate() {
                    zt[k] += alpha * dz[(a, 0)];
                }
                match self.static_tangent(t, &zt) {
                    Ok((rt, kt)) if norm(&rt) <= 10.0 * norm(&r) + 1e-300 => break (zt, rt, kt),
                    Ok(_) => {}
                    Err(e) => err = Some(e),
                }
                alpha *= 0.5;
                if alpha < 1.0 / 64.0 {
                    return Err(err.unwrap_or_else(|| {
                        ReductionError::Invalid(
                            "reduced equilibrium: Newton diverges (out-of-balance grows along the step)".into(),
                        )
                    }));
                }
            };
            let step = alpha * (0..free.len()).fold(0.0f64, |m, a| m.max(dz[(a, 0)].abs()));
            (z, r, kz) = (z_new, r_new, k_new);
            let scale = 1.0 + z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            last = step / scale;
            if last <= 1e-10 {
                return Ok(z);
            }
        }
        Err(ReductionError::Invalid(format!(
            "reduced equilibrium did not converge in 30 Newton iterations (last relative step {last:.2e})"
        )))
    }

    /// Undamped eigenfrequencies (Hz) of the reduced model at rest at z: the
    /// rest linearization (F.7), all n_z of them, ascending.
    pub fn frequencies_at_rest(&mut self, t: f64, z: &[f64]) -> Result<Vec<f64>, ReductionError> {
        let (mz, kz) = self.linearize_at_rest(t, z)?;
        Ok(flexmb_linearize::generalized_symmetric(&kz, &mz, mz.nrows())?.frequencies_hz())
    }
}

/// The reduced linearized equations of motion (thesis (F.4)–(F.5)):
/// Mz δz̈ + (Dz + Cz) δż + (Kz + Gz + Nz) δz = 0.
#[derive(Clone, Debug)]
pub struct ReducedLinearization {
    /// Mz (F.5a).
    pub m: Mat<f64>,
    /// Dz + Cz (F.5b)–(F.5c): damping and velocity sensitivity.
    pub damping: Mat<f64>,
    /// Kz + Gz + Nz (F.5d)–(F.5f).
    pub stiffness: Mat<f64>,
}

impl ReducedModel {
    /// The reduced residual g_z = G,zᵀ g(G(z), G,z ż, G,z z̈ + (G,zz ż)ż) (F.1).
    pub fn residual(
        &mut self,
        t: f64,
        z: &[f64],
        zd: &[f64],
        zdd: &[f64],
    ) -> Result<Vec<f64>, ReductionError> {
        self.check_reduced(&[("z", z.len()), ("ż", zd.len()), ("z̈", zdd.len())])?;
        let (q, qd, qdd) = self.full_motion(z, zd, zdd);
        let mut g = vec![0.0; q.len()];
        self.dy.residual(t, &q, &qd, &qdd, &mut g)?;
        Ok(self.project(&g))
    }

    /// q, q̇ and q̈ = G,z z̈ + (G,zz ż)ż of a reduced state ((6.13)).
    fn full_motion(
        &mut self,
        z: &[f64],
        zd: &[f64],
        zdd: &[f64],
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (q, qd) = self.full_state(z, zd);
        let qdd: Vec<f64> = (0..q.len())
            .map(|i| {
                self.conv[i]
                    + (0..zdd.len())
                        .map(|k| self.gz[(i, k)] * zdd[k])
                        .sum::<f64>()
            })
            .collect();
        (q, qd, qdd)
    }

    /// G,zᵀ v.
    fn project(&self, v: &[f64]) -> Vec<f64> {
        (0..self.gz.ncols())
            .map(|k| (0..v.len()).map(|i| self.gz[(i, k)] * v[i]).sum())
            .collect()
    }

    /// The reduced linearization (F.5) about any state (z, ż, z̈) at time t,
    /// by the chain rule through q = G(z) from the unreduced linearization
    /// (E.5) at (G(z), G,z ż, G,z z̈ + (G,zz ż)ż):
    ///
    /// * Mz = G,zᵀ Mq G,z,
    /// * Dz + Cz = G,zᵀ((Dq + Cq) G,z + 2 Mq G,zz ż),
    /// * Kz + Gz + Nz = G,zzᵀ g + G,zᵀ((Kq + Gq + Nq) G,z + (Dq + Cq) G,zz ż
    ///   + Mq (G,zz z̈ + (G,zzz ż)ż)),
    ///
    /// with g the unreduced residual (E.1). At rest in equilibrium this is (F.7).
    pub fn linearize(
        &mut self,
        t: f64,
        z: &[f64],
        zd: &[f64],
        zdd: &[f64],
    ) -> Result<ReducedLinearization, ReductionError> {
        self.check_reduced(&[("z", z.len()), ("ż", zd.len()), ("z̈", zdd.len())])?;
        let (q, qd, qdd) = self.full_motion(z, zd, zdd);
        let mut g = vec![0.0; q.len()];
        self.dy.residual(t, &q, &qd, &qdd, &mut g)?;
        let lin = self.dy.linearize(t, &q, &qd, &qdd)?;
        let gz = self.gz.clone();
        let h_zd = self.basis.second_derivative_matrix(z, zd);
        let h_zdd = self.basis.second_derivative_matrix(z, zdd);
        let h3 = self.basis.third_derivative_matrix(z, zd);
        let dc = &lin.d + &lin.c;
        let m = gz.transpose() * &lin.m * &gz;
        let damping = gz.transpose() * (&dc * &gz + (&lin.m * &h_zd) * 2.0);
        let mut stiffness =
            gz.transpose() * (lin.stiffness_total() * &gz + &dc * &h_zd + &lin.m * (&h_zdd + &h3));
        stiffness += &self.basis.hessian_contraction(z, &g);
        Ok(ReducedLinearization {
            m,
            damping,
            stiffness,
        })
    }
}

/// A computed trajectory of a reduced model.
#[derive(Clone, Debug)]
pub struct ReducedTrajectory {
    /// Output times.
    pub t: Vec<f64>,
    /// z at each output time.
    pub z: Vec<Vec<f64>>,
    /// ż at each output time.
    pub zd: Vec<Vec<f64>>,
    /// The unreduced nodal coordinates x = F(G(z)) at each output time,
    /// solved when the integrator reached the output from the configuration
    /// of its last evaluation ([`Dynamics::output_configuration`]).
    pub x: Vec<Vec<f64>>,
    /// Integrator statistics (exact evaluation counts).
    pub stats: flexmb_ode::Stats,
    /// Wall time of the integration in seconds.
    pub wall_time: f64,
    /// True if stopped early by the observer.
    pub stopped: bool,
    /// The Euler-parameter charts that switched
    /// ([`simulate`](ReducedModel::simulate)).
    pub chart_switches: Vec<flexmb_model::ChartSwitch>,
}

impl ReducedModel {
    /// Integrates the reduced equations of motion (6.15) from (t0, z0, ż0)
    /// with an explicit integrator (the thesis's choice for reduced models);
    /// `observer(t, z, ż)` may stop the run. The trajectory holds each
    /// output's configuration, solved along the run.
    ///
    /// Euler-parameter charts ([`flexmb_model::EulerChart`]) switch as in
    /// the unreduced [`Dynamics::simulate_with`] where the basis keeps the
    /// node's DOF parameters as reduced coordinates
    /// ([`Basis::kept_coordinate`], e.g. the large coordinates of a modal
    /// basis): the integrator stops after the step where the dependent
    /// parameter got small, the reduced coordinate of the slot that changes
    /// takes the value and rate of the parameter it now stands for, nothing
    /// else moves, and the integration restarts (the counts include the
    /// restarts). Where the basis mixes a node's Euler parameters into its
    /// vectors, the reduced coordinates describe the node's orientation only
    /// in the chart the basis was built in: the basis's configurations in
    /// x fold back where that chart is singular (λ_dep = 0), no change of
    /// z continues them, and a motion that turns the node there stops with
    /// the node named. z and ż are given in the chart the run started with,
    /// and the model is in that chart again when this returns.
    pub fn simulate(
        &mut self,
        t0: f64,
        z0: &[f64],
        zd0: &[f64],
        opts: &flexmb_dynamics::SimulationOptions,
        mut observer: impl FnMut(f64, &[f64], &[f64]) -> flexmb_dynamics::Control,
    ) -> Result<ReducedTrajectory, ReductionError> {
        let n = self.n_z();
        if z0.len() != n || zd0.len() != n {
            return Err(ReductionError::Invalid(format!(
                "initial state of length {}/{} for {n} reduced coordinates",
                z0.len(),
                zd0.len()
            )));
        }
        let t_end = *opts
            .output_times
            .last()
            .ok_or_else(|| ReductionError::Invalid("no output times".into()))?;
        let start_mech = self.dy.mechanism().clone();
        let start = std::time::Instant::now();
        let result = self.simulate_charted(t0, z0, zd0, t_end, opts, &start_mech, &mut observer);
        self.dy.use_chart(&start_mech);
        self.watch = ChartWatch::default();
        let mut tr = result?;
        tr.wall_time = start.elapsed().as_secs_f64();
        Ok(tr)
    }

    /// [`simulate`](Self::simulate) in segments between chart switches.
    #[allow(clippy::too_many_arguments)]
    fn simulate_charted(
        &mut self,
        t0: f64,
        z0: &[f64],
        zd0: &[f64],
        t_end: f64,
        opts: &flexmb_dynamics::SimulationOptions,
        start_mech: &Arc<Mechanism>,
        observer: &mut impl FnMut(f64, &[f64], &[f64]) -> flexmb_dynamics::Control,
    ) -> Result<ReducedTrajectory, ReductionError> {
        let n = self.n_z();
        let mut tr = ReducedTrajectory {
            t: vec![],
            z: vec![],
            zd: vec![],
            x: vec![],
            stats: Default::default(),
            wall_time: 0.0,
            stopped: false,
            chart_switches: vec![],
        };
        let (mut t_now, mut z, mut zd) = (t0, z0.to_vec(), zd0.to_vec());
        let mut times = opts.output_times.clone();
        loop {
            self.switch_charts(t_now, &mut z, &mut zd, &mut tr.chart_switches)?;
            self.watch = ChartWatch::new(self);
            let seg_opts = flexmb_dynamics::SimulationOptions {
                output_times: times.clone(),
                ..opts.clone()
            };
            let mut y0 = z.clone();
            y0.extend_from_slice(&zd);
            let mut failure = None;
            let mut observer_stopped = false;
            let run = flexmb_dynamics::integrate_explicit(
                self,
                &seg_opts,
                t_now,
                &y0,
                |m: &mut Self, tt: f64, y: &[f64]| {
                    let (q, qd) = m.full_state(&y[..n], &y[n..]);
                    let x = match m.dy.output_configuration(tt, &q) {
                        Ok(x) => x,
                        Err(e) => {
                            failure = Some(e);
                            return flexmb_dynamics::Control::Stop;
                        }
                    };
                    let (mut zs, mut zds) = (y[..n].to_vec(), y[n..].to_vec());
                    let now = m.dy.mechanism();
                    kept_in_chart(&*m.basis, start_mech, now, &x, &qd, &mut zs, &mut zds);
                    tr.t.push(tt);
                    tr.x.push(x);
                    let c = observer(tt, &zs, &zds);
                    tr.z.push(zs);
                    tr.zd.push(zds);
                    observer_stopped |= c == flexmb_dynamics::Control::Stop;
                    c
                },
            );
            let (stats, stopped) = run.map_err(|e| {
                flexmb_dynamics::with_failure_cause(e, self.watch.last_failure.as_ref())
            })?;
            if let Some(e) = failure {
                return Err(e.into());
            }
            // the counts of every segment between chart switches
            tr.stats.accumulate(&stats);
            let switch_at = self.watch.switch_at.take();
            tr.stopped = stopped && (observer_stopped || switch_at.is_none());
            let Some((ts, zs, zds)) = switch_at else {
                break;
            };
            if tr.stopped || ts >= t_end {
                break;
            }
            (t_now, z, zd) = (ts, zs, zds);
            times.retain(|&tau| tau > ts);
            if times.is_empty() {
                break;
            }
        }
        Ok(tr)
    }

    /// The full slots whose Euler-parameter chart this model cannot switch:
    /// those the basis does not keep as a reduced coordinate.
    fn unswitchable_slots(&self) -> Vec<usize> {
        (0..self.basis.n_q())
            .filter(|k| self.basis.kept_coordinate(*k).is_none())
            .collect()
    }

    /// Switches the charts that need it at (t, z, ż) and whose slots the
    /// basis keeps ([`Dynamics::switch_charts`]); z and ż then describe
    /// the same state in the new chart.
    fn switch_charts(
        &mut self,
        t: f64,
        z: &mut [f64],
        zd: &mut [f64],
        log: &mut Vec<flexmb_model::ChartSwitch>,
    ) -> Result<(), ReductionError> {
        if self.dy.mechanism().euler_charts().is_empty() {
            return Ok(());
        }
        let keep = self.unswitchable_slots();
        let (q, qd) = self.full_state(z, zd);
        let before = self.dy.mechanism().clone();
        if self.dy.switch_charts(t, &q, &qd, &keep, log)?.is_some() {
            let (x, now) = (self.dy.kinematics().x(), self.dy.mechanism());
            kept_in_chart(&*self.basis, now, &before, x, &qd, z, zd);
        }
        Ok(())
    }
}

/// z, ż of a state in the chart of `from` (its DOF rates q̇ at the
/// configuration x) changed into the chart of `to` (the same scene in
/// another chart): the reduced coordinates that `basis` keeps for the
/// slots whose coordinate differs take the value and rate of the coordinate
/// `to` has there; nothing else changes.
fn kept_in_chart(
    basis: &dyn Basis,
    to: &Mechanism,
    from: &Mechanism,
    x: &[f64],
    qd: &[f64],
    z: &mut [f64],
    zd: &mut [f64],
) {
    for (k, (c, c_from)) in to.dofs.iter().zip(&from.dofs).enumerate() {
        let (Coordinate::Node(i), true) = (*c, c != c_from) else {
            continue;
        };
        if let Some((j, offset)) = basis.kept_coordinate(k) {
            z[j] = x[i] - offset;
            zd[j] = euler_rate(from, i, x, qd);
        }
    }
}

/// The rate of the Euler parameter with nodal-coordinate index `i` in the
/// chart of `mech` at x with DOF rates q̇: q̇ of its slot if it is a DOF
/// there, else (the chart's dependent one) from the normalization
/// Σ λ_m λ̇_m = 0 (thesis (2.9)).
fn euler_rate(mech: &Mechanism, i: usize, x: &[f64], qd: &[f64]) -> f64 {
    if let Some(k) = mech.dofs.iter().position(|c| *c == Coordinate::Node(i)) {
        return qd[k];
    }
    mech.euler_charts()
        .iter()
        .find(|c| c.dependent == i)
        .map(|c| -c.dofs.iter().map(|(k, m)| x[*m] * qd[*k]).sum::<f64>() / x[i])
        .unwrap_or(0.0)
}

/// What the integration of a reduced model watches between steps: the
/// charts it can switch, where one must, and the last evaluation that
/// failed recoverably (the cause to name if the run fails after it).
#[derive(Default)]
struct ChartWatch {
    /// The charts whose switching slots the basis keeps.
    charts: Vec<flexmb_model::EulerChart>,
    /// (t, z, ż) where a chart must switch.
    switch_at: Option<(f64, Vec<f64>, Vec<f64>)>,
    last_failure: Option<(f64, String)>,
}

impl ChartWatch {
    fn new(m: &ReducedModel) -> Self {
        let kept = |k: usize| m.basis.kept_coordinate(k).is_some();
        Self {
            charts: m
                .dy
                .mechanism()
                .euler_charts()
                .into_iter()
                .filter(|c| c.dofs.iter().any(|(k, _)| kept(*k)))
                .collect(),
            switch_at: None,
            last_failure: None,
        }
    }
}

impl OdeSystem for ReducedModel {
    fn dim(&self) -> usize {
        2 * self.basis.n_z()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.basis.n_z();
        let (z, zd) = y.split_at(n);
        if let Err(e) = self.accelerations(t, z, zd, &mut dy[n..]) {
            return Err(match e {
                ReductionError::Dynamics(flexmb_dynamics::DynamicsError::Kinematics { .. }) => {
                    let m = e.to_string();
                    self.watch.last_failure = Some((t, m.clone()));
                    RhsError::recoverable(m)
                }
                _ => RhsError::new(e.to_string()),
            });
        }
        dy[..n].copy_from_slice(zd);
        Ok(())
    }
    /// Stops the integration after a step where a chart this model can
    /// switch needs it ([`ReducedModel::simulate`] switches and restarts).
    fn step_accepted(&mut self, t: f64, y: &[f64]) -> flexmb_dynamics::Control {
        if self.watch.charts.is_empty() {
            return flexmb_dynamics::Control::Continue;
        }
        let n = self.basis.n_z();
        let (z, zd) = y.split_at(n);
        self.basis
            .eval(z, zd, &mut self.q, &mut self.gz, &mut self.conv);
        let q = &self.q;
        let basis = &self.basis;
        let needed = self.watch.charts.iter().any(|c| {
            c.needs_switch(q)
                .is_some_and(|(slot, _)| basis.kept_coordinate(slot).is_some())
        });
        if needed {
            self.watch.switch_at = Some((t, z.to_vec(), zd.to_vec()));
            return flexmb_dynamics::Control::Stop;
        }
        flexmb_dynamics::Control::Continue
    }
}
