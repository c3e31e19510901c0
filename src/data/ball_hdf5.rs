//! Import of real ball recordings in the HDF5 layout of the thesis authors' public release: a group
//! `processed` with one subgroup per trajectory (`<data group>%<index>`) holding `timestamps`,
//! `frame_indices`, `positions` (n × 3, measured frames only), `side_info` (7 values) and the attributes
//! `first_up_idx` (index of the first measurement after the table impact, −1 if none) and `split`.

use std::path::Path;

use super::ball_io::{Recording, RecordingInfo};
use crate::error::{Error, Result};

/// One imported trajectory with the name and split it had in the file.
pub struct ImportedTrajectory {
    pub name: String,
    pub split: String,
    pub recording: Recording,
}

fn h5(path: &Path, what: &str, e: hdf5::Error) -> Error {
    Error::bad_file(path, format!("{what}: {e}"))
}

pub fn read_hdf5_recordings(path: &Path) -> Result<Vec<ImportedTrajectory>> {
    let file = hdf5::File::open(path).map_err(|e| h5(path, "not a readable HDF5 file", e))?;
    let processed = file.group("processed").map_err(|e| h5(path, "expected a group 'processed'", e))?;
    let mut names = processed.member_names().map_err(|e| h5(path, "cannot list 'processed'", e))?;
    names.sort();
    let mut out = Vec::with_capacity(names.len());
    for (id, name) in names.iter().enumerate() {
        let at = |what: &str| format!("processed/{name}: {what}");
        let group = processed.group(name).map_err(|e| h5(path, &at("not a group"), e))?;
        let frames: Vec<i64> = group
            .dataset("frame_indices")
            .and_then(|d| d.read_raw::<i64>())
            .map_err(|e| h5(path, &at("frame_indices"), e))?;
        let positions: Vec<f64> =
            group.dataset("positions").and_then(|d| d.read_raw::<f64>()).map_err(|e| h5(path, &at("positions"), e))?;
        if positions.len() != 3 * frames.len() {
            return Err(Error::bad_file(
                path,
                at(&format!(
                    "positions hold {} values, expected 3 per frame index ({})",
                    positions.len(),
                    frames.len()
                )),
            ));
        }
        let side: Vec<f64> =
            group.dataset("side_info").and_then(|d| d.read_raw::<f64>()).map_err(|e| h5(path, &at("side_info"), e))?;
        let side_info = <[f64; 7]>::try_from(side.as_slice()).ok();
        let first_up: i64 = group
            .attr("first_up_idx")
            .and_then(|a| a.read_scalar::<i64>())
            .map_err(|e| h5(path, &at("attribute first_up_idx"), e))?;
        let split = group
            .attr("split")
            .and_then(|a| a.read_scalar::<hdf5::types::VarLenUnicode>())
            .map(|s| s.to_string())
            .map_err(|e| h5(path, &at("attribute split"), e))?;
        let mut recording = Recording {
            id: id as u32,
            frames: Vec::new(),
            positions: Vec::new(),
            truth: None,
            info: RecordingInfo { side_info, ..RecordingInfo::default() },
        };
        // Measured frames only in the file: lost frames between them become explicit gaps.
        for (k, (&frame, p)) in frames.iter().zip(positions.chunks(3)).enumerate() {
            if frame < 0 {
                return Err(Error::bad_file(path, at(&format!("frame index {frame} at {k} is negative"))));
            }
            if let Some(why) = super::ball_io::frame_step_error(recording.frames.last().copied(), frame as u64) {
                return Err(Error::bad_file(path, at(&format!("index {k}: {why}"))));
            }
            if p.iter().any(|v| !v.is_finite()) {
                return Err(Error::bad_file(path, at(&format!("non-finite position at index {k}"))));
            }
            if let Some(&last) = recording.frames.last() {
                for missing in last + 1..frame as u64 {
                    recording.frames.push(missing);
                    recording.positions.push(None);
                }
            }
            recording.frames.push(frame as u64);
            recording.positions.push(Some([p[0], p[1], p[2]]));
        }
        if recording.measured() < 2 {
            return Err(Error::bad_file(path, at("fewer than two measured positions")));
        }
        if first_up >= 0 {
            recording.info.impact_frame = frames.get(first_up as usize).map(|&f| f as u64);
        }
        out.push(ImportedTrajectory { name: name.clone(), split, recording });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_sample(path: &Path, frames: &[i64], positions: &[[f64; 3]]) {
        let file = hdf5::File::create(path).unwrap();
        let group = file.create_group("processed").unwrap();
        let traj = group.create_group("launcher_default%0007").unwrap();
        let times: Vec<f64> = frames.iter().map(|&f| f as f64 / 180.0).collect();
        traj.new_dataset_builder().with_data(&times).create("timestamps").unwrap();
        traj.new_dataset_builder().with_data(frames).create("frame_indices").unwrap();
        let flat = ndarray_free(positions);
        traj.new_dataset_builder().with_data(&flat).create("positions").unwrap();
        traj.new_dataset_builder().with_data(&[0.0, 1.0, 0.5, 0.8, 0.12, 0.16, 0.17]).create("side_info").unwrap();
        traj.new_attr::<i64>().create("first_up_idx").unwrap().write_scalar(&2i64).unwrap();
        let split: hdf5::types::VarLenUnicode = "train".parse().unwrap();
        traj.new_attr::<hdf5::types::VarLenUnicode>().create("split").unwrap().write_scalar(&split).unwrap();
    }

    fn ndarray_free(positions: &[[f64; 3]]) -> Vec<f64> {
        positions.iter().flatten().copied().collect()
    }

    #[test]
    fn reads_the_release_layout_with_gaps() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rec.hdf5");
        write_sample(&path, &[3, 4, 7, 8], &[[0.0, 3.0, 0.1], [0.0, 2.98, 0.11], [0.0, 2.92, 0.12], [0.0, 2.9, 0.13]]);
        let imported = read_hdf5_recordings(&path).unwrap();
        assert_eq!(imported.len(), 1);
        let t = &imported[0];
        assert_eq!(t.name, "launcher_default%0007");
        assert_eq!(t.split, "train");
        assert_eq!(t.recording.frames, vec![3, 4, 5, 6, 7, 8]);
        assert_eq!(t.recording.positions[2], None);
        assert_eq!(t.recording.info.impact_frame, Some(7));
        assert_eq!(t.recording.info.side_info.unwrap()[3], 0.8);
    }

    #[test]
    fn bad_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.hdf5");
        write_sample(&path, &[3, 2], &[[0.0; 3], [0.0; 3]]);
        let err = read_hdf5_recordings(&path).err().unwrap().to_string();
        assert!(err.contains("bad.hdf5") && err.contains("frame 2 does not follow"), "{err}");
        write_sample(&path, &[3, 4, 100_000_000_000], &[[0.0; 3], [0.0; 3], [0.0; 3]]);
        let err = read_hdf5_recordings(&path).err().unwrap().to_string();
        assert!(err.contains("longer than any flight"), "{err}");
        std::fs::write(dir.path().join("text.hdf5"), "not hdf5").unwrap();
        let err = read_hdf5_recordings(&dir.path().join("text.hdf5")).err().unwrap().to_string();
        assert!(err.contains("text.hdf5") && err.contains("not a readable HDF5 file"), "{err}");
    }
}
