//! `solve-board --model DIR`: boards solved by planning over a learned SEADS forward model and executing
//! the planned skills in the embodiment.

use std::path::Path;

use super::summary::ShownBoard;
use super::{random_board, SolveBoardOptions, SolveBoardSummary};
use crate::envs::boards::depth::DenseIndex;
use crate::envs::boards::{GameSpec, LightsOut, TileSwap};
use crate::envs::embodiments::Embodiment;
use crate::jobs::choices::SearchChoice;
use crate::jobs::model_options::{accepting, report_unfinished};
use crate::jobs::{Invocation, Job};
use crate::models::seads::planner::{load as load_seads, solve_with_skills, LoadedSeads};
use crate::planning::board_view::layout;
use crate::util::seeding::rng_for;
use crate::{refuse, Result};

pub(super) fn prepare(options: SolveBoardOptions, invocation: &Invocation) -> Result<Job<'static, SolveBoardSummary>> {
    let dir = Path::new(&options.model);
    if !dir.is_dir() {
        refuse!("--model '{}': expected `true` or a SEADS checkpoint directory", options.model);
    }
    let loaded = load_seads(dir, accepting(options.allow_incomplete))?;
    report_unfinished(dir, &loaded.progress);
    if let Some(game) = &options.game {
        if GameSpec::parse(game)? != loaded.env.game {
            refuse!("--game {game} differs from the checkpoint's game ({}); leave --game out", loaded.env.game.name());
        }
    }
    if let Some(e) = options.embodiment {
        if Embodiment::from(e) != loaded.env.embodiment {
            refuse!(
                "--embodiment differs from the checkpoint's ({}); its skills play with their own embodiment",
                loaded.env.name()
            );
        }
    }
    match loaded.env.game {
        GameSpec::LightsOut(n) => solve(options, LightsOut::new(n)?, loaded, invocation),
        GameSpec::TileSwap => solve(options, TileSwap::new(), loaded, invocation),
    }
}

fn solve<G: DenseIndex>(
    options: SolveBoardOptions,
    game: G,
    loaded: LoadedSeads,
    invocation: &Invocation,
) -> Result<Job<'static, SolveBoardSummary>> {
    let seed = invocation.seed;
    let board = match options.given_board(&game)? {
        Some(board) => board,
        None => random_board(&game, options.random_depth.unwrap_or_default(), options.split, seed)?,
    };
    let limits = options.limits();
    let bidirectional = options.search == SearchChoice::Bidirectional;
    let max_replans = options.max_replans;
    let title = format!("solve-board: {} with learned skills", loaded.env.name());
    Ok(Job::new(title.clone(), move |monitor| {
        monitor.emit(&layout(&title, game.side(), false));
        let mut rng = rng_for(seed, &[1]);
        let outcome = solve_with_skills(&game, &loaded, board, bidirectional, &limits, max_replans, &mut rng, monitor)?;
        let executed = outcome
            .executed
            .iter()
            .map(|e| {
                let performed = e.performed.map(|m| game.move_name(m)).unwrap_or_else(|| "no move".into());
                format!("skill {} → {performed} ({} steps)", e.skill, e.steps)
            })
            .collect();
        Ok(SolveBoardSummary::Learned {
            board: ShownBoard {
                id: game.canonical_string(board),
                game: loaded.env.name(),
                picture: game.render(board),
            },
            plans: outcome.plans,
            executed,
            bidirectional: outcome.bidirectional,
            planning_seconds: outcome.planning_seconds,
            control_steps: outcome.control_steps,
            final_board: game.render(outcome.final_board),
            solved: outcome.solved,
            max_replans,
        })
    }))
}
