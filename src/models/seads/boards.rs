//! The boards SEADS episodes start from: a solution depth uniform in 1..=D, then a uniform board of that depth
//! from one split (the authors' board loader with `random_solution_depth`). The layers come from a breadth-first
//! search from the goal, which for depth ≤ 5 touches 68k LightsOut boards instead of the 2²⁵ of a full depth table.

use std::collections::HashSet;

use rand::seq::IndexedRandom;
use rand::Rng;

use crate::envs::boards::split::{split_of, Split};
use crate::envs::boards::BoardGame;
use crate::error::{Error, Result};

/// Boards by exact solution depth (index 0 = depth 1), restricted to one split.
pub struct BoardPool<G: BoardGame> {
    layers: Vec<Vec<G::State>>,
}

impl<G: BoardGame> BoardPool<G> {
    pub fn new(game: &G, max_depth: u8, split: Split) -> Result<Self> {
        let goal = game.goal();
        let mut seen: HashSet<G::State> = HashSet::from([goal]);
        let mut frontier = vec![goal];
        let mut layers = Vec::with_capacity(max_depth as usize);
        for depth in 1..=max_depth {
            let mut next = Vec::new();
            for &board in &frontier {
                for mv in 0..game.num_moves() {
                    let successor = game.apply(board, mv);
                    if seen.insert(successor) {
                        next.push(successor);
                    }
                }
            }
            let in_split: Vec<G::State> =
                next.iter().copied().filter(|&b| split_of(&game.canonical_string(b)) == split).collect();
            if in_split.is_empty() {
                return Err(Error::config(format!(
                    "{} has no {} boards of solution depth {depth}; lower the maximum board depth",
                    game.name(),
                    split.as_str()
                )));
            }
            layers.push(in_split);
            frontier = next;
        }
        Ok(BoardPool { layers })
    }

    pub fn max_depth(&self) -> usize {
        self.layers.len()
    }

    /// Boards of exactly `depth` moves (1-based).
    pub fn layer(&self, depth: usize) -> &[G::State] {
        &self.layers[depth - 1]
    }

    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> G::State {
        let depth = rng.random_range(0..self.layers.len());
        *self.layers[depth].choose(rng).expect("layers are non-empty by construction")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::boards::depth::DepthTable;
    use crate::envs::boards::sets::boards_at;
    use crate::envs::boards::TileSwap;

    #[test]
    fn layers_match_the_depth_table() {
        let game = TileSwap::new();
        let table = DepthTable::build(&game).unwrap();
        let pool = BoardPool::new(&game, 4, Split::Train).unwrap();
        for depth in 1..=4 {
            let mut expected = boards_at(&game, &table, depth as u8, Some(Split::Train));
            let mut got = pool.layer(depth).to_vec();
            expected.sort_by_key(|s| s.0);
            got.sort_by_key(|s| s.0);
            assert_eq!(got, expected, "depth {depth}");
        }
    }
}
