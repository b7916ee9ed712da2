//! Eigenfrequencies against analytic beam theory, stress stiffening (G),
//! buckling, the straight guidance's first mode, a PD-controlled link, and MAC
//! tracking through a crossing and a veering.

use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_linearize::*;
use flexmb_model::Scene;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

fn dynamics(text: &str) -> Dynamics {
    Dynamics::new(Arc::new(
        Scene::from_ron_str(text).unwrap().build(None).unwrap(),
    ))
}

fn rest_modes(dy: &mut Dynamics, k: usize) -> Vec<f64> {
    let q0 = dy.mechanism().q0();
    let lin = dy.linearize_at_rest(0.0, &q0).unwrap();
    undamped_modes(&lin, k).unwrap().frequencies_hz()
}

/// Steel cantilever L = 1 m, 20 × 10 mm, n spatial Euler–Bernoulli beams.
fn cantilever(n: usize) -> String {
    format!(
        r#"(
        materials: {{ "steel": (e: 2.1e11, g: 8.0e10, rho: 7800.0) }},
        sections: {{ "bar": Rectangle(by: 0.02, bz: 0.01) }},
        nodes: [ (id: "A", at: [0.0, 0.0, 0.0]), (id: "B", at: [1.0, 0.0, 0.0]) ],
        elements: [ (id: "beam", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", up: Some([0.0, 1.0, 0.0]), n: {n}, timoshenko: false))) ],
        fixed: [ Node("A") ],
    )"#
    )
}

/// Relative errors of the first four bending frequencies in both planes and
/// the first torsion frequency against Euler–Bernoulli and St Venant theory.
fn cantilever_errors(n: usize) -> Vec<(String, f64)> {
    let (e, g, rho, l, by, bz): (f64, f64, f64, f64, f64, f64) =
        (2.1e11, 8.0e10, 7800.0, 1.0, 0.02, 0.01);
    let a = by * bz;
    let (iz, iy) = (bz * by.powi(3) / 12.0, by * bz.powi(3) / 12.0);
    let j = flexmb_element::rectangle_torsion_constant(by, bz);
    let beta = [
        1.875_104_068_711_961,
        4.694_091_132_974_175,
        7.854_757_438_237_613,
        10.995_540_734_875_467,
    ];
    let bend = |i: f64, b: f64| b * b / (l * l) * (e * i / (rho * a)).sqrt() / (2.0 * PI);
    let mut expected: Vec<(String, f64)> = vec![];
    for (k, b) in beta.iter().enumerate() {
        expected.push((format!("bending about y, mode {}", k + 1), bend(iy, *b)));
        expected.push((format!("bending about z, mode {}", k + 1), bend(iz, *b)));
    }
    expected.push((
        "torsion, mode 1".into(),
        PI / (2.0 * l) * (g * j / (rho * (iy + iz))).sqrt() / (2.0 * PI),
    ));
    let mut dy = dynamics(&cantilever(n));
    let f = rest_modes(&mut dy, 40);
    // match each analytic frequency with the closest computed one
    expected
        .into_iter()
        .map(|(name, fe)| {
            let got = f
                .iter()
                .copied()
                .min_by(|x, y| (x - fe).abs().total_cmp(&(y - fe).abs()))
                .unwrap();
            (name, got / fe - 1.0)
        })
        .collect()
}

#[test]
fn cantilever_frequencies_converge_to_beam_theory() {
    let e4: Vec<(String, f64)> = cantilever_errors(4);
    let e8 = cantilever_errors(8);
    let e16 = cantilever_errors(16);
    for ((name, a), ((_, b), (_, c))) in e4.iter().zip(e8.iter().zip(&e16)) {
        eprintln!("{name}: relative error n=4 {a:+.2e}, n=8 {b:+.2e}, n=16 {c:+.2e}");
        // convergence: the error shrinks with refinement down to the rotary
        // inertia of the consistent mass, which Euler–Bernoulli theory omits
        // (a shift of order (β r)² with r² = I/A, ≤ 4e-3 for mode 4 here)
        assert!(c.abs() <= a.abs() + 1e-4, "{name}: {a:e} {b:e} {c:e}");
    }
    // 8 elements (measured: bending ≤ 1.7e-3 for mode 4, ≤ 7e-4 for mode 3,
    // ≤ 5e-4 for modes 1–2; torsion 1.6e-3, converging quadratically with its
    // linear interpolation: 6.4e-3, 1.6e-3, 4.0e-4 for n = 4, 8, 16)
    assert!(
        (e16.last().unwrap().1 / e8.last().unwrap().1 - 0.25).abs() < 0.05,
        "torsion converges quadratically"
    );
    for (name, err) in &e8 {
        let tol = if name.contains("torsion") {
            2e-3
        } else if name.contains("mode 4") {
            2.5e-3
        } else if name.contains("mode 3") {
            1e-3
        } else {
            6e-4
        };
        assert!(err.abs() < tol, "{name}: 8-element relative error {err:e}");
    }
}

#[test]
fn axial_tension_stiffens_bending_as_beam_theory_predicts() {
    // pinned–pinned planar beam, L = 1 m, under axial tension P = 0.5 π²EI/L²:
    // ω₁²(P)/ω₁²(0) = 1 + P L²/(π² EI) = 1.5 (thesis G matrix)
    let (e, i) = (2.1e11, 0.02f64 * 0.005f64.powi(3) / 12.0);
    let p = 0.5 * PI * PI * e * i;
    let text = |load: f64| {
        format!(
            r#"(
            dimension: Planar,
            materials: {{ "steel": (e: 2.1e11, rho: 7800.0) }},
            sections: {{ "bar": Rectangle(by: 0.005, bz: 0.02) }},
            nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
            elements: [ (id: "beam", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", n: 16, timoshenko: false))) ],
            fixed: [ Coord("A", Position), Coord("B", Y) ],
            loads: [ (node: "B", force: Some([{load}, 0.0])) ],
        )"#
        )
    };
    let f1 = |load: f64| {
        let mut dy = dynamics(&text(load));
        let q0 = dy.mechanism().q0();
        let st = dy
            .static_equilibrium(0.0, &q0, &Default::default())
            .unwrap();
        let lin = dy.linearize_at_rest(0.0, &st.q).unwrap();
        undamped_modes(&lin, 1).unwrap().frequencies_hz()[0]
    };
    let ratio = (f1(p) / f1(0.0)).powi(2);
    assert!((ratio / 1.5 - 1.0).abs() < 1e-3, "ω² ratio {ratio} vs 1.5");
    // compression halves it: 1 − 0.5
    let ratio_c = (f1(-p) / f1(0.0)).powi(2);
    assert!(
        (ratio_c / 0.5 - 1.0).abs() < 2e-3,
        "ω² ratio {ratio_c} vs 0.5"
    );
}

#[test]
fn euler_column_buckling_factor() {
    // clamped–free column under compression P: μ = P_cr / P with P_cr = π²EI/(4L²)
    let (e, i) = (2.1e11, 0.02f64 * 0.005f64.powi(3) / 12.0);
    let pcr = PI * PI * e * i / 4.0;
    let text = format!(
        r#"(
        dimension: Planar,
        materials: {{ "steel": (e: 2.1e11, rho: 7800.0) }},
        sections: {{ "bar": Rectangle(by: 0.005, bz: 0.02) }},
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.0, 1.0]) ],
        elements: [ (id: "col", type: Beam((nodes: ("A", "B"), material: "steel", section: "bar", n: 8, timoshenko: false))) ],
        fixed: [ Node("A") ],
        loads: [ (node: "B", force: Some([0.0, {}])) ],
    )"#,
        -0.1 * pcr
    );
    let mut dy = dynamics(&text);
    let q0 = dy.mechanism().q0();
    let st = dy
        .static_equilibrium(0.0, &q0, &Default::default())
        .unwrap();
    let lin = dy.linearize_at_rest(0.0, &st.q).unwrap();
    let mu = buckling_factors(&lin, 1).unwrap()[0];
    assert!((mu / 10.0 - 1.0).abs() < 2e-3, "buckling factor {mu} vs 10");
}

