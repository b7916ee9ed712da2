//! Harwell–Boeing sparse matrices (Duff, Grimes & Lewis, *User's Guide for
//! the Harwell–Boeing Sparse Matrix Collection*, 1992), as ANSYS's `HBMAT`
//! writes them: four (or five) header lines, then the column pointers, the
//! row indices and the values in compressed-column form, each block in the
//! fixed-width Fortran format its header gives (e.g. `(10I8)`,
//! `(4E20.12)`), which is why the fields are cut by width, not by spaces.
//!
//! Real assembled matrices are read: `RSA` (symmetric, one triangle stored)
//! and `RUA` (unsymmetric storage of a matrix that must still be symmetric).
//! Right-hand sides after the values are ignored.

use crate::readers::check_not_cut_off;
use crate::Error;

/// A real symmetric matrix read from a Harwell–Boeing file: n and its
/// entries (0-based row, column, value) as stored.
#[derive(Debug, Clone)]
pub struct HbMatrix {
    /// Rows (= columns).
    pub n: usize,
    /// The stored entries.
    pub entries: Vec<(usize, usize, f64)>,
}

/// The repeat count and field width of a Fortran edit descriptor such as
/// `(10I8)`, `(4E20.12)`, `(1P,4D25.16)` or `(5E15.8E3)`.
fn field_width(format: &str) -> Option<(usize, usize)> {
    let f = format
        .trim()
        .trim_start_matches('(')
        .trim_end_matches(')')
        .to_ascii_uppercase();
    let item = f.rsplit(',').next()?.trim();
    // skip a scale factor such as "1P" glued to the item
    let item = item.split_once('P').map(|(_, r)| r).unwrap_or(item);
    let pos = item.find(['I', 'E', 'D', 'F', 'G'])?;
    let count: usize = if pos == 0 {
        1
    } else {
        item[..pos].parse().ok()?
    };
    let width: String = item[pos + 1..]
        .chars()
        .take_while(|c| c.is_ascii_digit())
        .collect();
    Some((count, width.parse().ok()?))
}

/// Reads `count` fields of `width` characters from consecutive lines.
fn fixed_fields<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    count: usize,
    (per_line, width): (usize, usize),
    what: &str,
    file: &str,
) -> Result<Vec<(usize, String)>, Error> {
    let mut out = Vec::with_capacity(count);
    let mut last = 0;
    while out.len() < count {
        let Some((ln, line)) = lines.next() else {
            return Err(Error::truncated(
                file,
                last,
                format!("the file ends after {} of the {count} {what}", out.len()),
            ));
        };
        last = ln + 1;
        for k in 0..per_line {
            if out.len() == count {
                break;
            }
            let a = k * width;
            if a >= line.len() {
                break;
            }
            let field = line
                .get(a..(a + width).min(line.len()))
                .unwrap_or("")
                .trim();
            if !field.is_empty() {
                out.push((ln + 1, field.to_string()));
            }
        }
    }
    Ok(out)
}

