//! Euler-parameter charts inside reduced models (issue 15): a free flexible
//! body spinning through two turns. Its floating node's orientation is
//! described by three Euler parameters as DOFs with the fourth dependent, a
//! chart that is singular 180° from where it was chosen. A reduced model
//! whose basis keeps those three as reduced coordinates switches the chart
//! as the unreduced model does; one whose basis mixes them cannot, and
//! stops with the node and the reason named.

use faer::Mat;
use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions};
use flexmb_model::{Mechanism, Scene};
use flexmb_reduction::{modal_basis, FixedBasis, ReducedModel};
use std::sync::Arc;

/// A free beam with a plate at its middle node, spun at 6 rad/s about y
/// (about two turns in 2 s).
fn spinning_beam() -> Arc<Mechanism> {
    let text = r#"(
        dimension: Spatial,
        materials: { "polymer": (e: 5.0e8, nu: 0.35, rho: 1200.0) },
        sections: { "bar": Rectangle(by: 0.02, bz: 0.005) },
        nodes: [ (id: "A", at: [-0.3, 0.0, 0.0]), (id: "B", at: [0.3, 0.0, 0.0]) ],
        elements: [
            (id: "beam", type: Beam((nodes: ("A", "B"), material: "polymer", section: "bar", up: Some([0.0, 1.0, 0.0]), n: 2))),
            (id: "plate", type: RigidBody(node: "beam.n1", mass: 0.05, inertia: [[1.0e-3, 0.0, 0.0], [0.0, 0.6e-3, 0.0], [0.0, 0.0, 1.6e-3]])),
        ],
        rigid: [ Def("beam", "elongation"), Def("beam", "torsion") ],
        initial_velocity: [ (omega: Some([0.06, 6.0, 0.06]), about: Some([0.0, 0.0, 0.0])) ],
    )"#;
    Arc::new(Scene::from_ron_str(text).unwrap().build(None).unwrap())
}

fn options() -> SimulationOptions {
    let mut opts = SimulationOptions::new(Integrator::Dopri5, 0.0, 2.0, 41);
    opts.rtol = 1e-10;
    opts.atol = 1e-12;
    opts
}

/// The unreduced run: its nodal coordinates at the outputs and the number
/// of chart switches.
fn unreduced(mech: &Arc<Mechanism>) -> (Vec<Vec<f64>>, usize) {
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = dy.initial_qd(0.0, &q0).unwrap();
    let tr = dy
        .simulate(0.0, &q0, &qd0, &options(), |_, _, _| Control::Continue)
        .unwrap();
    (tr.x, tr.chart_switches.len())
}

/// A reduced model of `mech` over `basis`, started from the scene's
/// initial velocities projected on it.
fn reduced_run(
    mech: &Arc<Mechanism>,
    basis: FixedBasis,
) -> Result<flexmb_reduction::ReducedTrajectory, String> {
    let n_z = basis.v.ncols();
    let mut red = ReducedModel::new(mech.clone(), Box::new(basis)).unwrap();
    let q0 = mech.q0();
    let qd0 = Dynamics::new(mech.clone()).initial_qd(0.0, &q0).unwrap();
    let z0 = vec![0.0; n_z];
    let zd0 = red.project_velocities(0.0, &z0, &qd0).unwrap();
    red.simulate(0.0, &z0, &zd0, &options(), |_, _, _| Control::Continue)
        .map_err(|e| e.to_string())
}

/// The largest difference of the nodal positions of two runs.
fn position_difference(mech: &Mechanism, a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    let pos: Vec<usize> = mech
        .nodes
        .iter()
        .flat_map(|n| n.position.iter().copied())
        .collect();
    a.iter().zip(b).fold(0.0f64, |m, (xa, xb)| {
        pos.iter().fold(m, |m, &i| m.max((xa[i] - xb[i]).abs()))
    })
}

/// The DOF slots of the floating node's three Euler parameters.
fn euler_slots(mech: &Mechanism) -> [usize; 3] {
    let charts = mech.euler_charts();
    assert_eq!(charts.len(), 1, "one floating node: {charts:?}");
    charts[0].dofs.map(|(k, _)| k)
}

