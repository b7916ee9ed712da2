//! The fixed basis method: V = I reproduces the unreduced model exactly; a
//! modal basis keeps the retained eigenfrequencies at its configuration; the
//! SVD-modal basis reports its singular values.

use faer::Mat;
use flexmb_dynamics::{Dynamics, DynamicsError};
use flexmb_linearize::{sweep, undamped_modes, SweepOptions, SweepParameter};
use flexmb_model::{Component, Mechanism, Scene, Select};
use flexmb_ode::{Dopri5, Dopri5Options, OdeSystem, Output, RhsError, Tolerance};
use flexmb_reduction::*;
use std::path::Path;
use std::sync::Arc;

fn planar_guidance() -> Arc<Mechanism> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_planar.ron");
    Arc::new(Scene::load(&p).unwrap().build(None).unwrap())
}

/// The unreduced equations of motion in the form a reduced model projects:
/// q̈ from Mq and the generalized force of (D.10) (`Dynamics::accelerations`
/// gets the same q̈ by another solve, see its tests).
struct Projected(Dynamics);

impl OdeSystem for Projected {
    fn dim(&self) -> usize {
        2 * self.0.n_q()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.0.n_q();
        let (q, qd) = y.split_at(n);
        let (head, tail) = dy.split_at_mut(n);
        head.copy_from_slice(qd);
        self.0
            .accelerations_by_projection(t, q, qd, tail)
            .map_err(|e| match e {
                // as `Dynamics::first_order_system`: a trial step that folds
                // the mechanism is retried smaller
                DynamicsError::Kinematics { .. } => RhsError::recoverable(e.to_string()),
                _ => RhsError::new(e.to_string()),
            })
    }
}

#[test]
fn identity_basis_reproduces_the_unreduced_trajectory_and_frequencies() {
    let mech = planar_guidance();
    let n = mech.n_dof();
    let q0 = mech.q0();
    let basis = FixedBasis {
        q0: q0.clone(),
        v: Mat::identity(n, n),
    };
    let times: Vec<f64> = (0..21).map(|i| 0.01 * i as f64).collect();
    // unreduced, DOPRI5 at tight tolerances, and reduced with V = I, the
    // same integrator and settings
    let o = Dopri5Options {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-11),
        ..Default::default()
    };
    let mut y0 = q0.clone();
    y0.extend(vec![0.0; n]);
    let full = Dopri5::new(o.clone())
        .solve(
            &mut Projected(Dynamics::new(mech.clone())),
            0.0,
            &y0,
            0.2,
            &Output::Times(times.clone()),
        )
        .unwrap();
    let mut red = ReducedModel::new(mech.clone(), Box::new(basis.clone())).unwrap();
    let sol = Dopri5::new(o)
        .solve(&mut red, 0.0, &vec![0.0; 2 * n], 0.2, &Output::Times(times))
        .unwrap();
    // The reduced path evaluates (6.15) by other products than the
    // unreduced one (F,z Mz by element blocks, issue 18), so the two round
    // differently and the step-size control may take a few other steps
    // (measured: 72876 against 72834); the trajectories still agree far
    // below the integration tolerance (measured 2.8e-14 of 9.4e-3).
    let (a, b) = (sol.stats.rhs_evals as f64, full.stats.rhs_evals as f64);
    assert!(
        (a / b - 1.0).abs() <= 1e-3,
        "the same steps: {a} against {b}"
    );
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    assert_eq!(sol.len(), full.len());
    for i in 0..sol.len() {
        let qf = &full.y(i)[..n];
        let z = sol.y(i);
        for k in 0..n {
            worst = worst.max((q0[k] + z[k] - qf[k]).abs());
            scale = scale.max(qf[k].abs());
        }
    }
    assert!(
        worst <= 1e-10 * scale.max(1e-6),
        "trajectories differ by {worst:e}"
    );
    let f_full = undamped_modes(
        &Dynamics::new(mech.clone())
            .linearize_at_rest(0.0, &q0)
            .unwrap(),
        n,
    )
    .unwrap()
    .frequencies_hz();
    let f_red = fixed_basis_frequencies(&mech, 0.0, &basis, n).unwrap();
    for (a, b) in f_full.iter().zip(&f_red) {
        assert!((a / b - 1.0).abs() < 1e-10, "{a} vs {b}");
    }
}

#[test]
fn modal_basis_keeps_its_eigenfrequencies() {
    // MODAL-3 of thesis §5.4.1: the three retained modes' frequencies at the
    // configuration are exactly those of the unreduced model
    let mech = planar_guidance();
    let q0 = mech.q0();
    let basis = modal_basis(&mech, 0.0, &q0, 3, None).unwrap();
    let f_red = fixed_basis_frequencies(&mech, 0.0, &basis, 3).unwrap();
    let f_full = undamped_modes(
        &Dynamics::new(mech.clone())
            .linearize_at_rest(0.0, &q0)
            .unwrap(),
        3,
    )
    .unwrap()
    .frequencies_hz();
    for (a, b) in f_full.iter().zip(&f_red) {
        assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
    }
    // the reduced model integrates: the pulse moves the body
    let mut red = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
    let sol = Dopri5::new(Dopri5Options::default())
        .solve(&mut red, 0.0, &[0.0; 6], 0.2, &Output::Final)
        .unwrap();
    let z = sol.last().unwrap().1.to_vec();
    assert!(z[..3].iter().any(|v| v.abs() > 1e-6));
}

