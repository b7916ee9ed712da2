//! The one style of every flexmb figure: colours, markers, line widths,
//! font sizes, and the bundled font (DejaVu Sans, Bitstream Vera licence,
//! `fonts/DejaVuSans-LICENSE.txt`) that both backends measure and draw with.

use plotters::style::{register_font, FontStyle, IntoFont};
use std::io;
use std::sync::OnceLock;

/// Series colours, in order (the Okabe–Ito set, then a few more; all dark
/// enough on white).
pub(crate) const COLORS: [(u8, u8, u8); 10] = [
    (0x00, 0x72, 0xb2),
    (0xd5, 0x5e, 0x00),
    (0x00, 0x9e, 0x73),
    (0xcc, 0x79, 0xa7),
    (0xe6, 0x9f, 0x00),
    (0x56, 0xb4, 0xe9),
    (0x33, 0x33, 0x33),
    (0x8c, 0x56, 0x4b),
    (0x7f, 0x7f, 0x7f),
    (0xbc, 0xbd, 0x22),
];

/// Marker shapes, in order, so that series differ in shape as well as colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// A filled circle.
    Circle,
    /// A filled square.
    Square,
    /// A filled triangle, apex up.
    TriangleUp,
    /// A filled diamond.
    Diamond,
    /// A filled triangle, apex down.
    TriangleDown,
}

pub(crate) const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
];

/// Sizes at scale 1 (pixels; font sizes in plotters' units).
pub(crate) const MARKER_R: f64 = 5.5;
/// Half the largest extent of any marker shape, in units of `MARKER_R`.
pub(crate) const MARKER_EXTENT: f64 = 1.25;
pub(crate) const LINE_W: f64 = 2.0;
pub(crate) const DASH: (f64, f64) = (9.0, 5.0);
pub(crate) const FONT_TITLE: f64 = 22.0;
pub(crate) const FONT_LABEL: f64 = 18.0;
pub(crate) const FONT_TICK: f64 = 16.0;
pub(crate) const FONT_LEGEND: f64 = 16.0;
pub(crate) const FONT_POINT: f64 = 15.0;

/// The family name the font is registered under (and written into SVG).
pub(crate) const FAMILY: &str = "sans-serif";

static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

/// Registers the bundled font with plotters (once).
pub(crate) fn ensure_font() -> io::Result<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    if ok {
        Ok(())
    } else {
        Err(io::Error::other(
            "flexmb-plot: the bundled font fonts/DejaVuSans.ttf could not be read",
        ))
    }
}

/// Width and height in pixels of `text` at font `size`, as both backends
/// lay it out (the bundled font's advances and kerning).
pub(crate) fn text_size(text: &str, size: f64) -> io::Result<(f64, f64)> {
    ensure_font()?;
    let (w, _) = (FAMILY, size)
        .into_font()
        .box_size(text)
        .map_err(|e| io::Error::other(format!("flexmb-plot: measuring {text:?}: {e}")))?;
    Ok((w as f64, size))
}
