//! Time integrators for `flexmb` that know nothing of mechanics and count
//! every function evaluation exactly.
//!
//! Three methods are provided:
//!
//! * [`Dopri5`]: Dormand–Prince 5(4) with the defaults and step-size control
//!   of MATLAB's `ode45`, FSAL and a 4th-order continuous extension, so that
//!   its evaluation counts can be compared with `ode45`'s;
//! * [`Adams`]: variable-order (1–12), variable-step Adams PECE method with
//!   local extrapolation in the style of the Shampine–Gordon code
//!   DE/STEP/INTRP;
//! * [`GeneralizedAlpha`]: the implicit generalized-α method of Chung &
//!   Hulbert for stiff second-order systems `g(t, q, q̇, q̈) = 0`, with
//!   modified Newton iterations, LU reuse (`flexmb_linalg::DenseLu`, one
//!   factorization kept while the step size and tangent are) and local error
//!   control.
//!
//! First-order problems implement [`OdeSystem`]; second-order problems in
//! residual form implement [`SecondOrderSystem`] and can be handed to the
//! explicit methods through [`FirstOrderForm`]. Every solve returns the
//! stored output points together with [`Stats`]; an observer can watch the
//! output points and stop the integration with [`Control::Stop`].
//! Work arrays are allocated once per integration; inside the step loop the
//! only allocations are the amortized growth of the stored output (none
//! with [`Output::Times`], whose storage is reserved up front).
//!
//! # Example
//!
//! ```
//! use flexmb_ode::{Dopri5, Dopri5Options, OdeSystem, Output, RhsError};
//!
//! /// y' = −y + sin t
//! struct Forced;
//!
//! impl OdeSystem for Forced {
//!     fn dim(&self) -> usize {
//!         1
//!     }
//!     fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
//!         dy[0] = -y[0] + t.sin();
//!         Ok(())
//!     }
//! }
//!
//! let solver = Dopri5::new(Dopri5Options::default().rtol(1e-8).atol(1e-10));
//! let times: Vec<f64> = (0..=20).map(|i| 0.1 * i as f64).collect();
//! let sol = solver.solve(&mut Forced, 0.0, &[1.0], 2.0, &Output::Times(times))?;
//!
//! let exact = |t: f64| 1.5 * (-t).exp() + 0.5 * (t.sin() - t.cos());
//! for (t, y) in sol.iter() {
//!     assert!((y[0] - exact(t)).abs() < 1e-8);
//! }
//! // FSAL: one initial evaluation plus six per attempted step.
//! let s = &sol.stats;
//! assert_eq!(s.rhs_evals, 1 + 6 * (s.steps_accepted + s.steps_rejected));
//! println!("{s}");
//! # Ok::<(), flexmb_ode::OdeError>(())
//! ```

#![warn(missing_docs)]
// Loops over several parallel arrays read closer to the published formulas
// with an explicit index.
#![allow(clippy::needless_range_loop)]

pub mod adams;
mod common;
pub mod dopri5;
mod error;
pub mod genalpha;
mod system;

pub use adams::{Adams, AdamsOptions};
pub use common::{Control, Output, Solution, Stats, Status, Tolerance};
pub use dopri5::{Dopri5, Dopri5Options};
pub use error::{OdeError, RhsError, RhsErrorKind};
pub use genalpha::{
    AlphaParameters, GeneralizedAlpha, GeneralizedAlphaOptions, SecondOrderSolution,
};
pub use system::{FirstOrderForm, OdeSystem, SecondOrderSystem};

/// Common interface of the first-order integrators ([`Dopri5`], [`Adams`]),
/// usable as a trait object to run the same problem with several methods.
pub trait FirstOrderIntegrator {
    /// Short human-readable name of the method.
    fn name(&self) -> &'static str;

    /// Integrates `sys` from `(t0, y0)` to `t_end`, storing the points
    /// selected by `output` and calling `observer` at each of them.
    fn integrate(
        &self,
        sys: &mut dyn OdeSystem,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        output: &Output,
        observer: &mut dyn FnMut(f64, &[f64]) -> Control,
    ) -> Result<Solution, OdeError>;
}
