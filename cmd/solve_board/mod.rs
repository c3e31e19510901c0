//! `mbrl solve-board`: shortest plan for a board by breadth-first search, optionally played by a
//! manipulator.

use anyhow::{bail, Context};
use clap::Args;
use mbrl::envs::boards::depth::{DenseIndex, DepthTable};
use mbrl::envs::boards::sets::sample_board;
use mbrl::envs::boards::{GameSpec, LightsOut, Split, TileSwap};
use mbrl::envs::embodiments::Embodiment;
use mbrl::planning::bfs::SearchLimits;
use mbrl::planning::board_view::layout;
use mbrl::planning::solve_board::{execute_plan, plan_board, SearchKind};
use mbrl::util::seeding::rng_for;

use crate::common::{run_job, GlobalArgs};
pub use mbrl::jobs::choices::{EmbodimentChoice, SearchChoice, SplitChoice};

/// Find a shortest solution of a LightsOut or TileSwap board and optionally play it with a manipulator.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl solve-board --game lightsout --board 0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0 --model true
  mbrl solve-board --game lightsout --random-depth 9 --split test --model true
  mbrl solve-board --game tileswap --board 8,7,6,5,4,3,2,1,0 --model true --search bfs
  mbrl solve-board --game tileswap --random-depth 5 --model true --embodiment reacher
  mbrl solve-board --model models/seads-tileswap-cursor --random-depth 3 --split test

With a SEADS checkpoint as --model, the game and embodiment are the checkpoint's: its forward model plans
(bidirectional search where the model proves self-inverse on every state it expands, else one-sided) and
its skill policies play the plan, replanning when the board differs from the prediction.

Boards are comma-separated field values, row-major: 0/1 lights for LightsOut (n*n values), the chip
number 0-8 on each field for TileSwap (solved: 0,1,2,...,8).")]
pub struct SolveBoardArgs {
    /// Game: lightsout (5x5), lightsout:<n>x<n> (n = 2..13), tileswap (default with a SEADS --model: its game).
    #[arg(long)]
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

mod learned;

use learned::run_learned;

pub fn run(global: &GlobalArgs, args: SolveBoardArgs) -> anyhow::Result<()> {
    if args.model != "true" {
        return run_learned(global, &args);
    }
    if args.allow_incomplete {
        bail!("--allow-incomplete takes a SEADS checkpoint as --model; `--model true` plans with the game's rules");
    }
    let game = args.game.as_deref().context("--game is required with --model true")?;
    match GameSpec::parse(game)? {
        GameSpec::LightsOut(n) => solve(global, &args, LightsOut::new(n)?),
        GameSpec::TileSwap => solve(global, &args, TileSwap::new()),
    }
}

pub(super) fn limits_of(args: &SolveBoardArgs) -> SearchLimits {
    SearchLimits { max_depth: args.max_depth, max_nodes: args.max_nodes, max_memory_bytes: args.max_memory_mib << 20 }
}

pub(super) fn board_of<G: DenseIndex>(args: &SolveBoardArgs, game: &G, seed: u64) -> anyhow::Result<G::State> {
    Ok(match (&args.board, args.random_depth) {
        (Some(text), _) => game.parse(text).with_context(|| format!("--board '{text}'"))?,
        (None, Some(depth)) => {
            let table = DepthTable::build(game)?;
            sample_board(game, &table, depth, args.split.map(Split::from), &mut rng_for(seed, &[0]))?
        }
        (None, None) => bail!("give --board or --random-depth"),
    })
}

fn solve<G: DenseIndex>(global: &GlobalArgs, args: &SolveBoardArgs, game: G) -> anyhow::Result<()> {
    let seed = global.seed;
    // A malformed --board is refused before the view opens; a random board is drawn inside the job, so
    // the view is up while the depth table is built.
    let given = match &args.board {
        Some(text) => Some(game.parse(text).with_context(|| format!("--board '{text}'"))?),
        None if args.random_depth.is_none() => bail!("give --board or --random-depth"),
        None => None,
    };
    let limits = SearchLimits {
        max_depth: args.max_depth,
        max_nodes: args.max_nodes,
        max_memory_bytes: args.max_memory_mib << 20,
    };
    let search = match args.search {
        SearchChoice::Bidirectional => SearchKind::Bidirectional,
        SearchChoice::Bfs => SearchKind::Bfs,
    };
    let embodiment = args.embodiment.map(Embodiment::from);
    let title = format!("solve-board: {}", game.name());
    let (board, result, execution) = run_job(global, &title, |monitor| {
        monitor.emit(&layout(&title, game.side(), true));
        let board = match (given, args.random_depth) {
            (Some(board), _) => board,
            (None, depth) => {
                let depth = depth.unwrap_or_default();
                let table = DepthTable::build(&game)?;
                sample_board(&game, &table, depth, args.split.map(Split::from), &mut rng_for(seed, &[0]))?
            }
        };
        let result = plan_board(&game, board, search, &limits, monitor)?;
        let plan = result.plan.clone().unwrap_or_default();
        let execution = match embodiment {
            Some(e) => Some(execute_plan(&game, board, &plan, e, &mut rng_for(seed, &[1]), monitor)?),
            None => None,
        };
        Ok((board, result, execution))
    })?;
    let plan = result.plan.unwrap_or_default();
    say!("board {} ({}):\n{}", game.canonical_string(board), game.name(), game.render(board));
    say!(
        "plan ({} move{}): {}",
        plan.len(),
        if plan.len() == 1 { "" } else { "s" },
        plan.iter().map(|&m| game.move_name(m)).collect::<Vec<_>>().join(", ")
    );
    let s = result.stats;
    say!(
        "search: {}, {} states expanded, {} generated, {} stored, {:.1} MiB",
        match args.search {
            SearchChoice::Bidirectional => "bidirectional BFS",
            SearchChoice::Bfs => "one-sided BFS",
        },
        s.expanded,
        s.generated,
        s.stored,
        s.peak_memory_bytes as f64 / (1u64 << 20) as f64
    );
    let solved_symbolically = plan.iter().fold(board, |b, &m| game.apply(b, m)) == game.goal();
    match execution {
        None => say!(
            "solved board:\n{}\nsolved: {}",
            game.render(game.goal()),
            if solved_symbolically { "yes" } else { "no" }
        ),
        Some(run) => {
            let performed = run.moves.iter().filter(|m| m.performed.is_some()).count();
            say!(
                "embodiment: {} of {} moves performed in {} control steps; final board:\n{}\nsolved: {}",
                performed,
                plan.len(),
                run.control_steps,
                game.render(run.final_board),
                if run.solved { "yes" } else { "no" }
            );
            if !run.solved {
                bail!(
                    "the {} controller did not reach the goal board",
                    embodiment.map_or("scripted", Embodiment::name)
                );
            }
        }
    }
    Ok(())
}
