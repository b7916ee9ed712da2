//! Statics at large rotations stays on the physical branch. A cantilever of n
//! beams rolled up into a full circle by an end moment M = 2πEI/L, planar and
//! spatial: the deformation functions (5.3), (6.2b) are periodic in the angle
//! between an element's chord and its node frames, so a state with elements
//! turned by π against their nodes satisfies the equations too, and before the
//! branch guard `static_equilibrium` landed on such states depending on the
//! load steps (planar, n = 16: tip rotation 2.82, 6.05 and 4.84 rad for 1, 2
//! and 8 steps, against 2π).

use flexmb_dynamics::{Dynamics, DynamicsError, StaticOptions};
use flexmb_model::{DofChoice, Mechanism, Scene};
use std::f64::consts::PI;
use std::sync::Arc;

const E: f64 = 2.0e11;
/// Side of the square section (m): EI = E b⁴/12 about either axis.
const B: f64 = 0.01;
const L: f64 = 1.0;

fn ei() -> f64 {
    E * B.powi(4) / 12.0
}

/// A cantilever of `n` Euler–Bernoulli beams along x, clamped at A, moment
/// `m` about z at the tip B.
fn cantilever(spatial: bool, n: usize, l: f64, m: f64) -> Arc<Mechanism> {
    Arc::new(cantilever_scene(spatial, n, l, m).build(None).unwrap())
}

fn cantilever_scene(spatial: bool, n: usize, l: f64, m: f64) -> Scene {
    let (dim, a, b, mom, up) = if spatial {
        (
            "Spatial",
            "[0.0, 0.0, 0.0]",
            format!("[{l:?}, 0.0, 0.0]"),
            format!("[0.0, 0.0, {m:?}]"),
            ", up: Some([0.0, 1.0, 0.0])",
        )
    } else {
        (
            "Planar",
            "[0.0, 0.0]",
            format!("[{l:?}, 0.0]"),
            format!("[{m:?}]"),
            "",
        )
    };
    Scene::from_ron_str(&format!(
        r#"(
    dimension: {dim},
    materials: {{ "steel": (e: {E:?}, nu: 0.3, rho: 0.0) }},
    sections: {{ "s": Rectangle(by: {B:?}, bz: {B:?}) }},
    nodes: [ (id: "A", at: {a}), (id: "B", at: {b}) ],
    elements: [ (id: "b", type: Beam((nodes: ("A", "B"), material: "steel", section: "s", n: {n}, timoshenko: false{up}))) ],
    fixed: [ Node("A") ],
    loads: [ (node: "B", moment: Some({mom})) ],
)"#
    ))
    .unwrap()
}

/// The tip pose (x, y, rotation about z) of the equilibrium the solver
/// found, and its nodal coordinates: the configuration the solver's
/// kinematics has there (solving x = F(q) afresh from the straight shape can
/// land on another branch, issue 13 item 4).
fn tip_pose(dy: &Dynamics) -> ([f64; 3], Vec<f64>) {
    let mech = dy.mechanism().clone();
    let x = dy.kinematics().x().to_vec();
    assert!(
        mech.flipped_element(&x).is_none(),
        "an element flipped at the equilibrium"
    );
    let tip = mech.node("B").unwrap();
    let p: Vec<f64> = tip.position.iter().map(|i| x[*i]).collect();
    let o: Vec<f64> = tip
        .orientation
        .as_ref()
        .unwrap()
        .iter()
        .map(|i| x[*i])
        .collect();
    let angle = if o.len() == 1 {
        o[0]
    } else {
        // a rotation about z only: λ = (cos φ/2, 0, 0, sin φ/2); φ in (0, 4π)
        assert!(p[2].abs() < 1e-12 && o[1].abs() < 1e-12 && o[2].abs() < 1e-12);
        let half = o[3].atan2(o[0]);
        2.0 * if half < 0.0 { half + 2.0 * PI } else { half }
    };
    ([p[0], p[1], angle], x)
}

fn equilibrium(mech: &Arc<Mechanism>, steps: usize) -> Result<([f64; 3], Vec<f64>), DynamicsError> {
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: steps,
        ..Default::default()
    };
    let sol = dy.static_equilibrium(0.0, &mech.q0(), &opts)?;
    dy.static_residual(0.0, &sol.q)?;
    Ok(tip_pose(&dy))
}

