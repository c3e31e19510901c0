//! Rollouts in a simulator, packed as a dataset: random rollouts, instance pairs for context models, and
//! replays of given action sequences.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::{Dataset, DatasetLayout, DatasetMeta, Rollout, Timestep};
use crate::data::dataset::RECORDED;
use crate::envs::{instance_env, Env, EnvName, EnvSpec, Exploration};
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::util::colored_noise::ColoredNoise;
use crate::util::seeding::{derive_seed, rng_for};

/// The random stream under `--seed` that a replay's reset state (and toy noise) come from.
pub(super) const REPLAY_STREAM: u64 = u64::from_be_bytes(*b"replay\0\0");

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
    check_size(&spec, settings.rollouts, settings.steps, "--rollouts × --steps")?;
    let mut instances = Vec::with_capacity(settings.rollouts);
    let mut steps = Vec::new();
    for k in 0..settings.rollouts {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        let mut rng = rng_for(settings.seed, &[k as u64]);
        env.sample_instance(&mut rng);
        let rollout = random_rollout(env.as_mut(), &spec, &mut rng, settings.steps);
        check_finite(&rollout, k as u64)?;
        instances.push(env.params());
        steps.extend(timesteps(&spec, &rollout, k as u32));
        monitor.progress("collect rollouts", k as u64 + 1, settings.rollouts as u64);
    }
    Ok(Dataset {
        meta: DatasetMeta::for_env(&spec, settings.seed, &settings.command_line, instances, DatasetLayout::Rollouts),
        steps,
        frames: Vec::new(),
    })
}

pub struct InstancePairSettings {
    pub env: EnvName,
    pub instances: usize,
    pub steps: usize,
    pub seed: u64,
    pub command_line: String,
}

/// The instance seed of instance `k` in an instance-pair dataset made with `seed`: `mbrl collect --actions …
/// --instance-seed <this>` replays in the same instance.
pub fn pair_instance_seed(seed: u64, k: u64) -> u64 {
    derive_seed(seed, &[k])
}

/// What a context model trains on (thesis B.2.1): per instance k, a target rollout (id 2k) and a context-source
/// rollout (id 2k+1) of the same hidden parameters, each with its own start state and random actions.
pub fn collect_instance_pairs(settings: &InstancePairSettings, monitor: &dyn Monitor) -> Result<Dataset> {
    if settings.instances == 0 || settings.steps == 0 {
        return Err(Error::config("--instances and --steps must be at least 1"));
    }
    let spec = settings.env.build()?.spec();
    let rollouts = settings.instances.checked_mul(2).ok_or_else(|| Error::config("--instances is too large"))?;
    check_size(&spec, rollouts, settings.steps, "2 × --instances × --steps")?;
    let mut instances = Vec::with_capacity(rollouts);
    let mut steps = Vec::new();
    for k in 0..settings.instances as u64 {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        let mut env = instance_env(&settings.env, pair_instance_seed(settings.seed, k))?;
        for role in 0..2 {
            let mut rng = rng_for(settings.seed, &[k, role]);
            let rollout = random_rollout(env.as_mut(), &spec, &mut rng, settings.steps);
            check_finite(&rollout, 2 * k + role)?;
            steps.extend(timesteps(&spec, &rollout, (2 * k + role) as u32));
            instances.push(env.params());
        }
        monitor.progress("collect instance pairs", k + 1, settings.instances as u64);
    }
    let layout = DatasetLayout::InstancePairs;
    Ok(Dataset {
        meta: DatasetMeta::for_env(&spec, settings.seed, &settings.command_line, instances, layout),
        steps,
        frames: Vec::new(),
    })
}

pub struct ReplaySettings {
    pub env: EnvName,
    /// One action per step. Values outside the action bounds are clipped by the env, as in any step.
    pub actions: Vec<Vec<f64>>,
    /// The start state; `None` draws one from the env's reset distribution under `seed`.
    pub init_state: Option<Vec<f64>>,
    /// Which instance of a parametrized family (see [`instance_env`]); `None` uses `seed`.
    pub instance_seed: Option<u64>,
    /// Keys the reset state and the transition noise of noisy envs (toy).
    pub seed: u64,
    pub command_line: String,
}

