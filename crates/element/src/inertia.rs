//! Co-rotational inertia of one- and two-node elements: T = ½ ẋᵀ Bᵀ M̄ B ẋ
//! (thesis (2.34), (3.30)), the mass matrix M = \[B; I\]ᵀ M̄ \[B; I\] (3.31) and the
//! inertia forces M ẍ + h with h of (2.40a)/(3.34b).
//!
//! One code path serves the spatial beam (M̄ its 12×12 consistent mass), the
//! superelement (M̄ from an FE model, with mode amplitudes η̄), and the rigid body
//! (one node, M̄ from mass, centre offset and inertia tensor). The planar
//! counterpart serves the planar beam.
//!
//! The inertia force is written once over a [`Real`] scalar:
//! F = Ḃᵀ p + Bᵀ M̄ ẇ − B*ᵀ p with w = (Bẋ, η̄̇), ẇ = (Bẍ + Ḃẋ, η̄̈), p = M̄ w,
//! where Ḃ comes from one dual pass along ẋ (Appendix B) and B*ᵀp = ∂(pᵀBẋ)/∂x
//! (Appendix C) from one dual pass over the orientation coordinates. Evaluated
//! with `f64` it is the force; with dual numbers its exact derivatives with
//! respect to x, ẋ and ẍ follow.

use flexmb_dual::{Dual, Mat3, Real, Vec3};
use flexmb_rotation::generic::{average, hemisphere_sign, lambda_bar_mat, lambda_mat, rotation};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Largest number of mode amplitudes η̄ a superelement may carry.
pub const MAX_MODES: usize = 24;
/// Largest length of the generalized velocity w = (v̄, η̄̇).
pub(crate) const MAX_W: usize = 12 + MAX_MODES;

/// How absolute nodal velocities are expressed in the co-rotational frame
/// (thesis §2.3.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum VelocityTransform {
    /// B1 (2.24): everything in the frame attached to node p.
    B1,
    /// B2 (2.31): everything in the average frame λr (2.29).
    B2,
    /// B3 (2.32)/(3.29): translations in the average frame, angular velocities
    /// in their own node frames (the thesis's recommendation, the default).
    #[default]
    B3,
}

/// The blocks of B for spatial nodes: `ft` maps ṙ, `g[i]` maps λ̇ of node i.
#[derive(Clone, Copy, Debug)]
struct SpatialBlocks<T> {
    ft: Mat3<T>,
    g: [[[T; 4]; 3]; 2],
}

/// Configuration of spatial co-rotational inertia (1 or 2 nodes, each with a
/// position and Euler parameters: local layout (r, λ) per node, then η̄).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SpatialInertia {
    pub nodes: usize,
    pub variant: VelocityTransform,
    /// R0ᵀ (rows are the local axes in the global frame).
    pub r0t: [[f64; 3]; 3],
    pub mbar: DMatrix<f64>,
    /// Ū with M̄ = ŪᵀŪ (row-major, upper triangular); `None` if M̄ is indefinite.
    pub ubar: Option<Vec<f64>>,
}

/// An upper-triangular U with A = UᵀU (row-major n × n) of a symmetric positive
/// semi-definite A (row-major). `None` if A is indefinite.
///
/// The coordinates of an element's mass matrix have their own units (m/s,
/// rad/s, the rad/(m s) of a warping rate), so its diagonal spans many
/// decades: a 10 × 0.5 mm sheet beam's warping inertia ρI_w l is 7e-14 of its
/// translational mass, whatever its length. The pivots are therefore judged
/// in the Jacobi-scaled matrix D⁻¹AD⁻¹ (D² = diag A, unit diagonal): a zero
/// diagonal entry, or a pivot below 1e-13 of its own diagonal entry, is a
/// massless direction (a zero row), and U = Û D. Where the scaled matrix is
/// not found semi-definite (a diagonal entry at rounding level with couplings
/// of the same size), the pivots are judged against the largest diagonal
/// entry instead ([`psd_factor_unscaled`]).
pub(crate) fn psd_factor(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let scale = (0..n).fold(0.0f64, |m, i| m.max(a[i * n + i].abs()));
    // a NaN diagonal entry is refused too
    if (0..n).any(|i| a[i * n + i].is_nan() || a[i * n + i] < -1e-13 * scale) {
        return None;
    }
    let d: Vec<f64> = (0..n).map(|i| a[i * n + i].max(0.0).sqrt()).collect();
    // off-diagonal entries of a massless coordinate must vanish (as in the
    // unscaled factor); the scaled matrix leaves them out
    let scaled: Vec<f64> = (0..n * n)
        .map(|k| {
            let (i, j) = (k / n, k % n);
            if d[i] > 0.0 && d[j] > 0.0 {
                a[k] / (d[i] * d[j])
            } else {
                0.0
            }
        })
        .collect();
    let massless_rows_vanish = (0..n * n).all(|k| {
        let (i, j) = (k / n, k % n);
        (d[i] > 0.0 && d[j] > 0.0) || a[k].abs() <= 1e-6 * scale
    });
    if massless_rows_vanish {
        if let Some(mut u) = psd_factor_unscaled(&scaled, n) {
            for k in 0..n * n {
                u[k] *= d[k % n];
            }
            return Some(u);
        }
    }
    psd_factor_unscaled(a, n)
}

/// [`psd_factor`] with every pivot judged against the largest diagonal
/// entry: Cholesky, where a pivot below 1e-13 of it gives a zero row (a
/// massless direction). `None` if A is indefinite.
fn psd_factor_unscaled(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let scale = (0..n).fold(0.0f64, |m, i| m.max(a[i * n + i].abs()));
    let tol = 1e-13 * scale;
    let mut u = vec![0.0; n * n];
    for k in 0..n {
        let d = a[k * n + k] - (0..k).map(|i| u[i * n + k] * u[i * n + k]).sum::<f64>();
        if !d.is_finite() || d < -tol {
            return None;
        }
        if d <= tol {
            // a massless direction: the rest of the row must vanish too
            for j in k + 1..n {
                let r = a[k * n + j] - (0..k).map(|i| u[i * n + k] * u[i * n + j]).sum::<f64>();
                if r.abs() > 1e-6 * scale {
                    return None;
                }
            }
            continue;
        }
        let ukk = d.sqrt();
        u[k * n + k] = ukk;
        for j in k + 1..n {
            let r = a[k * n + j] - (0..k).map(|i| u[i * n + k] * u[i * n + j]).sum::<f64>();
            u[k * n + j] = r / ukk;
        }
    }
    Some(u)
}

