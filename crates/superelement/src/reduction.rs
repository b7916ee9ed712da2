//! The constraint machinery shared by every static solve and eigen solve of the
//! builder.
//!
//! The *extended space* holds the FE equations, the 6 DOFs of each rigid-link
//! master and the 12 boundary coordinates µ̄. A problem (constraint modes,
//! warping modes, a clamped-free reference, …) is described by an expansion
//! u = E x + g: E maps the free unknowns x to the extended space (identity on
//! interior equations, rigid-body rows for link slaves and rigid interfaces,
//! the normal direction for a warping interface) and g holds prescribed values.
//! The free unknowns minimize the energy: (Eᵀ K E) x = −Eᵀ K g. Rigid interfaces
//! and links are thereby exact constraint transformations, not penalties.

use crate::model::{build_upper, sym_mul_add, FeModel};
use crate::Error;
use faer::sparse::SparseColMat;
use faer::{Mat, MatMut, MatRef};
use flexmb_linalg::{CholeskyError, SparseCholesky};

/// A dense mass block on a few extended indices (point masses).
#[derive(Clone, Debug)]
pub(crate) struct MassBlock {
    pub idx: Vec<usize>,
    /// Row-major idx.len() × idx.len().
    pub m: Vec<f64>,
}

/// K and M in the extended space: the FE matrices on the first `n_eq` entries,
/// point-mass blocks anywhere, nothing else.
pub(crate) struct ExtOps<'a> {
    pub model: &'a FeModel,
    pub n_ext: usize,
    pub masses: Vec<MassBlock>,
}

impl ExtOps<'_> {
    pub fn apply_k(&self, x: MatRef<'_, f64>, mut y: MatMut<'_, f64>) {
        let n = self.model.n_eq();
        y.fill(0.0);
        sym_mul_add(
            self.model.k(),
            x.subrows(0, n),
            y.as_mut().subrows_mut(0, n),
        );
    }
    pub fn apply_m(&self, x: MatRef<'_, f64>, mut y: MatMut<'_, f64>) {
        let n = self.model.n_eq();
        y.fill(0.0);
        sym_mul_add(
            self.model.m(),
            x.subrows(0, n),
            y.as_mut().subrows_mut(0, n),
        );
        for b in &self.masses {
            let s = b.idx.len();
            for c in 0..x.ncols() {
                for (r, &i) in b.idx.iter().enumerate() {
                    let mut acc = 0.0;
                    for (q, &j) in b.idx.iter().enumerate() {
                        acc += b.m[r * s + q] * x[(j, c)];
                    }
                    y[(i, c)] += acc;
                }
            }
        }
    }
    /// Aᵀ K_ext B for extended vectors (dense, small).
    pub fn k_form(&self, a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
        let mut kb = Mat::<f64>::zeros(self.n_ext, b.ncols());
        self.apply_k(b, kb.as_mut());
        a.transpose() * kb
    }
    /// Aᵀ M_ext B for extended vectors (dense, small).
    pub fn m_form(&self, a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
        let mut mb = Mat::<f64>::zeros(self.n_ext, b.ncols());
        self.apply_m(b, mb.as_mut());
        a.transpose() * mb
    }
}

/// u = E x: a sparse map from the free unknowns to the extended space, stored by
/// extended row.
#[derive(Clone, Debug)]
pub(crate) struct Expansion {
    ptr: Vec<usize>,
    idx: Vec<usize>,
    coef: Vec<f64>,
    pub n_free: usize,
}