/// V = I keeps every coordinate: the reduced model is the unreduced one,
/// and it switches the floating node's chart as that one does and follows
/// it through both turns. Without the switch it stopped at the first half
/// turn (the node's dependent parameter reaching zero).
#[test]
fn a_reduced_model_that_keeps_the_euler_parameters_switches_charts() {
    let mech = spinning_beam();
    let (x_full, switches_full) = unreduced(&mech);
    assert!(switches_full >= 2, "{switches_full} switches unreduced");
    let n = mech.n_dof();
    let basis = FixedBasis {
        q0: mech.q0(),
        v: Mat::identity(n, n),
    };
    let tr = reduced_run(&mech, basis).unwrap();
    assert!(!tr.stopped);
    assert_eq!(tr.t.len(), 41);
    assert_eq!(tr.chart_switches.len(), switches_full);
    let d = position_difference(&mech, &tr.x, &x_full);
    // measured: 1.0e-12 m (the body is 0.6 m long)
    assert!(d < 1e-9, "positions differ by {d:e} m");
    // z is in the chart the run started with: with V = I and q0 the
    // reference, z + q0 are the unreduced DOFs of that chart, i.e. the
    // nodal coordinates the start chart has in those slots
    let slots = euler_slots(&mech);
    let q0 = mech.q0();
    let mut dz = 0.0f64;
    for (z, x) in tr.z.iter().zip(&tr.x) {
        for &k in &slots {
            let flexmb_model::Coordinate::Node(i) = mech.dofs[k] else {
                panic!("an Euler parameter DOF is a nodal coordinate")
            };
            dz = dz.max((z[k] + q0[k] - x[i]).abs());
        }
    }
    // measured: 0 (z is read from x in those slots)
    assert!(dz < 1e-12, "z off the start chart by {dz:e}");
}

/// A modal basis with the floating node's coordinates as its large
/// coordinates (thesis (5.20)) and four modes of the rest: a real
/// reduction, which switches the chart and follows the unreduced run
/// through both turns.
#[test]
fn a_modal_basis_with_the_floating_node_kept_turns_through_two_turns() {
    let mech = spinning_beam();
    let (x_full, switches_full) = unreduced(&mech);
    let charts = mech.euler_charts();
    let node = &mech.nodes[charts[0].node];
    let large: Vec<usize> = node
        .position
        .iter()
        .chain(node.orientation.as_ref().unwrap())
        .filter_map(|i| {
            mech.dofs
                .iter()
                .position(|c| *c == flexmb_model::Coordinate::Node(*i))
        })
        .collect();
    assert_eq!(large.len(), 6);
    let basis = modal_basis(&mech, 0.0, &mech.q0(), 4, Some(&large)).unwrap();
    assert!(basis.v.ncols() < mech.n_dof(), "a reduction");
    let tr = reduced_run(&mech, basis).unwrap();
    assert_eq!(tr.t.len(), 41);
    assert_eq!(tr.chart_switches.len(), switches_full);
    let d = position_difference(&mech, &tr.x, &x_full);
    // the reduction's error: measured 2.2e-4 m (the body is 0.6 m long;
    // V = I above agrees to 1e-12 m)
    assert!(d < 1e-3, "positions differ by {d:e} m");
}

/// Item 4 of issue 15: when a run really cannot go on for an orientation,
/// the message names the node and the reason. The same V = I but with the
/// floating node's three Euler parameters mixed by a rotation: the same
/// model, but no reduced coordinate stands for one parameter, so the chart
/// cannot switch and the half turn is the end.
#[test]
fn a_reduced_model_that_mixes_the_euler_parameters_stops_naming_the_node() {
    let mech = spinning_beam();
    let n = mech.n_dof();
    let slots = euler_slots(&mech);
    let mut v = Mat::<f64>::identity(n, n);
    let (c, s) = (0.6, 0.8);
    let mix = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    for (a, &ka) in slots.iter().enumerate() {
        for (b, &kb) in slots.iter().enumerate() {
            v[(ka, kb)] = mix[a][b];
        }
    }
    let e = reduced_run(&mech, FixedBasis { q0: mech.q0(), v }).unwrap_err();
    let node = &mech.nodes[mech.euler_charts()[0].node].id;
    for part in [
        format!("node {node}: its Euler parameter"),
        "approaches zero".to_string(),
        "180°".to_string(),
        "a reduced model switches only the charts whose Euler parameters its basis keeps"
            .to_string(),
    ] {
        assert!(e.contains(&part), "'{part}' missing from: {e}");
    }
}
