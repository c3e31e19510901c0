//! Every mbrl data file as the tools users already have read it: a per-step CSV table, or NumPy arrays in
//! an `.npz` archive (`numpy.load`). The file's kind comes from its metadata record, so one command covers
//! rollout datasets (with their frames), board sets, ball recordings and filter estimates.

use std::io::Write;
use std::path::Path;

use ndarray::{ArrayD, IxDyn};
use ndarray_npy::{NpzWriter, WritableElement};

use super::ball_estimates::{read_estimates_mcap, STATE_NAMES as ESTIMATE_NAMES};
use super::ball_io::{read_ball_dataset, SIDE_INFO_COLUMNS};
use super::boardset::read_board_set;
use super::dataset::read_dataset;
use super::frames::frame_slots;
use super::mcap_io::metadata_names;
use super::{ball_estimates, ball_io, boardset, dataset};
use crate::envs::boards::split::Split;
use crate::error::{Error, Result};
use crate::util::atomic::{write_atomic, write_atomic_seekable};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportFormat {
    Csv,
    Npz,
}

impl ExportFormat {
    pub const NAMES: &'static str = "csv, npz";

    pub fn parse(text: &str) -> Option<Self> {
        match text.to_ascii_lowercase().as_str() {
            "csv" => Some(ExportFormat::Csv),
            "npz" => Some(ExportFormat::Npz),
            _ => None,
        }
    }

    pub fn extension(self) -> &'static str {
        match self {
            ExportFormat::Csv => "csv",
            ExportFormat::Npz => "npz",
        }
    }

    /// The format named by the output's extension, if it names one.
    pub fn of_path(path: &Path) -> Option<Self> {
        path.extension().and_then(|e| e.to_str()).and_then(Self::parse)
    }
}

/// What an mbrl MCAP file holds, from its metadata record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataKind {
    Rollouts,
    BoardSet,
    BallRecordings,
    BallEstimates,
}

impl DataKind {
    pub fn describe(self) -> &'static str {
        match self {
            DataKind::Rollouts => "rollout dataset",
            DataKind::BoardSet => "board set",
            DataKind::BallRecordings => "ball recordings",
            DataKind::BallEstimates => "ball filter estimates",
        }
    }

    pub fn detect(path: &Path) -> Result<Self> {
        let names = metadata_names(path)?;
        let known = [
            (dataset::METADATA_NAME, DataKind::Rollouts),
            (boardset::METADATA_NAME, DataKind::BoardSet),
            (ball_io::METADATA_NAME, DataKind::BallRecordings),
            (ball_estimates::METADATA_NAME, DataKind::BallEstimates),
        ];
        names.iter().find_map(|name| known.iter().find(|(n, _)| n == name).map(|&(_, kind)| kind)).ok_or_else(|| {
            let found = if names.is_empty() { "none".to_string() } else { names.join(", ") };
            Error::bad_file(
                path,
                format!(
                    "not an mbrl data file: metadata records found: {found}; expected one of {}",
                    known.map(|(n, _)| n).join(", ")
                ),
            )
        })
    }
}

enum Values {
    F64(Vec<f64>),
    I64(Vec<i64>),
    U8(Vec<u8>),
    Bool(Vec<bool>),
    /// Readable text for the CSV table only (NumPy string arrays would need pickling).
    Text(Vec<String>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::F64(v) => v.len(),
            Values::I64(v) => v.len(),
            Values::U8(v) => v.len(),
            Values::Bool(v) => v.len(),
            Values::Text(v) => v.len(),
        }
    }
}

/// One named array. `csv_columns` names the CSV columns of a per-step array (its trailing dimensions
/// flattened row-major); `None` keeps it out of the table (images, covariances, per-recording arrays).
struct Array {
    name: &'static str,
    shape: Vec<usize>,
    values: Values,
    csv_columns: Option<Vec<String>>,
}

impl Array {
    /// One value per row; the CSV column has the array's name.
    fn column(name: &'static str, values: Values) -> Self {
        Self::column_named(name, name, values)
    }

