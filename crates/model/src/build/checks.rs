//! Checks of scene values shared by the stages of the build: finite vectors
//! and 3-vectors, time functions, and the "did you mean" hint of an unknown
//! id.

use super::*;

pub(super) fn finite_vec(ctx: &str, v: &[f64]) -> Result<(), ModelError> {
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(ModelError::invalid(
            ctx,
            format!("contains a non-finite value {x}"),
        ));
    }
    Ok(())
}

pub(super) fn closest<'a>(id: &str, candidates: impl Iterator<Item = &'a String>) -> String {
    match flexmb_input::nearest(id, candidates) {
        Some(c) => format!(" (did you mean '{c}'?)"),
        None => String::new(),
    }
}

pub(super) fn vec3(ctx: &str, what: &str, v: &[f64]) -> Result<[f64; 3], ModelError> {
    if v.len() != 3 {
        return Err(ModelError::invalid(
            ctx,
            format!("{what} must have 3 components, got {}", v.len()),
        ));
    }
    finite_vec(&format!("{ctx} {what}"), v)?;
    Ok([v[0], v[1], v[2]])
}

pub(crate) fn opt_vec3(
    ctx: &str,
    what: &str,
    v: &Option<Vec<f64>>,
) -> Result<[f64; 3], ModelError> {
    match v {
        Some(v) => vec3(ctx, what, v),
        None => Ok([0.0; 3]),
    }
}

pub(crate) fn check_function(ctx: &str, f: &TimeFunction) -> Result<(), ModelError> {
    f.validate().map_err(|m| ModelError::invalid(ctx, m))
}
