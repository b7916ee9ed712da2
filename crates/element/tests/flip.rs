//! The flip check of the chord elements: the angle between the chord and a
//! node frame's x axis is exact (a node turned by θ about an axis normal to
//! the chord gives θ), invariant under rigid motion, blind to torsion, and
//! beyond π/2 the element counts as flipped. At π the deformations of the
//! element are all zero, which is why the deformation functions alone cannot
//! tell the spurious state from the undeformed one.

mod common;
use common::*;
use flexmb_element::*;
use flexmb_rotation::EulerParameters;
use nalgebra::{Unit, Vector3};
use std::f64::consts::PI;

/// Angles of the node turn, below and above the flip angle π/2.
const TURNS: [f64; 6] = [0.0, 0.3, 1.5, 1.65, 2.5, PI];

/// A spatial chord element: name, element, its reference configuration
/// (rp, λp, rq, λq, modes) and the frame R0 it was built with.
type Case = (String, Element, Vec<f64>, [[f64; 3]; 3]);

/// The spatial chord elements under test.
fn spatial_cases() -> Vec<Case> {
    let mut rng = rng(7);
    let mut v = vec![];
    let (p, q, up) = ([0.1, 0.2, -0.1], [0.3, 0.1, 0.05], [0.0, 0.0, 1.0]);
    let beam = Element::beam(
        p,
        q,
        up,
        &steel(),
        &SectionShape::Rectangle {
            by: 0.03,
            bz: 0.004,
        },
        &BeamOptions::default(),
    )
    .unwrap();
    let axis = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    let mut x = vec![];
    for r in [p, q] {
        x.extend(r);
        x.extend(EulerParameters::identity().0);
    }
    v.push((
        "spatial beam".into(),
        beam,
        x,
        frame_from_axis(&axis, &up).unwrap(),
    ));
    let (se, data) = random_superelement(&mut rng, 3, VelocityTransform::B3);
    let p = [0.4, -0.3, 0.2];
    let mut x = vec![];
    for s in [0.0, data.l0] {
        x.extend((0..3).map(|i| p[i] + s * data.r0[i][0]));
        x.extend(EulerParameters::identity().0);
    }
    x.extend([0.0; 3]);
    v.push(("superelement".into(), se, x, data.r0));
    v
}

fn turn(x: &mut [f64], at: usize, axis: Vector3<f64>, angle: f64) {
    let l = EulerParameters::from_axis_angle(&Unit::new_normalize(axis), angle);
    x[at..at + 4].copy_from_slice(&l.0);
}

#[test]
fn the_chord_angle_of_a_turned_node_is_the_turn_and_beyond_half_pi_the_element_flips() {
    for (name, e, x0, r0) in spatial_cases() {
        let col = |j: usize| Vector3::new(r0[0][j], r0[1][j], r0[2][j]);
        for &th in &TURNS {
            // node q turned about the element's y, node p about its z axis
            for (at, axis) in [(10, col(1)), (3, col(2))] {
                let mut x = x0.clone();
                turn(&mut x, at, axis, th);
                let a = e.chord_angle(&x).unwrap();
                assert!((a - th).abs() < 1e-7, "{name}: turn {th} gives {a}");
                assert_eq!(e.is_flipped(&x), th > FLIP_ANGLE, "{name}: turn {th}");
                // rigid motion beyond 2π leaves the angle unchanged
                let g = EulerParameters::from_axis_angle(
                    &Unit::new_normalize(Vector3::new(0.3, -1.0, 0.4)),
                    7.0,
                );
                let mut y = x.clone();
                for node in [0, 7] {
                    let r = g.rotation_matrix() * Vector3::new(x[node], x[node + 1], x[node + 2]);
                    y[node..node + 3].copy_from_slice(r.as_slice());
                    let l = g.compose(&EulerParameters([
                        x[node + 3],
                        x[node + 4],
                        x[node + 5],
                        x[node + 6],
                    ]));
                    y[node + 3..node + 7].copy_from_slice(&l.0);
                }
                let b = e.chord_angle(&y).unwrap();
                assert!(
                    (b - a).abs() < 1e-7,
                    "{name}: {b} after a rigid motion, {a} before"
                );
            }
        }
        // torsion of 3 rad (a turn about the chord) is no flip
        let mut x = x0.clone();
        turn(&mut x, 10, col(0), 3.0);
        assert!(
            e.chord_angle(&x).unwrap() < 1e-7 && !e.is_flipped(&x),
            "{name}"
        );
    }
}

