//! Naming the culprit of a failure: the degrees of freedom without inertia
//! of a mass matrix that is not positive definite, the motion a singular
//! static tangent leaves unrestrained, the state component of an integrator's
//! non-finite value. Only error paths call these (they allocate).

use faer::MatRef;
use flexmb_model::Mechanism;
use flexmb_ode::OdeError;

/// At most this many null vectors of a singular matrix are named.
const MAX_NULL_VECTORS: usize = 6;

/// At most this many coordinates are named; the rest are counted.
const MAX_NAMED: usize = 8;

/// A component of a null vector at least this fraction of its largest takes
/// part in the motion.
const PARTICIPATION: f64 = 0.25;

/// The degrees of freedom a mass matrix Mq (n_dof × n_dof) gives no inertia:
/// those whose diagonal is at most 1e-12 of the largest, else (when no single
/// DOF is massless, only a combination) those of the estimated null vectors
/// of Mq. Labels as [`Mechanism::dof_label`].
pub fn massless_dofs(mech: &Mechanism, mq: MatRef<'_, f64>) -> Vec<String> {
    let n = mq.nrows().min(mq.ncols());
    let mx = (0..n).fold(0.0f64, |m, i| m.max(mq[(i, i)].abs()));
    let named: Vec<String> = (0..n)
        .filter(|i| mq[(*i, *i)] <= 1e-12 * mx)
        .map(|i| mech.dof_label(i))
        .collect();
    if !named.is_empty() {
        return named;
    }
    let all: Vec<usize> = (0..n).collect();
    null_space_dofs(mech, mq, &all)
}

/// The degrees of freedom of the motions a singular matrix over the DOFs
/// `dofs` (its rows and columns, e.g. the free ones of a static tangent)
/// leaves unrestrained: the largest components of its estimated null vectors
/// ([`flexmb_kinematics::null_vectors`]), largest first, at most
/// eight and a count of the others.
pub fn null_space_dofs(mech: &Mechanism, a: MatRef<'_, f64>, dofs: &[usize]) -> Vec<String> {
    let vectors = flexmb_kinematics::null_vectors(a, MAX_NULL_VECTORS);
    // participation of each DOF: its largest share in any null vector
    let mut share = vec![0.0f64; dofs.len()];
    for v in &vectors {
        for (s, c) in share.iter_mut().zip(v) {
            *s = s.max(c.abs());
        }
    }
    let mut involved: Vec<usize> = (0..share.len())
        .filter(|k| share[*k] >= PARTICIPATION)
        .collect();
    involved.sort_by(|a, b| share[*b].total_cmp(&share[*a]));
    let mut names: Vec<String> = involved
        .iter()
        .take(MAX_NAMED)
        .map(|k| mech.dof_label(dofs[*k]))
        .collect();
    if involved.len() > MAX_NAMED {
        names.push(format!("and {} more", involved.len() - MAX_NAMED));
    }
    names
}

/// A number for messages: plain between 1e-4 and 1e6 (and 0), else in
/// exponent form, so that 1e-300 is not printed with 300 zeros.
pub fn short_number(v: f64) -> String {
    if v == 0.0 || (1e-4..1e6).contains(&v.abs()) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A list of names for a message: `": a, b"`, or nothing when empty.
pub(crate) fn listed(prefix: &str, names: &[String]) -> String {
    if names.is_empty() {
        String::new()
    } else {
        format!("{prefix}{}", names.join(", "))
    }
}

/// How the state vector of an integrator maps to the mechanism.
#[derive(Clone, Copy)]
pub(crate) enum StateLayout {
    /// y = (q, q̇) of the explicit integrators.
    FirstOrder,
    /// q, q̇, q̈ of the second-order (generalized-α) integrator.
    SecondOrder,
}

/// An integrator's error as text, with the state component it names (a
/// non-finite initial value, state or right-hand side) given as the DOF:
/// "initial value `y0` has a non-finite component 8: the rate of DOF q3 =
/// S.x (node S)".
pub(crate) fn integration_error(mech: &Mechanism, layout: StateLayout, e: &OdeError) -> String {
    let n = mech.n_dof();
    let component = |index: usize| match layout {
        StateLayout::FirstOrder => mech.state_label(index),
        StateLayout::SecondOrder => mech.dof_label(index),
    };
    let named = match e {
        OdeError::NonFiniteInitialValue { what, index } => match *what {
            "qd0" => Some(format!("the rate of {}", mech.dof_label(*index))),
            "initial_acceleration" => {
                Some(format!("the acceleration of {}", mech.dof_label(*index)))
            }
            _ => Some(component(*index)),
        },
        OdeError::NonFiniteState { index, .. } => Some(component(*index)),
        OdeError::NonFiniteRhs { what, index, .. } => match (*what, layout) {
            // ẏ = (q̇, q̈)
            ("rhs", StateLayout::FirstOrder) if *index >= n => {
                Some(format!("the acceleration of {}", mech.dof_label(index - n)))
            }
            ("tangent", _) if n > 0 => {
                let (m, rest) = (index / (n * n), index % (n * n));
                let matrix = ["mass", "damping", "stiffness"]
                    .get(m)
                    .copied()
                    .unwrap_or("tangent");
                Some(format!(
                    "the {matrix} matrix at row {} and column {}",
                    mech.dof_label(rest % n),
                    mech.dof_label(rest / n)
                ))
            }
            _ => Some(component(*index)),
        },
        _ => None,
    };
    match named {
        Some(c) => format!("{e}: {c}"),
        None => e.to_string(),
    }
}
