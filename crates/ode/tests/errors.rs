//! Error paths: every failure is reported as an error, never a panic.

mod common;

use common::{Counting, Forced, Linear2, Pendulum};
use faer::Mat;
use flexmb_ode::{
    Adams, AdamsOptions, Control, Dopri5, Dopri5Options, FirstOrderIntegrator, GeneralizedAlpha,
    GeneralizedAlphaOptions, OdeError, OdeSystem, Output, RhsError, SecondOrderSystem, Status,
};

fn explicit_methods() -> Vec<Box<dyn FirstOrderIntegrator>> {
    vec![Box::new(Dopri5::default()), Box::new(Adams::default())]
}

fn run(
    m: &dyn FirstOrderIntegrator,
    sys: &mut dyn OdeSystem,
    y0: &[f64],
    t_end: f64,
    output: &Output,
) -> Result<flexmb_ode::Solution, OdeError> {
    m.integrate(sys, 0.0, y0, t_end, output, &mut |_, _| Control::Continue)
}

/// Produces NaN in component 1 once t > 0.5 (or an error when `fail`).
struct Faulty {
    fail: bool,
}

impl OdeSystem for Faulty {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        if t > 0.5 {
            if self.fail {
                return Err(RhsError::new(
                    "Newton solve for the constraints did not converge",
                ));
            }
            dy[1] = f64::NAN;
        }
        dy[0] = -y[0];
        dy[2] = 1.0;
        if t <= 0.5 {
            dy[1] = 0.0;
        }
        Ok(())
    }
}