#[test]
fn a_planar_beam_flips_beyond_half_pi() {
    let e = Element::planar_beam(
        [0.1, 0.2],
        [0.35, 0.4],
        &steel(),
        &SectionShape::Rectangle {
            by: 0.03,
            bz: 0.004,
        },
        &BeamOptions::default(),
    )
    .unwrap();
    for &th in &TURNS {
        for (at, sign) in [(2, 1.0), (5, -1.0)] {
            let mut x = [0.1, 0.2, 0.0, 0.35, 0.4, 0.0];
            x[at] = sign * th;
            let a = e.chord_angle(&x).unwrap();
            assert!((a - th).abs() < 1e-7, "turn {th} gives {a}");
            assert_eq!(e.is_flipped(&x), th > FLIP_ANGLE, "turn {th}");
            // the same after a rigid rotation by 5 rad and a shift
            let (s, c) = 5.0f64.sin_cos();
            let mv = |px: f64, py: f64| (c * px - s * py + 1.0, s * px + c * py - 2.0);
            let (a0, a1) = mv(x[0], x[1]);
            let (b0, b1) = mv(x[3], x[4]);
            let y = [a0, a1, x[2] + 5.0, b0, b1, x[5] + 5.0];
            assert!((e.chord_angle(&y).unwrap() - a).abs() < 1e-7);
        }
    }
}

/// The spurious state: both node frames turned by π against the chord (or
/// the chord reversed against both frames). Its deformations (5.3), (6.2b),
/// (3.14b) are those of the undeformed element, zero to rounding; only the
/// flip check tells it apart.
#[test]
fn the_reversed_element_looks_undeformed_but_is_flipped() {
    for (name, e, x0, r0) in spatial_cases() {
        let z = Vector3::new(r0[0][2], r0[1][2], r0[2][2]);
        let mut x = x0.clone();
        turn(&mut x, 3, z, PI);
        turn(&mut x, 10, z, PI);
        let mut eps = vec![0.0; e.n_eps()];
        e.deformations(&x, None, &mut eps);
        assert!(max_abs(&eps) < 1e-12, "{name}: ε = {eps:?}");
        assert!(e.is_flipped(&x), "{name}");
        assert!((e.chord_angle(&x).unwrap() - PI).abs() < 1e-7, "{name}");
    }
    let e = Element::planar_beam(
        [0.0, 0.0],
        [0.2, 0.0],
        &steel(),
        &SectionShape::Circle { d: 0.01 },
        &BeamOptions::default(),
    )
    .unwrap();
    let x = [0.0, 0.0, PI, 0.2, 0.0, PI];
    let mut eps = [0.0; 3];
    e.deformations(&x, None, &mut eps);
    assert!(max_abs(&eps) < 1e-12 && e.is_flipped(&x), "ε = {eps:?}");
}

/// Trusses have no frames; hinge angles are unwrapped over turns (not
/// periodic); masses have no deformations: none of them can flip.
#[test]
fn elements_without_a_chord_and_frames_never_flip() {
    let mut rng = rng(3);
    for (name, e) in catalogue(&mut rng) {
        let has_chord = name.contains("beam") || name.contains("superelement");
        for _ in 0..20 {
            let x = random_x(&mut rng, &e);
            assert_eq!(e.chord_cosines(&x).is_some(), has_chord, "{name}");
            if !has_chord {
                assert!(!e.is_flipped(&x), "{name}");
            }
        }
    }
}
