//! Time simulation: the equations of motion in first-order form y = (q, q̇) for
//! the explicit integrators (the thesis counts evaluations of this right-hand
//! side), and in residual form with tangents for generalized-α.

use crate::{Dynamics, DynamicsError};
use faer::Mat;
use flexmb_ode::{
    Adams, AdamsOptions, Control, Dopri5, Dopri5Options, GeneralizedAlpha, GeneralizedAlphaOptions,
    OdeSystem, Output, RhsError, SecondOrderSystem, Stats, Tolerance,
};
use std::cell::RefCell;
use std::time::Instant;

/// Mass, damping and stiffness tangents (M, C, K) of the residual.
pub type TangentMatrices = (Mat<f64>, Mat<f64>, Mat<f64>);

/// The integrators offered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Dormand–Prince 5(4), ode45-like (thesis chapter 5).
    Dopri5,
    /// Variable-order Adams PECE, Shampine–Gordon style (thesis chapters 3, 6, 7).
    Adams,
    /// Generalized-α, implicit, for stiff unreduced models.
    GeneralizedAlpha,
}

impl std::str::FromStr for Integrator {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "dopri5" | "ode45" | "rk45" => Ok(Integrator::Dopri5),
            "adams" | "shampine-gordon" | "de" => Ok(Integrator::Adams),
            "genalpha" | "generalized-alpha" | "implicit" => Ok(Integrator::GeneralizedAlpha),
            _ => Err(format!(
                "unknown integrator '{s}': use dopri5, adams or genalpha"
            )),
        }
    }
}

/// Settings of a simulation.
#[derive(Clone, Debug)]
pub struct SimulationOptions {
    /// Integrator.
    pub integrator: Integrator,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Output times (dense output; no extra evaluations).
    pub output_times: Vec<f64>,
}

impl SimulationOptions {
    /// ode45's defaults (RelTol 1e-3, AbsTol 1e-6) with `n` equidistant outputs on [t0, t_end].
    pub fn new(integrator: Integrator, t0: f64, t_end: f64, n: usize) -> Self {
        let n = n.max(2);
        Self {
            integrator,
            rtol: 1e-3,
            atol: 1e-6,
            output_times: (0..n)
                .map(|k| t0 + (t_end - t0) * k as f64 / (n - 1) as f64)
                .collect(),
        }
    }
}

/// A computed trajectory.
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// Output times.
    pub t: Vec<f64>,
    /// q at each output time.
    pub q: Vec<Vec<f64>>,
    /// q̇ at each output time.
    pub qd: Vec<Vec<f64>>,
    /// The nodal coordinates x = F(q) at each output time, solved when the
    /// integrator reached the output from the configuration it had there
    /// (see [`Dynamics::output_configuration`]): the branch of the motion,
    /// whatever the run does later. Outputs start their position solves here
    /// ([`OutputTable::row`](crate::OutputTable::row)).
    pub x: Vec<Vec<f64>>,
    /// Integrator statistics (exact evaluation counts).
    pub stats: Stats,
    /// Wall time of the integration in seconds.
    pub wall_time: f64,
    /// True if stopped early by the observer.
    pub stopped: bool,
}

/// A system shared by the integrator and its output observer, so that the
/// observer can evaluate outputs with the system's own state (the
/// configuration of the integrator's last evaluation). The integrator never
/// evaluates the system while the observer runs, so the two borrows never
/// meet; if they did, the evaluation would fail with an error, not a panic.
struct Shared<'c, 's, S: ?Sized> {
    cell: &'c RefCell<&'s mut S>,
    dim: usize,
}

impl<'c, 's, S: ?Sized> Shared<'c, 's, S> {
    fn system(&self) -> Result<std::cell::RefMut<'c, &'s mut S>, RhsError> {
        self.cell
            .try_borrow_mut()
            .map_err(|_| RhsError::new("the system was evaluated while an output was recorded"))
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for Shared<'_, '_, S> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.system()?.rhs(t, y, dy)
    }
}

