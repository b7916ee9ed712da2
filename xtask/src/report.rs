//! Markdown tables and the helpers the chapter reports share.

use std::fmt::Write;

/// The machine's one-minute load average (`/proc/loadavg`) as a phrase for
/// a report's wall times, such as "load average 0.17 at the start", or
/// "load average unknown" where the system does not say. A report's times mean little without it
/// on a 2-core machine that also builds.
pub fn load_average_phrase() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_owned))
        .map(|l| format!("load average {l} at the start"))
        .unwrap_or_else(|| "load average unknown".into())
}

/// A markdown table.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column titles.
    pub fn new(header: &[&str]) -> Self {
        Self {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: vec![],
        }
    }
    /// Appends a row.
    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }
    /// The table as markdown.
    pub fn render(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "| {} |", self.header.join(" | "));
        let _ = writeln!(
            s,
            "|{}|",
            self.header
                .iter()
                .map(|_| "---")
                .collect::<Vec<_>>()
                .join("|")
        );
        for r in &self.rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        s
    }
}

/// A number with about four significant digits, without exponent for
/// ordinary magnitudes.
pub fn sig(v: f64) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e9).contains(&a) {
        format!("{v:.3e}")
    } else if a >= 1000.0 {
        format!("{v:.0}")
    } else {
        let digits = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    }
}

/// A relative quantity as a percentage.
pub fn pct(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v.abs() < 1e-4 {
        format!("{:.1e} %", 100.0 * v)
    } else {
        format!("{:.2} %", 100.0 * v)
    }
}

/// Linear interpolation of y(x) at `at` (x ascending; clamped at the ends).
pub fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    let n = x.len();
    if n == 0 {
        return f64::NAN;
    }
    if at <= x[0] {
        return y[0];
    }
    if at >= x[n - 1] {
        return y[n - 1];
    }
    let i = x.partition_point(|v| *v <= at).min(n - 1).max(1);
    let w = (at - x[i - 1]) / (x[i] - x[i - 1]);
    y[i - 1] + w * (y[i] - y[i - 1])
}

