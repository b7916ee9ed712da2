//! Shared fixtures for the element tests: a catalogue of elements and random
//! configurations around their reference geometry.
#![allow(dead_code)]

use flexmb_element::*;
use flexmb_rotation::EulerParameters;
use nalgebra::{DMatrix, Unit, Vector3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

pub fn steel() -> Material {
    Material::from_poisson(2.1e11, 0.3, 7800.0)
}

pub fn random_unit(rng: &mut StdRng) -> Unit<Vector3<f64>> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if v.norm() > 0.1 {
            return Unit::new_normalize(v);
        }
    }
}

/// A random rotation with an angle up to `max_angle` (may exceed 2π).
pub fn random_rotation(rng: &mut StdRng, max_angle: f64) -> EulerParameters {
    let a = random_unit(rng);
    EulerParameters::from_axis_angle(&a, rng.random_range(-max_angle..max_angle))
}

/// A random symmetric positive definite matrix of size n with the given scale.
pub fn random_spd(rng: &mut StdRng, n: usize, scale: f64) -> DMatrix<f64> {
    let a = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    (a.transpose() * &a + DMatrix::identity(n, n) * n as f64) * scale
}

/// A superelement with random S̄, M̄ and `k` modes (one p-side, one q-side, rest normal).
pub fn random_superelement(
    rng: &mut StdRng,
    k: usize,
    transform: VelocityTransform,
) -> (Element, LinearSuperelement) {
    let l0 = 0.3;
    let r0 = frame_from_axis(&[0.3, 0.1, -0.2], &[0.0, 0.0, 1.0]).unwrap();
    let mut modes = vec![];
    for i in 0..k {
        modes.push(match i {
            0 => ModeKind::Warping(Side::P),
            1 => ModeKind::Warping(Side::Q),
            _ => ModeKind::Normal {
                frequency_hz: 100.0 * i as f64,
            },
        });
    }
    let beam = spatial_beam_m_bar(
        &steel(),
        &SectionShape::Circle { d: 0.02 }.properties(0.3).unwrap(),
        l0,
    );
    let mut mbar = DMatrix::from_iterator(12, 12, beam.iter().copied()).resize(12 + k, 12 + k, 0.0);
    let extra = random_spd(rng, 12 + k, 0.05);
    mbar += extra;
    let sbar = random_spd(rng, 6 + k, 1e4);
    let data = LinearSuperelement::from_matrices(l0, r0, &sbar, &mbar, modes);
    (Element::superelement(&data, transform).unwrap(), data)
}

