//! Where everything of a figure goes, in pixels, before anything is drawn:
//! margins sized to the measured labels, axis ranges padded so that no
//! marker or line reaches the frame, ticks whose labels do not collide, a
//! legend as wide as its longest label, and direct point labels placed
//! beside their points inside the plot area.
//!
//! Both backends draw from the same [`Layout`], so the SVG and the PNG of a
//! figure agree, and tests can check the geometry without reading pixels.

use crate::axis::{linear_ticks, log_ticks, Range, Scale, Tick};
use crate::style::{self, MARKER_EXTENT, MARKER_R};
use crate::{Plot, Style};
use std::io;

/// An axis-aligned rectangle in pixels (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left.
    pub x0: f64,
    /// Top.
    pub y0: f64,
    /// Right.
    pub x1: f64,
    /// Bottom.
    pub y1: f64,
}

impl Rect {
    /// Whether `o` lies inside this rectangle.
    pub fn contains(&self, o: &Rect) -> bool {
        o.x0 >= self.x0 && o.x1 <= self.x1 && o.y0 >= self.y0 && o.y1 <= self.y1
    }
    /// Whether the two rectangles share more than an edge.
    pub fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
    fn around(x: f64, y: f64, r: f64) -> Rect {
        Rect {
            x0: x - r,
            y0: y - r,
            x1: x + r,
            y1: y + r,
        }
    }
}

/// Horizontal alignment of a text at its anchor point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    /// The anchor is the text's left end.
    Left,
    /// The anchor is the text's middle.
    Center,
    /// The anchor is the text's right end.
    Right,
}

/// A text to draw: anchored at `at` (vertically centred there), and the box
/// it covers.
#[derive(Clone, Debug, PartialEq)]
pub struct Text {
    /// The text, whole.
    pub text: String,
    /// Anchor point (pixels).
    pub at: (f64, f64),
    /// Horizontal alignment at the anchor.
    pub align: Align,
    /// Font size.
    pub size: f64,
    /// Drawn turned by 90° counter-clockwise (the y-axis label).
    pub vertical: bool,
    /// The box the text covers, from the bundled font's metrics.
    pub rect: Rect,
}

impl Text {
    fn new(text: &str, size: f64, at: (f64, f64), align: Align) -> io::Result<Text> {
        let (w, h) = style::text_size(text, size)?;
        Ok(Text::sized(text, size, at, align, w, h))
    }
    fn sized(text: &str, size: f64, at: (f64, f64), align: Align, w: f64, h: f64) -> Text {
        let x0 = match align {
            Align::Left => at.0,
            Align::Center => at.0 - w / 2.0,
            Align::Right => at.0 - w,
        };
        Text {
            text: text.into(),
            at,
            align,
            size,
            vertical: false,
            rect: Rect {
                x0,
                y0: at.1 - h / 2.0,
                x1: x0 + w,
                y1: at.1 + h / 2.0,
            },
        }
    }
}

/// One legend row.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendEntry {
    /// Index of the series.
    pub series: usize,
    /// The sample's left end and the row's centre line (pixels).
    pub sample: (f64, f64),
    /// The sample's length.
    pub sample_len: f64,
    /// The series' label.
    pub text: Text,
}

/// The legend: a box right of the plot area.
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    /// Its frame.
    pub rect: Rect,
    /// Its rows.
    pub entries: Vec<LegendEntry>,
}

/// The geometry of one figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Figure width (pixels).
    pub width: u32,
    /// Figure height (pixels).
    pub height: u32,
    /// Scale factor of all sizes (1 for SVG).
    pub scale: f64,
    /// The plot area (the frame).
    pub area: Rect,
    /// Range of the x axis.
    pub x: Range,
    /// Range of the y axis.
    pub y: Range,
    /// Ticks of the x axis.
    pub x_ticks: Vec<Tick>,
    /// Ticks of the y axis.
    pub y_ticks: Vec<Tick>,
    /// Labels of the labelled x ticks.
    pub x_tick_labels: Vec<Text>,
    /// Labels of the labelled y ticks.
    pub y_tick_labels: Vec<Text>,
    /// The title.
    pub title: Text,
    /// The x-axis label.
    pub xlabel: Text,
    /// The y-axis label (vertical).
    pub ylabel: Text,
    /// The legend, if any.
    pub legend: Option<Legend>,
    /// Direct labels of points, with the series and point they belong to.
    pub point_labels: Vec<(usize, usize, Text)>,
    /// Marker radius (pixels).
    pub marker_r: f64,
    /// Pixels kept free between the data and the frame.
    pub margin: f64,
}

