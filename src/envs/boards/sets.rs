//! Sets of boards by solution depth and split: what SEADS trains and tests on (thesis Table 7.2).

use rand::seq::IndexedRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::depth::{DenseIndex, DepthTable};
use super::split::{split_of, Split};
use crate::error::{Error, Result};

/// One board of a board set (one MCAP message).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoardRecord {
    /// Canonical comma-separated form (appendix D.1.4).
    pub board: String,
    pub depth: u32,
    pub split: Split,
    /// The symbolic observation (0/1 per entry).
    pub symbolic: Vec<u8>,
}

/// Boards of exactly `depth` moves, optionally restricted to one split, in index order.
pub fn boards_at<G: DenseIndex>(game: &G, table: &DepthTable, depth: u8, split: Option<Split>) -> Vec<G::State> {
    table
        .indices_at(depth)
        .into_iter()
        .map(|i| game.state_at(i))
        .filter(|&s| split.is_none_or(|want| split_of(&game.canonical_string(s)) == want))
        .collect()
}

pub fn record<G: DenseIndex>(game: &G, state: G::State, depth: u8) -> BoardRecord {
    let board = game.canonical_string(state);
    BoardRecord {
        split: split_of(&board),
        board,
        depth: depth as u32,
        symbolic: game.symbolic(state).iter().map(|&b| b as u8).collect(),
    }
}

/// All boards of depth 1..=max_depth (optionally one split), ordered by depth then index.
pub fn board_set<G: DenseIndex>(game: &G, table: &DepthTable, max_depth: u8, split: Option<Split>) -> Vec<BoardRecord> {
    (1..=max_depth)
        .flat_map(|d| boards_at(game, table, d, split).into_iter().map(move |s| (s, d)))
        .map(|(s, d)| record(game, s, d))
        .collect()
}

/// A uniformly drawn board of exactly `depth` moves.
pub fn sample_board<G: DenseIndex>(
    game: &G,
    table: &DepthTable,
    depth: u8,
    split: Option<Split>,
    rng: &mut ChaCha8Rng,
) -> Result<G::State> {
    let candidates = boards_at(game, table, depth, split);
    candidates.choose(rng).copied().ok_or_else(|| {
        Error::config(format!(
            "{} has no boards of depth {depth}{}; depths go up to {}",
            game.name(),
            split.map(|s| format!(" in the {} split", s.as_str())).unwrap_or_default(),
            table.max_depth()
        ))
    })
}
