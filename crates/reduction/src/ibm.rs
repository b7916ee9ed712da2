//! The interpolated basis method (thesis §6.3.3): q = Q(s) + V(s)η + q0 (6.23)
//! with Q and V cubic splines through n reference configurations, and the
//! derivatives of (6.24) and (F.6).

use crate::msi::{mac_sorted, modal_subspace_interpolation};
use crate::spline::CubicSpline;
use crate::{Basis, ReductionError};
use faer::Mat;

/// How V(s) is obtained from the eigenvectors at the reference configurations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SubspaceInterpolation {
    /// Modal subspace interpolation, steps 1–8 of §6.3.3 (MSI models).
    Msi,
    /// Eigenvectors sorted by MAC mode tracking (the MAC-7 model).
    MacSorted,
}

/// The data an interpolated basis is built from.
#[derive(Clone, Debug)]
pub struct Knots {
    /// The configuration coordinate at the knots.
    pub s: Vec<f64>,
    /// The DOFs at the knots.
    pub qs: Vec<Vec<f64>>,
    /// The interpolation-ready base vectors at the knots (r columns each).
    pub w: Vec<Vec<Vec<f64>>>,
    /// The equilibrium path's tangents dq/ds at the knots, when known
    /// ([`InterpolatedBasis::with_tangents`]): Q is then their cubic
    /// Hermite interpolant, else the natural spline of (6.23).
    pub tangents: Option<Vec<Vec<f64>>>,
}

/// An interpolated basis q = Q(s) + V(s)η + q0, z = (s, η).
#[derive(Clone, Debug)]
pub struct InterpolatedBasis {
    q0: Vec<f64>,
    knots: Knots,
    q: CubicSpline,
    v: CubicSpline,
    n_q: usize,
    r: usize,
    /// Spline work arrays of [`Basis::eval`] (Q and its derivatives, V and
    /// its derivatives column by column), so that the equations of motion
    /// do not allocate.
    work: SplineWork,
}

/// Work arrays behind a mutex (uncontended: each model evaluates in one
/// thread), so the basis stays `Sync` for parallel sweeps; a clone starts
/// with empty arrays.
#[derive(Debug, Default)]
struct SplineWork(std::sync::Mutex<[[Vec<f64>; 4]; 2]>);

impl Clone for SplineWork {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl InterpolatedBasis {
    /// From the configuration coordinate values `s`, the DOFs `qs` of the
    /// reference configurations, and the r retained eigenvectors `vecs` there
    /// (n_q × r each; for constrained eigenvectors without components along the
    /// motion). With `mass`, MSI mass-normalizes (step 7, (6.26)).
    pub fn new(
        q0: Vec<f64>,
        s: Vec<f64>,
        qs: &[Vec<f64>],
        vecs: &[Mat<f64>],
        mass: Option<&[Mat<f64>]>,
        method: SubspaceInterpolation,
    ) -> Result<Self, ReductionError> {
        let n_q = q0.len();
        if qs.len() != s.len() || vecs.len() != s.len() {
            return Err(ReductionError::Invalid(
                "one configuration and one set of eigenvectors per knot".into(),
            ));
        }
        let r = vecs.first().map_or(0, |v| v.ncols());
        if vecs.iter().any(|v| v.nrows() != n_q || v.ncols() != r)
            || qs.iter().any(|q| q.len() != n_q)
        {
            return Err(ReductionError::Invalid(
                "inconsistent sizes of configurations or eigenvectors".into(),
            ));
        }
        let w = match method {
            SubspaceInterpolation::Msi => modal_subspace_interpolation(vecs, mass),
            SubspaceInterpolation::MacSorted => mac_sorted(vecs),
        };
        let w: Vec<Vec<Vec<f64>>> = w
            .iter()
            .map(|m| (0..r).map(|j| m.col_as_slice(j).to_vec()).collect())
            .collect();
        Self::from_knots(q0, s, qs.to_vec(), w)
    }