/// Steps the env through the given actions and records the single rollout with its instance's parameters.
pub fn replay(settings: &ReplaySettings) -> Result<Dataset> {
    let mut env = instance_env(&settings.env, settings.instance_seed.unwrap_or(settings.seed))?;
    let spec = env.spec();
    if let Some((t, a)) = settings.actions.iter().enumerate().find(|(_, a)| a.len() != spec.action_dim()) {
        return Err(Error::data(format!(
            "action {t} has {} value(s); {} takes {}",
            a.len(),
            spec.name,
            spec.action_dim()
        )));
    }
    if settings.actions.is_empty() {
        return Err(Error::data("no actions to replay"));
    }
    // Reset even when the start is given: it also seeds the noise of noisy envs from `seed`.
    env.reset(&mut rng_for(settings.seed, &[REPLAY_STREAM]));
    if let Some(state) = &settings.init_state {
        check_start(env.as_ref(), &spec, state)?;
        env.set_state(state);
    }
    let mut rollout = Rollout::start(env.state(), env.observe());
    for action in &settings.actions {
        let step = env.step(action);
        rollout.push(action.clone(), step.reward, env.state(), step.obs);
    }
    check_finite(&rollout, 0)?;
    let steps = timesteps(&spec, &rollout, 0).collect();
    Ok(Dataset {
        meta: DatasetMeta::for_env(
            &spec,
            settings.seed,
            &settings.command_line,
            vec![env.params()],
            DatasetLayout::Rollouts,
        ),
        steps,
        frames: Vec::new(),
    })
}

/// A simulator gone non-finite is stopped at the step where it happened, not written as a dataset no reader
/// takes back.
fn check_finite(rollout: &Rollout, id: u64) -> Result<()> {
    match rollout.first_non_finite_step() {
        Some(t) => Err(Error::diverged(format!(
            "rollout {id}, step {t}: the simulator's state or reward became non-finite (state {:?}, action {:?})",
            rollout.states[t], rollout.actions[t]
        ))),
        None => Ok(()),
    }
}

/// Parses `--init-state`: comma-separated finite numbers, one per state dimension.
pub fn parse_state(text: &str, spec: &EnvSpec) -> Result<Vec<f64>> {
    let state = text
        .split(',')
        .map(|field| {
            let field = field.trim();
            field.parse::<f64>().map_err(|_| {
                Error::config(format!(
                    "--init-state: '{field}' is not a number; expected {} for {}",
                    spec.state_names.join(","),
                    spec.name
                ))
            })
        })
        .collect::<Result<Vec<f64>>>()?;
    check_state(spec, &state)?;
    Ok(state)
}

/// Whether `state` (`--init-state`) is one `env` can start from: its length, finite values, and the env's own
/// bounds ([`Env::state_error`]).
pub fn check_start(env: &dyn Env, spec: &EnvSpec, state: &[f64]) -> Result<()> {
    check_state(spec, state)?;
    if let Some(reason) = env.state_error(state) {
        return Err(Error::config(format!("--init-state: {reason} ({})", spec.state_names.join(","))));
    }
    // Every env's own bounds lie inside this; it keeps the envs without any (the toy) from recording a start
    // their dataset's readers refuse.
    for (name, &x) in spec.state_names.iter().zip(state) {
        RECORDED.check(name, x).map_err(|e| Error::config(format!("--init-state: {e}")))?;
    }
    Ok(())
}

fn check_state(spec: &EnvSpec, state: &[f64]) -> Result<()> {
    let expected =
        || format!("expected {} finite numbers ({}) for {}", spec.state_dim(), spec.state_names.join(","), spec.name);
    if state.len() != spec.state_dim() {
        return Err(Error::config(format!("--init-state has {} value(s); {}", state.len(), expected())));
    }
    if let Some(bad) = state.iter().find(|x| !x.is_finite()) {
        return Err(Error::config(format!("--init-state: {bad} is not finite; {}", expected())));
    }
    Ok(())
}

fn random_rollout(env: &mut dyn Env, spec: &EnvSpec, rng: &mut ChaCha8Rng, steps: usize) -> Rollout {
    let obs = env.reset(rng);
    let mut rollout = Rollout::start(env.state(), obs);
    let colored = match env.exploration() {
        Exploration::Uniform => None,
        Exploration::Colored { beta, std, min_len } => Some(colored_actions(spec, rng, steps, beta, std, min_len)),
    };
    for t in 0..steps {
        let action: Vec<f64> = match &colored {
            Some(actions) => actions[t].clone(),
            None => spec.action_low.iter().zip(&spec.action_high).map(|(&lo, &hi)| rng.random_range(lo..=hi)).collect(),
        };
        let step = env.step(&action);
        rollout.push(action, step.reward, env.state(), step.obs);
        if step.done {
            break;
        }
    }
    rollout
}

