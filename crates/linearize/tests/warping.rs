//! The spatial beam with Vlasov warping (`warping:` in a beam's spec) against
//! closed forms and the stored solid (fixtures/curves/solid, made by
//! research/sheet22): a clamped-free sheet
//! at rest converges to the Vlasov torsion frequency; deflected, its
//! out-of-plane modes follow the clamped solid. The chapter-6 guidance with
//! warping beams against the solid is xtask/tests/against_solid.rs (issue 22).

use flexmb_element::rectangle_torsion_constant;
use flexmb_linearize::*;
use flexmb_model::Scene;
use std::f64::consts::PI;
use std::sync::Arc;

const E: f64 = 2.1e11;
const RHO: f64 = 7600.0;
const L: f64 = 0.2;

/// The cantilever sheet of research/sheet22 (length L along y, height `b`
/// along z, thickness `t` along x, clamped at y = 0, tip force `p` along +x):
/// steel with ν = 0.3 in the beam's G = E/2.6. `warping` is the RON of the
/// beam's `warping:` field, `None` for the thesis's beam; `planar` gives the
/// in-plane model (the same sheet bending in the xy-plane).
fn sheet(b: f64, t: f64, n: usize, p: f64, warping: Option<&str>, planar: bool) -> String {
    let w = warping.map_or(String::new(), |w| format!(", warping: Some({w})"));
    let (dim, a, tip, force, up, sec) = if planar {
        (
            "Planar",
            "[0.0, 0.0]",
            format!("[0.0, {L}]"),
            format!("[{p:?}, 0.0]"),
            String::new(),
            format!("Rectangle(by: {t}, bz: {b})"),
        )
    } else {
        (
            "Spatial",
            "[0.0, 0.0, 0.0]",
            format!("[0.0, {L}, 0.0]"),
            format!("[{p:?}, 0.0, 0.0]"),
            ", up: Some([0.0, 0.0, 1.0])".to_string(),
            format!("Rectangle(by: {b}, bz: {t})"),
        )
    };
    format!(
        r#"(
    dimension: {dim},
    materials: {{ "steel": (e: {E}, nu: 0.3, rho: {RHO}) }},
    sections: {{ "sheet": {sec} }},
    nodes: [ (id: "A", at: {a}), (id: "B", at: {tip}) ],
    elements: [ (id: "sheet", type: Beam((nodes: ("A", "B"), material: "steel", section: "sheet"{up}, n: {n}{w}))) ],
    fixed: [Node("A")],
    loads: [ (node: "B", force: Some({force}), function: Some(Constant(1.0))) ],
)"#
    )
}

/// The first `k` frequencies at the end of a load sweep 0 → 1 in `steps`.
fn frequencies(text: &str, k: usize, steps: usize) -> Vec<f64> {
    let mech = Arc::new(Scene::from_ron_str(text).unwrap().build(None).unwrap());
    let values: Vec<f64> = (0..=steps).map(|i| i as f64 / steps as f64).collect();
    let opts = SweepOptions {
        values,
        modes: k,
        t: 0.0,
        keep_vectors: false,
    };
    let pts = sweep(&mech, &SweepParameter::LoadScale, &opts, &|_, _| {}).unwrap();
    pts.last().unwrap().frequencies_hz.clone()
}

/// The out-of-plane frequencies: the spatial model's that the in-plane model
/// does not have (within 1e-5 relative).
fn out_of_plane(spatial: &[f64], planar: &[f64]) -> Vec<f64> {
    spatial
        .iter()
        .copied()
        .filter(|f| !planar.iter().any(|g| (f / g - 1.0).abs() < 1e-5))
        .collect()
}

/// First torsion frequency (Hz) of a clamped-free strip with Vlasov
/// warping torsion: EI_w φ⁗ − GJ φ″ = ω² ρI_p φ, φ(0) = φ′(0) = 0 (the clamp
/// restrains warping), φ″(L) = 0 and GJ φ′(L) − EI_w φ‴(L) = 0 (free end).
/// The first sign change of the 4 × 4 boundary determinant above 0.9 × the
/// St-Venant frequency, refined by bisection.
fn vlasov_torsion_hz(b: f64, t: f64) -> f64 {
    let gj = E / 2.6 * rectangle_torsion_constant(b, t);
    let eiw = E * (b * t).powi(3) / 144.0;
    let ip = RHO * (b * t.powi(3) + t * b.powi(3)) / 12.0;
    let det = |w: f64| {
        let disc = (gj * gj + 4.0 * eiw * w * w * ip).sqrt();
        let a = ((gj + disc) / (2.0 * eiw)).sqrt();
        let c = ((disc - gj) / (2.0 * eiw)).sqrt();
        let el = (-a * L).exp();
        let (s, co) = (c * L).sin_cos();
        let m = [
            [1.0, el, 1.0, 0.0],
            [-a, a * el, 0.0, c],
            [a * a * el, a * a, -c * c * co, -c * c * s],
            [
                (eiw * a.powi(3) - gj * a) * el,
                gj * a - eiw * a.powi(3),
                -(gj * c + eiw * c.powi(3)) * s,
                (gj * c + eiw * c.powi(3)) * co,
            ],
        ];
        nalgebra::Matrix4::from_fn(|i, j| m[i][j]).determinant()
    };
    let st_venant = (gj / ip).sqrt() * PI / (2.0 * L);
    let mut lo = 0.9 * st_venant;
    while det(lo).signum() == det(lo * 1.001).signum() {
        lo *= 1.001;
        assert!(lo < 2.0 * st_venant, "no root below twice St-Venant");
    }
    let mut hi = lo * 1.001;
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if det(lo).signum() == det(mid).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi) / (2.0 * PI)
}

