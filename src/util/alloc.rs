//! The process allocator. A context-model training step allocates and frees hundreds of multi-megabyte tensors.
//! glibc's malloc and mimalloc's defaults hand such blocks back to the kernel within milliseconds, so the next
//! step faults the pages in again and the kernel zeroes them: 40 % of a step in perf, 650 ms instead of 390 ms
//! at batch 64. mimalloc with purging switched off keeps freed memory for reuse; the price is that a process
//! keeps its peak footprint until it exits, which suits a command-line run.
//!
//! The `#[global_allocator]` itself is declared by the programs (the `mbrl` binary in `cmd/main.rs`, and the
//! benchmarks, whose figures are meant to be the binary's): a library that picks the process allocator
//! forces it on every program linking it. Where the allocator is not mimalloc, `keep_freed_memory` sets an
//! option nobody reads, and nothing else changes.

use std::sync::Once;

/// mimalloc's `mi_option_purge_delay` (position 15 of `mi_option_e` in both v2 and v3; libmimalloc-sys names
/// the options around it but not this one).
const PURGE_DELAY_OPTION: libmimalloc_sys::mi_option_t = 15;

/// Stop returning freed memory to the kernel. Called by the tensor devices, so every training and planning run
/// (CLI, tests, benchmarks) gets it without a call in each `main`.
pub fn keep_freed_memory() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // SAFETY: mi_option_set only stores an integer in mimalloc's option table; −1 is the documented value
        // for "never purge".
        unsafe { libmimalloc_sys::mi_option_set(PURGE_DELAY_OPTION, -1) };
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn purge_delay_is_the_option_we_set() {
        keep_freed_memory();
        // SAFETY: reads an integer from mimalloc's option table.
        let value = unsafe { libmimalloc_sys::mi_option_get(PURGE_DELAY_OPTION) };
        assert_eq!(value, -1);
    }
}