/// RMS and maximum absolute difference of two equally sampled signals.
pub fn rms_and_max(a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = a.len().min(b.len());
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let (mut s, mut m) = (0.0, 0.0f64);
    for i in 0..n {
        let d = a[i] - b[i];
        s += d * d;
        m = m.max(d.abs());
    }
    ((s / n as f64).sqrt(), m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helpers() {
        assert_eq!(interpolate(&[0.0, 1.0, 2.0], &[0.0, 10.0, 0.0], 0.25), 2.5);
        assert_eq!(interpolate(&[0.0, 1.0], &[1.0, 3.0], 5.0), 3.0);
        let (r, m) = rms_and_max(&[0.0, 0.0], &[3.0, -4.0]);
        assert!((r - 12.5f64.sqrt()).abs() < 1e-15 && m == 4.0);
        assert_eq!(sig(1060595.0), "1060595");
        assert_eq!(sig(5.3312), "5.331");
        let mut t = Table::new(&["a", "b"]);
        t.row(vec!["1".into(), "2".into()]);
        assert_eq!(t.render(), "| a | b |\n|---|---|\n| 1 | 2 |\n");
    }
}

/// One row of a speed-against-error table.
#[derive(Clone, Debug, Default)]
pub struct ModelRow {
    /// Model name.
    pub name: String,
    /// Number of integrated coordinates.
    pub size: usize,
    /// Integrator and tolerances.
    pub settings: String,
    /// Function (right-hand side or residual) evaluations.
    pub evaluations: u64,
    /// Wall time of the integration (s).
    pub wall_time: f64,
    /// Largest relative error over the stroke of each retained eigenfrequency
    /// with respect to the unreduced model: (mode number from 1, error).
    pub freq_error: Vec<(usize, f64)>,
    /// True for the reference model the errors are measured against.
    pub reference: bool,
    /// Time-response errors: (signal, RMS, max, scale used for the relative values).
    pub response_error: Vec<(String, f64, f64, f64)>,
}

/// The speed-against-error table of a chapter.
pub fn speed_vs_error_table(rows: &[ModelRow]) -> String {
    let signals: Vec<String> = rows
        .iter()
        .flat_map(|r| r.response_error.iter().map(|e| e.0.clone()))
        .fold(vec![], |mut v, s| {
            if !v.contains(&s) {
                v.push(s);
            }
            v
        });
    let mut modes: Vec<usize> = rows
        .iter()
        .flat_map(|r| r.freq_error.iter().map(|e| e.0))
        .collect();
    modes.sort_unstable();
    modes.dedup();
    let mut head: Vec<String> = vec![
        "model".into(),
        "n".into(),
        "integrator, tolerances".into(),
        "wall time (s)".into(),
        "evaluations".into(),
        "evaluations/s".into(),
    ];
    head.extend(modes.iter().map(|k| format!("max err ω{k}")));
    for s in &signals {
        head.push(format!("{s} RMS err"));
        head.push(format!("{s} max err"));
    }
    let h: Vec<&str> = head.iter().map(|s| s.as_str()).collect();
    let mut t = Table::new(&h);
    for r in rows {
        let mut c = vec![
            r.name.clone(),
            r.size.to_string(),
            r.settings.clone(),
            format!("{:.3}", r.wall_time),
            r.evaluations.to_string(),
            sig(r.evaluations as f64 / r.wall_time.max(1e-9)),
        ];
        for k in &modes {
            c.push(
                r.freq_error
                    .iter()
                    .find(|e| e.0 == *k)
                    .map(|e| pct(e.1))
                    .unwrap_or_else(|| "–".into()),
            );
        }
        for s in &signals {
            match r.response_error.iter().find(|e| &e.0 == s) {
                _ if r.reference => {
                    c.push("reference".into());
                    c.push("reference".into());
                }
                Some((_, rms, max, scale)) => {
                    c.push(pct(rms / scale));
                    c.push(pct(max / scale));
                }
                None => {
                    c.push("–".into());
                    c.push("–".into());
                }
            }
        }
        t.row(c);
    }
    t.render()
}

/// The speed-against-error plot: wall time against the largest error over
/// the retained eigenfrequencies and the time responses, on log–log axes
/// (ticks in s and %), one labelled point per model; `error` names what the
/// error is of (the y label).
pub fn speed_vs_error_plot(title: &str, error: &str, rows: &[ModelRow]) -> flexmb_plot::Plot {
    let mut p = flexmb_plot::Plot::new(title, "wall time of the integration", error)
        .log_x()
        .log_y()
        .x_unit("s")
        .y_unit("%")
        .without_legend();
    for r in rows {
        let e = r
            .freq_error
            .iter()
            .map(|e| e.1)
            .chain(r.response_error.iter().map(|(_, _, m, s)| m / s))
            .fold(0.0f64, f64::max);
        if e > 0.0 && r.wall_time > 0.0 {
            p.push(flexmb_plot::Series::labelled_point(
                &r.name,
                r.wall_time,
                100.0 * e,
            ));
        }
    }
    p
}

/// The figures of one report: each saved as SVG and PNG side by side, and
/// listed in the Markdown with its PNG embedded and its SVG linked.
#[derive(Default)]
pub struct Figures {
    saved: Vec<(String, String)>,
}

impl Figures {
    /// Saves `plot` as `dir/stem.svg` and `dir/stem.png`.
    pub fn save(
        &mut self,
        plot: &flexmb_plot::Plot,
        dir: &std::path::Path,
        stem: &str,
    ) -> std::io::Result<()> {
        plot.save_both(&dir.join(stem))?;
        self.saved.push((stem.into(), plot.title().into()));
        Ok(())
    }

    /// The Markdown of the figures whose file stem passes `pick`, in the
    /// order they were saved.
    pub fn markdown(&self, pick: impl Fn(&str) -> bool) -> String {
        let mut s = String::new();
        for (stem, title) in self.saved.iter().filter(|(f, _)| pick(f)) {
            let _ = writeln!(
                s,
                "![{title}]({stem}.png)\n\n`{stem}` ([SVG]({stem}.svg))\n"
            );
        }
        s
    }
}
