//! JSON Schemas of the dataset messages, embedded in every MCAP file so generic viewers (Foxglove, the
//! mcap CLI) can decode them.

pub const TIMESTEP_SCHEMA_NAME: &str = "mbrl.Timestep";
pub const TIMESTEP_TOPIC: &str = "/rollouts";

pub const TIMESTEP_SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "mbrl.Timestep",
  "description": "One transition of a rollout: state s_t, action a_t, reward r_t, next state s_{t+1}.",
  "type": "object",
  "required": ["rollout", "t", "state", "action", "reward", "next_state"],
  "properties": {
    "rollout": {"type": "integer", "minimum": 0, "description": "rollout id, unique within the dataset"},
    "t": {"type": "integer", "minimum": 0, "description": "time step within the rollout, from 0"},
    "state": {"type": "array", "items": {"type": "number"}},
    "action": {"type": "array", "items": {"type": "number"}},
    "reward": {"type": "number"},
    "next_state": {"type": "array", "items": {"type": "number"}},
    "obs": {"type": "array", "items": {"type": "number"}, "description": "observation before the step"},
    "next_obs": {"type": "array", "items": {"type": "number"}, "description": "observation after the step"}
  }
}"#;

/// Camera frames of a dataset's states, as Foxglove's CompressedImage (so its Image panel shows them) with the
/// rollout and time step they belong to.
pub const FRAME_SCHEMA_NAME: &str = "foxglove.CompressedImage";
pub const FRAME_TOPIC: &str = "/frames";

pub const FRAME_SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "foxglove.CompressedImage",
  "description": "A rendered frame of state s_t of a rollout (t = 0 … T: one more frame than transitions), PNG-encoded.",
  "type": "object",
  "required": ["timestamp", "frame_id", "data", "format", "rollout", "t"],
  "properties": {
    "timestamp": {
      "type": "object",
      "title": "time",
      "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}
    },
    "frame_id": {"type": "string"},
    "data": {"type": "string", "contentEncoding": "base64", "description": "PNG bytes"},
    "format": {"type": "string", "description": "always png"},
    "rollout": {"type": "integer", "minimum": 0},
    "t": {"type": "integer", "minimum": 0, "description": "the state's time step; t = T is the rollout's last next_state"}
  }
}"#;