/// Ū of a mass matrix M̄ (see [`psd_factor`]).
fn mbar_factor(mbar: &DMatrix<f64>) -> Option<Vec<f64>> {
    let n = mbar.nrows();
    let a: Vec<f64> = (0..n * n).map(|k| mbar[(k / n, k % n)]).collect();
    psd_factor(&a, n)
}

/// The non-zeros of the columns of B̂ (thesis (3.31)): (row, value) × up to 3.
type BhatColumns = ([[(usize, f64); 3]; 14 + MAX_MODES], [usize; 14 + MAX_MODES]);

fn mat34_scaled<T: Real>(a: &Mat3<T>, l: &[[T; 4]; 3], s: f64) -> [[T; 4]; 3] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            (a.0[i][0] * l[0][j] + a.0[i][1] * l[1][j] + a.0[i][2] * l[2][j]) * s
        })
    })
}

fn m34_vec<T: Real>(m: &[[T; 4]; 3], v: &[T]) -> Vec3<T> {
    let r = |i: usize| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] + m[i][3] * v[3];
    Vec3([r(0), r(1), r(2)])
}

fn m34_tr_vec<T: Real>(m: &[[T; 4]; 3], w: &[T]) -> [T; 4] {
    std::array::from_fn(|j| m[0][j] * w[0] + m[1][j] * w[1] + m[2][j] * w[2])
}

impl SpatialInertia {
    pub fn new(
        nodes: usize,
        variant: VelocityTransform,
        r0t: [[f64; 3]; 3],
        mbar: DMatrix<f64>,
    ) -> Self {
        let ubar = mbar_factor(&mbar);
        Self {
            nodes,
            variant,
            r0t,
            mbar,
            ubar,
        }
    }
    pub fn nx_nodes(&self) -> usize {
        7 * self.nodes
    }
    pub fn nv(&self) -> usize {
        6 * self.nodes
    }

    fn blocks<T: Real>(&self, x: &[T]) -> SpatialBlocks<T> {
        let r0t = Mat3::<T>::cst(self.r0t);
        let lp: [T; 4] = [x[3], x[4], x[5], x[6]];
        if self.nodes == 1 {
            // rigid body: body frame R R0
            let ft = r0t.mul_mat(&rotation(&lp).transpose());
            let g0 = mat34_scaled(&r0t, &lambda_bar_mat(&lp), 2.0);
            return SpatialBlocks { ft, g: [g0, g0] };
        }
        let lq: [T; 4] = [x[10], x[11], x[12], x[13]];
        let frame = match self.variant {
            VelocityTransform::B1 => rotation(&lp),
            VelocityTransform::B2 | VelocityTransform::B3 => rotation(&average(&lp, &lq)),
        };
        let ft = r0t.mul_mat(&frame.transpose());
        let g = match self.variant {
            VelocityTransform::B1 | VelocityTransform::B2 => [
                mat34_scaled(&ft, &lambda_mat(&lp), 2.0),
                mat34_scaled(&ft, &lambda_mat(&lq), 2.0),
            ],
            VelocityTransform::B3 => [
                mat34_scaled(&r0t, &lambda_bar_mat(&lp), 2.0),
                mat34_scaled(&r0t, &lambda_bar_mat(&lq), 2.0),
            ],
        };
        SpatialBlocks { ft, g }
    }

    /// v̄ = B ẋ (first 6·nodes entries of `out`).
    fn apply<T: Real>(&self, b: &SpatialBlocks<T>, xd: &[T], out: &mut [T]) {
        for n in 0..self.nodes {
            let o = 7 * n;
            let v = b.ft.mul_vec(&Vec3([xd[o], xd[o + 1], xd[o + 2]]));
            let w = m34_vec(&b.g[n], &xd[o + 3..o + 7]);
            out[6 * n..6 * n + 3].copy_from_slice(&v.0);
            out[6 * n + 3..6 * n + 6].copy_from_slice(&w.0);
        }
    }

    /// Bᵀ u accumulated into `out` (node part, length 7·nodes) with factor `s`.
    fn apply_t_add<T: Real>(&self, b: &SpatialBlocks<T>, u: &[T], s: f64, out: &mut [T]) {
        for n in 0..self.nodes {
            let o = 7 * n;
            let f =
                b.ft.tr_mul_vec(&Vec3([u[6 * n], u[6 * n + 1], u[6 * n + 2]]));
            let m = m34_tr_vec(&b.g[n], &u[6 * n + 3..6 * n + 6]);
            for i in 0..3 {
                out[o + i] += f.0[i] * s;
            }
            for i in 0..4 {
                out[o + 3 + i] += m[i] * s;
            }
        }
    }

    /// The inertia force F = M ẍ + h over the local coordinates (nodes then η̄).
    pub fn force<T: Real>(&self, x: &[T], xd: &[T], xdd: &[T], out: &mut [T]) {
        let nxn = self.nx_nodes();
        let nv = self.nv();
        let nw = self.mbar.nrows();
        let b = self.blocks(x);
        // Ḃ by a dual pass along ẋ
        let xe: [Dual<T, 1>; 14] = std::array::from_fn(|i| {
            if i < nxn {
                Dual::new(x[i], [xd[i]])
            } else {
                Dual::constant(T::zero())
            }
        });
        let bd = self.blocks(&xe);
        let bdot = SpatialBlocks {
            ft: Mat3(bd.ft.0.map(|r| r.map(|v| v.eps[0]))),
            g: bd.g.map(|m| m.map(|r| r.map(|v| v.eps[0]))),
        };
        let mut w = [T::zero(); MAX_W];
        let mut wd = [T::zero(); MAX_W];
        let mut a = [T::zero(); 12];
        self.apply(&b, xd, &mut w);
        self.apply(&bdot, xd, &mut a);
        self.apply(&b, xdd, &mut wd);
        for i in 0..nv {
            wd[i] += a[i];
        }
        for i in nv..nw {
            w[i] = xd[nxn + i - nv];
            wd[i] = xdd[nxn + i - nv];
        }
        let mut p = [T::zero(); MAX_W];
        let mut q = [T::zero(); MAX_W];
        for i in 0..nw {
            let (mut pi, mut qi) = (T::zero(), T::zero());
            for j in 0..nw {
                let m = self.mbar[(i, j)];
                if m != 0.0 {
                    pi += w[j] * m;
                    qi += wd[j] * m;
                }
            }
            p[i] = pi;
            q[i] = qi;
        }
        for o in out.iter_mut().take(nxn + nw - nv) {
            *o = T::zero();
        }
        self.apply_t_add(&bdot, &p, 1.0, out);
        self.apply_t_add(&b, &q, 1.0, out);
        // − B*ᵀ p = − ∂(pᵀ B(x) ẋ)/∂x: B depends on the Euler parameters only.
        if !self.bstar_t_p_sub(x, xd, &p, out) {
            self.bstar_t_p_sub_dual(x, xd, &p, out);
        }
        for i in nv..nw {
            out[nxn + i - nv] = q[i];
        }
    }

