//! Board games played by a manipulator (`<game>:cursor|reacher`), recorded as skill episodes: random ones
//! from scrambled boards, or a replay of recorded actions.

use std::path::PathBuf;

use super::{CollectOptions, CollectSummary, Collection};
use crate::data::actions_csv::read_actions;
use crate::data::collect_embodied::{
    collect_embodied, parse_manipulator_state, replay_embodied, EmbodiedCollectSettings, EmbodiedReplaySettings,
};
use crate::data::write_dataset;
use crate::envs::boards::GameSpec;
use crate::envs::embodiments::Embodiment;
use crate::envs::EnvName;
use crate::jobs::{file_stem, output_file, Invocation, Job};
use crate::{refuse, Result};

pub(super) fn prepare(
    game: GameSpec,
    embodiment: Embodiment,
    options: CollectOptions,
    invocation: &Invocation,
) -> Result<Collection> {
    let name = EnvName::Embodied(game, embodiment).canonical();
    if options.boards {
        refuse!("--boards is for board games alone; for board sets use --env {}", game.name());
    }
    let mode = if options.actions.is_some() { "replay" } else { "random" };
    let default = || PathBuf::from(format!("datasets/{}-{mode}.mcap", file_stem(&name)));
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    let (seed, command_line) = (invocation.seed, invocation.command_line.clone());
    match (&options.actions, options.episodes) {
        (Some(actions), _) => {
            let init_state = options
                .init_state
                .as_deref()
                .map(|text| parse_manipulator_state(text, game, embodiment))
                .transpose()?;
            let action_dim = crate::envs::parse_env(&name)?.build()?.spec().action_dim();
            let settings = EmbodiedReplaySettings {
                game,
                embodiment,
                actions: read_actions(actions, action_dim)?,
                init_state,
                board: options.board,
                seed,
                command_line,
            };
            Ok(Collection::Now(Job::new("collect", move |_| {
                let data = replay_embodied(&settings)?;
                write_dataset(&out, &data)?;
                Ok(CollectSummary::Episodes {
                    steps: data.steps.len(),
                    episodes: data.meta.instances.len(),
                    env: name,
                    out,
                })
            })))
        }
        (None, Some(episodes)) => {
            let settings = EmbodiedCollectSettings { game, embodiment, episodes, seed, command_line };
            Ok(Collection::Viewed(Job::new("collect", move |monitor| {
                let data = collect_embodied(&settings, monitor)?;
                write_dataset(&out, &data)?;
                Ok(CollectSummary::Episodes {
                    steps: data.steps.len(),
                    episodes: data.meta.instances.len(),
                    env: name,
                    out,
                })
            })))
        }
        (None, None) => refuse!(
            "'{name}' is recorded as skill episodes: give --episodes N (random actions) or --actions CSV (a replay)"
        ),
    }
}
