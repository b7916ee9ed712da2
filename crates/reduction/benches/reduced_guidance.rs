//! One evaluation of the reduced equations of motion (6.15), z̈ from (z, ż),
//! of the 44-DOF spatial straight guidance (thesis §6.4, gravity):
//!
//! * MSI-2 (absolute nodal coordinates as DOFs, a 33-row kinematic
//!   Jacobian; the basis from 300 equilibria along the stroke as in `cargo
//!   xtask reproduce ch6`). Target ≤ 25 µs.
//! * MODAL-13 (deformation DOFs as the FBM models of ch6, a 77-row
//!   Jacobian; the first 13 modes at rest, the size of SVD-13).
//!
//! "at one state" repeats the evaluation at a fixed (z, ż); "along a
//! trajectory" evaluates, in their order, the 308 states an Adams run of
//! the response to the force pulse (6.27) from the gravity equilibrium
//! (rtol 1e-3, 601 outputs over 0.3 s, as in ch6) asked for, so the
//! position solve's chord steps and refinements happen as in a simulation.
//! "by the full mass" is the reference path, which forms the unreduced
//! Mq = F,qᵀ Mx F,q and projects it.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_dynamics::Integrator;
use flexmb_linearize::{sweep, SweepOptions, SweepParameter};
use flexmb_model::{Component, DofChoice, Select};
use flexmb_reduction::{
    interpolated_basis_from_sweep, modal_basis, ReducedModel, SubspaceInterpolation,
};
use std::sync::Arc;

mod common;

/// MSI-2 of ch6: the spatial guidance in nodal DOFs with S.x first, the
/// basis from a sweep over S.x ± 0.0834 m without gravity, the model with
/// gravity.
fn msi2() -> ReducedModel {
    let mut s = common::scene("straight_guidance_spatial.ron");
    s.dofs = DofChoice::NodalCoordinates;
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    let mech = Arc::new(s.clone().build(None).unwrap());
    s.gravity = None;
    let nog = Arc::new(s.build(None).unwrap());
    let x0 = mech.q0()[0];
    let values: Vec<f64> = (0..300)
        .map(|i| x0 - 0.0834 + 2.0 * 0.0834 * i as f64 / 299.0)
        .collect();
    let opts = SweepOptions {
        values,
        modes: 2,
        t: 0.0,
        keep_vectors: true,
    };
    let pts = sweep(&nog, &SweepParameter::Dof(0), &opts, &|_, _| {}).unwrap();
    let basis =
        interpolated_basis_from_sweep(mech.q0(), 0, &pts, 1..2, SubspaceInterpolation::Msi, true)
            .unwrap();
    ReducedModel::new(mech, Box::new(basis)).unwrap()
}

fn guidance(c: &mut Criterion) {
    let mut m = msi2();
    // the gravity equilibrium at t = 0, then the response to the pulse
    let z0 = m
        .newton_equilibrium(0.0, &m.basis().z_reference(), &[])
        .unwrap();
    let states = common::trajectory(&mut m, Integrator::Adams, (0.0, 0.3, 601), &z0);
    common::bench_model(
        c,
        "MSI-2, spatial guidance (n_q = 44, n_z = 2)",
        &mut m,
        &states,
        true,
    );
    // MODAL-13 in deformation DOFs, the response to the pulse from rest
    let mech = Arc::new(
        common::scene("straight_guidance_spatial.ron")
            .build(None)
            .unwrap(),
    );
    let basis = modal_basis(&mech, 0.0, &mech.q0(), 13, None).unwrap();
    let mut m = ReducedModel::new(mech, Box::new(basis)).unwrap();
    let states = common::trajectory(&mut m, Integrator::Adams, (0.0, 0.02, 41), &[0.0; 13]);
    common::bench_model(
        c,
        "MODAL-13, spatial guidance (n_q = 44, n_z = 13)",
        &mut m,
        &states,
        true,
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(300));
    targets = guidance
}
criterion_main!(benches);