    /// From the knot data directly: the configuration coordinate values `s`,
    /// the DOFs `qs` there and the (already interpolation-ready) base vectors
    /// `w` there (per knot, r columns of length n_q). This is how a saved
    /// model is restored.
    pub fn from_knots(
        q0: Vec<f64>,
        s: Vec<f64>,
        qs: Vec<Vec<f64>>,
        w: Vec<Vec<Vec<f64>>>,
    ) -> Result<Self, ReductionError> {
        let n_q = q0.len();
        let r = w.first().map_or(0, |v| v.len());
        if qs.len() != s.len()
            || w.len() != s.len()
            || qs.iter().any(|q| q.len() != n_q)
            || w.iter()
                .any(|v| v.len() != r || v.iter().any(|c| c.len() != n_q))
        {
            return Err(ReductionError::Invalid(
                "interpolated basis: inconsistent sizes of knots, configurations or base vectors"
                    .into(),
            ));
        }
        let dq: Vec<Vec<f64>> = qs
            .iter()
            .map(|q| q.iter().zip(&q0).map(|(a, b)| a - b).collect())
            .collect();
        let flat: Vec<Vec<f64>> = w.iter().map(|m| m.concat()).collect();
        Ok(Self {
            q: CubicSpline::new(s.clone(), dq)?,
            v: CubicSpline::new(s.clone(), flat)?,
            knots: Knots {
                s,
                qs,
                w,
                tangents: None,
            },
            work: SplineWork::default(),
            q0,
            n_q,
            r,
        })
    }

    /// The same basis with Q the cubic Hermite interpolant of the reference
    /// configurations and the equilibrium path's `tangents` dq/ds there (one
    /// per knot, n_q each; from [`crate::equilibrium_tangents`] times the
    /// held DOFs' ds-derivatives). At a knot Q,s is then the path's own
    /// tangent, where the natural spline's derivative strays into stiff
    /// directions and raises the mechanism modes' Ritz values (see
    /// [`crate::GridBasis::with_tangents`]).
    ///
    /// # Errors
    ///
    /// [`ReductionError::Invalid`] for a wrong count or length of tangents,
    /// or a non-finite entry.
    pub fn with_tangents(mut self, tangents: Vec<Vec<f64>>) -> Result<Self, ReductionError> {
        if tangents.len() != self.knots.s.len() || tangents.iter().any(|t| t.len() != self.n_q) {
            return Err(ReductionError::Invalid(format!(
                "interpolated basis: {} tangents of length {} for {} knots and {} DOFs",
                tangents.len(),
                tangents.first().map_or(0, Vec::len),
                self.knots.s.len(),
                self.n_q
            )));
        }
        let dq: Vec<Vec<f64>> = self
            .knots
            .qs
            .iter()
            .map(|q| q.iter().zip(&self.q0).map(|(a, b)| a - b).collect())
            .collect();
        self.q = CubicSpline::hermite(self.knots.s.clone(), dq, tangents.clone())?;
        self.knots.tangents = Some(tangents);
        Ok(self)
    }

    /// The knot data (for saving): s, the DOFs and the base vectors there.
    pub fn knots(&self) -> &Knots {
        &self.knots
    }

    /// The offset q0.
    pub fn q0(&self) -> &[f64] {
        &self.q0
    }

    /// The number of interpolated base vectors r (n_z = 1 + r).
    pub fn r(&self) -> usize {
        self.r
    }

    /// V(s) and its first three derivatives (n_q × r each).
    pub fn v_and_derivatives(&self, s: f64) -> [Mat<f64>; 4] {
        let mut w = self.v.work();
        self.v.eval(s, &mut w);
        std::array::from_fn(|o| Mat::from_fn(self.n_q, self.r, |i, j| w[o][j * self.n_q + i]))
    }

    /// The range of s covered by the reference configurations.
    pub fn range(&self) -> (f64, f64) {
        self.q.range()
    }

