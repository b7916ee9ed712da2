//! One evaluation of the reduced equations of motion allocates nothing once
//! the model has evaluated a first time: counted by a global allocator over
//! a sequence of moving states (chord steps of the position solve,
//! refinements and refactorizations of the kinematic Jacobian as in a
//! simulation), for an interpolated basis in nodal DOFs with gravity, a
//! modal basis in deformation DOFs, and the 720-DOF chain whose kinematic
//! Jacobian is sparse. (Its own test binary: the allocator counts every
//! thread, so nothing else may run beside it.)

use flexmb_linearize::{sweep, SweepOptions, SweepParameter};
use flexmb_model::{Component, DofChoice, Scene, Select};
use flexmb_reduction::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// The system allocator, counting allocations and reallocations.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the caller's contract is passed on unchanged
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: as above
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn scene(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    Scene::load(&p).unwrap()
}

/// Allocations during `n` evaluations at states moving away from the
/// basis's reference, after one evaluation there.
fn allocations(model: &mut ReducedModel, scale: &[f64], n: usize) -> usize {
    let nz = model.n_z();
    let z0 = model.basis().z_reference();
    let mut zdd = vec![0.0; nz];
    let state = |k: usize| -> (f64, Vec<f64>, Vec<f64>) {
        let a = k as f64 / n as f64;
        let z = z0.iter().zip(scale).map(|(z, s)| z + a * s).collect();
        let zd = scale.iter().map(|s| 10.0 * s).collect();
        (0.04 + 1e-3 * a, z, zd)
    };
    let (t, z, zd) = state(0);
    model.accelerations(t, &z, &zd, &mut zdd).unwrap();
    let states: Vec<_> = (1..=n).map(state).collect();
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for (t, z, zd) in &states {
        model.accelerations(*t, z, zd, &mut zdd).unwrap();
    }
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

#[test]
fn evaluations_do_not_allocate() {
    // MSI-2 of the spatial guidance (nodal DOFs, gravity), from a few knots
    let mut s = scene("straight_guidance_spatial.ron");
    s.dofs = DofChoice::NodalCoordinates;
    s.dofs_first = vec![Select::Coord("S".into(), Component::X)];
    let mech = Arc::new(s.build(None).unwrap());
    let x0 = mech.q0()[0];
    let o = SweepOptions {
        values: (0..7).map(|i| x0 - 0.06 + 0.02 * i as f64).collect(),
        modes: 2,
        t: 0.0,
        keep_vectors: true,
    };
    let pts = sweep(&mech, &SweepParameter::Dof(0), &o, &|_, _| {}).unwrap();
    let basis =
        interpolated_basis_from_sweep(mech.q0(), 0, &pts, 1..2, SubspaceInterpolation::Msi, true)
            .unwrap();
    let mut m = ReducedModel::new(mech, Box::new(basis)).unwrap();
    assert_eq!(allocations(&mut m, &[0.03, 1e-3], 200), 0, "MSI-2");

    // MODAL-2 of the spatial guidance (deformation DOFs, gravity)
    let mech = Arc::new(scene("straight_guidance_spatial.ron").build(None).unwrap());
    let basis = modal_basis(&mech, 0.0, &mech.q0(), 2, None).unwrap();
    let mut m = ReducedModel::new(mech, Box::new(basis)).unwrap();
    assert_eq!(allocations(&mut m, &[5e-3, 1e-3], 200), 0, "MODAL-2");

    // the chain: 720 DOFs, sparse kinematic Jacobian, 8 modes
    let mech = Arc::new(scene("flexure_chain_720.ron").build(None).unwrap());
    let basis = modal_basis(&mech, 0.0, &mech.q0(), 8, None).unwrap();
    let mut m = ReducedModel::new(mech, Box::new(basis)).unwrap();
    assert_eq!(allocations(&mut m, &[1e-3; 8], 20), 0, "chain MODAL-8");
}
