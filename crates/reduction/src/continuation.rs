//! Continuation of static equilibria in a load scale λ (the scene's loads
//! times λ, gravity unscaled), for quasi-static eigenfrequency curves of
//! reduced and unreduced models (thesis Figs 5.5, 6.9–6.13) and for reduced
//! models started from their static equilibrium.
//!
//! The functions are generic in the state (q of an unreduced model, z of a
//! reduced one) and in how one equilibrium is solved, so that the CLI and the
//! benchmark harness walk the same path.

use crate::ReductionError;

/// The substep counts tried by [`continue_load_scale`], in order.
pub const SUBSTEPS: [usize; 7] = [1, 2, 4, 8, 16, 32, 64];

/// The equilibrium at load scale `to` from the equilibrium `start` at `from`:
/// `solve(state, λ)` returns the equilibrium at λ from a nearby state. The
/// interval is walked in 1, 2, 4, … 64 equal substeps ([`SUBSTEPS`]), each
/// solved from the previous one; the first count whose substeps all converge
/// wins. Fails with [`ReductionError::NoEquilibrium`] carrying the last
/// solver message.
pub fn continue_load_scale<S: Clone>(
    start: &S,
    from: f64,
    to: f64,
    solve: &mut dyn FnMut(&S, f64) -> Result<S, String>,
) -> Result<S, ReductionError> {
    let mut message = String::new();
    'counts: for n in SUBSTEPS {
        let mut state = start.clone();
        for k in 1..=n {
            let l = from + (to - from) * k as f64 / n as f64;
            match solve(&state, l) {
                Ok(s) => state = s,
                Err(e) => {
                    message = e;
                    continue 'counts;
                }
            }
        }
        return Ok(state);
    }
    Err(ReductionError::NoEquilibrium {
        lambda: to,
        from,
        substeps: SUBSTEPS[SUBSTEPS.len() - 1],
        message,
    })
}

/// The equilibria at the load scales `lambdas` (any order), by continuation
/// ([`continue_load_scale`]) outwards from the equilibrium `at_zero` at λ = 0:
/// first through the non-negative values in increasing order, then, again
/// from `at_zero`, through the negative values in decreasing order. Each
/// equilibrium starts from its neighbour closer to zero, so that a curve
/// through both signs of the load never crosses λ = 0 in one jump.
/// `done(k)` is called after each solved value with the number solved so far.
/// The result is in the order of `lambdas`.
pub fn load_scale_path<S: Clone>(
    at_zero: &S,
    lambdas: &[f64],
    solve: &mut dyn FnMut(&S, f64) -> Result<S, String>,
    done: &mut dyn FnMut(usize),
) -> Result<Vec<S>, ReductionError> {
    if let Some(bad) = lambdas.iter().find(|l| !l.is_finite()) {
        return Err(ReductionError::Invalid(format!(
            "load scale {bad} is not finite"
        )));
    }
    let mut up: Vec<usize> = (0..lambdas.len()).filter(|i| lambdas[*i] >= 0.0).collect();
    let mut down: Vec<usize> = (0..lambdas.len()).filter(|i| lambdas[*i] < 0.0).collect();
    up.sort_by(|a, b| lambdas[*a].total_cmp(&lambdas[*b]));
    down.sort_by(|a, b| lambdas[*b].total_cmp(&lambdas[*a]));
    let mut out: Vec<Option<S>> = vec![None; lambdas.len()];
    let mut count = 0;
    for branch in [up, down] {
        let (mut state, mut prev) = (at_zero.clone(), 0.0);
        for i in branch {
            state = continue_load_scale(&state, prev, lambdas[i], solve)?;
            prev = lambdas[i];
            out[i] = Some(state.clone());
            count += 1;
            done(count);
        }
    }
    Ok(out.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x³ + x = λ: a stiffening spring, solved by Newton from the start.
    fn newton(x0: &f64, l: f64) -> Result<f64, String> {
        let mut x = *x0;
        for _ in 0..8 {
            let dx = -(x * x * x + x - l) / (3.0 * x * x + 1.0);
            x += dx;
            if dx.abs() < 1e-14 {
                return Ok(x);
            }
        }
        Err(format!("no convergence at λ = {l}"))
    }

    #[test]
    fn path_goes_outwards_from_zero_and_keeps_the_order() {
        let lambdas = [0.5, -2.0, 3.0, 0.0, -0.5];
        let mut seen = vec![];
        let mut solve = |x: &f64, l: f64| {
            seen.push(l);
            newton(x, l)
        };
        let mut count = 0;
        let xs = load_scale_path(&0.0, &lambdas, &mut solve, &mut |k| count = k).unwrap();
        assert_eq!(count, 5);
        for (x, l) in xs.iter().zip(&lambdas) {
            assert!((x * x * x + x - l).abs() < 1e-12, "x = {x} at λ = {l}");
        }
        // non-negative values upwards, then the negative ones downwards
        let firsts: Vec<f64> = seen
            .iter()
            .copied()
            .filter(|l| lambdas.contains(l))
            .collect();
        assert_eq!(firsts, vec![0.0, 0.5, 3.0, -0.5, -2.0]);
    }

    #[test]
    fn substeps_rescue_a_solver_with_a_small_radius_and_failures_name_the_load() {
        // a solver that only converges within 0.3 of its start
        let mut short = |x: &f64, l: f64| {
            if (l - x * x * x - x).abs() > 0.3 {
                Err("too far".to_string())
            } else {
                newton(x, l)
            }
        };
        let x = continue_load_scale(&0.0, 0.0, 2.0, &mut short).unwrap();
        assert!((x * x * x + x - 2.0).abs() < 1e-12);
        let mut never = |_: &f64, _: f64| -> Result<f64, String> { Err("diverged".into()) };
        let e = continue_load_scale(&0.0, 0.0, 1.5, &mut never).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("1.5") && m.contains("diverged"), "{m}");
    }
}
