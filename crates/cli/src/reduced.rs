//! `flexmb simulate --reduced` and `flexmb sweep --reduced`: a reduced model
//! saved by `flexmb reduce`, applied to a scene with the same degrees of
//! freedom.

use crate::out::say;
use crate::report::{count_bar, write_frequency_sweep, FrequencySweep, Response};
use crate::{Failure, SweepArgs};
use flexmb_dynamics::{Control, Integrator, SimulationOptions};
use flexmb_model::Mechanism;
use flexmb_reduction::{ReducedModel, SavedBasis, SavedModel};
use std::path::Path;
use std::sync::Arc;

/// Reads a saved model and applies it to `mech`: a model built for other
/// degrees of freedom is invalid input naming the first differing DOF.
fn load_model(mech: &Arc<Mechanism>, path: &Path) -> Result<(SavedModel, ReducedModel), Failure> {
    let saved = SavedModel::load(path).map_err(|e| Failure::Input(e.to_string()))?;
    let red = saved
        .into_model(mech.clone())
        .map_err(|e| Failure::Input(format!("{}: {e}", path.display())))?;
    say!("{}", mech.summary());
    say!(
        "reduced model {}: {} coordinates (from {}); {}",
        path.display(),
        red.n_z(),
        mech.n_dof(),
        saved.description
    );
    Ok((saved, red))
}

/// Integrates the reduced model `model` of `mech` from its reference
/// coordinates (or its static equilibrium under the loads and gravity at
/// t = 0, by load-scale continuation) with the scene's initial velocities
/// projected on the basis; returns the response mapped to q and the model's
/// description.
pub(crate) fn simulate(
    mech: &Arc<Mechanism>,
    model: &Path,
    opts: &SimulationOptions,
    static_first: bool,
    mut observer: impl FnMut(f64) -> Control,
) -> Result<(Response, String), Failure> {
    if opts.integrator == Integrator::GeneralizedAlpha {
        return Err(Failure::Input(
            "a reduced model is integrated with an explicit integrator (--integrator dopri5 or \
             adams): its point is large explicit steps (thesis chapters 5–6); genalpha is for \
             stiff unreduced models"
                .into(),
        ));
    }
    let (saved, mut red) = load_model(mech, model)?;
    let compute = |e: flexmb_reduction::ReductionError| Failure::Compute(e.to_string());
    let z0 = if static_first {
        let z = red
            .equilibria_over_load_scale(0.0, &[1.0], &mut |_| {})
            .map_err(|e| Failure::Compute(format!("reduced static equilibrium: {e}")))?;
        z.into_iter()
            .next()
            .map_or_else(|| red.basis().z_reference(), |e| e.z)
    } else {
        red.basis().z_reference()
    };
    red.set_load_scale(1.0);
    if matches!(saved.basis, SavedBasis::Interpolated { .. }) {
        say!(
            "initial s = {:.6e} ({})",
            z0[0],
            if static_first {
                "static equilibrium"
            } else {
                "the knot nearest to the scene's reference configuration"
            }
        );
    }
    let nz = red.n_z();
    let (q0, _) = red.full_state(&z0, &vec![0.0; nz]);
    // the model's own dynamics: its position solve continues from the
    // equilibrium it found (a fresh one would start at the reference)
    let qd0 = red
        .dynamics_mut()
        .initial_qd(0.0, &q0)
        .map_err(|e| Failure::Compute(e.to_string()))?;
    let zd0 = red.project_velocities(0.0, &z0, &qd0).map_err(compute)?;
    let phase = crate::interrupt::stoppable();
    let traj = red.simulate(0.0, &z0, &zd0, opts, |t, _, _| observer(t));
    phase.finish();
    let traj = traj.map_err(compute)?;
    let (q, qd) = traj
        .z
        .iter()
        .zip(&traj.zd)
        .map(|(z, zd)| red.full_state(z, zd))
        .unzip();
    Ok((
        Response {
            t: traj.t,
            q,
            qd,
            x: traj.x,
            stats: traj.stats,
            wall_time: traj.wall_time,
            stopped: traj.stopped,
            chart_switches: vec![],
        },
        saved.description,
    ))
}

/// The reduced model's eigenfrequencies (F.7) at its static equilibria along
/// the load scales `values` (continuation from load scale 0), written like
/// the unreduced sweep.
pub(crate) fn sweep(a: &SweepArgs, model: &Path, values: &[f64]) -> Result<(), Failure> {
    if a.over != "load" {
        return Err(Failure::Input(format!(
            "--reduced sweeps over `load` only (got --over {}): the reduced equilibria keep all \
             reduced coordinates free; sweep a coordinate with the unreduced model",
            a.over
        )));
    }
    let (_, mech) = crate::load(&a.scene)?;
    let (_, mut red) = load_model(&mech, model)?;
    crate::options::writable_dir("--out", &a.out)?;
    let n = values.len();
    let asked = a.modes.unwrap_or(6);
    let k = asked.min(red.n_z());
    if k < asked {
        say!(
            "the reduced model has {} coordinates: {k} eigenfrequencies per configuration",
            red.n_z()
        );
    }
    let pb = count_bar(2 * n as u64, "reduced equilibria, then eigen analyses");
    let start = std::time::Instant::now();
    let result = (|| {
        let zs = red
            .equilibria_over_load_scale(a.t_load, values, &mut |d| pb.set_position(d as u64))
            .map_err(|e| Failure::Compute(format!("reduced sweep: {e}")))?;
        let mut freqs = Vec::with_capacity(n);
        // the equilibria have no partial result; the frequencies do
        let _phase = crate::interrupt::stoppable();
        for (i, (l, eq)) in values.iter().zip(&zs).enumerate() {
            if crate::interrupt::requested() {
                break;
            }
            red.set_load_scale(*l);
            // the position solve starts at this equilibrium's configuration
            red.dynamics_mut().kinematics_mut().set_guess(&eq.x);
            let f = red.frequencies_at_rest(a.t_load, &eq.z).map_err(|e| {
                Failure::Compute(format!("reduced eigenfrequencies at load scale {l}: {e}"))
            })?;
            freqs.push(f.into_iter().take(k).collect::<Vec<f64>>());
            pb.set_position((n + i + 1) as u64);
        }
        Ok(freqs)
    })();
    pb.finish_and_clear();
    let freqs = result?;
    let done = freqs.len();
    if done == 0 {
        return Err(Failure::Interrupted(
            "nothing written: stopped before the first eigen analysis".into(),
        ));
    }
    say!(
        "{done} configurations, {k} modes each, in {:.2} s",
        start.elapsed().as_secs_f64()
    );
    let sw = FrequencySweep {
        title: &mech.name,
        parameter: "load_scale".into(),
        s: values[..done].to_vec(),
        frequencies: freqs,
        modes: k,
        holding: (vec![], vec![]),
    };
    let mut comments = vec![
        crate::sweep_command_line(a),
        "undamped eigenfrequencies of the reduced model at its static equilibria (rest linearization (F.7)), continuation from load scale 0".into(),
    ];
    if done < n {
        comments.push(format!("interrupted: {done} of {n} configurations"));
    }
    write_frequency_sweep(&sw, &comments, &a.out)?;
    if done < n {
        return Err(Failure::Interrupted(format!(
            "partial results written: {done} of {n} configurations"
        )));
    }
    Ok(())
}