    /// out −= B*ᵀ p = ∂(pᵀ B(x) ẋ)/∂x (Appendix C) by one dual pass over the
    /// eight Euler parameters; any velocity transform.
    fn bstar_t_p_sub_dual<T: Real>(&self, x: &[T], xd: &[T], p: &[T], out: &mut [T]) {
        let nxn = self.nx_nodes();
        let nv = self.nv();
        let xl: [Dual<T, 8>; 14] = std::array::from_fn(|i| {
            let n = i / 7;
            let k = i % 7;
            if i < nxn && k >= 3 {
                Dual::variable(x[i], 4 * n + k - 3)
            } else if i < nxn {
                Dual::constant(x[i])
            } else {
                Dual::constant(T::zero())
            }
        });
        let bl = self.blocks(&xl);
        let xdl: [Dual<T, 8>; 14] = std::array::from_fn(|i| {
            if i < nxn {
                Dual::constant(xd[i])
            } else {
                Dual::constant(T::zero())
            }
        });
        let mut v = [Dual::<T, 8>::constant(T::zero()); 12];
        self.apply(&bl, &xdl, &mut v);
        let mut phi = Dual::<T, 8>::constant(T::zero());
        for i in 0..nv {
            phi += v[i] * Dual::constant(p[i]);
        }
        for n in 0..self.nodes {
            for k in 0..4 {
                out[7 * n + 3 + k] -= phi.eps[4 * n + k];
            }
        }
    }

