//! Functions of time for prescribed inputs, load histories and controller
//! references, each with its first and second time derivative (the convective
//! terms need the acceleration of prescribed inputs).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A scalar function of time with exact first and second derivatives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TimeFunction {
    /// A constant value.
    Constant(f64),
    /// Linear from `v0` at `t0` to `v1` at `t1`, constant outside.
    Ramp {
        /// Start time.
        t0: f64,
        /// End time.
        t1: f64,
        /// Value up to `t0`.
        v0: f64,
        /// Value from `t1` on.
        v1: f64,
    },
    /// The raised-cosine pulse of thesis (5.24), (6.27), (3.38):
    /// A/2 (1 − cos(2πt/T)) for 0 ≤ t ≤ T, zero afterwards.
    RaisedCosinePulse {
        /// Peak value A.
        amplitude: f64,
        /// Duration T.
        duration: f64,
    },
    /// The spin-up angle of thesis (2.41): Ω/T (t²/2 − T²/(4π²)(1 − cos(2πt/T)))
    /// for t ≤ T, Ω(t − T/2) afterwards.
    SpinUp {
        /// Final angular velocity Ω.
        omega: f64,
        /// Spin-up time T.
        duration: f64,
    },
    /// A sine A sin(ωt + φ) (e.g. thesis (2.42)).
    Sine {
        /// Amplitude A.
        amplitude: f64,
        /// Angular frequency ω.
        omega: f64,
        /// Phase φ.
        phase: f64,
    },
    /// Point-to-point moves with the skew-sine profile of thesis (7.13), from
    /// `start` through each move (start time, duration T, displacement Δs),
    /// holding still between moves.
    SkewSineMoves {
        /// Initial value.
        start: f64,
        /// The moves: (t_start, T, Δs), in increasing t_start, non-overlapping.
        moves: Vec<(f64, f64, f64)>,
    },
    /// Piecewise polynomials in absolute time as in thesis (5.25): on
    /// `[breaks[i], breaks[i+1])` the value is `Σ_k coeffs[i][k] tᵏ`; before the first
    /// break the first piece, after the last break the constant `after`.
    PiecewisePolynomial {
        /// Break points (n + 1 for n pieces), increasing.
        breaks: Vec<f64>,
        /// Coefficients per piece, lowest order first, in absolute time t.
        coeffs: Vec<Vec<f64>>,
        /// Value after the last break.
        after: f64,
    },
    /// Tabulated data, interpolated linearly (derivative piecewise constant,
    /// second derivative zero), constant outside the table.
    Table {
        /// Times, increasing.
        t: Vec<f64>,
        /// Values.
        v: Vec<f64>,
    },
    /// A piecewise cubic Hermite curve through values and rates at the
    /// times `t`: on [t_i, t_i+1] the cubic with value and rate `value[i]`,
    /// `rate[i]` at t_i and `value[i+1]`, `rate[i+1]` at t_i+1, in the local
    /// time t − t_i (well conditioned for short pieces, unlike
    /// `PiecewisePolynomial`'s absolute time). C¹; constant at the end
    /// values outside [t_0, t_n] (rate and acceleration zero there).
    Hermite {
        /// Times, increasing (at least two).
        t: Vec<f64>,
        /// Values at them.
        value: Vec<f64>,
        /// Rates at them.
        rate: Vec<f64>,
    },
    /// A scaled copy: `scale` × `f`.
    Scaled {
        /// Factor.
        scale: f64,
        /// The function.
        f: Box<TimeFunction>,
    },
    /// The sum of several functions.
    Sum(Vec<TimeFunction>),
}

