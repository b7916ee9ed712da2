//! Linear (small-displacement) beam matrices in the element frame: the reduced
//! stiffness S̄ over the deformation boundary coordinates (thesis (2.3c), (2.5)),
//! the map S = AᵀS̄A (thesis (2.19), (3.20)), and the consistent mass M̄ over the
//! boundary velocities (thesis (2.8)).
//!
//! Bending uses Timoshenko beam theory through the shear parameter
//! Φ = 12 E I / (κ G A l²); Φ = 0 (κ = ∞) gives Euler–Bernoulli. The consistent mass
//! with shear deformation and rotary inertia is Przemieniecki's (*Theory of Matrix
//! Structural Analysis*, 1968, §11.4).

use crate::section::{Material, SectionProperties};
use nalgebra::{DMatrix, SMatrix};

/// Shear parameter Φ = 12 E I / (κ G A l²).
pub fn shear_parameter(mat: &Material, sec: &SectionProperties, i: f64, kappa: f64, l: f64) -> f64 {
    if kappa.is_infinite() {
        0.0
    } else {
        12.0 * mat.e * i / (kappa * mat.g * sec.area * l * l)
    }
}

/// Two-node bending stiffness over the end rotations (θp, θq) relative to the
/// chord: E I/(l(1+Φ)) ((4+Φ, 2−Φ), (2−Φ, 4+Φ)).
fn bending_block(ei: f64, phi: f64, l: f64) -> [[f64; 2]; 2] {
    let c = ei / (l * (1.0 + phi));
    [
        [c * (4.0 + phi), c * (2.0 - phi)],
        [c * (2.0 - phi), c * (4.0 + phi)],
    ]
}

/// S̄ of a spatial Timoshenko beam over µ̄e = (ū^q_x, φ̄^q_x, φ̄^p_y, φ̄^q_y, φ̄^p_z, φ̄^q_z),
/// thesis (2.3c): the beam's stiffness on those boundary coordinates.
pub fn spatial_beam_s_bar(mat: &Material, sec: &SectionProperties, l: f64) -> SMatrix<f64, 6, 6> {
    let mut s = SMatrix::<f64, 6, 6>::zeros();
    s[(0, 0)] = mat.e * sec.area / l;
    s[(1, 1)] = mat.g * sec.j / l;
    // bending about y (deflection in z): shear in z
    let by = bending_block(
        mat.e * sec.iy,
        shear_parameter(mat, sec, sec.iy, sec.kz, l),
        l,
    );
    // bending about z (deflection in y): shear in y
    let bz = bending_block(
        mat.e * sec.iz,
        shear_parameter(mat, sec, sec.iz, sec.ky, l),
        l,
    );
    for a in 0..2 {
        for b in 0..2 {
            s[(2 + a, 2 + b)] = by[a][b];
            s[(4 + a, 4 + b)] = bz[a][b];
        }
    }
    s
}

/// S̄ of a planar beam over (ū^q_x, φ̄^p, φ̄^q).
pub fn planar_beam_s_bar(mat: &Material, sec: &SectionProperties, l: f64) -> SMatrix<f64, 3, 3> {
    let mut s = SMatrix::<f64, 3, 3>::zeros();
    s[(0, 0)] = mat.e * sec.area / l;
    let bz = bending_block(
        mat.e * sec.iz,
        shear_parameter(mat, sec, sec.iz, sec.ky, l),
        l,
    );
    for a in 0..2 {
        for b in 0..2 {
            s[(1 + a, 1 + b)] = bz[a][b];
        }
    }
    s
}

/// The diagonal of A in µ̄e = A ε (thesis (2.17b), (3.18b)) for the six spatial
/// deformations: (1, 1/l0, −1/l0, 1/l0, −1/l0, 1/l0).
pub fn spatial_a_diag(l0: f64) -> [f64; 6] {
    [1.0, 1.0 / l0, -1.0 / l0, 1.0 / l0, -1.0 / l0, 1.0 / l0]
}

/// The diagonal of A for the planar beam: ε2 = l0 φ̄p, ε3 = −l0 φ̄q, so (1, 1/l0, −1/l0).
pub fn planar_a_diag(l0: f64) -> [f64; 3] {
    [1.0, 1.0 / l0, -1.0 / l0]
}

/// S = \[A; I\]ᵀ S̄ \[A; I\] of thesis (3.20): S̄ over (µ̄e, η̄) with `a` the diagonal
/// of A over the first `a.len()` entries and the identity on the mode amplitudes.
pub fn equivalent_stiffness(s_bar: &DMatrix<f64>, a: &[f64]) -> DMatrix<f64> {
    let n = s_bar.nrows();
    let d = |i: usize| if i < a.len() { a[i] } else { 1.0 };
    DMatrix::from_fn(n, n, |i, j| d(i) * s_bar[(i, j)] * d(j))
}

