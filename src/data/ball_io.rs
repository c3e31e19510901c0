//! Ball recordings on disk: MCAP datasets (simulated or imported) and CSV files of measured positions.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::mcap_io::{check_version, metadata_field, metadata_seed, read_messages, write_messages_with, Layout};
use super::scene::{scene_channel, ScenePoint, MEASURED};
use crate::error::{Error, Result};

pub const BALL_FORMAT_VERSION: u32 = 1;
pub const METADATA_NAME: &str = "mbrl.balls";
pub const TOPIC: &str = "/ball/frames";
/// The measured positions as `foxglove.SceneUpdate`, for Foxglove's 3D panel.
pub const SCENE_TOPIC: &str = "/ball/scene";
/// Camera frame rate of the recordings (thesis 6.5.1), the same the simulator's camera uses.
pub use crate::envs::ball::camera::FRAME_RATE;
/// The longest stretch of lost frames inside one trajectory: 10 s at 180 Hz, several times a table-tennis
/// flight. A larger jump is a corrupt frame index, and the filter would step through every missing frame.
pub const MAX_FRAME_GAP: u64 = 1800;

/// Why `frame` cannot follow `last` in one trajectory, if it cannot.
pub fn frame_step_error(last: Option<u64>, frame: u64) -> Option<String> {
    let last = last?;
    if frame <= last {
        Some(format!(
            "frame {frame} does not follow the previous frame {last} (indices must increase within a trajectory)"
        ))
    } else if frame - last > MAX_FRAME_GAP {
        Some(format!(
            "frame {frame} follows frame {last}: a gap of {} frames, longer than any flight (at most {MAX_FRAME_GAP} = {} s at {FRAME_RATE} Hz)",
            frame - last,
            MAX_FRAME_GAP as f64 / FRAME_RATE
        ))
    } else {
        None
    }
}

/// Launcher side information in the layout of the authors' public release.
pub const SIDE_INFO_COLUMNS: [&str; 7] = ["sin_phi_f", "cos_phi_f", "s_phi", "s_theta", "s_tl", "s_tr", "s_b"];

const SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "mbrl.BallFrame",
  "description": "One camera frame of a table-tennis ball recording.",
  "type": "object",
  "required": ["trajectory", "frame", "t"],
  "properties": {
    "trajectory": {"type": "integer", "minimum": 0},
    "frame": {"type": "integer", "minimum": 0, "description": "camera frame index (180 Hz)"},
    "t": {"type": "number", "description": "seconds, frame / 180"},
    "position": {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
                 "description": "measured ball centre [m]; null when the frame was lost"},
    "true_state": {"type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9,
                   "description": "simulated truth (position, velocity, spin); absent for real recordings"}
  }
}"#;

/// One camera frame (one MCAP message).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BallFrame {
    pub trajectory: u32,
    pub frame: u64,
    pub t: f64,
    pub position: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_state: Option<[f64; 9]>,
}

/// What is known about a recording besides its frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub struct RecordingInfo {
    /// Launcher side information (`SIDE_INFO_COLUMNS`), when the launcher settings are known.
    #[serde(default)]
    pub side_info: Option<[f64; 7]>,
    /// Launcher orientation name for simulated data (`default`, `unseen-1`..`unseen-5`).
    #[serde(default)]
    pub orientation: Option<String>,
    /// Full launch parameters of simulated shots (JSON), for inspection.
    #[serde(default)]
    pub launch: Option<serde_json::Value>,
    /// Frame of the (first) table impact, when known.
    #[serde(default)]
    pub impact_frame: Option<u64>,
    /// For augmented copies: the rotation angle about z [rad] and the recording it was made from.
    #[serde(default)]
    pub rotated_from: Option<(u32, f64)>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    pub id: u32,
    pub frames: Vec<u64>,
    pub positions: Vec<Option<[f64; 3]>>,
    pub truth: Option<Vec<[f64; 9]>>,
    pub info: RecordingInfo,
}

