//! The sources `collect` draws from besides random rollouts: replayed actions, embodied board episodes,
//! terrain maps, board sets and ball shots.

use std::path::{Path, PathBuf};

use anyhow::bail;
use mbrl::data::actions_csv::read_actions;
use mbrl::data::ball_io::write_ball_dataset;
use mbrl::data::boardset::{write_board_set, BoardSet};
use mbrl::data::collect::{parse_state, replay, ReplaySettings};
use mbrl::data::collect_ball::{collect_ball, BallCollectSettings};
use mbrl::data::collect_embodied::{
    collect_embodied, parse_manipulator_state, replay_embodied, EmbodiedCollectSettings, EmbodiedReplaySettings,
};
use mbrl::data::collect_frames::{add_pendulum_frames, check_frames_size};
use mbrl::data::terrain_set::{read_terrain_set, write_terrain_set};
use mbrl::data::{write_dataset, Dataset};
use mbrl::envs::ball::Orientation;
use mbrl::envs::boards::depth::{DenseIndex, DepthTable};
use mbrl::envs::boards::sets::board_set;
use mbrl::envs::boards::{GameSpec, LightsOut, Split, TileSwap};
use mbrl::envs::embodiments::Embodiment;
use mbrl::envs::terrain::{TerrainMap, TerrainSplit};
use mbrl::envs::unicycle::UnicycleTerrain;
use mbrl::envs::EnvName;

use crate::common::{check_output_file, command_line, file_stem, run_job, GlobalArgs};

use super::CollectArgs;

pub fn replay_actions(global: &GlobalArgs, env: EnvName, actions: &Path, args: &CollectArgs) -> anyhow::Result<()> {
    let spec = env.build()?.spec();
    let init_state = args.init_state.as_deref().map(|text| parse_state(text, &spec)).transpose()?;
    let actions = read_actions(actions, spec.action_dim())?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("datasets/{}-replay.mcap", file_stem(&env.canonical()))));
    check_output_file("--out", &out, "mcap")?;
    let settings = ReplaySettings {
        env,
        actions,
        init_state,
        instance_seed: args.instance_seed,
        seed: global.seed,
        command_line: command_line(),
    };
    let mut data: Dataset = replay(&settings)?;
    if args.images {
        check_frames_size(&settings.env, data.steps.len() as f64 + 1.0)?;
        add_pendulum_frames(&mut data, &mbrl::run::NullMonitor)?;
    }
    write_dataset(&out, &data)?;
    say!("wrote a replay of {} actions in {} to {}", data.steps.len(), data.meta.env, out.display());
    Ok(())
}

pub fn collect_embodied_episodes(
    global: &GlobalArgs,
    game: GameSpec,
    embodiment: Embodiment,
    args: &CollectArgs,
) -> anyhow::Result<()> {
    let name = EnvName::Embodied(game, embodiment).canonical();
    if args.boards {
        bail!("--boards is for board games alone; for board sets use --env {}", game.name());
    }
    let mode = if args.actions.is_some() { "replay" } else { "random" };
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("datasets/{}-{mode}.mcap", file_stem(&name))));
    check_output_file("--out", &out, "mcap")?;
    let data = match (&args.actions, args.episodes) {
        (Some(actions), _) => {
            let init_state =
                args.init_state.as_deref().map(|text| parse_manipulator_state(text, game, embodiment)).transpose()?;
            let action_dim = mbrl::envs::parse_env(&name)?.build()?.spec().action_dim();
            let settings = EmbodiedReplaySettings {
                game,
                embodiment,
                actions: read_actions(actions, action_dim)?,
                init_state,
                board: args.board.clone(),
                seed: global.seed,
                command_line: command_line(),
            };
            let data = replay_embodied(&settings)?;
            write_dataset(&out, &data)?;
            data
        }
        (None, Some(episodes)) => {
            let settings =
                EmbodiedCollectSettings { game, embodiment, episodes, seed: global.seed, command_line: command_line() };
            run_job(global, "collect", |monitor| {
                let data = collect_embodied(&settings, monitor)?;
                write_dataset(&out, &data)?;
                Ok(data)
            })?
        }
        (None, None) => bail!(
            "'{name}' is recorded as skill episodes: give --episodes N (random actions) or --actions CSV (a replay)"
        ),
    };
    let episodes = data.meta.instances.len();
    say!("wrote {} steps in {episodes} skill episodes of {name} to {}", data.steps.len(), out.display());
    Ok(())
}

