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
