//! Small, dependency-free SVG line plots and CSV tables for flexmb results.
//!
//! SVG is written directly (text is left to the viewer's fonts), so plots
//! render headless on a bare machine and open in any browser.
//!
//! ```
//! use flexmb_plot::{Plot, Series};
//! let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
//! let y: Vec<f64> = t.iter().map(|t| (6.0 * t).sin()).collect();
//! let svg = Plot::new("response", "t (s)", "x (m)")
//!     .series(Series::line("x", &t, &y))
//!     .to_svg();
//! assert!(svg.starts_with("<svg") && svg.contains("polyline"));
//! ```
#![warn(missing_docs)]

use std::fmt::Write as _;
use std::io;
use std::path::Path;

const COLORS: [&str; 10] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A polyline.
    Line,
    /// A dashed polyline.
    Dashed,
    /// Markers only.
    Points,
}

/// One data series.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// x values.
    pub x: Vec<f64>,
    /// y values.
    pub y: Vec<f64>,
    /// Drawing style.
    pub style: Style,
}

impl Series {
    /// A line series.
    pub fn line(label: &str, x: &[f64], y: &[f64]) -> Self {
        Self {
            label: label.into(),
            x: x.to_vec(),
            y: y.to_vec(),
            style: Style::Line,
        }
    }
    /// A dashed line series.
    pub fn dashed(label: &str, x: &[f64], y: &[f64]) -> Self {
        Self {
            style: Style::Dashed,
            ..Self::line(label, x, y)
        }
    }
    /// A marker series.
    pub fn points(label: &str, x: &[f64], y: &[f64]) -> Self {
        Self {
            style: Style::Points,
            ..Self::line(label, x, y)
        }
    }
}

/// A 2-D line plot.
#[derive(Clone, Debug)]
pub struct Plot {
    title: String,
    xlabel: String,
    ylabel: String,
    series: Vec<Series>,
    log_y: bool,
    width: f64,
    height: f64,
}

fn nice_step(range: f64, n: usize) -> f64 {
    let raw = range / n.max(1) as f64;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let k = if m < 1.5 {
        1.0
    } else if m < 3.0 {
        2.0
    } else if m < 7.0 {
        5.0
    } else {
        10.0
    };
    k * p
}

fn fmt_tick(v: f64, step: f64) -> String {
    // ticks are multiples of the step: rounding residue of zero is zero
    if v == 0.0 || v.abs() < 1e-9 * step.abs() {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.1e}");
    }
    let dec = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.dec$}")
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

impl Plot {
    /// A plot with a title and axis labels.
    pub fn new(title: &str, xlabel: &str, ylabel: &str) -> Self {
        Self {
            title: title.into(),
            xlabel: xlabel.into(),
            ylabel: ylabel.into(),
            series: vec![],
            log_y: false,
            width: 800.0,
            height: 500.0,
        }
    }
    /// Adds a series.
    pub fn series(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }
    /// Adds a series in place.
    pub fn push(&mut self, s: Series) {
        self.series.push(s);
    }
    /// A logarithmic y axis (non-positive values are skipped).
    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }

    /// The SVG document.
    pub fn to_svg(&self) -> String {
        let (w, h) = (self.width, self.height);
        let (l, r, t, b) = (80.0, 170.0, 40.0, 55.0);
        let pw = w - l - r;
        let ph = h - t - b;
        let ty = |v: f64| if self.log_y { v.log10() } else { v };
        let pts: Vec<(f64, f64)> = self
            .series
            .iter()
            .flat_map(|s| s.x.iter().zip(&s.y).map(|(x, y)| (*x, *y)))
            .filter(|(x, y)| x.is_finite() && y.is_finite() && (!self.log_y || *y > 0.0))
            .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (x, y) in &pts {
            x0 = x0.min(*x);
            x1 = x1.max(*x);
            y0 = y0.min(ty(*y));
            y1 = y1.max(ty(*y));
        }
        if pts.is_empty() {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        if x1 - x0 <= 0.0 {
            x0 -= 0.5;
            x1 += 0.5;
        }
        if y1 - y0 <= 0.0 {
            let d = if y0 == 0.0 { 1.0 } else { 0.1 * y0.abs() };
            y0 -= d;
            y1 += d;
        } else {
            let pad = 0.05 * (y1 - y0);
            y0 -= pad;
            y1 += pad;
        }
        let sx = |x: f64| l + (x - x0) / (x1 - x0) * pw;
        let sy = |y: f64| t + ph - (ty(y) - y0) / (y1 - y0) * ph;
        let mut s = String::new();
        let _ = write!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        let _ = write!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
        let _ = write!(
            s,
            r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            l + pw / 2.0,
            esc(&self.title)
        );
        // grid and ticks
        let xs = nice_step(x1 - x0, 8);
        let mut v = (x0 / xs).ceil() * xs;
        while v <= x1 + 1e-12 * xs {
            let px = sx(v);
            let _ = write!(
                s,
                r##"<line x1="{px:.1}" y1="{t}" x2="{px:.1}" y2="{:.1}" stroke="#e0e0e0"/>"##,
                t + ph
            );
            let _ = write!(
                s,
                r#"<text x="{px:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                t + ph + 16.0,
                fmt_tick(v, xs)
            );
            v += xs;
        }
        let ys = if self.log_y {
            1.0
        } else {
            nice_step(y1 - y0, 6)
        };
        let mut v = (y0 / ys).ceil() * ys;
        while v <= y1 + 1e-12 * ys {
            let py = t + ph - (v - y0) / (y1 - y0) * ph;
            let label = if self.log_y {
                format!("1e{}", v.round() as i64)
            } else {
                fmt_tick(v, ys)
            };
            let _ = write!(
                s,
                r##"<line x1="{l}" y1="{py:.1}" x2="{:.1}" y2="{py:.1}" stroke="#e0e0e0"/>"##,
                l + pw
            );
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                l - 6.0,
                py + 4.0,
                label
            );
            v += ys;
        }
        let _ = write!(
            s,
            r##"<rect x="{l}" y="{t}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>"##
        );
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            l + pw / 2.0,
            h - 12.0,
            esc(&self.xlabel)
        );
        let _ = write!(
            s,
            r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">{}</text>"#,
            t + ph / 2.0,
            t + ph / 2.0,
            esc(&self.ylabel)
        );
        // series
        for (k, se) in self.series.iter().enumerate() {
            let c = COLORS[k % COLORS.len()];
            let mut poly = String::new();
            let flush = |poly: &mut String, s: &mut String| {
                if !poly.is_empty() {
                    let dash = if se.style == Style::Dashed {
                        r#" stroke-dasharray="6,4""#
                    } else {
                        ""
                    };
                    let _ = write!(
                        s,
                        r#"<polyline fill="none" stroke="{c}" stroke-width="1.6"{dash} points="{poly}"/>"#
                    );
                    poly.clear();
                }
            };
            for (x, y) in se.x.iter().zip(&se.y) {
                let ok = x.is_finite() && y.is_finite() && (!self.log_y || *y > 0.0);
                if !ok {
                    flush(&mut poly, &mut s);
                    continue;
                }
                if se.style == Style::Points {
                    let _ = write!(
                        s,
                        r#"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="{c}"/>"#,
                        sx(*x),
                        sy(*y)
                    );
                } else {
                    let _ = write!(poly, "{:.1},{:.1} ", sx(*x), sy(*y));
                }
            }
            flush(&mut poly, &mut s);
            let ly = t + 14.0 + 18.0 * k as f64;
            let lx = l + pw + 12.0;
            let _ = write!(
                s,
                r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="2"/>"#,
                lx + 22.0
            );
            let _ = write!(
                s,
                r#"<text x="{}" y="{}">{}</text>"#,
                lx + 28.0,
                ly + 4.0,
                esc(&se.label)
            );
        }
        s.push_str("</svg>\n");
        s
    }

    /// Writes the SVG file.
    pub fn save(&self, path: &Path) -> io::Result<()> {
        std::fs::write(path, self.to_svg())
    }
}

