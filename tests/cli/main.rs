//! The end-to-end tests, one module per area, in one test binary: each integration test file used to be its
//! own binary linking the whole library, so a change to `src/` relinked twenty of them.
//!
//! `cargo test --release --test cli pets::` runs one module's tests.

mod common;

mod bad_input;
mod ball;
mod board_tables;
mod boards;
mod collect;
mod context;
mod dlgpd;
mod embodied;
mod eval_render;
mod export;
mod foxglove_schemas;
mod jaco;
mod kill;
mod list;
mod outputs;
mod overrides;
mod pendulum_plan;
mod pendulum_reference;
mod pets;
mod seads;
mod surface;
mod sweep;
mod sweep_slurm;
mod tradyn;
mod train_methods;
mod unicycle;
mod watch_export;