    /// out −= B*ᵀ p in closed form where B's orientation blocks are linear in
    /// each node's own λ: the rigid body (ft = R0ᵀR(λ)ᵀ, g = 2R0ᵀΛ̄(λ)) and B3
    /// (ft = R0ᵀR(λr)ᵀ with the average λr (2.29), g_n = 2R0ᵀΛ̄(λn), (3.29)).
    /// With a_n = R0 p_v,n and C = Σ_n ṙ_n a_nᵀ, pᵀ ft ṙ = Σ_jk R_jk C_jk, whose
    /// gradient with respect to the frame quaternion is 2K(C)λ; and
    /// uᵀΛ̄(λ)λ̇ = −uᵀΛ̄(λ̇)λ gives ∂/∂λ = −Λ̄(λ̇)ᵀu. Returns false (nothing done)
    /// for B1 and B2.
    fn bstar_t_p_sub<T: Real>(&self, x: &[T], xd: &[T], p: &[T], out: &mut [T]) -> bool {
        if self.nodes == 2 && self.variant != VelocityTransform::B3 {
            return false;
        }
        let r0t = &self.r0t;
        // C = Σ_n ṙ_n (R0 p_v,n)ᵀ
        let mut c = [[T::zero(); 3]; 3];
        for n in 0..self.nodes {
            let pv = &p[6 * n..6 * n + 3];
            let a: [T; 3] =
                std::array::from_fn(|k| pv[0] * r0t[0][k] + pv[1] * r0t[1][k] + pv[2] * r0t[2][k]);
            let rd = &xd[7 * n..7 * n + 3];
            for j in 0..3 {
                for k in 0..3 {
                    c[j][k] += rd[j] * a[k];
                }
            }
        }
        let lp: [T; 4] = [x[3], x[4], x[5], x[6]];
        let (lf, sign, inv) = if self.nodes == 1 {
            (lp, 1.0, T::one())
        } else {
            let lq: [T; 4] = [x[10], x[11], x[12], x[13]];
            let s = hemisphere_sign(&lp, &lq);
            let sum: [T; 4] = std::array::from_fn(|i| lp[i] + lq[i] * s);
            let nrm =
                (sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2] + sum[3] * sum[3]).sqrt();
            let inv = T::one() / nrm;
            (sum.map(|v| v * inv), s, inv)
        };
        // ∂(Σ R_jk C_jk)/∂λ = 2 K λ, K symmetric
        let [l0, l1, l2, l3] = lf;
        let k00 = c[0][0] + c[1][1] + c[2][2];
        let k11 = c[0][0] - c[1][1] - c[2][2];
        let k22 = c[1][1] - c[0][0] - c[2][2];
        let k33 = c[2][2] - c[0][0] - c[1][1];
        let k01 = c[2][1] - c[1][2];
        let k02 = c[0][2] - c[2][0];
        let k03 = c[1][0] - c[0][1];
        let k12 = c[0][1] + c[1][0];
        let k13 = c[0][2] + c[2][0];
        let k23 = c[1][2] + c[2][1];
        let mut g = [
            (l0 * k00 + l1 * k01 + l2 * k02 + l3 * k03) * 2.0,
            (l0 * k01 + l1 * k11 + l2 * k12 + l3 * k13) * 2.0,
            (l0 * k02 + l1 * k12 + l2 * k22 + l3 * k23) * 2.0,
            (l0 * k03 + l1 * k13 + l2 * k23 + l3 * k33) * 2.0,
        ];
        if self.nodes == 2 {
            // through λr = σ/|σ|, σ = λp + s λq: (I − λr λrᵀ)/|σ|
            let d = g[0] * l0 + g[1] * l1 + g[2] * l2 + g[3] * l3;
            for (gi, li) in g.iter_mut().zip(lf) {
                *gi = (*gi - li * d) * inv;
            }
            for k in 0..4 {
                out[3 + k] -= g[k];
                out[10 + k] -= g[k] * sign;
            }
        } else {
            for k in 0..4 {
                out[3 + k] -= g[k];
            }
        }
        // rotations: 2 (R0 p_ω,n)ᵀ Λ̄(λn) λ̇n, gradient −2 Λ̄(λ̇n)ᵀ R0 p_ω,n
        for n in 0..self.nodes {
            let pw = &p[6 * n + 3..6 * n + 6];
            let u: [T; 3] =
                std::array::from_fn(|k| pw[0] * r0t[0][k] + pw[1] * r0t[1][k] + pw[2] * r0t[2][k]);
            let ld: [T; 4] = [xd[7 * n + 3], xd[7 * n + 4], xd[7 * n + 5], xd[7 * n + 6]];
            let lb = lambda_bar_mat(&ld);
            for k in 0..4 {
                out[7 * n + 3 + k] += (lb[0][k] * u[0] + lb[1][k] * u[1] + lb[2][k] * u[2]) * 2.0;
            }
        }
        true
    }

    /// The generalized force of a uniform acceleration field `g` (gravity):
    /// f = Bᵀ M̄ B ẋ_g with ẋ_g = g on every position, zero elsewhere. Exact for
    /// rigid motion; it depends on the orientations.
    pub fn gravity<T: Real>(&self, x: &[T], g: &[f64; 3], out: &mut [T]) {
        let nxn = self.nx_nodes();
        let nv = self.nv();
        let nw = self.mbar.nrows();
        let b = self.blocks(x);
        let mut xg = [T::zero(); 14];
        for n in 0..self.nodes {
            for i in 0..3 {
                xg[7 * n + i] = T::cst(g[i]);
            }
        }
        let mut w = [T::zero(); MAX_W];
        self.apply(&b, &xg, &mut w);
        let mut p = [T::zero(); MAX_W];
        for (i, pi) in p.iter_mut().enumerate().take(nw) {
            for j in 0..nv {
                *pi += w[j] * self.mbar[(i, j)];
            }
        }
        for o in out.iter_mut().take(nxn + nw - nv) {
            *o = T::zero();
        }
        self.apply_t_add(&b, &p, 1.0, out);
        for i in nv..nw {
            out[nxn + i - nv] = p[i];
        }
    }

    /// The columns of B̂ = \[B 0; 0 I\] (3.31) at x: each has at most three
    /// non-zeros (a column of the 3×3 frame block, of a 3×4 Λ block, or a unit
    /// entry for a mode amplitude). With `bases[n] = Some(P)` (4 × 3) node n's
    /// four Euler-parameter columns are replaced by the three of G_n P
    /// (λ̇ = P a). Returns the columns and their number.
    fn bhat_columns(&self, x: &[f64], bases: &[Option<[[f64; 3]; 4]>]) -> (BhatColumns, usize) {
        let nv = self.nv();
        let nw = self.mbar.nrows();
        let b = self.blocks(x);
        let mut cols = [[(0usize, 0.0f64); 3]; 14 + MAX_MODES];
        let mut cnt = [0usize; 14 + MAX_MODES];
        let mut j0 = 0;
        for nd in 0..self.nodes {
            for j in 0..3 {
                for i in 0..3 {
                    cols[j0 + j][i] = (6 * nd + i, b.ft.0[i][j]);
                }
                cnt[j0 + j] = 3;
            }
            j0 += 3;
            let g = &b.g[nd];
            match bases.get(nd).copied().flatten() {
                Some(p) => {
                    for k in 0..3 {
                        for i in 0..3 {
                            let v = g[i][0] * p[0][k]
                                + g[i][1] * p[1][k]
                                + g[i][2] * p[2][k]
                                + g[i][3] * p[3][k];
                            cols[j0 + k][i] = (6 * nd + 3 + i, v);
                        }
                        cnt[j0 + k] = 3;
                    }
                    j0 += 3;
                }
                None => {
                    for j in 0..4 {
                        for i in 0..3 {
                            cols[j0 + j][i] = (6 * nd + 3 + i, g[i][j]);
                        }
                        cnt[j0 + j] = 3;
                    }
                    j0 += 4;
                }
            }
        }
        for i in nv..nw {
            cols[j0][0] = (i, 1.0);
            cnt[j0] = 1;
            j0 += 1;
        }
        ((cols, cnt), j0)
    }

    /// The mass matrix M = \[B; I\]ᵀ M̄ \[B; I\] (3.31) (row-major, n × n with
    /// n = 7·nodes + modes). Each column of B̂ = \[B 0; 0 I\] has at most three
    /// non-zeros: first P = M̄ B̂ (nw × n, three products per entry), then the
    /// upper triangle of M = B̂ᵀ P (three products per entry), mirrored.
    pub fn mass(&self, x: &[f64], out: &mut [f64]) {
        self.mass_with_bases(x, &[], out);
    }

    /// TᵀMT for the coordinates in which node n's Euler parameters are
    /// replaced through `bases[n] = Some(P)` (λ̇ = P a, P 4 × 3): the same
    /// products over the columns of B̂T (each still with at most three
    /// non-zeros), so the transformed matrix costs no more than M. Returns
    /// its order (7·nodes + modes − one per replaced node).
    pub fn mass_with_bases(
        &self,
        x: &[f64],
        bases: &[Option<[[f64; 3]; 4]>],
        out: &mut [f64],
    ) -> usize {
        let nw = self.mbar.nrows();
        let ((cols, cnt), n) = self.bhat_columns(x, bases);
        // P row-major nw × n; a beam's (12 × 14) fits a small array, whose
        // zeroing is a tenth of the one sized for the most modes
        const SMALL: usize = 12 * 14;
        if nw * n <= SMALL {
            let mut p = [0.0f64; SMALL];
            self.mass_from_columns(&cols, &cnt, n, &mut p[..nw * n], out);
        } else {
            let mut p = [0.0f64; MAX_W * (14 + MAX_MODES)];
            self.mass_from_columns(&cols, &cnt, n, &mut p[..nw * n], out);
        }
        n
    }

    /// M = B̂ᵀ (M̄ B̂) from the columns of B̂, with `p` (zeroed, nw × n) for M̄ B̂.
    fn mass_from_columns(
        &self,
        cols: &[[(usize, f64); 3]],
        cnt: &[usize],
        n: usize,
        p: &mut [f64],
        out: &mut [f64],
    ) {
        let nw = self.mbar.nrows();
        let mbar = self.mbar.as_slice(); // column-major: M̄[:, k] is contiguous
        for j in 0..n {
            for &(k, bk) in &cols[j][..cnt[j]] {
                let mk = &mbar[k * nw..(k + 1) * nw];
                for (a, m) in mk.iter().enumerate() {
                    p[a * n + j] += m * bk;
                }
            }
        }
        for i in 0..n {
            for j in i..n {
                let mut s = 0.0;
                for &(k, bk) in &cols[i][..cnt[i]] {
                    s += bk * p[k * n + j];
                }
                out[i * n + j] = s;
                out[j * n + i] = s;
            }
        }
    }

    /// A factor R = Ū B̂ (row-major nw × n) of the mass matrix, M = RᵀR
    /// = B̂ᵀ M̄ B̂ (3.31) with M̄ = ŪᵀŪ. Returns the number of rows nw, or `None`
    /// if M̄ is indefinite.
    pub fn mass_factor(&self, x: &[f64], out: &mut [f64]) -> Option<usize> {
        let ubar = self.ubar.as_ref()?;
        let nxn = self.nx_nodes();
        let nv = self.nv();
        let nw = self.mbar.nrows();
        let n = nxn + nw - nv;
        let b = self.blocks(x);
        for a in 0..nw {
            let u = &ubar[a * nw..(a + 1) * nw];
            let row = &mut out[a * n..(a + 1) * n];
            for nd in 0..self.nodes {
                let (o, v) = (7 * nd, 6 * nd);
                for j in 0..3 {
                    row[o + j] =
                        u[v] * b.ft.0[0][j] + u[v + 1] * b.ft.0[1][j] + u[v + 2] * b.ft.0[2][j];
                }
                let g = &b.g[nd];
                for k in 0..4 {
                    row[o + 3 + k] = u[v + 3] * g[0][k] + u[v + 4] * g[1][k] + u[v + 5] * g[2][k];
                }
            }
            row[nxn..n].copy_from_slice(&u[nv..nw]);
        }
        Some(nw)
    }

    /// Kinetic energy T = ½ wᵀ M̄ w.
    pub fn kinetic_energy<T: Real>(&self, x: &[T], xd: &[T]) -> T {
        let nxn = self.nx_nodes();
        let nv = self.nv();
        let nw = self.mbar.nrows();
        let b = self.blocks(x);
        let mut w = [T::zero(); MAX_W];
        self.apply(&b, xd, &mut w);
        for i in nv..nw {
            w[i] = xd[nxn + i - nv];
        }
        let mut e = T::zero();
        for i in 0..nw {
            for j in 0..nw {
                let m = self.mbar[(i, j)];
                if m != 0.0 {
                    e += w[i] * w[j] * m;
                }
            }
        }
        e * 0.5
    }
}