    /// One value per row under another CSV header (the board's text is `board` in the table).
    fn column_named(name: &'static str, header: &str, values: Values) -> Self {
        Array { name, shape: vec![values.len()], values, csv_columns: Some(vec![header.to_string()]) }
    }

    /// `columns.len()` values per row, row-major, each a CSV column. Stays two-dimensional with one column, so
    /// a shape does not depend on the data (an env with one action still gives `action` as (N, 1)).
    fn matrix(name: &'static str, rows: usize, values: Values, columns: Vec<String>) -> Self {
        Array { name, shape: vec![rows, columns.len()], values, csv_columns: Some(columns) }
    }

    fn npz_only(name: &'static str, shape: Vec<usize>, values: Values) -> Self {
        Array { name, shape, values, csv_columns: None }
    }
}

/// A data file in array form: what both formats write.
pub struct Exported {
    pub kind: DataKind,
    pub rows: usize,
    arrays: Vec<Array>,
}

impl Exported {
    /// `name shape` of every array, for the command's summary and the docs.
    pub fn array_shapes(&self, format: ExportFormat) -> Vec<String> {
        self.arrays
            .iter()
            .filter(|a| match format {
                ExportFormat::Csv => a.csv_columns.is_some(),
                ExportFormat::Npz => !matches!(a.values, Values::Text(_)),
            })
            .map(|a| {
                let dims: Vec<String> = a.shape.iter().map(usize::to_string).collect();
                format!("{} ({})", a.name, dims.join(" × "))
            })
            .collect()
    }
}

pub fn load(path: &Path) -> Result<Exported> {
    let exported = match DataKind::detect(path)? {
        DataKind::Rollouts => rollout_arrays(path)?,
        DataKind::BoardSet => board_arrays(path)?,
        DataKind::BallRecordings => ball_arrays(path)?,
        DataKind::BallEstimates => estimate_arrays(path)?,
    };
    for array in &exported.arrays {
        check_shape(path, exported.rows, array)?;
    }
    Ok(exported)
}

/// Rows of uneven width (a reader that let them through) would make a ragged array: refused by name.
fn check_shape(path: &Path, rows: usize, array: &Array) -> Result<()> {
    let len = array.values.len();
    let expected: usize = array.shape.iter().product();
    let table_ok = array.csv_columns.as_ref().is_none_or(|c| c.len() * rows == len);
    if len != expected || !table_ok {
        return Err(Error::bad_file(
            path,
            format!("'{}' has {len} values, not a {:?} array: entries of uneven width", array.name, array.shape),
        ));
    }
    Ok(())
}

fn numbered(prefix: &str, count: usize) -> Vec<String> {
    (0..count).map(|i| format!("{prefix}_{i}")).collect()
}

fn prefixed(prefix: &str, names: &[String]) -> Vec<String> {
    names.iter().map(|n| format!("{prefix}{n}")).collect()
}