impl TimeFunction {
    /// (f(t), f'(t), f''(t)).
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        match self {
            TimeFunction::Constant(v) => (*v, 0.0, 0.0),
            TimeFunction::Ramp { t0, t1, v0, v1 } => {
                if t <= *t0 {
                    (*v0, 0.0, 0.0)
                } else if t >= *t1 {
                    (*v1, 0.0, 0.0)
                } else {
                    let s = (v1 - v0) / (t1 - t0);
                    (v0 + s * (t - t0), s, 0.0)
                }
            }
            TimeFunction::RaisedCosinePulse {
                amplitude,
                duration,
            } => {
                if !(0.0..=*duration).contains(&t) {
                    (0.0, 0.0, 0.0)
                } else {
                    let w = 2.0 * PI / duration;
                    let a = 0.5 * amplitude;
                    (
                        a * (1.0 - (w * t).cos()),
                        a * w * (w * t).sin(),
                        a * w * w * (w * t).cos(),
                    )
                }
            }
            TimeFunction::SpinUp { omega, duration } => {
                let tt = *duration;
                if t <= 0.0 {
                    (0.0, 0.0, 0.0)
                } else if t <= tt {
                    let w = 2.0 * PI / tt;
                    let c = omega / tt;
                    (
                        c * (0.5 * t * t - (1.0 - (w * t).cos()) / (w * w)),
                        c * (t - (w * t).sin() / w),
                        c * (1.0 - (w * t).cos()),
                    )
                } else {
                    (omega * (t - 0.5 * tt), *omega, 0.0)
                }
            }
            TimeFunction::Sine {
                amplitude,
                omega,
                phase,
            } => {
                let a = omega * t + phase;
                (
                    amplitude * a.sin(),
                    amplitude * omega * a.cos(),
                    -amplitude * omega * omega * a.sin(),
                )
            }
            TimeFunction::SkewSineMoves { start, moves } => {
                let mut s = *start;
                for &(ts, dur, ds) in moves {
                    if t <= ts {
                        break;
                    }
                    if t >= ts + dur {
                        s += ds;
                        continue;
                    }
                    let tau = t - ts;
                    let w = 2.0 * PI / dur;
                    return (
                        s + tau * ds / dur - ds / (2.0 * PI) * (w * tau).sin(),
                        ds / dur * (1.0 - (w * tau).cos()),
                        2.0 * PI * ds / (dur * dur) * (w * tau).sin(),
                    );
                }
                (s, 0.0, 0.0)
            }
            TimeFunction::PiecewisePolynomial {
                breaks,
                coeffs,
                after,
            } => {
                if t >= *breaks.last().unwrap_or(&f64::INFINITY) {
                    return (*after, 0.0, 0.0);
                }
                let i = breaks
                    .iter()
                    .rposition(|b| t >= *b)
                    .unwrap_or(0)
                    .min(coeffs.len().saturating_sub(1));
                let c = &coeffs[i];
                let (mut v, mut d, mut dd) = (0.0, 0.0, 0.0);
                for (k, ck) in c.iter().enumerate() {
                    let kf = k as f64;
                    v += ck * t.powi(k as i32);
                    if k >= 1 {
                        d += kf * ck * t.powi(k as i32 - 1);
                    }
                    if k >= 2 {
                        dd += kf * (kf - 1.0) * ck * t.powi(k as i32 - 2);
                    }
                }
                (v, d, dd)
            }
            TimeFunction::Table { t: ts, v } => {
                if t <= ts[0] {
                    return (v[0], 0.0, 0.0);
                }
                if t >= ts[ts.len() - 1] {
                    return (v[v.len() - 1], 0.0, 0.0);
                }
                let i = ts.partition_point(|x| *x <= t) - 1;
                let s = (v[i + 1] - v[i]) / (ts[i + 1] - ts[i]);
                (v[i] + s * (t - ts[i]), s, 0.0)
            }
            TimeFunction::Hermite { t: ts, value, rate } => {
                let n = ts.len();
                if t <= ts[0] {
                    return (value[0], 0.0, 0.0);
                }
                if t >= ts[n - 1] {
                    return (value[n - 1], 0.0, 0.0);
                }
                let i = ts.partition_point(|x| *x <= t) - 1;
                hermite_piece(
                    ts[i + 1] - ts[i],
                    [value[i], rate[i]],
                    [value[i + 1], rate[i + 1]],
                    t - ts[i],
                )
            }
            TimeFunction::Scaled { scale, f } => {
                let (a, b, c) = f.eval(t);
                (scale * a, scale * b, scale * c)
            }
            TimeFunction::Sum(fs) => fs.iter().fold((0.0, 0.0, 0.0), |acc, f| {
                let (a, b, c) = f.eval(t);
                (acc.0 + a, acc.1 + b, acc.2 + c)
            }),
        }
    }

    /// The value f(t).
    pub fn value(&self, t: f64) -> f64 {
        self.eval(t).0
    }

    /// Checks the parameters; the error text says what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let fin = |name: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(format!("{name} is {v}"))
            }
        };
        match self {
            TimeFunction::Constant(v) => fin("constant value", *v),
            TimeFunction::Ramp { t0, t1, v0, v1 } => {
                for (n, v) in [("t0", t0), ("t1", t1), ("v0", v0), ("v1", v1)] {
                    fin(n, *v)?;
                }
                if t1 <= t0 {
                    return Err(format!("ramp needs t1 > t0, got t0 = {t0}, t1 = {t1}"));
                }
                Ok(())
            }
            TimeFunction::RaisedCosinePulse {
                amplitude,
                duration,
            }
            | TimeFunction::SpinUp {
                omega: amplitude,
                duration,
            } => {
                fin("amplitude", *amplitude)?;
                if !(duration.is_finite() && *duration > 0.0) {
                    return Err(format!("duration must be positive, got {duration}"));
                }
                Ok(())
            }
            TimeFunction::Sine {
                amplitude,
                omega,
                phase,
            } => {
                fin("amplitude", *amplitude)?;
                fin("omega", *omega)?;
                fin("phase", *phase)
            }
            TimeFunction::SkewSineMoves { start, moves } => {
                fin("start", *start)?;
                let mut last = f64::NEG_INFINITY;
                for (i, &(ts, d, ds)) in moves.iter().enumerate() {
                    if !(ts.is_finite() && d.is_finite() && d > 0.0 && ds.is_finite()) {
                        return Err(format!("move {i} = ({ts}, {d}, {ds}) must have finite values and positive duration"));
                    }
                    if ts < last {
                        return Err(format!(
                            "move {i} starts at {ts}, before the previous move ends at {last}"
                        ));
                    }
                    last = ts + d;
                }
                Ok(())
            }
            TimeFunction::PiecewisePolynomial {
                breaks,
                coeffs,
                after,
            } => {
                fin("after", *after)?;
                if breaks.len() != coeffs.len() + 1 || coeffs.is_empty() {
                    return Err(format!(
                        "piecewise polynomial needs n + 1 breaks for n pieces, got {} breaks and {} pieces",
                        breaks.len(),
                        coeffs.len()
                    ));
                }
                if breaks.iter().any(|b| !b.is_finite()) || breaks.windows(2).any(|w| w[1] <= w[0])
                {
                    return Err("piecewise polynomial breaks must be finite and increasing".into());
                }
                if coeffs.iter().flatten().any(|c| !c.is_finite()) {
                    return Err("piecewise polynomial coefficients must be finite".into());
                }
                Ok(())
            }
            TimeFunction::Table { t, v } => {
                if t.is_empty() || t.len() != v.len() {
                    return Err(format!(
                        "table needs equal, non-zero numbers of times and values, got {} and {}",
                        t.len(),
                        v.len()
                    ));
                }
                if t.iter().chain(v).any(|x| !x.is_finite()) || t.windows(2).any(|w| w[1] <= w[0]) {
                    return Err("table times must be finite and increasing, values finite".into());
                }
                Ok(())
            }
            TimeFunction::Hermite { t, value, rate } => {
                if t.len() < 2 || value.len() != t.len() || rate.len() != t.len() {
                    return Err(format!(
                        "Hermite needs at least two times and as many values and rates, got {}, {} and {}",
                        t.len(),
                        value.len(),
                        rate.len()
                    ));
                }
                if let Some(i) = t
                    .windows(2)
                    .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
                {
                    return Err(format!(
                        "Hermite times must increase: t[{}] = {} is followed by {}",
                        i,
                        t[i],
                        t[i + 1]
                    ));
                }
                for (name, v) in [("t", t), ("value", value), ("rate", rate)] {
                    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                        return Err(format!("Hermite {name}[{i}] is {}", v[i]));
                    }
                }
                Ok(())
            }
            TimeFunction::Scaled { scale, f } => {
                fin("scale", *scale)?;
                f.validate()
            }
            TimeFunction::Sum(fs) => fs.iter().try_for_each(|f| f.validate()),
        }
    }
}

