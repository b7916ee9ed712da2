//! Axis scales, ranges with padding, and tick positions and labels.
//!
//! A logarithmic axis is ticked at powers of ten; when its range spans two
//! decades or less, also at 2 and 5 times a power of ten, and at every
//! integer multiple when it spans less than about half a decade. Tick labels
//! are plain decimals (0.01, 0.2, 5, 1000) with an optional unit
//! ("0.01 s", "1 %"); outside 10⁻⁴ … 10⁶ they are written as powers of ten
//! ("10⁻⁵", "2·10⁻⁵").

/// How values map to an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Equal distances for equal differences.
    Linear,
    /// Equal distances for equal ratios (non-positive values are not drawn).
    Log,
}

/// The drawn range of one axis, in data units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Value at the left (x) or bottom (y) edge of the plot area.
    pub lo: f64,
    /// Value at the right (x) or top (y) edge of the plot area.
    pub hi: f64,
    /// The axis' scale.
    pub scale: Scale,
}

impl Scale {
    /// The value in the axis' linear coordinate (log10 for a log axis);
    /// `None` for a value this axis cannot show.
    pub fn coord(self, v: f64) -> Option<f64> {
        match self {
            _ if !v.is_finite() => None,
            Scale::Linear => Some(v),
            Scale::Log if v > 0.0 => Some(v.log10()),
            Scale::Log => None,
        }
    }
    /// Inverse of [`Scale::coord`].
    pub fn value(self, c: f64) -> f64 {
        match self {
            Scale::Linear => c,
            Scale::Log => 10f64.powf(c),
        }
    }
}

impl Range {
    /// Where `v` lies along the axis: 0 at `lo`, 1 at `hi`; `None` for a
    /// value the axis cannot show.
    pub fn fraction(&self, v: f64) -> Option<f64> {
        let (a, b) = (self.scale.coord(self.lo)?, self.scale.coord(self.hi)?);
        Some((self.scale.coord(v)? - a) / (b - a))
    }

    /// The range that shows the data extent `[lo, hi]` (axis coordinates
    /// from [`Scale::coord`]) on an axis `len` pixels long with `m_lo` and
    /// `m_hi` pixels left free at its two ends. A single value gets a range
    /// around it.
    pub fn padded(scale: Scale, lo: f64, hi: f64, len: f64, m_lo: f64, m_hi: f64) -> Range {
        let (mut a, mut b) = (lo, hi);
        if !(a.is_finite() && b.is_finite()) || a > b {
            (a, b) = match scale {
                Scale::Linear => (0.0, 1.0),
                Scale::Log => (0.0, 1.0),
            };
        }
        if b - a <= 1e-12 * a.abs().max(b.abs()) {
            let d = match scale {
                Scale::Log => 0.5,
                Scale::Linear if a == 0.0 => 1.0,
                Scale::Linear => 0.1 * a.abs(),
            };
            a -= d;
            b += d;
        }
        let inner = (len - m_lo - m_hi).max(0.2 * len).max(1.0);
        let per_px = (b - a) / inner;
        Range {
            lo: scale.value(a - m_lo * per_px),
            hi: scale.value(b + m_hi * per_px),
            scale,
        }
    }
}

/// One tick of an axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// Its value, in data units.
    pub value: f64,
    /// Its label; empty for an unlabelled (minor) tick.
    pub label: String,
}

