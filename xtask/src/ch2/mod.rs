//! Thesis chapter 2, §2.4: the non-linear two-node superelement with rigid
//! interfaces and its three velocity transformations B1, B2, B3, on the
//! planar spin-up beam (Table 2.1) and the spin-up beam on a universal joint
//! (Figs 2.9–2.12), and on the unbalanced rotating shaft (Table 2.2,
//! Figs 2.15–2.16: [`shaft`] the model, [`shaft_study`] the runs,
//! [`shaft_report`] the report's section). Every superelement
//! is built by flexmb's builder from a solid FE model (built-in 20-node
//! hexahedra). `cargo xtask reproduce ch2` writes `results/ch2/`.

pub mod chain;
pub mod curves;
pub mod report;
pub mod segments;
pub mod shaft;
pub mod shaft_report;
pub mod shaft_study;
pub mod spin_up;
pub mod universal_joint;

pub use report::reproduce;