/// Planar co-rotational inertia (1 or 2 nodes, each (x, y, φ)): v̄ = (Rβᵀṙ, φ̇)
/// per node with the frame angle β = β0 + φp (B1, or the single node) or
/// β0 + (φp + φq)/2 (B2 = B3 in the plane, thesis §2.4.1).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PlanarInertia {
    pub nodes: usize,
    pub variant: VelocityTransform,
    pub beta0: f64,
    pub mbar: DMatrix<f64>,
    /// Ū with M̄ = ŪᵀŪ (row-major, upper triangular); `None` if M̄ is indefinite.
    pub ubar: Option<Vec<f64>>,
}

impl PlanarInertia {
    pub fn new(nodes: usize, variant: VelocityTransform, beta0: f64, mbar: DMatrix<f64>) -> Self {
        let ubar = mbar_factor(&mbar);
        Self {
            nodes,
            variant,
            beta0,
            mbar,
            ubar,
        }
    }

    pub fn n(&self) -> usize {
        3 * self.nodes
    }

    fn angle<T: Real>(&self, x: &[T]) -> T {
        if self.nodes == 1 || self.variant == VelocityTransform::B1 {
            x[2] + self.beta0
        } else {
            (x[2] + x[5]) * 0.5 + self.beta0
        }
    }

    /// v̄ = B(β) ẋ.
    fn apply<T: Real>(&self, beta: T, xd: &[T], out: &mut [T]) {
        let (s, c) = (beta.sin(), beta.cos());
        for n in 0..self.nodes {
            let o = 3 * n;
            out[o] = c * xd[o] + s * xd[o + 1];
            out[o + 1] = c * xd[o + 1] - s * xd[o];
            out[o + 2] = xd[o + 2];
        }
    }

    fn apply_t_add<T: Real>(&self, beta: T, u: &[T], out: &mut [T]) {
        let (s, c) = (beta.sin(), beta.cos());
        for n in 0..self.nodes {
            let o = 3 * n;
            out[o] += c * u[o] - s * u[o + 1];
            out[o + 1] += s * u[o] + c * u[o + 1];
            out[o + 2] += u[o + 2];
        }
    }

    fn mbar_mul<T: Real>(&self, v: &[T], out: &mut [T]) {
        let n = self.n();
        for (i, o) in out.iter_mut().enumerate().take(n) {
            let mut s = T::zero();
            for (j, vj) in v.iter().enumerate().take(n) {
                let m = self.mbar[(i, j)];
                if m != 0.0 {
                    s += *vj * m;
                }
            }
            *o = s;
        }
    }

    /// F = M ẍ + h.
    pub fn force<T: Real>(&self, x: &[T], xd: &[T], xdd: &[T], out: &mut [T]) {
        let n = self.n();
        let beta = self.angle(x);
        let betad = self.angle(xd) - self.beta0;
        // Ḃ = β̇ ∂B/∂β; ∂B/∂β ẋ = B(β + π/2)-like rotation: compute with a dual.
        let bd = Dual::<T, 1>::new(beta, [betad]);
        let xdd1: [Dual<T, 1>; 6] = std::array::from_fn(|i| {
            if i < n {
                Dual::constant(xd[i])
            } else {
                Dual::constant(T::zero())
            }
        });
        let mut vdual = [Dual::<T, 1>::constant(T::zero()); 6];
        self.apply(bd, &xdd1, &mut vdual);
        let mut w = [T::zero(); 6];
        let mut wd = [T::zero(); 6];
        self.apply(beta, xd, &mut w);
        self.apply(beta, xdd, &mut wd);
        for i in 0..n {
            wd[i] += vdual[i].eps[0];
        }
        let mut p = [T::zero(); 6];
        let mut q = [T::zero(); 6];
        self.mbar_mul(&w, &mut p);
        self.mbar_mul(&wd, &mut q);
        for o in out.iter_mut().take(n) {
            *o = T::zero();
        }
        // Ḃᵀ p = β̇ (∂B/∂β)ᵀ p
        let mut pd = [Dual::<T, 1>::constant(T::zero()); 6];
        for i in 0..n {
            pd[i] = Dual::constant(p[i]);
        }
        let mut btp = [Dual::<T, 1>::constant(T::zero()); 6];
        self.apply_t_add(bd, &pd, &mut btp);
        for i in 0..n {
            out[i] += btp[i].eps[0];
        }
        self.apply_t_add(beta, &q, out);
        // − B*ᵀ p: ∂(pᵀ B(β) ẋ)/∂β · ∂β/∂φ
        let mut vb = [Dual::<T, 1>::constant(T::zero()); 6];
        let bb = Dual::<T, 1>::new(beta, [T::one()]);
        self.apply(bb, &xdd1, &mut vb);
        let mut dphi = T::zero();
        for i in 0..n {
            dphi += vb[i].eps[0] * p[i];
        }
        if self.nodes == 1 || self.variant == VelocityTransform::B1 {
            out[2] -= dphi;
        } else {
            out[2] -= dphi * 0.5;
            out[5] -= dphi * 0.5;
        }
    }

