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
use flexmb_rotation::generic::{average, lambda_bar_mat, lambda_mat, rotation};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Largest number of mode amplitudes η̄ a superelement may carry.
pub const MAX_MODES: usize = 24;
/// Largest length of the generalized velocity w = (v̄, η̄̇).
pub(crate) const MAX_W: usize = 12 + MAX_MODES;

/// How absolute nodal velocities are expressed in the co-rotational frame
/// (thesis §2.3.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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
}

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
        for i in nv..nw {
            out[nxn + i - nv] = q[i];
        }
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

    /// The mass matrix M = \[B; I\]ᵀ M̄ \[B; I\] (row-major, n × n with
    /// n = 7·nodes + modes). Each column of B̂ = \[B 0; 0 I\] has at most three
    /// non-zeros, so M_ij = Σ B̂_ki M̄_kl B̂_lj costs at most nine products.
    pub fn mass(&self, x: &[f64], out: &mut [f64]) {
        let nxn = self.nx_nodes();
        let nv = self.nv();
        let nw = self.mbar.nrows();
        let n = nxn + nw - nv;
        let b = self.blocks(x);
        // sparse columns of B̂: (row, value) × up to 3
        let mut cols = [[(0usize, 0.0f64); 3]; 14 + MAX_MODES];
        let mut cnt = [0usize; 14 + MAX_MODES];
        for nd in 0..self.nodes {
            for j in 0..3 {
                for i in 0..3 {
                    cols[7 * nd + j][i] = (6 * nd + i, b.ft.0[i][j]);
                }
                cnt[7 * nd + j] = 3;
            }
            for j in 0..4 {
                for i in 0..3 {
                    cols[7 * nd + 3 + j][i] = (6 * nd + 3 + i, b.g[nd][i][j]);
                }
                cnt[7 * nd + 3 + j] = 3;
            }
        }
        for i in nv..nw {
            cols[nxn + i - nv][0] = (i, 1.0);
            cnt[nxn + i - nv] = 1;
        }
        for i in 0..n {
            for j in i..n {
                let mut s = 0.0;
                for &(k, bk) in &cols[i][..cnt[i]] {
                    for &(l, bl) in &cols[j][..cnt[j]] {
                        s += bk * self.mbar[(k, l)] * bl;
                    }
                }
                out[i * n + j] = s;
                out[j * n + i] = s;
            }
        }
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
}

impl PlanarInertia {
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