impl Layout {
    /// The pixel position of a data point, `None` if an axis cannot show it.
    pub fn px(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let fx = self.x.fraction(x)?;
        let fy = self.y.fraction(y)?;
        let a = &self.area;
        Some((a.x0 + fx * (a.x1 - a.x0), a.y1 - fy * (a.y1 - a.y0)))
    }
}

/// Extent of the drawable coordinates of all series along one axis.
fn extent(plot: &Plot, scale: Scale, pick: impl Fn(f64, f64) -> f64) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for (x, y) in plot.drawable_points() {
        if let Some(c) = scale.coord(pick(x, y)) {
            lo = lo.min(c);
            hi = hi.max(c);
        }
    }
    (lo, hi)
}

/// Tick labels of one axis, or `None` when neighbours collide.
fn tick_texts(
    ticks: &[Tick],
    place: &dyn Fn(f64) -> ((f64, f64), Align),
    size: f64,
    gap: f64,
    horizontal: bool,
) -> io::Result<Option<Vec<Text>>> {
    let mut out: Vec<Text> = vec![];
    for t in ticks.iter().filter(|t| !t.label.is_empty()) {
        let (at, align) = place(t.value);
        let txt = Text::new(&t.label, size, at, align)?;
        if let Some(p) = out.last() {
            // ticks come in increasing value: rightwards on x, upwards on y
            let clash = if horizontal {
                txt.rect.x0 < p.rect.x1 + gap
            } else {
                txt.rect.y1 > p.rect.y0 - gap
            };
            if clash {
                return Ok(None);
            }
        }
        out.push(txt);
    }
    Ok(Some(out))
}

/// Ticks of an axis of pixel length `len` whose labels do not collide.
fn axis_ticks(
    r: &Range,
    unit: &str,
    len: f64,
    place: &dyn Fn(f64) -> ((f64, f64), Align),
    s: f64,
    horizontal: bool,
) -> io::Result<(Vec<Tick>, Vec<Text>)> {
    let size = style::FONT_TICK * s;
    let gap = if horizontal { 12.0 * s } else { 4.0 * s };
    let tries: Vec<Vec<Tick>> = match r.scale {
        Scale::Log => vec![log_ticks(r, true, unit), log_ticks(r, false, unit)],
        Scale::Linear => {
            let per = if horizontal { 65.0 } else { 55.0 };
            let n = (len / (per * s)).clamp(3.0, 10.0) as usize;
            [n, n * 2 / 3, n / 2, 2]
                .iter()
                .map(|k| linear_ticks(r, (*k).max(2), unit))
                .collect()
        }
    };
    for t in &tries {
        if let Some(texts) = tick_texts(t, place, size, gap, horizontal)? {
            return Ok((t.clone(), texts));
        }
    }
    // the sparsest division, labels kept only where they fit
    let t = tries.last().cloned().unwrap_or_default();
    let mut texts: Vec<Text> = vec![];
    for tk in t.iter().filter(|t| !t.label.is_empty()) {
        let (at, align) = place(tk.value);
        let txt = Text::new(&tk.label, size, at, align)?;
        if texts.last().is_none_or(|p| !p.rect.overlaps(&txt.rect)) {
            texts.push(txt);
        }
    }
    Ok((t, texts))
}

/// Extra pixels to keep free at the four sides of the data (left, right,
/// bottom, top), grown while direct labels do not fit.
#[derive(Clone, Copy, Default)]
struct Extra {
    l: f64,
    r: f64,
    b: f64,
    t: f64,
}

