//! Every result is checked for finite values before it is written or printed:
//! a NaN or an infinity is never output as a number. It is an error (exit
//! code 1) that names the culprit: the mode, the output column and time, the
//! configuration of a sweep, the coordinate of an equilibrium.

use crate::Failure;

/// What usually makes a result non-finite.
const HINT: &str = "the results are not written; extreme input data (e.g. a modulus or density near the limits of floating point) or a diverging solution make results overflow";

/// An error for the first non-finite of `values`, each named by `name(index)`.
pub(crate) fn check(
    what: &str,
    values: impl IntoIterator<Item = f64>,
    name: impl Fn(usize) -> String,
) -> Result<(), Failure> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((i, v)) => Err(Failure::Compute(format!(
            "{what}: {} is {v}, not a finite number; {HINT}",
            name(i)
        ))),
        None => Ok(()),
    }
}

/// [`check`] over a table's rows: names the column and the row by the value
/// of its first column (the time, the sweep parameter).
pub(crate) fn check_table(what: &str, header: &[String], rows: &[Vec<f64>]) -> Result<(), Failure> {
    let column = |c: usize| {
        header
            .get(c)
            .cloned()
            .unwrap_or_else(|| format!("{}", c + 1))
    };
    for (r, row) in rows.iter().enumerate() {
        check(what, row.iter().copied(), |c| {
            format!(
                "column `{}` at {} = {} (row {})",
                column(c),
                column(0),
                row[0],
                r + 1
            )
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(r: Result<(), Failure>) -> String {
        match r {
            Err(Failure::Compute(m)) => m,
            Err(_) => panic!("a non-finite result must be a computation failure (exit code 1)"),
            Ok(()) => panic!("expected an error"),
        }
    }

    #[test]
    fn a_non_finite_table_entry_is_named_by_column_and_first_column() {
        let header = ["t".to_string(), "tip.x".to_string(), "tip.y".to_string()];
        let rows = vec![vec![0.0, 1.0, 2.0], vec![0.5, 1.0, f64::NAN]];
        assert!(check_table("simulate outputs", &header, &rows[..1]).is_ok());
        let m = message(check_table("simulate outputs", &header, &rows));
        assert!(
            m.starts_with("simulate outputs: column `tip.y` at t = 0.5 (row 2) is NaN"),
            "{m}"
        );
        let m = message(check("eig", [1.0, f64::INFINITY], |i| {
            format!("mode {}", i + 1)
        }));
        assert!(m.contains("mode 2 is inf"), "{m}");
    }
}
