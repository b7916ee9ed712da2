//! The tangents of a held equilibrium: how its configuration moves with the
//! DOFs that hold it. At an equilibrium g_s(q) = 0 of the free DOFs f with
//! the held DOFs h prescribed, differentiating g_s,f along h gives
//! K_ff ∂q_f/∂q_h + K_fh = 0 with K the tangent stiffness there, so
//! ∂q_f/∂q_h = −K_ff⁻¹ K_fh and ∂q_h/∂q_h = I: the static modes of the held
//! DOFs. They are the derivatives of the equilibrium path (surface) that an
//! interpolated basis's Q(s) runs through (thesis (6.23)), and so the exact
//! Q,s at its reference configurations ([`crate::GridBasis::with_tangents`]).

use crate::ReductionError;
use faer::prelude::Solve;
use faer::{Mat, MatRef};

/// The tangents ∂q/∂q_h (n_q × held.len(), column k for held DOF
/// `held[k]`) of the equilibrium whose tangent stiffness is `k` (n_q × n_q,
/// such as [`flexmb_dynamics::Linearization::stiffness_total`] at rest),
/// with the DOFs `held` prescribed.
///
/// # Errors
///
/// [`ReductionError::Invalid`] naming the culprit for a non-square or
/// non-finite `k`, held indices out of range or repeated, or a free part
/// K_ff so near singular that the solve leaves a residual above 1e-8 of
/// the load (the free DOFs are not held: a mechanism or a buckled state).
pub fn equilibrium_tangents(
    k: MatRef<'_, f64>,
    held: &[usize],
) -> Result<Mat<f64>, ReductionError> {
    let n = k.nrows();
    if k.ncols() != n {
        return Err(ReductionError::Invalid(format!(
            "equilibrium tangents: the stiffness is {} × {}, not square",
            n,
            k.ncols()
        )));
    }
    if let Some(h) = held.iter().find(|h| **h >= n) {
        return Err(ReductionError::Invalid(format!(
            "equilibrium tangents: held DOF {h} of {n}"
        )));
    }
    if let Some(h) = held
        .iter()
        .enumerate()
        .find(|(i, h)| held[..*i].contains(h))
    {
        return Err(ReductionError::Invalid(format!(
            "equilibrium tangents: DOF {} held twice",
            h.1
        )));
    }
    if let Some((i, j)) = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .find(|(i, j)| !k[(*i, *j)].is_finite())
    {
        return Err(ReductionError::Invalid(format!(
            "equilibrium tangents: stiffness entry ({i}, {j}) is not finite"
        )));
    }
    let free: Vec<usize> = (0..n).filter(|i| !held.contains(i)).collect();
    let kff = Mat::from_fn(free.len(), free.len(), |a, b| k[(free[a], free[b])]);
    let load = Mat::from_fn(free.len(), held.len(), |a, c| -k[(free[a], held[c])]);
    let x = kff.partial_piv_lu().solve(&load);
    let residual = &kff * &x - &load;
    let scale = load.norm_max().max(f64::MIN_POSITIVE);
    let bad = residual.norm_max().partial_cmp(&(1e-8 * scale)) != Some(std::cmp::Ordering::Less)
        || (0..held.len()).any(|c| (0..free.len()).any(|a| !x[(a, c)].is_finite()));
    if bad {
        return Err(ReductionError::Invalid(format!(
            "equilibrium tangents: the stiffness of the {} free DOFs is singular (relative \
             residual {:.1e}): holding DOFs {held:?} leaves a mechanism or a buckled state",
            free.len(),
            residual.norm_max() / scale
        )));
    }
    let mut t = Mat::zeros(n, held.len());
    for (c, &h) in held.iter().enumerate() {
        t[(h, c)] = 1.0;
        for (a, &i) in free.iter().enumerate() {
            t[(i, c)] = x[(a, c)];
        }
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of springs k1 … k4 from the ground through DOFs 0, 1, 2, 3;
    /// holding DOF 1 at u: DOF 0 sits at u k2/(k1 + k2) (the two springs
    /// share the displacement), DOFs 2 and 3 follow rigidly (nothing pulls
    /// them back), so the tangent is (k2/(k1 + k2), 1, 1, 1).
    fn chain() -> Mat<f64> {
        let s = [3.0, 5.0, 7.0, 11.0];
        Mat::from_fn(4, 4, |i, j| {
            if i == j {
                s[i] + if i + 1 < 4 { s[i + 1] } else { 0.0 }
            } else if i + 1 == j || j + 1 == i {
                -s[i.max(j)]
            } else {
                0.0
            }
        })
    }

    #[test]
    fn the_tangents_of_a_spring_chain_are_its_static_modes() {
        let t = equilibrium_tangents(chain().as_ref(), &[1]).unwrap();
        let e = [5.0 / 8.0, 1.0, 1.0, 1.0];
        for i in 0..4 {
            assert!((t[(i, 0)] - e[i]).abs() < 1e-14, "DOF {i}: {}", t[(i, 0)]);
        }
        // two held DOFs: each column is zero on the other held DOF
        let t = equilibrium_tangents(chain().as_ref(), &[1, 3]).unwrap();
        assert_eq!((t[(3, 0)], t[(1, 1)]), (0.0, 0.0));
        // DOF 2 between held 1 and 3: k3 u1/(k3 + k4) and k4 u3/(k3 + k4)
        assert!((t[(2, 0)] - 7.0 / 18.0).abs() < 1e-14);
        assert!((t[(2, 1)] - 11.0 / 18.0).abs() < 1e-14);
    }

    #[test]
    fn bad_input_is_refused_with_the_culprit() {
        let k = chain();
        let msg = |r: Result<Mat<f64>, ReductionError>| r.unwrap_err().to_string();
        assert!(msg(equilibrium_tangents(k.as_ref(), &[4])).contains("held DOF 4 of 4"));
        assert!(msg(equilibrium_tangents(k.as_ref(), &[1, 1])).contains("DOF 1 held twice"));
        let rect = Mat::<f64>::zeros(3, 4);
        assert!(msg(equilibrium_tangents(rect.as_ref(), &[0])).contains("not square"));
        let mut nan = chain();
        nan[(2, 3)] = f64::NAN;
        assert!(msg(equilibrium_tangents(nan.as_ref(), &[0])).contains("entry (2, 3)"));
        // the end spring removed: holding DOF 0 leaves 1–3 free to float
        let mut floating = chain();
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            floating[(i, j)] -= [5.0, -5.0, -5.0, 5.0][2 * i + j];
        }
        assert!(msg(equilibrium_tangents(floating.as_ref(), &[0])).contains("singular"));
    }
}
