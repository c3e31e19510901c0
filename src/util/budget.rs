//! The memory a command may plan to hold, checked against estimates made from its flags before any work
//! starts, so an absurd value (`--candidates 1000000000`) is refused by name instead of ending in an
//! allocation abort or hours of swapping. The limit is the global `--max-memory-gib`.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

pub const DEFAULT_LIMIT_GIB: f64 = 16.0;
const GIB: f64 = (1u64 << 30) as f64;

static LIMIT_BYTES: AtomicU64 = AtomicU64::new((DEFAULT_LIMIT_GIB * GIB) as u64);

pub fn set_limit_gib(gib: f64) {
    LIMIT_BYTES.store((gib * GIB) as u64, Ordering::Relaxed);
}

pub fn limit_bytes() -> f64 {
    LIMIT_BYTES.load(Ordering::Relaxed) as f64
}

/// Refuses when `bytes` (an estimate for what `flags` ask for) exceeds the limit. `advice` says how to
/// get the work done within it.
pub fn check(flags: &str, bytes: f64, advice: &str) -> Result<()> {
    let limit = limit_bytes();
    if bytes.is_nan() || bytes > limit {
        let message = format!(
            "{flags} would hold about {} in memory, over the limit of {}: {advice}, or raise --max-memory-gib",
            human(bytes),
            human(limit)
        );
        return Err(Error::budget("--max-memory-gib", bytes, limit, message));
    }
    Ok(())
}

/// Bytes of `count` items of `bytes_each`, in f64 so that no product of flags can overflow.
pub fn times(counts: &[usize], bytes_each: usize) -> f64 {
    counts.iter().fold(bytes_each as f64, |acc, &c| acc * c as f64)
}

fn human(bytes: f64) -> String {
    if bytes >= GIB {
        format!("{:.0} GiB", bytes / GIB)
    } else {
        format!("{:.0} MiB", bytes / (1u64 << 20) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimates_over_the_limit_name_the_flags() {
        assert!(check("--x 1", 1024.0, "use less").is_ok());
        let err = check("--candidates 1000000000 × --horizon 30", times(&[1_000_000_000, 30], 8), "use fewer")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("--candidates 1000000000 × --horizon 30 would hold about 224 GiB"), "{err}");
        assert!(err.contains("--max-memory-gib"), "{err}");
        assert!(check("--x", f64::NAN, "").is_err());
    }
}
