//! Reading a whole input file without trusting it: only regular files (a FIFO without a writer would block
//! forever, /dev/zero would never end), and never more than a stated number of bytes.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// Opens a regular file for reading, refusing FIFOs and devices by their path's type first.
pub fn open_regular(path: &Path) -> Result<std::fs::File> {
    let before = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if !before.is_file() {
        return Err(Error::bad_file(path, "not a regular file"));
    }
    std::fs::File::open(path).map_err(|e| Error::io(path, e))
}

/// Reads a regular file of at most `max` bytes (one more byte is read to detect a file that grows). The type
/// is checked on the path before opening, because opening a FIFO for reading already blocks.
pub fn read_bounded(path: &Path, max: u64) -> Result<Vec<u8>> {
    let file = open_regular(path)?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(Error::bad_file(path, "not a regular file"));
    }
    if meta.len() > max {
        return Err(Error::bad_file(path, format!("{} bytes; at most {max} expected", meta.len())));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1).read_to_end(&mut bytes).map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > max {
        return Err(Error::bad_file(path, format!("grew past {max} bytes while being read")));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_and_oversized_files_are_refused_without_blocking() {
        assert!(read_bounded(Path::new("/dev/zero"), 100).unwrap_err().to_string().contains("not a regular file"));
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.mcap");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false);
        if made {
            // Opening this FIFO would block until a writer appears; the check comes first.
            assert!(read_bounded(&fifo, 100).unwrap_err().to_string().contains("not a regular file"));
        }
        let file = dir.path().join("big");
        std::fs::write(&file, [0u8; 200]).unwrap();
        assert!(read_bounded(&file, 100).unwrap_err().to_string().contains("at most 100"));
        assert_eq!(read_bounded(&file, 200).unwrap().len(), 200);
    }
}
