//! Random rollouts, one instance each, or instance pairs (two rollouts per instance) for context models.

use std::path::PathBuf;

use super::{CollectOptions, CollectSummary, Policy};
use crate::data::collect::{collect_instance_pairs, collect_random, CollectSettings, InstancePairSettings};
use crate::data::collect_frames::{add_pendulum_frames, check_frames_size};
use crate::data::write_dataset;
use crate::envs::EnvName;
use crate::jobs::{file_stem, output_file, Invocation, Job};
use crate::Result;

pub(super) fn prepare(
    env: EnvName,
    options: CollectOptions,
    invocation: &Invocation,
) -> Result<Job<'static, CollectSummary>> {
    let mode = if options.instances.is_some() { "pairs" } else { "random" };
    let default = || PathBuf::from(format!("datasets/{}-{mode}.mcap", file_stem(&env.canonical())));
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    if options.images {
        let rollouts = options.instances.map_or(options.rollouts, |n| 2 * n);
        check_frames_size(&env, rollouts as f64 * (options.steps as f64 + 1.0))?;
    }
    let (seed, command_line) = (invocation.seed, invocation.command_line.clone());
    Ok(Job::new("collect", move |monitor| {
        let mut data = match (options.instances, options.policy) {
            (Some(instances), Policy::Random) => {
                let settings = InstancePairSettings { env, instances, steps: options.steps, seed, command_line };
                collect_instance_pairs(&settings, monitor)?
            }
            (None, Policy::Random) => {
                let settings =
                    CollectSettings { env, rollouts: options.rollouts, steps: options.steps, seed, command_line };
                collect_random(&settings, monitor)?
            }
        };
        if options.images {
            add_pendulum_frames(&mut data, monitor)?;
        }
        write_dataset(&out, &data)?;
        Ok(CollectSummary::Rollouts {
            transitions: data.steps.len(),
            rollouts: data.meta.instances.len(),
            pairs: options.instances,
            env: data.meta.env,
            frames: data.frames.len(),
            out,
        })
    }))
}
