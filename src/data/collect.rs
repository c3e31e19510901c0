//! Rollouts of a behaviour policy in a simulator, packed as a dataset.

use rand::Rng;

use super::{Dataset, DatasetMeta, Rollout, FORMAT_VERSION};
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::util::seeding::rng_for;

pub struct CollectSettings {
    pub env: EnvName,
    pub rollouts: usize,
    pub steps: usize,
    pub seed: u64,
    pub command_line: String,
}

/// Uniformly random actions within the action bounds; each rollout draws a fresh instance of a
/// parametrized family and a start state from the environment's reset distribution.
pub fn collect_random(settings: &CollectSettings, monitor: &dyn Monitor) -> Result<Dataset> {
    if settings.rollouts == 0 || settings.steps == 0 {
        return Err(Error::config("--rollouts and --steps must be at least 1"));
    }
    let mut env = settings.env.build()?;
    let spec = env.spec();
    let mut instances = Vec::with_capacity(settings.rollouts);
    let mut steps = Vec::with_capacity(settings.rollouts * settings.steps);
    for k in 0..settings.rollouts {
        if monitor.is_cancelled() {
            return Err(Error::Cancelled);
        }
        let mut rng = rng_for(settings.seed, &[k as u64]);
        env.sample_instance(&mut rng);
        let obs = env.reset(&mut rng);
        let mut rollout = Rollout::start(env.state(), obs);
        for _ in 0..settings.steps {
            let action: Vec<f64> =
                spec.action_low.iter().zip(&spec.action_high).map(|(&lo, &hi)| rng.random_range(lo..=hi)).collect();
            let step = env.step(&action);
            rollout.push(action, step.reward, env.state(), step.obs);
            if step.done {
                break;
            }
        }
        instances.push(env.params());
        steps.extend(rollout.timesteps(k as u32));
        monitor.progress("collect rollouts", k as u64 + 1, settings.rollouts as u64);
    }
    Ok(Dataset {
        meta: DatasetMeta {
            format_version: FORMAT_VERSION,
            env: spec.name.clone(),
            seed: settings.seed,
            mbrl_version: crate::VERSION.to_string(),
            command_line: settings.command_line.clone(),
            instances,
            state_names: spec.state_names.clone(),
            action_dim: spec.action_dim(),
            dt: spec.dt,
        },
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::parse_env;
    use crate::run::NullMonitor;

    #[test]
    fn random_rollouts_stay_in_bounds_and_are_seeded() {
        let settings = CollectSettings {
            env: parse_env("pendulum:quadrant").unwrap(),
            rollouts: 3,
            steps: 20,
            seed: 5,
            command_line: "test".into(),
        };
        let a = collect_random(&settings, &NullMonitor).unwrap();
        assert_eq!(a.steps.len(), 60);
        assert_eq!(a.meta.instances.len(), 3);
        assert_ne!(a.meta.instances[0], a.meta.instances[1], "each rollout draws its own instance");
        assert!(a.steps.iter().all(|s| s.action[0].abs() <= 2.0 && s.state[1].abs() <= 8.0));
        assert_eq!(a, collect_random(&settings, &NullMonitor).unwrap());
    }
}
