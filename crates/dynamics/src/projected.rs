//! The equations of motion projected on n_z directions of the degrees of
//! freedom, the pieces of a reduced model q = G(z) (thesis (6.15)) at a cost
//! that grows with n_z, not with n_q.
//!
//! With V = G,z (n_q × n_z) and c = (G,zz ż)ż, (6.15) reads
//! Mz z̈ = Vᵀ(F,qᵀ(f − Mx ẍ0 − h) − E,qᵀσ − Mq c), Mz = Vᵀ Mq V. With the
//! reduced transfer matrix F,z = F,q V (n_x × n_z) and ẍ_c = ẍ0 + F,q c (the
//! nodal accelerations for z̈ = 0), and E,qᵀσ = F,qᵀ D,xᵀσ on the
//! deformations that are no constraint rows (D,x F,q = E,q there) plus the
//! unit rows of the deformation DOFs, this is
//!
//! ```text
//! Mz = F,zᵀ Mx F,z,
//! rhs = F,zᵀ (f − Mx ẍ_c − h − D,xᵀσ_free) − Σ_dof-deformations σ_j V(k_j, :)
//! ```
//!
//! F,z takes n_z solves with the kinematic Jacobian J
//! ([`Kinematics::transfer_times`]), ẍ_c one more
//! ([`Kinematics::accelerations_refined`]); the velocities are ẋ = F,z ż
//! (plus one solve for the prescribed inputs' rates if one moves,
//! [`Kinematics::velocities_from`]); Mz is assembled by element blocks
//! F_eᵀ M_e F_e, and the right-hand side is n_z dot products of length n_x.
//! No n_q × n_q matrix and no F,q (n_q solves) are formed, and the solves
//! refine against the exact J with the factorization of a nearby
//! configuration as the unreduced [`Dynamics::accelerations`] does, so J is
//! factorized only now and then. The work is O(n_x n_z) plus the element
//! loops and the position solve, which every evaluation of the non-linear
//! kinematics needs; [`Dynamics::mass_and_force`] (Mq, O(n_x n_q²) after
//! n_q + n_u solves for F,ξ) is the reference it is tested against.

use crate::eom::{inertia_pass, Assembly};
use crate::{Dynamics, DynamicsError};
use faer::{Mat, MatRef};
use flexmb_model::{Coordinate, ERole, Mechanism};

/// Work memory of the projected equations for one number of directions,
/// made on the first evaluation with it.
pub(crate) struct Projection {
    /// F,z = F,q V (n_x × n_z).
    fz: Mat<f64>,
    /// Mz = F,zᵀ Mx F,z.
    mz: Mat<f64>,
    /// Vᵀ (generalized force − Mq c).
    rhs: Vec<f64>,
    /// q̇ = V ż.
    qd: Vec<f64>,
    /// ẍ_c = ẍ0 + F,q c (then ẍ_c − ẋ_g).
    xdd: Vec<f64>,
    /// ẋ_q = F,z ż, then the nodal forces f − Mx ẍ_c − h − D,xᵀσ_free.
    y: Vec<f64>,
    /// −σ on the deformations that are no constraint rows, zero on the rows.
    neg_sigma: Vec<f64>,
    /// (index in q, deformation) of the deformation DOFs.
    dof_deformations: Vec<(usize, usize)>,
    /// (nodal coordinate, axis) of every position coordinate: gravity
    /// enters as the acceleration field −g (as in the nodal solve).
    positions: Vec<(usize, usize)>,
    asm: Assembly,
}

impl Projection {
    fn new(mech: &Mechanism, n_z: usize) -> Self {
        let n_x = mech.n_x();
        Self {
            fz: Mat::zeros(n_x, n_z),
            mz: Mat::zeros(n_z, n_z),
            rhs: vec![0.0; n_z],
            qd: vec![0.0; mech.n_dof()],
            xdd: vec![0.0; n_x],
            y: vec![0.0; n_x],
            neg_sigma: vec![0.0; mech.n_eps()],
            dof_deformations: mech
                .dofs
                .iter()
                .enumerate()
                .filter_map(|(k, c)| match c {
                    Coordinate::Def(j) => Some((k, *j)),
                    Coordinate::Node(_) => None,
                })
                .collect(),
            positions: mech
                .nodes
                .iter()
                .flat_map(|n| n.position.iter().enumerate().map(|(axis, i)| (*i, axis)))
                .collect(),
            asm: Assembly::new(mech, n_z),
        }
    }
}

