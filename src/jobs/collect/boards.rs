//! Board sets (`--boards --max-depth D`): every board of solution depth 1..=D with its train/test split.

use std::path::PathBuf;

use super::{CollectOptions, CollectSummary};
use crate::data::boardset::{write_board_set, BoardSet};
use crate::envs::boards::depth::{DenseIndex, DepthTable};
use crate::envs::boards::sets::{board_set, BoardRecord};
use crate::envs::boards::{BoardGame, GameSpec, LightsOut, Split, TileSwap};
use crate::jobs::{file_stem, output_file, Invocation, Job};
use crate::run::Monitor;
use crate::{refuse, Result};

pub(super) fn prepare(
    game: GameSpec,
    options: CollectOptions,
    invocation: &Invocation,
) -> Result<Job<'static, CollectSummary>> {
    let max_depth = options.max_depth.unwrap_or(0);
    let default = || PathBuf::from(format!("datasets/{}-boards-d{max_depth}.mcap", file_stem(&game.name())));
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    // Refused before the depth table (seconds of work) is built; the upper bound needs the table.
    let full_name = match game {
        GameSpec::LightsOut(n) => LightsOut::new(n)?.name(),
        GameSpec::TileSwap => TileSwap::new().name(),
    };
    if max_depth == 0 {
        refuse!("--max-depth D (at least 1) is needed for board sets of {full_name}");
    }
    let split = options.split.map(Split::from);
    let (seed, command_line) = (invocation.seed, invocation.command_line.clone());
    Ok(Job::new("collect boards", move |monitor| {
        let boards = match game {
            GameSpec::LightsOut(n) => records(&LightsOut::new(n)?, max_depth, split, monitor)?,
            GameSpec::TileSwap => records(&TileSwap::new(), max_depth, split, monitor)?,
        };
        let set = BoardSet { game: game.name(), seed, command_line, mbrl_version: crate::VERSION.to_string(), boards };
        write_board_set(&out, &set)?;
        let mut per_depth = vec![0usize; max_depth as usize + 1];
        for b in &set.boards {
            per_depth[b.depth as usize] += 1;
        }
        per_depth.remove(0);
        Ok(CollectSummary::Boards { boards: set.boards.len(), game: set.game, out, per_depth })
    }))
}

fn records<G: DenseIndex>(
    game: &G,
    max_depth: u8,
    split: Option<Split>,
    monitor: &dyn Monitor,
) -> Result<Vec<BoardRecord>> {
    monitor.message(&format!("building the depth table of {}", game.name()));
    let table = DepthTable::build(game)?;
    if max_depth > table.max_depth() {
        refuse!("--max-depth must be between 1 and {} for {}", table.max_depth(), game.name());
    }
    Ok(board_set(game, &table, max_depth, split))
}
