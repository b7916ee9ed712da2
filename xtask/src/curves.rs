//! Stored eigenfrequency curves (`fixtures/curves/`) and their comparison with
//! recomputed ones: the CI regression of `cargo xtask regress`.

use crate::models::CurvePoint;
use std::path::Path;

/// The eigenfrequency curve of one model as stored: per point the load scale,
/// the probed coordinate and the first eigenfrequencies.
#[derive(Clone, Debug, PartialEq)]
pub struct StoredCurve {
    /// The model's name.
    pub model: String,
    /// Load scale per point.
    pub lambda: Vec<f64>,
    /// The probed coordinate (e.g. the x-displacement) per point.
    pub x: Vec<f64>,
    /// Eigenfrequencies (Hz) per point.
    pub freqs: Vec<Vec<f64>>,
}

impl StoredCurve {
    /// From computed points: `coordinate` picks the probed component, `count`
    /// the number of eigenfrequencies kept (fewer if the model has fewer).
    pub fn from_points(
        model: &str,
        points: &[CurvePoint],
        coordinate: usize,
        count: usize,
    ) -> Self {
        Self {
            model: model.into(),
            lambda: points.iter().map(|p| p.lambda).collect(),
            x: points.iter().map(|p| p.position[coordinate]).collect(),
            freqs: points
                .iter()
                .map(|p| p.freqs.iter().take(count).copied().collect())
                .collect(),
        }
    }

    /// File name of a model's curve.
    pub fn file_name(model: &str) -> String {
        let slug: String = model
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                }
            })
            .collect();
        format!("{slug}.csv")
    }

    /// Writes the curve with a header saying how it was produced.
    pub fn write(&self, dir: &Path, provenance: &[String]) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        let nf = self.freqs.iter().map(|f| f.len()).max().unwrap_or(0);
        let mut header = vec!["lambda".to_string(), "x".to_string()];
        header.extend((1..=nf).map(|k| format!("f{k}_hz")));
        let rows: Vec<Vec<f64>> = (0..self.lambda.len())
            .map(|i| {
                let mut r = vec![self.lambda[i], self.x[i]];
                r.extend(&self.freqs[i]);
                r
            })
            .collect();
        let mut comments = vec![format!("model: {}", self.model)];
        comments.extend(provenance.iter().cloned());
        flexmb_plot::write_csv(
            &dir.join(Self::file_name(&self.model)),
            &comments,
            &header,
            &rows,
        )
    }

    /// Reads a model's stored curve from `dir`.
    pub fn read(dir: &Path, model: &str) -> Result<Self, String> {
        let path = dir.join(Self::file_name(model));
        let (header, rows) = flexmb_plot::read_csv(&path)
            .map_err(|e| format!("cannot read the stored curve {}: {e}", path.display()))?;
        if header.len() < 3 || header[0] != "lambda" || header[1] != "x" {
            return Err(format!("{}: unexpected header {header:?}", path.display()));
        }
        if rows.iter().any(|r| r.len() != header.len()) {
            return Err(format!("{}: rows of different lengths", path.display()));
        }
        Ok(Self {
            model: model.into(),
            lambda: rows.iter().map(|r| r[0]).collect(),
            x: rows.iter().map(|r| r[1]).collect(),
            freqs: rows.iter().map(|r| r[2..].to_vec()).collect(),
        })
    }
}

/// Compares a recomputed curve with the stored one: the same load scales, and
/// every eigenfrequency and probed coordinate within the relative tolerance
/// `rtol`. Returns one line per difference (empty when they agree).
pub fn compare(stored: &StoredCurve, new: &StoredCurve, rtol: f64) -> Vec<String> {
    let mut out = vec![];
    let name = &stored.model;
    if stored.lambda.len() != new.lambda.len() {
        return vec![format!(
            "{name}: {} stored points, {} recomputed",
            stored.lambda.len(),
            new.lambda.len()
        )];
    }
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= rtol * scale.max(a.abs());
    let x_scale = stored.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..stored.lambda.len() {
        if !close(stored.lambda[i], new.lambda[i], 1e-300) {
            out.push(format!(
                "{name} point {i}: load scale {} stored, {} recomputed",
                stored.lambda[i], new.lambda[i]
            ));
            continue;
        }
        if !close(stored.x[i], new.x[i], x_scale) {
            out.push(format!(
                "{name} point {i} (λ = {:.4}): x {:.9e} stored, {:.9e} recomputed",
                stored.lambda[i], stored.x[i], new.x[i]
            ));
        }
        if stored.freqs[i].len() != new.freqs[i].len() {
            out.push(format!(
                "{name} point {i}: {} stored eigenfrequencies, {} recomputed",
                stored.freqs[i].len(),
                new.freqs[i].len()
            ));
            continue;
        }
        for (k, (a, b)) in stored.freqs[i].iter().zip(&new.freqs[i]).enumerate() {
            if !close(*a, *b, 0.0) {
                out.push(format!(
                    "{name} point {i} (λ = {:.4}): f{} {a:.9e} Hz stored, {b:.9e} recomputed (relative change {:.2e}, tolerance {rtol:.0e})",
                    stored.lambda[i],
                    k + 1,
                    (b - a) / a
                ));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve() -> StoredCurve {
        StoredCurve {
            model: "MSI-7".into(),
            lambda: vec![-1.0, 0.0, 1.0],
            x: vec![-0.08, 0.0, 0.08],
            freqs: vec![vec![5.1, 40.0], vec![5.3, 79.4], vec![5.1, 40.0]],
        }
    }

    #[test]
    fn identical_curves_agree_and_round_trip_through_the_file() {
        let c = curve();
        let dir = std::env::temp_dir().join(format!("xtask-curves-{}", std::process::id()));
        c.write(&dir, &["test".into()]).unwrap();
        let back = StoredCurve::read(&dir, "MSI-7").unwrap();
        assert!(compare(&c, &back, 1e-12).is_empty());
        assert_eq!(StoredCurve::file_name("MSI-7g"), "msi_7g.csv");
    }

    #[test]
    fn a_perturbed_eigenfrequency_fails_the_comparison() {
        let c = curve();
        let mut p = c.clone();
        p.freqs[2][1] *= 1.0 + 1e-5;
        let d = compare(&c, &p, 1e-6);
        assert_eq!(d.len(), 1, "{d:?}");
        assert!(d[0].contains("point 2") && d[0].contains("f2"), "{}", d[0]);
        // within tolerance passes
        let mut q = c.clone();
        q.freqs[2][1] *= 1.0 + 1e-8;
        assert!(compare(&c, &q, 1e-6).is_empty());
        // a moved configuration or a missing point fails too
        let mut r = c.clone();
        r.x[0] += 1e-4;
        assert_eq!(compare(&c, &r, 1e-6).len(), 1);
        let mut s = c.clone();
        s.lambda.pop();
        assert_eq!(compare(&c, &s, 1e-6).len(), 1);
    }
}