/// Writes a CSV file: optional `#`-comment header lines, a column header, rows.
pub fn write_csv(
    path: &Path,
    comments: &[String],
    header: &[String],
    rows: &[Vec<f64>],
) -> io::Result<()> {
    let mut s = String::new();
    for c in comments {
        let _ = writeln!(s, "# {c}");
    }
    let _ = writeln!(s, "{}", header.join(","));
    for r in rows {
        let line: Vec<String> = r.iter().map(|v| format!("{v:.12e}")).collect();
        let _ = writeln!(s, "{}", line.join(","));
    }
    std::fs::write(path, s)
}

/// Reads a CSV written by [`write_csv`]: (header, rows), skipping `#` comments.
pub fn read_csv(path: &Path) -> io::Result<(Vec<String>, Vec<Vec<f64>>)> {
    let text = std::fs::read_to_string(path)?;
    let mut header = vec![];
    let mut rows = vec![];
    for (k, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        if header.is_empty() {
            header = line.split(',').map(|s| s.trim().to_string()).collect();
            continue;
        }
        let r: Result<Vec<f64>, _> = line.split(',').map(|s| s.trim().parse::<f64>()).collect();
        rows.push(r.map_err(|e| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: line {}: {e}", path.display(), k + 1),
            )
        })?);
    }
    Ok((header, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_at_rounding_distance_from_zero_is_zero() {
        assert_eq!(fmt_tick(-5.551115123125783e-17, 0.05), "0");
        assert_eq!(fmt_tick(0.05, 0.05), "0.05");
        assert_eq!(fmt_tick(-2e-4, 1e-4), "-2.0e-4");
    }

    #[test]
    fn csv_round_trips_and_svg_has_every_series() {
        let dir = std::env::temp_dir().join(format!("flexmb-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.csv");
        let rows = vec![vec![0.0, 1.5], vec![1.0, -2.25e-7]];
        write_csv(
            &p,
            &["made by a test".into()],
            &["t".into(), "x".into()],
            &rows,
        )
        .unwrap();
        let (h, r) = read_csv(&p).unwrap();
        assert_eq!(h, vec!["t", "x"]);
        assert_eq!(r, rows);
        let svg = Plot::new("t", "x", "y")
            .series(Series::line("a", &[0.0, 1.0], &[1.0, 2.0]))
            .series(Series::dashed("b", &[0.0, 1.0], &[f64::NAN, 2.0]))
            .series(Series::points("c", &[0.5], &[1.5]))
            .to_svg();
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("<circle"));
        let log = Plot::new("s", "i", "σ")
            .log_y()
            .series(Series::points("σ", &[1.0, 2.0], &[1.0, 1e-3]))
            .to_svg();
        assert!(log.contains("1e-3") || log.contains("1e-2"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