/// Parses a Harwell–Boeing file (see the module documentation).
pub fn parse_harwell_boeing(text: &str, file: &str) -> Result<HbMatrix, Error> {
    check_not_cut_off(text, file)?;
    let mut lines = text.lines().enumerate();
    let mut header = |n: usize| {
        lines
            .next()
            .map(|(_, l)| l)
            .ok_or_else(|| Error::parse(file, n, "the Harwell–Boeing header ends early"))
    };
    let _title = header(1)?;
    let counts = header(2)?;
    let rhs_lines: usize = counts
        .split_whitespace()
        .nth(4)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let kind = header(3)?;
    let k: Vec<&str> = kind.split_whitespace().collect();
    if k.len() < 4 {
        return Err(Error::parse(
            file,
            3,
            format!("expected 'TYPE nrow ncol nnz', got '{kind}'"),
        ));
    }
    let ty = k[0].to_ascii_uppercase();
    if !(ty == "RSA" || ty == "RUA") {
        return Err(Error::parse(
            file,
            3,
            format!("matrix type {ty}: only real assembled matrices (RSA, RUA) are read"),
        ));
    }
    let num = |s: &str| {
        s.parse::<usize>()
            .map_err(|_| Error::parse(file, 3, format!("'{s}' is not a count")))
    };
    let (nr, nc, nnz) = (num(k[1])?, num(k[2])?, num(k[3])?);
    if nr != nc {
        return Err(Error::parse(
            file,
            3,
            format!("the matrix is {nr} × {nc}, not square"),
        ));
    }
    // no more entries than the text can hold (a wrong count must not exhaust memory)
    if nnz > text.len() {
        return Err(Error::parse(
            file,
            3,
            format!("{nnz} entries cannot fit in a file of {} bytes", text.len()),
        ));
    }
    let formats = header(4)?;
    let parts: Vec<&str> = formats.split_whitespace().collect();
    if parts.len() < 3 {
        return Err(Error::parse(
            file,
            4,
            format!("expected the formats of pointers, indices and values, got '{formats}'"),
        ));
    }
    let fmt = |i: usize| {
        field_width(parts[i]).ok_or_else(|| {
            Error::parse(
                file,
                4,
                format!("cannot read the Fortran format '{}'", parts[i]),
            )
        })
    };
    let (pf, inf, vf) = (fmt(0)?, fmt(1)?, fmt(2)?);
    if rhs_lines > 0 {
        header(5)?;
    }
    let int = |(ln, s): &(usize, String)| {
        s.parse::<usize>()
            .map_err(|_| Error::parse(file, *ln, format!("'{s}' is not an index")))
    };
    let ptr: Vec<usize> = fixed_fields(&mut lines, nc + 1, pf, "column pointers", file)?
        .iter()
        .map(int)
        .collect::<Result<_, _>>()?;
    let rows: Vec<usize> = fixed_fields(&mut lines, nnz, inf, "row indices", file)?
        .iter()
        .map(int)
        .collect::<Result<_, _>>()?;
    let vals: Vec<f64> = fixed_fields(&mut lines, nnz, vf, "values", file)?
        .iter()
        .map(|(ln, s)| {
            s.parse::<f64>()
                .ok()
                .or_else(|| s.replace(['D', 'd'], "e").parse().ok())
                .ok_or_else(|| Error::parse(file, *ln, format!("bad value '{s}'")))
        })
        .collect::<Result<_, _>>()?;
    if ptr[0] != 1 || ptr[nc] != nnz + 1 || ptr.windows(2).any(|w| w[1] < w[0]) {
        return Err(Error::parse(
            file,
            0,
            format!(
                "the column pointers must rise from 1 to nnz + 1 = {}; they go from {} to {}",
                nnz + 1,
                ptr[0],
                ptr[nc]
            ),
        ));
    }
    let mut entries = Vec::with_capacity(nnz);
    for j in 0..nc {
        for p in (ptr[j] - 1)..(ptr[j + 1] - 1) {
            let i = rows[p];
            if i == 0 || i > nr {
                return Err(Error::parse(
                    file,
                    0,
                    format!("row index {i} outside 1..{nr} in column {}", j + 1),
                ));
            }
            entries.push((i - 1, j, vals[p]));
        }
    }
    Ok(HbMatrix { n: nr, entries })
}

