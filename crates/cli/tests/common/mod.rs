//! Helpers shared by the command-line tests (each test file includes this
//! module with `mod common;` and uses what it needs).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The `flexmb` binary of this package.
pub fn flexmb() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexmb"))
}

/// A scene of `fixtures/scenes`.
pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name)
}

/// A fresh-named directory `flexmb-{tag}-{name}-{pid}` in the system's
/// temporary directory, created.
pub fn temp_dir(tag: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-{tag}-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the Python `script` with a Python that has meshio (`python3`, or
/// the system's `/usr/bin/python3` where `python3` is another
/// installation; `.ci/run` installs python3-meshio) and asserts that it
/// printed `ok`.
pub fn meshio_check(script: &str) {
    let python = ["python3", "/usr/bin/python3"]
        .into_iter()
        .find(|p| {
            Command::new(p)
                .args(["-c", "import meshio"])
                .output()
                .is_ok_and(|o| o.status.success())
        })
        .expect("no Python with meshio (Debian: apt-get install python3-meshio)");
    let o = Command::new(python).args(["-c", script]).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && stdout.contains("ok"),
        "meshio check failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