impl Recording {
    pub fn times(&self) -> impl Iterator<Item = f64> + '_ {
        self.frames.iter().map(|&f| f as f64 / FRAME_RATE)
    }

    pub fn measured(&self) -> usize {
        self.positions.iter().filter(|p| p.is_some()).count()
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct BallDataset {
    /// `simulator` or `import`.
    pub source: String,
    pub seed: u64,
    pub command_line: String,
    pub mbrl_version: String,
    pub recordings: Vec<Recording>,
}

const LAYOUT: Layout<'static> = Layout {
    metadata_name: METADATA_NAME,
    topic: TOPIC,
    schema_name: "mbrl.BallFrame",
    schema: SCHEMA,
    tick_ns: (1e9 / FRAME_RATE) as u64,
};

pub fn write_ball_dataset(path: &Path, data: &BallDataset) -> Result<()> {
    let infos: BTreeMap<u32, &RecordingInfo> = data.recordings.iter().map(|r| (r.id, &r.info)).collect();
    let metadata = BTreeMap::from([
        ("format_version".to_string(), BALL_FORMAT_VERSION.to_string()),
        ("source".to_string(), data.source.clone()),
        ("seed".to_string(), data.seed.to_string()),
        ("command_line".to_string(), data.command_line.clone()),
        ("mbrl_version".to_string(), data.mbrl_version.clone()),
        ("recordings".to_string(), serde_json::to_string(&infos).unwrap_or_else(|_| "{}".into())),
    ]);
    let frames: Vec<BallFrame> = data
        .recordings
        .iter()
        .flat_map(|r| {
            (0..r.frames.len()).map(move |i| BallFrame {
                trajectory: r.id,
                frame: r.frames[i],
                t: r.frames[i] as f64 / FRAME_RATE,
                position: r.positions[i],
                true_state: r.truth.as_ref().map(|t| t[i]),
            })
        })
        .collect();
    let points = frames.iter().map(|f| ScenePoint { trajectory: f.trajectory, frame: f.frame, position: f.position });
    let scene = scene_channel(SCENE_TOPIC, &LAYOUT, points, MEASURED);
    write_messages_with(path, &LAYOUT, metadata, &frames, Some(&scene))
}

pub fn read_ball_dataset(path: &Path) -> Result<BallDataset> {
    let (meta, messages) = read_messages::<BallFrame>(path, METADATA_NAME, TOPIC)?;
    check_version(path, &meta, BALL_FORMAT_VERSION)?;
    let field = |key: &str| metadata_field(path, &meta, key);
    let infos: BTreeMap<u32, RecordingInfo> = serde_json::from_str(&field("recordings")?)
        .map_err(|e| Error::bad_file(path, format!("metadata field 'recordings': {e}")))?;
    let mut recordings: Vec<Recording> = Vec::new();
    for (sequence, frame) in messages {
        let where_ = format!("message {sequence} (trajectory {}, frame {})", frame.trajectory, frame.frame);
        if frame.position.is_some_and(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(Error::bad_file(path, format!("{where_}: non-finite position")));
        }
        let continues = recordings.last().is_some_and(|r| r.id == frame.trajectory);
        if !continues {
            let info = infos.get(&frame.trajectory).cloned().unwrap_or_default();
            let truth = frame.true_state.map(|_| Vec::new());
            recordings.push(Recording { id: frame.trajectory, frames: Vec::new(), positions: Vec::new(), truth, info });
        }
        let r = recordings.last_mut().expect("pushed above");
        if let Some(why) = frame_step_error(r.frames.last().copied(), frame.frame) {
            return Err(Error::bad_file(path, format!("{where_}: {why}")));
        }
        r.frames.push(frame.frame);
        r.positions.push(frame.position);
        match (&mut r.truth, frame.true_state) {
            (Some(t), Some(s)) => t.push(s),
            (None, None) => {}
            _ => return Err(Error::bad_file(path, format!("{where_}: true_state present on some frames only"))),
        }
    }
    for r in &recordings {
        check_enough_measurements(path, r)?;
    }
    Ok(BallDataset {
        source: field("source")?,
        seed: metadata_seed(path, &meta)?,
        command_line: field("command_line")?,
        mbrl_version: field("mbrl_version")?,
        recordings,
    })
}

