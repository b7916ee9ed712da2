//! The linear two-node superelement data (thesis §2.2, §3.2) that a builder
//! writes and scenes load: S̄ (3.8), M̄ (3.11), l0, R0 and the mode metadata.

use crate::inertia::MAX_MODES;
use crate::ElementError;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Which interface a deformable-interface mode belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Side {
    /// Boundary node p.
    P,
    /// Boundary node q.
    Q,
}

/// What an extra mode (a column of W in (3.1)) is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ModeKind {
    /// A warping mode (3.4)–(3.5) of the given interface.
    Warping(Side),
    /// Another deformable-interface mode of the given interface, named.
    DeformableInterface {
        /// The interface.
        side: Side,
        /// A name for the displacement pattern.
        name: String,
    },
    /// A fixed-interface normal mode with its frequency.
    Normal {
        /// Eigenfrequency with both interfaces fixed (Hz).
        frequency_hz: f64,
    },
}

/// Where the superelement data came from.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// Source files with their hashes, free text.
    pub sources: Vec<String>,
    /// Settings used by the builder, free text.
    pub settings: Vec<String>,
}

/// Linear two-node superelement data.
///
/// * `s_bar` is S̄ over (µ̄e, η̄) = (ū^q_x, φ̄^q_x, φ̄^p_y, φ̄^q_y, φ̄^p_z, φ̄^q_z, η̄), thesis (3.6c), (3.8);
/// * `m_bar` is M̄ over (v̄p, ω̄p, v̄q, ω̄q, η̄̇), thesis (3.9b), (3.11);
/// * `modes` describes the η̄ in order: first the p-side interface modes, then the
///   q-side ones, then the fixed-interface normal modes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearSuperelement {
    /// Reference length |q − p| (m).
    pub l0: f64,
    /// Initial orientation R0: its columns are the element's x, y, z axes in the
    /// global frame (x from p to q).
    pub r0: [[f64; 3]; 3],
    /// S̄, (6 + k) × (6 + k), row-major rows.
    pub s_bar: Vec<Vec<f64>>,
    /// M̄, (12 + k) × (12 + k), row-major rows.
    pub m_bar: Vec<Vec<f64>>,
    /// The k extra modes.
    pub modes: Vec<ModeKind>,
    /// Where the data came from.
    #[serde(default)]
    pub provenance: Provenance,
}

impl LinearSuperelement {
    /// Number of extra modes k.
    pub fn n_modes(&self) -> usize {
        self.modes.len()
    }

    /// Counts of (p-side, q-side, normal) modes.
    pub fn mode_counts(&self) -> (usize, usize, usize) {
        let side = |s: Side| {
            self.modes
                .iter()
                .filter(|m| match m {
                    ModeKind::Warping(x) => *x == s,
                    ModeKind::DeformableInterface { side, .. } => *side == s,
                    ModeKind::Normal { .. } => false,
                })
                .count()
        };
        let p = side(Side::P);
        let q = side(Side::Q);
        (p, q, self.modes.len() - p - q)
    }

    /// S̄ as a matrix.
    pub fn s_bar_matrix(&self) -> DMatrix<f64> {
        rows_to_matrix(&self.s_bar)
    }

    /// M̄ as a matrix.
    pub fn m_bar_matrix(&self) -> DMatrix<f64> {
        rows_to_matrix(&self.m_bar)
    }

    /// Builds the data from matrices.
    pub fn from_matrices(
        l0: f64,
        r0: [[f64; 3]; 3],
        s_bar: &DMatrix<f64>,
        m_bar: &DMatrix<f64>,
        modes: Vec<ModeKind>,
    ) -> Self {
        let rows = |m: &DMatrix<f64>| {
            (0..m.nrows())
                .map(|i| m.row(i).iter().copied().collect())
                .collect()
        };
        Self {
            l0,
            r0,
            s_bar: rows(s_bar),
            m_bar: rows(m_bar),
            modes,
            provenance: Provenance::default(),
        }
    }

    /// Checks sizes, symmetry, finiteness, the ordering of modes, and that R0 is
    /// a rotation. Errors name what is wrong.
    pub fn validate(&self) -> Result<(), ElementError> {
        let k = self.n_modes();
        crate::section::positive("superelement l0", self.l0)?;
        if k > MAX_MODES {
            return Err(ElementError::Superelement(format!(
                "{k} extra modes; at most {MAX_MODES} are supported"
            )));
        }
        let check = |name: &str, rows: &Vec<Vec<f64>>, n: usize| -> Result<(), ElementError> {
            if rows.len() != n || rows.iter().any(|r| r.len() != n) {
                return Err(ElementError::Superelement(format!(
                    "{name} must be {n} × {n} for {k} extra modes, got {} rows of lengths {:?}",
                    rows.len(),
                    rows.iter().map(|r| r.len()).collect::<Vec<_>>()
                )));
            }
            let scale = rows.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
            for (i, r) in rows.iter().enumerate() {
                for (j, v) in r.iter().enumerate() {
                    if !v.is_finite() {
                        return Err(ElementError::Superelement(format!(
                            "{name}[{i}][{j}] is {v}"
                        )));
                    }
                    if (v - rows[j][i]).abs() > 1e-9 * scale {
                        return Err(ElementError::Superelement(format!(
                            "{name} is not symmetric: [{i}][{j}] = {v} but [{j}][{i}] = {}",
                            rows[j][i]
                        )));
                    }
                }
            }
            Ok(())
        };
        check("S̄", &self.s_bar, 6 + k)?;
        check("M̄", &self.m_bar, 12 + k)?;
        // modes ordered p, q, normal
        let rank = |m: &ModeKind| match m {
            ModeKind::Warping(Side::P) | ModeKind::DeformableInterface { side: Side::P, .. } => 0,
            ModeKind::Warping(Side::Q) | ModeKind::DeformableInterface { side: Side::Q, .. } => 1,
            ModeKind::Normal { .. } => 2,
        };
        if self.modes.windows(2).any(|w| rank(&w[0]) > rank(&w[1])) {
            return Err(ElementError::Superelement(
                "modes must be ordered: p-side interface modes, q-side interface modes, then normal modes".into(),
            ));
        }
        let r = nalgebra::Matrix3::from_fn(|i, j| self.r0[i][j]);
        if (r.transpose() * r - nalgebra::Matrix3::identity()).norm() > 1e-9
            || r.determinant() < 0.0
        {
            return Err(ElementError::Superelement(
                "R0 is not a rotation matrix".into(),
            ));
        }
        Ok(())
    }
}

pub(crate) fn rows_to_matrix(rows: &[Vec<f64>]) -> DMatrix<f64> {
    let n = rows.len();
    let m = rows.first().map_or(0, |r| r.len());
    DMatrix::from_fn(n, m, |i, j| rows[i][j])
}