#[test]
fn straight_guidance_first_frequency_matches_the_parallel_guide_estimate() {
    // two clamped–guided flexures: k = 2·12EI/L³; mass = body + 2·(13/35)·flexure
    // (Rayleigh with the guided-beam shape 3ξ² − 2ξ³)
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes/straight_guidance_spatial.ron");
    let mut s = Scene::load(&p).unwrap();
    s.gravity = None;
    let mut dy = Dynamics::new(Arc::new(s.build(None).unwrap()));
    let f = rest_modes(&mut dy, 1)[0];
    let (e, rho, l): (f64, f64, f64) = (2.1e11, 7600.0, 0.2);
    let i = 0.03 * 1e-3f64.powi(3) / 12.0;
    let k = 2.0 * 12.0 * e * i / l.powi(3);
    let m = rho * 0.2 * 9e-4 + 2.0 * 13.0 / 35.0 * rho * l * 3e-5;
    let est = (k / m).sqrt() / (2.0 * PI);
    assert!(
        (f / est - 1.0).abs() < 0.01,
        "ω1 = {f} Hz vs parallel-guide estimate {est} Hz"
    );
}

#[test]
fn pd_controlled_link_has_the_second_order_frequency_and_damping() {
    // rigid massless link L = 0.5 m with a 2 kg tip mass on a PD-controlled
    // hinge: J = m L², ωn = √(kp/J), ζ = kd / (2√(kp J))
    let (m, l, kp, kd): (f64, f64, f64, f64) = (2.0, 0.5, 400.0, 8.0);
    let text = format!(
        r#"(
        dimension: Planar,
        materials: {{ "s": (e: 2.0e11, rho: 0.0) }},
        sections: {{ "b": Circle(d: 0.01) }},
        nodes: [ (id: "G", at: [0.0, 0.0]), (id: "O", position_of: Some("G")), (id: "T", at: [{l}, 0.0]) ],
        elements: [
            (id: "hinge", type: Hinge(nodes: ("G", "O"))),
            (id: "link", type: Beam((nodes: ("O", "T"), material: "s", section: "b", mass: false))),
            (id: "mass", type: PointMass(node: "T", mass: {m})),
        ],
        fixed: [ Node("G") ],
        rigid: [ Def("link", "*") ],
        controllers: [ (on: Def("hinge", "rotation"), kp: {kp}, kd: {kd}, reference: Constant(0.0)) ],
    )"#
    );
    let mut dy = dynamics(&text);
    let q0 = dy.mechanism().q0();
    let lin = dy.linearize(0.0, &q0, &[0.0], &[0.0]).unwrap();
    let modes = damped_modes(&lin).unwrap();
    let j = m * l * l;
    let (wn, zeta) = ((kp / j).sqrt(), kd / (2.0 * (kp * j).sqrt()));
    assert_eq!(modes.len(), 1);
    assert!(
        (modes[0].frequency_hz / (wn / (2.0 * PI)) - 1.0).abs() < 1e-10,
        "{:?}",
        modes[0]
    );
    assert!(
        (modes[0].damping_ratio / zeta - 1.0).abs() < 1e-10,
        "{:?} vs ζ = {zeta}",
        modes[0]
    );
}

