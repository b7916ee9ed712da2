//! The command line end to end: a real scene run, exit codes and messages.

mod common;
use common::flexmb;

use std::path::Path;

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn simulate_writes_csv_and_plot() {
    let out = std::env::temp_dir().join(format!("flexmb-cli-sim-{}", std::process::id()));
    let o = flexmb()
        .args([
            "simulate",
            &fixture("spin_up_planar.ron"),
            "--t-end",
            "2",
            "--outputs",
            "21",
            "--rtol",
            "1e-6",
            "--atol",
            "1e-9",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("function evaluations"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("outputs.csv")).unwrap();
    assert_eq!(
        csv.lines().filter(|l| !l.starts_with('#')).count(),
        22,
        "header + 21 rows"
    );
    assert!(std::fs::read_to_string(out.join("outputs.svg"))
        .unwrap()
        .contains("<polyline"));
    let png = std::fs::read(out.join("outputs.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn static_reports_displacements() {
    let out = std::env::temp_dir().join(format!("flexmb-cli-static-{}", std::process::id()));
    let o = flexmb()
        .args(["static", &fixture("straight_guidance_spatial.ron"), "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("equilibrium found"));
    assert!(out.join("node_positions.csv").exists());
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn bad_input_gives_exit_code_2_and_names_the_problem() {
    let o = flexmb()
        .args(["info", "/no/such/scene.ron"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read /no/such/scene.ron"));
    let dir = std::env::temp_dir().join(format!("flexmb-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.ron");
    std::fs::write(
        &p,
        "(\n  nodes: [ (id: \"A\", at: [0.0, 0.0, 0.0]) ],\n  elements: [ oops ],\n)\n",
    )
    .unwrap();
    let o = flexmb().arg("info").arg(&p).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 3"), "{err}");
    let o = flexmb()
        .args([
            "simulate",
            &fixture("spin_up_planar.ron"),
            "--integrator",
            "euler",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown integrator 'euler'"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn eig_and_sweep_report_frequencies() {
    let o = flexmb()
        .args([
            "eig",
            &fixture("straight_guidance_spatial.ron"),
            "--modes",
            "3",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(s.contains("undamped eigenfrequencies"), "{s}");
    let out = std::env::temp_dir().join(format!("flexmb-cli-sweep-{}", std::process::id()));
    let o = flexmb()
        .args([
            "sweep",
            &fixture("straight_guidance_spatial.ron"),
            "--over",
            "S.x",
            "--from",
            "0",
            "--to",
            "0.08",
            "--n",
            "9",
            "--modes",
            "2",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (h, rows) = flexmb_plot_read(&out.join("eigenfrequencies.csv"));
    assert_eq!(h, vec!["S.x change", "f1_hz", "f2_hz", "hold:S.x"]);
    assert_eq!(rows.len(), 9);
    // the force that holds S.x: zero at the reference, growing along the stroke
    assert!(rows[0][3].abs() < 1e-6, "{}", rows[0][3]);
    assert!(rows.windows(2).all(|w| w[1][3] > w[0][3]));
    // the out-of-plane mode drops sharply over the stroke (thesis Fig. 6.9b)
    assert!(
        rows[8][2] < 0.5 * rows[0][2],
        "ω2 {} → {}",
        rows[0][2],
        rows[8][2]
    );
    assert!(std::fs::read_to_string(out.join("eigenfrequencies.svg"))
        .unwrap()
        .contains("<polyline"));
    let png = std::fs::read(out.join("eigenfrequencies.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let o = flexmb()
        .args([
            "sweep",
            &fixture("straight_guidance_spatial.ron"),
            "--over",
            "Q.x",
            "--from",
            "0",
            "--to",
            "1",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("'Q.x' is neither"));
    std::fs::remove_dir_all(&out).ok();
}

fn flexmb_plot_read(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let h = lines
        .next()
        .unwrap()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (h, rows)
}

// ---------------------------------------------------------------------------
// `flexmb reduce`, `simulate --reduced`, `sweep --reduced` on the planar
// straight guidance (thesis §5.4.1)

use std::path::PathBuf;
use std::process::Output;
use std::sync::OnceLock;

const GUIDANCE: &str = "straight_guidance_planar.ron";
/// The peak of the guidance's force pulse (5.24): load sweeps scale it here.
const T_LOAD: &str = "0.05";
/// Simulated time of the round trips: the pulse and the largest deflection.
const T_END: &str = "0.15";

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("cli", name)
}

/// Runs `flexmb args...` and returns its output.
fn run<S: AsRef<str>>(args: &[S]) -> Output {
    flexmb()
        .args(args.iter().map(|a| a.as_ref()))
        .output()
        .unwrap()
}

/// The command line, for messages.
fn line<S: AsRef<str>>(args: &[S]) -> String {
    args.iter()
        .map(|a| a.as_ref())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Runs `flexmb args...`, requires success and returns stdout.
fn run_ok<S: AsRef<str>>(args: &[S]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "flexmb {}: {}",
        line(args),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs `flexmb args...`, requires exit code 2 (invalid input) and returns stderr.
fn run_bad_input<S: AsRef<str>>(args: &[S]) -> String {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "flexmb {}: {err}", line(args));
    err
}

/// The number in "... N function evaluations" of `flexmb simulate`.
fn evaluations(stdout: &str) -> u64 {
    let before = stdout
        .split(" function evaluations")
        .next()
        .filter(|s| s.len() < stdout.len())
        .unwrap_or_else(|| panic!("no evaluation count in {stdout}"));
    before.rsplit(' ').next().unwrap().parse().unwrap()
}

/// Column `name` of a CSV written by flexmb.
fn column(p: &Path, name: &str) -> Vec<f64> {
    let (h, rows) = flexmb_plot_read(p);
    let k = h
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {h:?}"));
    rows.iter().map(|r| r[k]).collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The unreduced guidance simulated to T_END (computed once, shared by the
/// tests): its evaluation count and the outputs S.x, S.y.
fn unreduced_run() -> &'static (u64, Vec<f64>, Vec<f64>) {
    static RUN: OnceLock<(u64, Vec<f64>, Vec<f64>)> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = temp_dir("unreduced");
        let out = dir.join("sim");
        let s = run_ok(&[
            "simulate",
            &fixture(GUIDANCE),
            "--t-end",
            T_END,
            "--outputs",
            "31",
            "--out",
            out.to_str().unwrap(),
        ]);
        let csv = out.join("outputs.csv");
        let r = (evaluations(&s), column(&csv, "S.x"), column(&csv, "S.y"));
        std::fs::remove_dir_all(&dir).ok();
        r
    })
}

/// Simulates `scene` with the reduced `model` to T_END and checks it against
/// the unreduced run: far fewer evaluations (the thesis's point), and the
/// path of S within `tol` of the largest deflection (the reduced state is
/// mapped back to q = G(z) for the outputs).
fn check_reduced_simulation(scene: &str, model: &Path, out: &Path, tol: f64) {
    let s = run_ok(&[
        "simulate",
        scene,
        "--reduced",
        model.to_str().unwrap(),
        "--t-end",
        T_END,
        "--outputs",
        "31",
        "--out",
        out.to_str().unwrap(),
    ]);
    let (full_evals, x, y) = unreduced_run();
    let evals = evaluations(&s);
    assert!(
        10 * evals < *full_evals,
        "{}: {evals} evaluations, unreduced {full_evals}",
        model.display()
    );
    let csv = out.join("outputs.csv");
    let (xr, yr) = (column(&csv, "S.x"), column(&csv, "S.y"));
    assert_eq!(xr.len(), 31);
    let deflection = x.iter().map(|v| (v - x[0]).abs()).fold(0.0, f64::max);
    assert!(deflection > 0.05, "the pulse moves S: {deflection}");
    let err = (0..31)
        .map(|i| (xr[i] - x[i]).abs().max((yr[i] - y[i]).abs()))
        .fold(0.0, f64::max);
    assert!(
        err < tol * deflection,
        "{}: path of S off by {err:e} (deflection {deflection})",
        model.display()
    );
}

/// Eigenfrequencies along a load sweep (`--from a --to b --n n`), unreduced
/// or with `--reduced model`: one row per load scale (the first at `a`; a
/// sweep has at least two).
fn load_sweep(scene: &str, model: Option<&Path>, range: [&str; 3], out: &Path) -> Vec<Vec<f64>> {
    let mut args = vec!["sweep", scene];
    if let Some(m) = model {
        args.extend(["--reduced", m.to_str().unwrap()]);
    }
    let o = out.to_str().unwrap();
    args.extend([
        "--over", "load", "--from", range[0], "--to", range[1], "--n", range[2], "--modes", "3",
        "--t-load", T_LOAD, "--out", o,
    ]);
    run_ok(&args);
    let csv = out.join("eigenfrequencies.csv");
    let (h, rows) = flexmb_plot_read(&csv);
    assert_eq!(h[0], "load_scale");
    rows
}

#[test]
fn modal_model_keeps_its_frequencies_through_save_load_and_simulates_cheaply() {
    let dir = temp_dir("modal");
    let scene = fixture(GUIDANCE);
    // the unreduced first three frequencies at rest (unloaded equilibrium = reference)
    let full = load_sweep(&scene, None, ["0", "1", "2"], &dir.join("full"));
    let model = dir.join("modal3.ron");
    let s = run_ok(&[
        "reduce",
        &scene,
        "--method",
        "modal",
        "--modes",
        "3",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(s.contains("reduced model: 3 coordinates (from 17)"), "{s}");
    let f = column(&dir.join("modal3.frequencies.csv"), "reduced_hz");
    assert_eq!(f.len(), 3);
    for k in 0..3 {
        assert!(
            rel(f[k], full[0][k + 1]) < 1e-8,
            "ω{}: reduced {} unreduced {}",
            k + 1,
            f[k],
            full[0][k + 1]
        );
    }
    // the saved model, read back by `sweep --reduced`: the same frequencies
    let loaded = load_sweep(&scene, Some(&model), ["0", "1", "2"], &dir.join("red"));
    for k in 0..3 {
        assert!(rel(loaded[0][k + 1], f[k]) < 1e-10, "{loaded:?} vs {f:?}");
    }
    check_reduced_simulation(&scene, &model, &dir.join("sim"), 0.05);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn svd_modal_model_follows_the_load_where_the_modal_model_does_not() {
    let dir = temp_dir("svd");
    let scene = fixture(GUIDANCE);
    let svd = dir.join("svd.ron");
    let s = run_ok(&[
        "reduce",
        &scene,
        "--method",
        "svd-modal",
        "--modes",
        "3",
        "--over",
        "load",
        "--from",
        "-1",
        "--to",
        "1",
        "--t-load",
        T_LOAD,
        "--out",
        svd.to_str().unwrap(),
    ]);
    // the singular values: relative to their sum, the kept ones above 1 %
    let rel_sv = column(&dir.join("svd.singular_values.csv"), "relative");
    assert!((rel_sv.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    let kept = rel_sv.iter().filter(|v| **v > 0.01).count();
    assert!(
        s.contains(&format!("kept {kept} of {}", rel_sv.len())),
        "{s}"
    );
    assert!(
        s.contains(&format!("reduced model: {kept} coordinates")),
        "{s}"
    );
    assert!(std::fs::read_to_string(dir.join("svd.singular_values.svg"))
        .unwrap()
        .contains("<circle"));
    let png = std::fs::read(dir.join("svd.singular_values.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let modal = dir.join("modal3.ron");
    run_ok(&[
        "reduce",
        &scene,
        "--method",
        "modal",
        "--modes",
        "3",
        "--out",
        modal.to_str().unwrap(),
    ]);
    // eigenfrequencies at the static equilibria under ±100 N (S at ±83 mm):
    // the SVD-modal model follows ω1–ω3, the modal one misses ω3 (Fig. 5.5)
    let range = ["-1", "1", "3"];
    let full = load_sweep(&scene, None, range, &dir.join("full"));
    let by_svd = load_sweep(&scene, Some(&svd), range, &dir.join("svd"));
    let by_modal = load_sweep(&scene, Some(&modal), range, &dir.join("modal"));
    for i in 0..3 {
        assert_eq!(by_svd[i][0], full[i][0]);
        for k in 1..=3 {
            assert!(
                rel(by_svd[i][k], full[i][k]) < 5e-3,
                "SVD-modal ω{k} at λ = {}: {} vs {}",
                full[i][0],
                by_svd[i][k],
                full[i][k]
            );
        }
    }
    for i in [0, 2] {
        assert!(
            rel(by_modal[i][3], full[i][3]) > 0.05,
            "MODAL-3 ω3 at λ = {}: {} vs {}",
            full[i][0],
            by_modal[i][3],
            full[i][3]
        );
    }
    check_reduced_simulation(&scene, &svd, &dir.join("sim"), 0.01);
    std::fs::remove_dir_all(&dir).ok();
}

/// The planar guidance with absolute nodal DOFs and the x of S first (the
/// interpolated basis method's s, thesis §6.4).
fn nodal_guidance(dir: &Path) -> String {
    let text = std::fs::read_to_string(fixture(GUIDANCE)).unwrap();
    assert!(text.contains("dofs: Deformations,"));
    let text = text.replace(
        "dofs: Deformations,",
        "dofs: NodalCoordinates,\n    dofs_first: [Coord(\"S\", X)],",
    );
    let p = dir.join("guidance_nodal.ron");
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn msi_model_on_a_nodal_scene_keeps_mode_2_exactly_and_follows_the_load() {
    let dir = temp_dir("msi");
    let scene = nodal_guidance(&dir);
    let model = dir.join("msi2.ron");
    let s = run_ok(&[
        "reduce",
        &scene,
        "--method",
        "ibm-msi",
        "--modes",
        "1",
        "--over",
        "S.x",
        "--from",
        "-0.08",
        "--to",
        "0.08",
        "--n",
        "21",
        "--no-gravity",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(s.contains("reduced model: 2 coordinates (from 17)"), "{s}");
    // at the middle knot (the reference) mode 2 is in the basis, so the
    // reduced ω2 is exact; ω1 comes from Q'(s), an upper bound close to it
    let full = load_sweep(&scene, None, ["0", "1", "2"], &dir.join("full0"));
    let f = column(&dir.join("msi2.frequencies.csv"), "reduced_hz");
    assert_eq!(f.len(), 2);
    assert!(
        rel(f[1], full[0][2]) < 1e-8,
        "ω2 {} vs {}",
        f[1],
        full[0][2]
    );
    assert!(f[0] >= full[0][1] * (1.0 - 1e-12) && rel(f[0], full[0][1]) < 1e-4);
    // MSI-2 captures ω1 and ω2 under the load (thesis Figs 6.12)
    let range = ["-1", "1", "3"];
    let full = load_sweep(&scene, None, range, &dir.join("full"));
    let red = load_sweep(&scene, Some(&model), range, &dir.join("red"));
    assert_eq!(red[0].len(), 3, "two reduced frequencies per load");
    for i in 0..3 {
        for k in 1..=2 {
            assert!(
                rel(red[i][k], full[i][k]) < 1e-3,
                "MSI-2 ω{k} at λ = {}: {} vs {}",
                full[i][0],
                red[i][k],
                full[i][k]
            );
        }
    }
    check_reduced_simulation(&scene, &model, &dir.join("sim"), 0.005);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn reduce_errors_name_the_culprit() {
    let dir = temp_dir("reduce-errors");
    let scene = fixture(GUIDANCE);
    let model = dir.join("m.ron");
    let m = model.to_str().unwrap();
    let reduce = |extra: &[&'static str]| -> Vec<String> {
        let mut a: Vec<String> = ["reduce", scene.as_str(), "--out", m]
            .iter()
            .map(|s| s.to_string())
            .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    // unknown coordinate
    let e = run_bad_input(&reduce(&[
        "--method", "modal", "--modes", "2", "--keep", "Q.x",
    ]));
    assert!(e.contains("unknown coordinate 'Q.x'"), "{e}");
    // a coordinate that is not a DOF: how to make it one
    let e = run_bad_input(&reduce(&[
        "--method", "ibm-msi", "--modes", "1", "--over", "S.x", "--from", "-0.05", "--to", "0.05",
        "--n", "5",
    ]));
    assert!(
        e.contains("'S.x' is a coordinate of the scene but not one of its degrees of freedom")
            && e.contains("dofs_first: [Coord(\"S\", X)]"),
        "{e}"
    );
    // options that do not apply to the method
    let e = run_bad_input(&reduce(&["--method", "modal", "--modes", "2", "--a", "1"]));
    assert!(e.contains("--a (svd-modal only)"), "{e}");
    let e = run_bad_input(&reduce(&[
        "--method",
        "svd-modal",
        "--modes",
        "2",
        "--over",
        "load",
        "--from",
        "-1",
        "--to",
        "1",
        "--t-load",
        T_LOAD,
        "--final-threshold",
        "0.01",
    ]));
    assert!(e.contains("--final-threshold (fbm-svd only)"), "{e}");
    let e = run_bad_input(&reduce(&[
        "--method", "ibm-mac", "--modes", "1", "--over", "load", "--from", "-1", "--to", "1",
    ]));
    assert!(e.contains("give --over COORD"), "{e}");
    let e = run_bad_input(&reduce(&["--method", "fbm-svd", "--modes", "2"]));
    assert!(e.contains("give --over load|COORD --from X --to Y"), "{e}");
    // a load sweep where the loads vanish
    let e = run_bad_input(&reduce(&[
        "--method",
        "svd-modal",
        "--modes",
        "2",
        "--over",
        "load",
        "--from",
        "-1",
        "--to",
        "1",
    ]));
    assert!(
        e.contains("loads are zero at t = 0") && e.contains("--t-load"),
        "{e}"
    );
    // more modes than DOFs
    let e = run_bad_input(&reduce(&["--method", "modal", "--modes", "18"]));
    assert!(
        e.contains("--modes 18") && e.contains("17 degrees of freedom"),
        "{e}"
    );
    // a sweep that does not converge: a computation failure (exit code 1)
    let o = run(&reduce(&[
        "--method",
        "svd-modal",
        "--modes",
        "2",
        "--over",
        "load",
        "--from",
        "0",
        "--to",
        "1000",
        "--n",
        "3",
        "--t-load",
        T_LOAD,
    ]));
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("the reference sweep did not converge (s is the load scale)"),
        "{e}"
    );
    assert!(!model.exists(), "no model written on failure");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn reduced_models_are_refused_where_they_do_not_apply() {
    let dir = temp_dir("reduced-errors");
    let scene = fixture(GUIDANCE);
    let model = dir.join("modal2.ron");
    let m = model.to_str().unwrap();
    run_ok(&[
        "reduce", &scene, "--method", "modal", "--modes", "2", "--out", m,
    ]);
    // a scene with other DOFs: the first differing one is named
    let nodal = nodal_guidance(&dir);
    let e = run_bad_input(&["simulate", &nodal, "--reduced", m, "--t-end", "0.01"]);
    assert!(
        e.contains("DOF 1 is `flexure1.1.bending_p` in the model and `S.x` in the scene"),
        "{e}"
    );
    let e = run_bad_input(&[
        "sweep",
        &nodal,
        "--reduced",
        m,
        "--over",
        "load",
        "--from",
        "0",
        "--to",
        "1",
    ]);
    assert!(e.contains("built for other degrees of freedom"), "{e}");
    // implicit integration of a reduced model
    let e = run_bad_input(&[
        "simulate",
        &scene,
        "--reduced",
        m,
        "--integrator",
        "genalpha",
    ]);
    assert!(e.contains("genalpha") && e.contains("explicit"), "{e}");
    // a reduced sweep over a coordinate
    let e = run_bad_input(&[
        "sweep",
        &scene,
        "--reduced",
        m,
        "--over",
        "S.x",
        "--from",
        "0",
        "--to",
        "0.1",
    ]);
    assert!(e.contains("--reduced sweeps over `load` only"), "{e}");
    // not a model file
    let e = run_bad_input(&["simulate", &scene, "--reduced", &scene]);
    assert!(e.contains("not a reduced model"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn per_mode_svd_and_mac_sorted_models_report_and_bound_the_frequencies() {
    let dir = temp_dir("fbm-mac");
    let scene = fixture(GUIDANCE);
    let full = load_sweep(&scene, None, ["0", "1", "2"], &dir.join("full"));
    let fbm = dir.join("fbm.ron");
    let s = run_ok(&[
        "reduce",
        &scene,
        "--method",
        "fbm-svd",
        "--modes",
        "3",
        "--over",
        "load",
        "--from",
        "-1",
        "--to",
        "1",
        "--n",
        "30",
        "--t-load",
        T_LOAD,
        "--out",
        fbm.to_str().unwrap(),
    ]);
    // one column per mode and one for the last SVD; the printed counts match
    // the 1 % and 0.5 % rules and the model's size
    let sv = dir.join("fbm.singular_values.csv");
    let (h, _) = flexmb_plot_read(&sv);
    assert_eq!(h, vec!["index", "mode1", "mode2", "mode3", "final"]);
    for (col, th) in [
        ("mode1", 0.01),
        ("mode2", 0.01),
        ("mode3", 0.01),
        ("final", 0.005),
    ] {
        let v: Vec<f64> = column(&sv, col)
            .into_iter()
            .filter(|x| !x.is_nan())
            .collect();
        assert!((v.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{col}");
        let kept = v.iter().filter(|x| **x > th).count();
        assert!(
            s.contains(&format!("{col:<8} kept {kept} of {}", v.len())),
            "{col}: {s}"
        );
        if col == "final" {
            assert!(
                s.contains(&format!("reduced model: {kept} coordinates")),
                "{s}"
            );
        }
    }
    // a fixed basis at the reference is a Rayleigh–Ritz subspace: upper bounds
    let f = column(&dir.join("fbm.frequencies.csv"), "reduced_hz");
    for k in 0..3 {
        assert!(f[k] >= full[0][k + 1] * (1.0 - 1e-12), "ω{}", k + 1);
        assert!(rel(f[k], full[0][k + 1]) < 1e-3, "ω{}: {}", k + 1, f[k]);
    }
    // MAC-sorted eigenvectors are eigenvectors at the knots, as MSI's span
    let nodal = nodal_guidance(&dir);
    let mac = dir.join("mac3.ron");
    run_ok(&[
        "reduce",
        &nodal,
        "--method",
        "ibm-mac",
        "--modes",
        "2",
        "--over",
        "S.x",
        "--from",
        "-0.05",
        "--to",
        "0.05",
        "--n",
        "11",
        "--out",
        mac.to_str().unwrap(),
    ]);
    let f = column(&dir.join("mac3.frequencies.csv"), "reduced_hz");
    assert_eq!(f.len(), 3);
    for k in 1..3 {
        assert!(rel(f[k], full[0][k + 1]) < 1e-8, "ω{}: {}", k + 1, f[k]);
    }
    std::fs::remove_dir_all(&dir).ok();
}

// ---------------------------------------------------------------------------
// Issue 13, items 2 and 4: results written from the configuration the solver
// had, never solved again from a far-away one.

/// Item 2: `simulate` used to solve every output again after the run, from
/// its final configuration; at t = 0 of a 20 s spin-up that landed on the
/// mirrored branch, tip at x = −8 m. At t = 0 the beam rests in its
/// reference configuration, tip at the scene's (8, 0) m. The rows at
/// t ≤ 5 s of a 5 s and a 20 s run (outputs every 0.04 s in both, DOPRI5 at
/// rtol 1e-6, atol 1e-9) must agree: the runs differ only in step sizes
/// chosen with the end time in view (measured 8.4e-11 m).
#[test]
fn simulate_outputs_do_not_depend_on_the_length_of_the_run() {
    let dir = temp_dir("run-length");
    let rows = |t_end: &str, outputs: &str| {
        let out = dir.join(t_end);
        let o = out.display().to_string();
        run_ok(&[
            "simulate",
            &fixture("spin_up_planar.ron"),
            "--t-end",
            t_end,
            "--outputs",
            outputs,
            "--rtol",
            "1e-6",
            "--atol",
            "1e-9",
            "--out",
            &o,
        ]);
        flexmb_plot_read(&out.join("outputs.csv"))
    };
    let (h, long) = rows("20", "501");
    let (_, short) = rows("5", "126");
    assert_eq!(h, ["t", "T.x", "T.y"]);
    for r in [&long, &short] {
        assert!(
            (r[0][1] - 8.0).abs() < 1e-9 && r[0][2].abs() < 1e-9,
            "tip at t = 0 at ({}, {}), not (8, 0)",
            r[0][1],
            r[0][2]
        );
    }
    assert_eq!(short.len(), 126);
    let mut worst = 0.0f64;
    for (a, b) in short.iter().zip(&long) {
        assert!(
            (a[0] - b[0]).abs() < 1e-12,
            "output times {} {}",
            a[0],
            b[0]
        );
        worst = worst.max((a[1] - b[1]).abs()).max((a[2] - b[2]).abs());
    }
    assert!(
        worst < 1e-9,
        "rows at t ≤ 5 s differ by {worst:.3e} m between --t-end 5 and --t-end 20"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Item 4: `static` writes the equilibrium the solver found. It used to
/// solve x = F(q) again from the undeformed shape, which for the 64-beam
/// roll-up (fixtures/scenes/rollup_planar.ron) could fail after "equilibrium
/// found" or land elsewhere. `--steps 64` is 64 equal load increments (it
/// was a first increment of 1/64 that then doubled, 7 increments), which
/// reach the closed form: a cantilever under the end moment M = 2πEI/L
/// curls into a full circle, the tip B returns to the root A = (0, 0). The
/// written positions are the library's equilibrium to the CSV's 13 digits
/// (measured tip: (1.61e-3, 8.2e-6) m, the 64-beam discretization error).
#[test]
fn static_writes_the_equilibrium_it_found() {
    let dir = temp_dir("rollup");
    let scene = fixture("rollup_planar.ron");
    let o = dir.display().to_string();
    let stdout = run_ok(&["static", &scene, "--steps", "64", "--out", &o]);
    assert!(
        stdout.contains("64 load increments"),
        "64 equal increments: {stdout}"
    );
    let (h, rows) = flexmb_plot_read(&dir.join("node_positions.csv"));
    assert_eq!(h, ["x", "y"]);
    // the same equilibrium through the library: its configuration
    let mech = std::sync::Arc::new(
        flexmb_model::Scene::load(Path::new(&scene))
            .unwrap()
            .build(None)
            .unwrap(),
    );
    let mut dy = flexmb_dynamics::Dynamics::new(mech.clone());
    let opts = flexmb_dynamics::StaticOptions {
        load_steps: 64,
        ..Default::default()
    };
    dy.static_equilibrium(0.0, &mech.q0(), &opts).unwrap();
    let x = dy.kinematics().x();
    assert_eq!(rows.len(), mech.nodes.len());
    for (n, r) in mech.nodes.iter().zip(&rows) {
        for (i, v) in n.position.iter().zip(r) {
            assert!(
                (x[*i] - v).abs() <= 1e-11 * (1.0 + v.abs()),
                "{}: written {v}, equilibrium {}",
                n.id,
                x[*i]
            );
        }
    }
    let b = mech.nodes.iter().position(|n| n.id == "B").unwrap();
    let (bx, by) = (rows[b][0], rows[b][1]);
    assert!(
        bx.hypot(by) < 2e-3,
        "tip B at ({bx:.3e}, {by:.3e}), the closed form puts it at the root (0, 0)"
    );
    let eps = std::fs::read_to_string(dir.join("deformations.csv")).unwrap();
    assert_eq!(
        eps.lines().filter(|l| !l.starts_with('#')).count(),
        1 + mech.n_eps(),
        "header + one row per deformation"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A free body through more than one turn (chart switches of its Euler
/// parameters) through the command line: the outputs are written in every
/// chart, the body's centre stays at rest and the energy stays constant (the
/// beam with a plate at its middle of issue 13, item 1, for 1.2 s ≈ 1.15
/// turns).
#[test]
fn simulate_a_free_body_through_more_than_a_turn() {
    let dir = temp_dir("free-body");
    let scene = dir.join("plate.ron");
    std::fs::write(
        &scene,
        r#"(
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
        outputs: [Position("beam.n1"), Position("B"), Energies],
    )"#,
    )
    .unwrap();
    let out = dir.join("out");
    let args = [
        "simulate",
        scene.to_str().unwrap(),
        "--t-end",
        "1.2",
        "--outputs",
        "25",
        "--rtol",
        "1e-10",
        "--atol",
        "1e-12",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = run(&args);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}: {stdout}{}",
        line(&args),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("chart switches"), "{stdout}");
    let (h, rows) = flexmb_plot_read(&out.join("outputs.csv"));
    let col = |name: &str| {
        h.iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("{name} in {h:?}"))
    };
    let (cx, cz, bx, kin) = (
        col("beam.n1.x"),
        col("beam.n1.z"),
        col("B.x"),
        col("kinetic"),
    );
    let t0 = rows[0][kin];
    assert!((t0 - 0.0496913).abs() < 1e-6, "T0 = {t0}");
    let mut min_bx = f64::MAX;
    for r in &rows {
        assert!(
            r[cx].abs() < 1e-9 && r[cz].abs() < 1e-9,
            "the centre moved: {r:?}"
        );
        assert!(
            (r[kin] + r[col("elastic")] - t0).abs() < 1e-9 * t0,
            "energy drifts: {r:?}"
        );
        min_bx = min_bx.min(r[bx]);
    }
    // B went around: through x = −0.3 m (half a turn)
    assert!(min_bx < -0.29, "B.x never below {min_bx}");
    std::fs::remove_dir_all(&dir).ok();
}
