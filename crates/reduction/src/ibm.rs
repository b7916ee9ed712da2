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

/// An interpolated basis q = Q(s) + V(s)η + q0, z = (s, η).
#[derive(Clone, Debug)]
pub struct InterpolatedBasis {
    q0: Vec<f64>,
    q: CubicSpline,
    v: CubicSpline,
    n_q: usize,
    r: usize,
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
        let dq: Vec<Vec<f64>> = qs
            .iter()
            .map(|q| q.iter().zip(&q0).map(|(a, b)| a - b).collect())
            .collect();
        let flat: Vec<Vec<f64>> = w
            .iter()
            .map(|m| (0..r).flat_map(|j| m.col_as_slice(j).to_vec()).collect())
            .collect();
        Ok(Self {
            q: CubicSpline::new(s.clone(), dq)?,
            v: CubicSpline::new(s, flat)?,
            q0,
            n_q,
            r,
        })
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
    /// (6.23)–(6.24): q = Q + Vη + q0, G,z = [Q' + V'η, V],
    /// (G,zz ż)ż = (Q'' + V''η) ṡ² + 2 V' η̇ ṡ.
    fn eval(&self, z: &[f64], zd: &[f64], q: &mut [f64], gz: &mut Mat<f64>, conv: &mut [f64]) {
        let (s, eta) = (z[0], &z[1..]);
        let (sd, etad) = (zd[0], &zd[1..]);
        let mut wq = self.q.work();
        self.q.eval(s, &mut wq);
        let v = self.v_and_derivatives(s);
        for i in 0..self.n_q {
            let (mut val, mut d1, mut d2, mut d1e) =
                (self.q0[i] + wq[0][i], wq[1][i], wq[2][i], 0.0);
            for j in 0..self.r {
                val += v[0][(i, j)] * eta[j];
                d1 += v[1][(i, j)] * eta[j];
                d2 += v[2][(i, j)] * eta[j];
                d1e += v[1][(i, j)] * etad[j];
                gz[(i, 1 + j)] = v[0][(i, j)];
            }
            q[i] = val;
            gz[(i, 0)] = d1;
            conv[i] = d2 * sd * sd + 2.0 * d1e * sd;
        }
    }
}
