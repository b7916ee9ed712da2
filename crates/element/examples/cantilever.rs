//! A spatial beam cantilever: the element's linear stiffness against Timoshenko
//! beam theory, and the first-order kinematics of a large deflection.
//!
//! Run: `cargo run --release -p flexmb-element --example cantilever`

use flexmb_element::{BeamOptions, Element, Material, SectionShape};
use flexmb_rotation::EulerParameters;
use nalgebra::{DMatrix, DVector};

fn main() {
    let steel = Material::from_poisson(2.1e11, 0.3, 7600.0);
    let shape = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.001,
    };
    let sec = shape.properties(steel.poisson()).expect("valid section");
    let l = 0.2;
    let beam = Element::beam(
        [0.0; 3],
        [l, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        &steel,
        &shape,
        &BeamOptions::default(),
    )
    .expect("valid beam");
    let id = EulerParameters::identity().0;
    let x: Vec<f64> = [0.0, 0.0, 0.0]
        .iter()
        .chain(&id)
        .chain(&[l, 0.0, 0.0])
        .chain(&id)
        .copied()
        .collect();

    // linear stiffness of the free node q over (u, θ) with δλ = ½Λᵀδθ
    let mut eps = [0.0; 6];
    let mut jac = [0.0; 6 * 14];
    beam.deformations_and_jacobian(&x, None, &mut eps, &mut jac);
    let d = DMatrix::from_row_slice(6, 14, &jac);
    let mut g = DMatrix::zeros(14, 6);
    for k in 0..3 {
        g[(7 + k, k)] = 1.0;
    }
    let lt = EulerParameters::identity().lambda().transpose() * 0.5;
    for a in 0..4 {
        for b in 0..3 {
            g[(10 + a, 3 + b)] = lt[(a, b)];
        }
    }
    let b = d * g;
    let k = b.transpose() * beam.stiffness() * b;
    let lu = k.lu();
    let p = 1.0;
    println!("flexmb — spatial beam cantilever, L = {l} m, section 30 × 1 mm, steel");
    println!(
        "{:<34} {:>14} {:>14} {:>10}",
        "quantity", "flexmb", "Timoshenko", "rel. diff"
    );
    let row = |what: &str, f: [f64; 6], i: usize, want: f64| {
        let u = lu
            .solve(&DVector::from_row_slice(&f))
            .expect("regular stiffness");
        println!(
            "{what:<34} {:>14.6e} {:>14.6e} {:>10.1e}",
            u[i],
            want,
            (u[i] / want - 1.0).abs()
        );
    };
    let (e, gm, a) = (steel.e, steel.g, sec.area);
    row(
        "tip deflection y under 1 N (m)",
        [0.0, p, 0.0, 0.0, 0.0, 0.0],
        1,
        p * l.powi(3) / (3.0 * e * sec.iz) + p * l / (sec.ky * gm * a),
    );
    row(
        "tip deflection z under 1 N (m)",
        [0.0, 0.0, p, 0.0, 0.0, 0.0],
        2,
        p * l.powi(3) / (3.0 * e * sec.iy) + p * l / (sec.kz * gm * a),
    );
    row(
        "twist under 1 N m (rad)",
        [0.0, 0.0, 0.0, p, 0.0, 0.0],
        3,
        p * l / (gm * sec.j),
    );
    row(
        "elongation under 1 N (m)",
        [p, 0.0, 0.0, 0.0, 0.0, 0.0],
        0,
        p * l / (e * a),
    );
}
