//! One interface for unreduced and reduced models: [`MechanicalModel`],
//! implemented by [`Dynamics`] (coordinates q) and [`ReducedModel`]
//! (coordinates z), so that a study (equilibrium → eigenfrequencies → sweep →
//! simulation) is written once for both.

use crate::{load_scale_path, ReducedModel, ReductionError};
use faer::Mat;
use flexmb_dynamics::{
    Control, Dynamics, Integrator, OutputTable, SimulationOptions, StaticOptions, Trajectory,
};
use flexmb_model::Mechanism;
use std::sync::Arc;

/// An observer of a run: `observer(t, c, ċ)` at each output time, the
/// model's coordinates and their rates; [`Control::Stop`] ends the run.
pub type StateObserver<'a> = &'a mut dyn FnMut(f64, &[f64], &[f64]) -> Control;

/// A static equilibrium of a model: its coordinates (q or z) and the
/// unreduced configuration x the solver converged to. Start later position
/// solves at this state from `x` (a solve from a far-away configuration can
/// land on another branch).
#[derive(Clone, Debug)]
pub struct Equilibrium {
    /// The model's coordinates: q (unreduced) or z (reduced).
    pub coordinates: Vec<f64>,
    /// The nodal coordinates x = F(q) there.
    pub x: Vec<f64>,
}

/// One point of a [`MechanicalModel::frequency_sweep`].
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// The load scale λ.
    pub load_scale: f64,
    /// The static equilibrium at λ.
    pub equilibrium: Equilibrium,
    /// The lowest undamped eigenfrequencies (Hz) there, ascending.
    pub frequencies: Vec<f64>,
}

/// A time response of a model.
#[derive(Clone, Debug)]
pub struct ModelTrajectory {
    /// The model's coordinates (q or z) at each output time.
    pub coordinates: Vec<Vec<f64>>,
    /// Their rates at each output time.
    pub velocities: Vec<Vec<f64>>,
    /// The unreduced response: output times, q, q̇, the configurations x
    /// solved along the run, exact evaluation counts, wall time, whether it
    /// was stopped, and chart switches.
    pub full: Trajectory,
}

/// A mechanical model: the unreduced equations of motion ([`Dynamics`],
/// coordinates q, thesis (D.10)) or a reduced model ([`ReducedModel`],
/// coordinates z with q = G(z), (6.15)), with one set of signatures for
/// statics, linearization, eigenfrequencies, sweeps and simulation. The
/// trait is object safe: `Box<dyn MechanicalModel>` holds either.
///
/// "Coordinates" are the model's own (q or z); the scene's loads are scaled
/// by [`set_load_scale`](Self::set_load_scale) (gravity stays).
pub trait MechanicalModel {
    /// The unreduced mechanism.
    fn mechanism(&self) -> &Arc<Mechanism>;
    /// The unreduced dynamics (configuration of the last evaluation).
    fn dynamics(&self) -> &Dynamics;
    /// The unreduced dynamics, mutable (e.g. to start the next position
    /// solve at a configuration).
    fn dynamics_mut(&mut self) -> &mut Dynamics;
    /// The number of coordinates (n_q or n_z), the size of a state.
    fn n_coordinates(&self) -> usize;
    /// True for a reduced model.
    fn is_reduced(&self) -> bool;
    /// The coordinates of the reference configuration: q0 of the scene, or
    /// the basis's [`z_reference`](crate::Basis::z_reference).
    fn reference_coordinates(&self) -> Vec<f64>;
    /// Scales the scene's loads by `s` (gravity stays).
    fn set_load_scale(&mut self, s: f64);
    /// The unreduced state (q, q̇) of a state of the model.
    fn full_state(&mut self, c: &[f64], cd: &[f64]) -> (Vec<f64>, Vec<f64>);

