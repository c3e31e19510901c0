//! `mbrl solve-board`: shortest plan for a board by breadth-first search, optionally played by a
//! manipulator.

mod learned;
mod rules;
mod summary;

use clap::Args;

use super::choices::{EmbodimentChoice, SearchChoice, SplitChoice};
use super::{Invocation, Job};
use crate::envs::boards::depth::{DenseIndex, DepthTable};
use crate::envs::boards::sets::sample_board;
use crate::envs::boards::{GameSpec, LightsOut, Split, TileSwap};
use crate::planning::bfs::SearchLimits;
use crate::util::seeding::rng_for;
use crate::{refuse, Error, Result};

pub use summary::{Ending, ShownBoard, SolveBoardSummary};

/// Find a shortest solution of a LightsOut or TileSwap board and optionally play it with a manipulator.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl solve-board --game lightsout --board 0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0 --model true
  mbrl solve-board --game lightsout --random-depth 9 --split test --model true
  mbrl solve-board --game tileswap --board 8,7,6,5,4,3,2,1,0 --model true --search bfs
  mbrl solve-board --game tileswap --random-depth 5 --model true --embodiment reacher
  mbrl solve-board --model models/seads-tileswap-cursor --random-depth 3 --split test

With a SEADS checkpoint as --model, the game and embodiment are the checkpoint's: its forward model plans (bidirectional search where the model proves self-inverse on every state it expands, else one-sided) and its skill policies play the plan, replanning when the board differs from the prediction.

Boards are comma-separated field values, row-major: 0/1 lights for LightsOut (n*n values), the chip number 0-8 on each field for TileSwap (solved: 0,1,2,...,8).")]
pub struct SolveBoardOptions {
    /// Game: lightsout (5x5), lightsout:<n>x<n> (n = 2..13), tileswap (default with a SEADS --model: its game).
    #[arg(long, value_parser = crate::jobs::names::games(), hide_possible_values = true)]
    game: Option<String>,
    /// The board to solve.
    #[arg(long, conflicts_with = "random_depth", required_unless_present = "random_depth")]
    board: Option<String>,
    /// Draw a random board whose shortest solution has this many moves (5x5 LightsOut, TileSwap).
    #[arg(long)]
    random_depth: Option<u8>,
    /// Draw the random board from this split only (thesis appendix D.1.4).
    #[arg(long, value_enum, requires = "random_depth")]
    split: Option<SplitChoice>,
    /// Successor model: `true` (the game's rules) or a SEADS checkpoint directory (its learned forward model
    /// and skill policies).
    #[arg(long)]
    model: String,
    /// Replans allowed when a skill's outcome differs from the model's prediction (SEADS --model).
    #[arg(long, default_value_t = 10)]
    max_replans: usize,
    /// Take a SEADS run still in training (the weights of its last checkpoint); a warning says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Play the plan with this manipulator's scripted controller.
    #[arg(long, value_enum)]
    embodiment: Option<EmbodimentChoice>,
    /// Search algorithm.
    #[arg(long, value_enum, default_value_t = SearchChoice::Bidirectional)]
    search: SearchChoice,
    /// Longest plan searched for.
    #[arg(long, default_value_t = 20)]
    max_depth: usize,
    /// Give up after storing this many states.
    #[arg(long, default_value_t = 50_000_000)]
    max_nodes: usize,
    /// Give up when the search needs more memory than this (MiB).
    #[arg(long, default_value_t = 4096)]
    max_memory_mib: usize,
}

pub fn prepare(options: SolveBoardOptions, invocation: &Invocation) -> Result<Job<'static, SolveBoardSummary>> {
    if options.model != "true" {
        return learned::prepare(options, invocation);
    }
    if options.allow_incomplete {
        refuse!("--allow-incomplete takes a SEADS checkpoint as --model; `--model true` plans with the game's rules");
    }
    let Some(game) = options.game.as_deref() else {
        refuse!("--game is required with --model true");
    };
    match GameSpec::parse(game)? {
        GameSpec::LightsOut(n) => rules::prepare(options, LightsOut::new(n)?, invocation),
        GameSpec::TileSwap => rules::prepare(options, TileSwap::new(), invocation),
    }
}

impl SolveBoardOptions {
    fn limits(&self) -> SearchLimits {
        SearchLimits {
            max_depth: self.max_depth,
            max_nodes: self.max_nodes,
            max_memory_bytes: self.max_memory_mib << 20,
        }
    }

    /// The --board given, checked against the game's rules.
    fn given_board<G: DenseIndex>(&self, game: &G) -> Result<Option<G::State>> {
        match &self.board {
            Some(text) => Ok(Some(game.parse(text).map_err(|e| e.field(format!("--board '{text}'")))?)),
            None if self.random_depth.is_none() => Err(Error::config("give --board or --random-depth")),
            None => Ok(None),
        }
    }
}

/// A board --random-depth moves from the goal, drawn from --split when given.
fn random_board<G: DenseIndex>(game: &G, depth: u8, split: Option<SplitChoice>, seed: u64) -> Result<G::State> {
    let table = DepthTable::build(game)?;
    sample_board(game, &table, depth, split.map(Split::from), &mut rng_for(seed, &[0]))
}