/// Computes the layout of `plot` at `scale` (1: the nominal size in pixels).
pub fn layout(plot: &Plot, scale: f64) -> io::Result<Layout> {
    let mut extra = Extra::default();
    let mut lay = layout_once(plot, scale, extra, None)?;
    for _ in 0..6 {
        let (ok, need) = place_point_labels(plot, &mut lay)?;
        if ok {
            break;
        }
        extra.l += need.l;
        extra.r += need.r;
        extra.b += need.b;
        extra.t += need.t;
        lay = layout_once(plot, scale, extra, None)?;
    }
    if plot.equal_aspect {
        // the ranges grow (never shrink) until a data unit is as many pixels
        // on both axes; the plot area moves with the tick labels, so again
        for _ in 0..4 {
            let ranges = equal_aspect_ranges(&lay);
            let area = lay.area;
            lay = layout_once(plot, scale, extra, Some(ranges))?;
            place_point_labels(plot, &mut lay)?;
            if lay.area == area {
                break;
            }
        }
    }
    Ok(lay)
}

/// The x and y ranges of `lay`, the one with fewer data units per pixel
/// widened about its centre to the other's (linear axes; a log axis is
/// kept).
fn equal_aspect_ranges(lay: &Layout) -> (Range, Range) {
    let (pw, ph) = (lay.area.x1 - lay.area.x0, lay.area.y1 - lay.area.y0);
    if lay.x.scale != Scale::Linear || lay.y.scale != Scale::Linear || pw <= 0.0 || ph <= 0.0 {
        return (lay.x, lay.y);
    }
    let u = ((lay.x.hi - lay.x.lo) / pw).max((lay.y.hi - lay.y.lo) / ph);
    let widen = |r: Range, len: f64| {
        let c = 0.5 * (r.lo + r.hi);
        Range {
            lo: c - 0.5 * u * len,
            hi: c + 0.5 * u * len,
            scale: r.scale,
        }
    };
    (widen(lay.x, pw), widen(lay.y, ph))
}

