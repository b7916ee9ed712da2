//! The dense reference choice of DOFs (thesis (6.4)): one SVD of the
//! constraint Jacobian at the reference configuration, greedy Gram–Schmidt on
//! its null space, and the SVD's names of redundant equations and
//! undetermined coordinates.

use super::*;

fn dense_of(rows: &[Vec<(usize, f64)>], m: usize, n: usize) -> Mat<f64> {
    let mut j = Mat::<f64>::zeros(m, n);
    for (r, row) in rows.iter().enumerate() {
        for (c, v) in row {
            j[(r, *c)] = *v;
        }
    }
    j
}

/// Relative singular-value threshold of the numerical rank.
pub(crate) const RANK_TOL: f64 = 1e-9;

/// Rank and null spaces of a (row-normalized) matrix: (rank, left null
/// vectors as columns, right null space as columns), from the SVD of
/// [`flexmb_linalg::svd`] (which falls back to other methods where faer's
/// does not converge). `what` names the matrix in the error.
pub(super) fn null_spaces(
    a: &Mat<f64>,
    what: &str,
) -> Result<(usize, Mat<f64>, Mat<f64>), ModelError> {
    let (m, n) = (a.nrows(), a.ncols());
    let d = flexmb_linalg::svd(a.as_ref()).map_err(|source| ModelError::Computation {
        what: format!("choosing the degrees of freedom: {what}"),
        source,
    })?;
    let r = d.rank(RANK_TOL);
    let left = Mat::from_fn(m, m - r, |i, j| d.u[(i, r + j)]);
    let right = Mat::from_fn(n, n - r, |i, j| d.v[(i, r + j)]);
    Ok((r, left, right))
}

pub(super) fn names_in(vectors: &Mat<f64>, names: &[String]) -> Vec<String> {
    let mut out = vec![];
    for j in 0..vectors.ncols() {
        let mx = (0..vectors.nrows())
            .map(|i| vectors[(i, j)].abs())
            .fold(0.0f64, f64::max);
        for i in 0..vectors.nrows() {
            if vectors[(i, j)].abs() > 0.2 * mx && !out.contains(&names[i]) {
                out.push(names[i].clone());
            }
        }
    }
    out
}

/// Greedy Gram–Schmidt on the null space of the whole constraint Jacobian
/// (one dense SVD): the original method, the reference for the sparse one.
struct Dense<'p, 'a> {
    p: &'p Problem<'a>,
    jac: Mat<f64>,
    null: Mat<f64>,
    basis: Vec<Vec<f64>>,
}

/// Gram–Schmidt acceptance of `g` against an orthonormal `basis`.
fn accept_gs(g: Vec<f64>, basis: &mut Vec<Vec<f64>>) -> bool {
    let n0 = g.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n0 < 1e-12 {
        return false;
    }
    let mut r = g;
    for _ in 0..2 {
        for b in basis.iter() {
            let p: f64 = r.iter().zip(b).map(|(a, c)| a * c).sum();
            for (ri, bi) in r.iter_mut().zip(b) {
                *ri -= p * bi;
            }
        }
    }
    let nr = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    if accepted(nr, || n0) {
        basis.push(r.into_iter().map(|v| v / nr).collect());
        true
    } else {
        false
    }
}

impl<'p, 'a> Dense<'p, 'a> {
    fn new(p: &'p Problem<'a>) -> Result<(Self, usize), ModelError> {
        check_dense("the deformation Jacobian", p.mech.n_eps(), p.mech.n_x(), 1)?;
        check_dense("the constraint Jacobian", p.crow.len(), p.free.len(), 2)?;
        check_dense("the null space", p.free.len(), p.free.len(), 2)?;
        let jac = dense_of(&p.rows, p.mech.n_eps(), p.mech.n_x());
        let free = &p.free;
        let crow = &p.crow;
        let c = Mat::from_fn(crow.len(), free.len(), |r, c| {
            let nrm = free
                .iter()
                .map(|fc| jac[(crow[r], *fc)].powi(2))
                .sum::<f64>()
                .sqrt();
            if nrm > 0.0 {
                jac[(crow[r], free[c])] / nrm
            } else {
                0.0
            }
        });
        let (rank, left, null) =
            null_spaces(&c, "the constraint Jacobian on the free coordinates")?;
        if rank < crow.len() {
            let names: Vec<String> = crow.iter().map(|j| p.mech.eps_names[*j].clone()).collect();
            return Err(ModelError::OverConstrained {
                redundant: names_in(&left, &names),
            });
        }
        let d = null.ncols();
        Ok((
            Dense {
                p,
                jac,
                null,
                basis: vec![],
            },
            d,
        ))
    }

    fn under_constrained(&mut self, chosen: usize) -> ModelError {
        let d = self.null.ncols();
        let mut rest = vec![];
        for k in 0..d {
            let mut e = vec![0.0; d];
            e[k] = 1.0;
            let before = self.basis.len();
            if accept_gs(e, &mut self.basis) {
                rest.push(self.basis[before].clone());
            }
        }
        let null = &self.null;
        let m = Mat::from_fn(self.p.free.len(), rest.len(), |i, j| {
            (0..d).map(|k| null[(i, k)] * rest[j][k]).sum()
        });
        let names: Vec<String> = self
            .p
            .free
            .iter()
            .map(|i| self.p.mech.x_names[*i].clone())
            .collect();
        ModelError::UnderConstrained {
            count: d - chosen,
            undetermined: names_in(&m, &names),
        }
    }
}

impl Oracle for Dense<'_, '_> {
    fn accept(&mut self, c: Coordinate) -> bool {
        let (p, jac, null) = (self.p, &self.jac, &self.null);
        let d = null.ncols();
        let g: Vec<f64> = match c {
            Coordinate::Node(i) => (0..d).map(|k| null[(p.free_pos[i], k)]).collect(),
            Coordinate::Def(j) => {
                let nrm = p
                    .free
                    .iter()
                    .map(|fc| jac[(j, *fc)].powi(2))
                    .sum::<f64>()
                    .sqrt()
                    .max(1e-300);
                (0..d)
                    .map(|k| {
                        (0..p.free.len())
                            .map(|c| jac[(j, p.free[c])] / nrm * null[(c, k)])
                            .sum()
                    })
                    .collect()
            }
        };
        accept_gs(g, &mut self.basis)
    }
}

/// The choice of DOFs with the dense method.
pub(super) fn choose_dense(scene: &Scene, p: &Problem) -> Result<Vec<Coordinate>, ModelError> {
    let (mut dense, d) = Dense::new(p)?;
    let chosen = greedy(scene, p, d, &mut dense)?;
    if chosen.len() < d {
        return Err(dense.under_constrained(chosen.len()));
    }
    Ok(chosen)
}