/// The element's own discretization of the roll-up: under a pure end moment
/// every element of the chain carries the moment M at both ends and no force,
/// the load of a single-element cantilever of length L/n. Its tip pose
/// (Δx, Δy, Δφ), composed n times, is the chain's tip pose.
fn composed_single_elements(spatial: bool, n: usize, m: f64) -> [f64; 3] {
    let one = cantilever(spatial, 1, L / n as f64, m);
    let ([dx, dy, dphi], _) = equilibrium(&one, 1).unwrap();
    let mut pose = [0.0f64; 3];
    for _ in 0..n {
        let (s, c) = pose[2].sin_cos();
        pose = [
            pose[0] + c * dx - s * dy,
            pose[1] + s * dx + c * dy,
            pose[2] + dphi,
        ];
    }
    pose
}

fn roll_up_moment() -> f64 {
    2.0 * PI * ei() / L
}

#[test]
fn the_roll_up_lands_on_the_same_equilibrium_whatever_the_load_steps() {
    for spatial in [false, true] {
        for n in [16, 32] {
            let mech = cantilever(spatial, n, L, roll_up_moment());
            let (tip1, x1) = equilibrium(&mech, 1).unwrap();
            for steps in [2, 8] {
                let (tip, x) = equilibrium(&mech, steps).unwrap();
                let d = x
                    .iter()
                    .zip(&x1)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    d < 1e-8,
                    "spatial {spatial}, n = {n}: {steps} steps give tip {tip:?}, 1 step {tip1:?} (nodal coordinates differ by {d:.2e})"
                );
            }
            // the chain's own discretization: n single elements composed
            let own = composed_single_elements(spatial, n, roll_up_moment());
            let d = (0..3).fold(0.0f64, |m, i| m.max((tip1[i] - own[i]).abs()));
            assert!(
                d < 1e-8,
                "spatial {spatial}, n = {n}: tip {tip1:?}, composed single elements {own:?}"
            );
        }
    }
}

/// The closed form of the continuum: a full circle, the tip back at the root
/// with rotation 2π. The beams' error in tip position and rotation falls as
/// 1/n²: observed orders log2(e_n / e_2n) for n = 8, 16, 32, 64 within
/// 1.8–2.2 from n = 16 on. At n = 8 (elements turned by π/4) the next term
/// of the error still shows: measured orders 2.23 (position) and 2.44
/// (rotation) from 8 to 16, then 2.05, 2.08 and 2.01, 2.02. The errors are the
/// element's own: bending deformations l0 sin θ of the end slopes θ, (5.3b,c),
/// make the end moment of an arc of angle α = 2θ proportional to ½ sin 2θ
/// instead of θ (tip rotation 2π − 0.174 rad at n = 16).
#[test]
fn the_roll_up_converges_to_the_full_circle_at_second_order() {
    for spatial in [false, true] {
        let errs: Vec<[f64; 2]> = [8, 16, 32, 64]
            .iter()
            .map(|&n| {
                let ([x, y, phi], _) =
                    equilibrium(&cantilever(spatial, n, L, roll_up_moment()), 1).unwrap();
                [x.hypot(y) / L, (phi - 2.0 * PI).abs()]
            })
            .collect();
        for (j, w) in errs.windows(2).enumerate() {
            for (k, what) in ["tip position", "tip rotation"].iter().enumerate() {
                let order = (w[0][k] / w[1][k]).log2();
                let range = if j == 0 { 1.8..=2.5 } else { 1.8..=2.2 };
                assert!(
                    range.contains(&order),
                    "spatial {spatial}: {what} errors {:.3e} → {:.3e}, order {order:.3} (all: {errs:?})",
                    w[0][k],
                    w[1][k]
                );
            }
        }
        println!("spatial {spatial}: errors (tip position / L, tip rotation) {errs:?}");
    }
}

/// An equilibrium search started from a flipped state fails with an error
/// that names the element, instead of converging there.
#[test]
fn a_flipped_start_is_an_error_naming_the_element() {
    let mut s = Scene::from_ron_str(
        r#"(
    dimension: Planar,
    materials: { "steel": (e: 2.0e11, nu: 0.3, rho: 0.0) },
    sections: { "s": Rectangle(by: 0.01, bz: 0.01) },
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
    elements: [ (id: "b", type: Beam((nodes: ("A", "B"), material: "steel", section: "s", n: 4))) ],
    fixed: [ Node("A") ],
    loads: [ (node: "B", force: Some([0.0, -1.0])) ],
)"#,
    )
    .unwrap();
    s.dofs = DofChoice::NodalCoordinates;
    let mech = Arc::new(s.build(None).unwrap());
    // the tip node turned by π against the last element's chord
    let mut q = mech.q0();
    let i = mech
        .dofs
        .iter()
        .position(|c| mech.coordinate_name(*c) == "B.angle")
        .unwrap();
    q[i] = PI;
    let mut dy = Dynamics::new(mech.clone());
    let err = dy
        .static_equilibrium(0.0, &q, &StaticOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("element 'b.4' has flipped") && err.contains("180.0°"),
        "{err}"
    );
}