/// Przemieniecki's two-node bending mass over (w₁, θ₁, w₂, θ₂) with θ = dw/dx
/// (xy-plane convention), translational plus rotary inertia.
fn bending_mass(rho_a: f64, rho_i: f64, phi: f64, l: f64) -> [[f64; 4]; 4] {
    let (p, p2) = (phi, phi * phi);
    let c = rho_a * l / (1.0 + p).powi(2);
    let m11 = 13.0 / 35.0 + 7.0 * p / 10.0 + p2 / 3.0;
    let m12 = (11.0 / 210.0 + 11.0 * p / 120.0 + p2 / 24.0) * l;
    let m13 = 9.0 / 70.0 + 3.0 * p / 10.0 + p2 / 6.0;
    let m14 = -(13.0 / 420.0 + 3.0 * p / 40.0 + p2 / 24.0) * l;
    let m22 = (1.0 / 105.0 + p / 60.0 + p2 / 120.0) * l * l;
    let m24 = -(1.0 / 140.0 + p / 60.0 + p2 / 120.0) * l * l;
    let t = [
        [m11, m12, m13, m14],
        [m12, m22, -m14, m24],
        [m13, -m14, m11, -m12],
        [m14, m24, -m12, m22],
    ];
    let r = rho_i / ((1.0 + p).powi(2) * l);
    let r12 = (0.1 - p / 2.0) * l;
    let r22 = (2.0 / 15.0 + p / 6.0 + p2 / 3.0) * l * l;
    let r24 = (-1.0 / 30.0 - p / 6.0 + p2 / 6.0) * l * l;
    let rot = [
        [1.2, r12, -1.2, r12],
        [r12, r22, -r12, r24],
        [-1.2, -r12, 1.2, -r12],
        [r12, r24, -r12, r22],
    ];
    std::array::from_fn(|i| std::array::from_fn(|j| c * t[i][j] + r * rot[i][j]))
}

/// Consistent 12×12 mass of a spatial Timoshenko beam over the boundary
/// velocities v̄ = (v̄p, ω̄p, v̄q, ω̄q) (thesis (2.6b)), with rotary inertia.
pub fn spatial_beam_m_bar(mat: &Material, sec: &SectionProperties, l: f64) -> SMatrix<f64, 12, 12> {
    let mut m = SMatrix::<f64, 12, 12>::zeros();
    let rho = mat.rho;
    let ax = rho * sec.area * l / 6.0;
    let to = rho * sec.polar() * l / 6.0;
    for (a, b, v) in [(0, 6, ax), (3, 9, to)] {
        m[(a, a)] = 2.0 * v;
        m[(b, b)] = 2.0 * v;
        m[(a, b)] = v;
        m[(b, a)] = v;
    }
    // xy-plane: (v, θz) at indices (1, 5, 7, 11); θz = dv/dx.
    let phi_y = shear_parameter(mat, sec, sec.iz, sec.ky, l);
    let bz = bending_mass(rho * sec.area, rho * sec.iz, phi_y, l);
    let idx = [1, 5, 7, 11];
    for a in 0..4 {
        for b in 0..4 {
            m[(idx[a], idx[b])] = bz[a][b];
        }
    }
    // xz-plane: (w, θy) at (2, 4, 8, 10); θy = −dw/dx, so flip the signs of θ.
    let phi_z = shear_parameter(mat, sec, sec.iy, sec.kz, l);
    let by = bending_mass(rho * sec.area, rho * sec.iy, phi_z, l);
    let idx = [2, 4, 8, 10];
    let sgn = [1.0, -1.0, 1.0, -1.0];
    for a in 0..4 {
        for b in 0..4 {
            m[(idx[a], idx[b])] = sgn[a] * sgn[b] * by[a][b];
        }
    }
    m
}

/// Consistent 6×6 mass of a planar Timoshenko beam over (v̄p, ω̄p, v̄q, ω̄q) =
/// (u, v, θ)_p, (u, v, θ)_q in the element frame.
pub fn planar_beam_m_bar(mat: &Material, sec: &SectionProperties, l: f64) -> SMatrix<f64, 6, 6> {
    let mut m = SMatrix::<f64, 6, 6>::zeros();
    let ax = mat.rho * sec.area * l / 6.0;
    m[(0, 0)] = 2.0 * ax;
    m[(3, 3)] = 2.0 * ax;
    m[(0, 3)] = ax;
    m[(3, 0)] = ax;
    let phi = shear_parameter(mat, sec, sec.iz, sec.ky, l);
    let bz = bending_mass(mat.rho * sec.area, mat.rho * sec.iz, phi, l);
    let idx = [1, 2, 4, 5];
    for a in 0..4 {
        for b in 0..4 {
            m[(idx[a], idx[b])] = bz[a][b];
        }
    }
    m
}