/// The layout with `extra` pixels kept free beside the data, and the axis
/// ranges `forced` (x, y) instead of those padded around the data.
fn layout_once(
    plot: &Plot,
    s: f64,
    extra: Extra,
    forced: Option<(Range, Range)>,
) -> io::Result<Layout> {
    let marker_r = MARKER_R * s;
    let margin = MARKER_EXTENT * marker_r + 5.0 * s;
    let title_probe = Text::new(
        &plot.title,
        style::FONT_TITLE * s,
        (0.0, 0.0),
        Align::Center,
    )?;
    let xl_probe = Text::new(
        &plot.xlabel,
        style::FONT_LABEL * s,
        (0.0, 0.0),
        Align::Center,
    )?;
    let yl_probe = Text::new(
        &plot.ylabel,
        style::FONT_LABEL * s,
        (0.0, 0.0),
        Align::Center,
    )?;
    let tick_h = style::FONT_TICK * s;
    let label_h = style::FONT_LABEL * s;
    // legend rows
    let legend_rows: Vec<(usize, Text)> = if plot.legend {
        plot.series
            .iter()
            .enumerate()
            .filter(|(_, se)| !se.label.is_empty())
            .map(|(i, se)| {
                Text::new(&se.label, style::FONT_LEGEND * s, (0.0, 0.0), Align::Left)
                    .map(|t| (i, t))
            })
            .collect::<io::Result<_>>()?
    } else {
        vec![]
    };
    let sample_len = 34.0 * s;
    let row_h = (style::FONT_LEGEND * s).max(2.0 * MARKER_EXTENT * marker_r) + 8.0 * s;
    let pad = 10.0 * s;
    let text_w = legend_rows
        .iter()
        .map(|(_, t)| t.rect.x1 - t.rect.x0)
        .fold(0.0, f64::max);
    let legend_w = pad + sample_len + 8.0 * s + text_w + pad;
    let legend_h = 2.0 * pad + row_h * legend_rows.len() as f64;
    let top = 12.0 * s + title_probe.rect.y1 - title_probe.rect.y0 + 14.0 * s;
    let bottom = 8.0 * s + tick_h + 10.0 * s + label_h + 12.0 * s;
    let right = 20.0 * s
        + if legend_rows.is_empty() {
            0.0
        } else {
            legend_w + 16.0 * s
        };
    let yl_len = yl_probe.rect.x1 - yl_probe.rect.x0;
    let height = (plot.height * s)
        .max(top + bottom + (yl_len + 20.0 * s).max(legend_h).max(220.0 * s))
        .ceil();
    let ph = height - top - bottom;
    // y axis
    let (ylo, yhi) = extent(plot, plot.y_scale, |_, y| y);
    let y = forced.map_or_else(
        || {
            Range::padded(
                plot.y_scale,
                ylo,
                yhi,
                ph,
                margin + extra.b,
                margin + extra.t,
            )
        },
        |f| f.1,
    );
    let y_at = |v: f64| top + ph - y.fraction(v).unwrap_or(0.0) * ph;
    // y tick labels are placed at x = 0 for now and shifted once `left` is known
    let (y_ticks, y_texts) = axis_ticks(
        &y,
        &plot.y_unit,
        ph,
        &|v| ((0.0, y_at(v)), Align::Right),
        s,
        false,
    )?;
    let ytw = y_texts
        .iter()
        .map(|t| t.rect.x1 - t.rect.x0)
        .fold(0.0, f64::max);
    let left = 12.0 * s + label_h + 12.0 * s + ytw + 9.0 * s;
    let width = (plot.width * s)
        .max(left + 480.0 * s + right)
        .max(title_probe.rect.x1 - title_probe.rect.x0 + 40.0 * s)
        .max(left + xl_probe.rect.x1 - xl_probe.rect.x0 + 20.0 * s + right)
        .ceil();
    let pw = width - left - right;
    let area = Rect {
        x0: left,
        y0: top,
        x1: left + pw,
        y1: top + ph,
    };
    let y_tick_labels: Vec<Text> = y_texts
        .into_iter()
        .map(|t| {
            Text::sized(
                &t.text,
                t.size,
                (left - 9.0 * s, t.at.1),
                Align::Right,
                t.rect.x1 - t.rect.x0,
                t.rect.y1 - t.rect.y0,
            )
        })
        .collect();
    // x axis
    let (xlo, xhi) = extent(plot, plot.x_scale, |x, _| x);
    let x = forced.map_or_else(
        || {
            Range::padded(
                plot.x_scale,
                xlo,
                xhi,
                pw,
                margin + extra.l,
                margin + extra.r,
            )
        },
        |f| f.0,
    );
    let x_at = |v: f64| left + x.fraction(v).unwrap_or(0.0) * pw;
    let ty = top + ph + 8.0 * s + tick_h / 2.0;
    let (x_ticks, x_tick_labels) = axis_ticks(
        &x,
        &plot.x_unit,
        pw,
        &|v| ((x_at(v), ty), Align::Center),
        s,
        true,
    )?;
    let title = Text::new(
        &plot.title,
        style::FONT_TITLE * s,
        (
            width / 2.0,
            12.0 * s + (title_probe.rect.y1 - title_probe.rect.y0) / 2.0,
        ),
        Align::Center,
    )?;
    let xlabel = Text::new(
        &plot.xlabel,
        style::FONT_LABEL * s,
        (left + pw / 2.0, height - 12.0 * s - label_h / 2.0),
        Align::Center,
    )?;
    let yc = (12.0 * s + label_h / 2.0, top + ph / 2.0);
    let ylabel = Text {
        vertical: true,
        rect: Rect {
            x0: yc.0 - label_h / 2.0,
            y0: yc.1 - yl_len / 2.0,
            x1: yc.0 + label_h / 2.0,
            y1: yc.1 + yl_len / 2.0,
        },
        ..Text::new(&plot.ylabel, style::FONT_LABEL * s, yc, Align::Center)?
    };
    let legend = (!legend_rows.is_empty()).then(|| {
        let x0 = area.x1 + 16.0 * s;
        let rect = Rect {
            x0,
            y0: top,
            x1: x0 + legend_w,
            y1: top + legend_h,
        };
        let entries = legend_rows
            .iter()
            .enumerate()
            .map(|(k, (i, t))| {
                let cy = top + pad + row_h * (k as f64 + 0.5);
                let tx = x0 + pad + sample_len + 8.0 * s;
                LegendEntry {
                    series: *i,
                    sample: (x0 + pad, cy),
                    sample_len,
                    text: Text::sized(
                        &t.text,
                        t.size,
                        (tx, cy),
                        Align::Left,
                        t.rect.x1 - t.rect.x0,
                        t.rect.y1 - t.rect.y0,
                    ),
                }
            })
            .collect();
        Legend { rect, entries }
    });
    Ok(Layout {
        width: width as u32,
        height: height as u32,
        scale: s,
        area,
        x,
        y,
        x_ticks,
        y_ticks,
        x_tick_labels,
        y_tick_labels,
        title,
        xlabel,
        ylabel,
        legend,
        point_labels: vec![],
        marker_r,
        margin,
    })
}