/// Mode sets of a 3-DOF system K(s) = diag(1 + s, 2 − s, 4) (+ coupling c
/// between the first two) with M = I, sorted by frequency.
fn family(c: f64) -> (Vec<f64>, Vec<Mat<f64>>, Vec<Vec<f64>>) {
    let s_vals: Vec<f64> = (0..21).map(|i| i as f64 * 0.05).collect();
    let mut sets = vec![];
    let mut freqs = vec![];
    for &s in &s_vals {
        let k = Mat::from_fn(3, 3, |i, j| match (i, j) {
            (0, 0) => 1.0 + s,
            (1, 1) => 2.0 - s,
            (2, 2) => 4.0,
            (0, 1) | (1, 0) => c,
            _ => 0.0,
        });
        let modes = generalized_symmetric(&k, &Mat::identity(3, 3), 3).unwrap();
        freqs.push(modes.omega2.clone());
        sets.push(modes.vectors);
    }
    (s_vals, sets, freqs)
}

#[test]
fn mac_tracking_follows_modes_through_a_crossing_and_reports_a_veering() {
    // crossing (no coupling): at s = 0.5 the two lowest modes cross; sorted by
    // frequency they swap, the tracking keeps each mode on its track
    let (s, sets, _) = family(0.0);
    let tr = track_modes(&sets, None);
    let i_after = s.iter().position(|v| *v > 0.55).unwrap();
    assert_eq!(tr.perms[0], vec![0, 1, 2]);
    assert_eq!(
        tr.perms[i_after][0], 1,
        "track 0 (shape e1) continues as the second-lowest mode after the crossing"
    );
    assert_eq!(tr.perms[i_after][1], 0);
    let min_conf = tr
        .confidence
        .iter()
        .flatten()
        .fold(1.0f64, |m, v| m.min(*v));
    assert!(
        min_conf > 1.0 - 1e-12,
        "a crossing is followed with MAC 1 ({min_conf})"
    );
    // veering (coupling 0.02): the frequencies do not cross and the shapes
    // rotate by 90° within a narrow band of s; MAC tracking then has no good
    // match in the middle of the veering (the confidence dips) and ends with
    // the shapes exchanged between the frequency branches
    let (_, sets, freqs) = family(0.02);
    assert!(
        freqs.iter().all(|w| w[1] - w[0] > 0.03),
        "veering: no crossing"
    );
    let tr = track_modes(&sets, None);
    let dip = tr.confidence.iter().map(|c| c[0]).fold(1.0f64, f64::min);
    assert!(
        dip < 0.9,
        "the MAC of the tracked mode dips in the veering ({dip})"
    );
}
