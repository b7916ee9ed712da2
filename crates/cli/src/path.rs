//! A sweep along a path P(s) of several coordinates (thesis (4.1)), read from
//! a CSV file: a column `s`, then one column per coordinate or deformation
//! (named as `flexmb info` prints them) holding its change from the reference
//! configuration. Between the rows the path is interpolated linearly.

use crate::{coords, Failure};
use flexmb_model::{Mechanism, Scene};
use std::path::Path;

/// A tabulated path.
pub(crate) struct TabulatedPath {
    /// The coordinate names (the columns after `s`).
    pub names: Vec<String>,
    s: Vec<f64>,
    values: Vec<Vec<f64>>,
}

impl TabulatedPath {
    /// Reads and checks a path file.
    pub(crate) fn read(file: &Path) -> Result<Self, Failure> {
        let bad = |m: String| Failure::Input(format!("path file {}: {m}", file.display()));
        let (header, rows) = flexmb_plot::read_csv(file).map_err(|e| bad(e.to_string()))?;
        if header.len() < 2 || header[0] != "s" {
            return Err(bad(format!(
                "the header must be `s,NAME,...` with at least one coordinate, found {header:?}"
            )));
        }
        if rows.len() < 2 || rows.iter().any(|r| r.len() != header.len()) {
            return Err(bad(format!(
                "need at least two rows of {} values",
                header.len()
            )));
        }
        if rows.iter().flatten().any(|v| !v.is_finite()) {
            return Err(bad("NaN or infinite values".into()));
        }
        if rows.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(bad("s must increase from row to row".into()));
        }
        Ok(Self {
            names: header[1..].to_vec(),
            s: rows.iter().map(|r| r[0]).collect(),
            values: rows.iter().map(|r| r[1..].to_vec()).collect(),
        })
    }

    /// The range of s.
    pub(crate) fn range(&self) -> (f64, f64) {
        (self.s[0], self.s[self.s.len() - 1])
    }

    /// The changes of the coordinates at s (linear between rows).
    pub(crate) fn at(&self, s: f64) -> Vec<f64> {
        let n = self.s.len();
        let i = self.s.partition_point(|v| *v <= s).clamp(1, n - 1);
        let w = (s - self.s[i - 1]) / (self.s[i] - self.s[i - 1]);
        (0..self.names.len())
            .map(|j| self.values[i - 1][j] + w * (self.values[i][j] - self.values[i - 1][j]))
            .collect()
    }

    /// Makes the path's coordinates degrees of freedom of `scene` (before the
    /// automatic choice) and returns the mechanism and their DOF indices.
    pub(crate) fn mechanism(
        &self,
        scene: &mut Scene,
        dir: Option<&Path>,
    ) -> Result<(Mechanism, Vec<usize>), Failure> {
        let probe = scene
            .build(dir)
            .map_err(|e| Failure::Input(e.to_string()))?;
        for name in self.names.iter().rev() {
            let sel = coords::selection(&probe, name)?.ok_or_else(|| {
                Failure::Input(format!(
                    "path column '{name}' is not a coordinate or deformation of the scene (see `flexmb info`)"
                ))
            })?;
            scene.dofs_first.insert(0, sel);
        }
        let mech = scene
            .build(dir)
            .map_err(|e| Failure::Input(e.to_string()))?;
        let ks = self
            .names
            .iter()
            .map(|n| coords::dof_index(&mech, n, "path column"))
            .collect::<Result<Vec<_>, _>>()?;
        Ok((mech, ks))
    }
}
