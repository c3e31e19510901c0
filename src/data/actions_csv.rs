//! Action sequences given as CSV, for replaying them in a simulator: one row per step, one column per action
//! dimension, an optional header row.

use std::io::Read;
use std::path::Path;

use crate::data::dataset::RECORDED;
use crate::error::{Error, Result};

/// More steps than any experiment needs; a file beyond it is a mistake, not a workload.
pub const MAX_ACTION_ROWS: usize = 1_000_000;
/// Bounds what is read at all, so an endless stream (a pipe, /dev/zero) fails instead of filling memory.
pub const MAX_ACTION_BYTES: u64 = 64 << 20;

/// Reads the actions in `path`, each row exactly `action_dim` finite numbers within the range every dataset
/// reader accepts (±1e9): the env clips an action to its bounds when it steps, but the replay records the action
/// as given, and a dataset its own readers refuse is no output. The first row is taken as a
/// header when it is not all numbers.
pub fn read_actions(path: &Path, action_dim: usize) -> Result<Vec<Vec<f64>>> {
    let file = crate::util::bounded_read::open_regular(path)?;
    parse_actions(path, file.take(MAX_ACTION_BYTES + 1), action_dim, Limits::DEFAULT)
}

/// The bounds, separate so tests can exercise them without reading 64 MiB.
#[derive(Clone, Copy)]
struct Limits {
    bytes: u64,
    rows: usize,
}

impl Limits {
    const DEFAULT: Limits = Limits { bytes: MAX_ACTION_BYTES, rows: MAX_ACTION_ROWS };
}

fn parse_actions(path: &Path, input: impl Read, action_dim: usize, limits: Limits) -> Result<Vec<Vec<f64>>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        // Rows of the wrong width are reported by us, with the expected width, not as csv's generic error.
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(input);
    let too_large = || {
        let size = if limits.bytes >= 1 << 20 {
            format!("{} MiB", limits.bytes >> 20)
        } else {
            format!("{} bytes", limits.bytes)
        };
        Error::bad_file(path, format!("larger than {size}; expected at most {} action rows", limits.rows))
    };
    let mut record = csv::StringRecord::new();
    let mut rows = Vec::new();
    let mut first = true;
    loop {
        let more = reader.read_record(&mut record).map_err(|e| match e.kind() {
            csv::ErrorKind::Io(_) if reader.position().byte() > limits.bytes => too_large(),
            _ => Error::bad_file(path, format!("not readable as CSV: {e}")),
        })?;
        if reader.position().byte() > limits.bytes {
            return Err(too_large());
        }
        if !more {
            break;
        }
        let row = record.position().map_or(rows.len() as u64 + 1, |p| p.line());
        let is_header = first && !record.iter().all(|field| field.parse::<f64>().is_ok());
        first = false;
        check_width(path, row, record.len(), action_dim)?;
        if is_header {
            continue;
        }
        if rows.len() == limits.rows {
            return Err(Error::bad_file(
                path,
                format!("more than {} action rows; expected at most that many steps", limits.rows),
            ));
        }
        rows.push(parse_row(path, row, &record)?);
    }
    if rows.is_empty() {
        return Err(Error::bad_file(
            path,
            format!("no action rows; expected one row per step with {action_dim} number(s), after an optional header"),
        ));
    }
    Ok(rows)
}

fn check_width(path: &Path, row: u64, width: usize, action_dim: usize) -> Result<()> {
    if width == action_dim {
        return Ok(());
    }
    Err(Error::bad_file(
        path,
        format!("row {row} has {width} column(s); expected {action_dim}, one per action dimension of the env"),
    ))
}

fn parse_row(path: &Path, row: u64, record: &csv::StringRecord) -> Result<Vec<f64>> {
    record
        .iter()
        .enumerate()
        .map(|(i, field)| {
            let column = i + 1;
            let value: f64 = field
                .parse()
                .map_err(|_| Error::bad_file(path, format!("row {row}, column {column}: '{field}' is not a number")))?;
            if RECORDED.contains(value) {
                return Ok(value);
            }
            let e = RECORDED.check(&format!("row {row}, column {column}"), value).unwrap_err();
            Err(Error::bad_file(path, format!("{e} (the env clips an action to its bounds; this is no action)")))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, dim: usize) -> Result<Vec<Vec<f64>>> {
        parse_actions(Path::new("a.csv"), text.as_bytes(), dim, Limits::DEFAULT)
    }

    #[test]
    fn rows_with_and_without_header() {
        assert_eq!(parse("0.5\n-1\n2e-1\n", 1).unwrap(), vec![vec![0.5], vec![-1.0], vec![0.2]]);
        assert_eq!(parse("u1, u2\n1, 2\n3,4", 2).unwrap(), vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
    }

    #[test]
    fn bad_cells_name_row_and_column() {
        let err = parse("u\n1\nabc\n", 1).unwrap_err().to_string();
        assert!(err.starts_with("a.csv: row 3, column 1: 'abc' is not a number"), "{err}");
        let err = parse("1,2\n3,NaN\n", 2).unwrap_err().to_string();
        assert!(err.contains("row 2, column 2 = NaN: expected a finite number in [-1e9, 1e9]"), "{err}");
        let err = parse("1\n-1e300\n", 1).unwrap_err().to_string();
        assert!(err.contains("row 2, column 1 = -1e300: expected a finite number"), "{err}");
        let err = parse("1\ninf\n", 1).unwrap_err().to_string();
        assert!(err.contains("row 2, column 1") && err.contains("finite"), "{err}");
    }

    #[test]
    fn wrong_width_is_named_with_the_expected_width() {
        let err = parse("1\n2,3\n", 1).unwrap_err().to_string();
        assert!(err.contains("row 2 has 2 column(s); expected 1"), "{err}");
        let err = parse("a,b\n1\n", 1).unwrap_err().to_string();
        assert!(err.contains("row 1 has 2 column(s)"), "a header of the wrong width is wrong too: {err}");
    }

    #[test]
    fn empty_and_header_only_files_are_rejected() {
        for text in ["", "\n\n", "u\n"] {
            let err = parse(text, 1).unwrap_err().to_string();
            assert!(err.contains("no action rows"), "{text:?}: {err}");
        }
    }

    #[test]
    fn endless_input_is_cut_off() {
        let small = Limits { bytes: 1000, rows: 50 };
        // One endless field, and endless short rows: both stop at the byte bound, not at the row bound.
        for pattern in ["1", "1\n"] {
            let stream = pattern.repeat(2000);
            let input = stream.as_bytes().take(small.bytes + 1);
            let err = parse_actions(Path::new("pipe"), input, 1, Limits { rows: 1_000_000, ..small }).unwrap_err();
            assert!(err.to_string().contains("larger than 1000 bytes"), "{err}");
        }
        let many = "0\n".repeat(51);
        let err = parse_actions(Path::new("a.csv"), many.as_bytes(), 1, small).unwrap_err().to_string();
        assert!(err.contains("more than 50 action rows"), "{err}");
        assert_eq!(parse_actions(Path::new("a.csv"), "0\n".repeat(50).as_bytes(), 1, small).unwrap().len(), 50);
    }
}