fn check_enough_measurements(path: &Path, r: &Recording) -> Result<()> {
    if r.measured() < 2 {
        return Err(Error::bad_file(
            path,
            format!("trajectory {}: {} measured positions; a filter needs at least two", r.id, r.measured()),
        ));
    }
    Ok(())
}

/// Larger than any recording (a 10-minute capture at 180 Hz is ~5 MB); an endless input stops here.
pub const MAX_BALL_CSV_BYTES: u64 = 256 << 20;

/// Reads CSV recordings: a header with `frame` (camera frame index) or `t` (seconds), then `x`, `y`,
/// `z` in metres (empty cells = lost frame), optionally the seven side-information columns
/// `SIDE_INFO_COLUMNS` (read from a trajectory's first row) and a `trajectory` column (as `export`
/// writes it) whose runs of equal ids are the recordings; without it the file is one recording.
pub fn read_ball_csv(path: &Path) -> Result<Vec<Recording>> {
    use std::io::Read;
    let file = crate::util::bounded_read::open_regular(path)?;
    let size = file.metadata().map_err(|e| Error::io(path, e))?.len();
    if size > MAX_BALL_CSV_BYTES {
        return Err(Error::bad_file(path, format!("{size} bytes; a recording is at most {MAX_BALL_CSV_BYTES}")));
    }
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).flexible(true).from_reader(file.take(MAX_BALL_CSV_BYTES + 1));
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| Error::bad_file(path, format!("cannot read the CSV header: {e}")))?
        .iter()
        .map(|h| h.to_ascii_lowercase())
        .collect();
    let column = |name: &str| header.iter().position(|h| h == name);
    let time_column = column("frame").map(|c| (c, true)).or_else(|| column("t").map(|c| (c, false)));
    let (Some((tc, is_frame)), Some(xc), Some(yc), Some(zc)) = (time_column, column("x"), column("y"), column("z"))
    else {
        return Err(Error::bad_file(
            path,
            format!("header '{}': expected columns frame (or t), x, y, z", header.join(",")),
        ));
    };
    let side_columns: Option<Vec<usize>> = SIDE_INFO_COLUMNS.iter().map(|c| column(c)).collect();
    let trajectory_column = column("trajectory");
    let empty = |id: u32| Recording {
        id,
        frames: Vec::new(),
        positions: Vec::new(),
        truth: None,
        info: RecordingInfo::default(),
    };
    let mut done: Vec<Recording> = Vec::new();
    // Ids already closed: a set, since a file of two-row trajectories has millions of them.
    let mut seen = std::collections::BTreeSet::new();
    let mut rec = empty(0);
    for (i, row) in reader.records().enumerate() {
        let line = i + 2;
        let row = row.map_err(|e| Error::bad_file(path, format!("row {line}: {e}")))?;
        if row.len() != header.len() {
            return Err(Error::bad_file(
                path,
                format!("row {line}: {} columns, expected {} as in the header", row.len(), header.len()),
            ));
        }
        let number = |c: usize, what: &str| -> Result<f64> {
            let v: f64 = row[c]
                .parse()
                .map_err(|_| Error::bad_file(path, format!("row {line}: {what} '{}' is not a number", &row[c])))?;
            if !v.is_finite() {
                return Err(Error::bad_file(path, format!("row {line}: {what} is {v}; expected a finite number")));
            }
            Ok(v)
        };
        if let Some(c) = trajectory_column {
            let id: u32 = row[c].parse().map_err(|_| {
                Error::bad_file(path, format!("row {line}: trajectory '{}' is not a non-negative integer", &row[c]))
            })?;
            if id != rec.id && !rec.frames.is_empty() {
                check_enough_measurements(path, &rec)?;
                seen.insert(rec.id);
                done.push(std::mem::replace(&mut rec, empty(id)));
            }
            if rec.frames.is_empty() {
                if seen.contains(&id) {
                    return Err(Error::bad_file(
                        path,
                        format!("row {line}: trajectory {id} appears again after other trajectories; keep its rows together"),
                    ));
                }
                rec.id = id;
            }
        }
        let stamp = number(tc, if is_frame { "frame" } else { "t" })?;
        let frame = if is_frame { stamp } else { stamp * FRAME_RATE };
        if frame < 0.0 || (frame - frame.round()).abs() > 0.05 {
            return Err(Error::bad_file(
                path,
                format!("row {line}: time {stamp} is not a non-negative whole camera frame at {FRAME_RATE} Hz"),
            ));
        }
        let frame = frame.round() as u64;
        if let Some(why) = frame_step_error(rec.frames.last().copied(), frame) {
            return Err(Error::bad_file(path, format!("row {line}: {why}")));
        }
        let cells = [&row[xc], &row[yc], &row[zc]];
        let position = if cells.iter().all(|c| c.is_empty()) {
            None
        } else {
            Some([number(xc, "x")?, number(yc, "y")?, number(zc, "z")?])
        };
        if rec.frames.is_empty() {
            if let Some(cols) = &side_columns {
                let mut side = [0.0; 7];
                for (k, &c) in cols.iter().enumerate() {
                    side[k] = number(c, SIDE_INFO_COLUMNS[k])?;
                }
                rec.info.side_info = Some(side);
            }
        }
        rec.frames.push(frame);
        rec.positions.push(position);
    }
    check_enough_measurements(path, &rec)?;
    done.push(rec);
    Ok(done)
}

