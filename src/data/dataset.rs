//! Datasets as MCAP files: JSON-encoded timestep messages with a JSON Schema, zstd-compressed chunks, and
//! one metadata record describing how the data was made. See datasets/README.md for the format.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::frames::{frame_channel, read_frames, FrameInfo};
use super::mcap_io::{check_version, read_messages_and_raw, write_messages_with, Layout};
use super::rollout::{Rollout, Timestep};
use super::schema::{FRAME_TOPIC, TIMESTEP_SCHEMA, TIMESTEP_SCHEMA_NAME, TIMESTEP_TOPIC};
use crate::error::{Error, Result};
use crate::util::domain::Domain;

/// Version of the on-disk layout; readers reject any other.
pub const FORMAT_VERSION: u32 = 1;
pub const METADATA_NAME: &str = "mbrl.dataset";

/// How a dataset's rollouts relate to each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DatasetLayout {
    /// Independent rollouts (metadata `layout` = `rollouts`, or no `layout` key: files made before it existed).
    #[default]
    Rollouts,
    /// Two rollouts per hidden-parameter instance k: id 2k is the target rollout, id 2k+1 the context source,
    /// both of the same instance with their own start states and actions (metadata `layout` = `instance-pairs`).
    InstancePairs,
}

impl DatasetLayout {
    pub fn as_str(self) -> &'static str {
        match self {
            DatasetLayout::Rollouts => "rollouts",
            DatasetLayout::InstancePairs => "instance-pairs",
        }
    }

    fn parse(path: &Path, text: &str) -> Result<Self> {
        match text {
            "rollouts" => Ok(DatasetLayout::Rollouts),
            "instance-pairs" => Ok(DatasetLayout::InstancePairs),
            other => Err(Error::bad_file(
                path,
                format!(
                    "metadata field 'layout': '{other}' is not a known layout; expected rollouts or instance-pairs"
                ),
            )),
        }
    }
}

/// What the metadata record says about a dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetMeta {
    pub format_version: u32,
    pub env: String,
    pub seed: u64,
    pub mbrl_version: String,
    pub command_line: String,
    /// Hidden parameters of each environment instance, by rollout id (JSON).
    pub instances: Vec<serde_json::Value>,
    pub state_names: Vec<String>,
    pub action_dim: usize,
    /// Simulated seconds between timesteps.
    pub dt: f64,
    #[serde(default)]
    pub layout: DatasetLayout,
    /// Rendered frames of the states (`collect --images`), absent in most datasets.
    #[serde(default)]
    pub frames: Option<FrameInfo>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    pub meta: DatasetMeta,
    pub steps: Vec<Timestep>,
    /// RGB of every state when `meta.frames` is set: per rollout t = 0 … T, in step order (see data::frames).
    pub frames: Vec<Vec<u8>>,
}

/// Every env steps at most a second at a time; a larger or non-positive `dt` is no recording this tool makes,
/// and a huge one would make time axes (plots, log times) unbounded.
const DT: Domain = Domain::above(0.0, 1.0).in_unit("s");
/// States, actions and rewards of every env stay far inside this (angles, metres, rewards per step); a value
/// beyond it is no recording, and its square (normalizers, losses) would overflow.
pub const RECORDED: Domain = Domain::closed(-1e9, 1e9);
/// The widest action of any env (the Jaco's joints and more): bounds what an action vector may claim.
const ACTION_DIM: Domain = Domain::count(0, 64);

impl DatasetMeta {
    fn to_record(&self) -> BTreeMap<String, String> {
        let mut record = BTreeMap::from([
            ("format_version".to_string(), self.format_version.to_string()),
            ("env".to_string(), self.env.clone()),
            ("seed".to_string(), self.seed.to_string()),
            ("mbrl_version".to_string(), self.mbrl_version.clone()),
            ("command_line".to_string(), self.command_line.clone()),
            ("instances".to_string(), to_json(&self.instances)),
            ("state_names".to_string(), to_json(&self.state_names)),
            ("action_dim".to_string(), self.action_dim.to_string()),
            ("dt".to_string(), format!("{:?}", self.dt)),
            ("layout".to_string(), self.layout.as_str().to_string()),
        ]);
        if let Some(frames) = &self.frames {
            record.insert("frames".to_string(), to_json(frames));
        }
        record
    }

