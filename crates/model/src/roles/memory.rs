//! The large-model memory checks: a dense matrix is allocated only when it
//! needs at most a quarter of the physical memory, else the choice of DOFs
//! (thesis (6.4)) refuses it with its size.

use super::*;

/// Physical memory in bytes (`MemTotal` of /proc/meminfo, else 8 GiB).
pub(crate) fn physical_memory() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("MemTotal:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or(8 << 30, |kb| kb * 1024)
}

/// A byte count for people: 4.8 TB, 512 MB.
pub(crate) fn human_bytes(b: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if k == 0 {
        format!("{v:.0} {}", units[k])
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// Checks before allocating `copies` dense `rows × cols` matrices of f64 that
/// they need at most a quarter of the physical memory.
pub(crate) fn check_dense(
    what: &str,
    rows: usize,
    cols: usize,
    copies: usize,
) -> Result<(), ModelError> {
    check_dense_against(what, rows, cols, copies, physical_memory() / 4)
}

pub(super) fn dense_bytes(rows: usize, cols: usize, copies: usize) -> f64 {
    rows as f64 * cols as f64 * copies as f64 * 8.0
}

fn check_dense_against(
    what: &str,
    rows: usize,
    cols: usize,
    copies: usize,
    limit: u64,
) -> Result<(), ModelError> {
    let bytes = dense_bytes(rows, cols, copies);
    if bytes > limit as f64 {
        return Err(ModelError::TooLarge {
            what: format!(
                "{what} of {rows} × {cols} would need {} dense ({} elements{})",
                human_bytes(bytes),
                rows as u128 * cols as u128,
                if copies > 1 {
                    format!(", {copies} copies")
                } else {
                    String::new()
                }
            ),
            limit: human_bytes(limit as f64),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dense_matrix_too_large_is_refused_with_its_size() {
        let e = check_dense_against("the constraint Jacobian", 720_000, 840_000, 1, 6 << 30)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("720000 × 840000")
                && e.contains("4.8 TB")
                && e.contains("604800000000 elements")
                && e.contains("6.4 GB"),
            "{e}"
        );
        assert!(check_dense_against("x", 1000, 1000, 2, 6 << 30).is_ok());
    }
}