impl Dynamics {
    /// The reduced mass matrix and generalized force of the equations of
    /// motion projected on the directions V (n_q × n_z, the columns of
    /// G,z of a reduced model q = G(z)) at (t, q, q̇ = V ż), with the extra
    /// nodal acceleration of q̈ = c (the basis's (G,zz ż)ż): thesis (6.15),
    ///
    /// Mz = Vᵀ Mq V,  rhs = Vᵀ(F,qᵀ(f − Mx(ẍ0 + F,q c) − h) − E,qᵀσ),
    ///
    /// evaluated without Mq or F,q (see the module `projected`): n_z + 1
    /// solves with the kinematic Jacobian (one more when a prescribed input
    /// moves) and element blocks, O(n_x n_z) besides the element loops.
    /// Mz z̈ = rhs gives the reduced accelerations. Counts one evaluation.
    /// No allocation after the first call with a given n_z.
    ///
    /// # Errors
    ///
    /// [`DynamicsError::Invalid`] for slices of the wrong length (q and c
    /// need n_q entries, V n_q rows, ż one per column of V);
    /// [`DynamicsError::NonFinite`] for a
    /// non-finite ż; [`DynamicsError::Kinematics`] when the position solve
    /// or a solve with J fails.
    pub fn projected_mass_and_force(
        &mut self,
        t: f64,
        q: &[f64],
        v: MatRef<'_, f64>,
        zd: &[f64],
        c: &[f64],
    ) -> Result<(&Mat<f64>, &[f64]), DynamicsError> {
        self.evaluations += 1;
        self.check_length("c", c.len())?;
        self.check_length("the rows of V", v.nrows())?;
        let n_z = v.ncols();
        if zd.len() != n_z {
            return Err(DynamicsError::Invalid(format!(
                "ż has {} entries for {n_z} directions",
                zd.len()
            )));
        }
        let mut p = match self.projection.take() {
            Some(p) if p.fz.ncols() == n_z && p.fz.nrows() == self.mech.n_x() => p,
            _ => Projection::new(&self.mech, n_z),
        };
        let r = self.project(t, q, v, zd, c, &mut p);
        self.projection = Some(p);
        r?;
        let p = self.projection.as_ref().expect("just stored");
        Ok((&p.mz, &p.rhs))
    }

    /// [`projected_mass_and_force`](Self::projected_mass_and_force) into `p`.
    fn project(
        &mut self,
        t: f64,
        q: &[f64],
        v: MatRef<'_, f64>,
        zd: &[f64],
        c: &[f64],
        p: &mut Projection,
    ) -> Result<(), DynamicsError> {
        let kin_err = |e| DynamicsError::Kinematics { t, source: e };
        self.kin.solve_chord(q, t).map_err(kin_err)?;
        if let Some(k) = zd.iter().position(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite {
                what: "ż",
                index: k,
                name: format!("reduced coordinate {k}"),
                t,
            });
        }
        // F,z = F,q V by one block solve (J factorized at x); ẋ = F,z ż
        // (+ F,u u̇) with q̇ = V ż
        self.kin
            .transfer_matrix(v, p.fz.as_mut())
            .map_err(kin_err)?;
        for (i, qd) in p.qd.iter_mut().enumerate() {
            *qd = (0..zd.len()).map(|k| v[(i, k)] * zd[k]).sum();
        }
        for (i, xd) in p.y.iter_mut().enumerate() {
            *xd = (0..zd.len()).map(|k| p.fz[(i, k)] * zd[k]).sum();
        }
        self.kin.velocities_from(&p.qd, &p.y).map_err(kin_err)?;
        // ẍ_c = ẍ0 + F,q c (with D,xx[ẋ, ẋ])
        self.kin
            .accelerations_refined(c, &mut p.xdd)
            .map_err(kin_err)?;
        // f without gravity, which enters as the acceleration field −g:
        // Mx ẋ_g is the consistent gravity force (Element::gravity_force)
        self.forces_with(t, true, false);
        if let Some(g) = self.mech.gravity {
            for &(i, axis) in &p.positions {
                p.xdd[i] -= g[axis] * self.load_factor;
            }
        }
        // y = f − Mx(ẍ_c − ẋ_g) − h, and Mz by element blocks
        p.y.copy_from_slice(&self.f);
        let (x, xd) = (self.kin.x(), self.kin.xd());
        inertia_pass(
            &self.mech,
            (x, xd, &p.xdd),
            &mut p.y,
            Some((&mut p.asm, p.fz.as_ref(), &mut p.mz)),
            None,
        );
        // y −= D,xᵀσ over the deformations that are no constraint rows
        for (j, (ns, s)) in p.neg_sigma.iter_mut().zip(&self.sigma).enumerate() {
            let row = matches!(
                self.mech.e_roles[j],
                ERole::Rigid | ERole::Dof(_) | ERole::Input(_)
            );
            *ns = if row { 0.0 } else { -s };
        }
        self.kin.add_deformation_forces(&p.neg_sigma, &mut p.y);
        // rhs = F,zᵀ y − Σ σ_j V(k_j, :) over the deformation DOFs (E,q's unit rows)
        for (k, r) in p.rhs.iter_mut().enumerate() {
            *r =
                p.fz.col_as_slice(k)
                    .iter()
                    .zip(&p.y)
                    .map(|(a, b)| a * b)
                    .sum();
            for &(i, j) in &p.dof_deformations {
                *r -= self.sigma[j] * v[(i, k)];
            }
        }
        Ok(())
    }
}
