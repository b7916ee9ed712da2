//! Saving and loading reduced models: the basis data (vectors, or knots with
//! configurations and interpolation-ready base vectors) in RON, checked against
//! the mechanism's degrees of freedom when loaded, so that a model built once
//! is simulated many times.

use crate::{
    Basis, FixedBasis, GridBasis, GridKnots, InterpolatedBasis, ReducedModel, ReductionError,
};
use faer::Mat;
use flexmb_model::Mechanism;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Arc;

/// The current file format version.
pub const FORMAT_VERSION: u32 = 1;

/// A reduced model on disk.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SavedModel {
    /// File format version ([`FORMAT_VERSION`]).
    pub format: u32,
    /// What the model is and how it was built (method, modes, sweep).
    pub description: String,
    /// The scene it reduces (as given when it was built).
    pub scene: String,
    /// The names of the unreduced degrees of freedom q, in order.
    pub dofs: Vec<String>,
    /// The constraint q = G(z).
    pub basis: SavedBasis,
}

/// The data of a basis.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SavedBasis {
    /// G = q0 + Vη (6.16).
    Fixed {
        /// Offset q0.
        q0: Vec<f64>,
        /// The columns of V.
        vectors: Vec<Vec<f64>>,
    },
    /// G = Q(s) + V(s)η + q0 (6.23).
    Interpolated {
        /// Offset q0.
        q0: Vec<f64>,
        /// The knots s.
        s: Vec<f64>,
        /// The DOFs at the knots.
        q: Vec<Vec<f64>>,
        /// The base vectors at the knots (per knot, r columns).
        w: Vec<Vec<Vec<f64>>>,
        /// The equilibrium path's tangents dq/ds at the knots, if Q is
        /// their Hermite interpolant ([`InterpolatedBasis::with_tangents`]).
        #[serde(default)]
        tangents: Option<Vec<Vec<f64>>>,
    },
    /// G = Q(s1, s2) + V(s1, s2)η + q0 over a tensor grid ([`GridBasis`]).
    Grid {
        /// Offset q0.
        q0: Vec<f64>,
        /// The grid lines of s1.
        s1: Vec<f64>,
        /// The grid lines of s2.
        s2: Vec<f64>,
        /// The DOFs at the grid points (point (i, j) at index i + n1 j).
        q: Vec<Vec<f64>>,
        /// The base vectors there (per point, r columns).
        w: Vec<Vec<Vec<f64>>>,
        /// The equilibrium tangents ∂q/∂s1, ∂q/∂s2 there, if Q is the
        /// Hermite interpolant ([`GridBasis::with_tangents`]).
        #[serde(default)]
        tangents: Option<Vec<[Vec<f64>; 2]>>,
    },
}

impl SavedBasis {
    /// How many of the reduced coordinates are configuration coordinates
    /// (s of an interpolated basis, s1 and s2 of a grid): 0, 1 or 2.
    pub fn configuration_coordinates(&self) -> usize {
        match self {
            Self::Fixed { .. } => 0,
            Self::Interpolated { .. } => 1,
            Self::Grid { .. } => 2,
        }
    }
}

/// The names of a mechanism's degrees of freedom.
pub fn dof_names(mech: &Mechanism) -> Vec<String> {
    mech.dofs
        .iter()
        .map(|c| mech.coordinate_name(*c).to_string())
        .collect()
}

impl SavedModel {
    /// A fixed basis of `mech`.
    pub fn fixed(description: &str, scene: &str, mech: &Mechanism, b: &FixedBasis) -> Self {
        Self::of(
            description,
            scene,
            mech,
            SavedBasis::Fixed {
                q0: b.q0.clone(),
                vectors: (0..b.v.ncols())
                    .map(|j| b.v.col_as_slice(j).to_vec())
                    .collect(),
            },
        )
    }

    /// An interpolated basis of `mech`.
    pub fn interpolated(
        description: &str,
        scene: &str,
        mech: &Mechanism,
        b: &InterpolatedBasis,
    ) -> Self {
        let k = b.knots();
        Self::of(
            description,
            scene,
            mech,
            SavedBasis::Interpolated {
                q0: b.q0().to_vec(),
                s: k.s.clone(),
                q: k.qs.clone(),
                w: k.w.clone(),
                tangents: k.tangents.clone(),
            },
        )
    }

    /// A saved model of `mech` with the basis data `basis`.
    fn of(description: &str, scene: &str, mech: &Mechanism, basis: SavedBasis) -> Self {
        Self {
            format: FORMAT_VERSION,
            description: description.into(),
            scene: scene.into(),
            dofs: dof_names(mech),
            basis,
        }
    }

