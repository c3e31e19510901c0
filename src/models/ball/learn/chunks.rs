//! Training chunks (eq. 6.24): windows of consecutive camera frames cut from recordings.
//!
//! A chunk is `len` consecutive camera frames f … f + len − 1 (frames a recording lacks and lost frames alike
//! are missing measurements). It starts wherever frames f and f + 1 are both measured, so the filter starts from
//! m_1 = m(f), m_2 = m(f + 1) one frame apart as in `initial_belief`, and the loss covers the measured frames
//! among the remaining len − 2 slots. Every such start is used, overlapping, as the thesis' chunk operator takes
//! all L + 1 − N windows; a window must fit entirely inside the recording.
//!
//! The start's phase (has m_2 been taken after the bounce?) decides the initial spin belief and whether the model
//! may still add an impact. It comes from the recording's impact frame, or, where that is unknown (real
//! recordings), from the measurements (`detect_impact_frame`). Windows whose m_1 is before and m_2 after the
//! bounce are skipped: their finite-difference velocity mixes the incoming and outgoing flight and describes
//! neither.

use super::rotation::motor_actuations;
use crate::data::ball_io::Recording;
use crate::error::{Error, Result};
use crate::models::ball::BallPhysics;

#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    /// Id of the recording it was cut from.
    pub recording: u32,
    /// Camera frame of m_1.
    pub start_frame: u64,
    pub m1: [f64; 3],
    pub m2: [f64; 3],
    /// Frames start + 2 …; `None` = no measurement.
    pub slots: Vec<Option<[f64; 3]>>,
    /// m_2 was taken after the table impact.
    pub after_impact: bool,
    pub side_info: Option<[f64; 7]>,
}

impl Chunk {
    pub fn measured(&self) -> usize {
        self.slots.iter().filter(|s| s.is_some()).count()
    }

    pub fn motor_actuations(&self) -> Option<[f64; 3]> {
        self.side_info.as_ref().map(motor_actuations)
    }
}

/// All chunks of `len` frames in `recordings`, in recording and frame order.
pub fn cut_chunks(recordings: &[Recording], len: usize, physics: &BallPhysics) -> Result<Vec<Chunk>> {
    if len < 3 {
        return Err(Error::config(format!("chunk length {len}: needs two frames to start and one to score")));
    }
    let mut chunks = Vec::new();
    for rec in recordings {
        let dense = dense_positions(rec)?;
        let Some(&first) = rec.frames.first() else { continue };
        let impact = rec.info.impact_frame.or_else(|| detect_impact_frame(&dense, physics).map(|k| first + k as u64));
        for s in 0..(dense.len() + 1).saturating_sub(len) {
            let (Some(m1), Some(m2)) = (dense[s], dense[s + 1]) else { continue };
            let second = first + s as u64 + 1;
            if impact == Some(second) {
                continue;
            }
            let slots = dense[s + 2..s + len].to_vec();
            if slots.iter().all(Option::is_none) {
                continue;
            }
            chunks.push(Chunk {
                recording: rec.id,
                start_frame: second - 1,
                m1,
                m2,
                slots,
                after_impact: impact.is_some_and(|k| k < second),
                side_info: rec.info.side_info,
            });
        }
    }
    Ok(chunks)
}

/// One entry per camera frame from the recording's first to its last frame.
fn dense_positions(rec: &Recording) -> Result<Vec<Option<[f64; 3]>>> {
    let bad = |message: String| Err(Error::data(format!("recording {}: {message}", rec.id)));
    if rec.frames.len() != rec.positions.len() {
        return bad(format!("{} frame indices but {} positions", rec.frames.len(), rec.positions.len()));
    }
    let (Some(&first), Some(&last)) = (rec.frames.first(), rec.frames.last()) else { return Ok(Vec::new()) };
    if rec.frames.windows(2).any(|w| w[1] <= w[0]) {
        return bad("frame indices must increase".into());
    }
    if rec.positions.iter().flatten().flatten().any(|x| !x.is_finite()) {
        return bad("non-finite measured position".into());
    }
    let mut dense = vec![None; (last - first + 1) as usize];
    for (&f, &p) in rec.frames.iter().zip(&rec.positions) {
        dense[(f - first) as usize] = p;
    }
    Ok(dense)
}

/// Index (into the dense frame list) of the first frame measured after the bounce, for recordings that do not
/// carry it: the first frame k where the straight continuation of frames k − 2, k − 1 would put the ball's lower
/// edge under the table (the model's own crossing test, eq. 6.22) and the measurement at k lies above that
/// continuation (the ball came back up rather than falling past the table's end). Needs frames k − 2 … k measured;
/// a bounce hidden by dropouts is not found, and the recording then counts as bounce-free.
pub fn detect_impact_frame(dense: &[Option<[f64; 3]>], physics: &BallPhysics) -> Option<usize> {
    (2..dense.len()).find(|&k| {
        let (Some(a), Some(b), Some(c)) = (dense[k - 2], dense[k - 1], dense[k]) else { return false };
        let continued = 2.0 * b[2] - a[2];
        b[2] < a[2] && continued - physics.ball_radius < physics.table_z && c[2] > continued
    })
}