    fn from_record(path: &Path, record: &BTreeMap<String, String>) -> Result<Self> {
        let field = |key: &str| {
            record
                .get(key)
                .ok_or_else(|| Error::bad_file(path, format!("metadata '{METADATA_NAME}' lacks the field '{key}'")))
        };
        let parse_err =
            |key: &str, expected: &str| Error::bad_file(path, format!("metadata field '{key}': expected {expected}"));
        let version = check_version(path, record, FORMAT_VERSION)?;
        Ok(DatasetMeta {
            format_version: version,
            env: field("env")?.clone(),
            seed: field("seed")?.parse().map_err(|_| parse_err("seed", "an unsigned integer"))?,
            mbrl_version: field("mbrl_version")?.clone(),
            command_line: field("command_line")?.clone(),
            instances: serde_json::from_str(field("instances")?).map_err(|_| parse_err("instances", "a JSON array"))?,
            state_names: serde_json::from_str(field("state_names")?)
                .map_err(|_| parse_err("state_names", "a JSON array of strings"))?,
            action_dim: ACTION_DIM
                .check_count(
                    "metadata.action_dim",
                    field("action_dim")?.parse().map_err(|_| parse_err("action_dim", "an integer"))?,
                )
                .map_err(|e| Error::bad_file(path, e.to_string()))? as usize,
            dt: DT
                .check("metadata.dt", field("dt")?.parse().map_err(|_| parse_err("dt", "a number"))?)
                .map_err(|e| Error::bad_file(path, e.to_string()))?,
            layout: match record.get("layout") {
                Some(text) => DatasetLayout::parse(path, text)?,
                None => DatasetLayout::Rollouts,
            },
            frames: match record.get("frames") {
                Some(text) => Some(parse_frame_info(path, text)?),
                None => None,
            },
        })
    }
}

/// Frames larger than this are not a rendering this tool makes; the bound keeps a forged header from sizing
/// buffers.
const MAX_FRAME_SIDE: u32 = 4096;

fn parse_frame_info(path: &Path, text: &str) -> Result<FrameInfo> {
    let info: FrameInfo = serde_json::from_str(text).map_err(|e| {
        Error::bad_file(path, format!("metadata field 'frames': expected {{width, height, renderer}}: {e}"))
    })?;
    let side_ok = |s: u32| (1..=MAX_FRAME_SIDE).contains(&s);
    if !side_ok(info.width) || !side_ok(info.height) {
        return Err(Error::bad_file(
            path,
            format!(
                "metadata field 'frames': {} × {} pixels; expected 1 … {MAX_FRAME_SIDE} per side",
                info.width, info.height
            ),
        ));
    }
    Ok(info)
}

fn to_json<T: Serialize>(value: &T) -> String {
    serde_json::to_string(value).unwrap_or_else(|_| "null".into())
}

fn layout(meta: &DatasetMeta) -> Layout<'static> {
    Layout {
        metadata_name: METADATA_NAME,
        topic: TIMESTEP_TOPIC,
        schema_name: TIMESTEP_SCHEMA_NAME,
        schema: TIMESTEP_SCHEMA,
        // Rollouts are laid end to end on the log clock so viewers play them one after another.
        tick_ns: (meta.dt * 1e9).round().max(1.0) as u64,
    }
}

impl DatasetMeta {
    /// The metadata of a dataset of `spec`'s env made now by this build.
    pub fn for_env(
        spec: &crate::envs::EnvSpec,
        seed: u64,
        command_line: &str,
        instances: Vec<serde_json::Value>,
        layout: DatasetLayout,
    ) -> Self {
        DatasetMeta {
            format_version: FORMAT_VERSION,
            env: spec.name.clone(),
            seed,
            mbrl_version: crate::VERSION.to_string(),
            command_line: command_line.to_string(),
            instances,
            state_names: spec.state_names.clone(),
            action_dim: spec.action_dim(),
            dt: spec.dt,
            layout,
            frames: None,
        }
    }
}

