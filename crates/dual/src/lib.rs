//! Nestable forward-mode dual numbers for exact derivatives of small
//! element functions, and a generic 3-vector to write those functions once.
//!
//! The flexmb element library writes each deformation function ε = D(x) and each
//! kinetic energy once, generically over a [`Real`] scalar. Evaluated with
//! * `f64` it gives the value,
//! * [`Dual<f64, N>`] it gives the value and the full gradient/Jacobian (N seeds),
//! * `Dual<Dual<f64, 1>, 1>` it gives a directional second derivative D,xx\[a, b\],
//! * `Dual<Dual<f64, N>, N>` it gives a full Hessian.
//!
//! These are exact derivatives (to rounding), not finite differences: the chain
//! rule is applied operation by operation.
//!
//! ```
//! use flexmb_dual::{Dual, Real};
//! // f(x, y) = x² y + sin(y)
//! fn f<T: Real>(x: T, y: T) -> T { x * x * y + y.sin() }
//! let x = Dual::<f64, 2>::variable(3.0, 0);
//! let y = Dual::<f64, 2>::variable(0.5, 1);
//! let r = f(x, y);
//! assert!((r.re - (4.5 + 0.5f64.sin())).abs() < 1e-15);
//! assert!((r.eps[0] - 3.0).abs() < 1e-15);            // ∂f/∂x = 2xy
//! assert!((r.eps[1] - (9.0 + 0.5f64.cos())).abs() < 1e-15); // ∂f/∂y = x² + cos y
//! ```
#![warn(missing_docs)]

mod dual;
mod real;
mod vec3;

pub use dual::{Dual, Dual1, Dual2};
pub use real::Real;
pub use vec3::{Mat3, Vec3};
