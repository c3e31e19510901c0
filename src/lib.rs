//! mbrl: model-based reinforcement learning as a library. The `mbrl` binary (in `cmd/`) is a thin shell
//! over these modules; see ARCHITECTURE.md for how the rooms fit together.

pub mod control;
pub mod data;
pub mod envs;
pub mod error;
pub mod eval;
pub mod filtering;
pub mod jobs;
pub mod models;
pub mod nn;
pub mod planning;
pub mod rl;
pub mod run;
pub mod sweep;
pub mod train;
pub mod tui;
pub mod util;

pub use error::{Error, ErrorKind, Result};

#[cfg(test)]
mod layering;

// The unit tests train and plan in-process: they run on the allocator the binary ships with (see util::alloc),
// so their memory behaviour is the binary's. Programs linking the library still choose their own.
#[cfg(test)]
#[global_allocator]
static TEST_ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The version written into datasets and run directories.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