    /// A grid basis of `mech` (beyond the thesis: two configuration
    /// coordinates).
    pub fn grid(description: &str, scene: &str, mech: &Mechanism, b: &GridBasis) -> Self {
        let k = b.knots();
        Self::of(
            description,
            scene,
            mech,
            SavedBasis::Grid {
                q0: b.q0().to_vec(),
                s1: k.s1.clone(),
                s2: k.s2.clone(),
                q: k.qs.clone(),
                w: k.w.clone(),
                tangents: k.tangents.clone(),
            },
        )
    }

    /// Writes the model as RON.
    pub fn save(&self, path: &Path) -> Result<(), ReductionError> {
        let text = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
            .map_err(|e| ReductionError::Invalid(format!("cannot serialize the model: {e}")))?;
        std::fs::write(path, text)
            .map_err(|e| ReductionError::Invalid(format!("cannot write {}: {e}", path.display())))
    }

    /// Reads a model written by [`save`](Self::save).
    pub fn load(path: &Path) -> Result<Self, ReductionError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ReductionError::Invalid(format!("cannot read {}: {e}", path.display())))?;
        let m: Self = flexmb_input::from_ron(&text).map_err(|e| {
            ReductionError::Invalid(format!(
                "{}:{}:{}: not a reduced model: {}",
                path.display(),
                e.line,
                e.column,
                e.message
            ))
        })?;
        if m.format != FORMAT_VERSION {
            return Err(ReductionError::Invalid(format!(
                "{}: reduced-model format {} (this flexmb reads {FORMAT_VERSION})",
                path.display(),
                m.format
            )));
        }
        Ok(m)
    }

    /// The basis, checked against `mech`: the same degrees of freedom in the
    /// same order, finite data.
    pub fn basis_for(&self, mech: &Mechanism) -> Result<Box<dyn Basis>, ReductionError> {
        let names = dof_names(mech);
        if names != self.dofs {
            let first = names
                .iter()
                .zip(&self.dofs)
                .position(|(a, b)| a != b)
                .unwrap_or(names.len().min(self.dofs.len()));
            let name = |v: &[String]| {
                v.get(first)
                    .map(|n| format!("`{n}`"))
                    .unwrap_or_else(|| "absent".into())
            };
            return Err(ReductionError::Invalid(format!(
                "the reduced model was built for other degrees of freedom: DOF {} is {} in the model and {} in the scene (the model has {} DOFs, the scene {}); rebuild the model from this scene",
                first + 1,
                name(&self.dofs),
                name(&names),
                self.dofs.len(),
                names.len(),
            )));
        }
        let n_q = names.len();
        let q0_len = match &self.basis {
            SavedBasis::Fixed { q0, .. }
            | SavedBasis::Interpolated { q0, .. }
            | SavedBasis::Grid { q0, .. } => q0.len(),
        };
        if q0_len != n_q {
            return Err(ReductionError::Invalid(format!(
                "the model lists {n_q} DOFs but its offset q0 has {q0_len} values"
            )));
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        match &self.basis {
            SavedBasis::Fixed { q0, vectors } => {
                let n = q0.len();
                if vectors.is_empty()
                    || vectors.iter().any(|c| c.len() != n || !finite(c))
                    || !finite(q0)
                {
                    return Err(ReductionError::Invalid(
                        "fixed basis: no vectors, vectors of the wrong length, or non-finite values".into(),
                    ));
                }
                Ok(Box::new(FixedBasis {
                    q0: q0.clone(),
                    v: Mat::from_fn(n, vectors.len(), |i, j| vectors[j][i]),
                }))
            }
            SavedBasis::Interpolated {
                q0,
                s,
                q,
                w,
                tangents,
            } => {
                if !finite(q0)
                    || !finite(s)
                    || q.iter().any(|v| !finite(v))
                    || w.iter().flatten().any(|v| !finite(v))
                {
                    return Err(ReductionError::Invalid(
                        "interpolated basis: non-finite values".into(),
                    ));
                }
                let b = InterpolatedBasis::from_knots(q0.clone(), s.clone(), q.clone(), w.clone())?;
                Ok(Box::new(match tangents {
                    Some(t) => b.with_tangents(t.clone())?,
                    None => b,
                }))
            }
            // sizes and finiteness are checked by from_knots
            SavedBasis::Grid {
                q0,
                s1,
                s2,
                q,
                w,
                tangents,
            } => Ok(Box::new(GridBasis::from_knots(
                q0.clone(),
                GridKnots {
                    s1: s1.clone(),
                    s2: s2.clone(),
                    qs: q.clone(),
                    w: w.clone(),
                    tangents: tangents.clone(),
                },
            )?)),
        }
    }

    /// The reduced model of `mech`.
    pub fn into_model(&self, mech: Arc<Mechanism>) -> Result<ReducedModel, ReductionError> {
        let b = self.basis_for(&mech)?;
        ReducedModel::new(mech, b)
    }
}