    /// The third derivative of G along ż, ż, ż: (G,zzz ż)ż)ż, from (F.6).
    pub fn third_derivative(&self, z: &[f64], zd: &[f64], out: &mut [f64]) {
        let (s, eta) = (z[0], &z[1..]);
        let (sd, etad) = (zd[0], &zd[1..]);
        let mut wq = self.q.work();
        self.q.eval(s, &mut wq);
        let v = self.v_and_derivatives(s);
        for i in 0..self.n_q {
            let mut a = wq[3][i];
            let mut b = 0.0;
            for j in 0..self.r {
                a += v[3][(i, j)] * eta[j];
                b += v[2][(i, j)] * etad[j];
            }
            out[i] = a * sd * sd * sd + 3.0 * b * sd * sd;
        }
    }
}

impl Basis for InterpolatedBasis {
    fn n_z(&self) -> usize {
        1 + self.r
    }
    /// (F.6): G,ss = Q'' + V''η, G,sη = V', G,ηη = 0, contracted with r.
    fn hessian_contraction(&self, z: &[f64], r: &[f64]) -> Mat<f64> {
        let (s, eta) = (z[0], &z[1..]);
        let mut wq = self.q.work();
        self.q.eval(s, &mut wq);
        let v = self.v_and_derivatives(s);
        let mut h = Mat::zeros(1 + self.r, 1 + self.r);
        let mut hss = 0.0;
        for i in 0..self.n_q {
            let mut g = wq[2][i];
            for j in 0..self.r {
                g += v[2][(i, j)] * eta[j];
            }
            hss += r[i] * g;
        }
        h[(0, 0)] = hss;
        for j in 0..self.r {
            let hsj: f64 = (0..self.n_q).map(|i| r[i] * v[1][(i, j)]).sum();
            h[(0, 1 + j)] = hsj;
            h[(1 + j, 0)] = hsj;
        }
        h
    }
    fn n_q(&self) -> usize {
        self.n_q
    }
    /// (F.6): column s = v_s (Q″ + V″η) + V′ v_η, column η_j = v_s V′_j.
    fn second_derivative_matrix(&self, z: &[f64], v: &[f64]) -> Mat<f64> {
        let (s, eta) = (z[0], &z[1..]);
        let mut wq = self.q.work();
        self.q.eval(s, &mut wq);
        let vv = self.v_and_derivatives(s);
        Mat::from_fn(self.n_q, 1 + self.r, |i, k| {
            if k == 0 {
                let mut gss = wq[2][i];
                let mut a = 0.0;
                for j in 0..self.r {
                    gss += vv[2][(i, j)] * eta[j];
                    a += vv[1][(i, j)] * v[1 + j];
                }
                v[0] * gss + a
            } else {
                v[0] * vv[1][(i, k - 1)]
            }
        })
    }
    /// (F.6): column s = (Q‴ + V‴η) ṡ² + 2 V″η̇ ṡ, column η_j = V″_j ṡ².
    fn third_derivative_matrix(&self, z: &[f64], zd: &[f64]) -> Mat<f64> {
        let (s, eta) = (z[0], &z[1..]);
        let (sd, etad) = (zd[0], &zd[1..]);
        let mut wq = self.q.work();
        self.q.eval(s, &mut wq);
        let vv = self.v_and_derivatives(s);
        Mat::from_fn(self.n_q, 1 + self.r, |i, k| {
            if k == 0 {
                let mut g3 = wq[3][i];
                let mut b = 0.0;
                for j in 0..self.r {
                    g3 += vv[3][(i, j)] * eta[j];
                    b += vv[2][(i, j)] * etad[j];
                }
                g3 * sd * sd + 2.0 * b * sd
            } else {
                vv[2][(i, k - 1)] * sd * sd
            }
        })
    }
    /// (s, 0) with s the knot whose configuration is closest to q0.
    fn z_reference(&self) -> Vec<f64> {
        let k = crate::basis::nearest_configuration(&self.knots.qs, &self.q0);
        let mut z = vec![0.0; 1 + self.r];
        z[0] = self.knots.s[k];
        z
    }
    /// (6.23)–(6.24): q = Q + Vη + q0, G,z = [Q' + V'η, V],
    /// (G,zz ż)ż = (Q'' + V''η) ṡ² + 2 V' η̇ ṡ.
    fn eval(&self, z: &[f64], zd: &[f64], q: &mut [f64], gz: &mut Mat<f64>, conv: &mut [f64]) {
        let (s, eta) = (z[0], &z[1..]);
        let (sd, etad) = (zd[0], &zd[1..]);
        let mut work = self.work.0.lock().unwrap_or_else(|p| p.into_inner());
        let [wq, wv] = &mut *work;
        if wq[0].len() != self.n_q {
            *wq = self.q.work();
            *wv = self.v.work();
        }
        self.q.eval(s, wq);
        self.v.eval(s, wv);
        // V's derivative o, entry (i, j), is wv[o][j n_q + i]
        let n = self.n_q;
        for i in 0..n {
            let (mut val, mut d1, mut d2, mut d1e) =
                (self.q0[i] + wq[0][i], wq[1][i], wq[2][i], 0.0);
            for j in 0..self.r {
                let c = j * n + i;
                val += wv[0][c] * eta[j];
                d1 += wv[1][c] * eta[j];
                d2 += wv[2][c] * eta[j];
                d1e += wv[1][c] * etad[j];
                gz[(i, 1 + j)] = wv[0][c];
            }
            q[i] = val;
            gz[(i, 0)] = d1;
            conv[i] = d2 * sd * sd + 2.0 * d1e * sd;
        }
    }
}

/// An interpolated basis from a sweep along the degree of freedom `s_dof`
/// (its values are the knots s; they must increase): the configurations are
/// the sweep's equilibria and V(s) interpolates the mode shapes `modes`
/// (0-based indices, e.g. 1..7 for the thesis's MSI-7: mode 0 is the motion
/// along s, which Q'(s) carries). With `mass_normalize`, MSI applies (6.26)
/// (the sweep must keep mass matrices).
pub fn interpolated_basis_from_sweep(
    q0: Vec<f64>,
    s_dof: usize,
    points: &[flexmb_linearize::SweepPoint],
    modes: std::ops::Range<usize>,
    method: SubspaceInterpolation,
    mass_normalize: bool,
) -> Result<InterpolatedBasis, ReductionError> {
    if s_dof >= q0.len() {
        return Err(ReductionError::Invalid(format!(
            "configuration coordinate index {s_dof} ≥ n_q = {}",
            q0.len()
        )));
    }
    let s: Vec<f64> = points.iter().map(|p| p.q[s_dof]).collect();
    let qs: Vec<Vec<f64>> = points.iter().map(|p| p.q.clone()).collect();
    let mut vecs = Vec::with_capacity(points.len());
    let mut masses = Vec::with_capacity(points.len());
    for p in points {
        let v = p.modes.as_ref().ok_or_else(|| {
            ReductionError::Invalid("sweep points carry no mode shapes (keep_vectors)".into())
        })?;
        if v.ncols() < modes.end {
            return Err(ReductionError::Invalid(format!(
                "a sweep point has {} modes, {} needed",
                v.ncols(),
                modes.end
            )));
        }
        vecs.push(Mat::from_fn(v.nrows(), modes.len(), |i, j| {
            v[(i, modes.start + j)]
        }));
        if mass_normalize {
            masses.push(p.mass.clone().ok_or_else(|| {
                ReductionError::Invalid("mass normalization needs the sweep's mass matrices".into())
            })?);
        }
    }
    InterpolatedBasis::new(
        q0,
        s,
        &qs,
        &vecs,
        mass_normalize.then_some(masses.as_slice()),
        method,
    )
}