/// The maps `--map` / `--maps DIR --split S` name, loaded once for every instance.
pub fn unicycle_terrain(
    map: Option<&Path>,
    maps: Option<&str>,
    split: Option<mbrl::jobs::choices::SplitChoice>,
) -> anyhow::Result<UnicycleTerrain> {
    match (map, maps) {
        (Some(path), _) => {
            if split.is_some() {
                bail!("--split picks maps of a set (--maps DIR); a single --map has no split");
            }
            Ok(UnicycleTerrain::new(vec![TerrainMap::read_png(path)?]))
        }
        (None, Some(dir)) => {
            let Some(split) = split else {
                bail!("--maps {dir}: give --split train or --split test (models train on one half of a map set and are tested on the other)");
            };
            Ok(UnicycleTerrain::new(read_terrain_set(Path::new(dir), Some(TerrainSplit::from(split)))?))
        }
        (None, None) => bail!(mbrl::envs::registry::UNICYCLE_NEEDS_MAPS),
    }
}

pub fn collect_terrain(global: &GlobalArgs, args: &CollectArgs) -> anyhow::Result<()> {
    let Some(count) = &args.maps else {
        bail!("'terrain' makes map sets: give --maps N (e.g. --maps 100: 50 train and 50 test maps)");
    };
    let count: usize = count.parse().map_err(|_| {
        anyhow::anyhow!("--maps: '{count}' is not a count; --env terrain takes the number of maps to make")
    })?;
    if args.map.is_some() || args.split.is_some() || args.actions.is_some() || args.instances.is_some() || args.images {
        bail!("--env terrain takes only --maps N, --out DIR and --seed");
    }
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("datasets/terrain"));
    run_job(global, "collect terrain", |monitor| {
        write_terrain_set(&out, count, global.seed, &command_line(), monitor)
    })?;
    let train = count.div_ceil(2);
    say!("wrote {count} terrain maps ({train} train, {} test) to {}", count - train, out.display());
    Ok(())
}

pub fn collect_boards(global: &GlobalArgs, game: GameSpec, args: &CollectArgs) -> anyhow::Result<()> {
    let max_depth = args.max_depth.unwrap_or(0);
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("datasets/{}-boards-d{max_depth}.mcap", file_stem(&game.name()))));
    check_output_file("--out", &out, "mcap")?;
    let split = args.split.map(Split::from);
    let set = run_job(global, "collect boards", |monitor| {
        let boards = match game {
            GameSpec::LightsOut(n) => records(&LightsOut::new(n)?, max_depth, split, monitor)?,
            GameSpec::TileSwap => records(&TileSwap::new(), max_depth, split, monitor)?,
        };
        let set = BoardSet {
            game: game.name(),
            seed: global.seed,
            command_line: command_line(),
            mbrl_version: mbrl::VERSION.to_string(),
            boards,
        };
        write_board_set(&out, &set)?;
        Ok(set)
    })?;
    let mut per_depth = vec![0usize; max_depth as usize + 1];
    for b in &set.boards {
        per_depth[b.depth as usize] += 1;
    }
    let counts: Vec<String> = (1..=max_depth as usize).map(|d| format!("{d}: {}", per_depth[d])).collect();
    say!("wrote {} boards of {} to {} (per depth {})", set.boards.len(), set.game, out.display(), counts.join(", "));
    Ok(())
}

fn records<G: DenseIndex>(
    game: &G,
    max_depth: u8,
    split: Option<Split>,
    monitor: &dyn mbrl::run::Monitor,
) -> mbrl::Result<Vec<mbrl::envs::boards::sets::BoardRecord>> {
    // Refused before the depth table (seconds of work) is built; the upper bound needs the table.
    if max_depth == 0 {
        return Err(mbrl::Error::config(format!(
            "--max-depth D (at least 1) is needed for board sets of {}",
            game.name()
        )));
    }
    monitor.message(&format!("building the depth table of {}", game.name()));
    let table = DepthTable::build(game)?;
    if max_depth == 0 || max_depth > table.max_depth() {
        return Err(mbrl::Error::config(format!(
            "--max-depth must be between 1 and {} for {}",
            table.max_depth(),
            game.name()
        )));
    }
    Ok(board_set(game, &table, max_depth, split))
}

pub fn collect_ball_shots(global: &GlobalArgs, trajectories: usize, args: &CollectArgs) -> anyhow::Result<()> {
    let orientation = Orientation::parse(&args.orientation)?;
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("datasets/ball-{}.mcap", orientation.name())));
    check_output_file("--out", &out, "mcap")?;
    let settings = BallCollectSettings {
        trajectories,
        orientation,
        augment_rotations: args.augment_rotations,
        seed: global.seed,
        command_line: command_line(),
    };
    let data = run_job(global, "collect ball shots", |monitor| {
        let data = collect_ball(&settings, monitor)?;
        write_ball_dataset(&out, &data)?;
        Ok(data)
    })?;
    let frames: usize = data.recordings.iter().map(|r| r.frames.len()).sum();
    say!(
        "wrote {} ball trajectories ({} shots from the {} pose, {} rotated copies), {frames} frames, to {}",
        data.recordings.len(),
        trajectories,
        orientation.name(),
        data.recordings.len() - trajectories,
        out.display()
    );
    Ok(())
}
