//! `solve-board --model true`: a shortest plan by the game's rules, optionally played by a manipulator's
//! scripted controller.

use super::summary::{Ending, ShownBoard};
use super::{random_board, SolveBoardOptions, SolveBoardSummary};
use crate::envs::boards::depth::DenseIndex;
use crate::envs::embodiments::Embodiment;
use crate::jobs::choices::SearchChoice;
use crate::jobs::{Invocation, Job};
use crate::planning::board_view::layout;
use crate::planning::solve_board::{execute_plan, plan_board, SearchKind};
use crate::util::seeding::rng_for;
use crate::Result;

pub(super) fn prepare<G: DenseIndex>(
    options: SolveBoardOptions,
    game: G,
    invocation: &Invocation,
) -> Result<Job<'static, SolveBoardSummary>> {
    let seed = invocation.seed;
    // A malformed --board is refused before the view opens; a random board is drawn inside the job, so
    // the view is up while the depth table is built.
    let given = options.given_board(&game)?;
    let limits = options.limits();
    let bidirectional = options.search == SearchChoice::Bidirectional;
    let search = if bidirectional { SearchKind::Bidirectional } else { SearchKind::Bfs };
    let embodiment = options.embodiment.map(Embodiment::from);
    if let Some(e) = embodiment {
        e.ensure_buildable()?;
    }
    let title = format!("solve-board: {}", game.name());
    Ok(Job::new(title.clone(), move |monitor| {
        monitor.emit(&layout(&title, game.side(), true));
        let board = match given {
            Some(board) => board,
            None => random_board(&game, options.random_depth.unwrap_or_default(), options.split, seed)?,
        };
        let result = plan_board(&game, board, search, &limits, monitor)?;
        let plan = result.plan.unwrap_or_default();
        let ending = match embodiment {
            Some(e) => {
                let run = execute_plan(&game, board, &plan, e, &mut rng_for(seed, &[1]), monitor)?;
                Ending::Embodied {
                    embodiment: e.name(),
                    performed: run.moves.iter().filter(|m| m.performed.is_some()).count(),
                    control_steps: run.control_steps,
                    final_board: game.render(run.final_board),
                    solved: run.solved,
                }
            }
            None => Ending::Symbolic {
                goal: game.render(game.goal()),
                solved: plan.iter().fold(board, |b, &m| game.apply(b, m)) == game.goal(),
            },
        };
        Ok(SolveBoardSummary::Rules {
            board: ShownBoard { id: game.canonical_string(board), game: game.name(), picture: game.render(board) },
            moves: plan.iter().map(|&m| game.move_name(m)).collect(),
            bidirectional,
            stats: result.stats,
            ending,
        })
    }))
}
