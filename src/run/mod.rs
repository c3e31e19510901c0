//! A run: its directory on disk, its configuration and its stream of events.

pub mod dir;
pub mod event;
pub mod follow;
pub mod job_record;
pub mod lock;
pub mod monitor;
pub mod watched;

pub use event::{Background, Event, PanelSpec, PathView};
pub use monitor::{ChannelMonitor, ConsoleMonitor, Fanout, JsonlMonitor, Monitor, NullMonitor, Tee};
