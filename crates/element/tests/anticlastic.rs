//! The anticlastic overlay (`anticlastic_overlay`) against Ashwell's strip in
//! pure bending: a short element bent to a uniform curvature κ, its curl
//! amplitudes at their energy minimum, gives the strip's bending energy as a
//! function of Searle's β = b²κ/t. The reference values are those of
//! research/sheet22/anticlastic.py (an independent Legendre–Ritz code): its
//! two-term solution (the overlay's curl shapes) and the converged one.

use flexmb_element::*;

const B: f64 = 0.03;
const T: f64 = 0.001;
const L: f64 = 0.001;

fn steel() -> Material {
    Material::from_poisson(2.1e11, 0.3, 7600.0)
}

/// The overlay of a beam from (0, 0, 0) to (L, 0, 0) (local y along global y).
fn overlay(shape: SectionShape, q: [f64; 3], inertia: bool) -> Result<Element, ElementError> {
    anticlastic_overlay([0.0; 3], q, [0.0, 1.0, 0.0], &steel(), &shape, inertia)
}

const SHEET: SectionShape = SectionShape::Rectangle { by: B, bz: T };

/// The node coordinates of the element from (0, 0, 0) to (L, 0, 0) with its
/// ends turned by ∓φ about global y (the weak axis: local y is global y,
/// the 1 mm side along local z): a uniform curvature 2φ/L.
fn bent(phi: f64, eta: [f64; 4]) -> Vec<f64> {
    let (c, s) = ((phi / 2.0).cos(), (phi / 2.0).sin());
    let mut x = vec![0.0, 0.0, 0.0, c, 0.0, -s, 0.0];
    x.extend([L, 0.0, 0.0, c, 0.0, s, 0.0]);
    x.extend(eta);
    x
}

/// The overlay's energy ½ εᵀSε at curl amplitudes η (the same at both ends).
fn energy(e: &Element, phi: f64, eta: [f64; 2]) -> f64 {
    let x = bent(phi, [eta[0], eta[1], eta[0], eta[1]]);
    let mut eps = vec![0.0; e.n_eps()];
    e.deformations(&x, None, &mut eps);
    e.elastic_energy(&eps)
}

/// The minimum over η of the overlay's energy, quadratic in η at fixed node
/// positions: from its values at three points per direction.
fn minimum(e: &Element, phi: f64) -> f64 {
    let h = 1e-5;
    let f = |a: f64, b: f64| energy(e, phi, [a, b]);
    let f0 = f(0.0, 0.0);
    let g = [
        (f(h, 0.0) - f(-h, 0.0)) / (2.0 * h),
        (f(0.0, h) - f(0.0, -h)) / (2.0 * h),
    ];
    let h11 = (f(h, 0.0) - 2.0 * f0 + f(-h, 0.0)) / (h * h);
    let h22 = (f(0.0, h) - 2.0 * f0 + f(0.0, -h)) / (h * h);
    let h12 = (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h);
    let det = h11 * h22 - h12 * h12;
    let a = -(h22 * g[0] - h12 * g[1]) / det;
    let b = -(h11 * g[1] - h12 * g[0]) / det;
    let min = f(a, b);
    // the energy is quadratic in η: the stationary point is the minimum
    assert!(min <= f0 && min <= f(1.01 * a, 0.99 * b), "{min} {f0}");
    min
}

#[test]
fn a_uniformly_bent_strip_has_ashwells_bending_energy() {
    let mat = steel();
    let nu = mat.poisson();
    let e = overlay(SHEET, [L, 0.0, 0.0], true).unwrap();
    let ei = mat.e * B * T.powi(3) / 12.0;
    // β, the two-term Ritz factor and the converged one (anticlastic.py)
    for (beta, ritz2, exact) in [
        (0.5, 1.000373, 1.000373),
        (2.0, 1.005528, 1.005522),
        (8.0, 1.040692, 1.040429),
        (20.0, 1.064725, 1.064568),
    ] {
        let kappa = beta * T / (B * B);
        let phi = kappa * L / 2.0;
        // the bending of the beam, EI κ²/2 per length, plus the overlay's
        let w = 0.5 * ei * kappa * kappa * L;
        let factor = (w + minimum(&e, phi)) / w;
        // the rotations are finite: sin φ against φ is 1e-6 here
        assert!(
            (factor / ritz2 - 1.0).abs() < 2e-5,
            "β = {beta}: {factor} against {ritz2}"
        );
        assert!((factor / exact - 1.0).abs() < 3e-4, "β = {beta}: {factor}");
    }
    // β → ∞: towards the plate, D b = EI/(1 − ν²) (β = 200: 1.0958 with
    // the two-term curl, 1.0880 converged)
    let kappa = 200.0 * T / (B * B);
    let w = 0.5 * ei * kappa * kappa * L;
    let factor = (w + minimum(&e, kappa * L / 2.0)) / w;
    assert!(factor < 1.0 / (1.0 - nu * nu) && factor > 1.09, "{factor}");
    // free curl (κ small): the beam exactly
    let w = 0.5 * ei * 1e-4 * L;
    assert!(minimum(&e, 1e-2 * L / 2.0) < 1e-6 * w);
}

#[test]
fn a_twisted_flat_strip_stiffens_only_with_the_trapeze_term() {
    // no curvature: the curl stays zero and the overlay's energy is the
    // trapeze (Buckley) term of the twist, (E t b⁵/1440) τ⁴ per length
    let mat = steel();
    let e = overlay(SHEET, [L, 0.0, 0.0], false).unwrap();
    let tau = 3.0; // rad/m
    let psi = tau * L;
    let (c, s) = ((psi / 2.0).cos(), (psi / 2.0).sin());
    let mut x = vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    x.extend([L, 0.0, 0.0, c, s, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let mut eps = vec![0.0; e.n_eps()];
    e.deformations(&x, None, &mut eps);
    let u = e.elastic_energy(&eps);
    let expected = mat.e * T * B.powi(5) / 1440.0 * tau.powi(4) * L;
    // τ is sin(ψ)/L: 1.5e-6 relative
    assert!((u / expected - 1.0).abs() < 1e-5, "{u} {expected}");
}

#[test]
fn the_overlay_refuses_what_is_not_a_sheet() {
    let err = overlay(SectionShape::Circle { d: 0.01 }, [L, 0.0, 0.0], true).unwrap_err();
    assert!(err.to_string().contains("Rectangle"), "{err}");
    let err = overlay(SHEET, [0.0; 3], true).unwrap_err();
    assert!(err.to_string().contains("no length"), "{err}");
}
