//! The spatial beam with Vlasov warping (`BeamOptions::warping`): at a
//! uniform twist rate w_p = w_q = Θ/l0 it is the St-Venant beam exactly, that
//! state is stationary in w, and bad input names the culprit. Derivatives
//! and rigid-motion invariance are checked with the rest of the catalogue
//! (tests/derivatives.rs, tests/physics.rs: "spatial beam with warping").

mod common;
use common::*;
use flexmb_element::*;

fn beams(shape: &SectionShape) -> (Element, Element) {
    let (p, q, up) = ([0.1, 0.2, -0.1], [0.3, 0.1, 0.05], [0.0, 0.0, 1.0]);
    let plain = Element::beam(p, q, up, &steel(), shape, &BeamOptions::default()).unwrap();
    let warping = BeamOptions {
        warping: true,
        ..Default::default()
    };
    let warped = Element::beam(p, q, up, &steel(), shape, &warping).unwrap();
    (plain, warped)
}

fn energy_and_gradient(e: &Element, x: &[f64]) -> (f64, Vec<f64>) {
    let (ne, nx) = (e.n_eps(), e.n_x());
    let mut eps = vec![0.0; ne];
    let mut jac = vec![0.0; ne * nx];
    e.deformations_and_jacobian(x, None, &mut eps, &mut jac);
    let mut sigma = vec![0.0; ne];
    e.stress(&eps, None, &mut sigma);
    let grad = (0..nx)
        .map(|c| (0..ne).map(|r| sigma[r] * jac[r * nx + c]).sum())
        .collect();
    (e.elastic_energy(&eps), grad)
}

#[test]
fn uniform_twist_rate_gives_the_st_venant_beam_and_is_stationary_in_w() {
    let mut r = rng(41);
    let shape = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.002,
    };
    let (plain, warped) = beams(&shape);
    assert_eq!(warped.n_x(), 16);
    assert_eq!(
        &warped.deformation_names()[6..],
        &["warping_p".to_string(), "warping_q".to_string()]
    );
    let l0 = plain.reference_length().unwrap();
    for _ in 0..10 {
        let mut x = random_x(&mut r, &plain);
        // a moderate deformation: q near its reference place, turned a little
        let mut eps = [0.0; 6];
        plain.deformations(&x, None, &mut eps);
        let theta = eps[1] / l0; // the torsion deformation is l0 × the angle
        let (u_plain, _) = energy_and_gradient(&plain, &x);
        x.extend([theta / l0, theta / l0]);
        let (u, grad) = energy_and_gradient(&warped, &x);
        assert!(
            (u / u_plain - 1.0).abs() < 1e-12,
            "energy {u} against the St-Venant beam's {u_plain}"
        );
        let scale = grad[..14].iter().fold(0.0f64, |m, g| m.max(g.abs()));
        for g in &grad[14..] {
            assert!(g.abs() < 1e-12 * scale * l0, "∂U/∂w = {g} (scale {scale})");
        }
        // away from it the energy is larger (warping restraint stiffens)
        x[14] = 0.0;
        let (u0, _) = energy_and_gradient(&warped, &x);
        assert!(u0 > u, "{u0} ≤ {u}");
    }
}

#[test]
fn torsion_stiffness_at_rest_is_the_hermite_block() {
    let shape = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.001,
    };
    let mat = steel();
    let (_, warped) = beams(&shape);
    let sec = shape.properties(mat.poisson()).unwrap();
    let l0 = warped.reference_length().unwrap();
    let iw = 0.03f64.powi(3) * 0.001f64.powi(3) / 144.0;
    assert!((sec.iw.unwrap() / iw - 1.0).abs() < 1e-14);
    let k = torsion_warping_block(mat.g * sec.j, mat.e * iw, l0);
    let s = warped.stiffness();
    // ε2 = l0 Θ: S over (ε2, ε7, ε8) is K scaled by 1/l0 on the torsion row/column
    let at = [1, 6, 7];
    let d = [1.0 / l0, 1.0, 1.0];
    for a in 0..3 {
        for b in 0..3 {
            let want = d[a] * k[a][b] * d[b];
            assert!(
                (s[(at[a], at[b])] - want).abs() < 1e-12 * want.abs().max(1e-30),
                "S[{a}][{b}] = {} against {want}",
                s[(at[a], at[b])]
            );
        }
    }
}

#[test]
fn bad_warping_input_names_the_culprit() {
    let mat = steel();
    let opts = BeamOptions {
        warping: true,
        ..Default::default()
    };
    let rect = SectionShape::Rectangle {
        by: 0.03,
        bz: 0.001,
    };
    let e = Element::planar_beam([0.0, 0.0], [0.2, 0.0], &mat, &rect, &opts).unwrap_err();
    assert!(
        e.to_string().contains("warping") && e.to_string().contains("planar"),
        "{e}"
    );
    let mut user = rect.properties(0.3).unwrap();
    user.iw = None;
    let e = Element::beam(
        [0.0; 3],
        [0.2, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        &mat,
        &SectionShape::User(user),
        &opts,
    )
    .unwrap_err();
    assert!(e.to_string().contains("`iw`"), "{e}");
    // without warping, the same section is fine
    assert!(Element::beam(
        [0.0; 3],
        [0.2, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        &mat,
        &SectionShape::User(user),
        &BeamOptions::default(),
    )
    .is_ok());
}
