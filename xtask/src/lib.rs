//! `cargo xtask`: regenerates the thesis benchmarks (chapters 2, 3, 5 and 6) with
//! the thesis's numbers side by side, speed against error, and the CI
//! regression of stored eigenfrequency curves, and fuzzes the scene parser,
//! validator and equations of motion (`cargo xtask fuzz`). See README.md,
//! docs/reproduce.md and docs/cli.md.
#![warn(missing_docs)]

pub mod ch2;
pub mod ch3;
pub mod ch4;
pub mod ch5;
pub mod ch6;
pub mod ch7;
pub mod ch7xy;
pub mod curves;
pub mod fuzz;
pub mod models;
pub mod pictures;
pub mod pictures3;
pub mod progress;
pub mod regress;
pub mod report;
pub mod reproduce3;
pub mod reproduce4;
pub mod reproduce6;
pub mod reproduce7;
pub mod reproduce7xy;
pub mod solid6;

/// The workspace root (the parent of this crate).
pub fn workspace_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(|p| p.to_path_buf())
        .unwrap_or_default()
}
