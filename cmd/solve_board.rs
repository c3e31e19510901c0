//! `mbrl solve-board`: shortest plan for a board by breadth-first search, optionally played by a
//! manipulator.

use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use mbrl::envs::boards::depth::{DenseIndex, DepthTable};
use mbrl::envs::boards::sets::sample_board;
use mbrl::envs::boards::{GameSpec, LightsOut, Split, TileSwap};
use mbrl::envs::embodiments::Embodiment;
use mbrl::planning::bfs::SearchLimits;
use mbrl::planning::solve_board::{execute_plan, layout, plan_board, SearchKind};
use mbrl::util::seeding::rng_for;

use crate::common::{run_job, GlobalArgs, ModelChoice};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SplitChoice {
    Train,
    Test,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SearchChoice {
    /// From both ends (moves undo themselves); far fewer states.
    Bidirectional,
    /// From the start only, as the thesis' planner.
    Bfs,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum EmbodimentChoice {
    /// A point moved by steps of at most 0.2, pushing where it stands (10 steps per move).
    Cursor,
    /// A torque-driven two-link arm over a 0.3 m board (50 steps per move).
    Reacher,
}

impl From<SplitChoice> for Split {
    fn from(choice: SplitChoice) -> Split {
        match choice {
            SplitChoice::Train => Split::Train,
            SplitChoice::Test => Split::Test,
        }
    }
}

impl From<EmbodimentChoice> for Embodiment {
    fn from(choice: EmbodimentChoice) -> Embodiment {
        match choice {
            EmbodimentChoice::Cursor => Embodiment::Cursor,
            EmbodimentChoice::Reacher => Embodiment::Reacher,
        }
    }
}

/// Find a shortest solution of a LightsOut or TileSwap board and optionally play it with a manipulator.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl solve-board --game lightsout --board 0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0 --model true
  mbrl solve-board --game lightsout --random-depth 9 --split test --model true
  mbrl solve-board --game tileswap --board 8,7,6,5,4,3,2,1,0 --model true --search bfs
  mbrl solve-board --game tileswap --random-depth 5 --model true --embodiment reacher

Boards are comma-separated field values, row-major: 0/1 lights for LightsOut (n*n values), the chip
number 0-8 on each field for TileSwap (solved: 0,1,2,...,8).")]
pub struct SolveBoardArgs {
    /// Game: lightsout (5x5), lightsout:<n>x<n> (n = 2..13), tileswap.
    #[arg(long)]
    game: String,
    /// The board to solve.
    #[arg(long, conflicts_with = "random_depth", required_unless_present = "random_depth")]
    board: Option<String>,
    /// Draw a random board whose shortest solution has this many moves (5x5 LightsOut, TileSwap).
    #[arg(long)]
    random_depth: Option<u8>,
    /// Draw the random board from this split only (thesis appendix D.1.4).
    #[arg(long, value_enum, requires = "random_depth")]
    split: Option<SplitChoice>,
    /// Successor model used by the search.
    #[arg(long, value_enum)]
    model: ModelChoice,
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

pub fn run(global: &GlobalArgs, args: SolveBoardArgs) -> anyhow::Result<()> {
    let ModelChoice::True = args.model;
    match GameSpec::parse(&args.game)? {
        GameSpec::LightsOut(n) => solve(global, &args, LightsOut::new(n)?),
        GameSpec::TileSwap => solve(global, &args, TileSwap::new()),
    }
}

fn solve<G: DenseIndex>(global: &GlobalArgs, args: &SolveBoardArgs, game: G) -> anyhow::Result<()> {
    let seed = global.seed;
    let board = match (&args.board, args.random_depth) {
        (Some(text), _) => game.parse(text).with_context(|| format!("--board '{text}'"))?,
        (None, Some(depth)) => {
            let table = DepthTable::build(&game)?;
            sample_board(&game, &table, depth, args.split.map(Split::from), &mut rng_for(seed, &[0]))?
        }
        (None, None) => bail!("give --board or --random-depth"),
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
    let (result, execution) = run_job(global, &title, |monitor| {
        monitor.emit(&layout(&title));
        let result = plan_board(&game, board, search, &limits, monitor)?;
        let plan = result.plan.clone().unwrap_or_default();
        let execution = match embodiment {
            Some(e) => Some(execute_plan(&game, board, &plan, e, &mut rng_for(seed, &[1]), monitor)?),
            None => None,
        };
        Ok((result, execution))
    })?;
    let plan = result.plan.unwrap_or_default();
    println!("board {} ({}):\n{}", game.canonical_string(board), game.name(), game.render(board));
    println!("plan ({} moves): {}", plan.len(), plan.iter().map(|&m| game.move_name(m)).collect::<Vec<_>>().join(", "));
    let s = result.stats;
    println!(
        "search: {:?}, {} states expanded, {} generated, {} stored, {:.1} MiB",
        args.search,
        s.expanded,
        s.generated,
        s.stored,
        s.peak_memory_bytes as f64 / (1u64 << 20) as f64
    );
    let solved_symbolically = plan.iter().fold(board, |b, &m| game.apply(b, m)) == game.goal();
    match execution {
        None => println!(
            "solved board:\n{}\nsolved: {}",
            game.render(game.goal()),
            if solved_symbolically { "yes" } else { "no" }
        ),
        Some(run) => {
            let performed = run.moves.iter().filter(|m| m.performed.is_some()).count();
            println!(
                "embodiment: {} of {} moves performed in {} control steps; final board:\n{}\nsolved: {}",
                performed,
                plan.len(),
                run.control_steps,
                game.render(run.final_board),
                if run.solved { "yes" } else { "no" }
            );
            if !run.solved {
                bail!("the {:?} controller did not reach the goal board", args.embodiment.unwrap());
            }
        }
    }
    Ok(())
}
