//! `flexmb simulate --reduced` and `flexmb sweep --reduced`: a reduced model
//! saved by `flexmb reduce`, applied to a scene with the same degrees of
//! freedom.

use crate::out::say;
use crate::report::{count_bar, write_frequency_sweep, FrequencySweep};
use crate::{Failure, SweepArgs};
use flexmb_dynamics::{Control, Integrator, SimulationOptions};
use flexmb_model::Mechanism;
use flexmb_reduction::{MechanicalModel, ReducedModel, SavedModel};
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

/// The reduced model `model` of `mech` to simulate, its description, and
/// how many configuration coordinates its basis has (0 fixed, 1
/// interpolated, 2 grid); explicit integrators only.
pub(crate) fn model_to_simulate(
    mech: &Arc<Mechanism>,
    model: &Path,
    opts: &SimulationOptions,
) -> Result<(Box<dyn MechanicalModel>, String, usize), Failure> {
    if opts.integrator == Integrator::GeneralizedAlpha {
        return Err(Failure::Input(
            "a reduced model is integrated with an explicit integrator (--integrator dopri5 or \
             adams): its point is large explicit steps (thesis chapters 5–6); genalpha is for \
             stiff unreduced models"
                .into(),
        ));
    }
    let (saved, red) = load_model(mech, model)?;
    let configuration = saved.basis.configuration_coordinates();
    Ok((Box::new(red), saved.description, configuration))
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
    if let Some(d) = &a.vtk {
        crate::options::writable_dir("--vtk", d)?;
    }
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
    // the equilibria have no partial result; the frequencies do
    let mut phase = None;
    let sweep = red.frequency_sweep(a.t_load, values, k, &mut |d| {
        pb.set_position(d as u64);
        if d < n {
            return Control::Continue;
        }
        phase.get_or_insert_with(crate::interrupt::stoppable);
        if crate::interrupt::requested() {
            Control::Stop
        } else {
            Control::Continue
        }
    });
    drop(phase);
    pb.finish_and_clear();
    let points = sweep.map_err(|e| Failure::Compute(format!("reduced sweep: {e}")))?;
    let freqs: Vec<Vec<f64>> = points.iter().map(|p| p.frequencies.clone()).collect();
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
    if let Some(d) = &a.vtk {
        crate::vtk_out::write_reduced_sweep(
            crate::vtk_out::VtkOut::new(d, a.vtk_style),
            &mut red,
            a.t_load,
            k,
            &points,
        )?;
    }
    if done < n {
        return Err(Failure::Interrupted(format!(
            "partial results written: {done} of {n} configurations"
        )));
    }
    Ok(())
}