/// `steps` random actions as the env explores when collecting data (uniform, or colored noise).
pub fn exploration_actions(env: &dyn Env, rng: &mut ChaCha8Rng, steps: usize) -> Vec<Vec<f64>> {
    let spec = env.spec();
    match env.exploration() {
        Exploration::Colored { beta, std, min_len } => colored_actions(&spec, rng, steps, beta, std, min_len),
        Exploration::Uniform => (0..steps)
            .map(|_| {
                spec.action_low.iter().zip(&spec.action_high).map(|(&lo, &hi)| rng.random_range(lo..=hi)).collect()
            })
            .collect(),
    }
}

/// `steps` actions of Gaussian colored noise, one sequence per action dimension (at least `min_len` long, of
/// which the first `steps` are used, so the spectrum does not depend on the rollout length), clipped.
fn colored_actions(
    spec: &EnvSpec,
    rng: &mut ChaCha8Rng,
    steps: usize,
    beta: f64,
    std: f64,
    min_len: usize,
) -> Vec<Vec<f64>> {
    let len = steps.max(min_len);
    let noise = ColoredNoise::new(beta, len);
    let mut scratch = vec![rustfft::num_complex::Complex::new(0.0, 0.0); len];
    let per_dim: Vec<Vec<f64>> = (0..spec.action_dim())
        .map(|_| {
            let mut sequence = vec![0.0; len];
            noise.sample_into(rng, &mut scratch, &mut sequence);
            sequence
        })
        .collect();
    (0..steps)
        .map(|t| {
            per_dim
                .iter()
                .zip(spec.action_low.iter().zip(&spec.action_high))
                .map(|(seq, (&lo, &hi))| (seq[t] * std).clamp(lo, hi))
                .collect()
        })
        .collect()
}

/// Observations are stored only where they differ from the state (see datasets/README.md).
pub(super) fn timesteps<'a>(spec: &EnvSpec, rollout: &'a Rollout, id: u32) -> impl Iterator<Item = Timestep> + 'a {
    let keep_obs = spec.obs_names != spec.state_names;
    rollout.timesteps(id).map(move |mut step| {
        if !keep_obs {
            (step.obs, step.next_obs) = (None, None);
        }
        step
    })
}

