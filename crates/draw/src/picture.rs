//! A picture: layers of [`Geometry`] (the reference configuration, the
//! drawn configuration, the phases of a mode shape) turned into a
//! [`flexmb_plot::Plot`] with equal axis scales, and written as SVG or PNG.

use crate::geometry::{styled_geometry, Geometry, ItemKind, Style};
use crate::mode::{mode_shape, Configuration, ModeShape};
use crate::{DrawError, View};
use flexmb_plot::{Marker, Plot, Series};
use std::path::Path;

/// What to draw of a configuration.
#[derive(Clone, Debug, Default)]
pub struct DrawOptions {
    /// The projection [default: [`View::default_for`] the mechanism].
    pub view: Option<View>,
    /// Overlay the reference configuration in a light colour.
    pub reference: bool,
    /// Draw this mode shape (from 1) of the linearization at the
    /// configuration.
    pub mode: Option<usize>,
    /// The mode's largest nodal displacement (m) [default: 10 % of the
    /// mechanism's size, [`Geometry::size`]].
    pub amplitude: Option<f64>,
    /// Phases of the mode drawn, from +amplitude to −amplitude in equal
    /// steps [default: 1, +amplitude only].
    pub phases: Option<usize>,
    /// The title [default: the mechanism's name]; a mode's number,
    /// frequency and amplitude follow it.
    pub title: Option<String>,
    /// Beams as thin boxes and superelements as their FE outline (the
    /// default), or as lines and chords.
    pub style: Style,
}

/// One layer of a picture: a configuration's items, drawn in one colour
/// (or each kind in its own when `color` is `None`).
#[derive(Clone, Debug)]
pub struct Layer {
    /// Its legend label (empty: each kind's label, or none).
    pub label: String,
    /// Its colour for segments; `None`: each kind's colour.
    pub color: Option<(u8, u8, u8)>,
    /// Whether its markers (hinges, masses, nodes) are drawn.
    pub markers: bool,
    /// Its items.
    pub geometry: Geometry,
}

/// A mechanism picture: layers drawn in order, later over earlier.
#[derive(Clone, Debug)]
pub struct Picture {
    /// The title.
    pub title: String,
    /// The projection.
    pub view: View,
    /// The layers.
    pub layers: Vec<Layer>,
    /// The mode drawn, if any, and the eigenvector scale used (nodal
    /// displacement = scale × [`ModeShape::x`]).
    pub mode: Option<(ModeShape, f64)>,
}

/// The light grey of the reference configuration.
pub const REFERENCE_COLOR: (u8, u8, u8) = (0xc8, 0xc8, 0xc8);
/// The grey of the configuration a mode is drawn about.
pub const REST_COLOR: (u8, u8, u8) = (0x99, 0x99, 0x99);
/// The colour of a mode's first phase (later phases fade towards white).
pub const MODE_COLOR: (u8, u8, u8) = (0x00, 0x72, 0xb2);

/// The colour and marker of each kind of item.
fn kind_style(k: ItemKind) -> ((u8, u8, u8), Marker) {
    match k {
        ItemKind::Beam => ((0x00, 0x72, 0xb2), Marker::Circle),
        ItemKind::Truss => ((0x00, 0x9e, 0x73), Marker::Circle),
        ItemKind::SuperelementChord | ItemKind::SuperelementOutline => {
            ((0xd5, 0x5e, 0x00), Marker::Circle)
        }
        ItemKind::InterfaceNode => ((0xd5, 0x5e, 0x00), Marker::Square),
        ItemKind::Hinge => ((0xcc, 0x79, 0xa7), Marker::Circle),
        ItemKind::PointMass => ((0x56, 0xb4, 0xe9), Marker::Square),
        ItemKind::RigidBody => ((0xe6, 0x9f, 0x00), Marker::Diamond),
        ItemKind::FixedNode => ((0x33, 0x33, 0x33), Marker::TriangleUp),
        ItemKind::Other => ((0x8c, 0x56, 0x4b), Marker::Circle),
    }
}

/// `c` mixed with white: `f` = 0 keeps it, 1 gives white.
fn fade(c: (u8, u8, u8), f: f64) -> (u8, u8, u8) {
    let m = |v: u8| (v as f64 + (255.0 - v as f64) * f).round() as u8;
    (m(c.0), m(c.1), m(c.2))
}

/// The factors of the amplitude of `n` phases: +1 down to −1 in equal
/// steps (+1 alone for one phase).
pub fn phase_factors(n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![1.0];
    }
    (0..n)
        .map(|j| 1.0 - 2.0 * j as f64 / (n - 1) as f64)
        .collect()
}

