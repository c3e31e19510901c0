//! `solve-board --model DIR`: boards solved by planning over a learned SEADS forward model and executing
//! the planned skills in the embodiment.

use anyhow::bail;
use mbrl::envs::boards::depth::DenseIndex;
use mbrl::envs::boards::{GameSpec, LightsOut, TileSwap};
use mbrl::envs::embodiments::Embodiment;
use mbrl::models::seads::planner::{load as load_seads, solve_with_skills, LoadedSeads};
use mbrl::planning::board_view::layout;
use mbrl::util::seeding::rng_for;

use super::{board_of, limits_of, SearchChoice, SolveBoardArgs};
use crate::common::{run_job, GlobalArgs};
use mbrl::jobs::model_options::{accepting, report_unfinished};

pub fn run_learned(global: &GlobalArgs, args: &SolveBoardArgs) -> anyhow::Result<()> {
    let dir = std::path::Path::new(&args.model);
    if !dir.is_dir() {
        bail!("--model '{}': expected `true` or a SEADS checkpoint directory", args.model);
    }
    let loaded = load_seads(dir, accepting(args.allow_incomplete))?;
    report_unfinished(dir, &loaded.progress);
    if let Some(game) = &args.game {
        if GameSpec::parse(game)? != loaded.env.game {
            bail!("--game {game} differs from the checkpoint's game ({}); leave --game out", loaded.env.game.name());
        }
    }
    if let Some(e) = args.embodiment {
        if Embodiment::from(e) != loaded.env.embodiment {
            bail!(
                "--embodiment differs from the checkpoint's ({}); its skills play with their own embodiment",
                loaded.env.name()
            );
        }
    }
    match loaded.env.game {
        GameSpec::LightsOut(n) => solve_learned(global, args, LightsOut::new(n)?, &loaded),
        GameSpec::TileSwap => solve_learned(global, args, TileSwap::new(), &loaded),
    }
}

fn solve_learned<G: DenseIndex>(
    global: &GlobalArgs,
    args: &SolveBoardArgs,
    game: G,
    loaded: &LoadedSeads,
) -> anyhow::Result<()> {
    let board = board_of(args, &game, global.seed)?;
    let limits = limits_of(args);
    let bidirectional = args.search == SearchChoice::Bidirectional;
    let title = format!("solve-board: {} with learned skills", loaded.env.name());
    let outcome = run_job(global, &title, |monitor| {
        monitor.emit(&layout(&title, game.side(), false));
        solve_with_skills(
            &game,
            loaded,
            board,
            bidirectional,
            &limits,
            args.max_replans,
            &mut rng_for(global.seed, &[1]),
            monitor,
        )
    })?;
    say!("board {} ({}):\n{}", game.canonical_string(board), loaded.env.name(), game.render(board));
    for (i, plan) in outcome.plans.iter().enumerate() {
        let skills: Vec<String> = plan.iter().map(|k| k.to_string()).collect();
        say!("plan {} ({} skills): {}", i + 1, plan.len(), skills.join(", "));
    }
    let moves: Vec<String> = outcome
        .executed
        .iter()
        .map(|e| {
            let performed = e.performed.map(|m| game.move_name(m)).unwrap_or_else(|| "no move".into());
            format!("skill {} → {performed} ({} steps)", e.skill, e.steps)
        })
        .collect();
    say!("executed: {}", moves.join(", "));
    say!(
        "search: {}, planning {:.3} s; {} replans; {} control steps; final board:\n{}\nsolved: {}",
        if outcome.bidirectional { "bidirectional (model verified self-inverse)" } else { "breadth-first" },
        outcome.planning_seconds,
        outcome.plans.len().saturating_sub(1),
        outcome.control_steps,
        game.render(outcome.final_board),
        if outcome.solved { "yes" } else { "no" }
    );
    if !outcome.solved {
        bail!("the learned skills did not reach the goal board within {} replans", args.max_replans);
    }
    Ok(())
}
