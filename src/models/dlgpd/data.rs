//! DLGPD's training data: every window of three consecutive observations (o_k, o_{k+1}, o_{k+2}) of a
//! rollout is one transition, observation (o_k, o_{k+1}) → next observation (o_{k+1}, o_{k+2}) under the
//! action taken at k + 1 and that step's reward, so a rollout of T transitions gives T − 1 (the thesis' 30
//! frames give 28). An observation is a rendered frame (pixels scaled to [0, 1]) or, for the small preset, the
//! pole's direction (cos θ, sin θ): what a frame shows, in two numbers. Both get N(0, 0.01²) noise once at
//! load, as the authors' loader does, drawn from the seed (pixels clipped to [0, 1]).

use rand::Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::data::{Dataset, Rollout};
use crate::error::{Error, Result};
use crate::util::seeding::rng_for;

pub const OBSERVATION_NOISE_STD: f32 = 0.01;
const NOISE_STREAM: u64 = u64::from_be_bytes(*b"dlgpdpix");

/// What one time step's observation is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum ObservationKind {
    /// An RGB frame, side × side, stored channels first.
    Images { side: usize },
    /// (cos θ, sin θ) of the pendulum's state.
    Angles,
}

impl ObservationKind {
    /// Values of one time step's observation.
    pub fn frame_len(&self) -> usize {
        match self {
            ObservationKind::Images { side } => 3 * side * side,
            ObservationKind::Angles => 2,
        }
    }

    /// Values of a model input: two consecutive frames.
    pub fn input_len(&self) -> usize {
        2 * self.frame_len()
    }

    /// The observation kind a dataset offers: its frames when it has them, else the pendulum angle.
    pub fn of(data: &Dataset, images: bool) -> Result<ObservationKind> {
        if !images {
            if data.meta.state_names.first().map(String::as_str) != Some("theta") {
                return Err(Error::data(format!(
                    "dataset of {} has no pendulum angle 'theta' as its first state ({}); the angle observations \
                     of the small preset are for the pendulum",
                    data.meta.env,
                    data.meta.state_names.join(", ")
                )));
            }
            return Ok(ObservationKind::Angles);
        }
        let info = data.meta.frames.as_ref().ok_or_else(|| {
            Error::data(format!(
                "dataset of {} has no frames; DLGPD's image presets learn from them: collect with `mbrl collect \
                 --env {} --images`, or train the small preset on angles",
                data.meta.env, data.meta.env
            ))
        })?;
        if info.width != info.height {
            return Err(Error::data(format!("frames are {} × {}; DLGPD needs square frames", info.width, info.height)));
        }
        Ok(ObservationKind::Images { side: info.width as usize })
    }
}

/// The pendulum's angle as an observation.
pub fn angle_observation(theta: f64) -> [f32; 2] {
    [theta.cos() as f32, theta.sin() as f32]
}

/// RGB bytes (rows of pixels, HWC) → channel planes in [0, 1].
pub fn frame_planes(rgb: &[u8], plane: usize) -> impl Iterator<Item = f32> + '_ {
    (0..3).flat_map(move |channel| (0..plane).map(move |p| rgb[p * 3 + channel] as f32 / 255.0))
}

/// Observations of every time step, and the transitions that index them.
#[derive(Clone, Debug)]
pub struct Windows {
    pub kind: ObservationKind,
    /// One observation per state (t = 0 … T of each rollout), rollouts end to end.
    frames: Vec<f32>,
    /// Index of each transition's oldest observation o_k.
    first_frame: Vec<usize>,
    /// The rollout each transition comes from (the dataset's ids).
    pub rollout: Vec<u32>,
    pub actions: Vec<f64>,
    pub rewards: Vec<f64>,
    pub action_dim: usize,
}

impl Windows {
    pub fn from_dataset(data: &Dataset, kind: ObservationKind, seed: u64) -> Result<Windows> {
        let rollouts = Rollout::group(&data.steps)
            .map_err(|i| Error::data(format!("message {i} does not continue its rollout")))?;
        let mut rng = rng_for(seed, &[NOISE_STREAM]);
        let mut noisy = |clean: f32| clean + rng.sample::<f32, _>(StandardNormal) * OBSERVATION_NOISE_STD;
        let frames: Vec<f32> = match kind {
            ObservationKind::Images { side } => {
                let plane = side * side;
                if data.frames.iter().any(|f| f.len() != 3 * plane) {
                    return Err(Error::data(format!("a frame is not {side} × {side} RGB")));
                }
                data.frames.iter().flat_map(|rgb| frame_planes(rgb, plane)).map(|v| noisy(v).clamp(0.0, 1.0)).collect()
            }
            ObservationKind::Angles => rollouts
                .iter()
                .flat_map(|(_, r)| r.states.iter().map(|s| s[0]))
                .flat_map(angle_observation)
                .map(&mut noisy)
                .collect(),
        };
        let (mut first_frame, mut rollout_ids, mut actions, mut rewards) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut frame_start = 0;
        for (id, rollout) in &rollouts {
            for k in 0..rollout.len().saturating_sub(1) {
                first_frame.push(frame_start + k);
                rollout_ids.push(*id);
                actions.extend_from_slice(&rollout.actions[k + 1]);
                rewards.push(rollout.rewards[k + 1]);
            }
            frame_start += rollout.len() + 1;
        }
        if frame_start * kind.frame_len() != frames.len() {
            return Err(Error::data(format!(
                "{} observations for {frame_start} states",
                frames.len() / kind.frame_len().max(1)
            )));
        }
        if first_frame.is_empty() {
            return Err(Error::data("no rollout has the 2 transitions (3 observations) one DLGPD transition needs"));
        }
        Ok(Windows {
            kind,
            frames,
            first_frame,
            rollout: rollout_ids,
            actions,
            rewards,
            action_dim: data.meta.action_dim,
        })
    }

