//! DLGPD's training data from a dataset with frames: every window of three consecutive frames
//! (f_k, f_{k+1}, f_{k+2}) of a rollout is one transition, observation (f_k, f_{k+1}) → next observation
//! (f_{k+1}, f_{k+2}) under the action taken at k + 1 and that step's reward, so a rollout of T transitions
//! gives T − 1 (the thesis' 30 frames give 28). Pixels are scaled to [0, 1] and get N(0, 0.01²) noise,
//! clipped, once at load (the authors' loader), drawn from the seed.

use rand::Rng;
use rand_distr::StandardNormal;

use crate::data::{Dataset, Rollout};
use crate::error::{Error, Result};
use crate::util::seeding::rng_for;

pub const PIXEL_NOISE_STD: f32 = 0.01;
const NOISE_STREAM: u64 = u64::from_be_bytes(*b"dlgpdpix");

/// Frames as channels-first f32 planes, and the transitions that index them.
#[derive(Clone, Debug)]
pub struct FrameTransitions {
    pub side: usize,
    /// Each frame 3 × side × side (RGB planes), frames of all rollouts end to end.
    frames: Vec<f32>,
    /// Index of each transition's oldest frame f_k.
    first_frame: Vec<usize>,
    pub actions: Vec<f32>,
    pub rewards: Vec<f32>,
    pub action_dim: usize,
}

impl FrameTransitions {
    pub fn from_dataset(data: &Dataset, seed: u64) -> Result<FrameTransitions> {
        let info = data.meta.frames.as_ref().ok_or_else(|| {
            Error::data(format!(
                "dataset of {} has no frames; DLGPD learns from images: collect with `mbrl collect --env {} --images`",
                data.meta.env, data.meta.env
            ))
        })?;
        if info.width != info.height {
            return Err(Error::data(format!("frames are {} × {}; DLGPD needs square frames", info.width, info.height)));
        }
        let side = info.width as usize;
        let plane = side * side;
        let rollouts = Rollout::group(&data.steps)
            .map_err(|i| Error::data(format!("message {i} does not continue its rollout")))?;
        let mut rng = rng_for(seed, &[NOISE_STREAM]);
        let mut frames = Vec::with_capacity(data.frames.len() * 3 * plane);
        for rgb in &data.frames {
            // HWC bytes → CHW [0, 1] with the loader's noise.
            for channel in 0..3 {
                for p in 0..plane {
                    let clean = rgb[p * 3 + channel] as f32 / 255.0;
                    let noise: f32 = rng.sample::<f32, _>(StandardNormal) * PIXEL_NOISE_STD;
                    frames.push((clean + noise).clamp(0.0, 1.0));
                }
            }
        }
        let (mut first_frame, mut actions, mut rewards) = (Vec::new(), Vec::new(), Vec::new());
        let mut frame_start = 0;
        for (_, rollout) in &rollouts {
            for k in 0..rollout.len().saturating_sub(1) {
                first_frame.push(frame_start + k);
                actions.extend(rollout.actions[k + 1].iter().map(|&a| a as f32));
                rewards.push(rollout.rewards[k + 1] as f32);
            }
            frame_start += rollout.len() + 1;
        }
        if first_frame.is_empty() {
            return Err(Error::data("no rollout has the 2 transitions (3 frames) one DLGPD transition needs"));
        }
        Ok(FrameTransitions { side, frames, first_frame, actions, rewards, action_dim: data.meta.action_dim })
    }

    pub fn len(&self) -> usize {
        self.first_frame.len()
    }

    pub fn is_empty(&self) -> bool {
        self.first_frame.is_empty()
    }

    fn frame(&self, index: usize) -> &[f32] {
        let size = 3 * self.side * self.side;
        &self.frames[index * size..(index + 1) * size]
    }

    /// Observations and next observations of the transitions `rows`, each [rows, 6, side, side] row-major
    /// (older frame's RGB first).
    pub fn observations(&self, rows: &[usize]) -> (Vec<f32>, Vec<f32>) {
        let size = 6 * self.side * self.side;
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
        let t = FrameTransitions::from_dataset(&data, 0).unwrap();
        assert_eq!(t.len(), 2 * 4, "5 transitions (6 frames) per rollout give 4 windows");
        // The second rollout's first window: frames 6, 7, 8; action and reward of its step t = 1.
        assert_eq!(t.actions[4], data.steps[6].action[0] as f32);
        assert_eq!(t.rewards[4], data.steps[6].reward as f32);
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
        let again = FrameTransitions::from_dataset(&data, 0).unwrap();
        assert_eq!(again.observations(&[4]).0, obs, "the same seed, the same noise");
    }

    #[test]
    fn a_dataset_without_frames_is_a_clear_error() {
        let mut data = dataset();
        data.meta.frames = None;
        data.frames.clear();
        let e = FrameTransitions::from_dataset(&data, 0).unwrap_err().to_string();
        assert!(e.contains("--images"), "{e}");
    }
}
