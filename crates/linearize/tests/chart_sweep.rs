//! A sweep whose equilibria turn orientation nodes past a chart switch
//! (issue 15 item 1): with absolute nodal coordinates as DOFs each node's
//! Euler parameters have one dependent component, a chart singular 180°
//! from where it was chosen. The static solves of a sweep switch it
//! (`Dynamics::static_equilibrium`); the sweep then linearizes each point in
//! the chart its equilibrium was found in, and gives q, the mode shapes and
//! the mass in the chart of the mechanism it was given.

use flexmb_dynamics::Dynamics;
use flexmb_linearize::{sweep_until, SweepOptions, SweepParameter, SweepPoint};
use flexmb_model::{ChartSwitch, Coordinate, DofChoice, Mechanism, Scene};
use std::f64::consts::PI;
use std::sync::Arc;

const E: f64 = 2.0e11;
/// Side of the square section (m).
const B: f64 = 0.01;
/// Beams of the cantilever.
const N: usize = 8;

/// A spatial cantilever of N beams along x (1 m, steel), clamped at A,
/// rolled up by the end moment M = 2πEI/L about z at the tip B: at load
/// scale s its nodes turn by up to 2πs.
fn roll_up(dofs: DofChoice) -> Arc<Mechanism> {
    let m = 2.0 * PI * E * B.powi(4) / 12.0;
    let mut scene = Scene::from_ron_str(&format!(
        r#"(
    dimension: Spatial,
    materials: {{ "steel": (e: {E:?}, nu: 0.3, rho: 7800.0) }},
    sections: {{ "s": Rectangle(by: {B:?}, bz: {B:?}) }},
    nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [1.0, 0.0, 0.0]) ],
    elements: [ (id: "b", type: Beam((nodes: ("A", "B"), material: "steel", section: "s", n: {N}, timoshenko: false, up: Some([0.0, 1.0, 0.0])))) ],
    fixed: [ Node("A") ],
    loads: [ (node: "B", moment: Some([0.0, 0.0, {m:?}])) ],
)"#
    ))
    .unwrap();
    scene.dofs = dofs;
    Arc::new(scene.build(None).unwrap())
}

/// The load sweep s = 0, ⅛, …, 1 (the tip turns by 2πs), and the charts
/// it switched.
fn roll_up_sweep(
    mech: &Arc<Mechanism>,
    keep_vectors: bool,
) -> (Vec<SweepPoint>, Vec<(usize, ChartSwitch)>) {
    let opts = SweepOptions {
        values: (0..=8).map(|i| i as f64 / 8.0).collect(),
        modes: 6,
        t: 0.0,
        keep_vectors,
    };
    let o = sweep_until(mech, &SweepParameter::LoadScale, &opts, &|_, _| {}, None).unwrap();
    assert!(!o.stopped);
    (o.points, o.chart_switches)
}

/// The largest relative difference of two lists of frequencies.
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / y.abs()))
}

/// Up to the full circle, the sweep with nodal DOFs has the frequencies and
/// equilibria of the same sweep with deformations as DOFs (whose charts
/// never switch: no node's Euler parameters are DOFs), and its q are in the
/// chart of the mechanism it was given: every node's three DOF parameters
/// with the dependent one make a unit quaternion, which they would not in
/// a chart that switched.
#[test]
fn a_sweep_with_nodal_dofs_passes_chart_switches_and_has_the_frequencies_of_the_deformation_one() {
    let nodal = roll_up(DofChoice::NodalCoordinates);
    assert!(
        !nodal.euler_charts().is_empty(),
        "the nodes' Euler parameters are DOFs"
    );
    let deformation = roll_up(DofChoice::Deformations);
    assert!(deformation.euler_charts().is_empty());
    // at s = ½ the tip has turned by π: λ0, its dependent parameter at the
    // start, is zero there, and the start chart singular (the static solve
    // fails in it): the sweep gets there only by switching
    let (with_nodal, switches) = roll_up_sweep(&nodal, false);
    let (with_def, none) = roll_up_sweep(&deformation, false);
    assert!(none.is_empty());
    // every node past about 127° switched, the tip more than once
    assert!(switches.len() >= N / 2, "{switches:?}");
    assert!(
        switches.iter().filter(|(_, c)| c.node == "B").count() >= 2,
        "{switches:?}"
    );
    // the equilibria: nodal positions, from the deformation model's q
    // solved by continuation along the sweep
    let mut dy = Dynamics::new(deformation.clone());
    for (a, b) in with_nodal.iter().zip(&with_def) {
        let d = relative_difference(&a.frequencies_hz, &b.frequencies_hz);
        // measured: 3.5e-10 at most
        assert!(
            d < 1e-8,
            "s = {}: {:?} against {:?}",
            a.s,
            a.frequencies_hz,
            b.frequencies_hz
        );
        dy.kinematics_mut().solve(&b.q, 0.0).unwrap();
        let x = dy.kinematics().x();
        // every nodal coordinate that is a DOF: the positions, and the
        // Euler parameters of the sweep's chart (the start chart's: a q in a
        // switched chart would put the old dependent parameter in a slot)
        let (mut dp, mut dl) = (0.0f64, 0.0f64);
        for (k, c) in nodal.dofs.iter().enumerate() {
            if let Coordinate::Node(i) = *c {
                if nodal.nodes.iter().any(|nd| nd.position.contains(&i)) {
                    dp = dp.max((a.q[k] - x[i]).abs());
                } else {
                    dl = dl.max((a.q[k] - x[i]).abs());
                }
            }
        }
        // measured: 3.8e-11 m and 1.1e-10 at most
        assert!(dp < 1e-10, "s = {}: positions differ by {dp:e} m", a.s);
        assert!(dl < 1e-9, "s = {}: Euler parameters differ by {dl:e}", a.s);
    }
}