const CLAMPED_TIP_FREE: &str = "(p: Restrained, q: Free)";

#[test]
fn clamped_sheet_at_rest_converges_to_the_vlasov_torsion_frequency() {
    for (b, t) in [(0.03, 0.001), (0.015, 0.0005)] {
        let exact = vlasov_torsion_hz(b, t);
        let planar = frequencies(&sheet(b, t, 40, 0.0, None, true), 8, 1);
        let st_venant = out_of_plane(
            &frequencies(&sheet(b, t, 40, 0.0, None, false), 12, 1),
            &planar,
        )[0];
        let mut errors = vec![];
        for n in [5, 10, 20, 40] {
            let f = frequencies(&sheet(b, t, n, 0.0, Some(CLAMPED_TIP_FREE), false), 12, 1);
            let planar = frequencies(&sheet(b, t, n, 0.0, None, true), 8, 1);
            let o1 = out_of_plane(&f, &planar)[0];
            eprintln!("b = {b}, t = {t}, n = {n}: o1 = {o1:.3} Hz, Vlasov {exact:.3} Hz, St-Venant beam {st_venant:.3} Hz");
            errors.push((o1 / exact - 1.0).abs());
        }
        // the St-Venant beam is 1.8–3.8 % below; the warping beam converges
        assert!(st_venant < exact * 0.99, "{st_venant} against {exact}");
        assert!(errors[3] < 1e-3, "n = 40: {:.4} % off", 100.0 * errors[3]);
        assert!(errors[3] < errors[0], "{errors:?}");
    }
}

/// Rows (P or x, mode, f) of a stored solid CSV of fixtures/curves/solid
/// (regenerated by research/sheet22/run_all.sh) whose `kind` column (if
/// any) is `want`.
fn solid_rows(file: &str, key: usize, want: Option<&str>) -> Vec<(f64, f64)> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/curves/solid")
        .join(file);
    std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .skip(1)
        .filter_map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            let kind_ok = want.is_none_or(|w| c.last() == Some(&w));
            let f_at = if want.is_some() {
                c.len() - 2
            } else {
                c.len() - 1
            };
            kind_ok.then(|| (c[key].parse().unwrap(), c[f_at].parse().unwrap()))
        })
        .collect()
}

/// The first two out-of-plane frequencies of the stored clamped solid at
/// tip load `p` (b = 30 mm, t = 1 mm, 50 × 8 × 2, 10 increments).
fn solid_o1_o2(p: f64) -> [f64; 2] {
    let rows: Vec<f64> = solid_rows("solid_t0.001_nu0_50x8x2_incs10.csv", 5, Some("out"))
        .into_iter()
        .filter(|(pp, _)| (pp - p).abs() < 1e-9 * p.max(1.0))
        .map(|(_, f)| f)
        .collect();
    [rows[0], rows[1]]
}

#[test]
fn deflected_clamped_sheet_with_warping_follows_the_solid() {
    let (b, t, n): (f64, f64, usize) = (0.03, 0.001, 20);
    let ei = E * b * t.powi(3) / 12.0;
    for alpha in [0.5, 1.0, 1.5] {
        let p = alpha * ei / (L * L);
        let solid = solid_o1_o2(p);
        let planar = frequencies(&sheet(b, t, n, p, None, true), 10, 10);
        let gaps = |warping: Option<&str>| {
            let f = frequencies(&sheet(b, t, n, p, warping, false), 16, 10);
            let o = out_of_plane(&f, &planar);
            [o[0] / solid[0] - 1.0, o[1] / solid[1] - 1.0]
        };
        let plain = gaps(None);
        let warped = gaps(Some(CLAMPED_TIP_FREE));
        eprintln!(
            "alpha = {alpha}: solid o1 {:.3}, o2 {:.3} Hz; beam − solid: St-Venant {:+.2} %, {:+.2} %; warping {:+.2} %, {:+.2} %",
            solid[0],
            solid[1],
            100.0 * plain[0],
            100.0 * plain[1],
            100.0 * warped[0],
            100.0 * warped[1]
        );
        // the thesis's beam is 4–11 % below the solid here; the warp-free
        // solid (the beam's clamp) left 0.2–1.4 % (research/sheet22/README.md)
        for k in 0..2 {
            assert!(
                warped[k].abs() < 0.01 && plain[k] < -0.04,
                "alpha {alpha}, o{}: warping {warped:?}, St-Venant {plain:?}",
                k + 1
            );
        }
    }
}