fn rollout_arrays(path: &Path) -> Result<Exported> {
    let data = read_dataset(path)?;
    let steps = &data.steps;
    let rows = steps.len();
    let names = &data.meta.state_names;
    let flat = |get: &dyn Fn(&super::rollout::Timestep) -> &[f64]| -> Vec<f64> {
        steps.iter().flat_map(|s| get(s).iter().copied()).collect()
    };
    let mut arrays = vec![
        Array::column("rollout", Values::I64(steps.iter().map(|s| s.rollout as i64).collect())),
        Array::column("t", Values::I64(steps.iter().map(|s| s.t as i64).collect())),
        Array::matrix("state", rows, Values::F64(flat(&|s| &s.state)), names.clone()),
        Array::matrix("action", rows, Values::F64(flat(&|s| &s.action)), numbered("action", data.meta.action_dim)),
        Array::column("reward", Values::F64(steps.iter().map(|s| s.reward).collect())),
        Array::matrix("next_state", rows, Values::F64(flat(&|s| &s.next_state)), prefixed("next_", names)),
    ];
    // Observations exist only for envs whose observation differs from the state; they are exported when
    // every step has them with one width.
    let obs_width = steps.first().and_then(|s| s.obs.as_ref()).map(Vec::len);
    if let Some(width) = obs_width {
        let uniform = |get: &dyn Fn(&super::rollout::Timestep) -> Option<&Vec<f64>>| {
            steps.iter().all(|s| get(s).is_some_and(|o| o.len() == width))
        };
        if uniform(&|s| s.obs.as_ref()) && uniform(&|s| s.next_obs.as_ref()) {
            let obs: Vec<f64> =
                steps.iter().flat_map(|s| s.obs.as_deref().unwrap_or_default().iter().copied()).collect();
            let next: Vec<f64> =
                steps.iter().flat_map(|s| s.next_obs.as_deref().unwrap_or_default().iter().copied()).collect();
            arrays.push(Array::matrix("obs", rows, Values::F64(obs), numbered("obs", width)));
            arrays.push(Array::matrix("next_obs", rows, Values::F64(next), numbered("next_obs", width)));
        }
    }
    if let Some(info) = &data.meta.frames {
        let slots = frame_slots(steps);
        let pixels: Vec<u8> = data.frames.iter().flatten().copied().collect();
        let (height, width) = (info.height as usize, info.width as usize);
        arrays.push(Array::npz_only("frames", vec![data.frames.len(), height, width, 3], Values::U8(pixels)));
        arrays.push(Array::npz_only(
            "frame_rollout",
            vec![slots.len()],
            Values::I64(slots.iter().map(|&(r, _, _)| r as i64).collect()),
        ));
        arrays.push(Array::npz_only(
            "frame_t",
            vec![slots.len()],
            Values::I64(slots.iter().map(|&(_, t, _)| t as i64).collect()),
        ));
    }
    Ok(Exported { kind: DataKind::Rollouts, rows, arrays })
}

fn board_arrays(path: &Path) -> Result<Exported> {
    let set = read_board_set(path)?;
    let rows = set.boards.len();
    let mut fields = Vec::new();
    let mut width = None;
    let mut symbolic_width = None;
    for (i, record) in set.boards.iter().enumerate() {
        let values: Vec<i64> =
            record.board.split(',').map(|v| v.trim().parse::<i64>()).collect::<std::result::Result<_, _>>().map_err(
                |_| Error::bad_file(path, format!("board {i}: '{}' is not comma-separated integers", record.board)),
            )?;
        let same = |seen: &mut Option<usize>, n: usize, what: &str| match *seen {
            Some(w) if w != n => {
                Err(Error::bad_file(path, format!("board {i}: {n} {what}, the boards before it have {w}")))
            }
            _ => {
                *seen = Some(n);
                Ok(())
            }
        };
        same(&mut width, values.len(), "fields")?;
        same(&mut symbolic_width, record.symbolic.len(), "symbolic entries")?;
        fields.extend(values);
    }
    let width = width.unwrap_or(0);
    let symbolic_width = symbolic_width.unwrap_or(0);
    let arrays = vec![
        Array::column_named("board_text", "board", Values::Text(set.boards.iter().map(|b| b.board.clone()).collect())),
        Array::matrix("board", rows, Values::I64(fields), numbered("field", width)),
        Array::column("depth", Values::I64(set.boards.iter().map(|b| b.depth as i64).collect())),
        Array::column("test_split", Values::Bool(set.boards.iter().map(|b| b.split == Split::Test).collect())),
        Array::matrix(
            "symbolic",
            rows,
            Values::U8(set.boards.iter().flat_map(|b| b.symbolic.iter().copied()).collect()),
            numbered("symbolic", symbolic_width),
        ),
    ];
    Ok(Exported { kind: DataKind::BoardSet, rows, arrays })
}

const TRUE_STATE_NAMES: [&str; 9] =
    ["true_px", "true_py", "true_pz", "true_vx", "true_vy", "true_vz", "true_wx", "true_wy", "true_wz"];