/// The spatial roll-up with absolute nodal coordinates as DOFs: the nodes'
/// Euler parameters are DOFs, three per node with the fourth dependent, a
/// chart that is singular 180° from where it was chosen. The static solve
/// switches the chart of each node that turns past it and reaches the full
/// circle, the same equilibrium as with deformations as DOFs.
#[test]
fn the_roll_up_with_nodal_dofs_switches_charts_and_reaches_the_full_circle() {
    let n = 16;
    let (reference, x_ref) = equilibrium(&cantilever(true, n, L, roll_up_moment()), 1).unwrap();
    let mut scene = cantilever_scene(true, n, L, roll_up_moment());
    scene.dofs = DofChoice::NodalCoordinates;
    let mech = Arc::new(scene.build(None).unwrap());
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: 16,
        ..Default::default()
    };
    let sol = dy.static_equilibrium(0.0, &mech.q0(), &opts).unwrap();
    // every node past about 127° switched once or more (the tip turns 2π)
    assert!(
        sol.chart_switches.len() >= n / 2,
        "{} chart switches: {:?}",
        sol.chart_switches.len(),
        sol.chart_switches
    );
    // in balance, in the chart the solve ended in
    let g = dy.static_residual(0.0, &sol.q).unwrap();
    assert!(g.iter().all(|v| v.abs() < 1e-6), "out of balance {g:?}");
    let (tip, x) = tip_pose(&dy);
    let d = x
        .iter()
        .zip(&x_ref)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // λ and −λ are the same orientation: compare positions and the tip pose
    let dp = mech
        .nodes
        .iter()
        .flat_map(|nd| nd.position.iter())
        .fold(0.0f64, |m, &i| m.max((x[i] - x_ref[i]).abs()));
    // measured: 4.4e-12 m and 2.9e-11 rad, 14 switches
    assert!(
        dp < 1e-10,
        "positions differ by {dp:e} (all coordinates by {d:e}): tip {tip:?} against {reference:?}"
    );
    assert!(
        (tip[2] - reference[2]).abs() < 1e-9,
        "{tip:?} against {reference:?}"
    );
}

/// When a node's orientation really cannot go on (issue 15 item 4), the
/// error names the node and the reason: the tip's Euler parameter B.l3,
/// a DOF of its chart, is held and driven to 0.9999 (the tip turned by
/// 178.4°, B.l0 = 0.014). Its chart cannot switch, since the parameter
/// that would become dependent is held, so the dependent B.l0 approaches
/// zero where that chart is singular.
#[test]
fn a_held_euler_parameter_driven_to_the_charts_singularity_names_the_node() {
    let mut scene = cantilever_scene(true, 8, L, 0.0);
    scene.dofs = DofChoice::NodalCoordinates;
    let mech = Arc::new(scene.build(None).unwrap());
    let l3 = mech.x_names.iter().position(|s| s == "B.l3").unwrap();
    let slot = mech
        .dofs
        .iter()
        .position(|c| *c == flexmb_model::Coordinate::Node(l3))
        .expect("B.l3 is a DOF of B's chart");
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: 8,
        held: vec![(slot, 0.9999)],
        ..Default::default()
    };
    let err = dy
        .static_equilibrium(0.0, &mech.q0(), &opts)
        .expect_err("the held chart is singular at the target");
    let msg = err.to_string();
    for part in ["node B", "B.l0", "approaches zero"] {
        assert!(msg.contains(part), "`{part}` missing from: {msg}");
    }
    // the same held value short of the singular region is reached: the
    // failure is the chart's, not the solver's
    let near = StaticOptions {
        held: vec![(slot, 0.99)],
        ..opts
    };
    let mut dy = Dynamics::new(mech.clone());
    let sol = dy.static_equilibrium(0.0, &mech.q0(), &near).unwrap();
    let x = dy.kinematics().x();
    assert!((x[l3] - 0.99).abs() < 1e-12, "{}", x[l3]);
    assert!(sol.chart_switches.iter().all(|c| c.node != "B"));
}