/// Where a point's equilibrium is in a switched chart, its mode shapes and
/// mass are mapped into the sweep's chart: they are those of a
/// linearization in the sweep's chart itself, where that chart is still
/// regular (the tip at 135°, λ0 = cos 67.5° ≈ 0.38, past the switch at
/// |λ0| < ½ max |λ|).
#[test]
fn the_mapped_modes_and_mass_are_those_of_the_sweeps_chart() {
    let nodal = roll_up(DofChoice::NodalCoordinates);
    let (pts, switches) = roll_up_sweep(&nodal, true);
    let p = &pts[3];
    assert_eq!(p.s, 3.0 / 8.0);
    // its equilibrium is in a switched chart: the tip's switched at s = ⅜
    // or before
    assert!(
        switches.iter().any(|(i, c)| *i <= 3 && c.node == "B"),
        "{switches:?}"
    );
    let mut dy = Dynamics::new(nodal.clone());
    // the start chart's solve from the straight shape may land on another
    // branch: continue along the sweep's points
    for q in pts[..=3].iter().map(|p| &p.q) {
        dy.kinematics_mut().solve(q, 0.0).unwrap();
    }
    dy.set_load_scale(p.s);
    let lin = dy.linearize_at_rest(0.0, &p.q).unwrap();
    let direct = flexmb_linearize::undamped_modes(&lin, 6).unwrap();
    let (m, v) = (p.mass.as_ref().unwrap(), p.modes.as_ref().unwrap());
    let scale = lin.m.norm_max();
    let dm = (m - &lin.m).norm_max() / scale;
    // measured: 5e-15
    assert!(dm < 1e-9, "mass differs by {dm:e} of its largest entry");
    let df = relative_difference(&p.frequencies_hz, &direct.frequencies_hz());
    // measured: 6e-11
    assert!(df < 1e-8, "frequencies differ by {df:e}");
    // the shapes are eigenvectors of the sweep chart's stiffness and mass
    // (the square section has pairs of equal frequencies: compare the
    // eigen equation, not the vectors)
    let k = lin.stiffness_total();
    let k = (&k + k.transpose()) * faer::Scale(0.5);
    for j in 0..6 {
        let a = v.col(j);
        // (signed: the moment, fixed in space, makes some ω² negative)
        let f = p.frequencies_hz[j];
        let w2 = f.signum() * (2.0 * PI * f).powi(2);
        let mv = m * a;
        let r = &k * a - &mv * faer::Scale(w2);
        let size = w2.abs() * mv.norm_max();
        // measured: 9.5e-10 at most
        assert!(
            r.norm_max() < 1e-6 * size,
            "mode {}: K v − ω² M v is {:e} of ω² M v",
            j + 1,
            r.norm_max() / size
        );
        // mass-normalized in the sweep's chart
        let n = a.transpose() * &mv;
        assert!((n - 1.0).abs() < 1e-8, "mode {}: vᵀMv = {n}", j + 1);
    }
}

/// The planar roll-up with rigid elongations: with nodal DOFs the x of each
/// node is solved from its element's elongation, which stops determining
/// it near 90°. The static solves of the sweep choose the dependent set
/// again there (`StaticSolution::partition_switches`), and the sweep has
/// the frequencies of the deformation-DOF sweep all the way round.
#[test]
fn a_planar_sweep_with_nodal_dofs_passes_changes_of_the_dependent_set() {
    let build = |dofs: DofChoice| {
        let m = 2.0 * PI * E * B.powi(4) / 12.0;
        let mut scene = Scene::from_ron_str(&format!(
            r#"(
    dimension: Planar,
    materials: {{ "steel": (e: {E:?}, nu: 0.3, rho: 7800.0) }},
    sections: {{ "s": Rectangle(by: {B:?}, bz: {B:?}) }},
    nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
    elements: [ (id: "b", type: Beam((nodes: ("A", "B"), material: "steel", section: "s", n: {N}, timoshenko: false))) ],
    fixed: [ Node("A") ],
    rigid: [ Def("b", "elongation") ],
    loads: [ (node: "B", moment: Some([{m:?}])) ],
)"#
        ))
        .unwrap();
        scene.dofs = dofs;
        Arc::new(scene.build(None).unwrap())
    };
    let opts = SweepOptions {
        values: (0..=8).map(|i| i as f64 / 8.0).collect(),
        modes: 4,
        t: 0.0,
        keep_vectors: false,
    };
    let run = |mech: &Arc<Mechanism>| {
        sweep_until(mech, &SweepParameter::LoadScale, &opts, &|_, _| {}, None).unwrap()
    };
    let nodal = run(&build(DofChoice::NodalCoordinates));
    let deformation = run(&build(DofChoice::Deformations));
    assert!(
        nodal.partition_switches.len() >= 2,
        "{:?}",
        nodal.partition_switches
    );
    assert!(deformation.partition_switches.is_empty());
    assert_eq!(nodal.points.len(), 9);
    let mut worst = 0.0f64;
    for (a, b) in nodal.points.iter().zip(&deformation.points) {
        worst = worst.max(relative_difference(&a.frequencies_hz, &b.frequencies_hz));
    }
    // measured: 4.7e-11, with 4 changes of the dependent set
    assert!(worst < 1e-8, "frequencies differ by {worst:e}");
}
