//! The equations of motion in independent coordinates (thesis (D.10)):
//! Mq q̈ = F,qᵀ (f − Mx ẍ0 − h) − E,qᵀ σ, with Mq = F,qᵀ Mx F,q assembled
//! element by element, and the residual g(q, q̇, q̈, t) of (E.1).

use crate::nodal_eom::NodalEom;
use crate::DynamicsError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{matmul as tri_matmul, BlockStructure};
use faer::linalg::solvers::Solve;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use flexmb_element::Element;
use flexmb_kinematics::Kinematics;
use flexmb_model::{Coordinate, ERole, Load, Mechanism};
use flexmb_rotation::EulerParameters;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Energies of a state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energies {
    /// Kinetic energy T.
    pub kinetic: f64,
    /// Elastic energy ½εᵀSε (+ σ0ᵀε) of the non-rigid deformations.
    pub elastic: f64,
    /// Gravitational potential of the elements that have an exact one (point
    /// masses); see `gravity_exact`.
    pub gravitational: f64,
    /// True when every massive element contributed an exact potential; else
    /// use the integrated external work for energy balances.
    pub gravity_exact: bool,
}

/// How many elements of the mass assembly [`Dynamics::inertia_until`]
/// assembles between two reads of the stop flag (an atomic load: nothing
/// next to an element's block).
const STOP_CHECK_ELEMENTS: usize = 16;

/// Work arrays of the element-block assembly Mq = Σ_e F_eᵀ M_e F_e (D.10).
///
/// For each element, the columns of F,q that are not zero on its rows form
/// the set S (ascending), and F_e is gathered on them (n × |S|). With the
/// factor M_e = R_eᵀR_e the element adds W_eᵀW_e, W_e = R_e F_e. The W_e of
/// consecutive elements with the same S are stacked (up to [`STACK_ROWS`]
/// rows) and added to Mq by one product WᵀW when S changes; on a contiguous S
/// directly into the diagonal block of Mq, else through a compact block.
pub(crate) struct Assembly {
    /// Column set of the stacked W (first `pending` entries valid).
    cols: Vec<usize>,
    pending: usize,
    /// Rows of W in use.
    rows: usize,
    /// Column set of the current element.
    cur: Vec<usize>,
    /// F_e (n × |S|).
    fe: Mat<f64>,
    /// The stacked W (`STACK_ROWS` + n_max rows).
    w: Mat<f64>,
    /// The factor R_e (or the mass matrix M_e), row-major.
    re: Vec<f64>,
    /// M_e F_e for elements without a factor.
    mfe: Mat<f64>,
    /// A compact |S| × |S| block for column sets that are not contiguous.
    c: Mat<f64>,
    /// Per element, its x_index as runs of consecutive global indices
    /// (global start, local start, length): a node's coordinates are adjacent.
    runs: Vec<Vec<(usize, usize, usize)>>,
}

/// Rows of stacked W_e before a product WᵀW is added to Mq.
const STACK_ROWS: usize = 96;

impl Assembly {
    /// Work arrays for a product over `n_q` columns (the DOFs for Mq, the
    /// reduced coordinates for a projected mass).
    pub(crate) fn new(mech: &flexmb_model::Mechanism, n_q: usize) -> Self {
        let nmax = mech
            .elements
            .iter()
            .map(|e| e.x_index.len())
            .max()
            .unwrap_or(0);
        Self {
            cols: vec![0; n_q],
            pending: 0,
            rows: 0,
            cur: vec![0; n_q],
            fe: Mat::zeros(nmax, n_q),
            w: Mat::zeros(STACK_ROWS + nmax, n_q),
            re: vec![0.0; nmax * nmax],
            mfe: Mat::zeros(nmax, n_q),
            c: Mat::zeros(n_q, n_q),
            runs: mech
                .elements
                .iter()
                .map(|e| {
                    let mut r: Vec<(usize, usize, usize)> = vec![];
                    for (k, &g) in e.x_index.iter().enumerate() {
                        match r.last_mut() {
                            Some((g0, _, len)) if *g0 + *len == g => *len += 1,
                            _ => r.push((g, k, 1)),
                        }
                    }
                    r
                })
                .collect(),
        }
    }

    /// Adds F_eᵀ M_e F_e of element `ei` (local coordinates `xl`) to the
    /// lower triangle of Mq (possibly at the next [`flush`](Self::flush)),
    /// F the n_x × n_q transfer matrix (F,q, or F,z of a projection).
    fn add_element(
        &mut self,
        ei: usize,
        el: &Element,
        xl: &[f64],
        fq: MatRef<'_, f64>,
        mq: &mut Mat<f64>,
    ) {
        let (n, n_q) = (xl.len(), fq.ncols());
        // the non-zero columns of F_e, gathered
        let runs = &self.runs[ei];
        let mut s = 0;
        for c in 0..n_q {
            let col = fq
                .col(c)
                .try_as_col_major()
                .expect("F,q and F,z are stored by columns")
                .as_slice();
            let dst = &mut self.fe.col_as_slice_mut(s)[..n];
            for &(g, k, len) in runs {
                dst[k..k + len].copy_from_slice(&col[g..g + len]);
            }
            if dst.iter().any(|v| *v != 0.0) {
                self.cur[s] = c;
                s += 1;
            }
        }
        if s == 0 {
            return;
        }
        let Some(m) = el.mass_factor(xl, &mut self.re) else {
            // no factor: F_eᵀ (M_e F_e) at once
            el.mass_matrix(xl, &mut self.re[..n * n]);
            let me = MatRef::from_row_major_slice(&self.re[..n * n], n, n);
            let fe = self.fe.as_ref().submatrix(0, 0, n, s);
            let mut mfe = self.mfe.as_mut().submatrix_mut(0, 0, n, s);
            matmul(mfe.as_mut(), Accum::Replace, me, fe, 1.0, Par::Seq);
            let mut c = self.c.as_mut().submatrix_mut(0, 0, s, s);
            matmul(
                c.as_mut(),
                Accum::Replace,
                fe.transpose(),
                mfe.as_ref(),
                1.0,
                Par::Seq,
            );
            add_lower(mq, c.as_ref(), &self.cur[..s]);
            return;
        };
        if m == 0 {
            return;
        }
        if self.cur[..s] != self.cols[..self.pending] || self.rows + m > STACK_ROWS {
            self.flush(mq);
            self.cols[..s].copy_from_slice(&self.cur[..s]);
            self.pending = s;
        }
        let r = MatRef::from_row_major_slice(&self.re[..m * n], m, n);
        let fe = self.fe.as_ref().submatrix(0, 0, n, s);
        let w = self.w.as_mut().submatrix_mut(self.rows, 0, m, s);
        product(w, r, fe);
        self.rows += m;
    }

