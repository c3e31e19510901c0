//! Filter output on disk: one estimate per camera frame, as CSV (mean and standard deviations) and MCAP
//! (mean and full covariance).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::mcap_io::{check_version, metadata_field, read_messages, write_messages_with, Layout};
use super::scene::{scene_channel, ScenePoint, ESTIMATED};
use crate::error::{Error, Result};
use crate::util::table::write_csv;

pub const STATE_NAMES: [&str; 11] = ["px", "py", "pz", "vx", "vy", "vz", "wx", "wy", "wz", "a_d", "a_m"];
pub const METADATA_NAME: &str = "mbrl.ball_estimates";
pub const TOPIC: &str = "/ball/estimates";
/// The filter means as `foxglove.SceneUpdate`, for Foxglove's 3D panel.
pub const SCENE_TOPIC: &str = "/ball/estimates/scene";
const FORMAT_VERSION: u32 = 1;
const SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "mbrl.BallEstimate",
  "description": "EKF belief about the ball state z = (p, v, w, a_d, a_m) after a camera frame.",
  "type": "object",
  "required": ["trajectory", "frame", "t", "mean", "covariance", "after_impact"],
  "properties": {
    "trajectory": {"type": "integer"},
    "frame": {"type": "integer"},
    "t": {"type": "number"},
    "measurement": {"type": ["array", "null"], "items": {"type": "number"}},
    "mean": {"type": "array", "items": {"type": "number"}, "minItems": 11, "maxItems": 11},
    "covariance": {"type": "array", "items": {"type": "number"}, "minItems": 121, "maxItems": 121,
                   "description": "row-major 11x11"},
    "after_impact": {"type": "boolean"}
  }
}"#;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BallEstimate {
    pub trajectory: u32,
    pub frame: u64,
    pub t: f64,
    pub measurement: Option<[f64; 3]>,
    pub mean: [f64; 11],
    pub covariance: Vec<f64>,
    pub after_impact: bool,
}

pub fn write_estimates_csv(path: &Path, estimates: &[BallEstimate]) -> Result<()> {
    let mut header: Vec<String> =
        ["trajectory", "frame", "t", "mx", "my", "mz"].iter().map(|s| s.to_string()).collect();
    header.extend(STATE_NAMES.iter().map(|s| s.to_string()));
    header.extend(STATE_NAMES.iter().map(|s| format!("std_{s}")));
    header.push("after_impact".into());
    let rows: Vec<Vec<String>> = estimates
        .iter()
        .map(|e| {
            let mut row = vec![e.trajectory.to_string(), e.frame.to_string(), format!("{:.6}", e.t)];
            match e.measurement {
                Some(m) => row.extend(m.iter().map(|x| format!("{x:.6}"))),
                None => row.extend(["", "", ""].iter().map(|s| s.to_string())),
            }
            row.extend(e.mean.iter().map(|x| format!("{x:.6e}")));
            row.extend((0..11).map(|i| format!("{:.6e}", e.covariance[i * 11 + i].max(0.0).sqrt())));
            row.push(e.after_impact.to_string());
            row
        })
        .collect();
    let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv(path, &header_refs, &rows)
}

pub fn write_estimates_mcap(path: &Path, model: &str, command_line: &str, estimates: &[BallEstimate]) -> Result<()> {
    let layout = Layout {
        metadata_name: METADATA_NAME,
        topic: TOPIC,
        schema_name: "mbrl.BallEstimate",
        schema: SCHEMA,
        tick_ns: (1e9 / super::ball_io::FRAME_RATE) as u64,
    };
    let metadata = BTreeMap::from([
        ("format_version".to_string(), FORMAT_VERSION.to_string()),
        ("model".to_string(), model.to_string()),
        ("command_line".to_string(), command_line.to_string()),
        ("mbrl_version".to_string(), crate::VERSION.to_string()),
    ]);
    let points = estimates.iter().map(|e| ScenePoint {
        trajectory: e.trajectory,
        frame: e.frame,
        position: Some([e.mean[0], e.mean[1], e.mean[2]]),
    });
    let scene = scene_channel(SCENE_TOPIC, &layout, points, ESTIMATED);
    write_messages_with(path, &layout, metadata, estimates, Some(&scene))
}

/// An estimates file as `filter --out F.mcap` writes it.
#[derive(Clone, Debug, PartialEq)]
pub struct EstimatesFile {
    pub model: String,
    pub command_line: String,
    pub estimates: Vec<BallEstimate>,
}

pub fn read_estimates_mcap(path: &Path) -> Result<EstimatesFile> {
    let (meta, messages) = read_messages::<BallEstimate>(path, METADATA_NAME, TOPIC)?;
    check_version(path, &meta, FORMAT_VERSION)?;
    let mut estimates = Vec::with_capacity(messages.len());
    for (sequence, estimate) in messages {
        let dim = STATE_NAMES.len();
        if estimate.covariance.len() != dim * dim {
            return Err(Error::bad_file(
                path,
                format!(
                    "message {sequence}: covariance has {} entries; expected {} (row-major {dim} × {dim})",
                    estimate.covariance.len(),
                    dim * dim
                ),
            ));
        }
        estimates.push(estimate);
    }
    Ok(EstimatesFile {
        model: metadata_field(path, &meta, "model")?,
        command_line: metadata_field(path, &meta, "command_line")?,
        estimates,
    })
}
