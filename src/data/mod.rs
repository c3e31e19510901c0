//! Rollouts and datasets on disk.

pub mod actions_csv;
pub mod ball_estimates;
#[cfg(feature = "hdf5")]
pub mod ball_hdf5;
pub mod ball_io;
pub mod boardset;
pub mod collect;
pub mod collect_ball;
pub mod collect_embodied;
pub mod collect_frames;
pub mod dataset;
pub mod export;
pub mod frames;
pub mod mcap_io;
pub mod metrics_export;
pub mod rollout;
pub mod scene;
pub mod schema;
pub mod terrain_set;

pub use dataset::{instance_pairs, read_dataset, write_dataset, Dataset, DatasetLayout, DatasetMeta, FORMAT_VERSION};
pub use rollout::{Rollout, Timestep};
