//! The configuration a picture shows, and the mode shapes of the
//! linearization there ([`flexmb_linearize::undamped_modes`], as `flexmb
//! eig`), as nodal displacements.

use crate::DrawError;
use flexmb_dynamics::{Dynamics, StaticOptions};
use flexmb_kinematics::Kinematics;
use flexmb_model::Mechanism;
use std::sync::Arc;

/// A configuration of a mechanism: its degrees of freedom and nodal
/// coordinates.
#[derive(Clone, Debug)]
pub struct Configuration {
    /// The mechanism (after a static solve: in the Euler-parameter charts
    /// that solve ended in).
    pub mechanism: Arc<Mechanism>,
    /// The degrees of freedom.
    pub q: Vec<f64>,
    /// The nodal coordinates x = F(q).
    pub x: Vec<f64>,
    /// The time at which inputs and loads are evaluated.
    pub t: f64,
    /// The scale of the nodal loads ([`Dynamics::set_load_scale`]).
    pub load_scale: f64,
}

fn compute(e: impl std::fmt::Display) -> DrawError {
    DrawError::Compute(e.to_string())
}

impl Configuration {
    /// The configuration with degrees of freedom `q` at t = 0, solved from
    /// the reference configuration.
    pub fn at(mech: &Arc<Mechanism>, q: &[f64]) -> Result<Configuration, DrawError> {
        if q.len() != mech.n_dof() {
            return Err(DrawError::Input(format!(
                "{} values for the {} degrees of freedom of '{}'",
                q.len(),
                mech.n_dof(),
                mech.name
            )));
        }
        let mut kin = Kinematics::new(mech.clone());
        kin.solve(q, 0.0).map_err(compute)?;
        Ok(Configuration {
            mechanism: mech.clone(),
            q: q.to_vec(),
            x: kin.x().to_vec(),
            t: 0.0,
            load_scale: 1.0,
        })
    }

    /// The reference configuration.
    pub fn reference(mech: &Arc<Mechanism>) -> Result<Configuration, DrawError> {
        Configuration::at(mech, &mech.q0())
    }

    /// The static equilibrium under the scene's loads and gravity at t = 0
    /// (as `flexmb static` and `flexmb eig --static-first` find it).
    pub fn static_equilibrium(mech: &Arc<Mechanism>) -> Result<Configuration, DrawError> {
        Configuration::loaded(mech, 0.0, 1.0, 1)
    }

    /// The static equilibrium under the scene's loads at time `t` scaled by
    /// `load_scale`, and gravity, reached in `load_steps` equal increments.
    pub fn loaded(
        mech: &Arc<Mechanism>,
        t: f64,
        load_scale: f64,
        load_steps: usize,
    ) -> Result<Configuration, DrawError> {
        let mut dy = Dynamics::new(mech.clone());
        dy.set_load_scale(load_scale);
        let opts = StaticOptions {
            load_steps,
            ..Default::default()
        };
        let sol = dy
            .static_equilibrium(t, &mech.q0(), &opts)
            .map_err(compute)?;
        Ok(Configuration {
            mechanism: dy.mechanism().clone(),
            q: sol.q,
            x: sol.x,
            t,
            load_scale,
        })
    }
}

/// One undamped mode of the linearization at a configuration.
#[derive(Clone, Debug)]
pub struct ModeShape {
    /// The mode's number, from 1 (lowest frequency).
    pub number: usize,
    /// Its frequency (Hz; negative for an unstable direction).
    pub frequency_hz: f64,
    /// The mass-normalized eigenvector in the degrees of freedom.
    pub q: Vec<f64>,
    /// The nodal displacement F,q v of the eigenvector v (first order).
    pub x: Vec<f64>,
}

/// Mode `number` (from 1) exists: an input error that says how many modes
/// `mech` has otherwise.
pub fn check_mode(mech: &Mechanism, number: usize) -> Result<(), DrawError> {
    let n = mech.n_dof();
    if number == 0 || number > n {
        return Err(DrawError::Input(format!(
            "{number}: no such mode; '{}' has {n} modes (one per degree of freedom), numbered 1 to {n}",
            mech.name
        )));
    }
    Ok(())
}

/// Mode `number` (from 1) of the rest linearization (thesis (E.6)) at
/// `at` (its time and load scale). A number beyond the degrees of freedom is an input error that
/// says how many modes there are.
pub fn mode_shape(at: &Configuration, number: usize) -> Result<ModeShape, DrawError> {
    let mech = &at.mechanism;
    check_mode(mech, number)?;
    let n = mech.n_dof();
    let mut dy = Dynamics::new(mech.clone());
    dy.set_load_scale(at.load_scale);
    // from the configuration's own nodal coordinates: from the reference
    // the position solve of q may converge on another branch (a deflected
    // chapter-4 mechanism gave "mode 3, -1596987 Hz")
    dy.kinematics_mut().set_guess(&at.x);
    let lin = dy.linearize_at_rest(at.t, &at.q).map_err(compute)?;
    let modes = flexmb_linearize::undamped_modes(&lin, number).map_err(compute)?;
    let k = number - 1;
    let v: Vec<f64> = (0..n).map(|i| modes.vectors[(i, k)]).collect();
    let mut kin = Kinematics::new(mech.clone());
    kin.set_guess(&at.x);
    kin.solve(&at.q, at.t).map_err(compute)?;
    let f = kin.f_xi();
    let mut dx = vec![0.0; f.nrows()];
    for (c, vc) in v.iter().enumerate() {
        for (d, fc) in dx.iter_mut().zip(f.col_as_slice(c)) {
            *d += fc * vc;
        }
    }
    Ok(ModeShape {
        number,
        frequency_hz: modes.frequencies_hz()[k],
        q: v,
        x: dx,
    })
}

impl ModeShape {
    /// The largest nodal displacement (m) of the eigenvector.
    pub fn largest_nodal_displacement(&self, mech: &Mechanism) -> f64 {
        mech.nodes
            .iter()
            .map(|n| {
                n.position
                    .iter()
                    .map(|i| self.x[*i].powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max)
    }

    /// The scale of the eigenvector that makes its largest nodal
    /// displacement `amplitude` (m).
    pub fn scale_for(&self, mech: &Mechanism, amplitude: f64) -> f64 {
        let d = self.largest_nodal_displacement(mech);
        if d > 0.0 {
            amplitude / d
        } else {
            0.0
        }
    }
}
