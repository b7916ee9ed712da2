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
    /// The FE mesh and its displacement recovery, if the builder wrote them
    /// (files without it still load).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fe_mesh: Option<FeMesh>,
}

/// One cell of a superelement's FE mesh: its VTK cell type (10 tetra, 24
/// quadratic tetra, 12 hexahedron, 25 quadratic hexahedron, 13 wedge, 26
/// quadratic wedge) and its nodes (indices into [`FeMesh::nodes`]) in VTK order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeCell {
    /// VTK cell type.
    pub vtk_type: u8,
    /// Node indices.
    pub nodes: Vec<usize>,
}

/// The FE mesh of a superelement with the recovery of its displacement field
/// (issue 21). Everything is in the element frame of the reference
/// configuration: origin at node p, axes the columns of R0.
///
/// A node at X (element frame) moves, in the element frame, by Σ_c Φ_c ζ_c with
/// ζ = (µ̄e, η̄) the coordinates of S̄ (thesis (3.6c)); see
/// `flexmb_superelement::recovery` for the co-rotated placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeMesh {
    /// Reference node positions X (element frame, m).
    pub nodes: Vec<[f64; 3]>,
    /// The cells (none when the FE elements are not known).
    pub cells: Vec<FeCell>,
    /// Per node the 3 translations per coordinate ζ_c, coordinate-major:
    /// `recovery[i][3 c + d]` is component d of Φ_c at node i; 3 (6 + k) per node.
    pub recovery: Vec<Vec<f64>>,
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
            fe_mesh: None,
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
        if let Some(mesh) = &self.fe_mesh {
            mesh.validate(6 + k)?;
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

impl FeCell {
    /// The number of nodes of a cell of VTK type `vtk_type`, for the types
    /// a mesh may hold (see [`FeCell`]); `None` for other types.
    pub fn node_count(vtk_type: u8) -> Option<usize> {
        match vtk_type {
            10 => Some(4),
            24 => Some(10),
            12 => Some(8),
            25 => Some(20),
            13 => Some(6),
            26 => Some(15),
            _ => None,
        }
    }
}

impl FeMesh {
    /// Checks the sizes against `n_coords` = 6 + k coordinates, the cells'
    /// types, node counts and node indices, and finiteness. Errors name the
    /// node or cell.
    pub fn validate(&self, n_coords: usize) -> Result<(), ElementError> {
        let bad = |m: String| Err(ElementError::Superelement(format!("fe_mesh: {m}")));
        let n = self.nodes.len();
        if self.recovery.len() != n {
            return bad(format!(
                "{} recovery rows for {n} nodes",
                self.recovery.len()
            ));
        }
        for (i, (x, r)) in self.nodes.iter().zip(&self.recovery).enumerate() {
            if r.len() != 3 * n_coords {
                return bad(format!(
                    "recovery row of node {i} has {} entries, expected 3 × {n_coords}",
                    r.len()
                ));
            }
            if x.iter().chain(r).any(|v| !v.is_finite()) {
                return bad(format!(
                    "node {i} has a non-finite position or recovery entry"
                ));
            }
        }
        for (c, cell) in self.cells.iter().enumerate() {
            match FeCell::node_count(cell.vtk_type) {
                None => {
                    return bad(format!(
                        "cell {c} has VTK type {}, not one of 10, 24, 12, 25, 13, 26 (tetra, quadratic tetra, hexahedron, quadratic hexahedron, wedge, quadratic wedge)",
                        cell.vtk_type
                    ))
                }
                Some(k) if k != cell.nodes.len() => {
                    return bad(format!(
                        "cell {c} (VTK type {}) has {} nodes, the type has {k}",
                        cell.vtk_type,
                        cell.nodes.len()
                    ))
                }
                Some(_) => {}
            }
            if let Some(&j) = cell.nodes.iter().find(|&&j| j >= n) {
                return bad(format!(
                    "cell {c} refers to node {j}, but there are {n} nodes"
                ));
            }
        }
        Ok(())
    }
}

pub(crate) fn rows_to_matrix(rows: &[Vec<f64>]) -> DMatrix<f64> {
    let n = rows.len();
    let m = rows.first().map_or(0, |r| r.len());
    DMatrix::from_fn(n, m, |i, j| rows[i][j])
}
