//! `Model.reduce`: the basis methods of `flexmb reduce` (thesis chapters
//! 5–6) on the reduction crate, giving the saved form of the reduced model.

use crate::errors;
use crate::model::dof_index;
use crate::run::Watch;
use flexmb::linearize::{sweep_until, SweepOptions, SweepParameter, SweepPoint};
use flexmb::model::Mechanism;
use flexmb::reduction::{
    interpolated_basis_from_sweep, modal_basis, per_mode_svd_basis, svd_modal_basis, SavedModel,
    SubspaceInterpolation, FINAL_SVD_THRESHOLD, SVD_THRESHOLD,
};
use pyo3::PyResult;
use std::sync::Arc;

/// How the basis is built (the `--method` of `flexmb reduce`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The first R modes at the reference configuration (5.21).
    Modal,
    /// The first R modes over a sweep, weighted, one SVD (5.22)–(5.23).
    SvdModal,
    /// Per-mode SVDs over a sweep, then a final SVD (§6.3.2).
    FbmSvd,
    /// Interpolated basis by modal subspace interpolation (§6.3.3).
    IbmMsi,
    /// Interpolated basis of MAC-sorted eigenvectors.
    IbmMac,
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "modal" => Method::Modal,
            "svd-modal" => Method::SvdModal,
            "fbm-svd" => Method::FbmSvd,
            "ibm-msi" => Method::IbmMsi,
            "ibm-mac" => Method::IbmMac,
            _ => {
                return Err(format!(
                    "unknown method '{s}': use modal, svd-modal, fbm-svd, ibm-msi or ibm-mac"
                ))
            }
        })
    }
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Modal => "modal",
            Method::SvdModal => "svd-modal",
            Method::FbmSvd => "fbm-svd",
            Method::IbmMsi => "ibm-msi",
            Method::IbmMac => "ibm-mac",
        }
    }
    fn is_ibm(self) -> bool {
        matches!(self, Method::IbmMsi | Method::IbmMac)
    }
}

/// The arguments of `Model.reduce`.
pub struct ReduceArgs {
    pub method: Method,
    pub modes: usize,
    pub keep: Vec<String>,
    pub a: Option<f64>,
    pub threshold: Option<f64>,
    pub final_threshold: Option<f64>,
    pub over: Option<String>,
    pub values: Option<Vec<f64>>,
    pub t_load: f64,
    pub no_gravity: bool,
}

impl ReduceArgs {
    /// Rejects arguments that do not apply to the method and missing or
    /// invalid values, naming the argument.
    pub fn check(&self, mech: &Mechanism) -> PyResult<()> {
        let m = self.method;
        let bad = |s: String| Err(errors::argument(s));
        let mut wrong = vec![];
        if !self.keep.is_empty() && m != Method::Modal {
            wrong.push("keep (modal only)");
        }
        if self.a.is_some() && m != Method::SvdModal {
            wrong.push("a (svd-modal only)");
        }
        if self.threshold.is_some() && !matches!(m, Method::SvdModal | Method::FbmSvd) {
            wrong.push("threshold (svd-modal and fbm-svd)");
        }
        if self.final_threshold.is_some() && m != Method::FbmSvd {
            wrong.push("final_threshold (fbm-svd only)");
        }
        if m == Method::Modal && (self.over.is_some() || self.values.is_some()) {
            wrong.push("over and values (modal uses the modes at the reference configuration)");
        }
        if !wrong.is_empty() {
            return bad(format!(
                "{} not for method={:?}",
                wrong.join(", "),
                m.name()
            ));
        }
        if self.modes == 0 {
            return bad("modes must be at least 1".into());
        }
        for (v, o) in [
            (self.threshold, "threshold"),
            (self.final_threshold, "final_threshold"),
        ] {
            if let Some(v) = v {
                if !(v > 0.0 && v < 1.0) {
                    return bad(format!(
                        "{o} is a fraction of the sum of the singular values, in (0, 1); got {v}"
                    ));
                }
            }
        }
        if !self.t_load.is_finite() || !self.a.unwrap_or(0.0).is_finite() {
            return bad("t_load and a must be finite".into());
        }
        let needed = match m {
            Method::Modal => self.modes + self.keep.len(),
            Method::IbmMsi | Method::IbmMac => self.modes + 1,
            _ => self.modes,
        };
        if needed > mech.n_dof() {
            return bad(format!(
                "modes={} needs {needed} modes but the model has {} degrees of freedom",
                self.modes,
                mech.n_dof()
            ));
        }
        if m == Method::Modal {
            return Ok(());
        }
        let (Some(over), Some(values)) = (&self.over, &self.values) else {
            return bad(format!(
                "method={:?} builds its basis from a sweep: give over={} and values=[...]",
                m.name(),
                if m.is_ibm() {
                    "COORD"
                } else {
                    "\"load\" or COORD"
                }
            ));
        };
        if m.is_ibm() {
            if over == "load" {
                return bad(format!(
                    "method={:?} interpolates along a degree of freedom s held over the sweep \
                     ((6.23)); give over=COORD (e.g. \"S.x\")",
                    m.name()
                ));
            }
            if values.len() < 3 || values.windows(2).any(|w| w[1] <= w[0]) {
                return bad(
                    "values: an interpolated basis needs at least 3 increasing knots".into(),
                );
            }
        } else if values.len() < 2 {
            return bad("values: a sweep needs at least 2 configurations".into());
        }
        if over != "load" {
            dof_index(mech, over, "over")?;
        }
        Ok(())
    }
}

