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

/// A pivot ratio of J at most this fraction of the one at the start of a
/// run marks a configuration near a singular one in a stall's explanation.
const NEAR_SINGULAR: f64 = 1e-2;

/// At most this many DOFs are named as the fastest accelerating.
const MAX_FASTEST: usize = 3;

impl crate::Dynamics {
    /// Why a run may have stalled at (t, q, q̇), its last accepted step,
    /// when no evaluation failed (an implicit step whose Newton iterations
    /// stop converging, a step size that error estimates alone shrink),
    /// for the message of the integrator's error: either the kinematics is
    /// near a singular configuration there (the pivot ratio of J has fallen
    /// to at most [`NEAR_SINGULAR`] of `start_pivot`, its value at the start
    /// of the run), naming the dependent coordinates J determines worst, or
    /// the degrees of freedom with the largest accelerations. Error path
    /// only: it solves and evaluates afresh.
    pub(crate) fn explain_stall(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        start_pivot: f64,
    ) -> String {
        let at = format!("at the last accepted step (t = {t:.6})");
        if let Err(e) = self.kinematics_at(t, q, None) {
            return format!("{at} the position solve fails: {e}");
        }
        let pivot = self.kin.pivot_ratio();
        if pivot <= NEAR_SINGULAR * start_pivot {
            let names = self.kin.least_determined_coordinates();
            return format!(
                "no evaluation failed; {at} the mechanism is near a singular configuration: the \
                 pivot ratio of the kinematic Jacobian fell to {:.2e} from {:.2e} at the start, and it \
                 determines the dependent coordinates{} least (a straightened toggle, a \
                 prescribed motion at the edge of its reach, or, with nodal coordinates as \
                 DOFs, a dependent set that no other set betters there)",
                pivot,
                start_pivot,
                listed(" ", &names)
            );
        }
        let mut qdd = vec![0.0; q.len()];
        if let Err(e) = self.accelerations(t, q, qd, &mut qdd) {
            return format!("{at} the equations of motion fail: {e}");
        }
        let mut order: Vec<usize> = (0..q.len()).collect();
        order.sort_by(|a, b| qdd[*b].abs().total_cmp(&qdd[*a].abs()));
        let fastest: Vec<String> = order
            .iter()
            .take(MAX_FASTEST)
            .map(|k| format!("{} (q̈ = {:.3e})", self.mech.dof_label(*k), qdd[*k]))
            .collect();
        format!(
            "no evaluation failed; {at} the kinematics is regular (pivot ratio {:.2e}, {:.2e} at \
             the start) and the largest accelerations are{}: the motion may be too fast or too \
             stiff for the tolerances there, or an input may jump",
            pivot,
            start_pivot,
            listed(" ", &fastest)
        )
    }
}

#[cfg(test)]
mod tests {
    use crate::Dynamics;
    use std::sync::Arc;

    /// Near a straightened toggle a stall is explained by the kinematics:
    /// two rigid bars of 1 m, the free end C on the x axis and driven in x
    /// to 1.99999 m (0.01 mm short of stretched), where J hardly determines
    /// the elbow's height.
    #[test]
    fn a_stall_near_a_stretched_toggle_names_the_least_determined_coordinates() {
        let mech = flexmb_model::Scene::from_ron_str(
            r#"(
        dimension: Planar,
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [0.8, 0.6]), (id: "C", at: [1.6, 0.0]) ],
        elements: [
            (id: "ab", type: Truss(nodes: ("A", "B"), ea: 1.0e6, mass_per_length: 1.0)),
            (id: "bc", type: Truss(nodes: ("B", "C"), ea: 1.0e6, mass_per_length: 1.0)),
        ],
        fixed: [ Coord("A", Position), Coord("C", Y) ],
        rigid: [ Def("ab", "*"), Def("bc", "*") ],
        prescribed: [ (what: Coord("C", X), function: Ramp(t0: 0.0, t1: 1.0, v0: 1.6, v1: 2.5)) ],
    )"#,
        )
        .unwrap()
        .build(None)
        .unwrap();
        let mut dy = Dynamics::new(Arc::new(mech));
        let q = dy.mechanism().q0();
        assert!(q.is_empty());
        dy.kinematics_at(0.0, &q, None).unwrap();
        let start = dy.kin.pivot_ratio();
        // C.x = 1.6 + 0.9 t reaches 1.99999 m at t = 0.39999 / 0.9
        let t_end = 0.39999 / 0.9;
        for k in 1..=40 {
            let t = t_end * (1.0 - (1.0 - k as f64 / 40.0).powi(3));
            dy.kinematics_at(t, &q, None).unwrap();
        }
        let why = dy.explain_stall(t_end, &q, &q, start);
        for part in [
            "no evaluation failed",
            "near a singular configuration",
            "B.y",
        ] {
            assert!(why.contains(part), "`{part}` missing from: {why}");
        }
    }

    /// At a regular configuration a stall is explained by the largest
    /// accelerations: a free point mass of 2 kg under (0, −6) N accelerates
    /// by −3 m/s² in y, 0 in x.
    #[test]
    fn a_stall_at_a_regular_configuration_names_the_fastest_dofs() {
        let mech = flexmb_model::Scene::from_ron_str(
            r#"(
        dimension: Planar,
        nodes: [ (id: "S", at: [0.0, 0.0]) ],
        elements: [ (id: "m", type: PointMass(node: "S", mass: 2.0)) ],
        loads: [ (node: "S", force: Some([0.0, -6.0])) ],
    )"#,
        )
        .unwrap()
        .build(None)
        .unwrap();
        let mut dy = Dynamics::new(Arc::new(mech));
        let why = dy.explain_stall(0.5, &[0.0, 0.0], &[1.0, 0.0], 1.0);
        for part in [
            "no evaluation failed",
            "t = 0.500000",
            "regular",
            "largest accelerations are DOF q1 = S.y (node S) (q̈ = -3.000e0)",
        ] {
            assert!(why.contains(part), "`{part}` missing from: {why}");
        }
    }
}