/// The planar roll-up with rigid elongations and nodal coordinates as DOFs:
/// the x of each node is dependent at the reference (solved from its
/// element's rigid elongation), which no longer determines it once the
/// element has turned near 90°. The static solve chooses the dependent set
/// again where it got ill-conditioned (issue 15; before, it stopped at load
/// factor 0.26 with a position solve that "did not converge") and reaches
/// the full circle, the equilibrium of the same scene with deformations as
/// DOFs.
#[test]
fn the_planar_roll_up_with_nodal_dofs_and_rigid_elongations_repartitions_to_the_full_circle() {
    let n = 16;
    let rigid = || vec![flexmb_model::Select::Def("b".into(), "elongation".into())];
    let mut by_deformations = cantilever_scene(false, n, L, roll_up_moment());
    by_deformations.rigid = rigid();
    let reference = Arc::new(by_deformations.build(None).unwrap());
    let (tip_ref, x_ref) = equilibrium(&reference, 16).unwrap();
    let mut scene = cantilever_scene(false, n, L, roll_up_moment());
    scene.dofs = DofChoice::NodalCoordinates;
    scene.rigid = rigid();
    let mech = Arc::new(scene.build(None).unwrap());
    assert!(!mech.partition_eligible().is_empty());
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: 16,
        ..Default::default()
    };
    let sol = dy.static_equilibrium(0.0, &mech.q0(), &opts).unwrap();
    // element k turns by (k + ½)/n of the full circle: the x of every node
    // from the fifth on passes 90° and becomes a DOF at some switch; the
    // switches happen between load increments, at increasing load factors
    let mut freed: Vec<&str> = sol
        .partition_switches
        .iter()
        .flat_map(|s| s.now_dof.iter().filter(|c| c.ends_with(".x")))
        .map(|c| c.as_str())
        .collect();
    freed.sort_unstable();
    freed.dedup();
    assert!(
        freed.len() >= 3 * n / 4,
        "x coordinates made DOFs: {freed:?} in {:?}",
        sol.partition_switches
    );
    let lf: Vec<f64> = sol.partition_switches.iter().map(|s| s.t).collect();
    assert!(
        lf.windows(2).all(|w| w[0] < w[1]) && lf.iter().all(|l| *l > 0.0 && *l < 1.0),
        "load factors of the switches: {lf:?}"
    );
    assert!(sol.chart_switches.is_empty());
    let g = dy.static_residual(0.0, &sol.q).unwrap();
    assert!(g.iter().all(|v| v.abs() < 1e-6), "out of balance {g:?}");
    let (tip, x) = tip_pose(&dy);
    let d = x
        .iter()
        .zip(&x_ref)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // measured: 9.2e-11 m, after 4 changes of the dependent set in 55
    // increments
    assert!(
        d < 1e-9,
        "nodal coordinates differ by {d:e}: {tip:?} against {tip_ref:?}"
    );
    // the whole way round (the chain's own discretization error aside)
    assert!(tip[2] > 1.9 * PI, "{tip:?}");
}

/// A held DOF keeps its coordinate through a re-partitioning: the tip's
/// angle B.angle held and driven to 3π/2 (three quarters of a turn) rolls
/// the rigid-elongation chain up; its x coordinates lose their
/// determination on the way, the held angle stays the DOF it is, and the
/// equilibrium is the roll-up under the moment that holds it (its
/// reaction), solved with deformations as DOFs.
#[test]
fn a_held_dof_stays_a_dof_when_the_static_solve_repartitions() {
    let n = 8;
    let build = |dofs: DofChoice, moment: f64| {
        let mut s = cantilever_scene(false, n, L, moment);
        s.dofs = dofs;
        s.rigid = vec![flexmb_model::Select::Def("b".into(), "elongation".into())];
        Arc::new(s.build(None).unwrap())
    };
    let mech = build(DofChoice::NodalCoordinates, 0.0);
    let phi = mech.x_names.iter().position(|s| s == "B.angle").unwrap();
    let slot = mech
        .dofs
        .iter()
        .position(|c| *c == flexmb_model::Coordinate::Node(phi))
        .expect("B.angle is a DOF");
    let mut dy = Dynamics::new(mech.clone());
    let opts = StaticOptions {
        load_steps: 12,
        held: vec![(slot, 1.5 * PI)],
        ..Default::default()
    };
    let sol = dy.static_equilibrium(0.0, &mech.q0(), &opts).unwrap();
    assert!(!sol.partition_switches.is_empty(), "no re-partitioning");
    assert_eq!(
        dy.mechanism().dofs[slot],
        flexmb_model::Coordinate::Node(phi)
    );
    assert!((dy.kinematics().x()[phi] - 1.5 * PI).abs() < 1e-12);
    let x = dy.kinematics().x().to_vec();
    // the same chain under the holding moment
    let moment = sol.reactions[0];
    let (tip, x_ref) = equilibrium(&build(DofChoice::Deformations, moment), 12).unwrap();
    assert!(
        (tip[2] - 1.5 * PI).abs() < 1e-8,
        "{tip:?} under {moment} N m"
    );
    let d = x
        .iter()
        .zip(&x_ref)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // measured: 1.8e-11 m, after 2 changes of the dependent set
    assert!(d < 1e-8, "nodal coordinates differ by {d:e}");
}