    /// Adds WᵀW of the stacked rows to Mq and empties the stack.
    fn flush(&mut self, mq: &mut Mat<f64>) {
        let (s, rows) = (self.pending, self.rows);
        self.pending = 0;
        self.rows = 0;
        if s == 0 || rows == 0 {
            return;
        }
        let w = self.w.as_ref().submatrix(0, 0, rows, s);
        let c0 = self.cols[0];
        if self.cols[s - 1] - c0 + 1 == s {
            // contiguous columns: straight into the diagonal block
            let dst = mq.as_mut().submatrix_mut(c0, c0, s, s);
            gram_lower(dst, w, Accum::Add);
        } else {
            let mut c = self.c.as_mut().submatrix_mut(0, 0, s, s);
            gram_lower(c.as_mut(), w, Accum::Replace);
            add_lower(mq, c.as_ref(), &self.cols[..s]);
        }
    }
}

/// Column counts up to which the element-block products are plain loops:
/// for the few columns of a projection (n_z) faer's dispatch costs more
/// than the arithmetic.
const PLAIN_UP_TO: usize = 8;

/// dst = a b: plain dot products when b has at most [`PLAIN_UP_TO`]
/// columns and the rows of a and columns of b and dst are contiguous,
/// else faer.
fn product(mut dst: MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    if b.ncols() <= PLAIN_UP_TO && a.row_stride() == a.ncols() as isize && a.col_stride() == 1 {
        if let (Some(bs), true) = (contiguous_columns(b), dst.row_stride() == 1) {
            let av = contiguous_rows(a);
            for (c, bc) in bs.enumerate() {
                let dc = dst
                    .as_mut()
                    .col_mut(c)
                    .try_as_col_major_mut()
                    .expect("contiguous");
                for (d, ar) in dc.as_slice_mut().iter_mut().zip(av.clone()) {
                    *d = ar.iter().zip(bc).map(|(x, y)| x * y).sum();
                }
            }
            return;
        }
    }
    matmul(dst, Accum::Replace, a, b, 1.0, Par::Seq);
}

/// The lower triangle of wᵀw, added to or replacing dst's: plain loops for
/// at most [`PLAIN_UP_TO`] columns of w with contiguous columns, else faer.
fn gram_lower(mut dst: MatMut<'_, f64>, w: MatRef<'_, f64>, accum: Accum) {
    if let (Some(cols), true) = (contiguous_columns(w), w.ncols() <= PLAIN_UP_TO) {
        for (j, wj) in cols.clone().enumerate() {
            for (i, wi) in cols.clone().enumerate().skip(j) {
                let v: f64 = wi.iter().zip(wj).map(|(x, y)| x * y).sum();
                dst[(i, j)] = match accum {
                    Accum::Add => dst[(i, j)] + v,
                    Accum::Replace => v,
                };
            }
        }
        return;
    }
    tri_matmul(
        dst,
        BlockStructure::TriangularLower,
        accum,
        w.transpose(),
        BlockStructure::Rectangular,
        w,
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
}

/// The columns of m as slices, if they are contiguous.
fn contiguous_columns<'a>(m: MatRef<'a, f64>) -> Option<impl Iterator<Item = &'a [f64]> + Clone> {
    (m.row_stride() == 1 || m.nrows() <= 1).then(|| {
        (0..m.ncols()).map(move |c| {
            m.col(c)
                .try_as_col_major()
                .expect("unit row stride")
                .as_slice()
        })
    })
}

/// The rows of a row-major m as slices.
fn contiguous_rows<'a>(m: MatRef<'a, f64>) -> impl Iterator<Item = &'a [f64]> + Clone {
    (0..m.nrows()).map(move |r| {
        m.row(r)
            .try_as_row_major()
            .expect("unit column stride")
            .as_slice()
    })
}

/// Adds the lower triangle of the compact block `c` on the (ascending) index
/// set `idx` to the lower triangle of `mq`.
fn add_lower(mq: &mut Mat<f64>, c: MatRef<'_, f64>, idx: &[usize]) {
    for (a, &ia) in idx.iter().enumerate() {
        let col = mq.col_as_slice_mut(ia);
        for (b, &ib) in idx.iter().enumerate().skip(a) {
            col[ib] += c[(b, a)];
        }
    }
}

