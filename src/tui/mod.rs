//! The live view of a running job: an [`App`] that folds the event stream into state, a renderer that
//! draws it, and a terminal loop that ties both to a real terminal. State and drawing are kept free of
//! terminal I/O so they can be tested against ratatui's `TestBackend`.

pub mod app;
mod keys;
mod method;
mod overlay;
mod overlay_view;
mod panel;
mod path;
mod plot;
pub mod render;
mod series;
pub mod terminal;
mod text_panel;

pub use app::App;
pub use terminal::{run_live, run_overlay, LiveOptions, LiveOutcome, DEFAULT_GRACE};
