//! Elements on nodes that start rotated: the constant change of coordinates
//! that measures an element's orientation slots from their initial
//! orientations.
//!
//! Every element is written for nodes whose orientation is the identity in
//! the reference configuration: its frames are the global axes turned by
//! R(λ) (thesis (2.10)), so it is undeformed when λ = (1, 0, 0, 0). A node
//! that starts in the orientation λ₀ instead has λ = λ₀ in the reference
//! configuration. The element then sees
//!
//! * spatial: λ' = λ ∘ λ₀* (R(λ') = R(λ) R(λ₀)ᵀ, the rotation since the
//!   start), a linear map λ' = Q λ with Q orthogonal (4 × 4), so that
//!   λ'ᵀλ' = λᵀλ and the normalization (2.9) is unchanged;
//! * planar: φ' = φ − φ₀.
//!
//! With x' = T x + c (T block diagonal: the identity on positions and mode
//! amplitudes, Q on each rotated orientation slot) every quantity of the
//! element follows from its values at x' by the chain rule, exactly:
//! D,x = D',x' T; D,xx\[a, b\] = D',x'x'\[T a, T b\]; M = Tᵀ M' T;
//! F = Tᵀ F'(x', T ẋ, T ẍ); a mass factor R = R' T. Only elements on a rotated
//! node carry the map, so the others pay nothing.

use crate::custom::MAX_ELEMENT_COORDS;
use crate::Slot;

/// A 4 × 3 velocity basis of an orientation slot (λ̇ = P a).
type Basis = [[f64; 3]; 4];

/// The most orientation slots an element can have.
pub(crate) const MAX_ORIENTATION_SLOTS: usize = MAX_ELEMENT_COORDS / 4;
use flexmb_rotation::generic::compose;

/// One rotated orientation slot.
#[derive(Clone, Debug, PartialEq)]
enum Block {
    /// A planar angle at local index `at`: φ' = φ − φ₀.
    Angle { at: usize, phi0: f64 },
    /// Euler parameters at local indices `at..at + 4`: λ' = Q λ (row-major).
    Euler { at: usize, q: [[f64; 4]; 4] },
}

/// The map x' = T x + c of an element whose orientation slots start rotated.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct InitialFrames {
    blocks: Vec<Block>,
}

/// A local coordinate vector on the stack (no allocation per evaluation),
/// read as the slice of its first `n` entries.
pub(crate) struct Local {
    buf: [f64; MAX_ELEMENT_COORDS],
    n: usize,
}

impl std::ops::Deref for Local {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.buf[..self.n]
    }
}

impl InitialFrames {
    /// No rotated slot yet.
    pub fn new() -> Self {
        Self { blocks: vec![] }
    }

    /// The planar angle slot at `at` starts at φ₀.
    pub fn push_angle(&mut self, at: usize, phi0: f64) {
        self.blocks.push(Block::Angle { at, phi0 });
    }

    /// The Euler-parameter slot at `at` starts at the unit λ₀: Q with
    /// Q λ = λ ∘ λ₀*, column i being eᵢ ∘ λ₀*.
    pub fn push_euler(&mut self, at: usize, lambda0: [f64; 4]) {
        let conj = [lambda0[0], -lambda0[1], -lambda0[2], -lambda0[3]];
        let mut q = [[0.0; 4]; 4];
        for i in 0..4 {
            let mut e = [0.0; 4];
            e[i] = 1.0;
            let col = compose(&e, &conj);
            for r in 0..4 {
                q[r][i] = col[r];
            }
        }
        self.blocks.push(Block::Euler { at, q });
    }

    /// Whether the slot at local index `at` is already rotated.
    pub fn has(&self, at: usize) -> bool {
        self.blocks.iter().any(|b| match b {
            Block::Angle { at: a, .. } | Block::Euler { at: a, .. } => *a == at,
        })
    }

    /// Whether no slot is rotated.
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// x' = T x + c (the first `x.len()` entries of the result).
    pub fn point(&self, x: &[f64]) -> Local {
        let mut out = self.direction(x);
        for b in &self.blocks {
            if let Block::Angle { at, phi0 } = b {
                out.buf[*at] -= phi0;
            }
        }
        out
    }

