//! CSV tables: `#`-comment lines, a header, rows of numbers.

use std::fmt::Write as _;
use std::io;
use std::path::Path;

/// Writes a CSV file: optional `#`-comment header lines, a column header, rows.
pub fn write_csv(
    path: &Path,
    comments: &[String],
    header: &[String],
    rows: &[Vec<f64>],
) -> io::Result<()> {
    let mut s = String::new();
    for c in comments {
        let _ = writeln!(s, "# {c}");
    }
    let _ = writeln!(s, "{}", header.join(","));
    for r in rows {
        let line: Vec<String> = r.iter().map(|v| format!("{v:.12e}")).collect();
        let _ = writeln!(s, "{}", line.join(","));
    }
    std::fs::write(path, s)
}

/// Reads a CSV written by [`write_csv`]: (header, rows), skipping `#` comments.
pub fn read_csv(path: &Path) -> io::Result<(Vec<String>, Vec<Vec<f64>>)> {
    let text = std::fs::read_to_string(path)?;
    let mut header = vec![];
    let mut rows = vec![];
    for (k, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        if header.is_empty() {
            header = line.split(',').map(|s| s.trim().to_string()).collect();
            continue;
        }
        let r: Result<Vec<f64>, _> = line.split(',').map(|s| s.trim().parse::<f64>()).collect();
        rows.push(r.map_err(|e| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: line {}: {e}", path.display(), k + 1),
            )
        })?);
    }
    Ok((header, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trips_and_a_bad_number_names_its_line() {
        let dir = std::env::temp_dir().join(format!("flexmb-plot-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.csv");
        let rows = vec![vec![0.0, 1.5], vec![1.0, -2.25e-7]];
        write_csv(
            &p,
            &["made by a test".into()],
            &["t".into(), "x".into()],
            &rows,
        )
        .unwrap();
        let (h, r) = read_csv(&p).unwrap();
        assert_eq!(h, vec!["t", "x"]);
        assert_eq!(r, rows);
        std::fs::write(&p, "t,x\n0,1\n1,oops\n").unwrap();
        let e = read_csv(&p).unwrap_err().to_string();
        assert!(e.contains("line 3"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
