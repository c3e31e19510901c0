//! Ball positions as Foxglove `SceneUpdate` messages beside the recordings' own messages, so that Foxglove's
//! 3D panel shows a shot as it flies: one small sphere per measured (or estimated) position, kept until the
//! next trajectory starts, which clears the scene.

use serde::Serialize;

use super::mcap_io::{message_clock, ExtraChannel, Layout};

pub const SCENE_SCHEMA_NAME: &str = "foxglove.SceneUpdate";

/// The part of Foxglove's published `foxglove.SceneUpdate` schema these messages use; every message also
/// validates against the published schema itself (tests/fixtures/foxglove).
pub const SCENE_SCHEMA: &str = r##"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "foxglove.SceneUpdate",
  "description": "Ball positions for Foxglove's 3D panel: per camera frame one sphere entity (deletions clear the previous trajectory).",
  "type": "object",
  "required": ["deletions", "entities"],
  "properties": {
    "deletions": {"type": "array", "items": {"type": "object", "required": ["timestamp", "type", "id"]}},
    "entities": {
      "type": "array",
      "items": {
        "type": "object",
        "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes",
                     "spheres", "cylinders", "lines", "triangles", "texts", "models"],
        "properties": {
          "frame_id": {"type": "string", "description": "world: the table frame of the recordings (metres)"},
          "spheres": {"type": "array", "items": {"type": "object", "required": ["pose", "size", "color"]}}
        }
      }
    }
  }
}"##;

/// Frame of reference every entity is drawn in: the recordings' table frame.
const FRAME_ID: &str = "world";
/// Sphere diameter: a table-tennis ball (40 mm).
const BALL_DIAMETER: f64 = 0.04;

#[derive(Serialize)]
struct Time {
    sec: u64,
    nsec: u32,
}

impl Time {
    fn of(clock_ns: u64) -> Self {
        Time { sec: clock_ns / 1_000_000_000, nsec: (clock_ns % 1_000_000_000) as u32 }
    }
}

#[derive(Serialize)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Serialize)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Serialize)]
struct Pose {
    position: Vector3,
    orientation: Quaternion,
}

#[derive(Serialize, Clone, Copy)]
pub struct Color {
    pub r: f64,
    pub g: f64,
    pub b: f64,
    pub a: f64,
}

/// Measured positions.
pub const MEASURED: Color = Color { r: 0.95, g: 0.45, b: 0.05, a: 1.0 };
/// Filter means.
pub const ESTIMATED: Color = Color { r: 0.12, g: 0.47, b: 0.71, a: 1.0 };

#[derive(Serialize)]
struct Sphere {
    pose: Pose,
    size: Vector3,
    color: Color,
}

#[derive(Serialize)]
struct Duration {
    sec: i64,
    nsec: u32,
}

#[derive(Serialize)]
struct KeyValue {
    key: String,
    value: String,
}

#[derive(Serialize)]
struct Entity {
    timestamp: Time,
    frame_id: &'static str,
    id: String,
    /// Zero: kept until replaced or deleted.
    lifetime: Duration,
    frame_locked: bool,
    metadata: Vec<KeyValue>,
    arrows: [(); 0],
    cubes: [(); 0],
    spheres: Vec<Sphere>,
    cylinders: [(); 0],
    lines: [(); 0],
    triangles: [(); 0],
    texts: [(); 0],
    models: [(); 0],
}

#[derive(Serialize)]
struct Deletion {
    timestamp: Time,
    /// 1 = ALL: every entity of this topic.
    #[serde(rename = "type")]
    kind: u8,
    id: String,
}

#[derive(Serialize)]
struct SceneUpdate {
    deletions: Vec<Deletion>,
    entities: Vec<Entity>,
}

/// One point of a trajectory: the trajectory and frame, and the position (`None` for a lost frame, which
/// draws nothing but still clears the scene when a trajectory starts).
pub struct ScenePoint {
    pub trajectory: u32,
    pub frame: u64,
    pub position: Option<[f64; 3]>,
}

/// The `topic` channel of `points`, point k drawn at the time of the file's main message k (`layout`).
pub fn scene_channel<'a>(
    topic: &'a str,
    layout: &Layout,
    points: impl IntoIterator<Item = ScenePoint>,
    color: Color,
) -> ExtraChannel<'a> {
    let mut messages = Vec::new();
    let mut previous: Option<u32> = None;
    for (sequence, point) in points.into_iter().enumerate() {
        let clock_ns = message_clock(layout, sequence);
        let starts = previous != Some(point.trajectory);
        previous = Some(point.trajectory);
        if point.position.is_none() && !starts {
            continue;
        }
        let deletions = if starts {
            vec![Deletion { timestamp: Time::of(clock_ns), kind: 1, id: String::new() }]
        } else {
            Vec::new()
        };
        let entities = point
            .position
            .map(|[x, y, z]| Entity {
                timestamp: Time::of(clock_ns),
                frame_id: FRAME_ID,
                id: format!("trajectory {} frame {}", point.trajectory, point.frame),
                lifetime: Duration { sec: 0, nsec: 0 },
                frame_locked: false,
                metadata: vec![KeyValue { key: "trajectory".into(), value: point.trajectory.to_string() }],
                arrows: [],
                cubes: [],
                spheres: vec![Sphere {
                    pose: Pose {
                        position: Vector3 { x, y, z },
                        orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
                    },
                    size: Vector3 { x: BALL_DIAMETER, y: BALL_DIAMETER, z: BALL_DIAMETER },
                    color,
                }],
                cylinders: [],
                lines: [],
                triangles: [],
                texts: [],
                models: [],
            })
            .into_iter()
            .collect();
        let update = SceneUpdate { deletions, entities };
        // Plain numbers, strings and fixed structs: serialization cannot fail.
        let bytes = serde_json::to_vec(&update).unwrap_or_default();
        messages.push((clock_ns, bytes));
    }
    ExtraChannel { topic, schema_name: SCENE_SCHEMA_NAME, schema: SCENE_SCHEMA, messages }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_new_trajectory_clears_the_scene_and_lost_frames_draw_nothing() {
        let point = |trajectory, frame, position| ScenePoint { trajectory, frame, position };
        let points = [
            point(0, 0, Some([0.1, 0.2, 0.3])),
            point(0, 1, None),
            point(0, 2, Some([0.2, 0.2, 0.3])),
            point(1, 0, None),
        ];
        // One nanosecond per message: point k is drawn at time k + 1.
        let layout = Layout { metadata_name: "m", topic: "/t", schema_name: "s", schema: "{}", tick_ns: 1 };
        let channel = scene_channel("/scene", &layout, points, MEASURED);
        let json: Vec<serde_json::Value> =
            channel.messages.iter().map(|(_, b)| serde_json::from_slice(b).unwrap()).collect();
        assert_eq!(channel.messages.iter().map(|m| m.0).collect::<Vec<_>>(), [1, 3, 4]);
        assert_eq!(json[0]["deletions"][0]["type"], 1);
        assert_eq!(json[0]["entities"][0]["spheres"][0]["pose"]["position"]["z"], 0.3);
        assert_eq!(json[1]["deletions"].as_array().unwrap().len(), 0);
        assert_eq!(json[2]["entities"].as_array().unwrap().len(), 0);
        assert_eq!(json[2]["deletions"][0]["type"], 1);
    }
}