/// The element loop of the inertia: w −= Mx ẍ + h element by element at the
/// nodal state (x, ẋ, ẍ), and, with `mass` = (work arrays, F, M), the mass
/// M = Fᵀ Mx F by element blocks ([`Assembly`]), symmetric on return. Reads
/// `stop` every [`STOP_CHECK_ELEMENTS`] elements while M is assembled and
/// returns false, M incomplete, when it is set.
pub(crate) fn inertia_pass(
    mech: &Mechanism,
    (x, xd, xdd): (&[f64], &[f64], &[f64]),
    w: &mut [f64],
    mut mass: Option<(&mut Assembly, MatRef<'_, f64>, &mut Mat<f64>)>,
    stop: Option<&AtomicBool>,
) -> bool {
    if let Some((asm, _, m)) = mass.as_mut() {
        m.fill(0.0);
        asm.pending = 0;
    }
    let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
    let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
    let mut al = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
    let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
    for (ei, e) in mech.elements.iter().enumerate() {
        if let Some((asm, _, _)) = mass.as_mut() {
            if ei % STOP_CHECK_ELEMENTS == 0 && crate::simulate::check_stop(stop).is_err() {
                // the stacked blocks are dropped: the next assembly starts afresh
                asm.pending = 0;
                asm.rows = 0;
                return false;
            }
        }
        if !e.element.has_inertia() {
            continue;
        }
        let n = e.x_index.len();
        e.gather(x, &mut xl[..n]);
        e.gather(xd, &mut vl[..n]);
        e.gather(xdd, &mut al[..n]);
        e.element
            .inertia_force(&xl[..n], &vl[..n], &al[..n], &mut fl[..n]);
        e.scatter_add(&fl[..n], -1.0, w);
        if let Some((asm, f, m)) = mass.as_mut() {
            asm.add_element(ei, &e.element, &xl[..n], *f, m);
        }
    }
    if let Some((asm, _, m)) = mass {
        asm.flush(m);
        // mirror the lower triangle
        let n = m.nrows();
        for c in 0..n {
            for r in c + 1..n {
                m[(c, r)] = m[(r, c)];
            }
        }
    }
    true
}

/// The dynamics of one mechanism: kinematics plus forces; holds all buffers.
pub struct Dynamics {
    pub(crate) kin: Kinematics,
    pub(crate) mech: Arc<Mechanism>,
    pub(crate) f: Vec<f64>,
    pub(crate) sigma: Vec<f64>,
    pub(crate) w: Vec<f64>,
    /// Nodal accelerations ẍ0 + F,q q̈ of a residual evaluation.
    xdd: Vec<f64>,
    pub(crate) mq: Mat<f64>,
    pub(crate) rhs: Vec<f64>,
    /// Work arrays of the element-block assembly of Mq.
    asm: Assembly,
    /// Set-up and work memory of the nodal-coordinate solve of q̈.
    pub(crate) nodal: NodalEom,
    /// Work memory of the projected equations of a reduced model (made on
    /// their first evaluation).
    pub(crate) projection: Option<crate::projected::Projection>,
    /// The Cholesky factor of Mq (lower triangle) and its workspace.
    llt: Mat<f64>,
    llt_mem: MemBuffer,
    /// Factor on loads and gravity (load stepping in statics).
    pub(crate) load_factor: f64,
    /// A persistent scale of the loads (not gravity), e.g. for load sweeps.
    pub(crate) load_scale: f64,
    /// The factorized static tangent of the last static Newton step (chord steps).
    pub(crate) static_factor: Option<crate::statics::StaticFactor>,
    /// The position solve of outputs along a trajectory (made on first use),
    /// apart from `kin` so that recording outputs leaves the run unchanged.
    pub(crate) output_kin: Option<Kinematics>,
    pub(crate) evaluations: u64,
}

impl Dynamics {
    /// Prepares the dynamics of a mechanism.
    pub fn new(mech: Arc<Mechanism>) -> Self {
        let (n_x, n_e, n_q) = (mech.n_x(), mech.n_eps(), mech.n_dof());
        Self {
            kin: Kinematics::new(mech.clone()),
            f: vec![0.0; n_x],
            sigma: vec![0.0; n_e],
            w: vec![0.0; n_x],
            xdd: vec![0.0; n_x],
            mq: Mat::zeros(n_q, n_q),
            rhs: vec![0.0; n_q],
            asm: Assembly::new(&mech, n_q),
            nodal: NodalEom::new(&mech),
            projection: None,
            llt: Mat::zeros(n_q, n_q),
            llt_mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(
                n_q,
                Par::Seq,
                Default::default(),
            )),
            load_factor: 1.0,
            load_scale: 1.0,
            static_factor: None,
            output_kin: None,
            evaluations: 0,
            mech,
        }
    }
    /// The mechanism.
    pub fn mechanism(&self) -> &Arc<Mechanism> {
        &self.mech
    }
    /// The kinematics (configuration of the last evaluation).
    pub fn kinematics(&self) -> &Kinematics {
        &self.kin
    }
    /// Mutable access to the kinematics (Newton options, guesses).
    pub fn kinematics_mut(&mut self) -> &mut Kinematics {
        &mut self.kin
    }
    /// Number of degrees of freedom.
    pub fn n_q(&self) -> usize {
        self.mech.n_dof()
    }
    /// Number of equation-of-motion evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Solves the kinematics to first order (and velocities, accelerations if asked).
    /// `Ok` if a slice argument `what` of length `len` has one entry per
    /// DOF; the length rule of the public API (docs/ARCHITECTURE.md): a
    /// function that returns a `Result` reports a wrong length as
    /// [`DynamicsError::Invalid`], it does not panic or truncate.
    pub(crate) fn check_length(&self, what: &str, len: usize) -> Result<(), DynamicsError> {
        if len == self.n_q() {
            Ok(())
        } else {
            Err(DynamicsError::Invalid(format!(
                "{what} has {len} entries, but the mechanism has {} degrees of freedom",
                self.n_q()
            )))
        }
    }

    pub(crate) fn kinematics_at(
        &mut self,
        t: f64,
        q: &[f64],
        qd: Option<&[f64]>,
    ) -> Result<(), DynamicsError> {
        self.kin
            .solve(q, t)
            .map_err(|e| DynamicsError::Kinematics { t, source: e })?;
        self.kin.first_order();
        if let Some(qd) = qd {
            self.check_length("q̇", qd.len())?;
            if let Some(i) = qd.iter().position(|v| !v.is_finite()) {
                return Err(self.non_finite("q̇", qd, i, t));
            }
            self.kin.velocities(qd);
            self.kin.accelerations();
        }
        Ok(())
    }

    /// External nodal forces f (loads, gravity, controllers on nodal
    /// coordinates) and stress resultants σ (with damping and controllers on
    /// deformations; zero on rigid and prescribed deformations) at the current
    /// kinematic state. `with_rates`: include ε̇/ẋ terms (damping, D-action).
    pub(crate) fn forces(&mut self, t: f64, with_rates: bool) {
        self.forces_with(t, with_rates, true);
    }

    /// As [`forces`](Self::forces); without gravity in f when `gravity` is
    /// false (the nodal solve applies it as an acceleration field).
    pub(crate) fn forces_with(&mut self, t: f64, with_rates: bool, gravity: bool) {
        let mech = self.mech.clone();
        let x = self.kin.x();
        let eps = self.kin.eps();
        self.f.fill(0.0);
        let lf = self.load_factor * self.load_scale;
        for l in &mech.loads {
            match l {
                Load::Force { index, f, function } => {
                    let s = lf * function.value(t);
                    for (k, i) in index.iter().enumerate() {
                        self.f[*i] += f[k] * s;
                    }
                }
                Load::PlanarMoment { index, m, function } => {
                    self.f[*index] += lf * m * function.value(t)
                }
                Load::SpatialMoment { index, m, function } => {
                    let s = lf * function.value(t);
                    let lam = EulerParameters([x[index[0]], x[index[1]], x[index[2]], x[index[3]]]);
                    let lt = lam.lambda().transpose();
                    for a in 0..4 {
                        self.f[index[a]] +=
                            2.0 * s * (lt[(a, 0)] * m[0] + lt[(a, 1)] * m[1] + lt[(a, 2)] * m[2]);
                    }
                }
            }
        }
        if let (Some(g0), true) = (mech.gravity, gravity) {
            // the load scale of a load sweep does not scale gravity
            let g = g0.map(|v| v * self.load_factor);
            let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
            let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
            for e in &mech.elements {
                if !e.element.has_inertia() {
                    continue;
                }
                let n = e.x_index.len();
                for (k, gi) in e.x_index.iter().enumerate() {
                    xl[k] = x[*gi];
                }
                e.element.gravity_force(&xl[..n], &g, &mut fl[..n]);
                for (k, gi) in e.x_index.iter().enumerate() {
                    self.f[*gi] += fl[k];
                }
            }
        }
        // stresses
        let epsd = self.kin.epsd();
        for e in &mech.elements {
            let ne = e.element.n_eps();
            if ne == 0 {
                continue;
            }
            let o = e.eps_offset;
            let rate = if with_rates && e.element.damping().is_some() {
                Some(&epsd[o..o + ne])
            } else {
                None
            };
            e.element
                .stress(&eps[o..o + ne], rate, &mut self.sigma[o..o + ne]);
        }
        for c in &mech.controllers {
            let (r, rd, _) = c.reference.eval(t);
            match c.on {
                Coordinate::Node(i) => {
                    let v = if with_rates { self.kin.xd()[i] } else { 0.0 };
                    self.f[i] += c.kp * (r - x[i]) + if with_rates { c.kd * (rd - v) } else { 0.0 };
                }
                Coordinate::Def(j) => {
                    let v = if with_rates { epsd[j] } else { 0.0 };
                    self.sigma[j] -=
                        c.kp * (r - eps[j]) + if with_rates { c.kd * (rd - v) } else { 0.0 };
                }
            }
        }
        for (j, r) in mech.e_roles.iter().enumerate() {
            if matches!(r, ERole::Rigid | ERole::Input(_)) {
                self.sigma[j] = 0.0;
            }
        }
    }

    /// Assembles w = f − Mx ẍ0 − h and, if `mass`, Mq = F,qᵀ Mx F,q (D.10)
    /// element by element: Mq = Σ_e F_eᵀ M_e F_e with F_e the rows of F,q at
    /// the element's coordinates, restricted to the columns where F_e is not
    /// zero. With the factor M_e = R_eᵀR_e of co-rotational inertia
    /// (R_e = Ū B̂, (3.31)) the block is W_eᵀW_e, W_e = R_e F_e; only the lower
    /// triangle is accumulated, then mirrored.
    pub(crate) fn inertia(&mut self, mass: bool) {
        self.inertia_at(mass, None, None);
    }

    /// [`inertia`](Self::inertia)`(true)` that reads `stop` every
    /// [`STOP_CHECK_ELEMENTS`] elements of the mass assembly (the longest
    /// part of a linearization of a large model without a check: 0.17 s of
    /// the 0.5 s of the 1440-DOF chain's); `Interrupted` when it is set,
    /// with Mq left incomplete.
    pub(crate) fn inertia_until(&mut self, stop: Option<&AtomicBool>) -> Result<(), DynamicsError> {
        if self.inertia_at(true, None, stop) {
            Ok(())
        } else {
            Err(DynamicsError::Interrupted)
        }
    }

    /// As [`inertia`](Self::inertia), with the inertia forces of the nodal
    /// accelerations ẍ = ẍ0 + F,q q̈ when `qdd` is given: then `w` is
    /// f − Mx ẍ − h, and the generalized force F,qᵀw − E,qᵀσ is −(Mq q̈ −
    /// F,qᵀ(f − Mx ẍ0 − h) + E,qᵀσ), the residual of (D.10) without Mq.
    /// With `stop` set (read every [`STOP_CHECK_ELEMENTS`] elements while Mq
    /// is assembled) it ends early and returns false, Mq incomplete.
    fn inertia_at(&mut self, mass: bool, qdd: Option<&[f64]>, stop: Option<&AtomicBool>) -> bool {
        let mech = self.mech.clone();
        let n_q = mech.n_dof();
        let view = self.kin.first_order_view();
        let (x, xd, fq) = (view.x, view.xd, view.f);
        let xdd: &[f64] = match qdd {
            Some(qdd) => {
                self.xdd.copy_from_slice(view.xdd0);
                matmul(
                    MatMut::from_column_major_slice_mut(&mut self.xdd, fq.nrows(), 1),
                    Accum::Add,
                    fq.subcols(0, n_q),
                    MatRef::from_column_major_slice(qdd, n_q, 1),
                    1.0,
                    Par::Seq,
                );
                &self.xdd
            }
            None => view.xdd0,
        };
        self.w.copy_from_slice(&self.f);
        let mass = mass.then_some((&mut self.asm, fq.subcols(0, n_q), &mut self.mq));
        inertia_pass(&mech, (x, xd, xdd), &mut self.w, mass, stop)
    }

    /// rhs = F,qᵀ w − E,qᵀ σ.
    pub(crate) fn generalized_force(&mut self) {
        let n_q = self.mech.n_dof();
        let view = self.kin.first_order_view();
        let fq = view.f.subcols(0, n_q);
        let eq = view.e.subcols(0, n_q);
        let mut rhs = MatMut::from_column_major_slice_mut(&mut self.rhs, n_q, 1);
        let w = MatRef::from_column_major_slice(&self.w, self.w.len(), 1);
        let sigma = MatRef::from_column_major_slice(&self.sigma, self.sigma.len(), 1);
        matmul(
            rhs.as_mut(),
            Accum::Replace,
            fq.transpose(),
            w,
            1.0,
            Par::Seq,
        );
        matmul(rhs, Accum::Add, eq.transpose(), sigma, -1.0, Par::Seq);
    }

    /// The equations of motion (D.10) solved for q̈ at (t, q, q̇): one
    /// evaluation of the right-hand side of the integrators.
    ///
    /// Solved in nodal coordinates with multipliers for the constraint
    /// deformations (see the `nodal_eom` module): the same q̈ as the
    /// projection on the degrees of freedom
    /// ([`accelerations_by_projection`](Self::accelerations_by_projection)),
    /// without forming F,q or Mq. The position solve keeps the factorization
    /// of the kinematic Jacobian while chord steps converge fast, and the
    /// velocities are refined against the exact Jacobian. If the nodal
    /// system cannot be solved (a motion without inertia, dependent
    /// constraints) the projection is used, whose errors name the
    /// coordinates.
    pub fn accelerations(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.evaluations += 1;
        let n = self.n_q();
        self.check_length("q̈", qdd.len())?;
        if !self.nodal_accelerations(t, q, qd, &mut qdd[..n])? {
            return self.accelerations_by_projection(t, q, qd, qdd);
        }
        if let Some(i) = qdd[..n].iter().position(|v| !v.is_finite()) {
            return Err(self.non_finite_result("q̈", &qdd[..n], i, t));
        }
        Ok(())
    }

    /// q̈ by the nodal solve; false if that system is not solvable.
    pub(crate) fn nodal_accelerations(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<bool, DynamicsError> {
        let kin_err = |e| DynamicsError::Kinematics { t, source: e };
        self.kin.solve_chord(q, t).map_err(kin_err)?;
        self.check_length("q̇", qd.len())?;
        if let Some(i) = qd.iter().position(|v| !v.is_finite()) {
            return Err(self.non_finite("q̇", qd, i, t));
        }
        self.kin.velocities_refined(qd).map_err(kin_err)?;
        self.kin.convective_terms();
        self.forces_with(t, true, false);
        let g = self.mech.gravity.map(|g0| g0.map(|v| v * self.load_factor));
        Ok(self
            .nodal
            .accelerations(&self.kin, &self.mech, t, &self.f, &self.sigma, g, qdd)
            .is_ok())
    }

    /// The equations of motion (D.10) solved for q̈ by the projection on the
    /// degrees of freedom: Mq = F,qᵀMxF,q assembled element by element, its
    /// Cholesky factor in a preallocated buffer, two triangular solves. The
    /// reference for [`accelerations`](Self::accelerations) (which counts
    /// evaluations; this does not).
    pub fn accelerations_by_projection(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        self.generalized_force();
        let n = self.rhs.len();
        for c in 0..n {
            let (src, dst) = (self.mq.col_as_slice(c), self.llt.col_as_slice_mut(c));
            dst[c..].copy_from_slice(&src[c..]);
        }
        let stack = MemStack::new(&mut self.llt_mem);
        if cholesky_in_place(
            self.llt.as_mut(),
            Default::default(),
            Par::Seq,
            stack,
            Default::default(),
        )
        .is_err()
        {
            return Err(self.singular_mass());
        }
        let qdd = &mut qdd[..n];
        qdd.copy_from_slice(&self.rhs);
        faer::linalg::cholesky::llt::solve::solve_in_place(
            self.llt.as_ref(),
            MatMut::from_column_major_slice_mut(qdd, n, 1),
            Par::Seq,
            MemStack::new(&mut self.llt_mem),
        );
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(self.non_finite_result("q̈", qdd, i, t));
        }
        Ok(())
    }

    /// Mx v (element by element), added to `out` (length n_x).
    pub(crate) fn mass_times_add(&self, v: &[f64], out: &mut [f64]) {
        let x = self.kin.x();
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut ml = [0.0; flexmb_element::MAX_ELEMENT_COORDS * flexmb_element::MAX_ELEMENT_COORDS];
        for e in &self.mech.elements {
            if !e.element.has_inertia() {
                continue;
            }
            let n = e.x_index.len();
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = x[*gi];
            }
            e.element.mass_matrix(&xl[..n], &mut ml[..n * n]);
            for (a, ga) in e.x_index.iter().enumerate() {
                let row = &ml[a * n..a * n + n];
                out[*ga] += e
                    .x_index
                    .iter()
                    .zip(row)
                    .map(|(gb, m)| m * v[*gb])
                    .sum::<f64>();
            }
        }
    }

    /// The error for a mass matrix Mq that is not positive definite, naming
    /// the DOFs without inertia ([`crate::massless_dofs`]).
    fn singular_mass(&self) -> DynamicsError {
        DynamicsError::SingularMass {
            dofs: crate::massless_dofs(&self.mech, self.mq.as_ref()),
        }
    }

    /// The error for the DOF-sized `values` of `what`, whose entry `index`
    /// is the first that is not finite: names it and the next non-finite
    /// ones (up to three in all; an overflow in one DOF often spreads to
    /// others).
    pub(crate) fn non_finite(
        &self,
        what: &'static str,
        values: &[f64],
        index: usize,
        t: f64,
    ) -> DynamicsError {
        let bad: Vec<usize> = (index..values.len())
            .filter(|k| !values[*k].is_finite())
            .collect();
        DynamicsError::NonFinite {
            what,
            index,
            name: flexmb_model::list_some(&bad, |k| self.mech.dof_label(k)),
            t,
        }
    }

    /// The error for a non-finite result `what` (q̈, an initial q̇): the
    /// prescribed input, load or controller reference whose time function is
    /// not finite at t when there is one (the cause), else the DOFs.
    pub(crate) fn non_finite_result(
        &self,
        what: &'static str,
        values: &[f64],
        index: usize,
        t: f64,
    ) -> DynamicsError {
        let mech = &self.mech;
        let bad = |f: &flexmb_model::TimeFunction| {
            let (v, d, dd) = f.eval(t);
            (!(v.is_finite() && d.is_finite() && dd.is_finite()))
                .then(|| format!("its function gives value {v}, rate {d}, acceleration {dd}"))
        };
        let inputs = mech.inputs.iter().enumerate().filter_map(|(k, u)| {
            bad(&u.function).map(|m| {
                let name = format!("{} ({m})", mech.coordinate_name(u.target));
                ("prescribed input", k, name)
            })
        });
        let loads = mech.loads.iter().enumerate().filter_map(|(k, l)| {
            let (f, i) = match l {
                Load::Force {
                    function, index, ..
                } => (function, index[0]),
                Load::PlanarMoment {
                    function, index, ..
                } => (function, *index),
                Load::SpatialMoment {
                    function, index, ..
                } => (function, index[0]),
            };
            bad(f).map(|m| ("load", k, format!("{k} on {} ({m})", mech.x_names[i])))
        });
        let controllers = mech.controllers.iter().enumerate().filter_map(|(k, c)| {
            bad(&c.reference).map(|m| {
                let name = format!("the controller on {} ({m})", mech.coordinate_name(c.on));
                ("controller reference", k, name)
            })
        });
        match inputs.chain(loads).chain(controllers).next() {
            Some((what, index, name)) => DynamicsError::NonFinite {
                what,
                index,
                name,
                t,
            },
            None => self.non_finite(what, values, index, t),
        }
    }

    /// The residual g(q, q̇, q̈, t) = F,qᵀ(Mx ẍ − f) + E,qᵀσ of (E.1), with
    /// ẍ = ẍ0 + F,q q̈; it does not form Mq ([`mass_matrix`](Self::mass_matrix)
    /// is not updated).
    pub fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        g: &mut [f64],
    ) -> Result<(), DynamicsError> {
        self.check_length("q̈", qdd.len())?;
        self.check_length("g", g.len())?;
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        // Mq q̈ as F,qᵀ Mx F,q q̈ through the nodal accelerations: O(n_x n_q)
        // with a dense F,q, where forming Mq is O(n_x n_q²) (1 s per residual
        // on the 1440-DOF flexure chain)
        self.inertia_at(false, Some(qdd), None);
        self.generalized_force();
        for (gi, r) in g.iter_mut().zip(&self.rhs) {
            *gi = -r;
        }
        Ok(())
    }

    /// Scales the nodal loads (not gravity) by `s` in every later evaluation,
    /// statics and linearization: the parameter of a load sweep.
    pub fn set_load_scale(&mut self, s: f64) {
        self.load_scale = s;
    }

    /// Mq and the generalized force F,qᵀ(f − Mx ẍ0 − h) − E,qᵀσ at (t, q, q̇)
    /// with ẍ0 the accelerations for q̈ = 0: the pieces of (D.10) that a
    /// reduced model q = G(z) projects (thesis (6.15)).
    pub fn mass_and_force(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(&Mat<f64>, &[f64]), DynamicsError> {
        self.evaluations += 1;
        self.kinematics_at(t, q, Some(qd))?;
        self.forces(t, true);
        self.inertia(true);
        self.generalized_force();
        Ok((&self.mq, &self.rhs))
    }

    /// The mass matrix Mq of the last evaluation.
    pub fn mass_matrix(&self) -> &Mat<f64> {
        &self.mq
    }

    /// Energies at (q, q̇, t); an error naming the element at which an
    /// energy stops being finite (e.g. T = ½mv² overflowing for a velocity
    /// of 1e200), not a non-finite value.
    pub fn energies(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<Energies, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        let mech = self.mech.clone();
        let (x, xd, eps) = (self.kin.x(), self.kin.xd(), self.kin.eps());
        let mut en = Energies {
            gravity_exact: true,
            ..Default::default()
        };
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (index, e) in mech.elements.iter().enumerate() {
            let n = e.x_index.len();
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = x[*gi];
                vl[k] = xd[*gi];
            }
            if e.element.has_inertia() {
                en.kinetic += e.element.kinetic_energy(&xl[..n], &vl[..n]);
                if let Some(g) = mech.gravity {
                    match e.element.gravity_potential(&xl[..n], &g) {
                        Some(v) => en.gravitational += v,
                        None => en.gravity_exact = false,
                    }
                }
            }
            let ne = e.element.n_eps();
            if ne > 0 {
                let o = e.eps_offset;
                let rigid = (0..ne).all(|k| mech.e_roles[o + k] == ERole::Rigid);
                if !rigid {
                    en.elastic += e.element.elastic_energy(&eps[o..o + ne]);
                }
            }
            let sums = [
                ("kinetic energy", en.kinetic),
                ("elastic energy", en.elastic),
                ("gravitational potential", en.gravitational),
            ];
            if let Some((what, _)) = sums.iter().find(|(_, v)| !v.is_finite()) {
                return Err(DynamicsError::NonFinite {
                    what,
                    index,
                    name: format!("element '{}' (the sum up to it)", e.id),
                    t,
                });
            }
        }
        Ok(en)
    }

    /// Initial q̇ from the scene's initial nodal velocities (rigid-body fields),
    /// by least squares on F,q q̇ = ẋ0 − F,u u̇ at the configuration q0; an
    /// error naming the cause (an input whose rate is not finite, else the
    /// DOFs) when q̇ is not finite.
    pub fn initial_qd(&mut self, t: f64, q0: &[f64]) -> Result<Vec<f64>, DynamicsError> {
        let n_q = self.n_q();
        self.kinematics_at(t, q0, None)?;
        self.kin.velocities(&vec![0.0; n_q]);
        let view = self.kin.first_order_view();
        let f = view.f;
        let target: Vec<f64> = self
            .mech
            .initial_xd
            .iter()
            .zip(view.xd)
            .map(|(a, b)| a - b)
            .collect();
        let a = Mat::from_fn(n_q, n_q, |r, c| {
            f.col_as_slice(r)
                .iter()
                .zip(f.col_as_slice(c))
                .map(|(x, y)| x * y)
                .sum::<f64>()
        });
        let mut b = Mat::from_fn(n_q, 1, |r, _| {
            f.col_as_slice(r)
                .iter()
                .zip(&target)
                .map(|(x, y)| x * y)
                .sum::<f64>()
        });
        if n_q > 0 {
            let llt = a
                .llt(faer::Side::Lower)
                .map_err(|_| DynamicsError::Invalid("F,q is rank deficient".into()))?;
            llt.solve_in_place(b.as_mut());
        }
        let qd: Vec<f64> = (0..n_q).map(|i| b[(i, 0)]).collect();
        if let Some(i) = qd.iter().position(|v| !v.is_finite()) {
            return Err(self.non_finite_result("initial q̇", &qd, i, t));
        }
        Ok(qd)
    }

    /// Power of the external forces (loads, gravity, controllers) at (q, q̇, t):
    /// P = fᵀẋ − σ_cᵀε̇_c, whose time integral is the external work.
    pub fn external_power(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<f64, DynamicsError> {
        self.kinematics_at(t, q, Some(qd))?;
        let mech = self.mech.clone();
        // forces without element stresses: recompute and subtract the elastic part
        self.forces(t, true);
        let xd = self.kin.xd();
        let epsd = self.kin.epsd();
        let eps = self.kin.eps();
        let mut p: f64 = self.f.iter().zip(xd).map(|(a, b)| a * b).sum();
        // controller stresses on deformations do work; elastic/damping stresses are internal
        for c in &mech.controllers {
            if let Coordinate::Def(j) = c.on {
                let (r, rd, _) = c.reference.eval(t);
                p += (c.kp * (r - eps[j]) + c.kd * (rd - epsd[j])) * epsd[j];
            }
        }
        // inputs do work too (prescribed motion): their reaction is not known
        // here; report only the applied forces
        Ok(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixture;
    use flexmb_model::Scene;

    /// A spatial mechanism with every kind of spatial inertia: beams (one with
    /// B1, one with B2), a truss with mass, a point mass and a rigid body with
    /// an offset centre of mass.
    fn mixed_spatial() -> Scene {
        Scene::from_ron_str(
            r#"(
            dimension: Spatial,
            gravity: Some([0.0, 0.0, -9.81]),
            materials: { "m": (e: 2.1e11, nu: 0.3, rho: 7800.0) },
            sections: { "s": Rectangle(by: 0.02, bz: 0.004) },
            nodes: [
                (id: "A", at: [0.0, 0.0, 0.0]),
                (id: "B", at: [0.3, 0.0, 0.0]),
                (id: "C", at: [0.3, 0.2, 0.1]),
                (id: "D", at: [0.0, 0.2, 0.0]),
            ],
            elements: [
                (id: "b1", type: Beam((nodes: ("A", "B"), material: "m", section: "s", up: Some([0.0, 0.0, 1.0]), n: 2, transform: B1))),
                (id: "b2", type: Beam((nodes: ("B", "C"), material: "m", section: "s", up: Some([0.0, 0.0, 1.0]), transform: B2))),
                (id: "b3", type: Beam((nodes: ("C", "D"), material: "m", section: "s", up: Some([0.0, 0.0, 1.0])))),
                (id: "t", type: Truss(nodes: ("A", "C"), ea: 1.0e6, mass_per_length: 0.5)),
                (id: "pm", type: PointMass(node: "B", mass: 0.7)),
                (id: "rb", type: RigidBody(node: "D", mass: 1.3, com: Some([0.01, -0.02, 0.03]),
                    inertia: [[0.01, 0.001, 0.0], [0.001, 0.02, 0.0], [0.0, 0.0, 0.015]])),
            ],
            fixed: [Node("A")],
            rigid: [Def("b1", "elongation"), Def("b2", "elongation")],
        )"#,
        )
        .unwrap()
    }

    /// A configuration near the reference: q0 plus a few 1e-3 perturbations.
    fn off_reference(mech: &Mechanism) -> Vec<f64> {
        mech.q0()
            .iter()
            .enumerate()
            .map(|(i, v)| v + 1e-3 * ((i % 7) as f64 - 3.0))
            .collect()
    }

    /// A stop request ends the mass assembly inside its element loop with
    /// `Interrupted`, and the next assembly of the same `Dynamics` starts
    /// afresh: its Mq equals that of one never interrupted, bit for bit.
    #[test]
    fn an_interrupted_mass_assembly_leaves_no_trace_in_the_next() {
        let mech = Arc::new(mixed_spatial().build(None).unwrap());
        let q = off_reference(&mech);
        let mut clean = Dynamics::new(mech.clone());
        clean.kinematics_at(0.0, &q, None).unwrap();
        clean.forces(0.0, false);
        clean.inertia(true);
        let mut dy = Dynamics::new(mech.clone());
        dy.kinematics_at(0.0, &q, None).unwrap();
        dy.forces(0.0, false);
        // a first assembly, so that the interrupted one starts from a full Mq
        dy.inertia(true);
        let stop = AtomicBool::new(true);
        assert!(matches!(
            dy.inertia_until(Some(&stop)),
            Err(DynamicsError::Interrupted)
        ));
        assert!(!dy.inertia_at(true, None, Some(&stop)));
        stop.store(false, std::sync::atomic::Ordering::Relaxed);
        dy.inertia_until(Some(&stop)).unwrap();
        assert_eq!(dy.mq, clean.mq);
        assert!(dy.mq.norm_l2() > 0.0);
    }

    /// Mq and the generalized force against the plain formulas: a dense Mx from
    /// the element mass matrices, F,qᵀ Mx F,q, and F,qᵀ w − E,qᵀ σ.
    fn check_against_dense(scene: Scene) {
        let mech = Arc::new(scene.build(None).unwrap());
        let mut dy = Dynamics::new(mech.clone());
        let n = dy.n_q();
        let q = off_reference(&mech);
        let qd: Vec<f64> = (0..n).map(|i| 0.1 * ((i % 5) as f64 - 2.0)).collect();
        let (mq, rhs) = dy.mass_and_force(0.01, &q, &qd).unwrap();
        let (mq, rhs) = (mq.clone(), rhs.to_vec());
        let n_x = mech.n_x();
        let x = dy.kin.x().to_vec();
        let mut mx = Mat::<f64>::zeros(n_x, n_x);
        for e in &mech.elements {
            let k = e.x_index.len();
            let xl: Vec<f64> = e.x_index.iter().map(|i| x[*i]).collect();
            let mut ml = vec![0.0; k * k];
            e.element.mass_matrix(&xl, &mut ml);
            for (a, ga) in e.x_index.iter().enumerate() {
                for (b, gb) in e.x_index.iter().enumerate() {
                    mx[(*ga, *gb)] += ml[a * k + b];
                }
            }
        }
        let f = dy.kin.f_xi().subcols(0, n).to_owned();
        let reference = f.transpose() * &mx * &f;
        let scale = (0..n).fold(0.0f64, |m, i| m.max(reference[(i, i)].abs()));
        assert!(scale > 0.0);
        for r in 0..n {
            for c in 0..n {
                assert!(
                    (mq[(r, c)] - reference[(r, c)]).abs() <= 1e-12 * scale,
                    "Mq({r}, {c}) = {} vs {}",
                    mq[(r, c)],
                    reference[(r, c)]
                );
            }
        }
        let e = dy.kin.e_xi();
        for c in 0..n {
            let mut s = 0.0;
            let mut mag = 0.0f64;
            for i in 0..n_x {
                s += f[(i, c)] * dy.w[i];
                mag = mag.max((f[(i, c)] * dy.w[i]).abs());
            }
            for j in 0..dy.sigma.len() {
                s -= e[(j, c)] * dy.sigma[j];
                mag = mag.max((e[(j, c)] * dy.sigma[j]).abs());
            }
            assert!((rhs[c] - s).abs() <= 1e-12 * mag.max(1e-300), "rhs {c}");
        }
        // q̈ solves Mq q̈ = rhs
        let mut qdd = vec![0.0; n];
        dy.accelerations(0.01, &q, &qd, &mut qdd).unwrap();
        for r in 0..n {
            let s: f64 = (0..n).map(|c| reference[(r, c)] * qdd[c]).sum();
            let mag: f64 = (0..n)
                .map(|c| (reference[(r, c)] * qdd[c]).abs())
                .fold(rhs[r].abs(), f64::max);
            assert!(
                (s - rhs[r]).abs() <= 1e-9 * mag,
                "row {r}: {s} vs {}",
                rhs[r]
            );
        }
    }

    #[test]
    fn element_block_mass_matches_the_dense_product() {
        check_against_dense(fixture("straight_guidance_spatial.ron"));
        check_against_dense(fixture("straight_guidance_planar.ron"));
        check_against_dense(fixture("manipulator_planar.ron"));
        check_against_dense(mixed_spatial());
    }

    #[test]
    fn massless_degrees_of_freedom_are_named() {
        let scene = Scene::from_ron_str(
            r#"(
            dimension: Planar,
            materials: { "m": (e: 1.0e9, rho: 0.0) },
            sections: { "s": Circle(d: 0.01) },
            nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
            elements: [
                (id: "rod", type: Beam((nodes: ("A", "B"), material: "m", section: "s", mass: false))),
                (id: "bob", type: PointMass(node: "B", mass: 2.0)),
            ],
            fixed: [ Coord("A", Position) ],
        )"#,
        )
        .unwrap();
        let mut dy = Dynamics::new(Arc::new(scene.build(None).unwrap()));
        let n = dy.n_q();
        let mut qdd = vec![0.0; n];
        let q = dy.mechanism().q0();
        match dy.accelerations(0.0, &q, &vec![0.0; n], &mut qdd) {
            Err(DynamicsError::SingularMass { dofs }) => assert!(!dofs.is_empty(), "{dofs:?}"),
            other => panic!("expected SingularMass, got {other:?}"),
        }
    }
}