impl Dataset {
    /// Rollouts of `spec`'s env as a dataset (rollout ids 0, 1, …; `instances` per rollout), for the rollouts a
    /// planner or an evaluation executed.
    pub fn of_rollouts(
        spec: &crate::envs::EnvSpec,
        instances: Vec<serde_json::Value>,
        rollouts: &[Rollout],
        seed: u64,
        command_line: &str,
    ) -> Dataset {
        Dataset {
            meta: DatasetMeta::for_env(spec, seed, command_line, instances, DatasetLayout::Rollouts),
            steps: rollouts.iter().enumerate().flat_map(|(i, r)| r.timesteps(i as u32)).collect(),
            frames: Vec::new(),
        }
    }
}

/// Writes the dataset atomically: the file appears complete or not at all.
pub fn write_dataset(path: &Path, dataset: &Dataset) -> Result<()> {
    let layout = layout(&dataset.meta);
    let frames = match &dataset.meta.frames {
        Some(info) => Some(frame_channel(info, &dataset.steps, &dataset.frames, &layout)?),
        None if dataset.frames.is_empty() => None,
        None => return Err(Error::data("dataset has frames but its metadata does not describe them")),
    };
    write_messages_with(path, &layout, dataset.meta.to_record(), &dataset.steps, frames.as_ref())
}

pub fn read_dataset(path: &Path) -> Result<Dataset> {
    let (record, messages, raw_frames) =
        read_messages_and_raw::<Timestep>(path, METADATA_NAME, TIMESTEP_TOPIC, FRAME_TOPIC)?;
    let meta = DatasetMeta::from_record(path, &record)?;
    let mut steps = Vec::with_capacity(messages.len());
    for (sequence, step) in messages {
        validate_step(path, &meta, &step, sequence)?;
        steps.push(step);
    }
    let frames = match &meta.frames {
        Some(info) => read_frames(path, info, &steps, raw_frames)?,
        None => Vec::new(),
    };
    let data = Dataset { meta, steps, frames };
    if data.meta.layout == DatasetLayout::InstancePairs {
        check_pairs(&data.meta, &data.steps).map_err(|e| Error::bad_file(path, e))?;
    }
    Ok(data)
}

/// The (target, context-source) rollouts of each instance of an `instance-pairs` dataset, by instance.
pub fn instance_pairs(data: &Dataset) -> Result<Vec<(Rollout, Rollout)>> {
    if data.meta.layout != DatasetLayout::InstancePairs {
        return Err(Error::data(format!(
            "dataset of {} has layout '{}', not instance pairs; collect one with `mbrl collect --instances N`",
            data.meta.env,
            data.meta.layout.as_str()
        )));
    }
    pair_up(data).map_err(Error::data)
}

/// Checks the pairing rules and groups the rollouts; the error says what is wrong, the caller adds where.
fn pair_up(data: &Dataset) -> std::result::Result<Vec<(Rollout, Rollout)>, String> {
    check_pairs(&data.meta, &data.steps)?;
    let grouped = Rollout::group(&data.steps).map_err(|i| format!("message {i} does not continue its rollout"))?;
    let mut rollouts = grouped.into_iter().map(|(_, r)| r);
    let mut pairs = Vec::with_capacity(data.meta.instances.len() / 2);
    while let (Some(a), Some(b)) = (rollouts.next(), rollouts.next()) {
        pairs.push((a, b));
    }
    Ok(pairs)
}

