//! A reduction basis of one's own through the `Basis` trait of
//! `flexmb-reduction`: load-dependent Ritz vectors (Wilson's), v1 = K⁻¹f the
//! static deflection under the scene's force and v2 = K⁻¹M v1, made
//! M-orthonormal, as G(z) = q0 + V z on the planar straight guidance. The
//! reduced model is built, solved and analysed like any other
//! ([`MechanicalModel`]) and must show what a Ritz basis guarantees:
//!
//! * its eigenfrequencies lie above the unreduced ones (Rayleigh–Ritz);
//! * under a small load (1 % of the pulse's peak, nearly linear) its static
//!   deflection of S is the unreduced one, since v1 spans the linear static
//!   solution (within 1e-3).
//!
//! `cargo run --release -p flexmb --example custom_basis`

use flexmb::faer::linalg::solvers::Solve;
use flexmb::faer::Mat;
use flexmb::prelude::*;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

/// A fixed basis of any vectors: G(z) = q0 + Σ z_k v_k, so G,z = V and the
/// convective term (G,zz ż)ż vanishes (the trait's defaults give the zero
/// higher derivatives).
struct RitzBasis {
    q0: Vec<f64>,
    v: Vec<Vec<f64>>,
}

impl Basis for RitzBasis {
    fn n_z(&self) -> usize {
        self.v.len()
    }
    fn n_q(&self) -> usize {
        self.q0.len()
    }
    fn eval(&self, z: &[f64], _zd: &[f64], q: &mut [f64], gz: &mut Mat<f64>, conv: &mut [f64]) {
        q.copy_from_slice(&self.q0);
        for (k, (zk, vk)) in z.iter().zip(&self.v).enumerate() {
            for (i, vi) in vk.iter().enumerate() {
                q[i] += zk * vi;
                gz[(i, k)] = *vi;
            }
        }
        conv.fill(0.0);
    }
}

/// u ↦ uᵀ M w.
fn m_dot(m: &Mat<f64>, u: &[f64], w: &[f64]) -> f64 {
    (0..u.len())
        .map(|i| u[i] * (0..w.len()).map(|j| m[(i, j)] * w[j]).sum::<f64>())
        .sum()
}

/// The two Ritz vectors at q0 for the loads at time t.
fn ritz_vectors(dy: &mut Dynamics, t: f64, q0: &[f64]) -> Vec<Vec<f64>> {
    let lin = dy.linearize_at_rest(t, q0).expect("the rest linearization");
    let (k, m) = (lin.stiffness_total(), lin.m);
    let lu = k.partial_piv_lu();
    let solve = |b: &[f64]| -> Vec<f64> {
        let x = lu.solve(Mat::from_fn(b.len(), 1, |i, _| b[i]));
        (0..b.len()).map(|i| x[(i, 0)]).collect()
    };
    // the out-of-balance at the unloaded reference is −F,qᵀf
    let g = dy.static_residual(t, q0).expect("the out-of-balance");
    let mut v: Vec<Vec<f64>> = vec![];
    let mut next = solve(&g);
    for _ in 0..2 {
        for u in &v {
            let c = m_dot(&m, u, &next);
            next.iter_mut().zip(u).for_each(|(a, b)| *a -= c * b);
        }
        let norm = m_dot(&m, &next, &next).sqrt();
        next.iter_mut().for_each(|a| *a /= norm);
        let mv: Vec<f64> = (0..next.len())
            .map(|i| (0..next.len()).map(|j| m[(i, j)] * next[j]).sum())
            .collect();
        v.push(next);
        next = solve(&mv);
    }
    v
}

/// The x-displacement of S in equilibrium at load scale 0.01, by either model.
fn small_load_deflection(model: &mut dyn MechanicalModel, xs: usize, x_ref: f64) -> f64 {
    let eq = model
        .equilibria_over_load_scale(0.05, &[0.01], &mut |_| {})
        .expect("the equilibrium");
    eq[0].x[xs] - x_ref
}

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene = Scene::load(&root.join("fixtures/scenes/straight_guidance_planar.ron"))
        .expect("the guidance scene loads");
    let mech = Arc::new(scene.build(None).expect("the guidance builds"));
    let s = mech.node("S").expect("node S");
    let (xs, x_ref) = (s.position[0], s.at[0]);
    let q0 = mech.q0();

    let mut full = Dynamics::new(mech.clone());
    let v = ritz_vectors(&mut full, 0.05, &q0);
    let mut reduced = ReducedModel::new(mech.clone(), Box::new(RitzBasis { q0: q0.clone(), v }))
        .expect("the Ritz basis fits the mechanism");

    let f_full = full.eigenfrequencies(0.0, &q0, 2).expect("unreduced modes");
    let z0 = reduced.reference_coordinates();
    let f_red = reduced
        .eigenfrequencies(0.0, &z0, 2)
        .expect("reduced modes");
    let d_full = small_load_deflection(&mut full, xs, x_ref);
    let d_red = small_load_deflection(&mut reduced, xs, x_ref);
    println!("eigenfrequencies (Hz): unreduced {f_full:.4?}, Ritz basis {f_red:.4?}");
    println!("deflection of S at 1 % load: unreduced {d_full:.6e} m, Ritz basis {d_red:.6e} m");
    let above = f_red
        .iter()
        .zip(&f_full)
        .all(|(r, f)| *r >= f * (1.0 - 1e-9));
    let static_error = (d_red / d_full - 1.0).abs();
    if !above || static_error > 1e-3 {
        eprintln!(
            "Rayleigh–Ritz bound {}, static deflection off by {static_error:.1e}",
            if above { "holds" } else { "violated" }
        );
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
