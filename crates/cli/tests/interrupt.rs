//! Ctrl-C during `flexmb simulate`: the run stops at the next output, writes
//! the partial results and exits with 130.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn sigint_stops_a_simulation_with_partial_results_and_exit_130() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = std::env::temp_dir().join(format!("flexmb-interrupt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    // 44 DOF over 20 s with the explicit integrator: minutes of work
    let mut child = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args(["simulate"])
        .arg(root.join("fixtures/scenes/straight_guidance_spatial.ron"))
        .args(["--t-end", "20", "--outputs", "2001", "--out"])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("the kill command");
    assert!(status.success());
    let start = Instant::now();
    let output = loop {
        if let Some(_s) = child.try_wait().unwrap() {
            break child.wait_with_output().unwrap();
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the simulation did not stop within 60 s of SIGINT"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "stderr: {stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let csv = std::fs::read_to_string(out.join("outputs.csv")).expect("partial outputs written");
    let rows = csv.lines().filter(|l| !l.starts_with('#')).count() - 1;
    assert!(
        (1..2001).contains(&rows),
        "{rows} output rows: partial, not empty and not all"
    );
    let _ = std::fs::remove_dir_all(&out);
}