    pub fn gravity<T: Real>(&self, x: &[T], g: &[f64; 3], out: &mut [T]) {
        let n = self.n();
        let beta = self.angle(x);
        let mut xg = [T::zero(); 6];
        for nd in 0..self.nodes {
            xg[3 * nd] = T::cst(g[0]);
            xg[3 * nd + 1] = T::cst(g[1]);
        }
        let mut w = [T::zero(); 6];
        self.apply(beta, &xg, &mut w);
        let mut p = [T::zero(); 6];
        self.mbar_mul(&w, &mut p);
        for o in out.iter_mut().take(n) {
            *o = T::zero();
        }
        self.apply_t_add(beta, &p, out);
    }

    pub fn mass(&self, x: &[f64], out: &mut [f64]) {
        let n = self.n();
        let beta = self.angle(x);
        // columns of B: B e_j
        let mut bm = [[0.0; 6]; 6];
        for j in 0..n {
            let mut e = [0.0; 6];
            e[j] = 1.0;
            let mut col = [0.0; 6];
            self.apply(beta, &e, &mut col);
            for i in 0..n {
                bm[i][j] = col[i];
            }
        }
        for i in 0..n {
            for j in 0..n {
                let mut s = 0.0;
                for a in 0..n {
                    for b in 0..n {
                        s += bm[a][i] * self.mbar[(a, b)] * bm[b][j];
                    }
                }
                out[i * n + j] = s;
            }
        }
    }

    /// A factor R = Ū B (row-major n × n) of the mass matrix, M = RᵀR with
    /// M̄ = ŪᵀŪ; `None` if M̄ is indefinite.
    pub fn mass_factor(&self, x: &[f64], out: &mut [f64]) -> Option<usize> {
        let ubar = self.ubar.as_ref()?;
        let n = self.n();
        let beta = self.angle(x);
        let (s, c) = beta.sin_cos();
        // B per node: rows (u, v) = [c s; −s c] (ẋ, ẏ), row θ = φ̇
        for a in 0..n {
            for nd in 0..self.nodes {
                let o = 3 * nd;
                let (u0, u1, u2) = (ubar[a * n + o], ubar[a * n + o + 1], ubar[a * n + o + 2]);
                out[a * n + o] = u0 * c - u1 * s;
                out[a * n + o + 1] = u0 * s + u1 * c;
                out[a * n + o + 2] = u2;
            }
        }
        Some(n)
    }