fn ball_arrays(path: &Path) -> Result<Exported> {
    let data = read_ball_dataset(path)?;
    let recordings = &data.recordings;
    let rows: usize = recordings.iter().map(|r| r.frames.len()).sum();
    let per_frame = |f: &dyn Fn(&ball_io::Recording, usize) -> i64| -> Vec<i64> {
        recordings.iter().flat_map(|r| (0..r.frames.len()).map(move |i| f(r, i))).collect()
    };
    let positions: Vec<f64> =
        recordings.iter().flat_map(|r| r.positions.iter().flat_map(|p| p.unwrap_or([f64::NAN; 3]))).collect();
    let measured: Vec<bool> = recordings.iter().flat_map(|r| r.positions.iter().map(Option::is_some)).collect();
    let mut arrays = vec![
        Array::column("trajectory", Values::I64(per_frame(&|r, _| r.id as i64))),
        Array::column("frame", Values::I64(per_frame(&|r, i| r.frames[i] as i64))),
        Array::column("t", Values::F64(recordings.iter().flat_map(|r| r.times()).collect())),
        Array::matrix("position", rows, Values::F64(positions), ["x", "y", "z"].map(String::from).to_vec()),
        Array::column("measured", Values::Bool(measured)),
    ];
    if recordings.iter().all(|r| r.truth.is_some()) && !recordings.is_empty() {
        let truth: Vec<f64> =
            recordings.iter().flat_map(|r| r.truth.iter().flatten().flat_map(|s| s.iter().copied())).collect();
        arrays.push(Array::matrix("true_state", rows, Values::F64(truth), TRUE_STATE_NAMES.map(String::from).to_vec()));
    }
    let count = recordings.len();
    arrays.push(Array::npz_only(
        "recording_id",
        vec![count],
        Values::I64(recordings.iter().map(|r| r.id as i64).collect()),
    ));
    arrays.push(Array::npz_only(
        "recording_side_info",
        vec![count, SIDE_INFO_COLUMNS.len()],
        Values::F64(recordings.iter().flat_map(|r| r.info.side_info.unwrap_or([f64::NAN; 7])).collect()),
    ));
    arrays.push(Array::npz_only(
        "recording_impact_frame",
        vec![count],
        Values::I64(recordings.iter().map(|r| r.info.impact_frame.map_or(-1, |f| f as i64)).collect()),
    ));
    Ok(Exported { kind: DataKind::BallRecordings, rows, arrays })
}

fn estimate_arrays(path: &Path) -> Result<Exported> {
    let file = read_estimates_mcap(path)?;
    let estimates = &file.estimates;
    let rows = estimates.len();
    let dim = ESTIMATE_NAMES.len();
    let names = |prefix: &str| ESTIMATE_NAMES.iter().map(|n| format!("{prefix}{n}")).collect::<Vec<_>>();
    let arrays = vec![
        Array::column("trajectory", Values::I64(estimates.iter().map(|e| e.trajectory as i64).collect())),
        Array::column("frame", Values::I64(estimates.iter().map(|e| e.frame as i64).collect())),
        Array::column("t", Values::F64(estimates.iter().map(|e| e.t).collect())),
        Array::matrix(
            "measurement",
            rows,
            Values::F64(estimates.iter().flat_map(|e| e.measurement.unwrap_or([f64::NAN; 3])).collect()),
            ["mx", "my", "mz"].map(String::from).to_vec(),
        ),
        Array::matrix("mean", rows, Values::F64(estimates.iter().flat_map(|e| e.mean).collect()), names("")),
        Array::matrix(
            "std",
            rows,
            Values::F64(
                estimates.iter().flat_map(|e| (0..dim).map(|i| e.covariance[i * dim + i].max(0.0).sqrt())).collect(),
            ),
            names("std_"),
        ),
        Array::npz_only(
            "covariance",
            vec![rows, dim, dim],
            Values::F64(estimates.iter().flat_map(|e| e.covariance.iter().copied()).collect()),
        ),
        Array::column("after_impact", Values::Bool(estimates.iter().map(|e| e.after_impact).collect())),
    ];
    Ok(Exported { kind: DataKind::BallEstimates, rows, arrays })
}