/// The pairing rules, checked in one pass without copying the data (readers call it on every file).
fn check_pairs(meta: &DatasetMeta, steps: &[Timestep]) -> std::result::Result<(), String> {
    let rule = "layout 'instance-pairs'";
    let rollouts = meta.instances.len();
    if !rollouts.is_multiple_of(2) {
        return Err(format!("{rule}: 'instances' has {rollouts} entries; expected two (equal) entries per instance"));
    }
    let mut next_id = 0usize;
    let mut previous: Option<&Timestep> = None;
    for (i, step) in steps.iter().enumerate() {
        match previous {
            Some(p) if p.rollout == step.rollout => {
                if step.t != p.t + 1 || step.state != p.next_state {
                    return Err(format!(
                        "{rule}: message {i} (rollout {}, t {}) does not continue its rollout",
                        step.rollout, step.t
                    ));
                }
            }
            _ => {
                if step.rollout as usize != next_id || step.t != 0 {
                    return Err(format!(
                        "{rule}: rollout {next_id} (instance {}) is missing or out of order (message {i} is rollout \
                         {}, t {})",
                        next_id / 2,
                        step.rollout,
                        step.t
                    ));
                }
                if next_id >= rollouts {
                    return Err(format!("{rule}: rollout {next_id} has no entry in 'instances' ({rollouts} entries)"));
                }
                next_id += 1;
            }
        }
        previous = Some(step);
    }
    if next_id != rollouts {
        return Err(format!(
            "{rule}: instance {} lacks its {} rollout {next_id}; expected {rollouts} rollouts for {} instances",
            next_id / 2,
            if next_id.is_multiple_of(2) { "target" } else { "context-source" },
            rollouts / 2
        ));
    }
    if let Some(k) = (0..rollouts / 2).find(|k| meta.instances[2 * k] != meta.instances[2 * k + 1]) {
        return Err(format!("{rule}: instance {k} has different parameters for rollouts {} and {}", 2 * k, 2 * k + 1));
    }
    Ok(())
}