    pub fn kinetic_energy<T: Real>(&self, x: &[T], xd: &[T]) -> T {
        let n = self.n();
        let mut w = [T::zero(); 6];
        self.apply(self.angle(x), xd, &mut w);
        let mut p = [T::zero(); 6];
        self.mbar_mul(&w, &mut p);
        let mut e = T::zero();
        for i in 0..n {
            e += w[i] * p[i];
        }
        e * 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::beam_matrices::{planar_beam_m_bar, spatial_beam_m_bar};
    use crate::section::{Material, SectionShape};

    /// A unit quaternion from a rotation vector.
    fn quat(v: [f64; 3]) -> [f64; 4] {
        let a = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let s = if a > 0.0 { (a / 2.0).sin() / a } else { 0.5 };
        [(a / 2.0).cos(), v[0] * s, v[1] * s, v[2] * s]
    }

    /// The steel strip (30 × 2 mm) the inertia tests are built on.
    fn steel_strip() -> (Material, crate::SectionProperties) {
        let mat = Material::from_poisson(2.1e11, 0.3, 7800.0);
        let sec = SectionShape::Rectangle {
            by: 0.03,
            bz: 0.002,
        }
        .properties(0.3)
        .unwrap();
        (mat, sec)
    }

    fn beam_inertia(variant: VelocityTransform, modes: usize) -> SpatialInertia {
        let (mat, sec) = steel_strip();
        let m12 = spatial_beam_m_bar(&mat, &sec, 0.2);
        let nw = 12 + modes;
        // modes: a positive-definite block coupled weakly to the nodes
        let mbar = DMatrix::from_fn(nw, nw, |i, j| match (i < 12, j < 12) {
            (true, true) => m12[(i, j)],
            (false, false) if i == j => 0.01 * (1.0 + i as f64),
            (false, false) => 1e-4,
            // couple the modes to the translations only (M̄ stays definite)
            (true, false) if [0, 1, 2, 6, 7, 8].contains(&i) => 1e-3 * ((i + j) % 5) as f64,
            (false, true) if [0, 1, 2, 6, 7, 8].contains(&j) => 1e-3 * ((i + j) % 5) as f64,
            _ => 0.0,
        });
        let r0 = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        SpatialInertia::new(2, variant, r0, mbar)
    }

    fn state(modes: usize) -> Vec<f64> {
        let lp = quat([0.1, -0.2, 0.3]);
        let lq = quat([-0.05, 0.25, 0.1]);
        let mut x = vec![0.01, 0.02, -0.03];
        x.extend(lp);
        x.extend([0.21, -0.01, 0.02]);
        x.extend(lq);
        x.extend((0..modes).map(|k| 0.1 * k as f64));
        x
    }

    /// The former formula: M_ij = Σ_kl B̂_ki M̄_kl B̂_lj over the sparse columns.
    fn mass_reference(si: &SpatialInertia, x: &[f64]) -> Vec<f64> {
        let nw = si.mbar.nrows();
        let n = si.nx_nodes() + nw - si.nv();
        let ((cols, cnt), _) = si.bhat_columns(x, &[]);
        let mut out = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = 0.0;
                for &(k, bk) in &cols[i][..cnt[i]] {
                    for &(l, bl) in &cols[j][..cnt[j]] {
                        s += bk * si.mbar[(k, l)] * bl;
                    }
                }
                out[i * n + j] = s;
            }
        }
        out
    }

    fn max_abs(v: &[f64]) -> f64 {
        v.iter().fold(0.0f64, |m, a| m.max(a.abs()))
    }

    /// TᵀMT with node-wise 4 × 3 bases of the Euler-parameter rates against
    /// the explicit congruence of the full mass matrix.
    #[test]
    fn mass_with_bases_is_the_congruence_of_the_mass() {
        for (modes, variant) in [
            (0, VelocityTransform::B3),
            (3, VelocityTransform::B1),
            (0, VelocityTransform::B2),
        ] {
            let si = beam_inertia(variant, modes);
            let i = modes;
            let x = state(modes);
            let n = si.nx_nodes() + si.mbar.nrows() - si.nv();
            let mut m = vec![0.0; n * n];
            si.mass(&x, &mut m);
            let pa = [
                [0.3, -0.1, 0.7],
                [0.2, 0.9, -0.4],
                [-0.5, 0.1, 0.2],
                [0.6, 0.3, 0.1],
            ];
            let pb = [
                [-0.2, 0.4, 0.1],
                [0.7, -0.3, 0.5],
                [0.1, 0.2, -0.8],
                [0.3, 0.6, 0.2],
            ];
            for bases in [[Some(pa), None], [Some(pa), Some(pb)], [None, Some(pb)]] {
                // T: identity except the replaced orientation blocks
                let mut cols: Vec<Vec<f64>> = vec![];
                for nd in 0..2 {
                    for k in 0..3 {
                        let mut c = vec![0.0; n];
                        c[7 * nd + k] = 1.0;
                        cols.push(c);
                    }
                    match bases[nd] {
                        Some(p) => {
                            for k in 0..3 {
                                let mut c = vec![0.0; n];
                                for r in 0..4 {
                                    c[7 * nd + 3 + r] = p[r][k];
                                }
                                cols.push(c);
                            }
                        }
                        None => {
                            for r in 0..4 {
                                let mut c = vec![0.0; n];
                                c[7 * nd + 3 + r] = 1.0;
                                cols.push(c);
                            }
                        }
                    }
                }
                for k in 14..n {
                    let mut c = vec![0.0; n];
                    c[k] = 1.0;
                    cols.push(c);
                }
                let nr = cols.len();
                let mut out = vec![0.0; nr * nr];
                assert_eq!(si.mass_with_bases(&x, &bases, &mut out), nr);
                let scale = max_abs(&m);
                for a in 0..nr {
                    for b in 0..nr {
                        let mut v = 0.0;
                        for r in 0..n {
                            for c in 0..n {
                                v += cols[a][r] * m[r * n + c] * cols[b][c];
                            }
                        }
                        assert!(
                            (out[a * nr + b] - v).abs() <= 1e-13 * scale,
                            "modes {i}, {bases:?}: ({a}, {b}) {} vs {v}",
                            out[a * nr + b]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn spatial_mass_matches_the_reference_and_its_factor() {
        for variant in [
            VelocityTransform::B1,
            VelocityTransform::B2,
            VelocityTransform::B3,
        ] {
            for modes in [0, 3] {
                let si = beam_inertia(variant, modes);
                let x = state(modes);
                let n = x.len();
                let reference = mass_reference(&si, &x);
                let mut m = vec![0.0; n * n];
                si.mass(&x, &mut m);
                let scale = max_abs(&reference);
                let err: Vec<f64> = m.iter().zip(&reference).map(|(a, b)| a - b).collect();
                assert!(
                    max_abs(&err) < 1e-14 * scale,
                    "{variant:?} {modes}: {} of {scale}",
                    max_abs(&err)
                );
                // M = RᵀR
                let mut r = vec![0.0; n * n];
                let rows = si.mass_factor(&x, &mut r).unwrap();
                assert_eq!(rows, 12 + modes);
                for i in 0..n {
                    for j in 0..n {
                        let rtr: f64 = (0..rows).map(|k| r[k * n + i] * r[k * n + j]).sum();
                        assert!(
                            (rtr - reference[i * n + j]).abs() < 1e-13 * scale,
                            "{variant:?} {modes} ({i}, {j}): {rtr} vs {}",
                            reference[i * n + j]
                        );
                    }
                }
            }
        }
    }

    /// The closed-form B*ᵀp against the dual pass, in f64 and in dual numbers
    /// (as the force derivatives use it), also off the unit sphere.
    #[test]
    fn closed_form_bstar_matches_the_dual_pass() {
        fn check<T: Real>(si: &SpatialInertia, x: &[T], xd: &[T], p: &[T]) {
            let n = x.len();
            let mut a = vec![T::zero(); n];
            let mut b = vec![T::zero(); n];
            assert!(si.bstar_t_p_sub(x, xd, p, &mut a));
            si.bstar_t_p_sub_dual(x, xd, p, &mut b);
            let scale = b.iter().fold(0.0f64, |m, v| m.max(v.value().abs()));
            assert!(scale > 0.0);
            for (u, v) in a.iter().zip(&b) {
                assert!(
                    (u.value() - v.value()).abs() < 1e-13 * scale,
                    "{u:?} vs {v:?}"
                );
            }
        }
        let rb = {
            let mut mbar = DMatrix::zeros(6, 6);
            for a in 0..6 {
                mbar[(a, a)] = 1.0;
            }
            SpatialInertia::new(
                1,
                VelocityTransform::B1,
                [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
                mbar,
            )
        };
        let p: Vec<f64> = (0..15)
            .map(|i| 0.3 + 0.17 * i as f64 - 0.02 * (i * i) as f64)
            .collect();
        for (si, modes) in [
            (beam_inertia(VelocityTransform::B3, 0), 0),
            (beam_inertia(VelocityTransform::B3, 3), 3),
            (rb, 0),
        ] {
            let nodes = si.nodes;
            for stretch in [1.0, 1.3] {
                let mut x = state(modes);
                x.truncate(7 * nodes);
                for v in &mut x[3..7] {
                    *v *= stretch;
                }
                if nodes == 2 {
                    // λq in the other hemisphere
                    for v in &mut x[10..14] {
                        *v *= -0.9;
                    }
                }
                x.extend((0..modes).map(|k| 0.1 * k as f64));
                let xd: Vec<f64> = (0..x.len()).map(|i| 0.5 - 0.13 * i as f64).collect();
                check(&si, &x, &xd, &p);
                // with dual numbers: the derivatives agree as well
                let xe: Vec<Dual<f64, 2>> = x
                    .iter()
                    .enumerate()
                    .map(|(i, v)| Dual::new(*v, [0.01 * i as f64, if i == 4 { 1.0 } else { 0.0 }]))
                    .collect();
                let xde: Vec<Dual<f64, 2>> =
                    xd.iter().map(|v| Dual::new(*v, [0.3 * v, 1.0])).collect();
                let pe: Vec<Dual<f64, 2>> = p.iter().map(|v| Dual::new(*v, [0.0, -v])).collect();
                fn check_eps(
                    si: &SpatialInertia,
                    x: &[Dual<f64, 2>],
                    xd: &[Dual<f64, 2>],
                    p: &[Dual<f64, 2>],
                ) {
                    let n = x.len();
                    let mut a = vec![Dual::<f64, 2>::constant(0.0); n];
                    let mut b = vec![Dual::<f64, 2>::constant(0.0); n];
                    si.bstar_t_p_sub(x, xd, p, &mut a);
                    si.bstar_t_p_sub_dual(x, xd, p, &mut b);
                    for (u, v) in a.iter().zip(&b) {
                        for k in 0..2 {
                            assert!(
                                (u.eps[k] - v.eps[k]).abs() < 1e-12 * (1.0 + v.eps[k].abs()),
                                "{u:?} vs {v:?}"
                            );
                        }
                    }
                }
                check(&si, &xe, &xde, &pe);
                check_eps(&si, &xe, &xde, &pe);
            }
        }
    }

    #[test]
    fn rigid_body_factor_reproduces_the_mass() {
        let mut mbar = DMatrix::zeros(6, 6);
        for a in 0..3 {
            mbar[(a, a)] = 2.0;
            mbar[(3 + a, 3 + a)] = 0.1 + 0.05 * a as f64;
        }
        mbar[(1, 5)] = 0.2;
        mbar[(5, 1)] = 0.2;
        let si = SpatialInertia::new(
            1,
            VelocityTransform::B1,
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            mbar,
        );
        let x = {
            let mut x = vec![0.3, -0.1, 0.2];
            x.extend(quat([0.4, 0.1, -0.3]));
            x
        };
        let mut m = vec![0.0; 49];
        let mut r = vec![0.0; 49];
        si.mass(&x, &mut m);
        let reference = mass_reference(&si, &x);
        let rows = si.mass_factor(&x, &mut r).unwrap();
        for i in 0..7 {
            for j in 0..7 {
                let rtr: f64 = (0..rows).map(|k| r[k * 7 + i] * r[k * 7 + j]).sum();
                assert!((rtr - m[i * 7 + j]).abs() < 1e-13, "({i}, {j})");
                assert!(
                    (reference[i * 7 + j] - m[i * 7 + j]).abs() < 1e-14,
                    "({i}, {j})"
                );
            }
        }
    }

    #[test]
    fn planar_factor_reproduces_the_mass() {
        let (mat, sec) = steel_strip();
        let mbar = DMatrix::from_iterator(6, 6, planar_beam_m_bar(&mat, &sec, 0.2).iter().copied());
        for variant in [VelocityTransform::B1, VelocityTransform::B2] {
            let pi = PlanarInertia::new(2, variant, 0.4, mbar.clone());
            let x = [0.01, 0.02, 0.3, 0.2, 0.05, -0.2];
            let mut m = [0.0; 36];
            let mut r = [0.0; 36];
            pi.mass(&x, &mut m);
            let rows = pi.mass_factor(&x, &mut r).unwrap();
            let scale = max_abs(&m);
            for i in 0..6 {
                for j in 0..6 {
                    let rtr: f64 = (0..rows).map(|k| r[k * 6 + i] * r[k * 6 + j]).sum();
                    assert!(
                        (rtr - m[i * 6 + j]).abs() < 1e-13 * scale,
                        "{variant:?} ({i}, {j})"
                    );
                }
            }
        }
    }

    #[test]
    fn psd_factor_handles_massless_directions_and_rejects_indefinite() {
        // diag(2, 0, 3) with a coupling only between the massive entries
        let a = [2.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 3.0];
        let u = psd_factor(&a, 3).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = (0..3).map(|k| u[k * 3 + i] * u[k * 3 + j]).sum();
                assert!((v - a[i * 3 + j]).abs() < 1e-15, "({i}, {j})");
            }
        }
        assert!(psd_factor(&[1.0, 2.0, 2.0, 1.0], 2).is_none());
        assert!(psd_factor(&[0.0, 1.0, 1.0, 1.0], 2).is_none());
    }

    /// A mass whose diagonal spans 20 decades (the warping rate of a thin
    /// sheet beam next to its translations) keeps every direction: UᵀU = A
    /// entry by entry to rounding, relative to the entry's own scale, and a
    /// singular combination of two massive coordinates is still massless.
    #[test]
    fn psd_factor_keeps_tiny_inertia_in_other_units() {
        let (big, tiny) = (3.4e-5, 2.3e-18);
        // (big, big coupled singularly), then a 2 × 2 warping-like block
        let a = [
            big,
            big,
            0.0,
            0.0, //
            big,
            big,
            0.0,
            0.0, //
            0.0,
            0.0,
            tiny,
            -0.25 * tiny, //
            0.0,
            0.0,
            -0.25 * tiny,
            tiny,
        ];
        let u = psd_factor(&a, 4).unwrap();
        for i in 0..4 {
            for j in 0..4 {
                let v: f64 = (0..4).map(|k| u[k * 4 + i] * u[k * 4 + j]).sum();
                let s = (a[i * 4 + i] * a[j * 4 + j]).sqrt();
                assert!(
                    (v - a[i * 4 + j]).abs() <= 1e-14 * s,
                    "({i}, {j}): {v} vs {}",
                    a[i * 4 + j]
                );
            }
        }
        // the singular pair leaves one zero row, the tiny block two rows
        let rows = (0..4)
            .filter(|k| (0..4).any(|j| u[k * 4 + j] != 0.0))
            .count();
        assert_eq!(rows, 3);
        // the unscaled rule would have called the tiny block massless
        let old = psd_factor_unscaled(&a, 4).unwrap();
        assert_eq!(old[2 * 4 + 2], 0.0);
    }
}