/// The cubic on a piece of length `h` with value and rate `a` at its start
/// and `b` at its end, and its first two derivatives, at the local time τ.
fn hermite_piece(h: f64, a: [f64; 2], b: [f64; 2], tau: f64) -> (f64, f64, f64) {
    // p = a0 + a1 τ + c2 τ² + c3 τ³
    let c2 = (3.0 * (b[0] - a[0]) / h - 2.0 * a[1] - b[1]) / h;
    let c3 = (2.0 * (a[0] - b[0]) / h + a[1] + b[1]) / (h * h);
    (
        a[0] + tau * (a[1] + tau * (c2 + tau * c3)),
        a[1] + tau * (2.0 * c2 + 3.0 * tau * c3),
        2.0 * c2 + 6.0 * tau * c3,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(f: &TimeFunction, ts: &[f64]) {
        let h = 1e-6;
        for &t in ts {
            let (_, d, dd) = f.eval(t);
            let fd = (f.value(t + h) - f.value(t - h)) / (2.0 * h);
            let fdd = (f.eval(t + h).1 - f.eval(t - h).1) / (2.0 * h);
            assert!(
                (d - fd).abs() < 1e-6 * (1.0 + d.abs()),
                "{f:?} at {t}: {d} vs {fd}"
            );
            assert!(
                (dd - fdd).abs() < 1e-5 * (1.0 + dd.abs()),
                "{f:?} at {t}: {dd} vs {fdd}"
            );
        }
    }

    #[test]
    fn derivatives_match_differences() {
        check_derivatives(
            &TimeFunction::RaisedCosinePulse {
                amplitude: 100.0,
                duration: 0.1,
            },
            &[0.01, 0.05, 0.09],
        );
        check_derivatives(
            &TimeFunction::SpinUp {
                omega: 4.0,
                duration: 15.0,
            },
            &[1.0, 7.0, 14.0, 16.0],
        );
        check_derivatives(
            &TimeFunction::Sine {
                amplitude: 0.01,
                omega: 15.0,
                phase: 0.0,
            },
            &[0.3, 2.0],
        );
        check_derivatives(
            &TimeFunction::SkewSineMoves {
                start: 0.0,
                moves: vec![(0.05, 0.25, 0.1), (0.35, 0.25, -0.05)],
            },
            &[0.1, 0.2, 0.4, 0.55],
        );
    }

    /// Pieces of 1 ms late in a run (the chapter-7 angle references): the
    /// ends' values and rates to rounding, derivatives against differences,
    /// C¹ across the knots; outside the times the end values.
    #[test]
    fn hermite_pieces_keep_their_end_values_and_rates() {
        let t = vec![1.2, 1.201, 1.202];
        let f = TimeFunction::Hermite {
            t: t.clone(),
            value: vec![0.3, 0.298, 0.2961],
            rate: vec![-2.0, -1.9, -1.85],
        };
        f.validate().unwrap();
        let (v0, d0, _) = f.eval(1.2 + 1e-15);
        assert!((v0 - 0.3).abs() < 1e-14 && (d0 + 2.0).abs() < 1e-9);
        for (k, (v, r)) in [(0.298, -1.9), (0.2961, -1.85)].into_iter().enumerate() {
            let knot = t[k + 1];
            let (l, dl, _) = f.eval(knot - 1e-13);
            let (a, da, _) = f.eval(knot);
            assert!(
                (a - v).abs() < 1e-14 && (l - v).abs() < 1e-12,
                "{k}: {l} {a} {v}"
            );
            if k == 0 {
                assert!(
                    (da - r).abs() < 1e-9 && (dl - r).abs() < 1e-7,
                    "{k}: {dl} {da} {r}"
                );
            }
        }
        check_derivatives(&f, &[1.2003, 1.2017]);
        assert_eq!(f.eval(1.0), (0.3, 0.0, 0.0));
        assert_eq!(f.eval(2.0), (0.2961, 0.0, 0.0));
    }

    #[test]
    fn spin_up_is_continuous_at_the_end_of_the_ramp() {
        let f = TimeFunction::SpinUp {
            omega: 4.0,
            duration: 15.0,
        };
        let (a, b, _) = f.eval(15.0 - 1e-12);
        let (c, d, _) = f.eval(15.0 + 1e-12);
        assert!((a - c).abs() < 1e-9 && (b - d).abs() < 1e-9);
        assert!((c - 4.0 * 7.5).abs() < 1e-9);
    }

    #[test]
    fn manipulator_reference_of_thesis_5_25_is_continuous() {
        // φ1(t) of (5.25)
        let q = std::f64::consts::FRAC_PI_4;
        let f = TimeFunction::PiecewisePolynomial {
            breaks: vec![0.0, 1.0 / 6.0, 1.0 / 3.0, 0.5],
            coeffs: vec![
                vec![-q, 0.0, 0.0, 72.0 * q],
                vec![0.0, -18.0 * q, 108.0 * q, -144.0 * q],
                vec![-8.0 * q, 54.0 * q, -108.0 * q, 72.0 * q],
            ],
            after: q,
        };
        for b in [1.0 / 6.0, 1.0 / 3.0, 0.5] {
            let (a, da, _) = f.eval(b - 1e-9);
            let (c, dc, _) = f.eval(b + 1e-9);
            assert!(
                (a - c).abs() < 1e-7 && (da - dc).abs() < 1e-6,
                "at {b}: {a} {c} {da} {dc}"
            );
        }
        assert!((f.value(0.0) + q).abs() < 1e-15);
        assert!((f.value(1.0) - q).abs() < 1e-15);
    }

    #[test]
    fn invalid_parameters_are_reported() {
        assert!(TimeFunction::Ramp {
            t0: 1.0,
            t1: 1.0,
            v0: 0.0,
            v1: 1.0
        }
        .validate()
        .unwrap_err()
        .contains("t1 > t0"));
        assert!(TimeFunction::Table {
            t: vec![0.0, 1.0],
            v: vec![1.0]
        }
        .validate()
        .is_err());
        assert!(TimeFunction::Constant(f64::NAN).validate().is_err());
        let hermite = |t: Vec<f64>, value: Vec<f64>, rate: Vec<f64>| {
            TimeFunction::Hermite { t, value, rate }
                .validate()
                .unwrap_err()
        };
        assert!(hermite(vec![0.0, 1.0], vec![0.0], vec![0.0, 0.0]).contains("as many values"));
        assert!(hermite(vec![0.0, 0.0], vec![0.0; 2], vec![0.0; 2]).contains("t[0] = 0"));
        assert!(hermite(vec![0.0, 1.0], vec![0.0, f64::NAN], vec![0.0; 2]).contains("value[1]"));
    }
}