    pub fn len(&self) -> usize {
        self.first_frame.len()
    }

    pub fn is_empty(&self) -> bool {
        self.first_frame.is_empty()
    }

    fn frame(&self, index: usize) -> &[f32] {
        let size = self.kind.frame_len();
        &self.frames[index * size..(index + 1) * size]
    }

    /// Observations and next observations of the transitions `rows`, each [rows, 2 × frame] row-major
    /// (older observation first; for images [rows, 6, side, side]).
    pub fn observations(&self, rows: &[usize]) -> (Vec<f32>, Vec<f32>) {
        let size = self.kind.input_len();
        let (mut obs, mut next) = (Vec::with_capacity(rows.len() * size), Vec::with_capacity(rows.len() * size));
        for &row in rows {
            let k = self.first_frame[row];
            obs.extend_from_slice(self.frame(k));
            obs.extend_from_slice(self.frame(k + 1));
            next.extend_from_slice(self.frame(k + 1));
            next.extend_from_slice(self.frame(k + 2));
        }
        (obs, next)
    }

    /// Actions and rewards of the transitions `rows`.
    pub fn actions_and_rewards(&self, rows: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let a = self.action_dim;
        let actions = rows.iter().flat_map(|&r| self.actions[r * a..(r + 1) * a].iter().copied()).collect();
        (actions, rows.iter().map(|&r| self.rewards[r]).collect())
    }

    /// The transitions whose rollout `keep` accepts, as row indices.
    pub fn rows_where(&self, keep: impl Fn(u32) -> bool) -> Vec<usize> {
        (0..self.len()).filter(|&i| keep(self.rollout[i])).collect()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::data::collect::{collect_random, CollectSettings};
    use crate::data::collect_frames::add_pendulum_frames;
    use crate::envs::parse_env;
    use crate::run::NullMonitor;

    /// Random pendulum rollouts with their frames rendered.
    pub(crate) fn rendered_pendulum(rollouts: usize, steps: usize, seed: u64) -> Dataset {
        let env = parse_env("pendulum").unwrap();
        let settings = CollectSettings { env, rollouts, steps, seed, command_line: "test".into() };
        let mut data = collect_random(&settings, &NullMonitor).unwrap();
        add_pendulum_frames(&mut data, &NullMonitor).unwrap();
        data
    }

    fn dataset() -> Dataset {
        rendered_pendulum(2, 5, 1)
    }

    #[test]
    fn windows_of_three_frames_pair_with_the_middle_step() {
        let data = dataset();
        let kind = ObservationKind::of(&data, true).unwrap();
        assert_eq!(kind, ObservationKind::Images { side: 64 });
        let t = Windows::from_dataset(&data, kind, 0).unwrap();
        assert_eq!(t.len(), 2 * 4, "5 transitions (6 frames) per rollout give 4 windows");
        // The second rollout's first window: frames 6, 7, 8; action and reward of its step t = 1.
        assert_eq!(t.actions[4], data.steps[6].action[0]);
        assert_eq!(t.rewards[4], data.steps[6].reward);
        let (obs, next) = t.observations(&[4]);
        let plane = 3 * 64 * 64;
        assert_eq!(obs.len(), 2 * plane);
        assert_eq!(&obs[plane..], &next[..plane], "the newer frame of obs is the older frame of next");
        // Pixels near the frame: noise of 0.01 around the rendered value, inside [0, 1].
        let clean = crate::envs::pendulum::render::PendulumRenderer::new().frame(data.steps[5].state[0]);
        let red_plane: Vec<f32> = (0..64 * 64).map(|p| clean[p * 3] as f32 / 255.0).collect();
        let worst = obs[..64 * 64].iter().zip(&red_plane).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst > 0.0 && worst < 0.06, "largest deviation {worst}");
        assert!(obs.iter().all(|v| (0.0..=1.0).contains(v)));
        let again = Windows::from_dataset(&data, kind, 0).unwrap();
        assert_eq!(again.observations(&[4]).0, obs, "the same seed, the same noise");
    }

    #[test]
    fn a_dataset_without_frames_is_a_clear_error() {
        let mut data = dataset();
        data.meta.frames = None;
        data.frames.clear();
        let e = ObservationKind::of(&data, true).unwrap_err().to_string();
        assert!(e.contains("--images"), "{e}");
    }

    #[test]
    fn angle_windows_show_the_pole_direction_of_each_state() {
        let data = dataset();
        let t = Windows::from_dataset(&data, ObservationKind::Angles, 0).unwrap();
        assert_eq!(t.len(), 8);
        let (obs, next) = t.observations(&[4]);
        assert_eq!(obs.len(), 4);
        assert_eq!(&obs[2..], &next[..2]);
        // The second rollout's window starts at its state t = 0 (step 5 of the dataset).
        let clean = angle_observation(data.steps[5].state[0]);
        assert!((obs[0] - clean[0]).abs() < 0.05 && (obs[1] - clean[1]).abs() < 0.05, "{obs:?} vs {clean:?}");
        assert_eq!(t.rollout[4], data.steps[5].rollout);
        let (actions, rewards) = t.actions_and_rewards(&[4]);
        assert_eq!((actions[0], rewards[0]), (data.steps[6].action[0], data.steps[6].reward));
    }
}
