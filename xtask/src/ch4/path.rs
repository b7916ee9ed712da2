//! The end-effector path (4.1) of thesis §4.4, parametrized by its arc
//! length s: a cubic Hermite segment from the undeflected position to
//! (r, 0), leaving along +x and arriving along +y (4.1a), then a full circle
//! of radius r counter-clockwise about the undeflected position (4.1b),
//! r = 0.05 m.
//!
//! (4.1a), read from the text's garbled layout as
//! P1(ξ) = (ξ − 2ξ² + ξ³)[r, 0] + (3ξ² − 2ξ³)[r, 0] + (ξ³ − ξ²)[0, r],
//! i.e. x = r(ξ + ξ² − ξ³), y = −r ξ²(1 − ξ): it dips to y = −4r/27 at
//! ξ = 2/3 (the benchmark specification's reading; docs/reproduce.md).

use std::f64::consts::PI;

/// The path's radius r (m).
pub const RADIUS: f64 = 0.05;

/// Gauss–Legendre nodes and weights on [0, 1] (8 points).
const GAUSS: [(f64, f64); 8] = [
    (0.019_855_071_751_231_856, 0.050_614_268_145_188_13),
    (0.101_666_761_293_186_63, 0.111_190_517_226_687_24),
    (0.237_233_795_041_835_5, 0.156_853_322_938_943_64),
    (0.408_282_678_752_175, 0.181_341_891_689_181),
    (0.591_717_321_247_825, 0.181_341_891_689_181),
    (0.762_766_204_958_164_5, 0.156_853_322_938_943_64),
    (0.898_333_238_706_813_4, 0.111_190_517_226_687_24),
    (0.980_144_928_248_768_2, 0.050_614_268_145_188_13),
];

/// The Hermite segment (4.1a) and its ξ-derivatives.
fn segment(xi: f64) -> ([f64; 2], [f64; 2], [f64; 2]) {
    let r = RADIUS;
    (
        [r * (xi + xi * xi - xi.powi(3)), -r * xi * xi * (1.0 - xi)],
        [
            r * (1.0 + 2.0 * xi - 3.0 * xi * xi),
            -r * (2.0 * xi - 3.0 * xi * xi),
        ],
        [r * (2.0 - 6.0 * xi), -r * (2.0 - 6.0 * xi)],
    )
}

fn speed(xi: f64) -> f64 {
    let (_, d, _) = segment(xi);
    d[0].hypot(d[1])
}

/// Arc length of the segment from 0 to ξ (composite Gauss–Legendre, 16
/// panels: exact to rounding for this smooth speed).
fn segment_length(xi: f64) -> f64 {
    let panels = 16;
    let h = xi / panels as f64;
    (0..panels)
        .map(|k| {
            GAUSS
                .iter()
                .map(|(x, w)| w * h * speed((k as f64 + x) * h))
                .sum::<f64>()
        })
        .sum()
}

/// The path (4.1) by arc length.
#[derive(Clone, Copy, Debug)]
pub struct Path4 {
    /// Length of the Hermite segment (m).
    pub first: f64,
}

impl Path4 {
    /// The path with r = [`RADIUS`].
    pub fn new() -> Self {
        Self {
            first: segment_length(1.0),
        }
    }

    /// Total length: the segment and the circle 2πr (m).
    pub fn length(&self) -> f64 {
        self.first + 2.0 * PI * RADIUS
    }

    /// The end-effector's (x, y) relative to its undeflected position at arc
    /// length s (clamped to the path), with its tangent dP/ds and curvature
    /// vector d²P/ds².
    pub fn at(&self, s: f64) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let s = s.clamp(0.0, self.length());
        if s <= self.first {
            // ξ(s) by Newton on the arc length, from the linear guess
            let mut xi = s / self.first;
            for _ in 0..50 {
                let f = segment_length(xi) - s;
                let step = f / speed(xi);
                xi = (xi - step).clamp(0.0, 1.0);
                if step.abs() < 1e-15 {
                    break;
                }
            }
            let (p, d, dd) = segment(xi);
            let v = d[0].hypot(d[1]);
            let t = [d[0] / v, d[1] / v];
            // d²P/ds² = (P'' − (t·P'') t)/v²
            let tp = t[0] * dd[0] + t[1] * dd[1];
            let k = [(dd[0] - tp * t[0]) / (v * v), (dd[1] - tp * t[1]) / (v * v)];
            (p, t, k)
        } else {
            let a = (s - self.first) / RADIUS;
            let (sn, cs) = a.sin_cos();
            (
                [RADIUS * cs, RADIUS * sn],
                [-sn, cs],
                [-cs / RADIUS, -sn / RADIUS],
            )
        }
    }

    /// The quarter points of the circle where the thesis's Fig. 4.13 marks
    /// locations (lost; the choice of the benchmark specification): the
    /// start of the circle, then every quarter turn, and the end (m).
    pub fn marks(&self) -> [f64; 5] {
        let q = 0.5 * PI * RADIUS;
        [
            self.first,
            self.first + q,
            self.first + 2.0 * q,
            self.first + 3.0 * q,
            self.length(),
        ]
    }
}

impl Default for Path4 {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The benchmark specification's figures: a segment of 0.05510 m, 0.3693 m
    /// in all, the dip to −4r/27 at ξ = 2/3; the path is continuous with a
    /// continuous tangent where the circle begins, and the tangent is unit.
    #[test]
    fn the_path_has_the_specified_lengths_and_a_smooth_joint() {
        let p = Path4::new();
        assert!((p.first - 0.05510).abs() < 5e-6, "{}", p.first);
        assert!((p.length() - 0.3693).abs() < 5e-5, "{}", p.length());
        let (dip, _, _) = segment(2.0 / 3.0);
        assert!((dip[1] + 4.0 * RADIUS / 27.0).abs() < 1e-15);
        let (a, ta, _) = p.at(p.first - 1e-9);
        let (b, tb, _) = p.at(p.first + 1e-9);
        assert!((a[0] - b[0]).abs() < 1e-8 && (a[1] - b[1]).abs() < 1e-8);
        assert!((ta[0] - tb[0]).abs() < 1e-6 && (ta[1] - tb[1]).abs() < 1e-6);
        // the tangent against central differences of P(s)
        for s in [0.01, 0.03, 0.05, 0.1, 0.3] {
            let h = 1e-6;
            let (_, t, k) = p.at(s);
            let (pp, tp, _) = p.at(s + h);
            let (pm, tm, _) = p.at(s - h);
            for c in 0..2 {
                assert!(((pp[c] - pm[c]) / (2.0 * h) - t[c]).abs() < 1e-6, "s = {s}");
                assert!(((tp[c] - tm[c]) / (2.0 * h) - k[c]).abs() < 1e-4, "s = {s}");
            }
            assert!((t[0].hypot(t[1]) - 1.0).abs() < 1e-12);
        }
        let (start, _, _) = p.at(0.0);
        let (end, _, _) = p.at(p.length());
        assert_eq!(start, [0.0, 0.0]);
        assert!((end[0] - RADIUS).abs() < 1e-12 && end[1].abs() < 1e-12);
    }
}