impl<S: SecondOrderSystem + ?Sized> SecondOrderSystem for Shared<'_, '_, S> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        self.system()?.residual(t, q, qd, qdd, r)
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
        self.system()?
            .tangent(t, q, qd, qdd, mass, damping, stiffness)
    }
}

/// Integrates a first-order system y' = f(t, y) with one of the explicit
/// integrators (Dopri5 or Adams) from (t0, y0) to the last output time of
/// `opts`; `observer(sys, t, y)` sees each output, with the system in the
/// state of the integrator's last evaluation (e.g. to solve the output's
/// configuration from there), and may stop the run. Returns the
/// integrator's statistics and whether the observer stopped it. Reduced
/// models use this exactly like the unreduced equations of motion.
pub fn integrate_explicit<S: OdeSystem + ?Sized>(
    sys: &mut S,
    opts: &SimulationOptions,
    t0: f64,
    y0: &[f64],
    mut observer: impl FnMut(&mut S, f64, &[f64]) -> Control,
) -> Result<(Stats, bool), DynamicsError> {
    let t_end = *opts
        .output_times
        .last()
        .ok_or_else(|| DynamicsError::Invalid("no output times".into()))?;
    let out = Output::Times(opts.output_times.clone());
    let to_err = |e: flexmb_ode::OdeError| DynamicsError::Integration(e.to_string());
    let dim = sys.dim();
    let cell = RefCell::new(sys);
    let mut shared = Shared { cell: &cell, dim };
    let mut observe = |t: f64, y: &[f64]| match cell.try_borrow_mut() {
        Ok(mut s) => observer(&mut **s, t, y),
        // (unreachable: the integrator is not evaluating the system)
        Err(_) => Control::Stop,
    };
    let sol = match opts.integrator {
        Integrator::Dopri5 => {
            let o = Dopri5Options {
                rtol: opts.rtol,
                atol: Tolerance::Scalar(opts.atol),
                ..Default::default()
            };
            Dopri5::new(o)
                .solve_with(&mut shared, t0, y0, t_end, &out, &mut observe)
                .map_err(to_err)?
        }
        Integrator::Adams => {
            let o = AdamsOptions {
                rtol: opts.rtol,
                atol: Tolerance::Scalar(opts.atol),
                ..Default::default()
            };
            Adams::new(o)
                .solve_with(&mut shared, t0, y0, t_end, &out, &mut observe)
                .map_err(to_err)?
        }
        Integrator::GeneralizedAlpha => {
            return Err(DynamicsError::Invalid(
                "generalized-α needs the residual form (Dynamics::simulate); use dopri5 or adams for first-order systems".into(),
            ))
        }
    };
    Ok((
        sol.stats.clone(),
        !matches!(sol.status, flexmb_ode::Status::Completed),
    ))
}

/// Records the output point (t, q, q̇) in `traj` with its configuration,
/// solved from the state of the integrator's last evaluation in `dy`; a
/// failure is kept in `failure` and stops the run. Then asks `observer`.
fn record_output(
    traj: &mut Trajectory,
    failure: &mut Option<DynamicsError>,
    dy: &mut Dynamics,
    (t, q, qd): (f64, &[f64], &[f64]),
    observer: &mut impl FnMut(f64, &[f64], &[f64]) -> Control,
) -> Control {
    match dy.output_configuration(t, q) {
        Ok(x) => traj.x.push(x),
        Err(e) => {
            *failure = Some(e);
            return Control::Stop;
        }
    }
    traj.t.push(t);
    traj.q.push(q.to_vec());
    traj.qd.push(qd.to_vec());
    observer(t, q, qd)
}

/// Kinematic failures at a trial state are recoverable (a smaller step
/// reaches a solvable configuration); the others abort the integration.
fn to_rhs_error(e: DynamicsError) -> RhsError {
    match e {
        DynamicsError::Kinematics { .. } | DynamicsError::NonFinite { .. } => {
            RhsError::recoverable(e.to_string())
        }
        _ => RhsError::new(e.to_string()),
    }
}