fn validate_step(path: &Path, meta: &DatasetMeta, step: &Timestep, sequence: u32) -> Result<()> {
    let where_ = || format!("message {sequence} (rollout {}, t {})", step.rollout, step.t);
    let dim = meta.state_names.len();
    if step.state.len() != dim || step.next_state.len() != dim {
        return Err(Error::bad_file(path, format!("{}: state has the wrong length, expected {dim}", where_())));
    }
    if step.action.len() != meta.action_dim {
        return Err(Error::bad_file(
            path,
            format!("{}: action has the wrong length, expected {}", where_(), meta.action_dim),
        ));
    }
    let fields = [("state", &step.state[..]), ("next_state", &step.next_state), ("action", &step.action)];
    let values = fields.iter().flat_map(|(name, v)| v.iter().enumerate().map(move |(i, x)| (*name, Some(i), *x)));
    for (name, i, x) in values.chain([("reward", None, step.reward)]) {
        if !RECORDED.contains(x) {
            let index = i.map_or(String::new(), |i| format!("[{i}]"));
            let field = format!("messages[{sequence}].{name}{index}");
            let e = RECORDED.check(&field, x).unwrap_err();
            return Err(Error::bad_file(path, format!("{e} (rollout {}, t {})", step.rollout, step.t)));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::mcap_io::write_messages;
    use crate::data::Rollout;

    pub(crate) fn tiny_dataset() -> Dataset {
        let mut r = Rollout::start(vec![0.0, 0.0], vec![1.0, 0.0, 0.0]);
        r.push(vec![1.0], -0.5, vec![0.1, 0.2], vec![0.99, 0.1, 0.2]);
        r.push(vec![-1.0], -0.25, vec![0.2, 0.1], vec![0.98, 0.2, 0.1]);
        Dataset {
            meta: DatasetMeta {
                format_version: FORMAT_VERSION,
                env: "pendulum".into(),
                seed: 3,
                mbrl_version: crate::VERSION.into(),
                command_line: "mbrl collect".into(),
                instances: vec![serde_json::json!({"mass": 1.0})],
                state_names: vec!["theta".into(), "theta_dot".into()],
                action_dim: 1,
                dt: 0.05,
                layout: DatasetLayout::Rollouts,
                frames: None,
            },
            steps: r.timesteps(0).collect(),
            frames: Vec::new(),
        }
    }

    #[test]
    fn round_trip_preserves_everything() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.mcap");
        let data = tiny_dataset();
        write_dataset(&path, &data).unwrap();
        assert_eq!(read_dataset(&path).unwrap(), data);
    }

    #[test]
    fn floats_round_trip_to_the_last_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.mcap");
        let mut data = tiny_dataset();
        // Needs serde_json's float_roundtrip: its default parser can be one ulp off for values like these.
        data.steps[0].next_state = vec![-0.46664908355164947, 1.0 / 3.0];
        data.steps[1].state = data.steps[0].next_state.clone();
        write_dataset(&path, &data).unwrap();
        assert_eq!(read_dataset(&path).unwrap(), data);
    }

    #[test]
    fn same_dataset_same_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
        write_dataset(&a, &tiny_dataset()).unwrap();
        write_dataset(&b, &tiny_dataset()).unwrap();
        assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    }

    #[test]
    fn truncated_file_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.mcap");
        write_dataset(&path, &tiny_dataset()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("d.mcap") && err.contains("truncated or corrupt"), "{err}");
    }

    #[test]
    fn unknown_version_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v9.mcap");
        let mut data = tiny_dataset();
        data.meta.format_version = 9;
        write_dataset(&path, &data).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("format version 9 is not supported"), "{err}");
    }

    fn paired(instances: usize) -> Dataset {
        let mut data = tiny_dataset();
        data.meta.layout = DatasetLayout::InstancePairs;
        data.meta.instances = (0..instances).flat_map(|k| vec![serde_json::json!({"alpha": k}); 2]).collect();
        let one = Rollout::group(&data.steps).unwrap().remove(0).1;
        data.steps = (0..2 * instances as u32).flat_map(|id| one.timesteps(id).collect::<Vec<_>>()).collect();
        data
    }

    fn write_with_layout(path: &Path, data: &Dataset, layout_value: Option<&str>) {
        let mut record = data.meta.to_record();
        match layout_value {
            Some(v) => record.insert("layout".into(), v.into()),
            None => record.remove("layout"),
        };
        write_messages(path, &layout(&data.meta), record, &data.steps).unwrap();
    }

    /// Extreme values in a well-formed file: a time step beyond (0, 1] s (a huge one made `eval dataset` tick an
    /// infinite time axis), a count no env has, a recorded number whose square overflows.
    #[test]
    fn numbers_outside_their_domain_are_refused_with_the_field() {
        let dir = tempfile::tempdir().unwrap();
        let data = tiny_dataset();
        let write = |name: &str, key: &str, value: &str| {
            let path = dir.path().join(name);
            let mut record = data.meta.to_record();
            record.insert(key.into(), value.into());
            write_messages(&path, &layout(&data.meta), record, &data.steps).unwrap();
            read_dataset(&path).unwrap_err().to_string()
        };
        for dt in ["1.8e308", "1.7976931348623157e308", "0", "-0", "-1", "NaN", "2"] {
            let err = write("dt.mcap", "dt", dt);
            assert!(err.contains("dt.mcap") && err.contains("metadata.dt = ") && err.contains("(0, 1] s"), "{err}");
        }
        let err = write("dim.mcap", "action_dim", "18446744073709551615");
        assert!(err.contains("metadata.action_dim = 18446744073709551615: expected a whole number in 0..=64"), "{err}");
        let mut huge = tiny_dataset();
        huge.steps[1].state[1] = 1e300;
        huge.steps[0].next_state[1] = 1e300;
        let path = dir.path().join("huge.mcap");
        write_dataset(&path, &huge).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("messages[0].next_state[1] = 1e300: expected a finite number in [-1e9, 1e9]"), "{err}");
    }

    #[test]
    fn files_without_a_layout_read_as_plain_rollouts() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("old.mcap");
        write_with_layout(&path, &tiny_dataset(), None);
        assert_eq!(read_dataset(&path).unwrap().meta.layout, DatasetLayout::Rollouts);
    }

    #[test]
    fn unknown_layout_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("odd.mcap");
        write_with_layout(&path, &tiny_dataset(), Some("triples"));
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("odd.mcap") && err.contains("'triples'") && err.contains("instance-pairs"), "{err}");
    }

    #[test]
    fn instance_pairs_round_trip_and_pair_up() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pairs.mcap");
        let data = paired(3);
        write_dataset(&path, &data).unwrap();
        let back = read_dataset(&path).unwrap();
        assert_eq!(back, data);
        let pairs = instance_pairs(&back).unwrap();
        assert_eq!(pairs.len(), 3);
        assert_eq!(pairs[2].0.len(), 2);
        assert!(instance_pairs(&tiny_dataset()).unwrap_err().to_string().contains("--instances"));
    }

    #[test]
    fn a_missing_context_rollout_is_reported_with_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("half.mcap");
        let mut data = paired(2);
        data.steps.retain(|s| s.rollout != 3);
        write_dataset(&path, &data).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("half.mcap") && err.contains("instance 1") && err.contains("context-source"), "{err}");

        let mut data = paired(2);
        data.meta.instances[3] = serde_json::json!({"alpha": 9});
        write_dataset(&path, &data).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("instance 1 has different parameters"), "{err}");

        let mut data = paired(2);
        data.steps.retain(|s| s.rollout != 1);
        write_dataset(&path, &data).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("rollout 1 (instance 0) is missing"), "{err}");
    }

    /// The tiny dataset with a 4 × 2 frame per state (2 transitions → 3 frames).
    fn with_frames() -> Dataset {
        let mut data = tiny_dataset();
        data.meta.frames = Some(FrameInfo { width: 4, height: 2, renderer: "test".into() });
        data.frames = (0..3u8).map(|k| (0..24u8).map(|i| i.wrapping_mul(k + 1)).collect()).collect();
        data
    }

    /// Single bit flips anywhere in a file mbrl wrote (the class of input that made the MCAP library reserve
    /// up to 3.6e18 bytes): every one reads back as the original or is a one-line error; none panics or aborts.
    #[test]
    fn bit_flipped_files_are_errors_never_crashes() {
        use rand::{Rng, SeedableRng};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frames.mcap");
        let data = with_frames();
        write_dataset(&path, &data).unwrap();
        let original = std::fs::read(&path).unwrap();
        let mutated = dir.path().join("mutated.mcap");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
        let mut errors = 0;
        for _ in 0..400 {
            let mut bytes = original.clone();
            let bit = rng.random_range(0..bytes.len() * 8);
            bytes[bit / 8] ^= 1 << (bit % 8);
            std::fs::write(&mutated, &bytes).unwrap();
            match read_dataset(&mutated) {
                Ok(read) => assert_eq!(read, data, "flipping bit {bit} changed the data without an error"),
                Err(e) => {
                    assert_eq!(e.to_string().lines().count(), 1, "{e}");
                    errors += 1;
                }
            }
        }
        assert!(errors > 350, "only {errors} of 400 flips were detected");
        for cut in [0, 8, original.len() / 2, original.len() - 1] {
            std::fs::write(&mutated, &original[..cut]).unwrap();
            assert!(read_dataset(&mutated).is_err(), "a file cut at {cut} bytes was accepted");
        }
    }

    #[test]
    fn frames_round_trip_beside_the_timesteps() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frames.mcap");
        let data = with_frames();
        write_dataset(&path, &data).unwrap();
        assert_eq!(read_dataset(&path).unwrap(), data);
        let mut short = with_frames();
        short.frames.pop();
        let err = write_dataset(&dir.path().join("short.mcap"), &short).unwrap_err().to_string();
        assert!(err.contains("2 frames for 3 states"), "{err}");
        assert!(!dir.path().join("short.mcap").exists(), "nothing half-written");
    }

    #[test]
    fn frames_that_do_not_match_the_metadata_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let data = with_frames();
        let write_claiming = |name: &str, frames: &str| {
            let path = dir.path().join(name);
            let mut record = data.meta.to_record();
            record.insert("frames".into(), frames.into());
            let layout = layout(&data.meta);
            let channel =
                frame_channel(data.meta.frames.as_ref().unwrap(), &data.steps, &data.frames, &layout).unwrap();
            write_messages_with(&path, &layout, record, &data.steps, Some(&channel)).unwrap();
            read_dataset(&path).unwrap_err().to_string()
        };
        let err = write_claiming("big.mcap", r#"{"width": 100000, "height": 100000, "renderer": "x"}"#);
        assert!(err.contains("'frames'") && err.contains("4096"), "{err}");
        let err = write_claiming("other.mcap", r#"{"width": 2, "height": 4, "renderer": "x"}"#);
        assert!(err.contains("/frames message 0") && err.contains("expected 2 × 4"), "{err}");
        let err = write_claiming("garbled.mcap", "[1, 2]");
        assert!(err.contains("'frames'"), "{err}");
        // Frames declared but none stored.
        let path = dir.path().join("none.mcap");
        write_messages(&path, &layout(&data.meta), data.meta.to_record(), &data.steps).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("0 frames for 3 states"), "{err}");
    }
}