/// The reference sweep of a sweep method: the configurations with their
/// first `modes` mode shapes, the held DOF (if any) and a description.
fn reference_sweep(
    mech: &Arc<Mechanism>,
    a: &ReduceArgs,
    modes: usize,
    w: &Watch,
) -> PyResult<(Vec<SweepPoint>, Option<usize>, String)> {
    let over = a.over.clone().unwrap_or_default();
    let values = a.values.clone().unwrap_or_default();
    let n = values.len();
    let (lo, hi) = (values[0], values[n - 1]);
    let (param, values, dof, what) = if over == "load" {
        let what = format!(
            "{n} configurations over load scale [{lo}, {hi}] at t = {} s",
            a.t_load
        );
        (SweepParameter::LoadScale, values, None, what)
    } else {
        let k = dof_index(mech, &over, "over")?;
        let q_ref = mech.q0()[k];
        let what = format!("{n} configurations with {over} changed by [{lo}, {hi}]");
        let values = values.iter().map(|v| q_ref + v).collect();
        (SweepParameter::Dof(k), values, Some(k), what)
    };
    let opts = SweepOptions {
        values,
        modes,
        t: a.t_load,
        keep_vectors: true,
    };
    let outcome = sweep_until(
        mech,
        &param,
        &opts,
        &|d, total| w.progress(d as f64 / total.max(1) as f64),
        Some(&w.stop),
    )
    .map_err(|e| errors::solver(format!("the reference sweep did not converge: {e}")))?;
    if outcome.stopped {
        return Err(errors::FlexmbError::new_err("reduce: stopped"));
    }
    Ok((outcome.points, dof, what))
}

/// Builds the basis of `a.method` on `mech` and returns its saved form.
pub fn build(
    mech: &Arc<Mechanism>,
    a: &ReduceArgs,
    scene: &str,
    w: &Watch,
) -> PyResult<SavedModel> {
    let r = a.modes;
    let q0 = mech.q0();
    let no_g = if a.no_gravity {
        ", basis built without gravity"
    } else {
        ""
    };
    Ok(match a.method {
        Method::Modal => {
            let keep: Vec<usize> = a
                .keep
                .iter()
                .map(|c| dof_index(mech, c, "keep"))
                .collect::<PyResult<_>>()?;
            if let Some(c) = (0..keep.len()).find(|&i| keep[..i].contains(&keep[i])) {
                return Err(errors::argument(format!(
                    "keep lists '{}' twice",
                    a.keep[c]
                )));
            }
            let b = modal_basis(mech, a.t_load, &q0, r, (!keep.is_empty()).then_some(&keep))
                .map_err(errors::reduction)?;
            let kept = if keep.is_empty() {
                String::new()
            } else {
                format!(", keeping {}", a.keep.join(", "))
            };
            let d = format!(
                "modal: first {r} modes at the reference configuration (t = {} s){kept}{no_g}",
                a.t_load
            );
            SavedModel::fixed(&d, scene, mech, &b)
        }
        Method::SvdModal => {
            let (pts, _, what) = reference_sweep(mech, a, r, w)?;
            let (wt, th) = (a.a.unwrap_or(0.0), a.threshold.unwrap_or(SVD_THRESHOLD));
            let s = svd_modal_basis(&q0, &pts, r, wt, th).map_err(errors::reduction)?;
            let kept = s.basis.v.ncols();
            let d = format!(
                "svd-modal: first {r} modes at {what}, weights ω^-{wt}, {kept} singular vectors above {th} of the sum{no_g}"
            );
            SavedModel::fixed(&d, scene, mech, &s.basis)
        }
        Method::FbmSvd => {
            let (pts, _, what) = reference_sweep(mech, a, r, w)?;
            let th = a.threshold.unwrap_or(SVD_THRESHOLD);
            let fth = a.final_threshold.unwrap_or(FINAL_SVD_THRESHOLD);
            let modes: Vec<usize> = (0..r).collect();
            let p = per_mode_svd_basis(&q0, &pts, &modes, th, fth).map_err(errors::reduction)?;
            let kept = p.basis.v.ncols();
            let d = format!(
                "fbm-svd: modes 1..{r} at {what}, per-mode SVD above {th}, final SVD above {fth}: {kept} vectors{no_g}"
            );
            SavedModel::fixed(&d, scene, mech, &p.basis)
        }
        Method::IbmMsi | Method::IbmMac => {
            let (pts, dof, what) = reference_sweep(mech, a, r + 1, w)?;
            let (how, m) = if a.method == Method::IbmMsi {
                (
                    "modal subspace interpolation (mass-normalized)",
                    SubspaceInterpolation::Msi,
                )
            } else {
                ("MAC-sorted eigenvectors", SubspaceInterpolation::MacSorted)
            };
            let k = dof.ok_or_else(|| errors::argument("over=COORD needed"))?;
            let b = interpolated_basis_from_sweep(q0, k, &pts, 1..1 + r, m, true)
                .map_err(errors::reduction)?;
            let d = format!(
                "{}: s = {}, {what}, modes 2..{} by {how}{no_g}",
                a.method.name(),
                a.over.as_deref().unwrap_or("?"),
                r + 1
            );
            SavedModel::interpolated(&d, scene, mech, &b)
        }
    })
}
