//! Evaluations of the equations of motion of the 44-DOF spatial straight
//! guidance for an instruction count under callgrind, the robust
//! before/after comparison on a shared machine (criterion's `eom` bench
//! times the same evaluations):
//!
//! ```text
//! cargo build --release -p flexmb-dynamics --example eom_instructions
//! valgrind --tool=callgrind --toggle-collect='eom_instructions::at_one_state' \
//!     target/release/examples/eom_instructions one-state
//! valgrind --tool=callgrind --toggle-collect='eom_instructions::along_trajectory' \
//!     target/release/examples/eom_instructions trajectory
//! ```
//!
//! "one-state" repeats `Dynamics::accelerations` 1000 times at a fixed
//! (q, q̇), as the bench's "at one state"; "trajectory" evaluates, in
//! order, the states a DOPRI5 run of the first 2 ms from rest asked for, as
//! its "along a trajectory". Divide the collected instructions by the count
//! printed. The digest printed of the bits of q̈ shows whether a change
//! meant to keep every result kept it to the last bit.

#[path = "../benches/common/mod.rs"]
mod common;

use common::{load, one_state, trajectory};
use flexmb_dynamics::Dynamics;
use std::hint::black_box;

const SCENE: &str = "straight_guidance_spatial.ron";
const REPEATS: usize = 1000;

/// `REPEATS` evaluations at one state (the counted region of "one-state").
#[inline(never)]
fn at_one_state(dy: &mut Dynamics, q: &[f64], qd: &[f64], qdd: &mut [f64]) {
    for _ in 0..REPEATS {
        dy.accelerations(0.05, black_box(q), qd, qdd).unwrap();
    }
}

/// One evaluation at each recorded state, in order (the counted region of
/// "trajectory"); the digest of every q̈.
#[inline(never)]
fn along_trajectory(dy: &mut Dynamics, states: &[(f64, Vec<f64>)], qdd: &mut [f64]) -> u64 {
    let n = dy.n_q();
    let mut digest = 0;
    for (t, y) in states {
        dy.accelerations(*t, black_box(&y[..n]), &y[n..], qdd)
            .unwrap();
        digest = bits_digest(digest, qdd);
    }
    digest
}

/// An FNV-1a digest of the bit patterns of `v`, continuing `h` (0 to
/// start): equal digests before and after a change that should not change
/// any result show it did not, to the last bit.
fn bits_digest(h: u64, v: &[f64]) -> u64 {
    let mut h = if h == 0 { 0xcbf2_9ce4_8422_2325 } else { h };
    for x in v {
        h ^= x.to_bits();
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_default();
    let mut dy = load(SCENE);
    let mut qdd = vec![0.0; dy.n_q()];
    match mode.as_str() {
        "one-state" => {
            let (q, qd) = one_state(&dy);
            dy.accelerations(0.05, &q, &qd, &mut qdd).unwrap();
            at_one_state(&mut dy, &q, &qd, &mut qdd);
            println!(
                "{REPEATS} evaluations at one state; digest of q̈ {:016x}",
                bits_digest(0, &qdd)
            );
        }
        "trajectory" => {
            let states = trajectory(SCENE);
            let digest = along_trajectory(&mut dy, &states, &mut qdd);
            println!(
                "{} evaluations along the trajectory (digest of every q̈ {digest:016x}); {} factorizations, {} refinement steps",
                states.len(),
                dy.kinematics().factorizations(),
                dy.kinematics().refinements()
            );
        }
        _ => {
            eprintln!("usage: eom_instructions one-state|trajectory");
            std::process::exit(2);
        }
    }
}
