//! The projections of a picture: three orthographic views along the axes
//! and an isometric one.

use crate::DrawError;
use flexmb_model::Dimension;
use std::str::FromStr;

/// The direction a mechanism is looked at from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Along −z: x to the right, y up.
    Xy,
    /// Along +y: x to the right, z up.
    Xz,
    /// Along −x: y to the right, z up.
    Yz,
    /// Isometric, from the direction (1, 1, 1) with y up: the x axis runs
    /// right and down, z left and down, y straight up.
    Iso,
}

/// Screen axes (right, up) of the isometric view, unit vectors.
const ISO_RIGHT: [f64; 3] = [
    std::f64::consts::FRAC_1_SQRT_2,
    0.0,
    -std::f64::consts::FRAC_1_SQRT_2,
];
const ISO_UP: [f64; 3] = [
    -0.408_248_290_463_863,
    0.816_496_580_927_726,
    -0.408_248_290_463_863,
];

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl View {
    /// The default view of a mechanism: xy for planar, iso for spatial.
    pub fn default_for(dimension: Dimension) -> View {
        match dimension {
            Dimension::Planar => View::Xy,
            Dimension::Spatial => View::Iso,
        }
    }

    /// The point `p` (model coordinates, m) on the screen plane (m): right, up.
    pub fn project(self, p: [f64; 3]) -> [f64; 2] {
        match self {
            View::Xy => [p[0], p[1]],
            View::Xz => [p[0], p[2]],
            View::Yz => [p[1], p[2]],
            View::Iso => [dot(ISO_RIGHT, p), dot(ISO_UP, p)],
        }
    }

    /// The axis labels of the screen plane (right, up).
    pub fn axis_labels(self) -> (&'static str, &'static str) {
        match self {
            View::Xy => ("x (m)", "y (m)"),
            View::Xz => ("x (m)", "z (m)"),
            View::Yz => ("y (m)", "z (m)"),
            View::Iso => ("isometric, screen right (m)", "isometric, screen up (m)"),
        }
    }

    /// The view's name as the command line takes it.
    pub fn name(self) -> &'static str {
        match self {
            View::Xy => "xy",
            View::Xz => "xz",
            View::Yz => "yz",
            View::Iso => "iso",
        }
    }
}

impl FromStr for View {
    type Err = DrawError;
    fn from_str(s: &str) -> Result<View, DrawError> {
        match s {
            "xy" => Ok(View::Xy),
            "xz" => Ok(View::Xz),
            "yz" => Ok(View::Yz),
            "iso" => Ok(View::Iso),
            _ => Err(DrawError::Input(format!(
                "unknown view '{s}' (iso, xy, xz or yz)"
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso_axes_are_orthonormal_and_show_y_up() {
        assert!((dot(ISO_RIGHT, ISO_RIGHT) - 1.0).abs() < 1e-14);
        assert!((dot(ISO_UP, ISO_UP) - 1.0).abs() < 1e-14);
        assert!(dot(ISO_RIGHT, ISO_UP).abs() < 1e-14);
        // the viewing direction (1, 1, 1) projects to a point
        let d = View::Iso.project([1.0, 1.0, 1.0]);
        assert!(d[0].abs() < 1e-14 && d[1].abs() < 1e-14);
        assert!(View::Iso.project([0.0, 1.0, 0.0])[0].abs() < 1e-14);
        assert!(View::Iso.project([0.0, 1.0, 0.0])[1] > 0.8);
    }

    #[test]
    fn views_parse_by_name_and_others_are_refused() {
        for v in [View::Xy, View::Xz, View::Yz, View::Iso] {
            assert_eq!(v.name().parse::<View>().unwrap(), v);
        }
        let e = "top".parse::<View>().unwrap_err().to_string();
        assert!(
            e.contains("'top'") && e.contains("iso, xy, xz or yz"),
            "{e}"
        );
    }
}