    /// The static equilibrium at time `t` by Newton from `start`, the
    /// coordinates of `opts.held` held at their values. The unreduced model
    /// follows all of `opts` ([`Dynamics::static_equilibrium`]); the reduced
    /// one takes the held values and solves at the current load scale by one
    /// damped Newton solve ([`ReducedModel::newton_equilibrium`]: converged
    /// when ‖Δz‖∞ ≤ 1e-10 (1 + ‖z‖∞), at most 30 iterations; the load steps,
    /// ramp, tolerances and stop flag of `opts` are the unreduced solver's):
    /// a load ramp of a reduced model is
    /// [`equilibria_over_load_scale`](Self::equilibria_over_load_scale).
    fn static_equilibrium(
        &mut self,
        t: f64,
        start: &[f64],
        opts: &StaticOptions,
    ) -> Result<Equilibrium, ReductionError>;

    /// The static equilibrium under the scene's full loads at time `t` from
    /// the reference coordinates, each model's way: unreduced with the loads
    /// ramped in one increment (halved while Newton fails), reduced by
    /// load-scale continuation from 0 (a reduced Newton has no ramp). Leaves
    /// the load scale at 1.
    fn equilibrium_under_loads(&mut self, t: f64) -> Result<Equilibrium, ReductionError>;

    /// The rest linearization at the coordinates `c` (q̇ = 0, loads at `t`):
    /// the mass and total stiffness matrices (M, K) of (E.6), reduced (F.7).
    fn rest_matrices(&mut self, t: f64, c: &[f64]) -> Result<(Mat<f64>, Mat<f64>), ReductionError>;

    /// The lowest `count` undamped eigenfrequencies (Hz, ascending; at most
    /// [`n_coordinates`](Self::n_coordinates)) of the rest linearization at `c`.
    fn eigenfrequencies(
        &mut self,
        t: f64,
        c: &[f64],
        count: usize,
    ) -> Result<Vec<f64>, ReductionError>;

    /// The rates ċ of the scene's initial velocities at the coordinates `c`:
    /// q̇0 of [`Dynamics::initial_qd`], projected on the basis for a reduced
    /// model ([`ReducedModel::project_velocities`]).
    fn initial_velocities(&mut self, t: f64, c: &[f64]) -> Result<Vec<f64>, ReductionError>;

    /// Integrates from (t0, c0, ċ0) to the last output time;
    /// `observer(t, c, ċ)` is called at each output time and may stop the
    /// run (partial results are kept). A reduced model takes explicit
    /// integrators only.
    fn simulate(
        &mut self,
        t0: f64,
        c0: &[f64],
        cd0: &[f64],
        opts: &SimulationOptions,
        observer: StateObserver<'_>,
    ) -> Result<ModelTrajectory, ReductionError>;

    /// [`simulate`](Self::simulate), recording the rows of `table` (the
    /// scene's outputs, without the time column) at each output time: the
    /// unreduced model when the integrator reaches the output, in the chart
    /// of the orientations the run has there; a reduced model after the run
    /// from q = G(z), q̇ = G,z ż and the configurations solved along it.
    fn simulate_outputs(
        &mut self,
        t0: f64,
        c0: &[f64],
        cd0: &[f64],
        opts: &SimulationOptions,
        table: &OutputTable,
        observer: &mut dyn FnMut(f64) -> Control,
    ) -> Result<(ModelTrajectory, Vec<Vec<f64>>), ReductionError>;

