//! The shape of a beam for drawing (VTK boxes, `flexmb draw`): its
//! cross-section, the section's frame at the reference configuration, and
//! at a configuration the centre line with a section frame at stations
//! along it.
//!
//! The centre line of a beam element is the cubic Hermite curve from node
//! p to node q whose end tangents are the beam's local x axes at its nodes
//! (the node frames turned since the start times the reference frame),
//! scaled by the chord length: the Euler–Bernoulli deflection shape, which
//! the element's bending deformations (end rotations against the chord)
//! describe. The section's y axis at a station is the linear blend of the
//! end y axes made normal to the tangent; z completes the frame. Drawing
//! only: no deformation is computed from it.

use flexmb_element::SectionShape;
use flexmb_rotation::generic::rotation;

/// A beam's cross-section and its frame at the reference configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct BeamSection {
    /// The section.
    pub shape: SectionShape,
    /// The beam's local axes at the reference configuration, as columns:
    /// x along the beam (p → q), y and z the section's axes (global
    /// components; planar beams: z = global z).
    pub frame: [[f64; 3]; 3],
    /// A planar beam (coordinates x, y, φ per node) rather than a spatial one
    /// (r, λ per node).
    pub planar: bool,
}

/// A point of the centre line with the section's frame there (columns x,
/// y, z).
pub type Station = ([f64; 3], [[f64; 3]; 3]);

fn column(m: &[[f64; 3]; 3], j: usize) -> [f64; 3] {
    [m[0][j], m[1][j], m[2][j]]
}

