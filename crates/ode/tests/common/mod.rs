//! Test problems shared by the integration tests.
#![allow(dead_code, clippy::needless_range_loop)]

use faer::Mat;
use flexmb_ode::{OdeSystem, RhsError, SecondOrderSystem};

/// y' = −y + sin t, y(0) = 1; exact y = 1.5 e^{−t} + (sin t − cos t)/2.
pub struct Forced;

impl Forced {
    pub fn exact(t: f64) -> f64 {
        1.5 * (-t).exp() + 0.5 * (t.sin() - t.cos())
    }
}

impl OdeSystem for Forced {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = -y[0] + t.sin();
        Ok(())
    }
}

/// y' = −y.
pub struct Decay;

impl OdeSystem for Decay {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = -y[0];
        Ok(())
    }
}

/// Harmonic oscillator y1' = y2, y2' = −ω² y1.
pub struct Oscillator {
    pub omega: f64,
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = -self.omega * self.omega * y[0];
        Ok(())
    }
}

/// Counts calls independently of the integrators.
pub struct Counting<S> {
    pub inner: S,
    pub rhs_calls: usize,
    pub tangent_calls: usize,
}

impl<S> Counting<S> {
    pub fn new(inner: S) -> Self {
        Self {
            inner,
            rhs_calls: 0,
            tangent_calls: 0,
        }
    }
}

impl<S: OdeSystem> OdeSystem for Counting<S> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.rhs_calls += 1;
        self.inner.rhs(t, y, dy)
    }
}

impl<S: SecondOrderSystem> SecondOrderSystem for Counting<S> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        self.rhs_calls += 1;
        self.inner.residual(t, q, qd, qdd, r)
    }
    fn tangent(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        m: &mut Mat<f64>,
        c: &mut Mat<f64>,
        k: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        self.tangent_calls += 1;
        self.inner.tangent(t, q, qd, qdd, m, c, k)
    }
}

/// Linear second-order system M q̈ + C q̇ + K q = f(t) with
/// f_i(t) = force[i]·sin(t).
pub struct Linear2 {
    pub m: Vec<f64>,
    pub c: Vec<f64>,
    pub k: Vec<f64>,
    pub force: Vec<f64>,
    pub n: usize,
}

impl Linear2 {
    pub fn new(n: usize, m: Vec<f64>, c: Vec<f64>, k: Vec<f64>, force: Vec<f64>) -> Self {
        Self { m, c, k, force, n }
    }

    /// Single damped, forced oscillator q̈ + c q̇ + k q = sin t.
    pub fn sdof(c: f64, k: f64) -> Self {
        Self::new(1, vec![1.0], vec![c], vec![k], vec![1.0])
    }

    /// Chain of `n` unit masses joined by springs `k` (and to the ground at
    /// the first mass), light damping, free vibration.
    pub fn chain(n: usize, k: f64, c: f64) -> Self {
        let mut kk = vec![0.0; n * n];
        for i in 0..n {
            kk[i * n + i] = if i + 1 < n { 2.0 * k } else { k };
            if i + 1 < n {
                kk[i * n + i + 1] = -k;
                kk[(i + 1) * n + i] = -k;
            }
        }
        let mut m = vec![0.0; n * n];
        let mut cc = vec![0.0; n * n];
        for i in 0..n {
            m[i * n + i] = 1.0;
            cc[i * n + i] = c;
        }
        Self::new(n, m, cc, kk, vec![0.0; n])
    }

    /// Two-DOF system with modal frequencies 1 and `omega_fast` (stiffness
    /// ratio omega_fast²), modes rotated by 30°: q = R x.
    pub fn stiff_pair(omega_fast: f64) -> Self {
        let (s, c) = (std::f64::consts::PI / 6.0).sin_cos();
        let r = [[c, -s], [s, c]];
        let lam = [1.0, omega_fast * omega_fast];
        let mut k = vec![0.0; 4];
        for i in 0..2 {
            for j in 0..2 {
                k[i * 2 + j] = (0..2).map(|m| r[i][m] * lam[m] * r[j][m]).sum();
            }
        }
        Self::new(2, vec![1.0, 0.0, 0.0, 1.0], vec![0.0; 4], k, vec![0.0; 2])
    }

    /// Rotation used by [`Linear2::stiff_pair`] (slow mode direction).
    pub fn stiff_pair_slow_direction() -> [f64; 2] {
        let (s, c) = (std::f64::consts::PI / 6.0).sin_cos();
        [c, s]
    }
}

impl SecondOrderSystem for Linear2 {
    fn dim(&self) -> usize {
        self.n
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        let n = self.n;
        let st = t.sin();
        for i in 0..n {
            let mut acc = -self.force[i] * st;
            for j in 0..n {
                let ij = i * n + j;
                acc += self.m[ij] * qdd[j] + self.c[ij] * qd[j] + self.k[ij] * q[j];
            }
            r[i] = acc;
        }
        Ok(())
    }
    fn tangent(
        &mut self,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        _qdd: &[f64],
        m: &mut Mat<f64>,
        c: &mut Mat<f64>,
        k: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        let n = self.n;
        for i in 0..n {
            for j in 0..n {
                m[(i, j)] = self.m[i * n + j];
                c[(i, j)] = self.c[i * n + j];
                k[(i, j)] = self.k[i * n + j];
            }
        }
        Ok(())
    }
}

/// Exact solution of q̈ + c q̇ + k q = sin t, q(0) = q0, q̇(0) = v0, for an
/// underdamped system (c² < 4k, k ≠ 1 or c ≠ 0). Returns (q, q̇).
pub fn sdof_exact(c: f64, k: f64, q0: f64, v0: f64, t: f64) -> (f64, f64) {
    // Particular solution A sin t + B cos t.
    let d = (k - 1.0) * (k - 1.0) + c * c;
    let a = (k - 1.0) / d;
    let b = -c / d;
    let zeta_w = c / 2.0;
    let wd = (k - zeta_w * zeta_w).sqrt();
    // Homogeneous part e^{−ζω t}(C1 cos wd t + C2 sin wd t).
    let c1 = q0 - b;
    let c2 = (v0 - a + zeta_w * c1) / wd;
    let e = (-zeta_w * t).exp();
    let (s, co) = (wd * t).sin_cos();
    let qh = e * (c1 * co + c2 * s);
    let qhd = e * (-zeta_w * (c1 * co + c2 * s) + wd * (-c1 * s + c2 * co));
    (
        qh + a * t.sin() + b * t.cos(),
        qhd + a * t.cos() - b * t.sin(),
    )
}

/// Pendulum q̈ + sin q = 0 in residual form (nonlinear tangent).
pub struct Pendulum;

impl SecondOrderSystem for Pendulum {
    fn dim(&self) -> usize {
        1
    }
    fn residual(
        &mut self,
        _t: f64,
        q: &[f64],
        _qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        r[0] = qdd[0] + q[0].sin();
        Ok(())
    }
    fn tangent(
        &mut self,
        _t: f64,
        q: &[f64],
        _qd: &[f64],
        _qdd: &[f64],
        m: &mut Mat<f64>,
        c: &mut Mat<f64>,
        k: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        m[(0, 0)] = 1.0;
        c[(0, 0)] = 0.0;
        k[(0, 0)] = q[0].cos();
        Ok(())
    }
}

/// Pendulum in first-order form.
pub struct Pendulum1;

impl OdeSystem for Pendulum1 {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = -y[0].sin();
        Ok(())
    }
}
