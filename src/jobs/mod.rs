//! What each subcommand does, below the shell. A job module holds the subcommand's options (declared with
//! clap, so each flag's help is written where the flag is), the checks and defaults that turn them into work,
//! and the typed summary the binary prints. `cmd/` parses the command line, picks the view (live TUI,
//! progress lines or quiet) and prints; everything a command decides lives here, where scripts of the library
//! and tests get the same behaviour as the command line.
//!
//! The one room that knows clap: the engine below never parses flags.

pub mod calibrate;
pub mod cem_options;
pub mod choices;
pub mod collect;
mod common;
pub mod eval;
pub mod export;
pub mod filter;
pub mod list;
pub mod model_options;
pub mod names;
pub mod overrides;
pub mod plan;
pub mod predict;
pub mod solve_board;
pub mod sweep;
pub mod train;

pub use common::{
    check_output_file, file_stem, finite_f64, output_dir, output_file, parse_floats, pendulum_variant, warn,
    Invocation, Job, STEP_RECORD_BYTES,
};
