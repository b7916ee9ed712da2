//! Pictures of flexible mechanisms (`flexmb draw`): a configuration's
//! beams (thin boxes of their section along their deformed centre line, or
//! lines), trusses, hinges, masses, rigid bodies and superelements (the
//! outline of their recovered FE mesh, or their dashed chord, with their
//! interface nodes) projected orthographically along an axis or
//! isometrically, with the reference configuration overlaid and mode shapes
//! of the linearization drawn as deformed shapes at a chosen amplitude.
//!
//! The geometry is data ([`geometry`]: items in model and projected
//! coordinates), so tests check positions without pixels; [`Picture::plot`]
//! turns it into a [`flexmb_plot::Plot`] with equal axis scales, written
//! as SVG or PNG by the plot crate's one drawing routine.
//!
//! This is its own crate, not a module of `flexmb-plot`, so that the plot
//! crate stays free of the model, kinematics and dynamics.
#![warn(missing_docs)]

mod geometry;
mod mode;
mod picture;
mod view;

pub use geometry::{
    geometry, node_positions, styled_geometry, Geometry, Item, ItemKind, Style, BEAM_STATIONS,
    OUTLINE_ANGLE_DEG,
};
pub use mode::{check_mode, mode_shape, Configuration, ModeShape};
pub use picture::{
    figure_format, phase_factors, picture, DrawOptions, Format, Layer, Picture, MODE_COLOR,
    REFERENCE_COLOR, REST_COLOR,
};
pub use view::View;

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DrawError {
    /// Invalid input: a mode that does not exist, an unknown view, a bad
    /// amplitude, a figure name without .svg or .png.
    #[error("{0}")]
    Input(String),
    /// A computation failed (the configuration or the linearization).
    #[error("{0}")]
    Compute(String),
    /// The figure could not be written.
    #[error("{0}")]
    Write(String),
}
