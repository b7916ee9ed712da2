//! `cargo xtask regress`: recomputes the eigenfrequency curves of the
//! chapters' models and compares them with those stored in `fixtures/curves/`.

use crate::curves::{compare, StoredCurve};
use crate::progress::Progress;
use crate::{ch5, ch6};
use std::path::Path;

/// Relative tolerance on every stored eigenfrequency and x-displacement.
/// The curves are deterministic up to rounding (Newton converged to 1e-10
/// relative, eigenvalues refined by Rayleigh quotients), so changes of the
/// formulation, the elements or the reduction show up far above it.
pub const RTOL: f64 = 1e-6;

/// A chapter's recomputed curves and how they were produced.
pub struct Recomputed {
    /// Fixture directory.
    pub dir: std::path::PathBuf,
    /// The curves.
    pub curves: Vec<StoredCurve>,
    /// Provenance lines for the CSV headers.
    pub provenance: Vec<String>,
}

/// Recomputes chapter 6's curves (reference sweeps, models, curves).
pub fn recompute_ch6(root: &Path, pg: &Progress) -> Result<Recomputed, String> {
    let o = ch6::Ch6Options::default();
    let s = ch6::setup(root, &o)?;
    let r = ch6::references(&s, &o, pg)?;
    let m = ch6::models(&s, &r)?;
    let c = ch6::curves(&s, &m, o.n_curve, pg)?;
    Ok(Recomputed {
        dir: ch6::fixture_dir(root),
        curves: ch6::stored_curves(&c),
        provenance: ch6::provenance(&o, &s),
    })
}

/// Recomputes chapter 2's curves (the spin-up beam bent by a tip force, beams
/// and superelements).
pub fn recompute_ch2(root: &Path, _pg: &Progress) -> Result<Recomputed, String> {
    crate::ch2::curves::recompute(root)
}

/// Recomputes chapter 5's curves.
pub fn recompute_ch5(root: &Path, pg: &Progress) -> Result<Recomputed, String> {
    ch5::recompute_curves(root, pg)
}

/// Compares recomputed curves with the stored ones: one line per difference
/// or missing file.
pub fn check(r: &Recomputed) -> Vec<String> {
    let mut out = vec![];
    for c in &r.curves {
        match StoredCurve::read(&r.dir, &c.model) {
            Ok(stored) => out.extend(compare(&stored, c, RTOL)),
            Err(e) => out.push(e),
        }
    }
    out
}

/// The curves stored in `dir` are `curves` within [`RTOL`]: `Ok`, or every
/// difference, one per line, for a claims test to fail with.
pub fn reproduced(dir: std::path::PathBuf, curves: Vec<StoredCurve>) -> Result<(), String> {
    let d = check(&Recomputed {
        dir,
        curves,
        provenance: vec![],
    });
    if d.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} differences (tolerance {RTOL:e}):\n{}",
            d.len(),
            d.join("\n")
        ))
    }
}

/// Stores recomputed curves as the new fixtures.
pub fn update(r: &Recomputed) -> Result<(), String> {
    for c in &r.curves {
        c.write(&r.dir, &r.provenance)
            .map_err(|e| format!("{}: {e}", r.dir.display()))?;
    }
    Ok(())
}
