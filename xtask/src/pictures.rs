//! Pictures of the mechanisms in the reports (issue 23): `flexmb_draw`
//! pictures saved as SVG and PNG next to the other figures.

use crate::report::Figures;
use flexmb_draw::{picture, Configuration, DrawOptions, View};
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

/// The spatial guidance of chapter 6: at its maximum deflection with the
/// reference configuration overlaid (thesis Fig. 6.5), and modes 1–4 at
/// x = 0 and at x max (two phases, ±10 % of its size), all isometric.
/// Returns the frequencies drawn, (x = 0, x max) per mode.
pub fn ch6(
    figs: &mut Figures,
    out: &Path,
    setup: &crate::ch6::Setup,
) -> io::Result<Vec<(f64, f64)>> {
    let rest = equilibrium(&setup.def, crate::ch6::T_LOAD, 0.0)?;
    let max = equilibrium(&setup.def, crate::ch6::T_LOAD, setup.lambda_max)?;
    let iso = Some(View::Iso);
    save(
        figs,
        out,
        "mech_fig6_5_max_deflection",
        &max,
        &DrawOptions {
            view: iso,
            reference: true,
            title: Some(
                "Fig. 6.5: the guidance at its maximal deflection (grey: reference)".into(),
            ),
            ..Default::default()
        },
    )?;
    let mut freqs = vec![];
    for k in 1..=4 {
        let mut f = [0.0; 2];
        let at_x = [(&rest, "x0", "x = 0"), (&max, "xmax", "x max")];
        for (j, (at, tag, name)) in at_x.into_iter().enumerate() {
            f[j] = save(
                figs,
                out,
                &format!("mech_mode{k}_{tag}"),
                at,
                &DrawOptions {
                    view: iso,
                    mode: Some(k),
                    phases: Some(2),
                    title: Some(format!("Guidance at {name}")),
                    ..Default::default()
                },
            )?
            .unwrap_or(f64::NAN);
        }
        freqs.push((f[0], f[1]));
    }
    Ok(freqs)
}
