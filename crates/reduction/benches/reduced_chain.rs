//! One evaluation of the reduced equations of motion (6.15), z̈ from (z, ż),
//! of the 720-DOF flexure chain (`fixtures/scenes/flexure_chain_720.ron`,
//! 120 spatial beams, deformation DOFs, an 840 × 840 kinematic Jacobian
//! factorized sparsely) reduced to its first 2, 4 and 8 modes at rest: the
//! cost grows with n_z, not with n_q (no n_q × n_q matrix is formed).
//!
//! "at one state" and "along a trajectory" as in `reduced_guidance`; the
//! trajectory is the first 2 ms of a DOPRI5 run from rest under the tip
//! load. "by the full mass" (the reference path, Mq formed) only for n_z = 8.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_dynamics::Integrator;
use flexmb_reduction::{modal_basis, ReducedModel};
use std::sync::Arc;

mod common;

fn chain(c: &mut Criterion) {
    let mech = Arc::new(common::scene("flexure_chain_720.ron").build(None).unwrap());
    for r in [2, 4, 8] {
        let basis = modal_basis(&mech, 0.0, &mech.q0(), r, None).unwrap();
        let mut m = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
        let states = common::trajectory(&mut m, Integrator::Dopri5, (0.0, 2e-3, 5), &vec![0.0; r]);
        common::bench_model(
            c,
            &format!("modal-{r}, flexure chain (n_q = 720, n_z = {r})"),
            &mut m,
            &states,
            r == 8,
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(300));
    targets = chain
}
criterion_main!(benches);
