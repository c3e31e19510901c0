//! A replay of recorded actions (`--actions CSV`) in one simulator instance.

use std::path::{Path, PathBuf};

use super::{CollectOptions, CollectSummary};
use crate::data::actions_csv::read_actions;
use crate::data::collect::{parse_state, replay, ReplaySettings};
use crate::data::collect_frames::{add_pendulum_frames, check_frames_size};
use crate::data::write_dataset;
use crate::envs::EnvName;
use crate::jobs::{file_stem, output_file, Invocation, Job};
use crate::Result;

pub(super) fn prepare(
    env: EnvName,
    actions: &Path,
    options: CollectOptions,
    invocation: &Invocation,
) -> Result<Job<'static, CollectSummary>> {
    let spec = env.build()?.spec();
    let init_state = options.init_state.as_deref().map(|text| parse_state(text, &spec)).transpose()?;
    let actions = read_actions(actions, spec.action_dim())?;
    let default = || PathBuf::from(format!("datasets/{}-replay.mcap", file_stem(&env.canonical())));
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    let settings = ReplaySettings {
        env,
        actions,
        init_state,
        instance_seed: options.instance_seed,
        seed: invocation.seed,
        command_line: invocation.command_line.clone(),
    };
    let images = options.images;
    Ok(Job::new("collect", move |monitor| {
        let mut data = replay(&settings)?;
        if images {
            // How many frames the replay needs is known once it has run.
            check_frames_size(&settings.env, data.steps.len() as f64 + 1.0)?;
            add_pendulum_frames(&mut data, monitor)?;
        }
        write_dataset(&out, &data)?;
        Ok(CollectSummary::Replay { actions: data.steps.len(), env: data.meta.env, out })
    }))
}