impl Expansion {
    /// Starts an expansion over `n_ext` rows; rows are filled in order with
    /// [`Expansion::push_row`].
    pub fn with_capacity(n_ext: usize) -> Self {
        let mut ptr = Vec::with_capacity(n_ext + 1);
        ptr.push(0);
        Self {
            ptr,
            idx: Vec::with_capacity(n_ext),
            coef: Vec::with_capacity(n_ext),
            n_free: 0,
        }
    }
    /// Appends the next extended row.
    pub fn push_row(&mut self, entries: &[(usize, f64)]) {
        for &(j, c) in entries {
            if c != 0.0 {
                self.idx.push(j);
                self.coef.push(c);
                self.n_free = self.n_free.max(j + 1);
            }
        }
        self.ptr.push(self.idx.len());
    }
    pub fn n_ext(&self) -> usize {
        self.ptr.len() - 1
    }
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let (a, b) = (self.ptr[r], self.ptr[r + 1]);
        self.idx[a..b]
            .iter()
            .copied()
            .zip(self.coef[a..b].iter().copied())
    }
    /// E x.
    pub fn expand(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let mut u = Mat::<f64>::zeros(self.n_ext(), x.ncols());
        for r in 0..self.n_ext() {
            for (j, c) in self.row(r) {
                for k in 0..x.ncols() {
                    u[(r, k)] += c * x[(j, k)];
                }
            }
        }
        u
    }
    /// Eᵀ y.
    pub fn restrict(&self, y: MatRef<'_, f64>) -> Mat<f64> {
        let mut x = Mat::<f64>::zeros(self.n_free, y.ncols());
        for r in 0..self.n_ext() {
            for (j, c) in self.row(r) {
                for k in 0..y.ncols() {
                    x[(j, k)] += c * y[(r, k)];
                }
            }
        }
        x
    }
    /// Eᵀ A E for the FE matrix `a` (upper triangle over the first rows), upper triangle.
    pub fn project(
        &self,
        a: faer::sparse::SparseColMatRef<'_, usize, f64>,
    ) -> Result<SparseColMat<usize, f64>, Error> {
        let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(a.compute_nnz() + self.n_free);
        for b in 0..a.ncols() {
            for (&ai, &v) in a.row_idx_of_col_raw(b).iter().zip(a.val_of_col(b)) {
                if v == 0.0 {
                    continue;
                }
                for (ja, ca) in self.row(ai) {
                    for (jb, cb) in self.row(b) {
                        let w = ca * cb * v;
                        if ai == b {
                            if ja <= jb {
                                trip.push((ja, jb, w));
                            }
                        } else if ja == jb {
                            trip.push((ja, jb, 2.0 * w));
                        } else {
                            trip.push((ja.min(jb), ja.max(jb), w));
                        }
                    }
                }
            }
        }
        build_upper(self.n_free, trip)
    }
}

/// A factorized problem: expansion, projected stiffness and its Cholesky factor.
pub(crate) struct Problem {
    pub e: Expansion,
    pub k_ff: SparseColMat<usize, f64>,
    pub llt: SparseCholesky,
}

impl Problem {
    /// Projects and factorizes; `describe` names a free unknown for messages.
    pub fn new(
        e: Expansion,
        model: &FeModel,
        describe: &dyn Fn(usize) -> String,
    ) -> Result<Self, Error> {
        let k_ff = e.project(model.k())?;
        // a free unknown with no stiffness at all is detached
        let mut diag = vec![0.0f64; e.n_free];
        for j in 0..k_ff.ncols() {
            for (&i, &v) in k_ff.row_idx_of_col_raw(j).iter().zip(k_ff.val_of_col(j)) {
                if i == j {
                    diag[j] = v;
                }
            }
        }
        if let Some(j) = diag.iter().position(|&d| d < 0.0) {
            return Err(Error::NotPositiveSemiDefinite(format!(
                "the stiffness on {} is {:e} < 0",
                describe(j),
                diag[j]
            )));
        }
        if let Some(j) = diag.iter().position(|&d| d == 0.0) {
            return Err(Error::NotAttached(format!(
                "{} has no stiffness at all (not connected to any element)",
                describe(j)
            )));
        }
        let llt = match SparseCholesky::factor(k_ff.as_ref()) {
            Ok(l) => l,
            Err(CholeskyError::NonPositivePivot { index: j }) => {
                return Err(Error::NotPositiveSemiDefinite(format!(
                    "the Cholesky factorization of the interior stiffness broke down at {} (a zero or negative pivot): \
                     K is indefinite there, or that region is a mechanism / not attached to an interface",
                    describe(j)
                )))
            }
            Err(e) => return Err(e.into()),
        };
        let (ratio, j) = llt.min_pivot_ratio(k_ff.as_ref());
        if ratio < 1e-13 {
            return Err(Error::NotAttached(format!(
                "the interior stiffness is numerically singular (pivot ratio {ratio:.1e}) at {}: a region that can move \
                 rigidly without loading the interfaces",
                describe(j)
            )));
        }
        Ok(Self { e, k_ff, llt })
    }

    /// Solves for the free unknowns with prescribed extended vectors `g`
    /// (n_ext × k) and returns the full extended solutions g + E x; one step of
    /// iterative refinement.
    pub fn solve(&self, ops: &ExtOps<'_>, g: MatRef<'_, f64>) -> Mat<f64> {
        let mut kg = Mat::<f64>::zeros(ops.n_ext, g.ncols());
        ops.apply_k(g, kg.as_mut());
        let b = -self.e.restrict(kg.as_ref());
        let x = self.solve_ff(b.as_ref());
        let mut u = self.e.expand(x.as_ref());
        u += g;
        u
    }

    /// K_ff⁻¹ b with one refinement step.
    pub fn solve_ff(&self, b: MatRef<'_, f64>) -> Mat<f64> {
        let mut x = b.to_owned();
        self.llt.solve_in_place(x.as_mut());
        for _ in 0..1 {
            let mut r = b.to_owned();
            let mut kx = Mat::<f64>::zeros(b.nrows(), b.ncols());
            sym_mul_add(self.k_ff.as_ref(), x.as_ref(), kx.as_mut());
            r -= &kx;
            self.llt.solve_in_place(r.as_mut());
            x += &r;
        }
        x
    }
}