    /// The static equilibria at the load scales `lambdas` (loads at time
    /// `t`, gravity unscaled, any order): the equilibrium without the
    /// scene's loads from the reference coordinates (loads ramped), then
    /// [`load_scale_path`] with [`static_equilibrium`](Self::static_equilibrium)
    /// (loads not ramped), each position solve starting at the configuration
    /// of the equilibrium it continues from. `done(k)` reports progress. The
    /// load scale is left at the last value solved.
    fn equilibria_over_load_scale(
        &mut self,
        t: f64,
        lambdas: &[f64],
        done: &mut dyn FnMut(usize),
    ) -> Result<Vec<Equilibrium>, ReductionError> {
        let start = self.reference_coordinates();
        self.set_load_scale(0.0);
        let at_zero = self
            .static_equilibrium(t, &start, &StaticOptions::default())
            .map_err(|e| ReductionError::NoEquilibrium {
                lambda: 0.0,
                from: 0.0,
                substeps: 1,
                message: format!("without the scene's loads (gravity only): {e}"),
            })?;
        let continued = StaticOptions {
            ramp_loads: false,
            ..Default::default()
        };
        let mut solve = |from: &Equilibrium, l: f64| -> Result<Equilibrium, String> {
            self.set_load_scale(l);
            self.dynamics_mut().kinematics_mut().set_guess(&from.x);
            self.static_equilibrium(t, &from.coordinates, &continued)
                .map_err(|e| e.to_string())
        };
        load_scale_path(&at_zero, lambdas, &mut solve, done)
    }

    /// The lowest `count` eigenfrequencies at the static equilibria along the
    /// load scales `lambdas` ([`equilibria_over_load_scale`](Self::equilibria_over_load_scale),
    /// then [`eigenfrequencies`](Self::eigenfrequencies) at each, its load
    /// scale set and its position solve started at the equilibrium's x).
    /// `progress(k)` reports k of 2·n steps done (n equilibria, then n eigen
    /// analyses); returning [`Control::Stop`] before an eigen analysis ends
    /// the sweep with the points so far (the equilibria, a continuation, are
    /// all found first). The result is in the order of `lambdas`.
    fn frequency_sweep(
        &mut self,
        t: f64,
        lambdas: &[f64],
        count: usize,
        progress: &mut dyn FnMut(usize) -> Control,
    ) -> Result<Vec<SweepPoint>, ReductionError> {
        let n = lambdas.len();
        let eqs = self.equilibria_over_load_scale(t, lambdas, &mut |d| {
            progress(d);
        })?;
        let mut points = Vec::with_capacity(n);
        for (i, (l, eq)) in lambdas.iter().zip(eqs).enumerate() {
            if progress(n + i) == Control::Stop {
                return Ok(points);
            }
            self.set_load_scale(*l);
            self.dynamics_mut().kinematics_mut().set_guess(&eq.x);
            let frequencies = self
                .eigenfrequencies(t, &eq.coordinates, count)
                .map_err(|e| {
                    ReductionError::Computation(format!("eigenfrequencies at load scale {l}: {e}"))
                })?;
            points.push(SweepPoint {
                load_scale: *l,
                equilibrium: eq,
                frequencies,
            });
        }
        progress(2 * n);
        Ok(points)
    }
}

