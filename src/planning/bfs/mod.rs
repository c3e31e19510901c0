//! Breadth-first search over symbolic states with a pluggable successor model (thesis Alg. 3). The
//! model is queried a batch of states at a time for every action, as a learned forward model would be;
//! nothing here assumes the rules of a game.

mod bidirectional;
mod nodes;
mod unidirectional;

use std::hash::Hash;

pub use bidirectional::bidirectional;
pub use unidirectional::breadth_first;

use crate::envs::boards::BoardGame;
use crate::error::{Error, Result};

/// States handed to the model per call (the original code evaluates batches of 1024).
pub const BATCH: usize = 1024;

pub trait SuccessorModel: Sync {
    type State: Copy + Eq + Hash + Send + Sync;

    fn num_actions(&self) -> usize;

    /// Appends the successor of every state under every action: `out[i * K + k]` for state i, action k.
    fn expand(&self, states: &[Self::State], out: &mut Vec<Self::State>);

    /// Whether every action undoes itself, which lets the search run from both ends.
    fn self_inverse(&self) -> bool {
        false
    }
}

/// The true rules of a board game as a successor model.
pub struct GameRules<'a, G: BoardGame>(pub &'a G);

impl<G: BoardGame> SuccessorModel for GameRules<'_, G> {
    type State = G::State;

    fn num_actions(&self) -> usize {
        self.0.num_moves()
    }

    fn expand(&self, states: &[G::State], out: &mut Vec<G::State>) {
        let k = self.0.num_moves();
        out.reserve(states.len() * k);
        for &s in states {
            out.extend((0..k).map(|mv| self.0.apply(s, mv)));
        }
    }

    /// Every LightsOut push and TileSwap swap undoes itself.
    fn self_inverse(&self) -> bool {
        true
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchLimits {
    /// Longest plan searched for.
    pub max_depth: usize,
    /// Stored nodes after which the search gives up.
    pub max_nodes: usize,
    /// Estimated bytes of search memory after which the search gives up (instead of swapping).
    pub max_memory_bytes: usize,
}

impl Default for SearchLimits {
    fn default() -> Self {
        SearchLimits { max_depth: 20, max_nodes: 50_000_000, max_memory_bytes: 4 << 30 }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SearchStats {
    /// States whose successors were requested from the model.
    pub expanded: u64,
    /// Successors the model returned.
    pub generated: u64,
    /// Distinct states stored.
    pub stored: u64,
    pub peak_memory_bytes: usize,
    /// Deepest layer completed (sum of both sides for bidirectional search).
    pub depth: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SearchResult {
    /// Shortest action sequence to the goal; `None` when no plan exists within `max_depth`.
    pub plan: Option<Vec<usize>>,
    pub stats: SearchStats,
}

fn budget_error(stats: &SearchStats, limits: &SearchLimits) -> Option<Error> {
    if stats.stored as usize > limits.max_nodes {
        let message = format!(
            "search stopped at depth {} after storing {} states, over the node budget of {}; raise --max-nodes",
            stats.depth, stats.stored, limits.max_nodes
        );
        return Some(Error::budget("--max-nodes", stats.stored as f64, limits.max_nodes as f64, message));
    }
    if stats.peak_memory_bytes > limits.max_memory_bytes {
        let message = format!(
            "search stopped at depth {} using about {} MiB, over the memory budget of {} MiB; raise --max-memory-mib",
            stats.depth,
            stats.peak_memory_bytes >> 20,
            limits.max_memory_bytes >> 20
        );
        let (need, limit) = (stats.peak_memory_bytes as f64, limits.max_memory_bytes as f64);
        return Some(Error::budget("--max-memory-mib", need, limit, message));
    }
    None
}

pub(crate) fn check_budget(stats: &SearchStats, limits: &SearchLimits) -> Result<()> {
    budget_error(stats, limits).map_or(Ok(()), Err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::boards::{gf2, LightsOut, TileSwap};
    use rand::{Rng, SeedableRng};

    fn apply_plan<G: BoardGame>(game: &G, mut s: G::State, plan: &[usize]) -> G::State {
        for &mv in plan {
            s = game.apply(s, mv);
        }
        s
    }

    #[test]
    fn both_searches_find_optimal_lightsout_plans() {
        let game = LightsOut::new(5).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for depth in 1..=6 {
            let mut presses: Vec<usize> = Vec::new();
            while presses.len() < depth {
                let p = rng.random_range(0..25);
                if !presses.contains(&p) {
                    presses.push(p);
                }
            }
            let board = game.pressed(&presses);
            let optimal = gf2::solve(&game, board).unwrap().len();
            let goal = game.goal();
            let uni =
                breadth_first(&GameRules(&game), board, |s| *s == goal, &SearchLimits::default(), |_| {}).unwrap();
            let bi = bidirectional(&GameRules(&game), board, goal, &SearchLimits::default(), |_| {}).unwrap();
            for result in [&uni, &bi] {
                let plan = result.plan.as_ref().unwrap();
                assert_eq!(plan.len(), optimal, "depth {depth}");
                assert_eq!(apply_plan(&game, board, plan), goal);
            }
            assert!(bi.stats.expanded <= uni.stats.expanded);
        }
    }

    #[test]
    fn tileswap_plans_are_optimal_and_valid() {
        let game = TileSwap::new();
        let board = game.parse("8,7,6,5,4,3,2,1,0").unwrap();
        let goal = game.goal();
        let uni = breadth_first(&GameRules(&game), board, |s| *s == goal, &SearchLimits::default(), |_| {}).unwrap();
        let bi = bidirectional(&GameRules(&game), board, goal, &SearchLimits::default(), |_| {}).unwrap();
        assert_eq!(uni.plan.as_ref().unwrap().len(), bi.plan.as_ref().unwrap().len());
        assert_eq!(apply_plan(&game, board, bi.plan.as_ref().unwrap()), goal);
    }

    #[test]
    fn solved_start_needs_no_moves_and_depth_limit_is_respected() {
        let game = LightsOut::new(5).unwrap();
        let goal = game.goal();
        let r = bidirectional(&GameRules(&game), goal, goal, &SearchLimits::default(), |_| {}).unwrap();
        assert_eq!(r.plan, Some(vec![]));
        let board = game.pressed(&[0, 5, 10, 15]);
        let limits = SearchLimits { max_depth: 3, ..SearchLimits::default() };
        assert_eq!(breadth_first(&GameRules(&game), board, |s| *s == goal, &limits, |_| {}).unwrap().plan, None);
        assert_eq!(bidirectional(&GameRules(&game), board, goal, &limits, |_| {}).unwrap().plan, None);
    }

    #[test]
    fn budgets_abort_with_a_clear_message() {
        let game = LightsOut::new(5).unwrap();
        let goal = game.goal();
        let board = game.pressed(&[0, 3, 7, 11, 14, 18, 22]);
        let limits = SearchLimits { max_nodes: 1000, ..SearchLimits::default() };
        let err = breadth_first(&GameRules(&game), board, |s| *s == goal, &limits, |_| {}).unwrap_err().to_string();
        assert!(err.contains("node budget of 1000"), "{err}");
        let limits = SearchLimits { max_memory_bytes: 1 << 16, ..SearchLimits::default() };
        let err = bidirectional(&GameRules(&game), board, goal, &limits, |_| {}).unwrap_err().to_string();
        assert!(err.contains("memory budget"), "{err}");
    }
}
