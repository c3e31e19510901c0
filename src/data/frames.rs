//! Camera frames stored beside a dataset's timesteps (DLGPD learns from them): one frame per state, so a
//! rollout of T transitions has T + 1 frames, t = 0 … T. On disk each frame is a Foxglove CompressedImage
//! message (PNG, base64 in JSON) on its own topic, timed with the transition that starts from that state.

use std::path::Path;

use base64::Engine;
use serde::{Deserialize, Serialize};

use super::mcap_io::{message_clock, ExtraChannel, Layout};
use super::rollout::Timestep;
use super::schema::{FRAME_SCHEMA, FRAME_SCHEMA_NAME, FRAME_TOPIC};
use crate::error::{Error, Result};
use crate::util::png::{decode_rgb, encode_rgb};

/// What the metadata says about a dataset's frames (field `frames`, absent when it has none).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameInfo {
    pub width: u32,
    pub height: u32,
    /// How the frames were drawn, e.g. `gym-pendulum`.
    pub renderer: String,
}

impl FrameInfo {
    pub fn bytes_per_frame(&self) -> usize {
        self.width as usize * self.height as usize * 3
    }
}

#[derive(Serialize, Deserialize)]
struct Stamp {
    sec: u64,
    nsec: u32,
}

#[derive(Serialize, Deserialize)]
struct FrameMessage {
    timestamp: Stamp,
    frame_id: String,
    data: String,
    format: String,
    rollout: u32,
    t: u32,
}

/// The (rollout, t) of every frame a dataset with these steps must hold, in order, with the index of the
/// step whose clock each frame shares (for t = T: the rollout's last step).
pub fn frame_slots(steps: &[Timestep]) -> Vec<(u32, u32, usize)> {
    let mut slots = Vec::with_capacity(steps.len() + steps.len() / 8);
    for (i, step) in steps.iter().enumerate() {
        slots.push((step.rollout, step.t, i));
        let last_of_rollout = steps.get(i + 1).is_none_or(|next| next.rollout != step.rollout || next.t == 0);
        if last_of_rollout {
            slots.push((step.rollout, step.t + 1, i));
        }
    }
    slots
}

/// The frames as the messages of the `/frames` channel.
pub fn frame_channel<'a>(
    info: &FrameInfo,
    steps: &[Timestep],
    frames: &[Vec<u8>],
    layout: &Layout,
) -> Result<ExtraChannel<'a>> {
    let slots = frame_slots(steps);
    if slots.len() != frames.len() {
        return Err(Error::data(format!(
            "{} frames for {} states (one per state: each rollout's transitions + 1)",
            frames.len(),
            slots.len()
        )));
    }
    let mut messages = Vec::with_capacity(frames.len());
    for (&(rollout, t, step), rgb) in slots.iter().zip(frames) {
        let mut clock = message_clock(layout, step);
        if t > steps[step].t {
            clock += layout.tick_ns.max(2) / 2;
        }
        let png = encode_rgb(info.width, info.height, rgb)?;
        let message = FrameMessage {
            timestamp: Stamp { sec: clock / 1_000_000_000, nsec: (clock % 1_000_000_000) as u32 },
            frame_id: info.renderer.clone(),
            data: base64::engine::general_purpose::STANDARD.encode(png),
            format: "png".into(),
            rollout,
            t,
        };
        let bytes = serde_json::to_vec(&message).map_err(|e| Error::data(e.to_string()))?;
        messages.push((clock, bytes));
    }
    Ok(ExtraChannel { topic: FRAME_TOPIC, schema_name: FRAME_SCHEMA_NAME, schema: FRAME_SCHEMA, messages })
}

/// Decodes and checks the frame messages of a file: one per state, in order, each a PNG of the declared size.
pub fn read_frames(path: &Path, info: &FrameInfo, steps: &[Timestep], raw: Vec<Vec<u8>>) -> Result<Vec<Vec<u8>>> {
    let slots = frame_slots(steps);
    if raw.len() != slots.len() {
        return Err(Error::bad_file(
            path,
            format!(
                "{FRAME_TOPIC}: {} frames for {} states; expected one per state (each rollout's transitions + 1)",
                raw.len(),
                slots.len()
            ),
        ));
    }
    raw.into_iter()
        .zip(slots)
        .enumerate()
        .map(|(i, (bytes, (rollout, t, _)))| {
            let bad = |what: String| Error::bad_file(path, format!("{FRAME_TOPIC} message {i}: {what}"));
            let message: FrameMessage = serde_json::from_slice(&bytes).map_err(|e| bad(e.to_string()))?;
            if (message.rollout, message.t) != (rollout, t) {
                return Err(bad(format!(
                    "is rollout {}, t {}; expected rollout {rollout}, t {t}",
                    message.rollout, message.t
                )));
            }
            if message.format != "png" {
                return Err(bad(format!("format '{}' is not supported; expected png", message.format)));
            }
            let png = base64::engine::general_purpose::STANDARD
                .decode(message.data.as_bytes())
                .map_err(|e| bad(format!("data is not base64: {e}")))?;
            decode_rgb(&png, info.width, info.height).map_err(bad)
        })
        .collect()
}