impl MechanicalModel for Dynamics {
    fn mechanism(&self) -> &Arc<Mechanism> {
        Dynamics::mechanism(self)
    }
    fn dynamics(&self) -> &Dynamics {
        self
    }
    fn dynamics_mut(&mut self) -> &mut Dynamics {
        self
    }
    fn n_coordinates(&self) -> usize {
        self.n_q()
    }
    fn is_reduced(&self) -> bool {
        false
    }
    fn reference_coordinates(&self) -> Vec<f64> {
        Dynamics::mechanism(self).q0()
    }
    fn set_load_scale(&mut self, s: f64) {
        Dynamics::set_load_scale(self, s);
    }
    fn full_state(&mut self, c: &[f64], cd: &[f64]) -> (Vec<f64>, Vec<f64>) {
        (c.to_vec(), cd.to_vec())
    }
    fn static_equilibrium(
        &mut self,
        t: f64,
        start: &[f64],
        opts: &StaticOptions,
    ) -> Result<Equilibrium, ReductionError> {
        let sol = Dynamics::static_equilibrium(self, t, start, opts)?;
        Ok(Equilibrium {
            coordinates: sol.q,
            x: self.kinematics().x().to_vec(),
        })
    }
    fn equilibrium_under_loads(&mut self, t: f64) -> Result<Equilibrium, ReductionError> {
        Dynamics::set_load_scale(self, 1.0);
        let q0 = Dynamics::mechanism(self).q0();
        MechanicalModel::static_equilibrium(self, t, &q0, &StaticOptions::default())
    }
    fn rest_matrices(&mut self, t: f64, c: &[f64]) -> Result<(Mat<f64>, Mat<f64>), ReductionError> {
        let lin = self.linearize_at_rest(t, c)?;
        let k = lin.stiffness_total();
        Ok((lin.m, k))
    }
    fn eigenfrequencies(
        &mut self,
        t: f64,
        c: &[f64],
        count: usize,
    ) -> Result<Vec<f64>, ReductionError> {
        let lin = self.linearize_at_rest(t, c)?;
        let count = count.min(lin.m.nrows());
        Ok(flexmb_linearize::undamped_modes(&lin, count)?.frequencies_hz())
    }
    fn initial_velocities(&mut self, t: f64, c: &[f64]) -> Result<Vec<f64>, ReductionError> {
        Ok(self.initial_qd(t, c)?)
    }
    fn simulate(
        &mut self,
        t0: f64,
        c0: &[f64],
        cd0: &[f64],
        opts: &SimulationOptions,
        observer: StateObserver<'_>,
    ) -> Result<ModelTrajectory, ReductionError> {
        let full = Dynamics::simulate(self, t0, c0, cd0, opts, observer)?;
        Ok(ModelTrajectory {
            coordinates: full.q.clone(),
            velocities: full.qd.clone(),
            full,
        })
    }
    fn simulate_outputs(
        &mut self,
        t0: f64,
        c0: &[f64],
        cd0: &[f64],
        opts: &SimulationOptions,
        table: &OutputTable,
        observer: &mut dyn FnMut(f64) -> Control,
    ) -> Result<(ModelTrajectory, Vec<Vec<f64>>), ReductionError> {
        let mut rows = vec![];
        let mut failure = None;
        let full = self.simulate_with(t0, c0, cd0, opts, |p| {
            let x = p.dynamics.kinematics().x().to_vec();
            match table.row(p.dynamics, p.t, p.q_chart, p.qd_chart, &x) {
                Ok(r) => {
                    rows.push(r);
                    observer(p.t)
                }
                Err(e) => {
                    failure = Some(e);
                    Control::Stop
                }
            }
        })?;
        if let Some(e) = failure {
            return Err(e.into());
        }
        let traj = ModelTrajectory {
            coordinates: full.q.clone(),
            velocities: full.qd.clone(),
            full,
        };
        Ok((traj, rows))
    }
}

