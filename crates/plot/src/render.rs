//! The one drawing routine, generic over plotters' backends, and the SVG
//! and PNG writers built on it.

use crate::layout::{Align, Layout, Text};
use crate::style::{self, Marker, COLORS, MARKERS};
use crate::{Plot, Style};
use plotters::coord::Shift;
use plotters::drawing::{DrawingArea, DrawingAreaErrorKind, IntoDrawingArea};
use plotters::element::{Circle, DashedPathElement, PathElement, Polygon, Rectangle};
use plotters::prelude::{BitMapBackend, DrawingBackend, SVGBackend};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{Color, FontTransform, IntoFont, RGBColor, ShapeStyle, TextStyle};
use std::io;
use std::path::{Path, PathBuf};

/// Scale of the PNG relative to the SVG (sharper text and lines).
pub const PNG_SCALE: f64 = 1.5;

type Res<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn px(p: (f64, f64)) -> (i32, i32) {
    (p.0.round() as i32, p.1.round() as i32)
}

/// The colour of series `k`: its own, or the palette's k-th.
fn series_color(plot: &Plot, k: usize) -> RGBColor {
    let (r, g, b) = plot.series[k].color.unwrap_or(COLORS[k % COLORS.len()]);
    RGBColor(r, g, b)
}

/// The marker of series `k`: its own, or the sequence's k-th.
fn series_marker(plot: &Plot, k: usize) -> Marker {
    plot.series[k].marker.unwrap_or(MARKERS[k % MARKERS.len()])
}

fn text<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, t: &Text, color: &RGBColor) -> Res<DB> {
    let h = match t.align {
        Align::Left => HPos::Left,
        Align::Center => HPos::Center,
        Align::Right => HPos::Right,
    };
    let mut st = TextStyle::from((style::FAMILY, t.size).into_font())
        .color(color)
        .pos(Pos::new(h, VPos::Center));
    if t.vertical {
        st = st.transform(FontTransform::Rotate270);
    }
    root.draw_text(&t.text, &st, px(t.at))
}

fn marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    m: Marker,
    (x, y): (f64, f64),
    r: f64,
    color: &RGBColor,
) -> Res<DB> {
    let fill = color.filled();
    let poly = |pts: &[(f64, f64)]| -> Vec<(i32, i32)> {
        pts.iter()
            .map(|(dx, dy)| px((x + dx * r, y + dy * r)))
            .collect()
    };
    match m {
        Marker::Circle => root.draw(&Circle::new(px((x, y)), r.round() as i32, fill)),
        Marker::Square => root.draw(&Rectangle::new(
            [
                px((x - 0.85 * r, y - 0.85 * r)),
                px((x + 0.85 * r, y + 0.85 * r)),
            ],
            fill,
        )),
        Marker::TriangleUp => root.draw(&Polygon::new(
            poly(&[(0.0, -1.2), (-1.1, 0.8), (1.1, 0.8)]),
            fill,
        )),
        Marker::TriangleDown => root.draw(&Polygon::new(
            poly(&[(0.0, 1.2), (-1.1, -0.8), (1.1, -0.8)]),
            fill,
        )),
        Marker::Diamond => root.draw(&Polygon::new(
            poly(&[(0.0, -1.25), (1.0, 0.0), (0.0, 1.25), (-1.0, 0.0)]),
            fill,
        )),
    }
}

fn polyline<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pts: Vec<(i32, i32)>,
    dashed: bool,
    st: ShapeStyle,
    s: f64,
) -> Res<DB> {
    if pts.len() < 2 {
        return Ok(());
    }
    if dashed {
        let (d, g) = style::DASH;
        root.draw(&DashedPathElement::new(
            pts,
            (d * s).round() as i32,
            (g * s).round() as i32,
            st,
        ))
    } else {
        root.draw(&PathElement::new(pts, st))
    }
}