/// The first-order form y = (q, q̇), ẏ = (q̇, q̈).
pub struct FirstOrder<'a> {
    dy: &'a mut Dynamics,
    qdd: Vec<f64>,
}

impl OdeSystem for FirstOrder<'_> {
    fn dim(&self) -> usize {
        2 * self.dy.n_q()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.dy.n_q();
        let (q, qd) = y.split_at(n);
        self.dy
            .accelerations(t, q, qd, &mut self.qdd)
            .map_err(to_rhs_error)?;
        dy[..n].copy_from_slice(qd);
        dy[n..].copy_from_slice(&self.qdd);
        Ok(())
    }
}

struct Residual<'a> {
    dy: &'a mut Dynamics,
}

impl SecondOrderSystem for Residual<'_> {
    fn dim(&self) -> usize {
        self.dy.n_q()
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        self.dy.residual(t, q, qd, qdd, r).map_err(to_rhs_error)
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
        let (m, d, k) = self
            .dy
            .tangent_matrices(t, q, qd, qdd)
            .map_err(to_rhs_error)?;
        mass.copy_from(&m);
        damping.copy_from(&d);
        stiffness.copy_from(&k);
        Ok(())
    }
}

impl Dynamics {
    /// The first-order system for explicit integrators.
    pub fn first_order_system(&mut self) -> FirstOrder<'_> {
        let n = self.n_q();
        FirstOrder {
            dy: self,
            qdd: vec![0.0; n],
        }
    }

    /// Tangent matrices of the residual for implicit integration: M = Mq,
    /// C = Dq + controller damping, K = Kq + Gq (with Mxẍ − f in (E.5e)) −
    /// F,qᵀ f,x F,q. The velocity-dependent C and N terms of (E.5c,f) are
    /// omitted: a modified Newton iteration converges with them missing.
    pub fn tangent_matrices(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Result<TangentMatrices, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        let n_q = self.n_q();
        let mq = self.mq.clone();
        // w' = Mx ẍ − f = −w + Mx F,q q̈
        let mut xdd_q = vec![0.0; self.w.len()];
        let f = self.kin.f_xi();
        for (c, v) in qdd.iter().enumerate().take(n_q) {
            for (o, fv) in xdd_q.iter_mut().zip(f.col_as_slice(c)) {
                *o += fv * v;
            }
        }
        let mut wq: Vec<f64> = self.w.iter().map(|v| -v).collect();
        self.mass_times_add(&xdd_q, &mut wq);
        let sigma = self.sigma.clone();
        let mut k = self.kin.second_order_contraction(&wq, &sigma);
        k += &self.structural_stiffness();
        k -= &self.load_stiffness(t);
        let d = self.damping_matrix();
        Ok((mq, d, k))
    }

    /// Dq = E,qᵀ D E,q (E.6b) plus controller derivative gains.
    pub(crate) fn damping_matrix(&self) -> Mat<f64> {
        let mech = &self.mech;
        let n_q = mech.n_dof();
        let e = self.kin.e_xi();
        let f = self.kin.f_xi();
        let mut d = Mat::<f64>::zeros(n_q, n_q);
        for el in &mech.elements {
            let Some(dm) = el.element.damping() else {
                continue;
            };
            let ne = el.element.n_eps();
            let o = el.eps_offset;
            let ee = Mat::from_fn(ne, n_q, |a, c| e[(o + a, c)]);
            let dd = Mat::from_fn(ne, ne, |a, b| dm[(a, b)]);
            let de = &dd * &ee;
            d += ee.transpose() * de;
        }
        for c in &mech.controllers {
            let row: Vec<f64> = match c.on {
                flexmb_model::Coordinate::Node(i) => (0..n_q).map(|k| f[(i, k)]).collect(),
                flexmb_model::Coordinate::Def(j) => (0..n_q).map(|k| e[(j, k)]).collect(),
            };
            for a in 0..n_q {
                for b in 0..n_q {
                    d[(a, b)] += c.kd * row[a] * row[b];
                }
            }
        }
        d
    }

    /// The nodal coordinates x = F(q) at an output point (t, q) that the
    /// integrator has reached, solved by a kinematics of their own that
    /// starts from this dynamics' current configuration: the one of the
    /// integrator's last evaluation, within a step of t. So the output lies
    /// on the branch the integrator followed (a solve from a far-away
    /// configuration, e.g. the end of the run, can land on a mirrored one),
    /// and the integrator's own kinematics, and with it the run, is not
    /// disturbed.
    pub fn output_configuration(&mut self, t: f64, q: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let mech = &self.mech;
        let kin = self
            .output_kin
            .get_or_insert_with(|| flexmb_kinematics::Kinematics::new(mech.clone()));
        kin.set_newton_options(self.kin.newton_options());
        kin.set_guess(self.kin.x());
        kin.solve(q, t)
            .map_err(|e| DynamicsError::Kinematics { t, source: e })?;
        Ok(kin.x().to_vec())
    }

    /// Integrates from (t0, q0, q̇0) to the last output time. `observer(t, q, q̇)`
    /// is called at each output time and may stop the run (partial results
    /// are kept). The trajectory holds each output's configuration x, solved
    /// when the integrator reached it ([`Self::output_configuration`]).
    pub fn simulate(
        &mut self,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        opts: &SimulationOptions,
        mut observer: impl FnMut(f64, &[f64], &[f64]) -> Control,
    ) -> Result<Trajectory, DynamicsError> {
        let n = self.n_q();
        let t_end = *opts
            .output_times
            .last()
            .ok_or_else(|| DynamicsError::Invalid("no output times".into()))?;
        let out = Output::Times(opts.output_times.clone());
        let mut traj = Trajectory {
            t: vec![],
            q: vec![],
            qd: vec![],
            x: vec![],
            stats: Stats::default(),
            wall_time: 0.0,
            stopped: false,
        };
        let mut failure = None;
        let start = Instant::now();
        let to_err = |e: flexmb_ode::OdeError| DynamicsError::Integration(e.to_string());
        match opts.integrator {
            Integrator::Dopri5 | Integrator::Adams => {
                let mut y0 = q0.to_vec();
                y0.extend_from_slice(qd0);
                let mut sys = self.first_order_system();
                let (stats, stopped) =
                    integrate_explicit(&mut sys, opts, t0, &y0, |sys, t: f64, y: &[f64]| {
                        let (q, qd) = y.split_at(n);
                        record_output(&mut traj, &mut failure, sys.dy, (t, q, qd), &mut observer)
                    })?;
                traj.stats = stats;
                traj.stopped = stopped;
            }
            Integrator::GeneralizedAlpha => {
                let o = GeneralizedAlphaOptions {
                    rtol: opts.rtol,
                    atol: Tolerance::Scalar(opts.atol),
                    ..Default::default()
                };
                let mut res = Residual { dy: self };
                let cell = RefCell::new(&mut res);
                let mut shared = Shared {
                    cell: &cell,
                    dim: n,
                };
                let sol = GeneralizedAlpha::new(o)
                    .solve_with(&mut shared, t0, q0, qd0, t_end, &out, |t, q, qd, _| {
                        match cell.try_borrow_mut() {
                            Ok(mut r) => record_output(
                                &mut traj,
                                &mut failure,
                                r.dy,
                                (t, q, qd),
                                &mut observer,
                            ),
                            // (unreachable: the integrator is not evaluating the system)
                            Err(_) => Control::Stop,
                        }
                    })
                    .map_err(to_err)?;
                traj.stats = sol.stats.clone();
                traj.stopped = !matches!(sol.status, flexmb_ode::Status::Completed);
            }
        }
        if let Some(e) = failure {
            return Err(e);
        }
        traj.wall_time = start.elapsed().as_secs_f64();
        Ok(traj)
    }
}