/// Writes the lower triangle of a symmetric matrix given by its entries (any
/// triangle, 0-based) as an `RSA` Harwell–Boeing file, `(8I10)` and
/// `(4E25.16)`: for tests of the reader and for handing a matrix on.
pub fn write_harwell_boeing(n: usize, entries: &[(usize, usize, f64)], title: &str) -> String {
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for &(i, j, v) in entries {
        let (r, c) = (i.max(j), i.min(j));
        cols[c].push((r, v));
    }
    for c in &mut cols {
        c.sort_by_key(|x| x.0);
        c.dedup_by_key(|x| x.0);
    }
    let nnz: usize = cols.iter().map(Vec::len).sum();
    let mut ptr = vec![1usize];
    for c in &cols {
        ptr.push(ptr.last().copied().unwrap_or(1) + c.len());
    }
    let block = |items: Vec<String>, per: usize| -> Vec<String> {
        items.chunks(per).map(|c| c.concat()).collect()
    };
    let p = block(ptr.iter().map(|x| format!("{x:>10}")).collect(), 8);
    let r = block(
        cols.iter()
            .flatten()
            .map(|(i, _)| format!("{:>10}", i + 1))
            .collect(),
        8,
    );
    let v = block(
        cols.iter()
            .flatten()
            .map(|(_, x)| format!("{x:>25.16E}"))
            .collect(),
        4,
    );
    let mut out = format!("{title:<72}{:<8}\n", "KEY");
    out.push_str(&format!(
        "{:>14}{:>14}{:>14}{:>14}{:>14}\n",
        p.len() + r.len() + v.len(),
        p.len(),
        r.len(),
        v.len(),
        0
    ));
    out.push_str(&format!(
        "{:<14}{:>14}{:>14}{:>14}{:>14}\n",
        "RSA", n, n, nnz, 0
    ));
    out.push_str(&format!(
        "{:<16}{:<16}{:<20}\n",
        "(8I10)", "(8I10)", "(4E25.16)"
    ));
    for l in p.iter().chain(&r).chain(&v) {
        out.push_str(l);
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_formats_give_count_and_width() {
        assert_eq!(field_width("(10I8)"), Some((10, 8)));
        assert_eq!(field_width("(4E20.12)"), Some((4, 20)));
        assert_eq!(field_width("(1P,4D25.16)"), Some((4, 25)));
        assert_eq!(field_width("(1P4E25.16)"), Some((4, 25)));
        assert_eq!(field_width("(5E15.8E3)"), Some((5, 15)));
        assert_eq!(field_width("(I8)"), Some((1, 8)));
        assert_eq!(field_width("(X)"), None);
    }

    #[test]
    fn a_written_matrix_reads_back_and_touching_fields_are_cut_by_width() {
        let entries = vec![
            (0, 0, 4.0),
            (1, 0, -1.5e-3),
            (1, 1, 3.0),
            (2, 2, 1e10),
            (2, 0, -2.0),
        ];
        let text = write_harwell_boeing(3, &entries, "test");
        let m = parse_harwell_boeing(&text, "t.hb").unwrap();
        assert_eq!(m.n, 3);
        let mut got = m.entries.clone();
        got.sort_by_key(|a| (a.1, a.0));
        assert_eq!(
            got,
            vec![
                (0, 0, 4.0),
                (1, 0, -1.5e-3),
                (2, 0, -2.0),
                (1, 1, 3.0),
                (2, 2, 1e10)
            ]
        );
        // fields that touch (no blank between them) are still read
        let tight = "t\n 3 1 1 1 0\nRSA 2 2 2 0\n(3I2) (2I2) (2E10.3)\n 1 2 3\n 1 2\n 1.000E+00-2.000E+00\n";
        let m = parse_harwell_boeing(tight, "t.hb").unwrap();
        assert_eq!(m.entries, vec![(0, 0, 1.0), (1, 1, -2.0)]);
    }

    #[test]
    fn bad_files_are_named() {
        let text = write_harwell_boeing(2, &[(0, 0, 1.0), (1, 1, 2.0)], "t");
        let cut: String = text.lines().take(5).map(|l| format!("{l}\n")).collect();
        let e = parse_harwell_boeing(&cut, "k.hb").unwrap_err().to_string();
        assert!(e.contains("k.hb") && e.contains("ends after"), "{e}");
        let complex = text.replacen("RSA", "CSA", 1);
        let e = parse_harwell_boeing(&complex, "k.hb")
            .unwrap_err()
            .to_string();
        assert!(e.contains("only real assembled"), "{e}");
    }
}
