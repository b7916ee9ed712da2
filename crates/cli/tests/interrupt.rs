//! Signals and closed pipes (issue 14, item 3): SIGINT and SIGTERM stop a
//! long `simulate` or `sweep` between steps, the partial results are written
//! and the exit code is 130 or 143; a second signal exits at once; a closed
//! standard output is no panic.

mod common;
use common::fixture;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// The wall time from sending a signal to the exit that we accept: the
/// check itself is per integrator step (about 1 ms here, reported by the
/// process, see [`reported_stop_ms`]); the rest is writing the partial
/// results and process teardown on a loaded machine.
const EXIT_WITHIN: Duration = Duration::from_secs(1);

/// What the issue asks: the computation stops within 0.2 s of the signal.
const STOP_WITHIN_MS: f64 = 200.0;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-interrupt-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Starts `flexmb args...` with stdout and stderr piped.
fn start(args: &[&str], out: &Path) -> Child {
    start_with(args, out, &[])
}

/// Starts `flexmb` like [`start`], with these environment variables.
fn start_with(args: &[&str], out: &Path, env: &[(&str, &str)]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .envs(env.iter().copied())
        .args(args)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until the child has printed the scene's summary (the first line:
/// the mechanism is built, the computation starts), then `settle` longer.
fn wait_until_computing(
    child: &mut Child,
    settle: Duration,
) -> BufReader<std::process::ChildStdout> {
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    assert!(line.contains("degrees of freedom"), "first line: {line}");
    std::thread::sleep(settle);
    stdout
}

/// Sends `signal` (a name for kill(1): INT, TERM, STOP, CONT) to the child.
fn send(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("the kill command");
    assert!(status.success(), "kill -{signal}");
}

/// Waits for the child to exit, at most `limit`; returns its status, the
/// time it took and its stderr.
fn wait_for_exit(child: &mut Child, limit: Duration) -> (ExitStatus, Duration, String) {
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("the process did not exit within 60 s of the signal");
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let took = start.elapsed();
    let mut err = String::new();
    use std::io::Read;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(
        took < limit,
        "exited {:.3} s after the signal (limit {:.3} s); stderr: {err}",
        took.as_secs_f64(),
        limit.as_secs_f64()
    );
    (status, took, err)
}

/// Waits until every thread of the child is stopped (state `T` in
/// /proc/PID/task/*/stat), so that the signals sent next are all pending
/// when it continues.
fn wait_until_stopped(child: &Child) {
    let tasks = PathBuf::from(format!("/proc/{}/task", child.id()));
    let start = Instant::now();
    loop {
        let stopped = std::fs::read_dir(&tasks).unwrap().all(|t| {
            let stat = std::fs::read_to_string(t.unwrap().path().join("stat")).unwrap_or_default();
            // the state follows the command name in parentheses
            stat.rsplit_once(") ")
                .is_some_and(|(_, rest)| rest.starts_with('T'))
        });
        if stopped {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "SIGSTOP took no effect"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// "the computation stopped X ms after the signal" of stderr.
fn reported_stop_ms(stderr: &str) -> f64 {
    let (_, rest) = stderr
        .split_once("the computation stopped ")
        .unwrap_or_else(|| panic!("no stop latency in: {stderr}"));
    rest.split_once(" ms after the signal")
        .and_then(|(v, _)| v.parse().ok())
        .unwrap_or_else(|| panic!("no stop latency in: {stderr}"))
}

/// The data rows of a CSV written by flexmb.
fn rows(csv: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// 44 DOF of the spatial guidance over 20 s with the explicit integrator:
/// minutes of work, 2001 output times 0.01 s apart.
fn long_simulation(out: &Path, integrator: &str) -> Child {
    let scene = fixture("straight_guidance_spatial.ron");
    let scene = scene.to_str().unwrap();
    let args = [
        "simulate",
        scene,
        "--t-end",
        "20",
        "--outputs",
        "2001",
        "--integrator",
        integrator,
    ];
    start(&args, out)
}

/// A signal stops the run at the next integrator step; the rows are the
/// output times reached and the state where it stopped.
fn signal_stops_a_simulation(signal: &str, code: i32, integrator: &str) {
    let out = temp_dir(&format!("{signal}-{integrator}"));
    let mut child = long_simulation(&out, integrator);
    let _stdout = wait_until_computing(&mut child, Duration::from_millis(300));
    send(&child, signal);
    let (status, took, err) = wait_for_exit(&mut child, EXIT_WITHIN);
    assert_eq!(status.code(), Some(code), "{err}");
    let stop_ms = reported_stop_ms(&err);
    assert!(
        stop_ms < STOP_WITHIN_MS,
        "stopped {stop_ms} ms after {signal}: {err}"
    );
    assert!(
        err.contains(&format!("interrupted by SIG{signal}"))
            && err.contains("partial results written"),
        "{err}"
    );
    let r = rows(&out.join("outputs.csv"));
    assert!((1..2001).contains(&r.len()), "{} rows: partial", r.len());
    // the explicit integrators stop after an accepted step, and the last
    // row is the state there: after the last output time reached and
    // before the next one (0.01 s apart); generalized-α may also stop
    // before a step attempt (one step can take many), with the output
    // times reached only
    if err.contains("then the state where the run stopped") {
        assert!(r.len() >= 2);
        let (t_last, t_prev) = (r[r.len() - 1][0], r[r.len() - 2][0]);
        assert!(
            t_last > t_prev && t_last < t_prev + 0.01 + 1e-12,
            "last rows at t = {t_prev}, {t_last}"
        );
    } else {
        assert_eq!(integrator, "genalpha", "{err}");
        for (k, row) in r.iter().enumerate() {
            assert!(
                (row[0] - 0.01 * k as f64).abs() < 1e-12,
                "row {k}: t = {}",
                row[0]
            );
        }
    }
    let csv = std::fs::read_to_string(out.join("outputs.csv")).unwrap();
    assert!(csv.contains("# interrupted: "), "{csv}");
    eprintln!(
        "SIG{signal} ({integrator}): stopped {stop_ms} ms after the signal, exited after {:.1} ms",
        1e3 * took.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn sigint_stops_a_simulation_between_steps_with_partial_results_and_exit_130() {
    let _one_at_a_time = one_at_a_time();
    signal_stops_a_simulation("INT", 130, "dopri5");
}

#[test]
fn sigterm_stops_a_simulation_between_steps_with_partial_results_and_exit_143() {
    let _one_at_a_time = one_at_a_time();
    signal_stops_a_simulation("TERM", 143, "adams");
}

#[test]
fn sigint_stops_the_implicit_integrator_between_steps_too() {
    let _one_at_a_time = one_at_a_time();
    signal_stops_a_simulation("INT", 130, "genalpha");
}

/// Both signals arrive while the process is stopped (SIGSTOP), so both
/// handlers run before it executes anything else: the second one exits at
/// once, before any partial result is written. (One signal alone writes
/// them: the tests above.)
#[test]
fn a_second_signal_exits_at_once() {
    let _one_at_a_time = one_at_a_time();
    let out = temp_dir("twice");
    let mut child = long_simulation(&out, "dopri5");
    let _stdout = wait_until_computing(&mut child, Duration::from_millis(300));
    send(&child, "STOP");
    wait_until_stopped(&child);
    send(&child, "INT");
    send(&child, "TERM");
    send(&child, "CONT");
    let (status, _, err) = wait_for_exit(&mut child, EXIT_WITHIN);
    let code = status.code();
    assert!(code == Some(130) || code == Some(143), "{code:?}: {err}");
    assert!(!err.contains("partial results written"), "{err}");
    assert!(!out.join("outputs.csv").exists(), "nothing is written");
    let _ = std::fs::remove_dir_all(&out);
}

/// A long held-coordinate sweep (3000 equilibria of the spatial guidance):
/// SIGINT stops it before the next configuration or Newton iteration, with
/// exit code 130, saying what was written; with `--vtk`, the VTK series
/// has the configurations of the CSV.
#[test]
fn an_interrupted_sweep_stops_at_once_and_says_what_was_written() {
    let _one_at_a_time = one_at_a_time();
    let out = temp_dir("sweep");
    let vtk = temp_dir("sweep-vtk");
    let scene = fixture("straight_guidance_spatial.ron");
    let args = [
        "sweep",
        scene.to_str().unwrap(),
        "--over",
        "S.x",
        "--from",
        "0",
        "--to",
        "0.08",
        "--n",
        "3000",
        "--modes",
        "2",
        "--vtk",
        vtk.to_str().unwrap(),
    ];
    let mut child = start(&args, &out);
    let _stdout = wait_until_computing(&mut child, Duration::from_millis(300));
    send(&child, "INT");
    let (status, _, err) = wait_for_exit(&mut child, EXIT_WITHIN);
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(reported_stop_ms(&err) < STOP_WITHIN_MS, "{err}");
    let csv = out.join("eigenfrequencies.csv");
    if err.contains("nothing written: stopped") {
        assert!(!csv.exists());
    } else {
        assert!(err.contains("partial results written"), "{err}");
        let done = rows(&csv).len();
        assert!((1..3000).contains(&done));
        let pvd = std::fs::read_to_string(vtk.join("sweep.pvd")).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), done, "{pvd}");
    }
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&vtk);
}

/// `flexmb reduce` has nothing partial to write (a model from part of its
/// reference sweep would cover less than asked): SIGTERM during its sweep
/// of 3000 configurations (seconds of work) exits at once with 143 and
/// writes no model.
#[test]
fn an_interrupted_reduction_exits_at_once_without_a_model() {
    let _one_at_a_time = one_at_a_time();
    let dir = temp_dir("reduce");
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("model.ron");
    let scene = fixture("straight_guidance_spatial.ron");
    let args = [
        "reduce",
        scene.to_str().unwrap(),
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
        "--t-load",
        "0.05",
        "--n",
        "3000",
    ];
    let mut child = start(&args, &model);
    let _stdout = wait_until_computing(&mut child, Duration::from_millis(300));
    send(&child, "TERM");
    let (status, _, err) = wait_for_exit(&mut child, EXIT_WITHIN);
    assert_eq!(status.code(), Some(143), "{err}");
    assert!(
        err.contains("interrupted by SIGTERM: nothing partial to write"),
        "{err}"
    );
    assert!(!model.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `flexmb info SCENE | head -1` with the reader gone before anything is
/// printed: every write to stdout fails with BrokenPipe. No panic (it used
/// to be exit code 101, "failed printing to stdout"), exit code 0.
#[test]
fn a_closed_stdout_is_no_panic_and_no_error() {
    let _one_at_a_time = one_at_a_time();
    let scene = fixture("straight_guidance_spatial.ron");
    let mut child = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .arg("info")
        .arg(&scene)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(o.status.code(), Some(0), "{err}");
}

/// A simulation whose stdout is closed still writes its files; an error
/// with both stdout and stderr closed still gives its exit code.
#[test]
fn a_closed_stdout_does_not_stop_the_files_or_change_the_exit_code() {
    let _one_at_a_time = one_at_a_time();
    let out = temp_dir("pipe");
    let scene = fixture("straight_guidance_planar.ron");
    let mut child = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .arg("simulate")
        .arg(&scene)
        .args(["--t-end", "0.002", "--outputs", "3", "--out"])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert_eq!(rows(&out.join("outputs.csv")).len(), 3);
    let mut child = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(["info", "/no/such/scene.ron"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    drop(child.stderr.take());
    assert_eq!(child.wait().unwrap().code(), Some(2));
    let _ = std::fs::remove_dir_all(&out);
}

/// `flexmb sweep --reduced` (a 3-coordinate modal model of the planar
/// guidance, 300 000 load scales): the reduced equilibria have nothing
/// partial (exit at once), the eigen analyses after them do. SIGTERM some
/// seconds in (in the eigen analyses on this machine) exits with 143 within
/// [`EXIT_WITHIN`]; if it came in the eigen analyses, the rows written are
/// the configurations reported, and the file says it is partial.
#[test]
fn an_interrupted_reduced_sweep_exits_143_with_the_partial_frequencies() {
    let _one_at_a_time = one_at_a_time();
    let dir = temp_dir("reduced-sweep");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = fixture("straight_guidance_planar.ron");
    let scene = scene.to_str().unwrap();
    let model = dir.join("modal3.ron");
    let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args([
            "reduce", scene, "--method", "modal", "--modes", "3", "--out",
        ])
        .arg(&model)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let model = model.to_str().unwrap();
    // many points, so that the sweep is still running when the signal comes
    // on an idle machine too (30 000 could finish within the 6 s)
    const N: usize = 300_000;
    let n = N.to_string();
    let args = [
        "sweep",
        scene,
        "--reduced",
        model,
        "--over",
        "load",
        "--from",
        "0",
        "--to",
        "1",
        "--n",
        n.as_str(),
        "--modes",
        "2",
    ];
    let out = dir.join("sweep");
    let mut child = start(&args, &out);
    let _stdout = wait_until_computing(&mut child, Duration::from_secs(6));
    send(&child, "TERM");
    let (status, _, err) = wait_for_exit(&mut child, EXIT_WITHIN);
    assert_eq!(status.code(), Some(143), "{err}");
    let csv = out.join("eigenfrequencies.csv");
    if err.contains("nothing partial to write") {
        assert!(!csv.exists(), "{err}");
    } else {
        assert!(reported_stop_ms(&err) < STOP_WITHIN_MS, "{err}");
        let (_, done) = err
            .split_once("partial results written: ")
            .unwrap_or_else(|| panic!("{err}"));
        let done: usize = done.split(' ').next().unwrap().parse().unwrap();
        assert!((1..N).contains(&done), "{err}");
        assert_eq!(rows(&csv).len(), done, "{err}");
        let text = std::fs::read_to_string(&csv).unwrap();
        assert!(
            text.contains(&format!("# interrupted: {done} of {N}")),
            "{text}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The tests of this file run one at a time: each measures a stop latency,
/// and one measured while another test keeps the cores busy measures the
/// contention (two 1440-DOF tests in parallel on this 2-core machine, under
/// a concurrent build, missed the 1 s backstop; the sweep of that chain,
/// next to the other tests here on the CI machine, stopped 464 ms after the
/// signal).
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Holds [`ONE_AT_A_TIME`] until the test ends.
fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The flexure chain with its beams split in 20 (1440 degrees of freedom),
/// written to `dir`.
fn chain_1440(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(fixture("flexure_chain_720.ron")).unwrap();
    assert_eq!(text.matches("n: 10)").count(), 12, "the fixture changed");
    let scene = dir.join("chain_1440.ron");
    std::fs::write(&scene, text.replace("n: 10)", "n: 20)")).unwrap();
    scene
}

/// The arguments of a `sweep` of `scene` over load scales 0 to 0.001 in `n`
/// configurations with `modes` modes each.
fn chain_load_sweep(scene: &Path, n: &str, modes: &str) -> Vec<String> {
    let s = scene.to_str().unwrap();
    [
        "sweep", s, "--over", "load", "--from", "0", "--to", "0.001", "--n", n, "--modes", modes,
    ]
    .map(String::from)
    .to_vec()
}

/// The stop latency we accept for the 1440-DOF chain, from the signal to the
/// end of the computation as the process reports it. Its longest stretch
/// without a check is one part of a linearization (since the mass assembly
/// and the eigen analyses read the request inside, 69 ms at load 3.4),
/// about 0.1 s on an idle machine before; it stopped 61–194 ms after the signal on
/// this 2-core machine loaded by two other sessions (load average 5). Before
/// the checks inside the linearization and the eigensolver, each of the two
/// workers had about 1.4 s of work per configuration without a check: it
/// stopped 633 ms after the signal once, and three times not within the
/// 1 s backstop (nothing written). 350 ms leaves the loaded machine nearly
/// 2× its worst, and the old code passed it only if both workers were in
/// the last quarter of a configuration.
const CHAIN_STOP_WITHIN_MS: f64 = 350.0;

/// SIGINT in the eigen analyses of a sweep of the 1440-DOF chain (100 load
/// scales: the equilibria take about 4 s, the linearizations and eigen
/// analyses about 0.35 s per configuration on each of two workers; the
/// signal comes 10 s after the summary) stops
/// inside the analysis of a configuration, and the configurations done are
/// written.
#[test]
fn an_interrupted_sweep_of_a_large_model_stops_inside_the_eigen_analysis() {
    let _one_at_a_time = one_at_a_time();
    let dir = temp_dir("large-sweep");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = chain_1440(&dir);
    let args = chain_load_sweep(&scene, "100", "2");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = dir.join("sweep");
    // on a loaded machine the equilibria can take longer than 10 s: then
    // again with a later signal (the stop there is checked too)
    let mut found = None;
    for delay in [10, 20, 30] {
        let _ = std::fs::remove_dir_all(&out);
        let mut child = start(&args, &out);
        let _stdout = wait_until_computing(&mut child, Duration::from_secs(delay));
        send(&child, "INT");
        let (status, took, err) = wait_for_exit(&mut child, Duration::from_secs(3));
        assert_eq!(status.code(), Some(130), "{err}");
        let stop_ms = reported_stop_ms(&err);
        assert!(stop_ms < CHAIN_STOP_WITHIN_MS, "{err}");
        if err.contains("nothing written: stopped") {
            continue;
        }
        found = Some((took, err, stop_ms));
        break;
    }
    let (took, err, stop_ms) = found.expect("the eigen analyses were not reached in 30 s");
    let (_, done) = err
        .split_once("partial results written: ")
        .unwrap_or_else(|| panic!("not stopped in the eigen analyses: {err}"));
    let done: usize = done.split(' ').next().unwrap().parse().unwrap();
    assert!((1..100).contains(&done), "{err}");
    let csv = out.join("eigenfrequencies.csv");
    let r = rows(&csv);
    assert_eq!(r.len(), done, "{err}");
    // the rows are whole configurations: the load scale and the two
    // frequencies, which the tiny loads hardly change (1.16415 Hz and
    // 7.29551 Hz at load scale 0, by the full dense eigensolver before the
    // partial one was used)
    for row in &r {
        assert!(row[0] >= 0.0 && row[0] <= 0.001, "{row:?}");
        assert!((row[1] / 1.16415 - 1.0).abs() < 1e-4, "{row:?}");
        assert!((row[2] / 7.29551 - 1.0).abs() < 1e-4, "{row:?}");
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.contains(&format!("# interrupted: {done} of 100")),
        "{text}"
    );
    eprintln!(
        "1440-DOF sweep: stopped {stop_ms} ms after SIGINT, exited after {:.1} ms, {done} of 100 configurations",
        1e3 * took.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGINT in a sweep of the 1440-DOF chain that asks for 1000 modes per
/// configuration, more than the partial eigensolver takes: each
/// configuration is a dense factorization and eigendecomposition of the
/// whole model (0.3–2 s, no check inside), which a stop request now leaves
/// at once (it runs on a thread of its own, `flexmb_linalg`'s
/// `generalized_eigen_until`). The run stops within the bound of the other
/// 1440-DOF tests wherever the signal comes (2, 4 and 7 s after the
/// summary: in the equilibria or in the decompositions; before, it stopped
/// only after the decomposition, 87–328 ms on the CI machine and up to 2 s
/// on this one), and writes the configurations done.
#[test]
fn an_interrupted_sweep_with_many_modes_stops_inside_the_dense_decomposition() {
    let _one_at_a_time = one_at_a_time();
    let dir = temp_dir("dense-sweep");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = chain_1440(&dir);
    let args = chain_load_sweep(&scene, "40", "1000");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = dir.join("sweep");
    let mut latencies = vec![];
    let mut in_decompositions = 0;
    for delay in [2, 4, 7] {
        let _ = std::fs::remove_dir_all(&out);
        let mut child = start(&args, &out);
        let _stdout = wait_until_computing(&mut child, Duration::from_secs(delay));
        send(&child, "INT");
        let (status, _, err) = wait_for_exit(&mut child, Duration::from_secs(3));
        if status.code() == Some(0) {
            // a fast machine finished the sweep before the signal
            break;
        }
        assert_eq!(status.code(), Some(130), "{err}");
        let stop_ms = reported_stop_ms(&err);
        assert!(stop_ms < CHAIN_STOP_WITHIN_MS, "{err}");
        latencies.push(stop_ms);
        if let Some((_, done)) = err.split_once("partial results written: ") {
            let done: usize = done.split(' ').next().unwrap().parse().unwrap();
            assert_eq!(rows(&out.join("eigenfrequencies.csv")).len(), done, "{err}");
            in_decompositions += 1;
        }
    }
    assert!(
        in_decompositions > 0,
        "no signal came in the eigen analyses: stops after {latencies:?} ms"
    );
    eprintln!("1440-DOF sweep of 1000 modes: stopped {latencies:?} ms after SIGINT");
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGINT in a generalized-α run of the 1440-DOF chain stops inside the
/// step: its tangent (dense F,qᵀ Mx F,q and the geometric stiffness, about
/// 1 s) reads the stop request between its parts, and its residual no longer
/// forms Mq (before, 1 s each with no check: the run was forced out by the
/// backstop below, nothing written). The signal comes 20 s after the summary,
/// in the time steps (the set-up and the consistent start take about 10 s
/// on a loaded machine), or 40 s if the set-up was still running.
#[test]
fn an_interrupted_implicit_run_of_a_large_model_stops_inside_the_step() {
    let _one_at_a_time = one_at_a_time();
    let dir = temp_dir("large-genalpha");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = chain_1440(&dir);
    let args = [
        "simulate",
        scene.to_str().unwrap(),
        "--t-end",
        "1",
        "--integrator",
        "genalpha",
    ];
    let out = dir.join("simulation");
    // on a loaded machine the set-up can take longer than 20 s: then again
    // with a later signal
    let mut found = None;
    for delay in [20, 40] {
        let _ = std::fs::remove_dir_all(&out);
        let mut child = start(&args, &out);
        let _stdout = wait_until_computing(&mut child, Duration::from_secs(delay));
        send(&child, "INT");
        let (status, took, err) = wait_for_exit(&mut child, Duration::from_secs(3));
        assert_eq!(status.code(), Some(130), "{err}");
        if err.contains("nothing partial to write") {
            continue;
        }
        found = Some((took, err));
        break;
    }
    let (took, err) = found.expect("the time steps were not reached in 40 s");
    let stop_ms = reported_stop_ms(&err);
    assert!(stop_ms < CHAIN_STOP_WITHIN_MS, "{err}");
    assert!(err.contains("partial results written"), "{err}");
    let r = rows(&out.join("outputs.csv"));
    assert!(!r.is_empty(), "{err}");
    assert_eq!(r[0][0], 0.0, "{err}");
    eprintln!(
        "1440-DOF generalized-alpha: stopped {stop_ms} ms after SIGINT, exited after {:.1} ms, {} rows",
        1e3 * took.as_secs_f64(),
        r.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The backstop: a stoppable phase that reaches no check within the grace
/// time of the signal is forced out with the signal's code, writing
/// nothing. The grace time is set to 1 ms (`FLEXMB_STOP_GRACE`; the watcher
/// looks every 5 ms), so that any stretch of computation between two stop
/// checks that is longer triggers it: a sweep of the 1440-DOF flexure chain
/// has many (a Newton iteration's tangent, the parts of a linearization,
/// tens of milliseconds each). SIGINT comes 2 s after the summary; if it
/// still lands just before a check (a clean stop), again with a later
/// signal, at most three times. (With the default 1 s, no stretch of the
/// sweep is that long any more: since the dense decompositions of a large
/// model are left at once on a stop request, the test below, the longest
/// are the parts of a linearization. Before, the backstop was shown with
/// 1000 modes per configuration, whose decompositions on the CI machine
/// took 0.3–1 s, too short for the 1 s default: stop 29's CI failed on
/// it.)
#[test]
fn a_run_that_does_not_stop_within_the_grace_time_is_forced_out() {
    let _one_at_a_time = one_at_a_time();
    let dir = temp_dir("backstop");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = chain_1440(&dir);
    let args = chain_load_sweep(&scene, "100", "2");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = dir.join("sweep");
    let mut tries = vec![];
    for delay in [2, 4, 7] {
        let _ = std::fs::remove_dir_all(&out);
        let mut child = start_with(&args, &out, &[("FLEXMB_STOP_GRACE", "0.001")]);
        let _stdout = wait_until_computing(&mut child, Duration::from_secs(delay));
        send(&child, "INT");
        let (status, took, err) = wait_for_exit(&mut child, Duration::from_secs(3));
        if status.code() == Some(0) {
            // a fast machine finished the sweep before the signal
            tries.push(format!("{delay} s: finished before the signal"));
            break;
        }
        assert_eq!(status.code(), Some(130), "{err}");
        if err.contains("reached no point to stop at within 0.001 s; nothing written") {
            assert!(took >= Duration::from_millis(1), "{took:?}: {err}");
            assert!(!out.join("eigenfrequencies.csv").exists(), "{err}");
            let _ = std::fs::remove_dir_all(&dir);
            return;
        }
        assert!(
            err.contains("nothing partial to write")
                || err.contains("partial results written")
                || err.contains("nothing written: stopped"),
            "{err}"
        );
        tries.push(format!("{delay} s: {}", err.trim()));
    }
    panic!("no signal came inside a computation without checks: {tries:#?}");
}

/// A grace time that is not a positive number of seconds is an input
/// error that names the variable and the value, before anything runs.
#[test]
fn a_bad_grace_time_is_an_error_that_names_the_variable() {
    for bad in ["abc", "0", "-1", "NaN", "1e9"] {
        let out = Command::new(env!("CARGO_BIN_EXE_flexmb"))
            .env("FLEXMB_STOP_GRACE", bad)
            .args(["info", "no-such-scene.ron"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(
            err.contains(&format!("FLEXMB_STOP_GRACE=\"{bad}\"")),
            "{bad}: {err}"
        );
        assert!(!err.contains("no-such-scene"), "{bad}: {err}");
    }
}