/// A "nice" step (1, 2 or 5 times a power of ten) giving about `n` steps over `range`.
pub(crate) fn nice_step(range: f64, n: usize) -> f64 {
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

/// A linear tick label: as many decimals as the step needs.
pub(crate) fn fmt_tick(v: f64, step: f64) -> String {
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

fn superscript(n: i32) -> String {
    const D: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(D[c as usize - '0' as usize]);
    }
    s
}

/// The label of `m · 10^k` (`m` an integer 1–9) on a log axis.
pub(crate) fn fmt_log(m: u32, k: i32) -> String {
    if (-4..6).contains(&k) {
        let v = m as f64 * 10f64.powi(k);
        let dec = (-k).max(0) as usize;
        format!("{v:.dec$}")
    } else if m == 1 {
        format!("10{}", superscript(k))
    } else {
        format!("{m}·10{}", superscript(k))
    }
}

fn with_unit(s: String, unit: &str) -> String {
    if unit.is_empty() {
        s
    } else {
        format!("{s} {unit}")
    }
}

/// Ticks of a linear range with about `n` steps.
pub(crate) fn linear_ticks(r: &Range, n: usize, unit: &str) -> Vec<Tick> {
    let (lo, hi) = (r.lo.min(r.hi), r.lo.max(r.hi));
    let step = nice_step(hi - lo, n);
    let mut out = vec![];
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    for i in first..=last {
        let v = i as f64 * step;
        out.push(Tick {
            value: v,
            label: with_unit(fmt_tick(v, step), unit),
        });
    }
    out
}

/// Ticks of a log range. `labels_between` says whether ticks other than
/// powers of ten are labelled; unlabelled ones are minor ticks.
pub(crate) fn log_ticks(r: &Range, labels_between: bool, unit: &str) -> Vec<Tick> {
    let (a, b) = (r.lo.min(r.hi).log10(), r.lo.max(r.hi).log10());
    let decades = b - a;
    // mantissas ticked, and those labelled
    let (ticked, labelled): (&[u32], &[u32]) = if decades > 6.0 {
        (&[1], &[1])
    } else if decades > 2.0 {
        (&[1, 2, 3, 4, 5, 6, 7, 8, 9], &[1])
    } else if decades > 0.6 {
        (&[1, 2, 3, 4, 5, 6, 7, 8, 9], &[1, 2, 5])
    } else {
        (&[1, 2, 3, 4, 5, 6, 7, 8, 9], &[1, 2, 3, 4, 5, 6, 7, 8, 9])
    };
    // label every k-th decade when there are many
    let every = ((decades / 8.0).ceil() as i32).max(1);
    let mut out = vec![];
    for k in (a.floor() as i32)..=(b.ceil() as i32) {
        for &m in ticked {
            let v = m as f64 * 10f64.powi(k);
            let c = v.log10();
            if c < a - 1e-12 || c > b + 1e-12 {
                continue;
            }
            let lab = if m == 1 {
                k.rem_euclid(every) == 0
            } else {
                labels_between && labelled.contains(&m)
            };
            out.push(Tick {
                value: v,
                label: if lab {
                    with_unit(fmt_log(m, k), unit)
                } else {
                    String::new()
                },
            });
        }
    }
    if out.iter().filter(|t| !t.label.is_empty()).count() < 2 {
        // less than two labelled ticks: a linear division of the range
        return linear_ticks(r, 4, unit)
            .into_iter()
            .filter(|t| t.value > 0.0)
            .collect();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lr(lo: f64, hi: f64) -> Range {
        Range {
            lo,
            hi,
            scale: Scale::Log,
        }
    }

    #[test]
    fn a_tick_at_rounding_distance_from_zero_is_zero() {
        assert_eq!(fmt_tick(-5.551115123125783e-17, 0.05), "0");
        assert_eq!(fmt_tick(0.05, 0.05), "0.05");
        assert_eq!(fmt_tick(-2e-4, 1e-4), "-2.0e-4");
    }

    #[test]
    fn log_labels_read_as_decimals_or_powers_of_ten() {
        assert_eq!(fmt_log(1, -2), "0.01");
        assert_eq!(fmt_log(5, -1), "0.5");
        assert_eq!(fmt_log(1, 0), "1");
        assert_eq!(fmt_log(2, 3), "2000");
        assert_eq!(fmt_log(1, -5), "10⁻⁵");
        assert_eq!(fmt_log(2, -12), "2·10⁻¹²");
        assert_eq!(fmt_log(1, 7), "10⁷");
    }

    #[test]
    fn wide_log_ranges_are_labelled_at_powers_of_ten_only() {
        let t = log_ticks(&lr(0.013, 42.0), true, "s");
        let labelled: Vec<&Tick> = t.iter().filter(|t| !t.label.is_empty()).collect();
        let labels: Vec<&str> = labelled.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, ["0.1 s", "1 s", "10 s"]);
        for t in labelled {
            let e = t.value.log10();
            assert!(
                (e - e.round()).abs() < 1e-12,
                "{} is no power of ten",
                t.value
            );
        }
        // minor ticks at 2..9 times the decades, inside the range
        assert!(t.iter().any(|t| (t.value - 0.02).abs() < 1e-15));
        assert!(t.iter().all(|t| t.value >= 0.013 && t.value <= 42.0));
    }

    #[test]
    fn narrow_log_ranges_get_two_and_five() {
        let t = log_ticks(&lr(0.03, 0.9), true, "%");
        let labels: Vec<&str> = t
            .iter()
            .filter(|t| !t.label.is_empty())
            .map(|t| t.label.as_str())
            .collect();
        assert_eq!(labels, ["0.05 %", "0.1 %", "0.2 %", "0.5 %"]);
        // without room for them, only the decade is labelled ... and then
        // the range falls back to a linear division (two labels at least)
        let t = log_ticks(&lr(0.03, 0.9), false, "");
        assert!(t.iter().filter(|t| !t.label.is_empty()).count() >= 2);
    }

    #[test]
    fn many_decades_thin_the_labels() {
        let t = log_ticks(&lr(1e-16, 1.0), true, "");
        let n = t.iter().filter(|t| !t.label.is_empty()).count();
        assert!((5..=9).contains(&n), "{n} labels");
        assert!(t.iter().any(|t| t.label == "10⁻¹⁶"));
    }

    #[test]
    fn padding_leaves_the_requested_pixels_free() {
        let r = Range::padded(Scale::Log, -2.0, 0.0, 500.0, 10.0, 20.0);
        let f0 = r.fraction(0.01).unwrap();
        let f1 = r.fraction(1.0).unwrap();
        assert!((f0 * 500.0 - 10.0).abs() < 1e-9);
        assert!(((1.0 - f1) * 500.0 - 20.0).abs() < 1e-9);
        // a single value is centred in a range of its own
        let r = Range::padded(Scale::Linear, 3.0, 3.0, 500.0, 10.0, 10.0);
        assert!((r.fraction(3.0).unwrap() - 0.5).abs() < 1e-12);
        assert!(r.lo < 3.0 && r.hi > 3.0);
        assert_eq!(Scale::Log.coord(-1.0), None);
        assert_eq!(Scale::Log.coord(f64::NAN), None);
    }
}
