//! The interpolated basis over two configuration coordinates (beyond the
//! thesis: its recommendation 3, issue 18): q = Q(s1, s2) + V(s1, s2)η + q0,
//! z = (s1, s2, η), with Q and V bicubic splines ([`crate::BicubicSpline`])
//! through the reference configurations on a tensor grid and V from modal
//! subspace interpolation over the grid
//! ([`crate::modal_subspace_interpolation_grid`]). It is (6.23) with the
//! arc length s replaced by two coordinates; its derivatives are (6.24)
//! and (F.6) with the partial derivatives along s1 and s2.

use crate::bicubic::{order_index, BicubicSpline, ORDERS};
use crate::msi::modal_subspace_interpolation_grid;
use crate::{Basis, ReductionError};
use faer::Mat;

/// The data a grid basis is built from.
#[derive(Clone, Debug)]
pub struct GridKnots {
    /// The first configuration coordinate at the grid lines.
    pub s1: Vec<f64>,
    /// The second configuration coordinate at the grid lines.
    pub s2: Vec<f64>,
    /// The DOFs at the grid points, point (i, j) at index i + n1 j.
    pub qs: Vec<Vec<f64>>,
    /// The interpolation-ready base vectors there (r columns of length n_q).
    pub w: Vec<Vec<Vec<f64>>>,
    /// The equilibrium surface's tangents ∂q/∂s1 and ∂q/∂s2 at the grid
    /// points ([`crate::equilibrium_tangents`]), when known: Q is then the
    /// bicubic Hermite interpolant ([`BicubicSpline::hermite`]), whose Q,s
    /// at a grid point is the tangent itself, else the natural bicubic
    /// spline through the configurations.
    pub tangents: Option<Vec<[Vec<f64>; 2]>>,
}

/// An interpolated basis over a tensor grid of two configuration
/// coordinates, z = (s1, s2, η).
#[derive(Clone, Debug)]
pub struct GridBasis {
    q0: Vec<f64>,
    knots: GridKnots,
    q: BicubicSpline,
    v: BicubicSpline,
    n_q: usize,
    r: usize,
    /// The splines' work arrays (Q's and V's derivatives by [`ORDERS`]) for
    /// [`Basis::eval`], so that the equations of motion do not allocate.
    work: GridWork,
}

/// Work arrays behind an uncontended mutex (each model evaluates in one
/// thread), so the basis stays `Sync`; a clone starts with empty arrays.
#[derive(Debug, Default)]
struct GridWork(std::sync::Mutex<[Vec<Vec<f64>>; 2]>);

impl Clone for GridWork {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// The first `count` partial derivatives ([`ORDERS`]) of Q and of V at (s1,
/// s2): V's derivative o, entry (i, j), is `v[o][j n_q + i]`.
struct Derivatives {
    q: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
}

impl GridBasis {
    /// From the grid lines `s1` (n1) and `s2` (n2), the DOFs `qs` of the
    /// reference configurations at the grid points (index i + n1 j) and the
    /// r retained eigenvectors `vecs` there (n_q × r each). V is obtained
    /// by MSI over the grid, mass-normalized (6.26) with `mass` when given.
    /// Q is the natural bicubic spline through the configurations; see
    /// [`Self::with_tangents`] for the more accurate form.
    pub fn new(
        q0: Vec<f64>,
        s1: Vec<f64>,
        s2: Vec<f64>,
        qs: &[Vec<f64>],
        vecs: &[Mat<f64>],
        mass: Option<&[Mat<f64>]>,
    ) -> Result<Self, ReductionError> {
        Self::build(q0, [s1, s2], qs, None, vecs, mass)
    }

    /// As [`Self::new`], with the equilibrium surface's tangents
    /// ∂q/∂s1, ∂q/∂s2 at each grid point ([`crate::equilibrium_tangents`]
    /// of the held equilibrium there): Q is the bicubic Hermite
    /// interpolant, so that at the grid points Q,s1 and Q,s2 are the
    /// tangents themselves. Measured on the chapter-7 mechanism (5 × 5
    /// grid): the reduced ω1, ω2 at the grid points within 5e-5 of the
    /// unreduced ones, where the natural spline's derivatives put them 33
    /// and 27 times too high (their small components in directions 10⁴
    /// times stiffer than the mechanism's motion).
    pub fn with_tangents(
        q0: Vec<f64>,
        s1: Vec<f64>,
        s2: Vec<f64>,
        qs: &[Vec<f64>],
        tangents: &[[Vec<f64>; 2]],
        vecs: &[Mat<f64>],
        mass: Option<&[Mat<f64>]>,
    ) -> Result<Self, ReductionError> {
        Self::build(q0, [s1, s2], qs, Some(tangents), vecs, mass)
    }