fn matmul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 0.0 {
        v.map(|c| c / n)
    } else {
        v
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl BeamSection {
    /// The box drawn for the section, (width along y, height along z): a
    /// rectangle's sides, a circle's or a tube's outer diameter both ways, a
    /// user section's √A both ways (its shape is not known).
    pub fn box_size(&self) -> [f64; 2] {
        match self.shape {
            SectionShape::Rectangle { by, bz } => [by, bz],
            SectionShape::Circle { d } => [d, d],
            SectionShape::Tube { d_outer, .. } => [d_outer, d_outer],
            SectionShape::User(p) => [p.area.sqrt(); 2],
        }
    }

    /// The section's area (m²).
    pub fn area(&self) -> f64 {
        let quarter_pi = std::f64::consts::FRAC_PI_4;
        match self.shape {
            SectionShape::Rectangle { by, bz } => by * bz,
            SectionShape::Circle { d } => quarter_pi * d * d,
            SectionShape::Tube { d_outer, d_inner } => {
                quarter_pi * (d_outer * d_outer - d_inner * d_inner)
            }
            SectionShape::User(p) => p.area,
        }
    }

    /// A code of the shape (1 rectangle, 2 circle, 3 tube, 4 given
    /// properties) and its dimensions (rectangle: by, bz, 0; circle: d, d,
    /// 0; tube: d_outer, d_outer, d_inner; given properties: 0, 0, 0).
    pub fn code_and_dimensions(&self) -> (i32, [f64; 3]) {
        match self.shape {
            SectionShape::Rectangle { by, bz } => (1, [by, bz, 0.0]),
            SectionShape::Circle { d } => (2, [d, d, 0.0]),
            SectionShape::Tube { d_outer, d_inner } => (3, [d_outer, d_outer, d_inner]),
            SectionShape::User(_) => (4, [0.0; 3]),
        }
    }

    /// The positions and local frames of the two nodes from the element's
    /// coordinates as it measures them (`local`: planar x, y, φ per node;
    /// spatial r, λ per node, rotations since the start).
    pub fn ends(&self, local: &[f64]) -> [Station; 2] {
        std::array::from_fn(|end| {
            if self.planar {
                let o = 3 * end;
                let (s, c) = local[o + 2].sin_cos();
                let turn = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
                ([local[o], local[o + 1], 0.0], matmul(&turn, &self.frame))
            } else {
                let o = 7 * end;
                let mut lam = [local[o + 3], local[o + 4], local[o + 5], local[o + 6]];
                let n = lam.iter().map(|v| v * v).sum::<f64>().sqrt();
                if n > 0.0 {
                    lam.iter_mut().for_each(|v| *v /= n);
                }
                let r = rotation(&lam);
                let turn = r.0;
                (
                    [local[o], local[o + 1], local[o + 2]],
                    matmul(&turn, &self.frame),
                )
            }
        })
    }

    /// `n + 1` stations (n ≥ 1) from node p to node q along the centre line
    /// (see the module docs) of the element with coordinates `local`.
    pub fn stations(&self, local: &[f64], n: usize) -> Vec<Station> {
        let n = n.max(1);
        let [(rp, fp), (rq, fq)] = self.ends(local);
        let chord: [f64; 3] = std::array::from_fn(|d| rq[d] - rp[d]);
        let l = dot(chord, chord).sqrt();
        let (tp, tq) = (column(&fp, 0).map(|v| v * l), column(&fq, 0).map(|v| v * l));
        let (yp, yq) = (column(&fp, 1), column(&fq, 1));
        (0..=n)
            .map(|k| {
                let s = k as f64 / n as f64;
                let (s2, s3) = (s * s, s * s * s);
                let h = [
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    s3 - 2.0 * s2 + s,
                    -2.0 * s3 + 3.0 * s2,
                    s3 - s2,
                ];
                let dh = [
                    6.0 * s2 - 6.0 * s,
                    3.0 * s2 - 4.0 * s + 1.0,
                    -6.0 * s2 + 6.0 * s,
                    3.0 * s2 - 2.0 * s,
                ];
                let pos = std::array::from_fn(|d| {
                    h[0] * rp[d] + h[1] * tp[d] + h[2] * rq[d] + h[3] * tq[d]
                });
                let mut x = normalize(std::array::from_fn(|d| {
                    dh[0] * rp[d] + dh[1] * tp[d] + dh[2] * rq[d] + dh[3] * tq[d]
                }));
                if dot(x, x) == 0.0 {
                    x = column(&fp, 0);
                }
                let blend: [f64; 3] = std::array::from_fn(|d| (1.0 - s) * yp[d] + s * yq[d]);
                let y = normalize(std::array::from_fn(|d| blend[d] - dot(blend, x) * x[d]));
                let z = cross(x, y);
                let frame = std::array::from_fn(|i| [x[i], y[i], z[i]]);
                (pos, frame)
            })
            .collect()
    }

    /// The four corners of the section's box at a station, turning about
    /// its x axis: (−y, −z), (+y, −z), (+y, +z), (−y, +z) half-sizes.
    pub fn corners(&self, station: &Station) -> [[f64; 3]; 4] {
        let [w, h] = self.box_size();
        let (c, f) = station;
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(a, b)| std::array::from_fn(|d| c[d] + 0.5 * (a * w * f[d][1] + b * h * f[d][2])))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexmb_element::frame_from_axis;

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|d| (a[d] - b[d]).abs() <= tol)
    }

    /// An undeformed spatial beam: the stations lie on the chord, evenly,
    /// with the reference frame; the corners at ±by/2, ±bz/2 along y, z.
    #[test]
    fn an_undeformed_beam_is_a_straight_box() {
        let frame = frame_from_axis(&[1.0, 1.0, 0.0], &[0.0, 0.0, 1.0]).unwrap();
        let b = BeamSection {
            shape: SectionShape::Rectangle {
                by: 0.02,
                bz: 0.004,
            },
            frame,
            planar: false,
        };
        let local = [
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0,
        ];
        let st = b.stations(&local, 4);
        assert_eq!(st.len(), 5);
        for (k, (c, f)) in st.iter().enumerate() {
            let s = k as f64 / 4.0;
            assert!(close(*c, [s, s, 0.0], 1e-15), "{c:?}");
            for i in 0..3 {
                assert!(close(f[i], frame[i], 1e-15));
            }
        }
        let c = b.corners(&st[0]);
        // corner 1 at +by/2 along y (up, global z) and −bz/2 along z = x × y
        let (y, z) = (column(&frame, 1), column(&frame, 2));
        assert!(close(y, [0.0, 0.0, 1.0], 1e-15));
        let want = std::array::from_fn(|d| 0.01 * y[d] - 0.002 * z[d]);
        assert!(close(c[1], want, 1e-15), "{:?}", c[1]);
        assert_eq!(b.area(), 0.02 * 0.004);
    }

    /// A planar cantilever turned at its tip by θ: the Hermite centre line
    /// leaves p along the chord's start tangent and arrives at q along the
    /// tip's x axis; a spatial beam with the same end rotations about z gives
    /// the same stations.
    #[test]
    fn end_rotations_bend_the_centre_line() {
        let theta = 0.3f64;
        let planar = BeamSection {
            shape: SectionShape::Circle { d: 0.01 },
            frame: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            planar: true,
        };
        let tip = [0.9, 0.2];
        let st = planar.stations(&[0.0, 0.0, 0.0, tip[0], tip[1], theta], 8);
        assert!(close(st[8].0, [0.9, 0.2, 0.0], 1e-15));
        let x_end = [st[8].1[0][0], st[8].1[1][0], st[8].1[2][0]];
        assert!(
            close(x_end, [theta.cos(), theta.sin(), 0.0], 1e-12),
            "{x_end:?}"
        );
        let x_start = [st[0].1[0][0], st[0].1[1][0], st[0].1[2][0]];
        assert!(close(x_start, [1.0, 0.0, 0.0], 1e-12));
        let (s, c) = (0.5 * theta).sin_cos();
        let spatial = BeamSection {
            planar: false,
            ..planar.clone()
        };
        let local = [
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, tip[0], tip[1], 0.0, c, 0.0, 0.0, s,
        ];
        for (a, b) in st.iter().zip(spatial.stations(&local, 8)) {
            assert!(close(a.0, b.0, 1e-14));
        }
        assert_eq!(planar.box_size(), [0.01, 0.01]);
    }
}
