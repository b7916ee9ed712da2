//! The pictures of the chapter-3 report (issue 23): the short sheet flexure
//! modelled with SE-CW, drawn by `flexmb_draw` with its superelements as the
//! outline of their FE mesh and the link as boxes of its section, at rest
//! and deflected by ∓0.4 N m, and its modes 2 and 4 at rest and at both full
//! moments (the thesis's mode 4 changes from torsion to bending with the
//! sign of ϕ, §3.5.1).

use crate::ch3::{self, Kind};
use crate::pictures::{equilibrium, mode_pictures};
use crate::report::{sig, Figures, Table};
use flexmb_draw::{styled_geometry, Configuration, Layer, Picture, Style, View, REFERENCE_COLOR};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

/// The modes drawn.
pub const MODES: [usize; 2] = [2, 4];
/// The moments drawn (N m): at rest and the two full moments.
pub const MOMENTS: [f64; 3] = [0.0, -ch3::M_MAX, ch3::M_MAX];

/// The frequencies (Hz) of the modes drawn: one row per moment of
/// [`MOMENTS`], one column per mode of [`MODES`], with the end's rotation ϕ
/// (degrees) first.
pub type Drawn = Vec<(f64, f64, Vec<f64>)>;

fn io(e: std::io::Error) -> String {
    e.to_string()
}

/// The end's rotation about y (degrees) at a configuration.
fn end_rotation(at: &Configuration) -> f64 {
    let o = at
        .mechanism
        .node(&format!("N{}", ch3::SEGMENTS))
        .and_then(|n| n.orientation.clone())
        .expect("the flexure's end turns");
    (2.0 * at.x[o[2]].atan2(at.x[o[0]])).to_degrees()
}

/// Draws SE-CW (superelement file `file` in `dir`) into `out`: the
/// mechanism at rest and at ∓0.4 N m in one picture (`mech_deflected`), the
/// flexure alone likewise (`mech_flexure`), and modes 2 and 4 at each
/// moment (`mech_mode{k}_{tag}`, two phases at ±10 % of the mechanism's
/// size). Returns what was drawn.
pub fn draw(dir: &Path, file: &str, out: &Path, figs: &mut Figures) -> Result<Drawn, String> {
    let scene = flexmb_model::Scene::from_ron_str(&ch3::scene(Kind::SeCw, file))
        .map_err(|e| e.to_string())?;
    let mech = Arc::new(scene.build(Some(dir)).map_err(|e| e.to_string())?);
    let ats: Vec<Configuration> = MOMENTS
        .iter()
        .map(|m| equilibrium(&mech, 0.0, m / ch3::M_MAX).map_err(io))
        .collect::<Result<_, _>>()?;
    let view = View::Iso;
    let colors = [(0x00, 0x72, 0xb2), (0xd5, 0x5e, 0x00)];
    // the whole mechanism, then the flexure alone (its four superelements)
    for (stem, title, flexure_only) in [
        ("mech_deflected", "SE-CW at rest and at ∓0.4 N m", false),
        (
            "mech_flexure",
            "SE-CW: the flexure's FE outline at rest and at ∓0.4 N m",
            true,
        ),
    ] {
        let keep = |g: flexmb_draw::Geometry| {
            if !flexure_only {
                return g;
            }
            let items = g
                .items
                .into_iter()
                .filter(|i| (0..ch3::SEGMENTS).any(|k| i.id == format!("s{k}")) || i.id == "N0")
                .collect();
            flexmb_draw::Geometry { items, ..g }
        };
        let mut layers = vec![Layer {
            label: "at rest".into(),
            color: Some(REFERENCE_COLOR),
            markers: false,
            geometry: keep(styled_geometry(&mech, &ats[0].x, view, Style::Outline)),
        }];
        for (j, at) in ats[1..].iter().enumerate() {
            layers.push(Layer {
                label: format!(
                    "M = {:+.1} N m (ϕ = {:+.1}°)",
                    MOMENTS[j + 1],
                    end_rotation(at)
                ),
                color: Some(colors[j]),
                markers: j == 0,
                geometry: keep(styled_geometry(&mech, &at.x, view, Style::Outline)),
            });
        }
        let pic = Picture {
            title: title.into(),
            view,
            layers,
            mode: None,
        };
        figs.save(&pic.plot(), out, stem).map_err(io)?;
    }
    let tags = ["rest", "neg", "pos"];
    let titled: Vec<(&Configuration, &str, String)> = MOMENTS
        .iter()
        .zip(&ats)
        .zip(tags)
        .map(|((m, at), tag)| {
            let title = format!("SE-CW at M = {m:+.1} N m (ϕ = {:+.1}°)", end_rotation(at));
            (at, tag, title)
        })
        .collect();
    let f = mode_pictures(figs, out, &MODES, &titled).map_err(io)?;
    let drawn = MOMENTS
        .iter()
        .zip(&ats)
        .zip(f)
        .map(|((m, at), f)| (*m, end_rotation(at), f))
        .collect();
    Ok(drawn)
}

/// The report section of the pictures: what they show, the frequencies
/// drawn, and the figures.
pub fn section(figs: &Figures, drawn: &Drawn) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "### The flexure and its modes, drawn\n");
    let _ = writeln!(s, "Drawn by `flexmb_draw` (as `flexmb draw`): SE-CW at its static equilibrium under M = 0 and ∓{} N m, its four superelements as the outline of their FE mesh recovered from the superelement coordinates (the edges where the boundary faces of the quarter-flexure mesh turn by more than 30°, placed as the VTK output places the mesh), the rigid link as boxes of its 10 × 10 mm section (the whole mechanism, then the flexure alone); then modes 2 and 4 of the rest linearization at each moment, at ±10 % of the mechanism's size (the lighter line is −). The frequencies are those of the curves at these moments.\n", ch3::M_MAX);
    let mut header = vec!["M (N m)".to_string(), "ϕ (°)".into()];
    header.extend(MODES.iter().map(|k| format!("ω{k} (Hz)")));
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&hdr);
    for (m, phi, f) in drawn {
        let mut row = vec![format!("{m:+.1}"), format!("{phi:+.1}")];
        row.extend(f.iter().map(|v| sig(*v)));
        t.row(row);
    }
    let _ = writeln!(s, "{}", t.render());
    let _ = writeln!(s, "{}", figs.markdown(|f| f.starts_with("mech_")));
    s
}