/// Recordings from a `.mcap` ball dataset, a single `.csv` recording, or (built with the `hdf5` feature)
/// an `.hdf5`/`.h5` file in the layout of the authors' release.
pub fn read_recordings(path: &Path) -> Result<Vec<Recording>> {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("csv") => read_ball_csv(path),
        Some("mcap") => Ok(read_ball_dataset(path)?.recordings),
        Some("hdf5" | "h5") => read_hdf5(path),
        _ => Err(Error::bad_file(path, "expected a .mcap ball dataset, a .csv recording or an .hdf5 release file")),
    }
}

#[cfg(feature = "hdf5")]
fn read_hdf5(path: &Path) -> Result<Vec<Recording>> {
    Ok(super::ball_hdf5::read_hdf5_recordings(path)?.into_iter().map(|t| t.recording).collect())
}

#[cfg(not(feature = "hdf5"))]
fn read_hdf5(path: &Path) -> Result<Vec<Recording>> {
    Err(Error::bad_file(
        path,
        "HDF5 import needs a build with `--features hdf5` (and the system HDF5 library: apt-get install libhdf5-dev)",
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn csv_with_gaps_and_side_info() {
        let dir = tempfile::tempdir().unwrap();
        let header = format!("frame,x,y,z,{}", SIDE_INFO_COLUMNS.join(","));
        let p = write(
            dir.path(),
            "a.csv",
            &format!("{header}\n3,0.1,2.0,0.3,0,1,0.5,0.8,0.1,0.15,0.16\n4,,,,,,,,,,\n6,0.12,1.9,0.31,,,,,,,\n"),
        );
        let r = read_ball_csv(&p).unwrap().remove(0);
        assert_eq!(r.frames, vec![3, 4, 6]);
        assert_eq!(r.positions[1], None);
        assert_eq!(r.info.side_info.unwrap()[2], 0.5);
    }

    #[test]
    fn csv_trajectory_column_splits_recordings() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "t.csv", "trajectory,frame,x,y,z\n4,0,0,0,0\n4,1,0,0,1\n7,0,1,1,1\n7,2,1,1,2\n");
        let recordings = read_ball_csv(&p).unwrap();
        let ids: Vec<u32> = recordings.iter().map(|r| r.id).collect();
        assert_eq!(ids, vec![4, 7]);
        assert_eq!(recordings[1].frames, vec![0, 2]);
        let p = write(
            dir.path(),
            "again.csv",
            "trajectory,frame,x,y,z\n0,0,0,0,0\n0,1,0,0,1\n1,0,0,0,0\n1,1,0,0,0\n0,5,0,0,0\n",
        );
        let err = read_ball_csv(&p).unwrap_err().to_string();
        assert!(err.contains("row 6: trajectory 0 appears again"), "{err}");
        let p = write(dir.path(), "short.csv", "trajectory,frame,x,y,z\n0,0,0,0,0\n1,0,0,0,0\n1,1,0,0,0\n");
        let err = read_ball_csv(&p).unwrap_err().to_string();
        assert!(err.contains("trajectory 0: 1 measured positions"), "{err}");
        let p = write(dir.path(), "neg.csv", "trajectory,frame,x,y,z\n-1,0,0,0,0\n");
        let err = read_ball_csv(&p).unwrap_err().to_string();
        assert!(err.contains("row 2: trajectory '-1' is not a non-negative integer"), "{err}");
    }

    #[test]
    fn csv_errors_name_the_row() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            ("t,x,y,z\n0,0,0,0\n0.0055555555555556,nan,0,0\n", "row 3: x is NaN"),
            ("frame,x,y,z\n5,0,0,0\n4,0,0,0\n", "row 3: frame 4 does not follow"),
            ("frame,x,y,z\n1,0,0,0\n100000000000,0,0,0\n", "row 3: frame 100000000000 follows frame 1: a gap of"),
            ("frame,x,y,z\n5,0,0,0\n", "1 measured positions"),
            ("frame,x,y,z\n1,0,0\n2,0,0,0\n", "row 2: 3 columns, expected 4"),
            ("time,a,b\n1,2,3\n", "expected columns frame (or t), x, y, z"),
            ("t,x,y,z\n0.001,0,0,0\n0.002,0,0,0\n", "not a non-negative whole camera frame"),
        ];
        for (i, (text, needle)) in cases.iter().enumerate() {
            let p = write(dir.path(), &format!("c{i}.csv"), text);
            let err = read_ball_csv(&p).unwrap_err().to_string();
            assert!(err.contains(&format!("c{i}.csv")) && err.contains(needle), "{err}");
        }
    }

    #[test]
    fn datasets_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let rec = Recording {
            id: 2,
            frames: vec![0, 1, 3],
            positions: vec![Some([0.0, 1.0, 2.0]), None, Some([0.1, 1.1, 2.1])],
            truth: Some(vec![[0.0; 9], [1.0; 9], [2.0; 9]]),
            info: RecordingInfo { orientation: Some("default".into()), impact_frame: Some(1), ..Default::default() },
        };
        let data = BallDataset {
            source: "simulator".into(),
            seed: 1,
            command_line: "mbrl collect".into(),
            mbrl_version: crate::VERSION.into(),
            recordings: vec![rec],
        };
        let p = dir.path().join("b.mcap");
        write_ball_dataset(&p, &data).unwrap();
        assert_eq!(read_ball_dataset(&p).unwrap(), data);
    }

    #[test]
    fn a_frame_index_jump_in_a_dataset_is_an_error_not_an_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let rec = |frames: Vec<u64>| Recording {
            id: 0,
            positions: vec![Some([0.0, 1.0, 0.3]); frames.len()],
            frames,
            truth: None,
            info: RecordingInfo::default(),
        };
        let data = |frames| BallDataset {
            source: "simulator".into(),
            seed: 1,
            command_line: "mbrl collect".into(),
            mbrl_version: crate::VERSION.into(),
            recordings: vec![rec(frames)],
        };
        let p = dir.path().join("b.mcap");
        write_ball_dataset(&p, &data(vec![0, 1, 1 + MAX_FRAME_GAP])).unwrap();
        assert_eq!(read_ball_dataset(&p).unwrap().recordings[0].frames.len(), 3);
        write_ball_dataset(&p, &data(vec![0, 1, 2, 100_000_000_000])).unwrap();
        let err = read_ball_dataset(&p).unwrap_err().to_string();
        assert!(err.contains("frame 100000000000 follows frame 2") && err.contains("longer than any flight"), "{err}");
    }
}
