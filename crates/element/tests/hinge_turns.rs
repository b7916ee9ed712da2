//! The spatial hinge's bending measures through any number of turns: the
//! tilt of one node's axis against the other's is measured in the frame
//! halfway between them, so that its derivative with respect to a tilt is a
//! rotation (by θ/2) at every hinge angle θ. The SPACAR measures
//! (ep_x·eq_z − ep_z·eq_x)/2, … had the derivative (1 + cos θ)/2: zero at
//! half a turn, where a hinge with free bending was singular.

use flexmb_element::Element;
use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::PI;

/// x = (λp, λq): p at the identity, q turned by θ about the hinge axis x and
/// then tilted by `tilt` = (about global y, about global z).
fn config(theta: f64, tilt: [f64; 2]) -> [f64; 8] {
    let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), tilt[0])
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), tilt[1])
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), theta);
    let c = q.coords; // (i, j, k, w)
    [1.0, 0.0, 0.0, 0.0, c[3], c[0], c[1], c[2]]
}

fn eps(h: &Element, x: &[f64; 8], prev: Option<f64>) -> [f64; 3] {
    let mut e = [0.0; 3];
    let p = prev.map(|a| [a, 0.0, 0.0]);
    h.deformations(x, p.as_ref().map(|p| &p[..]), &mut e);
    e
}

#[test]
fn the_bending_measures_keep_the_tilt_at_every_hinge_angle() {
    let h = Element::hinge([1.0, 0.0, 0.0], 1.0, 1.0).unwrap();
    let d = 1e-6;
    for theta in [0.0, 1.0, 0.5 * PI, 2.5, PI, 4.0, 3.0 * PI, -PI, 10.5] {
        // ε1 is the angle, continuous past ±π with the previous value
        let e0 = eps(&h, &config(theta, [0.0, 0.0]), Some(theta));
        assert!((e0[0] - theta).abs() < 1e-12, "ε1 {} at θ = {theta}", e0[0]);
        assert!(e0[1].abs() < 1e-15 && e0[2].abs() < 1e-15, "{e0:?}");
        // J = ∂(ε2, ε3)/∂(tilt y, tilt z) by central differences
        let mut j = [[0.0; 2]; 2];
        for c in 0..2 {
            let mut tp = [0.0; 2];
            tp[c] = d;
            let mut tm = [0.0; 2];
            tm[c] = -d;
            let (ep, em) = (
                eps(&h, &config(theta, tp), Some(theta)),
                eps(&h, &config(theta, tm), Some(theta)),
            );
            for r in 0..2 {
                j[r][c] = (ep[r + 1] - em[r + 1]) / (2.0 * d);
            }
        }
        // JᵀJ = I: both singular values 1 (a rotation by θ/2)
        for a in 0..2 {
            for b in 0..2 {
                let jtj = j[0][a] * j[0][b] + j[1][a] * j[1][b];
                let expect = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (jtj - expect).abs() < 1e-8,
                    "θ = {theta}: ∂(ε2, ε3)/∂tilt = {j:?} is not a rotation"
                );
            }
        }
        let c = (0.5 * theta).cos();
        assert!(
            (j[0][0] - c).abs() < 1e-8 && (j[1][1] - c).abs() < 1e-8,
            "θ = {theta}: {j:?}, cos(θ/2) = {c}"
        );
    }
}

/// Swapping the nodes negates all three deformations, exactly (the halfway
/// frame is the same from either side), for a misaligned hinge too.
#[test]
fn swapping_the_nodes_negates_the_deformations() {
    let h = Element::hinge([1.0, 0.0, 0.0], 1.0, 1.0).unwrap();
    for (theta, tilt) in [
        (0.3, [0.02, -0.01]),
        (2.0, [-0.05, 0.03]),
        (-2.9, [0.1, 0.08]),
    ] {
        let x = config(theta, tilt);
        let swapped = [x[4], x[5], x[6], x[7], x[0], x[1], x[2], x[3]];
        let (a, b) = (eps(&h, &x, None), eps(&h, &swapped, None));
        for k in 0..3 {
            assert!(
                (a[k] + b[k]).abs() < 1e-14,
                "θ = {theta}: {a:?} against {b:?}"
            );
        }
    }
}
