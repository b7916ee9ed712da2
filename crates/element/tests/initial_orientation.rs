//! Elements whose nodes start rotated (`Element::with_initial_orientation`):
//! undeformed in their initial orientations, the same element as the
//! unrotated one for the rotation since the start, and clear errors. The
//! derivatives of the rotated variants are checked against central
//! differences with the rest of the catalogue (derivatives.rs, physics.rs).

mod common;
use common::*;
use flexmb_element::*;
use flexmb_rotation::EulerParameters;

/// Δ ∘ λ0: the orientation reached by turning a node that started at λ0
/// by Δ in global axes, R(Δ) R(λ0).
fn turned(delta: &EulerParameters, l0: &EulerParameters) -> [f64; 4] {
    delta.compose(l0).0
}

fn spatial_cases() -> Vec<(&'static str, Element)> {
    let mat = steel();
    let rect = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.004,
    };
    let mut r = rng(5);
    vec![
        (
            "beam",
            Element::beam(
                [0.1, 0.2, -0.1],
                [0.3, 0.1, 0.05],
                [0.0, 0.0, 1.0],
                &mat,
                &rect,
                &BeamOptions::default(),
            )
            .unwrap(),
        ),
        ("hinge", Element::hinge([0.2, 0.5, 1.0], 3.0, 1e3).unwrap()),
        (
            "superelement",
            random_superelement(&mut r, 3, VelocityTransform::B3).0,
        ),
    ]
}

/// The reference x of an element with the given orientation per
/// orientation slot (positions as built: p and q of the cases).
fn reference_x(e: &Element, positions: &[[f64; 3]], orientations: &[[f64; 4]]) -> Vec<f64> {
    let (mut x, mut p, mut o) = (vec![], positions.iter(), orientations.iter());
    for s in e.slots() {
        match s {
            Slot::Position3 => x.extend(p.next().unwrap()),
            Slot::Orientation => x.extend(o.next().unwrap()),
            Slot::Modes(n) => x.extend(std::iter::repeat_n(0.0, *n)),
            _ => unreachable!(),
        }
    }
    x
}

fn positions_of(name: &str) -> Vec<[f64; 3]> {
    match name {
        "beam" => vec![[0.1, 0.2, -0.1], [0.3, 0.1, 0.05]],
        "hinge" => vec![],
        // the superelement of spatial_cases: q at l0 along the x axis of R0
        _ => {
            let data = random_superelement(&mut rng(5), 3, VelocityTransform::B3).1;
            vec![[0.0; 3], std::array::from_fn(|i| data.l0 * data.r0[i][0])]
        }
    }
}

#[test]
fn a_rotated_element_is_undeformed_in_its_initial_orientations_and_measures_the_turn_since() {
    let mut r = rng(1);
    for (name, e) in spatial_cases() {
        let slots: Vec<usize> = (0..e.slots().len())
            .filter(|k| e.slots()[*k] == Slot::Orientation)
            .collect();
        let l0: Vec<EulerParameters> = slots.iter().map(|_| random_rotation(&mut r, 3.0)).collect();
        let mut rot = e.clone();
        for (k, l) in slots.iter().zip(&l0) {
            rot = rot.with_initial_orientation(*k, &l.0).unwrap();
        }
        let pos = positions_of(name);
        let ne = e.n_eps();
        // undeformed at the start
        let x0 = reference_x(&e, &pos, &l0.iter().map(|l| l.0).collect::<Vec<_>>());
        let mut eps = vec![0.0; ne];
        rot.deformations(&x0, None, &mut eps);
        assert!(max_abs(&eps) < 1e-13, "{name}: ε at the start {eps:?}");
        // turning each node by Δ from its start gives the unrotated
        // element's ε with the nodes turned by Δ from the identity
        for _ in 0..5 {
            let d: Vec<EulerParameters> =
                slots.iter().map(|_| random_rotation(&mut r, 1.0)).collect();
            let xr = reference_x(
                &e,
                &pos,
                &d.iter()
                    .zip(&l0)
                    .map(|(d, l)| turned(d, l))
                    .collect::<Vec<_>>(),
            );
            let xu = reference_x(&e, &pos, &d.iter().map(|d| d.0).collect::<Vec<_>>());
            let (mut a, mut b) = (vec![0.0; ne], vec![0.0; ne]);
            rot.deformations(&xr, None, &mut a);
            e.deformations(&xu, None, &mut b);
            assert!(rel_err(&a, &b) < 1e-12, "{name}: {a:?} vs {b:?}");
            assert!(max_abs(&a) > 1e-6, "{name}: the turn deforms the element");
        }
    }
}