    fn build(
        q0: Vec<f64>,
        [s1, s2]: [Vec<f64>; 2],
        qs: &[Vec<f64>],
        tangents: Option<&[[Vec<f64>; 2]]>,
        vecs: &[Mat<f64>],
        mass: Option<&[Mat<f64>]>,
    ) -> Result<Self, ReductionError> {
        let (n1, n2, n_q) = (s1.len(), s2.len(), q0.len());
        let points = n1 * n2;
        if qs.len() != points
            || vecs.len() != points
            || mass.is_some_and(|m| m.len() != points)
            || tangents.is_some_and(|t| t.len() != points)
        {
            return Err(ReductionError::Invalid(format!(
                "grid basis: {n1} × {n2} grid points, but {} configurations, {} sets of \
                 eigenvectors, {} mass matrices and {} pairs of tangents",
                qs.len(),
                vecs.len(),
                mass.map_or(0, |m| m.len()),
                tangents.map_or(0, |t| t.len())
            )));
        }
        let r = vecs.first().map_or(0, |v| v.ncols());
        if vecs.iter().any(|v| v.nrows() != n_q || v.ncols() != r) {
            return Err(ReductionError::Invalid(
                "grid basis: eigenvectors of inconsistent sizes".into(),
            ));
        }
        let w = modal_subspace_interpolation_grid(vecs, n1, n2, mass);
        let w = w
            .iter()
            .map(|m| (0..r).map(|j| m.col_as_slice(j).to_vec()).collect())
            .collect();
        Self::from_knots(
            q0,
            GridKnots {
                s1,
                s2,
                qs: qs.to_vec(),
                w,
                tangents: tangents.map(<[_]>::to_vec),
            },
        )
    }

    /// From the knot data directly (the base vectors already
    /// interpolation-ready).
    pub fn from_knots(q0: Vec<f64>, knots: GridKnots) -> Result<Self, ReductionError> {
        let n_q = q0.len();
        let r = knots.w.first().map_or(0, |v| v.len());
        let points = knots.s1.len() * knots.s2.len();
        if knots.qs.len() != points
            || knots.w.len() != points
            || knots.qs.iter().any(|q| q.len() != n_q)
            || knots
                .w
                .iter()
                .any(|v| v.len() != r || v.iter().any(|c| c.len() != n_q))
            || knots
                .tangents
                .as_ref()
                .is_some_and(|t| t.len() != points || t.iter().flatten().any(|c| c.len() != n_q))
        {
            return Err(ReductionError::Invalid(
                "grid basis: inconsistent sizes of grid, configurations or base vectors".into(),
            ));
        }
        if knots
            .qs
            .iter()
            .chain(knots.w.iter().flatten())
            .chain(knots.tangents.iter().flatten().flatten())
            .flatten()
            .any(|v| !v.is_finite())
        {
            return Err(ReductionError::Invalid(
                "grid basis: a configuration, tangent or base vector is not finite".into(),
            ));
        }
        let dq: Vec<Vec<f64>> = knots
            .qs
            .iter()
            .map(|q| q.iter().zip(&q0).map(|(a, b)| a - b).collect())
            .collect();
        let flat: Vec<Vec<f64>> = knots.w.iter().map(|m| m.concat()).collect();
        let (s1, s2) = (knots.s1.clone(), knots.s2.clone());
        let q = match &knots.tangents {
            Some(t) => {
                let along = |k: usize| t.iter().map(|p| p[k].clone()).collect();
                BicubicSpline::hermite(s1, s2, dq, along(0), along(1))?
            }
            None => BicubicSpline::new(s1, s2, dq)?,
        };
        Ok(Self {
            q,
            v: BicubicSpline::new(knots.s1.clone(), knots.s2.clone(), flat)?,
            knots,
            q0,
            n_q,
            r,
            work: GridWork::default(),
        })
    }