/// Draws `plot` laid out as `lay` onto `root`: the same routine for every backend.
pub(crate) fn draw<DB: DrawingBackend>(
    plot: &Plot,
    lay: &Layout,
    root: &DrawingArea<DB, Shift>,
) -> Res<DB> {
    let s = lay.scale;
    let a = lay.area;
    let ink = RGBColor(0x22, 0x22, 0x22);
    let grid = RGBColor(0xdd, 0xdd, 0xdd);
    root.fill(&RGBColor(255, 255, 255))?;
    let thin = |c: RGBColor| c.stroke_width(s.round().max(1.0) as u32);
    // grid and ticks
    for (ticks, horizontal) in [(&lay.x_ticks, true), (&lay.y_ticks, false)] {
        for t in ticks.iter() {
            let p = if horizontal {
                lay.x.fraction(t.value).map(|f| a.x0 + f * (a.x1 - a.x0))
            } else {
                lay.y.fraction(t.value).map(|f| a.y1 - f * (a.y1 - a.y0))
            };
            let Some(p) = p else { continue };
            let major = !t.label.is_empty();
            let tick_len = if major { 6.0 * s } else { 3.5 * s };
            let (line, tick) = if horizontal {
                (
                    [px((p, a.y0)), px((p, a.y1))],
                    [px((p, a.y1)), px((p, a.y1 + tick_len))],
                )
            } else {
                (
                    [px((a.x0, p)), px((a.x1, p))],
                    [px((a.x0 - tick_len, p)), px((a.x0, p))],
                )
            };
            // minor ticks get a tick mark only
            if major {
                root.draw(&PathElement::new(line.to_vec(), thin(grid)))?;
            }
            root.draw(&PathElement::new(tick.to_vec(), thin(ink)))?;
        }
    }
    root.draw(&Rectangle::new(
        [px((a.x0, a.y0)), px((a.x1, a.y1))],
        thin(ink),
    ))?;
    for t in lay.x_tick_labels.iter().chain(&lay.y_tick_labels) {
        text(root, t, &ink)?;
    }
    text(root, &lay.title, &ink)?;
    text(root, &lay.xlabel, &ink)?;
    text(root, &lay.ylabel, &ink)?;
    // series: lines first, markers over them
    let lw = (style::LINE_W * s).round().max(1.0) as u32;
    for (k, se) in plot.series.iter().enumerate() {
        let c = series_color(plot, k);
        if se.style == Style::Points {
            continue;
        }
        let mut run: Vec<(i32, i32)> = vec![];
        for (x, y) in se.x.iter().zip(&se.y) {
            match lay.px(*x, *y) {
                Some(p) => run.push(px(p)),
                None => polyline(
                    root,
                    std::mem::take(&mut run),
                    se.style == Style::Dashed,
                    c.stroke_width(lw),
                    s,
                )?,
            }
        }
        polyline(root, run, se.style == Style::Dashed, c.stroke_width(lw), s)?;
    }
    for (k, se) in plot.series.iter().enumerate() {
        if se.style != Style::Points {
            continue;
        }
        let c = series_color(plot, k);
        for (x, y) in se.x.iter().zip(&se.y) {
            if let Some(p) = lay.px(*x, *y) {
                marker(root, series_marker(plot, k), p, lay.marker_r, &c)?;
            }
        }
    }
    for (_, _, t) in &lay.point_labels {
        text(root, t, &ink)?;
    }
    // legend
    if let Some(l) = &lay.legend {
        let r = l.rect;
        root.draw(&Rectangle::new(
            [px((r.x0, r.y0)), px((r.x1, r.y1))],
            RGBColor(255, 255, 255).filled(),
        ))?;
        root.draw(&Rectangle::new(
            [px((r.x0, r.y0)), px((r.x1, r.y1))],
            thin(RGBColor(0xaa, 0xaa, 0xaa)),
        ))?;
        for e in &l.entries {
            let se = &plot.series[e.series];
            let c = series_color(plot, e.series);
            let (x0, cy) = e.sample;
            match se.style {
                Style::Points => marker(
                    root,
                    series_marker(plot, e.series),
                    (x0 + e.sample_len / 2.0, cy),
                    lay.marker_r,
                    &c,
                )?,
                st => polyline(
                    root,
                    vec![px((x0, cy)), px((x0 + e.sample_len, cy))],
                    st == Style::Dashed,
                    c.stroke_width(lw),
                    s,
                )?,
            }
            text(root, &e.text, &ink)?;
        }
    }
    Ok(())
}

fn err<E: std::error::Error + Send + Sync>(what: &str, e: DrawingAreaErrorKind<E>) -> io::Error {
    io::Error::other(format!("{what}: {e}"))
}

impl Plot {
    /// The SVG document.
    pub fn to_svg(&self) -> io::Result<String> {
        let lay = self.layout(1.0)?;
        let mut s = String::new();
        {
            let root = SVGBackend::with_string(&mut s, (lay.width, lay.height)).into_drawing_area();
            draw(self, &lay, &root).map_err(|e| err(&self.title, e))?;
            root.present().map_err(|e| err(&self.title, e))?;
        }
        Ok(s)
    }

    /// The PNG's pixels (RGB, row by row) and its layout, at [`PNG_SCALE`].
    pub fn to_rgb(&self) -> io::Result<(Layout, Vec<u8>)> {
        let lay = self.layout(PNG_SCALE)?;
        let mut buf = vec![0u8; 3 * lay.width as usize * lay.height as usize];
        {
            let root =
                BitMapBackend::with_buffer(&mut buf, (lay.width, lay.height)).into_drawing_area();
            draw(self, &lay, &root).map_err(|e| err(&self.title, e))?;
            root.present().map_err(|e| err(&self.title, e))?;
        }
        Ok((lay, buf))
    }

    fn write_png(&self, path: &Path) -> io::Result<()> {
        let lay = self.layout(PNG_SCALE)?;
        let what = path.display().to_string();
        let root = BitMapBackend::new(path, (lay.width, lay.height)).into_drawing_area();
        draw(self, &lay, &root).map_err(|e| err(&what, e))?;
        root.present().map_err(|e| err(&what, e))
    }

    /// Writes the figure as SVG or PNG, by the extension of `path`.
    pub fn save(&self, path: &Path) -> io::Result<()> {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("svg") => std::fs::write(path, self.to_svg()?),
            Some(e) if e.eq_ignore_ascii_case("png") => self.write_png(path),
            _ => Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "{}: unknown figure format (the file name must end in .svg or .png)",
                    path.display()
                ),
            )),
        }
    }

    /// Writes the figure twice, as `path` with the extensions .svg and .png;
    /// returns the two paths.
    pub fn save_both(&self, path: &Path) -> io::Result<(PathBuf, PathBuf)> {
        let svg = path.with_extension("svg");
        let png = path.with_extension("png");
        self.save(&svg)?;
        self.save(&png)?;
        Ok((svg, png))
    }
}