/// The picture of the configuration `at` (see [`DrawOptions`]).
pub fn picture(at: &Configuration, opts: &DrawOptions) -> Result<Picture, DrawError> {
    let mech = &at.mechanism;
    let view = opts.view.unwrap_or(View::default_for(mech.dimension));
    if let Some(a) = opts.amplitude {
        if !(a > 0.0 && a.is_finite()) {
            return Err(DrawError::Input(format!(
                "the amplitude must be positive and finite; got {a}"
            )));
        }
    }
    if opts.phases == Some(0) {
        return Err(DrawError::Input(
            "the number of phases must be at least 1".into(),
        ));
    }
    let mut layers = vec![];
    if opts.reference {
        layers.push(Layer {
            label: "reference configuration".into(),
            color: Some(REFERENCE_COLOR),
            markers: false,
            geometry: styled_geometry(mech, &mech.x0, view, opts.style),
        });
    }
    let here = styled_geometry(mech, &at.x, view, opts.style);
    let Some(k) = opts.mode else {
        layers.push(Layer {
            label: String::new(),
            color: None,
            markers: true,
            geometry: here,
        });
        let title = opts.title.clone().unwrap_or_else(|| mech.name.clone());
        return Ok(Picture {
            title,
            view,
            layers,
            mode: None,
        });
    };
    let shape = mode_shape(at, k)?;
    let amplitude = opts.amplitude.unwrap_or(0.1 * here.size());
    let scale = shape.scale_for(mech, amplitude);
    let size = here.size();
    layers.push(Layer {
        label: "at rest".into(),
        color: Some(REST_COLOR),
        markers: false,
        geometry: here,
    });
    let factors = phase_factors(opts.phases.unwrap_or(1));
    let n = factors.len();
    for (j, f) in factors.iter().enumerate() {
        let x: Vec<f64> =
            at.x.iter()
                .zip(&shape.x)
                .map(|(x, d)| x + f * scale * d)
                .collect();
        let fading = if n > 1 {
            0.6 * j as f64 / (n - 1) as f64
        } else {
            0.0
        };
        layers.push(Layer {
            label: format!("mode {k}, {:+.2} × amplitude", f),
            color: Some(fade(MODE_COLOR, fading)),
            markers: j == 0,
            geometry: styled_geometry(mech, &x, view, opts.style),
        });
    }
    let title = format!(
        "{}: mode {k}, {} Hz (amplitude {:.3} m, {:.0} % of the size)",
        opts.title.as_deref().unwrap_or(&mech.name),
        significant(shape.frequency_hz),
        amplitude,
        100.0 * amplitude / size.max(f64::MIN_POSITIVE)
    );
    Ok(Picture {
        title,
        view,
        layers,
        mode: Some((shape, scale)),
    })
}

/// `v` with four significant digits.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let dec = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.dec$}")
}

/// The x and y series of the items of `kind` in `g`, segments separated by
/// a gap (NaN, which the plot does not draw).
fn polyline_of(g: &Geometry, kind: ItemKind) -> (Vec<f64>, Vec<f64>) {
    let (mut xs, mut ys) = (vec![], vec![]);
    for it in g.items.iter().filter(|i| i.kind == kind) {
        if !xs.is_empty() && !kind.is_marker() {
            xs.push(f64::NAN);
            ys.push(f64::NAN);
        }
        for p in &it.projected {
            xs.push(p[0]);
            ys.push(p[1]);
        }
    }
    (xs, ys)
}

const KINDS: [ItemKind; 10] = [
    ItemKind::Beam,
    ItemKind::Truss,
    ItemKind::Other,
    ItemKind::SuperelementChord,
    ItemKind::SuperelementOutline,
    ItemKind::InterfaceNode,
    ItemKind::Hinge,
    ItemKind::PointMass,
    ItemKind::RigidBody,
    ItemKind::FixedNode,
];

impl Picture {
    /// The plot that draws the picture: equal scales on both axes, one
    /// series per layer and kind of item.
    pub fn plot(&self) -> Plot {
        let (xl, yl) = self.view.axis_labels();
        let mut plot = Plot::new(&self.title, xl, yl).equal_aspect().size(900, 650);
        for layer in &self.layers {
            let mut labelled = layer.label.is_empty();
            for kind in KINDS {
                if kind.is_marker() && !layer.markers {
                    continue;
                }
                let (x, y) = polyline_of(&layer.geometry, kind);
                if x.is_empty() {
                    continue;
                }
                let (kc, m) = kind_style(kind);
                let label = if !labelled {
                    labelled = true;
                    layer.label.clone()
                } else if layer.color.is_none() || kind.is_marker() {
                    kind.label().to_string()
                } else {
                    String::new()
                };
                let color = match layer.color {
                    Some(c) if !kind.is_marker() => c,
                    _ => kc,
                };
                let s = if kind.is_marker() {
                    Series::points(&label, &x, &y).with_marker(m)
                } else if kind == ItemKind::SuperelementChord {
                    Series::dashed(&label, &x, &y)
                } else {
                    Series::line(&label, &x, &y)
                };
                plot.push(s.with_color(color));
            }
        }
        plot
    }

    /// Writes the picture as SVG or PNG, by the extension of `path`.
    pub fn save(&self, path: &Path) -> Result<(), DrawError> {
        figure_format(path)?;
        self.plot()
            .save(path)
            .map_err(|e| DrawError::Write(format!("cannot write {}: {e}", path.display())))
    }
}

/// A figure's file format by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// .svg
    Svg,
    /// .png
    Png,
}

/// The format of the figure file `path`: an input error for any extension
/// but .svg and .png.
pub fn figure_format(path: &Path) -> Result<Format, DrawError> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("svg") => Ok(Format::Svg),
        Some(e) if e.eq_ignore_ascii_case("png") => Ok(Format::Png),
        _ => Err(DrawError::Input(format!(
            "{}: unknown figure format (the file name must end in .svg or .png)",
            path.display()
        ))),
    }
}
