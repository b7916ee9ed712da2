//! Dense LU factorization with partial pivoting on preallocated storage.
//!
//! A thin wrapper over faer's in-place routines, so that refactorizations
//! and solves inside the step loop do not allocate.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Mat, MatMut, Par};

/// Reusable LU workspace of fixed dimension.
pub(crate) struct DenseLu {
    n: usize,
    lu: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    valid: bool,
}

impl DenseLu {
    pub(crate) fn new(n: usize) -> Self {
        let req = factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default())
            .or(solve::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq));
        Self {
            n,
            lu: Mat::zeros(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            mem: MemBuffer::new(req.or(StackReq::EMPTY)),
            valid: false,
        }
    }

    /// The matrix to be factored; fill it, then call [`DenseLu::factor`].
    pub(crate) fn matrix_mut(&mut self) -> MatMut<'_, f64> {
        self.valid = false;
        self.lu.as_mut()
    }

    /// Factors the matrix in place. Returns `false` if it is singular (a zero
    /// or non-finite pivot); the factorization is then unusable.
    pub(crate) fn factor(&mut self) -> bool {
        let stack = MemStack::new(&mut self.mem);
        factor::lu_in_place(
            self.lu.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
        self.valid = (0..self.n).all(|i| {
            let d = self.lu[(i, i)];
            d != 0.0 && d.is_finite()
        });
        self.valid
    }

    /// Solves `A x = b` in place (`x` holds `b` on entry).
    pub(crate) fn solve_in_place(&mut self, x: &mut [f64]) {
        debug_assert!(self.valid);
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, self.n);
        let rhs = MatMut::from_column_major_slice_mut(x, self.n, 1);
        let stack = MemStack::new(&mut self.mem);
        solve::solve_in_place(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            rhs,
            Par::Seq,
            stack,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_small_system() {
        let mut lu = DenseLu::new(3);
        {
            let mut a = lu.matrix_mut();
            let vals = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
            for i in 0..3 {
                for j in 0..3 {
                    a[(i, j)] = vals[i][j];
                }
            }
        }
        assert!(lu.factor());
        // x = (1, 2, 3): b = A x
        let mut x = [7.0, 3.0, 6.0];
        lu.solve_in_place(&mut x);
        for (xi, ei) in x.iter().zip([1.0, 2.0, 3.0]) {
            assert!((xi - ei).abs() < 1e-14);
        }
    }

    #[test]
    fn detects_singular() {
        let mut lu = DenseLu::new(2);
        {
            let mut a = lu.matrix_mut();
            a[(0, 0)] = 1.0;
            a[(0, 1)] = 2.0;
            a[(1, 0)] = 2.0;
            a[(1, 1)] = 4.0;
        }
        assert!(!lu.factor());
    }
}