/// Places the direct point labels beside their points: right, left, above,
/// below or diagonal, the first spot inside the plot area that covers no
/// marker and no label placed before. Returns whether all fitted, and
/// otherwise the pixels to add at each side for the next try.
fn place_point_labels(plot: &Plot, lay: &mut Layout) -> io::Result<(bool, Extra)> {
    let s = lay.scale;
    let size = style::FONT_POINT * s;
    let reach = MARKER_EXTENT * lay.marker_r + 4.0 * s;
    let inside = Rect {
        x0: lay.area.x0 + 2.0 * s,
        y0: lay.area.y0 + 2.0 * s,
        x1: lay.area.x1 - 2.0 * s,
        y1: lay.area.y1 - 2.0 * s,
    };
    let mut blocked: Vec<Rect> = vec![];
    for se in plot.series.iter().filter(|se| se.style == Style::Points) {
        for (x, y) in se.x.iter().zip(&se.y) {
            if let Some((px, py)) = lay.px(*x, *y) {
                blocked.push(Rect::around(px, py, MARKER_EXTENT * lay.marker_r));
            }
        }
    }
    let mut need = Extra::default();
    let mut ok = true;
    let mut placed = vec![];
    for (i, se) in plot.series.iter().enumerate() {
        for (j, lab) in se.point_labels.iter().enumerate() {
            if lab.is_empty() {
                continue;
            }
            let Some((px, py)) =
                se.x.get(j)
                    .zip(se.y.get(j))
                    .and_then(|(x, y)| lay.px(*x, *y))
            else {
                continue;
            };
            let (w, h) = style::text_size(lab, size)?;
            let d = reach + h / 2.0;
            let spots = [
                ((px + reach, py), Align::Left),
                ((px - reach, py), Align::Right),
                ((px, py - d), Align::Center),
                ((px, py + d), Align::Center),
                ((px + reach * 0.7, py - d), Align::Left),
                ((px - reach * 0.7, py - d), Align::Right),
                ((px + reach * 0.7, py + d), Align::Left),
                ((px - reach * 0.7, py + d), Align::Right),
            ];
            let cands: Vec<Text> = spots
                .iter()
                .map(|(at, al)| Text::sized(lab, size, *at, *al, w, h))
                .collect();
            let free =
                |t: &Text| inside.contains(&t.rect) && !blocked.iter().any(|b| b.overlaps(&t.rect));
            if let Some(t) = cands.iter().find(|t| free(t)) {
                blocked.push(t.rect);
                placed.push((i, j, t.clone()));
                continue;
            }
            // inside but crowded: take the inside spot; outside: widen the
            // side the preferred (right or left) spot sticks out of
            if let Some(t) = cands.iter().find(|t| inside.contains(&t.rect)) {
                blocked.push(t.rect);
                placed.push((i, j, t.clone()));
                continue;
            }
            ok = false;
            let r = &cands[0].rect;
            let l = &cands[1].rect;
            if r.x1 - inside.x1 <= inside.x0 - l.x0 {
                need.r = need.r.max(r.x1 - inside.x1 + 2.0 * s);
            } else {
                need.l = need.l.max(inside.x0 - l.x0 + 2.0 * s);
            }
            need.t = need.t.max(inside.y0 - r.y0);
            need.b = need.b.max(r.y1 - inside.y1);
            placed.push((i, j, cands[0].clone()));
        }
    }
    lay.point_labels = placed;
    Ok((ok, need))
}
