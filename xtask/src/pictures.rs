//! Pictures of the mechanisms in the reports (issue 23): `flexmb_draw`
//! pictures saved as SVG and PNG next to the other figures.

use crate::report::Figures;
use flexmb_draw::{picture, Configuration, DrawOptions};
use std::io;
use std::path::Path;

fn io_err(e: flexmb_draw::DrawError) -> io::Error {
    io::Error::other(e.to_string())
}

/// Saves the picture of `at` drawn with `opts` as `out/stem.svg` and
/// `.png`; returns the mode's frequency (Hz) if one is drawn.
pub fn save(
    figs: &mut Figures,
    out: &Path,
    stem: &str,
    at: &Configuration,
    opts: &DrawOptions,
) -> io::Result<Option<f64>> {
    let pic = picture(at, opts).map_err(io_err)?;
    figs.save(&pic.plot(), out, stem)?;
    Ok(pic.mode.as_ref().map(|(m, _)| m.frequency_hz))
}

/// The static equilibrium of `mech` under its loads at `t` scaled by
/// `load_scale` (in four increments) and gravity.
pub fn equilibrium(
    mech: &std::sync::Arc<flexmb_model::Mechanism>,
    t: f64,
    load_scale: f64,
) -> io::Result<Configuration> {
    Configuration::loaded(mech, t, load_scale, 4).map_err(io_err)
}

/// A straight guidance (chapters 5 and 6) in its default view: at its
/// maximal deflection (load scale `lambda_max` at `t`) with the reference
/// configuration overlaid, titled `title` (thesis Fig. 6.5), and modes
/// 1..=`modes` at x = 0 and at x max (two phases, ±10 % of its size).
/// Returns the frequencies drawn, (x = 0, x max) per mode.
pub fn guidance(
    figs: &mut Figures,
    out: &Path,
    mech: &std::sync::Arc<flexmb_model::Mechanism>,
    (t, lambda_max): (f64, f64),
    title: &str,
    modes: usize,
) -> io::Result<Vec<(f64, f64)>> {
    let rest = equilibrium(mech, t, 0.0)?;
    let max = equilibrium(mech, t, lambda_max)?;
    save(
        figs,
        out,
        "mech_max_deflection",
        &max,
        &DrawOptions {
            reference: true,
            title: Some(title.into()),
            ..Default::default()
        },
    )?;
    let at_x = [
        (&rest, "x0", "Guidance at x = 0".to_string()),
        (&max, "xmax", "Guidance at x max".to_string()),
    ];
    let modes: Vec<usize> = (1..=modes).collect();
    let f = mode_pictures(figs, out, &modes, &at_x)?;
    Ok((0..modes.len()).map(|k| (f[0][k], f[1][k])).collect())
}

/// Draws modes `modes` at each configuration of `ats` (configuration, file
/// tag, title) as `mech_mode{k}_{tag}`, mode by mode (each mode's pictures
/// side by side in a report): two phases at ±10 % of the mechanism's size.
/// Returns the frequencies drawn (Hz), per configuration and mode.
pub fn mode_pictures(
    figs: &mut Figures,
    out: &Path,
    modes: &[usize],
    ats: &[(&Configuration, &str, String)],
) -> io::Result<Vec<Vec<f64>>> {
    let mut f = vec![vec![f64::NAN; modes.len()]; ats.len()];
    for (j, &k) in modes.iter().enumerate() {
        for (i, (at, tag, title)) in ats.iter().enumerate() {
            let opts = DrawOptions {
                mode: Some(k),
                phases: Some(2),
                title: Some(title.clone()),
                ..Default::default()
            };
            if let Some(hz) = save(figs, out, &format!("mech_mode{k}_{tag}"), at, &opts)? {
                f[i][j] = hz;
            }
        }
    }
    Ok(f)
}

/// The report section of the pictures of [`guidance`]: what they show, the
/// frequencies drawn, and the figures.
pub fn section(figs: &Figures, lambda_max: f64, freqs: &[(f64, f64)]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "## The mechanism and its modes\n");
    let _ = writeln!(s, "Drawn by `flexmb_draw` (as `flexmb draw`): the unreduced model at its static equilibrium under the static x-force at S (and gravity, if the scene has it), at x = 0 (λ = 0) and at x max (λ = {lambda_max:.4}); the modes of its rest linearization there, each at ±10 % of the guidance's size (the lighter line is −). Their frequencies are those of the curves' end points.\n");
    let mut t = crate::report::Table::new(&["mode", "frequency at x = 0 (Hz)", "at x max (Hz)"]);
    for (k, (f0, f1)) in freqs.iter().enumerate() {
        t.row(vec![
            (k + 1).to_string(),
            crate::report::sig(*f0),
            crate::report::sig(*f1),
        ]);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "{}", figs.markdown(|f| f.starts_with("mech_")));
    s
}