impl SecondOrderSystem for Faulty {
    fn dim(&self) -> usize {
        3
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        _qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        let mut f = [0.0; 3];
        OdeSystem::rhs(self, t, q, &mut f)?;
        for i in 0..3 {
            r[i] = qdd[i] - f[i];
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
        for i in 0..3 {
            for j in 0..3 {
                m[(i, j)] = if i == j { 1.0 } else { 0.0 };
                c[(i, j)] = 0.0;
                k[(i, j)] = if i == 0 && j == 0 { 1.0 } else { 0.0 };
            }
        }
        Ok(())
    }
}

/// NaN in the right-hand side is reported with the time (just after 0.5)
/// and the first offending component (1), for every method.
#[test]
fn nan_in_rhs_reports_time_and_component() {
    for m in explicit_methods() {
        let err = run(
            &*m,
            &mut Faulty { fail: false },
            &[1.0, 0.0, 0.0],
            2.0,
            &Output::Steps,
        )
        .unwrap_err();
        match err {
            OdeError::NonFiniteRhs { what, t, index } => {
                assert_eq!(what, "rhs");
                assert_eq!(index, 1, "{}", m.name());
                assert!(t > 0.5 && t < 2.0, "{}: t = {t}", m.name());
            }
            other => panic!("{}: unexpected {other:?}", m.name()),
        }
        let msg = err.to_string();
        assert!(msg.contains("component 1") && msg.contains("t = "), "{msg}");
    }
    let err = GeneralizedAlpha::default()
        .solve(
            &mut Faulty { fail: false },
            0.0,
            &[1.0, 0.0, 0.0],
            &[0.0; 3],
            2.0,
            &Output::Steps,
        )
        .unwrap_err();
    assert!(
        matches!(err, OdeError::NonFiniteRhs { what: "residual", index: 1, t } if t > 0.5),
        "{err:?}"
    );
}

/// An error returned by the system is propagated with its message and time.
#[test]
fn rhs_error_is_propagated() {
    for m in explicit_methods() {
        let err = run(
            &*m,
            &mut Faulty { fail: true },
            &[1.0, 0.0, 0.0],
            2.0,
            &Output::Steps,
        )
        .unwrap_err();
        match &err {
            OdeError::Rhs { t, source } => {
                assert!(*t > 0.5);
                assert_eq!(
                    source.message(),
                    "Newton solve for the constraints did not converge"
                );
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(err.to_string().contains("did not converge"));
        assert!(std::error::Error::source(&err).is_some());
    }
    let err = GeneralizedAlpha::default()
        .solve(
            &mut Faulty { fail: true },
            0.0,
            &[1.0, 0.0, 0.0],
            &[0.0; 3],
            2.0,
            &Output::Steps,
        )
        .unwrap_err();
    assert!(matches!(err, OdeError::Rhs { t, .. } if t > 0.5), "{err:?}");
}

/// Invalid options and inputs are rejected before any evaluation.
#[test]
fn invalid_inputs_are_rejected_without_evaluation() {
    let out = Output::Steps;
    let cases: Vec<(Dopri5Options, AdamsOptions, GeneralizedAlphaOptions, &str)> = vec![
        (
            Dopri5Options::default().rtol(0.0),
            AdamsOptions::default().rtol(0.0),
            GeneralizedAlphaOptions::default().rtol(0.0),
            "rtol",
        ),
        (
            Dopri5Options::default().rtol(-1e-3),
            AdamsOptions::default().rtol(f64::NAN),
            GeneralizedAlphaOptions::default().rtol(-1.0),
            "rtol",
        ),
        (
            Dopri5Options::default().atol(0.0),
            AdamsOptions::default().atol(-1e-6),
            GeneralizedAlphaOptions::default().atol(0.0),
            "atol",
        ),
        (
            Dopri5Options::default().atol(vec![1e-6, 0.0]),
            AdamsOptions::default().atol(vec![1e-6, -1.0]),
            GeneralizedAlphaOptions::default().atol(vec![0.0]),
            "atol",
        ),
        (
            Dopri5Options::default().h0(-1.0),
            AdamsOptions::default().h0(0.0),
            GeneralizedAlphaOptions::default().h0(-0.1),
            "h0",
        ),
        (
            Dopri5Options::default().fixed_step(0.0),
            AdamsOptions::default().max_order(13),
            GeneralizedAlphaOptions::default().rho_inf(1.5),
            "",
        ),
        (
            Dopri5Options::default().max_steps(0),
            AdamsOptions::default().max_order(0),
            GeneralizedAlphaOptions::default().max_steps(0),
            "",
        ),
    ];
    for (d, a, g, name) in cases {
        let mut sys = Counting::new(Forced);
        let e1 = Dopri5::new(d)
            .solve(&mut sys, 0.0, &[1.0], 1.0, &out)
            .unwrap_err();
        let e2 = Adams::new(a)
            .solve(&mut sys, 0.0, &[1.0], 1.0, &out)
            .unwrap_err();
        assert_eq!(sys.rhs_calls, 0);
        let mut so = Counting::new(Pendulum);
        let e3 = GeneralizedAlpha::new(g)
            .solve(&mut so, 0.0, &[1.0], &[0.0], 1.0, &out)
            .unwrap_err();
        assert_eq!(so.rhs_calls + so.tangent_calls, 0);
        for e in [e1, e2, e3] {
            match &e {
                OdeError::InvalidOption { name: n, .. } => {
                    assert!(name.is_empty() || *n == name, "{e}")
                }
                OdeError::DimensionMismatch { what, .. } => assert_eq!(*what, "atol"),
                other => panic!("unexpected {other:?}"),
            }
        }
    }
    // Wrong dimension, bad interval, non-finite initial value, bad output
    // times.
    for m in explicit_methods() {
        let mut sys = Counting::new(Forced);
        let mut call = |y0: &[f64], t_end: f64, out: &Output| {
            m.integrate(&mut sys, 0.0, y0, t_end, out, &mut |_, _| Control::Continue)
                .unwrap_err()
        };
        assert!(matches!(
            call(&[1.0, 2.0], 1.0, &out),
            OdeError::DimensionMismatch {
                what: "y0",
                expected: 1,
                found: 2
            }
        ));
        assert!(matches!(
            call(&[1.0], 0.0, &out),
            OdeError::InvalidInterval { .. }
        ));
        assert!(matches!(
            call(&[1.0], f64::INFINITY, &out),
            OdeError::InvalidInterval { .. }
        ));
        assert!(matches!(
            call(&[f64::NAN], 1.0, &out),
            OdeError::NonFiniteInitialValue {
                what: "y0",
                index: 0
            }
        ));
        assert!(matches!(
            call(&[1.0], 1.0, &Output::Times(vec![0.5, 1.5])),
            OdeError::InvalidOutputTimes { index: 1, .. }
        ));
        assert!(matches!(
            call(&[1.0], 1.0, &Output::Times(vec![0.5, 0.2])),
            OdeError::InvalidOutputTimes { index: 1, .. }
        ));
        assert_eq!(sys.rhs_calls, 0);
    }
    let ga = GeneralizedAlpha::default();
    assert!(matches!(
        ga.solve(&mut Pendulum, 0.0, &[1.0], &[0.0, 0.0], 1.0, &out),
        Err(OdeError::DimensionMismatch { what: "qd0", .. })
    ));
    assert!(matches!(
        ga.solve(&mut Pendulum, 1.0, &[1.0], &[0.0], 0.0, &out),
        Err(OdeError::InvalidInterval { .. })
    ));
}

/// The configured step limit is enforced for every method.
#[test]
fn max_steps_exceeded() {
    let d = Dopri5::new(Dopri5Options::default().max_steps(5));
    let a = Adams::new(AdamsOptions::default().max_steps(5));
    for m in [&d as &dyn FirstOrderIntegrator, &a] {
        let err = run(m, &mut Forced, &[1.0], 100.0, &Output::Steps).unwrap_err();
        assert!(
            matches!(err, OdeError::MaxStepsExceeded { max_steps: 5, t } if t > 0.0 && t < 100.0),
            "{err:?}"
        );
    }
    let err = GeneralizedAlpha::new(GeneralizedAlphaOptions::default().max_steps(5))
        .solve(&mut Pendulum, 0.0, &[1.0], &[0.0], 100.0, &Output::Steps)
        .unwrap_err();
    assert!(matches!(
        err,
        OdeError::MaxStepsExceeded { max_steps: 5, .. }
    ));
}

/// Control::Stop ends the run cleanly, keeping the output gathered so far.
#[test]
fn observer_stop_keeps_partial_output() {
    for m in explicit_methods() {
        let mut calls = 0;
        let times: Vec<f64> = (0..=100).map(|i| 0.1 * i as f64).collect();
        let sol = m
            .integrate(
                &mut Forced,
                0.0,
                &[1.0],
                10.0,
                &Output::Times(times),
                &mut |t, _| {
                    calls += 1;
                    if t >= 3.0 - 1e-12 {
                        Control::Stop
                    } else {
                        Control::Continue
                    }
                },
            )
            .unwrap();
        assert_eq!(calls, 31, "{}", m.name());
        assert_eq!(sol.len(), 31);
        assert!(matches!(sol.status, Status::Stopped { t } if (t - 3.0).abs() < 1e-12));
        let (t, y) = sol.last().unwrap();
        assert!((y[0] - Forced::exact(t)).abs() < 1e-2);
        assert!(sol.stats.steps_accepted > 0);
    }
    // Stop at the initial point: no step is taken.
    let sol = Dopri5::default()
        .solve_with(&mut Forced, 0.0, &[1.0], 1.0, &Output::Steps, |_, _| {
            Control::Stop
        })
        .unwrap();
    assert_eq!(sol.len(), 1);
    assert_eq!(sol.stats.steps_accepted, 0);
    assert_eq!(sol.stats.rhs_evals, 1);
    // Generalized-α.
    let sol = GeneralizedAlpha::default()
        .solve_with(
            &mut Pendulum,
            0.0,
            &[1.0],
            &[0.0],
            10.0,
            &Output::Steps,
            |t, _, _, _| {
                if t > 2.0 {
                    Control::Stop
                } else {
                    Control::Continue
                }
            },
        )
        .unwrap();
    assert!(matches!(sol.status, Status::Stopped { t } if t > 2.0 && t < 10.0));
    assert!(*sol.t().last().unwrap() > 2.0);
}

/// y' = y², y(0) = 1 blows up at t = 1: the step size underflows (or the
/// state overflows) and an error naming a time just before 1 is returned.
#[test]
fn blow_up_reports_step_size_underflow() {
    struct Blow;
    impl OdeSystem for Blow {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
            dy[0] = y[0] * y[0];
            Ok(())
        }
    }
    for m in explicit_methods() {
        let err = run(&*m, &mut Blow, &[1.0], 2.0, &Output::Final).unwrap_err();
        let t = match err {
            OdeError::StepSizeTooSmall { t, .. }
            | OdeError::NonFiniteRhs { t, .. }
            | OdeError::NonFiniteState { t, .. }
            | OdeError::ToleranceTooSmall { t, .. } => t,
            other => panic!("{}: unexpected {other:?}", m.name()),
        };
        assert!((t - 1.0).abs() < 1e-2, "{}: t = {t} ({err})", m.name());
    }
}

/// Tolerances below the machine precision are reported by the Adams code
/// (Shampine–Gordon test 2u‖y‖ > 1/2 in the weighted norm).
#[test]
fn adams_tolerance_too_small() {
    let err = Adams::new(AdamsOptions::default().rtol(1e-20).atol(1e-30))
        .solve(&mut Forced, 0.0, &[1.0], 1.0, &Output::Final)
        .unwrap_err();
    assert!(matches!(err, OdeError::ToleranceTooSmall { t, factor } if t == 0.0 && factor > 1.0));
}

/// A singular mass matrix is reported when computing the initial
/// acceleration.
#[test]
fn singular_mass_matrix() {
    let mut sys = Linear2::new(
        2,
        vec![1.0, 1.0, 1.0, 1.0],
        vec![0.0; 4],
        vec![1.0, 0.0, 0.0, 1.0],
        vec![0.0; 2],
    );
    let err = GeneralizedAlpha::default()
        .solve(&mut sys, 0.0, &[1.0, 0.0], &[0.0, 0.0], 1.0, &Output::Final)
        .unwrap_err();
    assert!(matches!(err, OdeError::SingularMatrix { what: "mass", t, .. } if t == 0.0));
}

/// A tangent with NaN entries is reported with its flat index.
#[test]
fn nan_in_tangent() {
    struct BadTangent;
    impl SecondOrderSystem for BadTangent {
        fn dim(&self) -> usize {
            2
        }
        fn residual(
            &mut self,
            _t: f64,
            q: &[f64],
            _qd: &[f64],
            qdd: &[f64],
            r: &mut [f64],
        ) -> Result<(), RhsError> {
            r[0] = qdd[0] + q[0];
            r[1] = qdd[1] + q[1];
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
            m.fill(0.0);
            m[(0, 0)] = 1.0;
            m[(1, 1)] = 1.0;
            c.fill(0.0);
            k.fill(0.0);
            k[(1, 0)] = f64::NAN;
            Ok(())
        }
    }
    let err = GeneralizedAlpha::default()
        .solve(
            &mut BadTangent,
            0.0,
            &[1.0, 0.0],
            &[0.0, 0.0],
            1.0,
            &Output::Final,
        )
        .unwrap_err();
    // Stiffness block starts at 2·n² = 8; entry (1, 0) is column-major index 1.
    assert!(
        matches!(
            err,
            OdeError::NonFiniteRhs {
                what: "tangent",
                index: 9,
                ..
            }
        ),
        "{err:?}"
    );
}

/// A free undamped oscillator q̈ + q = 0 (q = sin t) whose residual cannot be
/// evaluated (a recoverable error, as a position solve that does not
/// converge) at iterates with |q| > 1.02, which the exact solution never
/// reaches but the predictor of a large first step does. Generalized-α
/// retries such steps smaller, as the explicit methods do, and completes
/// with the accuracy of an unobstructed run.
struct Fenced {
    inner: Linear2,
    refusals: usize,
}

impl SecondOrderSystem for Fenced {
    fn dim(&self) -> usize {
        1
    }
    fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        if q[0].abs() > 1.02 {
            self.refusals += 1;
            return Err(RhsError::recoverable("configuration out of reach"));
        }
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
        self.inner.tangent(t, q, qd, qdd, m, c, k)
    }
}

#[test]
fn generalized_alpha_retries_steps_whose_iterates_cannot_be_evaluated() {
    let free = || {
        let mut s = Linear2::sdof(0.0, 1.0);
        s.force = vec![0.0];
        s
    };
    let opts = GeneralizedAlphaOptions::default()
        .rtol(1e-6)
        .atol(1e-8)
        .h0(2.0);
    let out = Output::Times(vec![10.0]);
    let mut fenced = Fenced {
        inner: free(),
        refusals: 0,
    };
    let sol = GeneralizedAlpha::new(opts.clone())
        .solve(&mut fenced, 0.0, &[0.0], &[1.0], 10.0, &out)
        .expect("the refused iterates are retried, not fatal");
    assert!(fenced.refusals > 0, "the test never hit the fence");
    assert!(sol.stats.newton_failures >= fenced.refusals.min(1));
    let reference = GeneralizedAlpha::new(opts)
        .solve(&mut free(), 0.0, &[0.0], &[1.0], 10.0, &out)
        .unwrap();
    let exact = 10f64.sin();
    let (q, q_ref) = (sol.q(0)[0], reference.q(0)[0]);
    assert!(
        (q - exact).abs() <= 2.0 * (q_ref - exact).abs().max(1e-6),
        "q(10) = {q} (unobstructed {q_ref}, exact {exact})"
    );
}

/// A damped oscillator whose tangent is interrupted at its `stop_at`-th
/// evaluation, as a large model's tangent honours a stop request.
struct InterruptedTangent {
    tangents: usize,
    stop_at: usize,
}

impl SecondOrderSystem for InterruptedTangent {
    fn dim(&self) -> usize {
        1
    }
    fn residual(
        &mut self,
        _t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        r[0] = qdd[0] + 0.1 * qd[0] + q[0] + 10.0 * q[0].powi(3);
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
        self.tangents += 1;
        if self.tangents == self.stop_at {
            return Err(RhsError::interrupted());
        }
        m[(0, 0)] = 1.0;
        c[(0, 0)] = 0.1;
        k[(0, 0)] = 1.0 + 30.0 * q[0] * q[0];
        Ok(())
    }
}

#[test]
fn a_tangent_interrupted_by_a_stop_request_ends_the_run_cleanly_with_the_steps_so_far() {
    // a tangent at nearly every step (refresh above a contraction of 1e-6)
    let method = GeneralizedAlpha::new(GeneralizedAlphaOptions {
        jacobian_refresh: 1e-6,
        ..GeneralizedAlphaOptions::default().rtol(1e-6)
    });
    // the whole run, to know how many tangents it takes
    let mut full = InterruptedTangent {
        tangents: 0,
        stop_at: usize::MAX,
    };
    let whole = method
        .solve(&mut full, 0.0, &[1.0], &[0.0], 20.0, &Output::Steps)
        .unwrap();
    assert!(full.tangents >= 4, "{} tangents", full.tangents);
    let stop_at = full.tangents / 2 + 1;
    let mut sys = InterruptedTangent {
        tangents: 0,
        stop_at,
    };
    let sol = method
        .solve(&mut sys, 0.0, &[1.0], &[0.0], 20.0, &Output::Steps)
        .expect("an interruption is not an error");
    let Status::Stopped { t } = sol.status else {
        panic!("not stopped: {:?}", sol.status);
    };
    assert!(t > 0.0 && t < 20.0, "stopped at {t}");
    assert_eq!(sys.tangents, stop_at, "evaluated on after the interruption");
    // the steps so far are those of the uninterrupted run, up to the stop
    let k = sol.len();
    assert!(k >= 2 && k < whole.len(), "{k} of {} points", whole.len());
    assert_eq!(sol.t()[k - 1], t);
    for i in 0..k {
        assert_eq!(sol.t()[i], whole.t()[i]);
        assert_eq!(sol.q(i), whole.q(i));
    }
    // a fatal tangent error is still an error
    let mut fatal = Faulty { fail: true };
    assert!(matches!(
        method.solve(
            &mut fatal,
            0.0,
            &[1.0, 0.0, 0.0],
            &[0.0; 3],
            1.0,
            &Output::Steps
        ),
        Err(OdeError::Rhs { .. })
    ));
}

#[test]
fn an_rhs_error_keeps_its_typed_cause() {
    #[derive(Debug, PartialEq)]
    struct Unreachable(usize);
    impl std::fmt::Display for Unreachable {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "node {} out of reach", self.0)
        }
    }
    impl std::error::Error for Unreachable {}
    let e = RhsError::from_cause(flexmb_ode::RhsErrorKind::Recoverable, Unreachable(3));
    assert!(e.is_recoverable() && !e.is_interrupted());
    assert_eq!(e.message(), "node 3 out of reach");
    assert_eq!(e.downcast_cause::<Unreachable>(), Some(&Unreachable(3)));
    assert!(e.downcast_cause::<std::fmt::Error>().is_none());
    // the message already is the cause's text: no repetition in a source chain
    assert!(std::error::Error::source(&e).is_none());
    assert!(RhsError::new("x").cause().is_none());
}
