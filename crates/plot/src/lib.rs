//! Line and marker plots of flexmb results, written as SVG and PNG from one
//! drawing routine, and CSV tables.
//!
//! A [`Plot`] is laid out once ([`Plot::layout`]: margins sized to the
//! measured labels, axis ranges padded so that no marker or line touches
//! the frame, linear or logarithmic axes ticked at readable values, a legend
//! as wide as its longest label, direct point labels) and then drawn by the
//! same code onto plotters' SVG backend or its bitmap backend. Text is
//! measured and (in PNG) rasterized with the bundled DejaVu Sans font, so
//! both render headless with no system library.
//!
//! ```
//! use flexmb_plot::{Plot, Series};
//! let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
//! let y: Vec<f64> = t.iter().map(|t| (6.0 * t).sin()).collect();
//! let svg = Plot::new("response", "t (s)", "x (m)")
//!     .series(Series::line("x", &t, &y))
//!     .to_svg()
//!     .unwrap();
//! assert!(svg.starts_with("<svg") && svg.contains("polyline"));
//! ```
#![warn(missing_docs)]

mod axis;
mod csv;
mod layout;
mod render;
mod style;

pub use axis::{Range, Scale, Tick};
pub use csv::{read_csv, write_csv};
pub use layout::{Align, Layout, Legend, LegendEntry, Rect, Text};
pub use style::Marker;

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
    /// Labels written next to the points (empty: none), one per point.
    pub point_labels: Vec<String>,
    /// Its colour (RGB) instead of the next one of the palette.
    pub color: Option<(u8, u8, u8)>,
    /// Its marker shape instead of the next one of the sequence.
    pub marker: Option<Marker>,
}

impl Series {
    /// A line series.
    pub fn line(label: &str, x: &[f64], y: &[f64]) -> Self {
        Self {
            label: label.into(),
            x: x.to_vec(),
            y: y.to_vec(),
            style: Style::Line,
            point_labels: vec![],
            color: None,
            marker: None,
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
    /// One marker, labelled with `label` next to it.
    pub fn labelled_point(label: &str, x: f64, y: f64) -> Self {
        Self::points(label, &[x], &[y]).with_point_labels([label])
    }
    /// Labels written next to the points, in order (an empty one: none).
    pub fn with_point_labels<S: Into<String>>(
        mut self,
        labels: impl IntoIterator<Item = S>,
    ) -> Self {
        self.point_labels = labels.into_iter().map(Into::into).collect();
        self
    }
    /// Drawn in this colour (RGB) instead of the palette's.
    pub fn with_color(mut self, rgb: (u8, u8, u8)) -> Self {
        self.color = Some(rgb);
        self
    }
    /// Drawn with this marker shape instead of the sequence's.
    pub fn with_marker(mut self, m: Marker) -> Self {
        self.marker = Some(m);
        self
    }
}

/// A 2-D plot: lines, dashed lines and markers on linear or log axes.
#[derive(Clone, Debug)]
pub struct Plot {
    title: String,
    xlabel: String,
    ylabel: String,
    series: Vec<Series>,
    x_scale: Scale,
    y_scale: Scale,
    x_unit: String,
    y_unit: String,
    legend: bool,
    equal_aspect: bool,
    width: f64,
    height: f64,
}

impl Plot {
    /// A plot with a title and axis labels.
    pub fn new(title: &str, xlabel: &str, ylabel: &str) -> Self {
        Self {
            title: title.into(),
            xlabel: xlabel.into(),
            ylabel: ylabel.into(),
            series: vec![],
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            x_unit: String::new(),
            y_unit: String::new(),
            legend: true,
            equal_aspect: false,
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
    /// The title.
    pub fn title(&self) -> &str {
        &self.title
    }
    /// The series, in order.
    pub fn series_list(&self) -> &[Series] {
        &self.series
    }
    /// A logarithmic x axis (non-positive values are not drawn).
    pub fn log_x(mut self) -> Self {
        self.x_scale = Scale::Log;
        self
    }
    /// A logarithmic y axis (non-positive values are not drawn).
    pub fn log_y(mut self) -> Self {
        self.y_scale = Scale::Log;
        self
    }
    /// A unit written after every x tick label ("0.1 s").
    pub fn x_unit(mut self, unit: &str) -> Self {
        self.x_unit = unit.into();
        self
    }
    /// A unit written after every y tick label ("1 %").
    pub fn y_unit(mut self, unit: &str) -> Self {
        self.y_unit = unit.into();
        self
    }
    /// No legend (for plots whose points carry their own labels).
    pub fn without_legend(mut self) -> Self {
        self.legend = false;
        self
    }
    /// One data unit is as long on the x axis as on the y axis (linear
    /// axes; for drawings of mechanisms): the axis whose data would be
    /// drawn larger gets a wider range, centred on the data.
    pub fn equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }
    /// The nominal size in pixels (the figure grows where its labels need it).
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width as f64;
        self.height = height as f64;
        self
    }

    /// Every point that both axes can show.
    pub(crate) fn drawable_points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.series.iter().flat_map(move |s| {
            s.x.iter()
                .zip(&s.y)
                .map(|(x, y)| (*x, *y))
                .filter(move |(x, y)| {
                    self.x_scale.coord(*x).is_some() && self.y_scale.coord(*y).is_some()
                })
        })
    }

    /// The figure's geometry at `scale` (1 for SVG, [`PNG_SCALE`] for PNG).
    pub fn layout(&self, scale: f64) -> std::io::Result<Layout> {
        layout::layout(self, scale)
    }
}

pub use render::PNG_SCALE;
