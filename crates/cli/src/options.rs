//! Checks of command-line values that clap's types do not express: ranges
//! of counts and tolerances, and that the output location can be written,
//! all before any computation. Each failure is invalid input (exit code 2)
//! naming the option and the value given.

use crate::Failure;
use flexmb_model::Mechanism;
use std::path::Path;

/// `value` of `option` must be at least `min`; `why` says what the count is.
pub(crate) fn at_least(option: &str, value: usize, min: usize, why: &str) -> Result<(), Failure> {
    if value < min {
        return Err(Failure::Input(format!(
            "{option} must be at least {min} ({why}); got {value}"
        )));
    }
    Ok(())
}

/// The number of modes: `--modes` if given (at most the degrees of
/// freedom), else `default` or every degree of freedom if there are fewer.
pub(crate) fn modes_or_default(
    modes: Option<usize>,
    default: usize,
    mech: &Mechanism,
) -> Result<usize, Failure> {
    match modes {
        Some(k) => at_most_dofs("--modes", k, mech).map(|_| k),
        None => Ok(default.min(mech.n_dof())),
    }
}

/// `modes` of `option` must not exceed the mechanism's degrees of freedom.
pub(crate) fn at_most_dofs(option: &str, modes: usize, mech: &Mechanism) -> Result<(), Failure> {
    let n = mech.n_dof();
    if modes > n {
        return Err(Failure::Input(format!(
            "{option} {modes}: the scene has {n} degrees of freedom, so at most {n} modes"
        )));
    }
    Ok(())
}

/// `value` of `option` must be a finite number.
pub(crate) fn finite(option: &str, value: f64) -> Result<(), Failure> {
    if !value.is_finite() {
        return Err(Failure::Input(format!(
            "{option} must be a finite number; got {value}"
        )));
    }
    Ok(())
}

/// `value` of `option` must be positive and finite.
pub(crate) fn positive(option: &str, value: f64) -> Result<(), Failure> {
    if !(value > 0.0 && value.is_finite()) {
        return Err(Failure::Input(format!(
            "{option} must be positive and finite; got {value}"
        )));
    }
    Ok(())
}

/// The two ends of a range must differ.
pub(crate) fn distinct_ends(from: f64, to: f64) -> Result<(), Failure> {
    if from == to {
        return Err(Failure::Input(format!(
            "--from and --to must differ (the range of the sweep); both are {from}"
        )));
    }
    Ok(())
}

/// An invalid-input error naming the output location `path` of `option`.
fn unwritable(option: &str, path: &Path, why: impl std::fmt::Display) -> Failure {
    Failure::Input(format!(
        "{option} {}: cannot write there: {why}",
        path.display()
    ))
}

/// Creates a probe file in the directory `dir` and removes it again.
fn probe(option: &str, dir: &Path, shown: &Path) -> Result<(), Failure> {
    let p = dir.join(format!(".flexmb-write-probe-{}", std::process::id()));
    std::fs::write(&p, b"").map_err(|e| unwritable(option, shown, e))?;
    let _ = std::fs::remove_file(&p);
    Ok(())
}

/// The output directory `dir` of `option` exists (it is created) and a file
/// can be written in it.
pub(crate) fn writable_dir(option: &str, dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| unwritable(option, dir, e))?;
    probe(option, dir, dir)
}

/// The output file `file` of `option` can be written: it is no directory,
/// its directory exists (it is created) and takes a file, and an existing
/// `file` can be opened for writing (it is not changed).
pub(crate) fn writable_file(option: &str, file: &Path) -> Result<(), Failure> {
    if file.is_dir() {
        return Err(unwritable(option, file, "it is a directory"));
    }
    let dir = file
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if dir.exists() && !dir.is_dir() {
        return Err(unwritable(
            option,
            file,
            format!("{} is not a directory", dir.display()),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| unwritable(option, file, e))?;
    if file.exists() {
        std::fs::OpenOptions::new()
            .append(true)
            .open(file)
            .map_err(|e| unwritable(option, file, e))?;
        return Ok(());
    }
    probe(option, dir, file)
}
