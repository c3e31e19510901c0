//! Episodes of skill execution and the ring memory they are sampled from (the authors' EpisodeMemory: capacity
//! 2048, uniform sampling with replacement), stored whole in the training state so a resumed run continues
//! with the memory it stopped with.

use rand::Rng;

use crate::error::{Error, Result};
use crate::train::tensors::{StoredTensor, TensorData};

/// One execution of a skill from a fresh reset until the board changed or the step limit.
#[derive(Clone, Debug, PartialEq)]
pub struct Episode {
    /// The skill the policy was asked to execute.
    pub label: usize,
    /// Observations s_0..s_T (manipulator ⊕ board bits ⊕ remaining time), row-major.
    pub obs: Vec<f32>,
    /// Actions a_0..a_{T−1}, row-major, in env units.
    pub actions: Vec<f32>,
    /// The game move the episode performed, if the board changed (for statistics; not used in learning).
    pub performed: Option<usize>,
}

/// Where the parts of an observation lie.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObsLayout {
    pub obs_dim: usize,
    pub action_dim: usize,
    pub bits_offset: usize,
    pub bits: usize,
}

impl ObsLayout {
    pub fn steps(&self, episode: &Episode) -> usize {
        episode.actions.len() / self.action_dim
    }

    pub fn obs<'a>(&self, episode: &'a Episode, t: usize) -> &'a [f32] {
        &episode.obs[t * self.obs_dim..(t + 1) * self.obs_dim]
    }

    pub fn board<'a>(&self, episode: &'a Episode, t: usize) -> &'a [f32] {
        &self.obs(episode, t)[self.bits_offset..self.bits_offset + self.bits]
    }

    pub fn first_board<'a>(&self, episode: &'a Episode) -> &'a [f32] {
        self.board(episode, 0)
    }

    pub fn last_board<'a>(&self, episode: &'a Episode) -> &'a [f32] {
        self.board(episode, self.steps(episode))
    }

    pub fn changed(&self, episode: &Episode) -> bool {
        self.first_board(episode) != self.last_board(episode)
    }
}

pub struct EpisodeMemory {
    capacity: usize,
    episodes: Vec<Episode>,
    /// Slot the next episode goes to.
    position: usize,
}

impl EpisodeMemory {
    pub fn new(capacity: usize) -> Self {
        EpisodeMemory { capacity: capacity.max(1), episodes: Vec::new(), position: 0 }
    }

    pub fn len(&self) -> usize {
        self.episodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.episodes.is_empty()
    }

    pub fn add(&mut self, episode: Episode) {
        if self.episodes.len() < self.capacity {
            self.episodes.push(episode);
        } else {
            self.episodes[self.position] = episode;
        }
        self.position = (self.position + 1) % self.capacity;
    }

    /// `count` episodes drawn uniformly with replacement.
    pub fn sample<R: Rng + ?Sized>(&self, count: usize, rng: &mut R) -> Vec<&Episode> {
        if self.episodes.is_empty() {
            return Vec::new();
        }
        (0..count).map(|_| &self.episodes[rng.random_range(0..self.episodes.len())]).collect()
    }

    /// The `count` most recently added episodes, oldest first.
    pub fn recent(&self, count: usize) -> Vec<&Episode> {
        let n = self.episodes.len();
        let count = count.min(n);
        let newest = (self.position + self.capacity - 1) % self.capacity;
        (0..count).rev().map(|back| &self.episodes[(newest + n - back) % n]).collect()
    }

    pub fn episodes(&self) -> &[Episode] {
        &self.episodes
    }

    pub fn to_stored(&self, prefix: &str) -> Vec<StoredTensor> {
        let n = self.episodes.len();
        let f64s =
            |name: &str, values: Vec<f64>| StoredTensor::f64(format!("{prefix}.{name}"), vec![values.len()], values);
        let obs: Vec<f32> = self.episodes.iter().flat_map(|e| e.obs.iter().copied()).collect();
        let actions: Vec<f32> = self.episodes.iter().flat_map(|e| e.actions.iter().copied()).collect();
        vec![
            f64s("position", vec![self.position as f64]),
            f64s("labels", self.episodes.iter().map(|e| e.label as f64).collect()),
            // −1 = no move performed.
            f64s("performed", self.episodes.iter().map(|e| e.performed.map_or(-1.0, |m| m as f64)).collect()),
            f64s("obs_len", self.episodes.iter().map(|e| e.obs.len() as f64).collect()),
            f64s("action_len", self.episodes.iter().map(|e| e.actions.len() as f64).collect()),
            StoredTensor::f32(format!("{prefix}.obs"), vec![obs.len()], obs),
            StoredTensor::f32(format!("{prefix}.actions"), vec![actions.len()], actions),
        ]
        .into_iter()
        .chain(std::iter::once(f64s("count", vec![n as f64])))
        .collect()
    }