#[test]
fn a_rotated_planar_beam_and_hinge_measure_the_angle_from_the_start() {
    let mat = steel();
    let rect = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.004,
    };
    let beam =
        Element::planar_beam([0.0, 0.0], [0.3, 0.1], &mat, &rect, &BeamOptions::default()).unwrap();
    let rot = beam
        .clone()
        .with_initial_orientation(1, &[0.7])
        .unwrap()
        .with_initial_orientation(3, &[-2.0])
        .unwrap();
    let mut e = [0.0; 3];
    rot.deformations(&[0.0, 0.0, 0.7, 0.3, 0.1, -2.0], None, &mut e);
    assert!(max_abs(&e) < 1e-15, "{e:?}");
    let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
    rot.deformations(&[0.0, 0.0, 0.8, 0.3, 0.1, -2.05], None, &mut a);
    beam.deformations(&[0.0, 0.0, 0.1, 0.3, 0.1, -0.05], None, &mut b);
    assert!(rel_err(&a, &b) < 1e-13 && max_abs(&a) > 1e-3, "{a:?} {b:?}");
    let hinge = Element::planar_hinge(2.0)
        .unwrap()
        .with_initial_orientation(0, &[1.0])
        .unwrap();
    let mut h = [0.0];
    hinge.deformations(&[1.0, 1.0], None, &mut h);
    assert_eq!(h, [1.0], "φq − (φp − 1) with φq unrotated");
}

/// λ̇ = P a with P = Λᵀ(λ)/2 (ω in global axes): the mass in the reduced
/// velocities equals Pᵀ M P computed from the full mass matrix.
#[test]
fn the_mass_matrix_in_angular_velocities_matches_the_full_one_on_rotated_nodes() {
    let mut r = rng(9);
    let (name, beam) = spatial_cases().remove(0);
    let body = Element::rigid_body(
        2.0,
        [0.1, -0.05, 0.02],
        [[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    )
    .unwrap();
    for (name, e) in [(name, beam), ("rigid body", body)] {
        let e = start_rotated(&mut r, &e);
        let x = random_x(&mut r, &e);
        let n = e.n_x();
        let mut m = vec![0.0; n * n];
        e.mass_matrix(&x, &mut m);
        // T: identity on positions, P on each orientation slot
        let mut bases = vec![];
        let mut cols = vec![];
        let mut at = 0;
        for s in e.slots() {
            match s {
                Slot::Orientation => {
                    let l = EulerParameters([x[at], x[at + 1], x[at + 2], x[at + 3]]);
                    let lt = l.lambda().transpose() * 0.5;
                    let p: [[f64; 3]; 4] =
                        std::array::from_fn(|i| std::array::from_fn(|j| lt[(i, j)]));
                    bases.push(Some(p));
                    for j in 0..3 {
                        let mut c = vec![0.0; n];
                        for i in 0..4 {
                            c[at + i] = p[i][j];
                        }
                        cols.push(c);
                    }
                }
                _ => {
                    for i in 0..s.len() {
                        let mut c = vec![0.0; n];
                        c[at + i] = 1.0;
                        cols.push(c);
                    }
                }
            }
            at += s.len();
        }
        let nr = cols.len();
        let mut want = vec![0.0; nr * nr];
        for a in 0..nr {
            for b in 0..nr {
                let mut s = 0.0;
                for i in 0..n {
                    for j in 0..n {
                        s += cols[a][i] * m[i * n + j] * cols[b][j];
                    }
                }
                want[a * nr + b] = s;
            }
        }
        let mut got = vec![0.0; nr * nr];
        let k = e.mass_matrix_with_bases(&x, &bases, &mut got).unwrap();
        assert_eq!(k, nr, "{name}");
        assert!(
            rel_err(&got, &want) < 1e-12,
            "{name}: {:e}",
            rel_err(&got, &want)
        );
    }
}

#[test]
fn a_wrong_initial_orientation_is_an_error_naming_the_slot() {
    let beam = spatial_cases().remove(0).1;
    let msg = |r: Result<Element, ElementError>| r.unwrap_err().to_string();
    let m = msg(beam
        .clone()
        .with_initial_orientation(0, &[1.0, 0.0, 0.0, 0.0]));
    assert!(m.contains("slot 0") && m.contains("Position3"), "{m}");
    let m = msg(beam
        .clone()
        .with_initial_orientation(9, &[1.0, 0.0, 0.0, 0.0]));
    assert!(m.contains("slot 9") && m.contains("4 slots"), "{m}");
    let m = msg(beam.clone().with_initial_orientation(1, &[1.0, 0.0, 0.0]));
    assert!(m.contains("4 values, not 3"), "{m}");
    let m = msg(beam
        .clone()
        .with_initial_orientation(1, &[1.0, 0.1, 0.0, 0.0]));
    assert!(m.contains("norm") && m.contains("not 1"), "{m}");
    let m = msg(beam
        .clone()
        .with_initial_orientation(1, &[f64::NAN, 0.0, 0.0, 0.0]));
    assert!(m.contains("not finite"), "{m}");
    let m = msg(beam
        .clone()
        .with_initial_orientation(1, &[0.0, 1.0, 0.0, 0.0])
        .unwrap()
        .with_initial_orientation(1, &[0.0, 1.0, 0.0, 0.0]));
    assert!(m.contains("given twice"), "{m}");
    // within 1e-9 of unit: normalized, accepted
    assert!(beam
        .with_initial_orientation(3, &[1.0 + 5e-10, 0.0, 0.0, 0.0])
        .is_ok());
}
