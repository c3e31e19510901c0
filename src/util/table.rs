//! CSV tables for reports, written atomically.

use std::path::Path;

use crate::error::{Error, Result};
use crate::util::atomic::write_atomic;

pub fn write_csv(path: &Path, header: &[&str], rows: &[Vec<String>]) -> Result<()> {
    write_atomic(path, |w| {
        let mut out = csv::Writer::from_writer(w);
        let err = |e: csv::Error| Error::bad_file(path, e.to_string());
        out.write_record(header).map_err(err)?;
        for row in rows {
            out.write_record(row).map_err(err)?;
        }
        out.flush().map_err(|e| Error::io(path, e))?;
        Ok(())
    })
}