    /// The memory saved by [`Self::to_stored`], checked against the observation layout and the skill count.
    pub fn from_stored(
        stored: &[StoredTensor],
        prefix: &str,
        capacity: usize,
        layout: ObsLayout,
        skills: usize,
    ) -> Result<Self> {
        let bad = |what: &str| Error::config(format!("training state: episode memory {what}"));
        let find = |name: &str| stored.iter().find(|t| t.name == format!("{prefix}.{name}")).map(|t| &t.data);
        let f64s = |name: &str| match find(name) {
            Some(TensorData::F64(v)) => Ok(v),
            _ => Err(bad(&format!("lacks '{name}'"))),
        };
        let f32s = |name: &str| match find(name) {
            Some(TensorData::F32(v)) => Ok(v),
            _ => Err(bad(&format!("lacks '{name}'"))),
        };
        let whole = |v: f64, max: usize| -> Result<usize> {
            if v.fract() == 0.0 && v >= 0.0 && v <= max as f64 {
                Ok(v as usize)
            } else {
                Err(bad(&format!("holds {v} where a count up to {max} belongs")))
            }
        };
        let count = whole(*f64s("count")?.first().ok_or_else(|| bad("lacks its count"))?, capacity)?;
        let position = whole(*f64s("position")?.first().ok_or_else(|| bad("lacks its position"))?, capacity - 1)?;
        let (labels, performed) = (f64s("labels")?, f64s("performed")?);
        let (obs_len, action_len) = (f64s("obs_len")?, f64s("action_len")?);
        let (obs, actions) = (f32s("obs")?, f32s("actions")?);
        if [labels.len(), performed.len(), obs_len.len(), action_len.len()].iter().any(|&l| l != count) {
            return Err(bad("has per-episode lists of different lengths"));
        }
        let (mut obs_at, mut action_at) = (0usize, 0usize);
        let mut episodes = Vec::with_capacity(count);
        for e in 0..count {
            let o = whole(obs_len[e], obs.len() - obs_at)?;
            let a = whole(action_len[e], actions.len() - action_at)?;
            let steps = a / layout.action_dim.max(1);
            if a % layout.action_dim.max(1) != 0 || o != (steps + 1) * layout.obs_dim || steps == 0 {
                return Err(bad(&format!("episode {e} does not fit the observation layout")));
            }
            let label = whole(labels[e], skills - 1)?;
            let performed = if performed[e] == -1.0 { None } else { Some(whole(performed[e], usize::MAX >> 1)?) };
            episodes.push(Episode {
                label,
                obs: obs[obs_at..obs_at + o].to_vec(),
                actions: actions[action_at..action_at + a].to_vec(),
                performed,
            });
            obs_at += o;
            action_at += a;
        }
        if obs_at != obs.len() || action_at != actions.len() {
            return Err(bad("holds more values than its episodes"));
        }
        if count < capacity && position != count % capacity {
            return Err(bad("position does not match a memory that is still filling"));
        }
        Ok(EpisodeMemory { capacity, episodes, position })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn episode(label: usize) -> Episode {
        Episode { label, obs: vec![label as f32; 6], actions: vec![0.5; 2], performed: Some(label) }
    }

    #[test]
    fn recent_and_round_trip() {
        let layout = ObsLayout { obs_dim: 3, action_dim: 2, bits_offset: 1, bits: 1 };
        let mut memory = EpisodeMemory::new(4);
        for k in 0..6 {
            memory.add(episode(k));
        }
        let recent: Vec<usize> = memory.recent(3).iter().map(|e| e.label).collect();
        assert_eq!(recent, vec![3, 4, 5]);
        let back = EpisodeMemory::from_stored(&memory.to_stored("memory"), "memory", 4, layout, 6).unwrap();
        assert_eq!(back.episodes(), memory.episodes());
        assert_eq!(back.recent(2).iter().map(|e| e.label).collect::<Vec<_>>(), vec![4, 5]);
        let mut broken = memory.to_stored("memory");
        broken.retain(|t| t.name != "memory.obs");
        assert!(EpisodeMemory::from_stored(&broken, "memory", 4, layout, 6).is_err());
    }

    /// Every count and length in a saved memory is checked against the values present: corrupted ones are
    /// errors, never a panic or a huge allocation.
    #[test]
    fn corrupted_counts_and_lengths_are_errors() {
        let layout = ObsLayout { obs_dim: 3, action_dim: 2, bits_offset: 1, bits: 1 };
        let mut memory = EpisodeMemory::new(4);
        for k in 0..3 {
            memory.add(episode(k));
        }
        let saved = memory.to_stored("memory");
        for (name, index, value) in [
            ("memory.count", 0, 1e18),
            ("memory.count", 0, 2.0),
            ("memory.position", 0, -1.0),
            ("memory.obs_len", 1, 1e12),
            ("memory.obs_len", 0, 5.0),
            ("memory.action_len", 2, f64::NAN),
            ("memory.labels", 0, 6.0),
            ("memory.performed", 0, 0.5),
        ] {
            let mut broken = saved.clone();
            let tensor = broken.iter_mut().find(|t| t.name == name).unwrap();
            if let TensorData::F64(v) = &mut tensor.data {
                v[index] = value;
            }
            assert!(
                EpisodeMemory::from_stored(&broken, "memory", 4, layout, 6).is_err(),
                "{name}[{index}] = {value} was accepted"
            );
        }
    }
}
