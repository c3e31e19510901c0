//! Solving one board: search a shortest plan with a successor model, then optionally play it through a
//! manipulator with its scripted controller.

use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::bfs::{bidirectional, breadth_first, GameRules, SearchLimits, SearchResult, SearchStats};
use super::board_view::{plan_text, search_text, show_boards, EffectorTrace};
use crate::envs::boards::BoardGame;
use crate::envs::embodiments::embodied::{EmbodiedBoard, MoveOutcome};
use crate::envs::embodiments::{BoardLayout, Embodiment};
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::run::{Event, Monitor};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SearchKind {
    /// From the start only, goal tested when generated (thesis Alg. 3).
    Bfs,
    /// From both ends; needs self-inverse moves.
    Bidirectional,
}

/// Shortest plan from `board` to the goal with the game's true rules. Unsolvable boards and plans
/// beyond the depth limit are errors with an explanation.
pub fn plan_board<G: BoardGame>(
    game: &G,
    board: G::State,
    search: SearchKind,
    limits: &SearchLimits,
    monitor: &dyn Monitor,
) -> Result<SearchResult> {
    if !game.is_solvable(board) {
        return Err(Error::data(format!(
            "board {} of {} cannot be solved: no sequence of moves reaches the goal (on 5x5 LightsOut only a quarter of all boards can)",
            game.canonical_string(board),
            game.name()
        )));
    }
    show_boards(monitor, game, board, None);
    let model = GameRules(game);
    // The depth counter stalls on the deep layers where the work is; stored states against the
    // --max-nodes budget move with the work and show how near the search is to giving up.
    let phase = "search: states stored of --max-nodes";
    let on_layer = |s: &SearchStats| {
        monitor.scalar("bfs/stored", s.depth as u64, s.stored as f64);
        monitor.scalar("bfs/expanded", s.depth as u64, s.expanded as f64);
        monitor.progress(phase, s.stored, limits.max_nodes as u64);
        monitor.emit(&Event::text("search", search_text(s)));
    };
    let result = match search {
        SearchKind::Bfs => breadth_first(&model, board, |s| *s == game.goal(), limits, on_layer)?,
        SearchKind::Bidirectional => bidirectional(&model, board, game.goal(), limits, on_layer)?,
    };
    // Done: the gauge fills instead of reporting an ETA for a budget the search no longer spends.
    monitor.progress(phase, result.stats.stored, result.stats.stored);
    monitor.emit(&Event::text("search", search_text(&result.stats)));
    let plan = result.plan.as_ref().ok_or_else(|| {
        let depth = limits.max_depth as f64;
        Error::budget(
            "--max-depth",
            depth + 1.0,
            depth,
            format!("no plan of at most {} moves exists; raise --max-depth", limits.max_depth),
        )
    })?;
    monitor.emit(&Event::text("plan", plan_text(&move_names(game, plan), 0, false)));
    let after = plan.iter().fold(board, |b, &m| game.apply(b, m));
    show_boards(monitor, game, board, Some(("after plan", after)));
    Ok(result)
}

#[derive(Clone, Debug)]
pub struct Execution<S> {
    pub moves: Vec<MoveOutcome>,
    pub final_board: S,
    pub solved: bool,
    pub control_steps: usize,
}

/// Plays `plan` through the embodiment's scripted controller. Stops at the first move the controller
/// fails to perform (step limit reached, or a different move happened).
pub fn execute_plan<G: BoardGame>(
    game: &G,
    board: G::State,
    plan: &[usize],
    embodiment: Embodiment,
    rng: &mut ChaCha8Rng,
    monitor: &dyn Monitor,
) -> Result<Execution<G::State>> {
    let (manipulator, mut controller) = embodiment.build(&BoardLayout::of(game))?;
    let mut env = EmbodiedBoard::new(game.clone(), manipulator, board);
    env.reset(rng);
    let mut moves = Vec::with_capacity(plan.len());
    let names = move_names(game, plan);
    let mut trace = EffectorTrace::default();
    for (i, &mv) in plan.iter().enumerate() {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        monitor.emit(&Event::text("plan", plan_text(&names, i, true)));
        let outcome = env.execute_observed(controller.as_mut(), mv, |_, p| trace.record(monitor, p));
        monitor.progress("execute moves", i as u64 + 1, plan.len() as u64);
        let caption = format!("after {}/{}", i + 1, plan.len());
        show_boards(monitor, game, board, Some((&caption, env.board())));
        let ok = outcome.performed == Some(mv);
        moves.push(outcome);
        if !ok {
            break;
        }
    }
    let played = moves.iter().zip(plan).take_while(|(m, &mv)| m.performed == Some(mv)).count();
    monitor.emit(&Event::text("plan", plan_text(&names, played, false)));
    let final_board = env.board();
    let control_steps = moves.iter().map(|m| m.steps).sum();
    Ok(Execution { solved: final_board == game.goal(), moves, final_board, control_steps })
}

fn move_names<G: BoardGame>(game: &G, plan: &[usize]) -> Vec<String> {
    plan.iter().map(|&m| game.move_name(m)).collect()
}