/// The catalogue of elements under test, with a name.
pub fn catalogue(rng: &mut StdRng) -> Vec<(String, Element)> {
    let mat = steel();
    let rect = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.004,
    };
    let mut v = vec![];
    for (tag, opts) in [
        ("", BeamOptions::default()),
        (
            " (EB, no shortening, B1)",
            BeamOptions {
                shortening: false,
                timoshenko: false,
                velocity_transform: VelocityTransform::B1,
                ..Default::default()
            },
        ),
    ] {
        v.push((
            format!("planar beam{tag}"),
            Element::planar_beam([0.1, 0.2], [0.35, 0.4], &mat, &rect, &opts).unwrap(),
        ));
        v.push((
            format!("spatial beam{tag}"),
            Element::beam(
                [0.1, 0.2, -0.1],
                [0.3, 0.1, 0.05],
                [0.0, 0.0, 1.0],
                &mat,
                &rect,
                &opts,
            )
            .unwrap(),
        ));
    }
    v.push((
        "spatial beam B2".into(),
        Element::beam(
            [0.0; 3],
            [0.2, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &mat,
            &rect,
            &BeamOptions {
                velocity_transform: VelocityTransform::B2,
                ..Default::default()
            },
        )
        .unwrap(),
    ));
    v.push((
        "planar truss".into(),
        Element::planar_truss([0.0, 0.0], [0.3, 0.1], 1e6, 2.0).unwrap(),
    ));
    v.push(("planar hinge".into(), Element::planar_hinge(3.0).unwrap()));
    v.push((
        "planar mass".into(),
        Element::planar_mass(2.0, Some(0.1)).unwrap(),
    ));
    v.push((
        "truss".into(),
        Element::truss([0.0; 3], [0.3, 0.1, 0.2], 1e6, 2.0).unwrap(),
    ));
    v.push((
        "hinge".into(),
        Element::hinge([0.2, 0.5, 1.0], 3.0, 1e3).unwrap(),
    ));
    v.push(("point mass".into(), Element::point_mass(1.5).unwrap()));
    let r0 = frame_from_axis(&[1.0, 1.0, 0.0], &[0.0, 0.0, 1.0]).unwrap();
    v.push((
        "rigid body".into(),
        Element::rigid_body(
            2.0,
            [0.1, -0.05, 0.02],
            [[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]],
            r0,
        )
        .unwrap(),
    ));
    v.push(("normalization".into(), Element::normalization()));
    for (t, tr) in [
        ("B1", VelocityTransform::B1),
        ("B2", VelocityTransform::B2),
        ("B3", VelocityTransform::B3),
    ] {
        v.push((
            format!("superelement {t}"),
            random_superelement(rng, 3, tr).0,
        ));
    }
    // every element with an orientation slot again, its nodes starting in
    // random, different orientations (Element::with_initial_orientation)
    let rotated: Vec<(String, Element)> = v
        .iter()
        .filter(|(_, e)| {
            e.slots()
                .iter()
                .any(|s| matches!(s, Slot::Angle | Slot::Orientation))
        })
        .map(|(name, e)| {
            (
                format!("{name} (nodes start rotated)"),
                start_rotated(rng, e),
            )
        })
        .collect();
    v.extend(rotated);
    // appended last, and rotated with a generator of its own, so that the
    // random configurations drawn for the elements above stay as they were
    let warping = Element::beam(
        [0.1, 0.2, -0.1],
        [0.3, 0.1, 0.05],
        [0.0, 0.0, 1.0],
        &mat,
        &rect,
        &BeamOptions {
            warping: true,
            ..Default::default()
        },
    )
    .unwrap();
    let warping_rotated = start_rotated(&mut self::rng(0x5ee7), &warping);
    v.push(("spatial beam with warping".into(), warping));
    v.push((
        "spatial beam with warping (nodes start rotated)".into(),
        warping_rotated,
    ));
    // the anticlastic overlay of a sheet, weak about local y and about local z
    for (name, by, bz) in [("y", 0.03, 0.002), ("z", 0.002, 0.03)] {
        let sheet = SectionShape::Rectangle { by, bz };
        let curl = flexmb_element::anticlastic_overlay(
            [0.1, 0.2, -0.1],
            [0.3, 0.1, 0.05],
            [0.0, 0.0, 1.0],
            &mat,
            &sheet,
            true,
        )
        .unwrap();
        let rotated = start_rotated(&mut self::rng(0xc011), &curl);
        v.push((format!("anticlastic overlay (weak about {name})"), curl));
        v.push((
            format!("anticlastic overlay (weak about {name}, nodes start rotated)"),
            rotated,
        ));
    }
    v
}

/// `e` with each orientation slot starting in a random orientation (angles
/// up to 3 rad).
pub fn start_rotated(rng: &mut StdRng, e: &Element) -> Element {
    let mut e = e.clone();
    for (k, s) in e.slots().to_vec().iter().enumerate() {
        e = match s {
            Slot::Angle => e
                .with_initial_orientation(k, &[rng.random_range(-3.0..3.0)])
                .unwrap(),
            Slot::Orientation => e
                .with_initial_orientation(k, &random_rotation(rng, 3.0).0)
                .unwrap(),
            _ => e,
        };
    }
    assert!(e.has_initial_orientation());
    e
}

/// A random configuration of an element: positions O(1), orientations random
/// unit quaternions, angles random, modes small.
pub fn random_x(rng: &mut StdRng, e: &Element) -> Vec<f64> {
    let mut x = vec![];
    for s in e.slots() {
        match s {
            Slot::Position2 | Slot::Position3 => {
                for _ in 0..s.len() {
                    x.push(rng.random_range(-0.5..0.5));
                }
            }
            Slot::Angle => x.push(rng.random_range(-3.0..3.0)),
            Slot::Orientation => x.extend(random_rotation(rng, 3.0).0),
            Slot::Modes(n) => {
                for _ in 0..*n {
                    x.push(rng.random_range(-0.01..0.01));
                }
            }
        }
    }
    x
}

/// A random velocity consistent with the orientation constraint (λᵀλ̇ = 0).
pub fn random_xd(rng: &mut StdRng, e: &Element, x: &[f64]) -> Vec<f64> {
    let mut v = vec![];
    let mut i = 0;
    for s in e.slots() {
        match s {
            Slot::Orientation => {
                let l = EulerParameters([x[i], x[i + 1], x[i + 2], x[i + 3]]);
                let w = Vector3::new(
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                );
                v.extend(l.lambda_dot_from_omega(&w));
            }
            _ => {
                for _ in 0..s.len() {
                    v.push(rng.random_range(-2.0..2.0));
                }
            }
        }
        i += s.len();
    }
    v
}

pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, b| a.max(b.abs()))
}

/// Relative error of `a` against `b`, normalized by the largest entry of `b`
/// (with a floor so that an all-zero reference is compared absolutely).
pub fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    max_abs(&d) / max_abs(b).max(1e-6)
}