    /// The offset q0.
    pub fn q0(&self) -> &[f64] {
        &self.q0
    }

    /// The knot data.
    pub fn knots(&self) -> &GridKnots {
        &self.knots
    }

    /// The number of interpolated base vectors r (n_z = 2 + r).
    pub fn r(&self) -> usize {
        self.r
    }

    /// The ranges of s1 and s2 covered by the grid.
    pub fn range(&self) -> [(f64, f64); 2] {
        let (a, b) = self.q.knots();
        [(a[0], a[a.len() - 1]), (b[0], b[b.len() - 1])]
    }

    /// Q's and V's partial derivatives up to `count` of [`ORDERS`] at z.
    fn derivatives(&self, z: &[f64], count: usize) -> Derivatives {
        let (mut q, mut v) = (self.q.work(), self.v.work());
        self.q.eval(z[0], z[1], count, &mut q);
        self.v.eval(z[0], z[1], count, &mut v);
        Derivatives { q, v }
    }
}

impl Derivatives {
    /// Entry i of the partial derivative `o` (an index of [`ORDERS`]) of
    /// G's (s1, s2) part at η: Q,o + V,o η.
    fn g(&self, o: usize, i: usize, n_q: usize, eta: &[f64]) -> f64 {
        let mut g = self.q[o][i];
        for (j, e) in eta.iter().enumerate() {
            g += self.v[o][j * n_q + i] * e;
        }
        g
    }
    /// Entry i of Σⱼ V_j,o cⱼ.
    fn vc(&self, o: usize, i: usize, n_q: usize, c: &[f64]) -> f64 {
        c.iter()
            .enumerate()
            .map(|(j, cj)| self.v[o][j * n_q + i] * cj)
            .sum()
    }
}

/// The index in [`ORDERS`] of ∂/∂s_a ∂/∂s_b (a, b ∈ {0, 1}), and of a third
/// one ∂/∂s_c.
fn second(a: usize, b: usize) -> usize {
    order_index(2 - a - b, a + b)
}
fn third(a: usize, b: usize, c: usize) -> usize {
    order_index(3 - a - b - c, a + b + c)
}

impl Basis for GridBasis {
    fn n_z(&self) -> usize {
        2 + self.r
    }
    fn n_q(&self) -> usize {
        self.n_q
    }
    /// (6.23)–(6.24) in two coordinates: q = Q + Vη + q0,
    /// G,z = [Q,1 + V,1η, Q,2 + V,2η, V], and
    /// (G,zz ż)ż = Σ_ab (Q,ab + V,abη) ṡ_a ṡ_b + 2 Σ_a V,a η̇ ṡ_a.
    fn eval(&self, z: &[f64], zd: &[f64], q: &mut [f64], gz: &mut Mat<f64>, conv: &mut [f64]) {
        let (eta, etad) = (&z[2..], &zd[2..]);
        let sd = [zd[0], zd[1]];
        let mut work = self.work.0.lock().unwrap_or_else(|p| p.into_inner());
        let [wq, wv] = &mut *work;
        if wq.len() != ORDERS.len() || wq[0].len() != self.n_q {
            *wq = self.q.work();
            *wv = self.v.work();
        }
        self.q.eval(z[0], z[1], 6, wq);
        self.v.eval(z[0], z[1], 6, wv);
        let n = self.n_q;
        // the derivative orders of ORDERS: 1, 2 first; 3, 4, 5 second
        let (d11, d12, d22) = (3, 4, 5);
        for i in 0..n {
            let mut g = [0.0; 6];
            let mut ve = [0.0; 3];
            for (o, go) in g.iter_mut().enumerate() {
                *go = wq[o][i];
            }
            for j in 0..self.r {
                let c = j * n + i;
                for (o, go) in g.iter_mut().enumerate() {
                    *go += wv[o][c] * eta[j];
                }
                ve[1] += wv[1][c] * etad[j];
                ve[2] += wv[2][c] * etad[j];
                gz[(i, 2 + j)] = wv[0][c];
            }
            q[i] = self.q0[i] + g[0];
            gz[(i, 0)] = g[1];
            gz[(i, 1)] = g[2];
            conv[i] = g[d11] * sd[0] * sd[0]
                + 2.0 * g[d12] * sd[0] * sd[1]
                + g[d22] * sd[1] * sd[1]
                + 2.0 * (ve[1] * sd[0] + ve[2] * sd[1]);
        }
    }
    /// Σᵢ rᵢ Gᵢ,zz: (s_a, s_b) rᵀ(Q,ab + V,abη), (s_a, η_j) rᵀV_j,a,
    /// (η, η) zero.
    fn hessian_contraction(&self, z: &[f64], r: &[f64]) -> Mat<f64> {
        let eta = &z[2..];
        let d = self.derivatives(z, 6);
        let n = self.n_q;
        let mut h = Mat::zeros(2 + self.r, 2 + self.r);
        for a in 0..2 {
            for b in 0..2 {
                h[(a, b)] = (0..n).map(|i| r[i] * d.g(second(a, b), i, n, eta)).sum();
            }
            for j in 0..self.r {
                let v: f64 = (0..n).map(|i| r[i] * d.v[1 + a][j * n + i]).sum();
                h[(a, 2 + j)] = v;
                h[(2 + j, a)] = v;
            }
        }
        h
    }
    /// Column s_a: Σ_b v_b (Q,ab + V,abη) + Σⱼ v_(2+j) V_j,a; column η_j:
    /// Σ_b v_b V_j,b.
    fn second_derivative_matrix(&self, z: &[f64], v: &[f64]) -> Mat<f64> {
        let eta = &z[2..];
        let d = self.derivatives(z, 6);
        let n = self.n_q;
        Mat::from_fn(n, 2 + self.r, |i, k| {
            if k < 2 {
                (0..2)
                    .map(|b| v[b] * d.g(second(k, b), i, n, eta))
                    .sum::<f64>()
                    + d.vc(1 + k, i, n, &v[2..])
            } else {
                let c = (k - 2) * n + i;
                v[0] * d.v[1][c] + v[1] * d.v[2][c]
            }
        })
    }
    /// ∂/∂z_k of (G,zz ż)ż: column s_c: Σ_ab (Q,abc + V,abcη) ṡ_a ṡ_b
    /// + 2 Σ_a V,ac η̇ ṡ_a; column η_j: Σ_ab V_j,ab ṡ_a ṡ_b.
    fn third_derivative_matrix(&self, z: &[f64], zd: &[f64]) -> Mat<f64> {
        let eta = &z[2..];
        let (sd, etad) = ([zd[0], zd[1]], &zd[2..]);
        let d = self.derivatives(z, 10);
        let n = self.n_q;
        Mat::from_fn(n, 2 + self.r, |i, k| {
            let mut out = 0.0;
            for a in 0..2 {
                for b in 0..2 {
                    out += sd[a]
                        * sd[b]
                        * if k < 2 {
                            d.g(third(a, b, k), i, n, eta)
                        } else {
                            d.v[second(a, b)][(k - 2) * n + i]
                        };
                }
                if k < 2 {
                    out += 2.0 * sd[a] * d.vc(second(a, k), i, n, etad);
                }
            }
            out
        })
    }
    /// (s1, s2, 0) at the grid point whose configuration is closest to q0.
    fn z_reference(&self) -> Vec<f64> {
        let k = crate::basis::nearest_configuration(&self.knots.qs, &self.q0);
        let n1 = self.knots.s1.len();
        let mut z = vec![0.0; 2 + self.r];
        z[0] = self.knots.s1[k % n1];
        z[1] = self.knots.s2[k / n1];
        z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{largest_principal_angle, InterpolatedBasis, SubspaceInterpolation};

    const N_Q: usize = 6;
    const R: usize = 2;

    /// A smooth synthetic field over the grid: configurations, eigenvector
    /// pairs that turn with (s1, s2), and SPD mass matrices.
    fn config(a: f64, b: f64) -> Vec<f64> {
        (0..N_Q)
            .map(|i| (i as f64 + 1.0) * (0.3 * a + 0.2 * i as f64).sin() + a * b * b)
            .collect()
    }
    fn vectors(a: f64, b: f64) -> Mat<f64> {
        Mat::from_fn(N_Q, R, |i, j| {
            ((i + 2 * j) as f64 * 0.7 + a * (1.0 + j as f64) - 0.5 * b * i as f64).cos()
        })
    }
    fn mass(a: f64, b: f64) -> Mat<f64> {
        Mat::from_fn(N_Q, N_Q, |i, j| {
            if i == j {
                2.0 + 0.3 * (a + i as f64).sin() + 0.1 * b
            } else {
                0.05 / (1.0 + (i as f64 - j as f64).abs())
            }
        })
    }
    fn knots() -> (Vec<f64>, Vec<f64>) {
        (vec![0.0, 0.3, 0.5, 0.9, 1.2], vec![-0.2, 0.1, 0.25, 0.6])
    }
    fn build(dependent_on_s2: bool) -> GridBasis {
        let (s1, s2) = knots();
        let at = |a: f64, b: f64| if dependent_on_s2 { (a, b) } else { (a, 0.0) };
        let pts: Vec<(f64, f64)> = s2
            .iter()
            .flat_map(|b| s1.iter().map(move |a| at(*a, *b)))
            .collect();
        let qs: Vec<Vec<f64>> = pts.iter().map(|(a, b)| config(*a, *b)).collect();
        let vs: Vec<Mat<f64>> = pts.iter().map(|(a, b)| vectors(*a, *b)).collect();
        let ms: Vec<Mat<f64>> = pts.iter().map(|(a, b)| mass(*a, *b)).collect();
        GridBasis::new(config(0.0, 0.0), s1, s2, &qs, &vs, Some(&ms)).unwrap()
    }
    /// ∂config/∂a and ∂config/∂b.
    fn tangents(a: f64, b: f64) -> [Vec<f64>; 2] {
        [
            (0..N_Q)
                .map(|i| (i as f64 + 1.0) * 0.3 * (0.3 * a + 0.2 * i as f64).cos() + b * b)
                .collect(),
            (0..N_Q).map(|_| 2.0 * a * b).collect(),
        ]
    }
    /// [`build`]`(true)` with the exact tangents (the Hermite form of Q).
    fn build_hermite() -> GridBasis {
        let (s1, s2) = knots();
        let pts: Vec<(f64, f64)> = s2
            .iter()
            .flat_map(|b| s1.iter().map(move |a| (*a, *b)))
            .collect();
        let qs: Vec<Vec<f64>> = pts.iter().map(|(a, b)| config(*a, *b)).collect();
        let ts: Vec<[Vec<f64>; 2]> = pts.iter().map(|(a, b)| tangents(*a, *b)).collect();
        let vs: Vec<Mat<f64>> = pts.iter().map(|(a, b)| vectors(*a, *b)).collect();
        let ms: Vec<Mat<f64>> = pts.iter().map(|(a, b)| mass(*a, *b)).collect();
        GridBasis::with_tangents(config(0.0, 0.0), s1, s2, &qs, &ts, &vs, Some(&ms)).unwrap()
    }
    fn eval(b: &GridBasis, z: &[f64], zd: &[f64]) -> (Vec<f64>, Mat<f64>, Vec<f64>) {
        let (mut q, mut gz, mut conv) = (vec![0.0; N_Q], Mat::zeros(N_Q, 2 + R), vec![0.0; N_Q]);
        b.eval(z, zd, &mut q, &mut gz, &mut conv);
        (q, gz, conv)
    }

    #[test]
    fn exact_at_the_grid_points() {
        let b = build(true);
        let (s1, s2) = knots();
        for (j, y) in s2.iter().enumerate() {
            for (i, x) in s1.iter().enumerate() {
                let (q, gz, _) = eval(&b, &[*x, *y, 0.0, 0.0], &[0.0; 4]);
                let e = config(*x, *y);
                assert!(q.iter().zip(&e).all(|(a, b)| (a - b).abs() < 1e-13));
                let v = Mat::from_fn(N_Q, R, |r, c| gz[(r, 2 + c)]);
                let angle = largest_principal_angle(&v, &vectors(*x, *y)).unwrap();
                assert!(angle < 1e-10, "({i}, {j}): principal angle {angle}");
                // mass-normalized (6.26)
                let m = mass(*x, *y);
                for c in 0..R {
                    let mv = &m * v.col(c);
                    let n: f64 = (0..N_Q).map(|r| v[(r, c)] * mv[r]).sum();
                    assert!((n - 1.0).abs() < 1e-12);
                }
            }
        }
    }

    /// With the tangents, Q,s1 and Q,s2 at the grid points are the
    /// tangents, and Q between them is closer to the surface than the
    /// natural spline's.
    #[test]
    fn with_tangents_q_takes_them_at_the_grid_points() {
        let (b, natural) = (build_hermite(), build(true));
        let (s1, s2) = knots();
        for y in &s2 {
            for x in &s1 {
                let (q, gz, _) = eval(&b, &[*x, *y, 0.0, 0.0], &[0.0; 4]);
                let (e, t) = (config(*x, *y), tangents(*x, *y));
                for i in 0..N_Q {
                    assert!((q[i] - e[i]).abs() < 1e-13);
                    assert!((gz[(i, 0)] - t[0][i]).abs() < 1e-12, "Q,s1 at ({x}, {y})");
                    assert!((gz[(i, 1)] - t[1][i]).abs() < 1e-12, "Q,s2 at ({x}, {y})");
                }
            }
        }
        let worst = |b: &GridBasis| {
            let mut w = 0.0f64;
            for &(x, y) in &[(0.15, -0.05), (0.4, 0.17), (0.7, 0.4), (1.05, 0.2)] {
                let (q, _, _) = eval(b, &[x, y, 0.0, 0.0], &[0.0; 4]);
                let e = config(x, y);
                w = q.iter().zip(&e).fold(w, |m, (a, b)| m.max((a - b).abs()));
            }
            w
        };
        let (h, n) = (worst(&b), worst(&natural));
        assert!(h < 0.2 * n, "Hermite {h:.2e} against natural {n:.2e}");
        // a wrong count of tangents is refused
        let (s1, s2) = knots();
        let qs = vec![config(0.0, 0.0); 20];
        let vs = vec![vectors(0.0, 0.0); 20];
        let ts = vec![tangents(0.0, 0.0); 19];
        let e = GridBasis::with_tangents(config(0.0, 0.0), s1, s2, &qs, &ts, &vs, None);
        assert!(e.unwrap_err().to_string().contains("19 pairs of tangents"));
    }

    #[test]
    fn reproduces_the_one_parameter_basis_when_the_data_lie_along_rows() {
        let b = build(false);
        let (s1, _) = knots();
        let one = InterpolatedBasis::new(
            config(0.0, 0.0),
            s1.clone(),
            &s1.iter().map(|a| config(*a, 0.0)).collect::<Vec<_>>(),
            &s1.iter().map(|a| vectors(*a, 0.0)).collect::<Vec<_>>(),
            Some(&s1.iter().map(|a| mass(*a, 0.0)).collect::<Vec<_>>()),
            SubspaceInterpolation::Msi,
        )
        .unwrap();
        for (z, zd) in [
            ([0.2, 0.0, 0.3, -0.1], [0.7, 0.0, 0.2, 0.4]),
            ([1.0, 0.4, -0.2, 0.5], [-0.3, 0.0, 1.1, -0.6]),
        ] {
            let (q, gz, conv) = eval(&b, &z, &zd);
            let z1 = [z[0], z[2], z[3]];
            let zd1 = [zd[0], zd[2], zd[3]];
            let (mut q1, mut g1, mut c1) = (vec![0.0; N_Q], Mat::zeros(N_Q, 1 + R), vec![0.0; N_Q]);
            one.eval(&z1, &zd1, &mut q1, &mut g1, &mut c1);
            for i in 0..N_Q {
                assert!((q[i] - q1[i]).abs() < 1e-12);
                assert!((conv[i] - c1[i]).abs() < 1e-10);
                assert!((gz[(i, 0)] - g1[(i, 0)]).abs() < 1e-11);
                assert!(gz[(i, 1)].abs() < 1e-11, "G,s2 = {}", gz[(i, 1)]);
                for j in 0..R {
                    assert!((gz[(i, 2 + j)] - g1[(i, 1 + j)]).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        derivatives_of_match_central_differences(&build(true));
        derivatives_of_match_central_differences(&build_hermite());
    }

    fn derivatives_of_match_central_differences(b: &GridBasis) {
        let h = 1e-6;
        let n_z = 2 + R;
        for (z, zd) in [
            (vec![0.4, 0.2, 0.3, -0.2], vec![0.7, -0.5, 0.2, 0.4]),
            (vec![1.1, -0.1, -0.6, 0.5], vec![-0.3, 0.9, 1.1, -0.6]),
        ] {
            let (_, gz, conv) = eval(b, &z, &zd);
            let r: Vec<f64> = (0..N_Q).map(|i| 0.3 + (i as f64).sin()).collect();
            let hc = b.hessian_contraction(&z, &r);
            let sdm = b.second_derivative_matrix(&z, &zd);
            let tdm = b.third_derivative_matrix(&z, &zd);
            // (G,zz ż)ż = d/dε G,z(z + ε ż) ż at ε = 0
            let along = |e: f64| {
                let ze: Vec<f64> = z.iter().zip(&zd).map(|(a, b)| a + e * b).collect();
                let (_, g, _) = eval(b, &ze, &zd);
                (0..N_Q)
                    .map(|i| (0..n_z).map(|k| g[(i, k)] * zd[k]).sum::<f64>())
                    .collect::<Vec<f64>>()
            };
            let (p, m) = (along(h), along(-h));
            for i in 0..N_Q {
                let fd = (p[i] - m[i]) / (2.0 * h);
                assert!(
                    (fd - conv[i]).abs() < 1e-6 * (1.0 + conv[i].abs()),
                    "conv {i}"
                );
            }
            for k in 0..n_z {
                let mut zp = z.clone();
                let mut zm = z.clone();
                zp[k] += h;
                zm[k] -= h;
                let (qp, gp, cp) = eval(b, &zp, &zd);
                let (qm, gm, cm) = eval(b, &zm, &zd);
                for i in 0..N_Q {
                    // G,z against differences of q
                    let fd = (qp[i] - qm[i]) / (2.0 * h);
                    assert!(
                        (fd - gz[(i, k)]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "G,z ({i}, {k})"
                    );
                    // the second-derivative matrix: d/dz_k (G,z ż)
                    let dp: f64 = (0..n_z).map(|c| gp[(i, c)] * zd[c]).sum();
                    let dm: f64 = (0..n_z).map(|c| gm[(i, c)] * zd[c]).sum();
                    let fd = (dp - dm) / (2.0 * h);
                    assert!(
                        (fd - sdm[(i, k)]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "G,zz ż ({i}, {k})"
                    );
                    // the third-derivative matrix: d/dz_k of the convective term
                    let fd = (cp[i] - cm[i]) / (2.0 * h);
                    assert!(
                        (fd - tdm[(i, k)]).abs() < 1e-5 * (1.0 + fd.abs()),
                        "(G,zzz ż)ż ({i}, {k}): {fd} against {}",
                        tdm[(i, k)]
                    );
                }
                // G,zzᵀ r: d/dz_k (G,zᵀ r)
                for c in 0..n_z {
                    let fp: f64 = (0..N_Q).map(|i| gp[(i, c)] * r[i]).sum();
                    let fm: f64 = (0..N_Q).map(|i| gm[(i, c)] * r[i]).sum();
                    let fd = (fp - fm) / (2.0 * h);
                    assert!(
                        (fd - hc[(c, k)]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "G,zzᵀr ({c}, {k})"
                    );
                }
            }
        }
    }

    #[test]
    fn the_reference_is_the_grid_point_nearest_q0_and_bad_input_is_refused() {
        let b = build(true);
        // q0 = Q(0, s2) for every s2 (the data's s2 term vanishes at s1 = 0):
        // the first of the equally near grid points
        assert_eq!(b.z_reference(), vec![0.0, -0.2, 0.0, 0.0]);
        let (s1, s2) = knots();
        let qs = vec![vec![0.0; N_Q]; 3];
        let vs = vec![Mat::zeros(N_Q, R); 3];
        let e = GridBasis::new(vec![0.0; N_Q], s1.clone(), s2.clone(), &qs, &vs, None);
        assert!(matches!(e, Err(ReductionError::Invalid(m)) if m.contains("5 × 4")));
        let n = s1.len() * s2.len();
        let mut qs = vec![vec![0.0; N_Q]; n];
        qs[3][1] = f64::NAN;
        let vs: Vec<Mat<f64>> = (0..n).map(|_| vectors(0.1, 0.2)).collect();
        assert!(GridBasis::new(vec![0.0; N_Q], s1, s2, &qs, &vs, None).is_err());
    }
}