#[test]
fn svd_modal_basis_from_ten_configurations() {
    // SVDm of thesis §5.4.1: first three modes in ten equidistant
    // configurations over the stroke, weight exponents a = 0 and a = 1, 1 % rule
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_planar.ron");
    let mut s = Scene::load(&p).unwrap();
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    let swept = Arc::new(s.build(None).unwrap());
    let x0 = swept.q0()[0];
    let values: Vec<f64> = (0..10).map(|i| x0 + 0.0833 * i as f64 / 9.0).collect();
    let pts = sweep(
        &swept,
        &SweepParameter::Dof(0),
        &SweepOptions {
            values,
            modes: 4,
            t: 0.0,
            keep_vectors: true,
        },
        &|_, _| {},
    )
    .unwrap();
    for a in [0.0, 1.0] {
        let svd = svd_modal_basis(&swept.q0(), &pts, 3, a, 0.01).unwrap();
        let kept = svd.basis.v.ncols();
        eprintln!(
            "a = {a}: {kept} singular vectors above 1 %, relative values {:?}",
            &svd.relative[..8.min(svd.relative.len())]
        );
        assert!(svd.relative.windows(2).all(|w| w[0] >= w[1]));
        assert!((svd.relative.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((3..=10).contains(&kept), "{kept}");
    }
}

#[test]
fn full_state_and_velocity_projection_invert_each_other_on_the_basis() {
    let mech = planar_guidance();
    let b = modal_basis(&mech, 0.0, &mech.q0(), 3, None).unwrap();
    let v = b.v.clone();
    let mut red = ReducedModel::new(mech.clone(), Box::new(b)).unwrap();
    let (z, zd) = ([0.01, -0.002, 0.003], [0.5, 0.2, -0.1]);
    let (q, qd) = red.full_state(&z, &zd);
    for i in 0..q.len() {
        let vz: f64 = (0..3).map(|k| v[(i, k)] * z[k]).sum();
        let vzd: f64 = (0..3).map(|k| v[(i, k)] * zd[k]).sum();
        assert!((q[i] - mech.q0()[i] - vz).abs() < 1e-15);
        assert!((qd[i] - vzd).abs() < 1e-15);
    }
    // q̇ in the range of G,z is projected back exactly; q̇ = 0 gives ż = 0
    let back = red.project_velocities(0.0, &z, &qd).unwrap();
    for k in 0..3 {
        assert!((back[k] - zd[k]).abs() < 1e-10 * zd[k].abs(), "{back:?}");
    }
    let zero = red
        .project_velocities(0.0, &z, &vec![0.0; q.len()])
        .unwrap();
    assert_eq!(zero, vec![0.0; 3]);
    // a coordinate listed twice as large is refused
    let e = modal_basis(&mech, 0.0, &mech.q0(), 2, Some(&[1, 1])).unwrap_err();
    assert!(e.to_string().contains("listed twice"), "{e}");
}

#[test]
fn a_basis_that_does_not_fit_and_slices_of_the_wrong_length_are_errors() {
    let mech = planar_guidance();
    let n = mech.n_dof();
    // a basis for another mechanism (one coordinate too many)
    let wrong = FixedBasis {
        q0: vec![0.0; n + 1],
        v: Mat::identity(n + 1, 2),
    };
    let msg = ReducedModel::new(mech.clone(), Box::new(wrong))
        .err()
        .expect("a basis of the wrong size")
        .to_string();
    assert!(
        msg.contains(&format!("{}", n + 1)) && msg.contains(&format!("{n} degrees of freedom")),
        "{msg}"
    );
    let empty = FixedBasis {
        q0: mech.q0(),
        v: Mat::zeros(n, 0),
    };
    let msg = ReducedModel::new(mech.clone(), Box::new(empty))
        .err()
        .expect("a basis without reduced coordinates")
        .to_string();
    assert!(msg.contains("0 reduced coordinates"), "{msg}");

    let basis = FixedBasis {
        q0: mech.q0(),
        v: Mat::identity(n, 2),
    };
    let mut red = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
    let mut zdd = [0.0; 2];
    let msg = red
        .accelerations(0.0, &[0.0; 3], &[0.0; 2], &mut zdd)
        .expect_err("z of length 3")
        .to_string();
    assert!(
        msg.contains("z has 3 entries") && msg.contains("2 coordinates"),
        "{msg}"
    );
    let msg = red
        .linearize_at_rest(0.0, &[0.0; 1])
        .expect_err("z of length 1")
        .to_string();
    assert!(msg.contains("z has 1 entries"), "{msg}");
    red.accelerations(0.0, &[0.0; 2], &[0.0; 2], &mut zdd)
        .unwrap();
}