/// A transition in memory: the struct, its vectors' heap blocks, and the f64s in them.
pub(super) fn check_size(spec: &EnvSpec, rollouts: usize, steps: usize, flags: &str) -> Result<()> {
    let values = 2 * spec.state_dim() + spec.action_dim() + 2 * spec.obs_names.len();
    let per_step = std::mem::size_of::<Timestep>() + 5 * 16 + 8 * values;
    crate::util::budget::check(
        flags,
        crate::util::budget::times(&[rollouts, steps], per_step),
        "collect in several files",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::instance_pairs;
    use crate::envs::parse_env;
    use crate::error::ErrorKind;
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

    fn collect_pairs(env: &str, instances: usize, seed: u64) -> Dataset {
        let settings = InstancePairSettings {
            env: parse_env(env).unwrap(),
            instances,
            steps: 15,
            seed,
            command_line: "test".into(),
        };
        collect_instance_pairs(&settings, &NullMonitor).unwrap()
    }

    #[test]
    fn instance_pairs_share_parameters_but_not_starts_or_actions() {
        for env in ["toy:outer", "mountaincar", "pendulum:quadrant"] {
            let data = collect_pairs(env, 3, 2);
            assert_eq!(data.meta.layout, DatasetLayout::InstancePairs);
            assert_eq!(data.meta.instances.len(), 6);
            assert_ne!(data.meta.instances[0], data.meta.instances[2], "{env}: instances differ");
            let pairs = instance_pairs(&data).unwrap();
            for (k, (a, b)) in pairs.iter().enumerate() {
                assert_eq!(data.meta.instances[2 * k], data.meta.instances[2 * k + 1]);
                assert_eq!((a.len(), b.len()), (15, 15));
                assert_ne!(a.states[0], b.states[0], "{env}: own start states");
                assert_ne!(a.actions, b.actions, "{env}: own actions");
            }
            assert_eq!(data, collect_pairs(env, 3, 2), "{env}: seeded");
        }
    }

    #[test]
    fn pair_instances_are_the_ones_their_instance_seed_names() {
        let data = collect_pairs("toy:inner", 2, 9);
        let env = parse_env("toy:inner").unwrap();
        let replayed = instance_env(&env, pair_instance_seed(9, 1)).unwrap().params();
        assert_eq!(data.meta.instances[2], replayed);
    }

    #[test]
    fn state_only_envs_store_no_duplicate_observations() {
        let data = collect_pairs("mountaincar", 1, 0);
        assert!(data.steps.iter().all(|s| s.obs.is_none() && s.next_obs.is_none()));
        let data = collect_pairs("pendulum", 1, 0);
        assert!(data.steps.iter().all(|s| s.obs.as_ref().is_some_and(|o| o.len() == 3)));
    }

    fn replay_settings(env: &str, actions: Vec<Vec<f64>>, init_state: Option<Vec<f64>>) -> ReplaySettings {
        ReplaySettings {
            env: parse_env(env).unwrap(),
            actions,
            init_state,
            instance_seed: Some(4),
            seed: 1,
            command_line: "test".into(),
        }
    }

    #[test]
    fn replay_follows_the_given_actions_from_the_given_state() {
        let actions: Vec<Vec<f64>> = (0..10).map(|t| vec![(t as f64 - 4.5) * 0.5]).collect();
        let data = replay(&replay_settings("mountaincar", actions.clone(), Some(vec![0.1, -0.5]))).unwrap();
        assert_eq!(data.steps.iter().map(|s| s.action.clone()).collect::<Vec<_>>(), actions);
        assert_eq!(data.steps[0].state, vec![0.1, -0.5]);
        let mut env = instance_env(&parse_env("mountaincar").unwrap(), 4).unwrap();
        assert_eq!(data.meta.instances, vec![env.params()]);
        env.set_state(&[0.1, -0.5]);
        for step in &data.steps {
            assert_eq!(env.step(&step.action).obs, step.next_state);
        }
    }

    #[test]
    fn replay_noise_follows_the_seed() {
        let actions = vec![vec![1.5]; 5];
        let run = |seed| {
            replay(&ReplaySettings { seed, ..replay_settings("toy:outer", actions.clone(), Some(vec![0.0, 0.0])) })
        };
        assert_eq!(run(1).unwrap(), run(1).unwrap());
        assert_ne!(run(1).unwrap().steps, run(2).unwrap().steps);
    }

    #[test]
    fn bad_start_states_are_explained() {
        let spec = parse_env("pendulum").unwrap().build().unwrap().spec();
        assert_eq!(parse_state("3.1, -0.5", &spec).unwrap(), vec![3.1, -0.5]);
        let err = parse_state("1,2,3", &spec).unwrap_err().to_string();
        assert!(err.contains("3 value(s)") && err.contains("theta,theta_dot"), "{err}");
        let err = parse_state("1,nan", &spec).unwrap_err().to_string();
        assert!(err.contains("NaN is not finite"), "{err}");
        let err = parse_state("1,x", &spec).unwrap_err().to_string();
        assert!(err.contains("'x' is not a number"), "{err}");
        let err = replay(&replay_settings("pendulum", vec![vec![0.0]], Some(vec![1.0]))).unwrap_err().to_string();
        assert!(err.contains("--init-state has 1 value(s)"), "{err}");
        let err = replay(&replay_settings("pendulum", vec![vec![0.0, 1.0]], None)).unwrap_err().to_string();
        assert!(err.contains("action 0 has 2 value(s)"), "{err}");
    }

    #[test]
    fn oversized_collections_are_refused_before_allocating() {
        let settings = InstancePairSettings {
            env: parse_env("toy:inner").unwrap(),
            instances: 1 << 40,
            steps: 100,
            seed: 0,
            command_line: "test".into(),
        };
        let err = collect_instance_pairs(&settings, &NullMonitor).unwrap_err();
        assert!(matches!(err.kind(), ErrorKind::Budget { flag, .. } if flag == "--max-memory-gib"), "{err}");
    }
}
