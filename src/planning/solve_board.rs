//! Solving one board: search a shortest plan with a successor model, then optionally play it through a
//! manipulator with its scripted controller.

use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::bfs::{bidirectional, breadth_first, GameRules, SearchLimits, SearchResult, SearchStats};
use crate::envs::boards::BoardGame;
use crate::envs::embodiments::embodied::{EmbodiedBoard, MoveOutcome};
use crate::envs::embodiments::Embodiment;
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::run::{Event, Monitor, PanelSpec};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SearchKind {
    /// From the start only, goal tested when generated (thesis Alg. 3).
    Bfs,
    /// From both ends; needs self-inverse moves.
    Bidirectional,
}

pub fn layout(title: &str) -> Event {
    Event::Layout {
        title: title.to_string(),
        panels: vec![
            PanelSpec {
                title: "search (states stored per depth)".into(),
                x_label: "depth".into(),
                series: vec!["bfs/stored".into(), "bfs/expanded".into()],
                restart_on_rewind: true,
            },
            PanelSpec {
                title: "effector (current move)".into(),
                x_label: "step".into(),
                series: vec!["effector/x".into(), "effector/y".into()],
                restart_on_rewind: true,
            },
        ],
    }
}

fn stats_text(stats: &SearchStats) -> String {
    format!(
        "depth {}\nexpanded {}\ngenerated {}\nstored {}\nmemory {:.1} MiB",
        stats.depth,
        stats.expanded,
        stats.generated,
        stats.stored,
        stats.peak_memory_bytes as f64 / (1u64 << 20) as f64
    )
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
    monitor.emit(&Event::text("board", game.render(board)));
    let model = GameRules(game);
    let on_layer = |s: &SearchStats| {
        monitor.scalar("bfs/stored", s.depth as u64, s.stored as f64);
        monitor.scalar("bfs/expanded", s.depth as u64, s.expanded as f64);
        // The depth counter stalls on the deep layers where the work is; stored states against the
        // --max-nodes budget move with the work and show how near the search is to giving up.
        monitor.progress("search: states stored of --max-nodes", s.stored, limits.max_nodes as u64);
        monitor.emit(&Event::text("search", stats_text(s)));
    };
    let result = match search {
        SearchKind::Bfs => breadth_first(&model, board, |s| *s == game.goal(), limits, on_layer)?,
        SearchKind::Bidirectional => bidirectional(&model, board, game.goal(), limits, on_layer)?,
    };
    monitor.emit(&Event::text("search", stats_text(&result.stats)));
    let plan = result.plan.as_ref().ok_or_else(|| {
        Error::Budget(format!("no plan of at most {} moves exists; raise --max-depth", limits.max_depth))
    })?;
    let names: Vec<String> = plan.iter().map(|&m| game.move_name(m)).collect();
    monitor.emit(&Event::text("plan", format!("{} moves\n{}", plan.len(), names.join("\n"))));
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
    let (manipulator, mut controller) = embodiment.build();
    let mut env = EmbodiedBoard::new(game.clone(), manipulator, board);
    env.reset(rng);
    let mut moves = Vec::with_capacity(plan.len());
    for (i, &mv) in plan.iter().enumerate() {
        if monitor.is_cancelled() {
            return Err(Error::Cancelled);
        }
        let outcome = env.execute_observed(controller.as_mut(), mv, |step, p| {
            monitor.scalar("effector/x", step as u64, p[0]);
            monitor.scalar("effector/y", step as u64, p[1]);
        });
        monitor.progress("execute moves", i as u64 + 1, plan.len() as u64);
        monitor.emit(&Event::text("board", game.render(env.board())));
        let ok = outcome.performed == Some(mv);
        moves.push(outcome);
        if !ok {
            break;
        }
    }
    let final_board = env.board();
    let control_steps = moves.iter().map(|m| m.steps).sum();
    Ok(Execution { solved: final_board == game.goal(), moves, final_board, control_steps })
}
