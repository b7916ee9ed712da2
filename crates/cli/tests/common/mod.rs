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
