//! The thesis's claims of chapter 2 (§2.4.1, Table 2.1), asserted on our
//! models: superelements built by flexmb's builder from solid FE models of
//! the beam segments, against flexmb's non-linear beams.

use flexmb_element::VelocityTransform::{self, B1, B2, B3};
use xtask::ch2::report::{euler_bernoulli_clamped_free, nearest};
use xtask::ch2::segments;
use xtask::ch2::spin_up::{self, Integration};

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-ch2-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The 2 m segment's FE model (20 × 2 × 1 hexahedra) clamped at p has
/// Euler–Bernoulli's in-plane bending frequencies: the first within 0.5 %
/// (measured +0.39 %: the solid is slightly stiffer, its clamped face
/// restraining the Poisson contraction), the second within 1 %.
#[test]
fn the_spin_up_segment_fe_model_bends_as_an_euler_bernoulli_beam() {
    let b = spin_up::segment(4, spin_up::MESH, 40).unwrap();
    let eb = euler_bernoulli_clamped_free(2.0);
    for (k, (target, tol)) in eb.iter().zip([5e-3, 1e-2]).enumerate() {
        let nearest = nearest(&b.fe_frequencies, *target);
        let e = nearest / target - 1.0;
        assert!(
            e.abs() < tol,
            "in-plane mode {}: FE {nearest} Hz against Euler–Bernoulli {target} Hz ({e:+.2e}); FE modes {:?}",
            k + 1,
            b.fe_frequencies
        );
    }
}

/// Table 2.1 with 4 elements:
/// * B2 and B3 "will always give identical results for planar simulations":
///   equal to 1e-9 of the deflection;
/// * B1 differs slightly (thesis: −3e-5 m): by more than 1e-6 and less than
///   1e-3 of the deflection;
/// * "only a small relative difference" between the superelements and the
///   beams of the same elongation formulation (ε1 = l − l0): within 1 %;
/// * each within 1 % of its thesis value.
#[test]
fn table_2_1_superelements_b2_and_b3_agree_and_b1_differs_slightly() {
    let dir = temp_dir("table21");
    let se = spin_up::segment(4, spin_up::MESH, 0).unwrap();
    segments::write(&dir, "s.se.ron", &se.data).unwrap();
    let how = Integration::table(1e-7);
    let run = |t: VelocityTransform| {
        spin_up::run(&spin_up::superelement_scene(4, "s.se.ron", t), &dir, how)
            .unwrap()
            .max()
    };
    let (b1, b2, b3) = (run(B1), run(B2), run(B3));
    let beams = spin_up::run(&spin_up::beam_scene(4, false), &dir, how)
        .unwrap()
        .max();
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("max Δy′: beams {beams}, B1 {b1}, B2 {b2}, B3 {b3}");
    assert!((b2 - b3).abs() < 1e-9 * b3, "B2 {b2} against B3 {b3}");
    let d = (b1 - b2).abs() / b2;
    assert!(d > 1e-6 && d < 1e-3, "B1 {b1} against B2 {b2}: {d:.2e}");
    assert!(
        (b3 / beams - 1.0).abs() < 1e-2,
        "B3 {b3} against the beams {beams}"
    );
    for (v, thesis) in [(beams, 0.5388), (b1, 0.53751), (b3, 0.53754)] {
        assert!(
            (v / thesis - 1.0).abs() < 1e-2,
            "{v} against the thesis's {thesis}"
        );
    }
}

/// The convergence helper: three values converging at order 2 give p = 2
/// and the limit.
#[test]
fn richardson_recovers_the_order_and_the_limit() {
    let f = |n: f64| 0.534 + 0.01 / (n * n);
    let (p, v) = spin_up::richardson(f(2.0), f(4.0), f(8.0)).unwrap();
    assert!(
        (p - 2.0).abs() < 1e-9 && (v - 0.534).abs() < 1e-12,
        "{p} {v}"
    );
    assert!(spin_up::richardson(1.0, 2.0, 1.5).is_none(), "not monotone");
}