    /// a' = T a: a direction (velocity, acceleration, perturbation).
    pub fn direction(&self, a: &[f64]) -> Local {
        let mut buf = [0.0; MAX_ELEMENT_COORDS];
        buf[..a.len()].copy_from_slice(a);
        for b in &self.blocks {
            if let Block::Euler { at, q } = b {
                let v: [f64; 4] = std::array::from_fn(|k| a[at + k]);
                for r in 0..4 {
                    buf[at + r] = (0..4).map(|k| q[r][k] * v[k]).sum();
                }
            }
        }
        Local { buf, n: a.len() }
    }

    /// m ← m T for a row-major `rows × nx` matrix (a Jacobian or a mass
    /// factor): each row is mapped by Tᵀ.
    pub fn right(&self, m: &mut [f64], rows: usize, nx: usize) {
        for b in &self.blocks {
            if let Block::Euler { at, q } = b {
                for r in 0..rows {
                    let row = &mut m[r * nx + at..r * nx + at + 4];
                    let v: [f64; 4] = std::array::from_fn(|k| row[k]);
                    for (j, out) in row.iter_mut().enumerate() {
                        *out = (0..4).map(|k| v[k] * q[k][j]).sum();
                    }
                }
            }
        }
    }

    /// m ← Tᵀ m for a row-major `nx × cols` matrix (a force when
    /// `cols` = 1).
    pub fn left_transposed(&self, m: &mut [f64], cols: usize) {
        for b in &self.blocks {
            if let Block::Euler { at, q } = b {
                for c in 0..cols {
                    let v: [f64; 4] = std::array::from_fn(|k| m[(at + k) * cols + c]);
                    for j in 0..4 {
                        m[(at + j) * cols + c] = (0..4).map(|k| q[k][j] * v[k]).sum();
                    }
                }
            }
        }
    }

    /// m ← Tᵀ m T for a row-major `nx × nx` matrix (mass, stiffness-like
    /// derivatives).
    pub fn congruence(&self, m: &mut [f64], nx: usize) {
        self.left_transposed(m, nx);
        self.right(m, nx, nx);
    }

    /// The 4 × 3 velocity bases P of the orientation slots (in slot order,
    /// as [`Element::mass_matrix_with_bases`](crate::Element::mass_matrix_with_bases)
    /// takes them) mapped to Q P, the bases of λ̇' = Q λ̇, written to `out`
    /// (no allocation); returns how many were written.
    pub fn bases(
        &self,
        bases: &[Option<Basis>],
        slots: &[Slot],
        out: &mut [Option<Basis>; MAX_ORIENTATION_SLOTS],
    ) -> usize {
        let mut at = 0;
        let mut k = 0;
        for s in slots {
            if *s == Slot::Orientation && k < bases.len() {
                let q = self.blocks.iter().find_map(|b| match b {
                    Block::Euler { at: a, q } if *a == at => Some(q),
                    _ => None,
                });
                out[k] = match (bases[k], q) {
                    (Some(p), Some(q)) => Some(std::array::from_fn(|r| {
                        std::array::from_fn(|c| (0..4).map(|i| q[r][i] * p[i][c]).sum())
                    })),
                    (p, _) => p,
                };
                k += 1;
            }
            at += s.len();
        }
        k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(v: [f64; 4]) -> [f64; 4] {
        let n = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        v.map(|a| a / n)
    }

    #[test]
    fn q_composes_with_the_conjugate_and_is_orthogonal() {
        let l0 = unit([0.3, -0.5, 0.7, 0.2]);
        let mut f = InitialFrames::new();
        f.push_euler(0, l0);
        // λ₀ itself maps to the identity
        let id = f.point(&l0);
        for (k, want) in [1.0, 0.0, 0.0, 0.0].iter().enumerate() {
            assert!((id[k] - want).abs() < 1e-15, "{:?}", &id[..]);
        }
        // any λ maps to λ ∘ λ₀*
        let l = unit([-0.1, 0.4, 0.2, 0.9]);
        let want = compose(&l, &[l0[0], -l0[1], -l0[2], -l0[3]]);
        let got = f.point(&l);
        for k in 0..4 {
            assert!((got[k] - want[k]).abs() < 1e-15);
        }
        // QᵀQ = I: Tᵀ(T a) = a
        let a = [0.3, 1.0, -2.0, 0.5];
        let mut ta = f.direction(&a)[..4].to_vec();
        f.left_transposed(&mut ta, 1);
        for k in 0..4 {
            assert!((ta[k] - a[k]).abs() < 1e-15);
        }
    }
}