pub fn write(exported: &Exported, format: ExportFormat, out: &Path) -> Result<()> {
    match format {
        ExportFormat::Csv => write_csv(exported, out),
        ExportFormat::Npz => write_npz(exported, out),
    }
}

/// Shortest text that reads back to the same f64; missing values (NaN) are empty cells, which
/// `numpy.genfromtxt` and pandas read as NaN.
pub(crate) fn format_f64(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn write_csv(exported: &Exported, out: &Path) -> Result<()> {
    let table: Vec<(&Array, usize)> =
        exported.arrays.iter().filter_map(|a| a.csv_columns.as_ref().map(|c| (a, c.len()))).collect();
    write_atomic(out, |sink| {
        let io = |e: csv::Error| Error::io(out, std::io::Error::other(e));
        let mut writer = csv::Writer::from_writer(sink);
        let header: Vec<&str> =
            table.iter().flat_map(|(a, _)| a.csv_columns.iter().flatten().map(String::as_str)).collect();
        writer.write_record(&header).map_err(io)?;
        let mut record: Vec<String> = Vec::with_capacity(header.len());
        for row in 0..exported.rows {
            record.clear();
            for &(array, width) in &table {
                let cells = row * width..(row + 1) * width;
                match &array.values {
                    Values::F64(v) => record.extend(v[cells].iter().map(|&x| format_f64(x))),
                    Values::I64(v) => record.extend(v[cells].iter().map(i64::to_string)),
                    Values::U8(v) => record.extend(v[cells].iter().map(u8::to_string)),
                    Values::Bool(v) => record.extend(v[cells].iter().map(|&b| u8::from(b).to_string())),
                    Values::Text(v) => record.extend(v[cells].iter().cloned()),
                }
            }
            writer.write_record(&record).map_err(io)?;
        }
        writer.flush().map_err(|e| Error::io(out, e))?;
        Ok(())
    })
}

fn write_npz(exported: &Exported, out: &Path) -> Result<()> {
    write_atomic_seekable(out, |file| {
        let npz_err = |e: ndarray_npy::WriteNpzError| Error::io(out, std::io::Error::other(e));
        let mut npz = NpzWriter::new(&mut *file);
        for array in &exported.arrays {
            match &array.values {
                Values::F64(v) => add(&mut npz, array, v).map_err(npz_err)?,
                Values::I64(v) => add(&mut npz, array, v).map_err(npz_err)?,
                Values::U8(v) => add(&mut npz, array, v).map_err(npz_err)?,
                Values::Bool(v) => add(&mut npz, array, v).map_err(npz_err)?,
                Values::Text(_) => {}
            }
        }
        npz.finish().map_err(npz_err)?;
        file.flush().map_err(|e| Error::io(out, e))
    })
}

fn add<W, T>(npz: &mut NpzWriter<W>, array: &Array, values: &[T]) -> std::result::Result<(), ndarray_npy::WriteNpzError>
where
    W: Write + std::io::Seek,
    T: WritableElement + Clone,
{
    // `load` checked every shape against its values, so this cannot fail.
    match ArrayD::from_shape_vec(IxDyn(&array.shape), values.to_vec()) {
        Ok(data) => npz.add_array(array.name, &data),
        Err(e) => Err(ndarray_npy::WriteNpzError::Npy(ndarray_npy::WriteNpyError::Io(std::io::Error::other(e)))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_read_back_exactly() {
        for x in [0.0, -1.5, 0.1, 1e-7, 3.0e20, -2.5e-300, f64::MAX, f64::MIN_POSITIVE, 123456.789] {
            assert_eq!(format_f64(x).parse::<f64>().unwrap(), x, "{x}");
        }
        assert_eq!(format_f64(f64::NAN), "");
    }

    #[test]
    fn format_follows_the_extension() {
        assert_eq!(ExportFormat::of_path(Path::new("a/b.NPZ")), Some(ExportFormat::Npz));
        assert_eq!(ExportFormat::of_path(Path::new("b.csv")), Some(ExportFormat::Csv));
        assert_eq!(ExportFormat::of_path(Path::new("b.mcap")), None);
    }
}
