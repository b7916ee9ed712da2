//! The problem interfaces: first-order systems `y' = f(t, y)` and
//! second-order systems in residual form `g(t, q, q̇, q̈) = 0`.

use faer::Mat;

use crate::common::Control;
use crate::error::RhsError;
use flexmb_linalg::DenseLu;

/// A first-order system of ordinary differential equations `y' = f(t, y)`.
///
/// The integrators call [`OdeSystem::rhs`] and count every call.
pub trait OdeSystem {
    /// Dimension of the state `y`.
    fn dim(&self) -> usize;

    /// Evaluates `dy = f(t, y)`. `y` and `dy` have length [`OdeSystem::dim`].
    ///
    /// Return an error if the evaluation fails (e.g. a nested Newton solve
    /// did not converge); the integration then stops with
    /// [`OdeError::Rhs`](crate::OdeError::Rhs). Non-finite values written to
    /// `dy` are detected by the integrator.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError>;

    /// Called after every accepted step with the new state `(t, y)`, once
    /// the output points of that step have been emitted. Returning
    /// [`Control::Stop`] ends the integration there with
    /// [`Status::Stopped`](crate::Status::Stopped), e.g. to change the
    /// coordinates of the system and restart (a chart switch of a rotation
    /// parametrization). The default goes on.
    fn step_accepted(&mut self, _t: f64, _y: &[f64]) -> Control {
        Control::Continue
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for &mut S {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        (**self).rhs(t, y, dy)
    }
    fn step_accepted(&mut self, t: f64, y: &[f64]) -> Control {
        (**self).step_accepted(t, y)
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for Box<S> {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        (**self).rhs(t, y, dy)
    }
    fn step_accepted(&mut self, t: f64, y: &[f64]) -> Control {
        (**self).step_accepted(t, y)
    }
}

/// A second-order system in residual form `g(t, q, q̇, q̈) = 0`, typically
/// `g = M(q) q̈ − f(t, q, q̇)` for the equations of motion `M q̈ = f`.
///
/// Used by the [generalized-α](crate::GeneralizedAlpha) integrator.
pub trait SecondOrderSystem {
    /// Number of coordinates (length of `q`).
    fn dim(&self) -> usize;

    /// Evaluates the residual `r = g(t, q, q̇, q̈)`.
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError>;

    /// Evaluates the tangent matrices `mass = ∂g/∂q̈`, `damping = ∂g/∂q̇` and
    /// `stiffness = ∂g/∂q` (all `dim × dim`). The matrices passed in are not
    /// cleared: every entry must be written.
    #[allow(clippy::too_many_arguments)]
    fn tangent(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        mass: &mut Mat<f64>,
        damping: &mut Mat<f64>,
        stiffness: &mut Mat<f64>,
    ) -> Result<(), RhsError>;

    /// Called after every accepted step with the new state, once the output
    /// points of that step have been emitted; [`Control::Stop`] ends the
    /// integration there (see [`OdeSystem::step_accepted`]).
    fn step_accepted(&mut self, _t: f64, _q: &[f64], _qd: &[f64]) -> Control {
        Control::Continue
    }

    /// Asked before every step attempt, accepted or rejected: `true` ends
    /// the integration at the last accepted step with
    /// [`Status::Stopped`](crate::Status::Stopped). For a stop requested
    /// from outside (a signal) that must not wait for the next accepted
    /// step, which for an implicit method can take many Newton iterations
    /// and tangents. The default never stops.
    fn stop_requested(&mut self) -> bool {
        false
    }
}

impl<S: SecondOrderSystem + ?Sized> SecondOrderSystem for &mut S {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        (**self).residual(t, q, qd, qdd, r)
    }
    fn tangent(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        mass: &mut Mat<f64>,
        damping: &mut Mat<f64>,
        stiffness: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        (**self).tangent(t, q, qd, qdd, mass, damping, stiffness)
    }
    fn step_accepted(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Control {
        (**self).step_accepted(t, q, qd)
    }
    fn stop_requested(&mut self) -> bool {
        (**self).stop_requested()
    }
}

/// Adapter presenting a [`SecondOrderSystem`] as the first-order system
/// `y = (q, q̇)`, `y' = (q̇, q̈)`, so that the explicit integrators can be
/// applied to the same model.
///
/// Each [`OdeSystem::rhs`] call evaluates the residual once at `q̈ = 0` and
/// solves `M q̈ = −g(t, q, q̇, 0)`, which is exact when `g` is affine in `q̈`
/// (as for `M(q) q̈ − f(t, q, q̇)`). The mass matrix is obtained from
/// [`SecondOrderSystem::tangent`] and factored on every call, or only on the
/// first call when the adapter is built with
/// [`FirstOrderForm::with_constant_mass`].
pub struct FirstOrderForm<S> {
    system: S,
    n: usize,
    constant_mass: bool,
    factored: bool,
    mass: Mat<f64>,
    damping: Mat<f64>,
    stiffness: Mat<f64>,
    zeros: Vec<f64>,
    lu: DenseLu,
    residual_evals: usize,
    tangent_evals: usize,
}

impl<S: SecondOrderSystem> FirstOrderForm<S> {
    /// Wraps `system`; the mass matrix is re-evaluated on every call.
    pub fn new(system: S) -> Self {
        let n = system.dim();
        Self {
            system,
            n,
            constant_mass: false,
            factored: false,
            mass: Mat::zeros(n, n),
            damping: Mat::zeros(n, n),
            stiffness: Mat::zeros(n, n),
            zeros: vec![0.0; n],
            lu: DenseLu::new(n).with_singular_pivot_ratio(0.0),
            residual_evals: 0,
            tangent_evals: 0,
        }
    }

    /// Wraps `system` whose mass matrix does not depend on `t`, `q`, `q̇`:
    /// it is evaluated and factored once.
    pub fn with_constant_mass(system: S) -> Self {
        let mut s = Self::new(system);
        s.constant_mass = true;
        s
    }

    /// The wrapped system.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The wrapped system, mutably.
    pub fn system_mut(&mut self) -> &mut S {
        &mut self.system
    }

    /// Unwraps the system.
    pub fn into_inner(self) -> S {
        self.system
    }

    /// Number of residual evaluations made so far.
    pub fn residual_evals(&self) -> usize {
        self.residual_evals
    }

    /// Number of tangent evaluations made so far.
    pub fn tangent_evals(&self) -> usize {
        self.tangent_evals
    }
}

impl<S: SecondOrderSystem> OdeSystem for FirstOrderForm<S> {
    fn dim(&self) -> usize {
        2 * self.n
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.n;
        let (q, qd) = y.split_at(n);
        let (dq, dqd) = dy.split_at_mut(n);
        if !(self.constant_mass && self.factored) {
            self.tangent_evals += 1;
            self.system.tangent(
                t,
                q,
                qd,
                &self.zeros,
                &mut self.mass,
                &mut self.damping,
                &mut self.stiffness,
            )?;
            let mut a = self.lu.matrix_mut();
            a.copy_from(&self.mass);
            if let Err(e) = self.lu.factor_in_place() {
                return Err(RhsError::new(format!(
                    "singular mass matrix at t = {t:e} ({e})"
                )));
            }
            self.factored = true;
        }
        self.residual_evals += 1;
        self.system.residual(t, q, qd, &self.zeros, dqd)?;
        for v in dqd.iter_mut() {
            *v = -*v;
        }
        self.lu.solve_vec(dqd);
        dq.copy_from_slice(qd);
        Ok(())
    }

    fn step_accepted(&mut self, t: f64, y: &[f64]) -> Control {
        let (q, qd) = y.split_at(self.n);
        self.system.step_accepted(t, q, qd)
    }
}
