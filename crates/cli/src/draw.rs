//! `flexmb draw`: a picture of the mechanism (reference, static equilibrium
//! or a given state) and its mode shapes, by the library crate
//! `flexmb-draw`.

use crate::{coords, load, options, Failure};
use clap::Args;
use flexmb_draw::{Configuration, DrawError, DrawOptions, View};
use flexmb_dynamics::{Dynamics, OutputTable};
use flexmb_model::Mechanism;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Options of `flexmb draw`.
#[derive(Args)]
pub(crate) struct DrawArgs {
    /// Scene file (RON).
    scene: PathBuf,
    /// Draw this state: a CSV file whose columns are degrees of freedom
    /// (named as `flexmb info` prints them, or `q:NAME` as `simulate`
    /// writes them with `Dofs` among the scene's outputs), the scene's other
    /// output columns (passed over) and optionally `t`; its last row is
    /// drawn, degrees of freedom it does not list keep their reference values.
    #[arg(long, value_name = "FILE.csv", conflicts_with = "static_first")]
    state: Option<PathBuf>,
    /// Draw the static equilibrium under the scene's loads and gravity at t = 0.
    #[arg(long)]
    static_first: bool,
    /// Draw mode shape K (from 1, lowest frequency) of the linearization at
    /// the drawn configuration.
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    mode: Option<usize>,
    /// The mode's largest nodal displacement (m) [default: 10 % of the
    /// mechanism's size].
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    amplitude: Option<f64>,
    /// Phases of the mode drawn, from +A to −A in equal steps, fading [default: 1].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    phases: Option<usize>,
    /// Overlay the reference configuration in light grey.
    #[arg(long)]
    reference: bool,
    /// Draw beams as lines between their nodes and superelements as their
    /// chord, not as thin boxes of their section and the outline of their
    /// FE mesh.
    #[arg(long)]
    lines: bool,
    /// iso, xy, xz or yz [default: xy for planar scenes, iso for spatial].
    #[arg(long)]
    view: Option<String>,
    /// The figure: FIG.svg or FIG.png.
    #[arg(long, value_name = "FIG.svg|FIG.png")]
    out: PathBuf,
}

fn failure(e: DrawError) -> Failure {
    match e {
        DrawError::Input(m) => Failure::Input(m),
        DrawError::Compute(m) | DrawError::Write(m) => Failure::Compute(m),
    }
}

/// `flexmb draw`.
pub(crate) fn draw(a: &DrawArgs) -> Result<(), Failure> {
    let view = a
        .view
        .as_deref()
        .map(|v| {
            v.parse::<View>()
                .map_err(|e| Failure::Input(format!("--view: {e}")))
        })
        .transpose()?;
    if let Some(k) = a.mode {
        options::at_least("--mode", k, 1, "modes are numbered from 1")?;
    }
    if let Some(amp) = a.amplitude {
        options::positive("--amplitude", amp)?;
    }
    if let Some(n) = a.phases {
        options::at_least("--phases", n, 1, "the phases of the mode drawn")?;
    }
    flexmb_draw::figure_format(&a.out).map_err(|e| Failure::Input(format!("--out {e}")))?;
    options::writable_file("--out", &a.out)?;
    let (_, mech) = load(&a.scene)?;
    if let Some(k) = a.mode {
        flexmb_draw::check_mode(&mech, k).map_err(|e| Failure::Input(format!("--mode {e}")))?;
    }
    let at = if a.static_first {
        Configuration::static_equilibrium(&mech)
    } else if let Some(file) = &a.state {
        Configuration::at(&mech, &read_state(&mech, file)?)
    } else {
        Configuration::reference(&mech)
    }
    .map_err(failure)?;
    let opts = DrawOptions {
        view,
        reference: a.reference,
        mode: a.mode,
        amplitude: a.amplitude,
        phases: a.phases,
        title: None,
        style: if a.lines {
            flexmb_draw::Style::Lines
        } else {
            flexmb_draw::Style::Outline
        },
    };
    let pic = flexmb_draw::picture(&at, &opts).map_err(failure)?;
    pic.save(&a.out).map_err(failure)?;
    if let Some((m, _)) = &pic.mode {
        crate::say!("mode {}: {:.6} Hz", m.number, m.frequency_hz);
    }
    crate::say!("wrote {}", a.out.display());
    Ok(())
}

/// The degrees of freedom of the state file `file` (see [`DrawArgs`]): its
/// DOF columns (`NAME` or `q:NAME`). Columns that `simulate` writes for the
/// scene's other `outputs` (positions, energies, …) are passed over; they
/// do not fix a configuration. Any other column is an error, and so is a
/// file without a DOF column (it would draw the reference silently).
fn read_state(mech: &Arc<Mechanism>, file: &Path) -> Result<Vec<f64>, Failure> {
    let bad = |m: String| Failure::Input(format!("--state {}: {m}", file.display()));
    let (header, rows) = flexmb_plot::read_csv(file).map_err(|e| bad(e.to_string()))?;
    let last = rows
        .last()
        .ok_or_else(|| bad("no row of values after the header".into()))?;
    if last.len() != header.len() {
        return Err(bad(format!(
            "the last row has {} values for the {} columns {header:?}",
            last.len(),
            header.len()
        )));
    }
    let outputs = OutputTable::new(&Dynamics::new(mech.clone()))
        .map_err(|e| bad(e.to_string()))?
        .header;
    let mut q = mech.q0();
    let mut dofs_read = 0;
    let mut passed_over = vec![];
    for (name, v) in header.iter().zip(last) {
        if name == "t" {
            continue;
        }
        let dof = name.strip_prefix("q:").unwrap_or(name);
        let is_dof = mech.dofs.iter().any(|c| mech.coordinate_name(*c) == dof);
        if !is_dof && outputs.iter().any(|o| o == name) {
            passed_over.push(name.as_str());
            continue;
        }
        let k = coords::dof_index(mech, dof, &format!("--state {}:", file.display()))?;
        if !v.is_finite() {
            return Err(bad(format!("{name} is {v}")));
        }
        q[k] = *v;
        dofs_read += 1;
    }
    if dofs_read == 0 {
        if passed_over.is_empty() {
            return Err(bad(
                "no degree-of-freedom column (`flexmb info SCENE` lists them)".into(),
            ));
        }
        // an output column that is a coordinate of the scene (`S.x`): also
        // say how to make it a degree of freedom
        let as_dof = passed_over
            .iter()
            .find(|name| matches!(coords::selection(mech, name), Ok(Some(_))))
            .and_then(|name| coords::dof_index(mech, name, "").err())
            .map(|e| match e {
                Failure::Input(m) | Failure::Compute(m) | Failure::Interrupted(m) => {
                    format!(";{m}")
                }
            })
            .unwrap_or_default();
        return Err(bad(format!(
            "no degree-of-freedom column, only the scene's outputs {passed_over:?}, which do not \
             fix a configuration: add `Dofs` to the scene's `outputs` and run `simulate` again{as_dof}"
        )));
    }
    Ok(q)
}