/// Figs 2.11–2.12: reversing every element changes the response of B1 only.
/// The universal joint over 0–6 s (DOPRI5, rtol 1e-7): B1's reversed model
/// differs from the original by more than 100 times the larger difference
/// of B2 and B3, which stay below 1e-6 m (rtol × the 0.9 m response: the
/// two are different ODEs integrated to the tolerance). Over 0–20 s the
/// report measured 8.4e-2 m for B1 against 6.6e-10 (B2) and 4.2e-8 m (B3).
#[test]
fn only_b1_is_sensitive_to_reversing_the_elements() {
    use xtask::ch2::universal_joint as uj;
    let dir = temp_dir("reversal");
    for (rev, file) in [(false, "u.se.ron"), (true, "u_rev.se.ron")] {
        segments::write(&dir, file, &uj::segment(rev).unwrap().data).unwrap();
    }
    let difference = |t: VelocityTransform| {
        let run = |rev: bool, file: &str| {
            uj::run(
                &uj::scene(uj::Kind::Superelement(t), rev, file),
                &dir,
                6.0,
                601,
                1e-7,
            )
            .unwrap()
        };
        let d = run(false, "u.se.ron").max_difference(&run(true, "u_rev.se.ron"));
        d[0].max(d[1])
    };
    let (d1, d2, d3) = (difference(B1), difference(B2), difference(B3));
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("reversal differences over 0–6 s: B1 {d1:.2e} m, B2 {d2:.2e} m, B3 {d3:.2e} m");
    assert!(d2 < 1e-6 && d3 < 1e-6, "B2 {d2:.2e} m, B3 {d3:.2e} m");
    assert!(
        d1 > 100.0 * d2.max(d3),
        "B1 {d1:.2e} m against {:.2e} m",
        d2.max(d3)
    );
}

/// The configuration a run keeps for its picture is the one at its largest
/// |Δy′|, as the run reached it: Δy′ recomputed from its nodal coordinates
/// and the spin angle at its time is the run's maximum, and the picture
/// puts the tip there; the report's picture of it is written as SVG and
/// PNG.
#[test]
fn the_spin_up_picture_shows_the_largest_deflection() {
    let dir = temp_dir("picture");
    let scene = spin_up::beam_scene(4, false);
    let tip = spin_up::run(&scene, &dir, Integration::table(1e-6)).unwrap();
    let mut figs = xtask::report::Figures::default();
    let opts = flexmb_draw::DrawOptions {
        view: Some(flexmb_draw::View::Xy),
        reference: true,
        ..Default::default()
    };
    xtask::pictures::save(&mut figs, &dir, "mech", &tip.at_max, &opts).unwrap();
    for ext in ["svg", "png"] {
        let f = dir.join(format!("mech.{ext}"));
        assert!(
            std::fs::metadata(&f)
                .map(|m| m.len() > 1000)
                .unwrap_or(false),
            "{f:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    let at = &tip.at_max;
    let mech = &at.mechanism;
    let spin = mech.inputs[0].function.value(at.t);
    let t_node = mech.node("T").unwrap();
    let (x, y) = (at.x[t_node.position[0]], at.x[t_node.position[1]]);
    let dy = -spin.sin() * x + spin.cos() * y;
    assert!(
        (dy.abs() - tip.max()).abs() <= 1e-12 * tip.max(),
        "Δy′ at the kept configuration {dy} (t = {}), the run's maximum {}",
        at.t,
        tip.max()
    );
    assert!(at.t > 0.0, "the largest deflection is not at the start");
    let k = mech.nodes.iter().position(|n| n.id == "T").unwrap();
    let drawn = flexmb_draw::node_positions(mech, &at.x)[k];
    assert_eq!([drawn[0], drawn[1]], [x, y]);
}

/// Figs 2.9–2.12's ranking ("B3 at least as close to the beams as B2, and
/// B2 closer than B1") cannot be read from our models, and this is why:
/// over 0–6 s of the universal joint, 4 superelements of B1, B2 and B3
/// differ among themselves by far less than 4 from 8 superelements of one
/// transform, so the element count, not the velocity transformation, sets
/// each one's distance from the beams. Measured 3.6e-3 m among the three
/// against 3.2e-2 m (B3, 4 against 8); the report states the claim as not
/// reproduced (docs/reproduce.md).
#[test]
fn the_element_count_not_the_transform_sets_the_distance_to_the_beams() {
    use xtask::ch2::universal_joint as uj;
    let dir = temp_dir("ranking");
    let run = |t: VelocityTransform, n: usize| {
        let file = format!("u{n}.se.ron");
        if !dir.join(&file).exists() {
            segments::write(&dir, &file, &uj::segment_with(false, n).unwrap().data).unwrap();
        }
        uj::run(
            &uj::scene_with(uj::Kind::Superelement(t), false, &file, n),
            &dir,
            6.0,
            601,
            1e-7,
        )
        .unwrap()
    };
    let four = [run(B1, 4), run(B2, 4), run(B3, 4)];
    let eight = run(B3, 8);
    let _ = std::fs::remove_dir_all(&dir);
    let largest = |d: [f64; 2]| d[0].max(d[1]);
    let among = (0..3)
        .flat_map(|a| (a + 1..3).map(move |b| (a, b)))
        .map(|(a, b)| largest(four[a].max_difference(&four[b])))
        .fold(0.0, f64::max);
    let refined = largest(four[2].max_difference(&eight));
    eprintln!("among B1, B2, B3: {among:.2e} m; B3 4 against 8 elements: {refined:.2e} m");
    assert!(
        among < 0.25 * refined,
        "among {among:.2e} m, refinement {refined:.2e} m"
    );
}