impl MechanicalModel for ReducedModel {
    fn mechanism(&self) -> &Arc<Mechanism> {
        self.dynamics().mechanism()
    }
    fn dynamics(&self) -> &Dynamics {
        ReducedModel::dynamics(self)
    }
    fn dynamics_mut(&mut self) -> &mut Dynamics {
        ReducedModel::dynamics_mut(self)
    }
    fn n_coordinates(&self) -> usize {
        self.n_z()
    }
    fn is_reduced(&self) -> bool {
        true
    }
    fn reference_coordinates(&self) -> Vec<f64> {
        self.basis().z_reference()
    }
    fn set_load_scale(&mut self, s: f64) {
        ReducedModel::set_load_scale(self, s);
    }
    fn full_state(&mut self, c: &[f64], cd: &[f64]) -> (Vec<f64>, Vec<f64>) {
        ReducedModel::full_state(self, c, cd)
    }
    fn static_equilibrium(
        &mut self,
        t: f64,
        start: &[f64],
        opts: &StaticOptions,
    ) -> Result<Equilibrium, ReductionError> {
        let mut z0 = start.to_vec();
        let mut held = Vec::with_capacity(opts.held.len());
        for &(k, v) in &opts.held {
            if k >= z0.len() {
                return Err(ReductionError::Invalid(format!(
                    "reduced equilibrium: held coordinate {k} of {} reduced coordinates",
                    z0.len()
                )));
            }
            z0[k] = v;
            held.push(k);
        }
        let z = self.newton_equilibrium(t, &z0, &held)?;
        Ok(Equilibrium {
            coordinates: z,
            x: self.dynamics().kinematics().x().to_vec(),
        })
    }
    fn equilibrium_under_loads(&mut self, t: f64) -> Result<Equilibrium, ReductionError> {
        let eq = self.equilibria_over_load_scale(t, &[1.0], &mut |_| {})?;
        ReducedModel::set_load_scale(self, 1.0);
        Ok(eq
            .into_iter()
            .next()
            .expect("one load scale, one equilibrium"))
    }
    fn rest_matrices(&mut self, t: f64, c: &[f64]) -> Result<(Mat<f64>, Mat<f64>), ReductionError> {
        self.linearize_at_rest(t, c)
    }
    fn eigenfrequencies(
        &mut self,
        t: f64,
        c: &[f64],
        count: usize,
    ) -> Result<Vec<f64>, ReductionError> {
        let mut f = self.frequencies_at_rest(t, c)?;
        f.truncate(count);
        Ok(f)
    }
    fn initial_velocities(&mut self, t: f64, c: &[f64]) -> Result<Vec<f64>, ReductionError> {
        let (q, _) = ReducedModel::full_state(self, c, &vec![0.0; c.len()]);
        // the model's own dynamics: its position solve continues from the
        // configuration it last solved (e.g. the equilibrium it found)
        let qd = ReducedModel::dynamics_mut(self).initial_qd(t, &q)?;
        self.project_velocities(t, c, &qd)
    }
    fn simulate(
        &mut self,
        t0: f64,
        c0: &[f64],
        cd0: &[f64],
        opts: &SimulationOptions,
        observer: StateObserver<'_>,
    ) -> Result<ModelTrajectory, ReductionError> {
        if opts.integrator == Integrator::GeneralizedAlpha {
            return Err(ReductionError::Invalid(
                "a reduced model is integrated with an explicit integrator (DOPRI5 or Adams)"
                    .into(),
            ));
        }
        let tr = ReducedModel::simulate(self, t0, c0, cd0, opts, observer)?;
        let (q, qd) =
            tr.z.iter()
                .zip(&tr.zd)
                .map(|(z, zd)| ReducedModel::full_state(self, z, zd))
                .unzip();
        Ok(ModelTrajectory {
            full: Trajectory {
                t: tr.t,
                q,
                qd,
                stats: tr.stats,
                wall_time: tr.wall_time,
                stopped: tr.stopped,
                x: tr.x,
                chart_switches: tr.chart_switches,
                // a reduced model keeps the dependent set of its basis
                partition_switches: vec![],
            },
            coordinates: tr.z,
            velocities: tr.zd,
        })
    }
    fn simulate_outputs(
        &mut self,
        t0: f64,
        c0: &[f64],
        cd0: &[f64],
        opts: &SimulationOptions,
        table: &OutputTable,
        observer: &mut dyn FnMut(f64) -> Control,
    ) -> Result<(ModelTrajectory, Vec<Vec<f64>>), ReductionError> {
        let traj = MechanicalModel::simulate(self, t0, c0, cd0, opts, &mut |t, _, _| observer(t))?;
        let f = &traj.full;
        let dy = ReducedModel::dynamics_mut(self);
        let rows = (0..f.t.len())
            .map(|i| table.row(dy, f.t[i], &f.q[i], &f.qd[i], &f.x[i]))
            .collect::<Result<Vec<_>, _>>()?;
        Ok((traj, rows))
    }
}
