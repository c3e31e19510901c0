//! Optimal solution depth of every reachable board, by breadth-first search backwards from the goal over
//! a dense table (thesis Table 7.1). Feasible for LightsOut up to 5×5 (2^25 entries) and TileSwap 3×3
//! (9! entries).

use super::{BoardGame, LightsOut, LightsOutState, TileSwap, TileSwapState};
use crate::error::{Error, Result};

const UNREACHED: u8 = u8::MAX;

/// A game whose boards can be numbered densely.
pub trait DenseIndex: BoardGame {
    fn state_count(&self) -> usize;
    fn index_of(&self, state: Self::State) -> usize;
    fn state_at(&self, index: usize) -> Self::State;

    /// Solution depth per board index (`UNREACHED` for unsolvable boards). Games with more structure
    /// than a move function override this.
    fn solution_depths(&self) -> Vec<u8> {
        reverse_bfs(self)
    }
}

/// Breadth-first search backwards from the goal: the depth of every board from its shortest path.
fn reverse_bfs<G: DenseIndex>(game: &G) -> Vec<u8> {
    let mut depths = vec![UNREACHED; game.state_count()];
    let goal = game.index_of(game.goal());
    depths[goal] = 0;
    let mut frontier = vec![goal];
    let mut depth = 0u8;
    while !frontier.is_empty() {
        depth += 1;
        let mut next = Vec::new();
        for &index in &frontier {
            let state = game.state_at(index);
            for mv in 0..game.num_moves() {
                let successor = game.index_of(game.apply(state, mv));
                if depths[successor] == UNREACHED {
                    depths[successor] = depth;
                    next.push(successor);
                }
            }
        }
        frontier = next;
    }
    depths
}

impl DenseIndex for LightsOut {
    fn state_count(&self) -> usize {
        1usize << self.fields()
    }

    fn index_of(&self, state: LightsOutState) -> usize {
        state.low_bits() as usize
    }

    fn state_at(&self, index: usize) -> LightsOutState {
        LightsOutState([index as u64, 0, 0])
    }

    /// Presses commute and a press done twice cancels, so a shortest solution presses each field at most
    /// once, and a board's depth is the fewest presses of any press set that produces it. Walking all
    /// 2^fields press sets in Gray-code order changes one press per step, which makes the whole table one
    /// XOR and one compare per press set (≈ 0.2 s for 5×5, against ≈ 18 s for a BFS over the moves).
    fn solution_depths(&self) -> Vec<u8> {
        let fields = self.fields();
        let masks: Vec<u64> = (0..fields).map(|mv| self.apply(LightsOutState::default(), mv).low_bits()).collect();
        let mut depths = vec![UNREACHED; 1usize << fields];
        let mut board = 0u64;
        let mut presses = 0u8;
        depths[0] = 0;
        for step in 1u64..(1u64 << fields) {
            let flipped = step.trailing_zeros() as usize;
            board ^= masks[flipped];
            // In Gray-code order the flipped press is now on iff bit `flipped` of the code is set.
            let code = step ^ (step >> 1);
            if code >> flipped & 1 == 1 {
                presses += 1;
            } else {
                presses -= 1;
            }
            let slot = &mut depths[board as usize];
            *slot = (*slot).min(presses);
        }
        depths
    }
}

const FACTORIALS: [usize; 10] = [1, 1, 2, 6, 24, 120, 720, 5040, 40320, 362880];

impl DenseIndex for TileSwap {
    fn state_count(&self) -> usize {
        FACTORIALS[9]
    }

    /// Lehmer code of the chip permutation.
    fn index_of(&self, state: TileSwapState) -> usize {
        let chips = state.chips();
        let mut rank = 0;
        for i in 0..9 {
            let smaller_later = chips[i + 1..].iter().filter(|&&c| c < chips[i]).count();
            rank += smaller_later * FACTORIALS[8 - i];
        }
        rank
    }

    fn state_at(&self, mut index: usize) -> TileSwapState {
        let mut remaining: Vec<usize> = (0..9).collect();
        let mut chips = [0usize; 9];
        for (i, chip) in chips.iter_mut().enumerate() {
            let f = FACTORIALS[8 - i];
            *chip = remaining.remove(index / f);
            index %= f;
        }
        TileSwapState::from_chips(&chips)
    }
}

/// Solution depth per board index; `None` for boards that cannot be solved.
pub struct DepthTable {
    depths: Vec<u8>,
}

impl DepthTable {
    /// Reverse BFS from the goal. LightsOut boards larger than 5×5 are refused (the table would not fit).
    pub fn build<G: DenseIndex>(game: &G) -> Result<Self> {
        let count = game.state_count();
        if count > 1 << 25 {
            return Err(Error::config(format!(
                "a full depth table of {} needs {count} entries; supported: lightsout up to 5x5 and tileswap-3x3",
                game.name()
            )));
        }
        Ok(DepthTable { depths: game.solution_depths() })
    }

    pub fn depth_of_index(&self, index: usize) -> Option<u8> {
        self.depths.get(index).copied().filter(|&d| d != UNREACHED)
    }

    pub fn depth<G: DenseIndex>(&self, game: &G, state: G::State) -> Option<u8> {
        self.depth_of_index(game.index_of(state))
    }

    pub fn max_depth(&self) -> u8 {
        self.depths.iter().copied().filter(|&d| d != UNREACHED).max().unwrap_or(0)
    }

    /// Number of boards at each depth 0..=max_depth.
    pub fn counts(&self) -> Vec<u64> {
        let mut counts = vec![0u64; self.max_depth() as usize + 1];
        for &d in self.depths.iter().filter(|&&d| d != UNREACHED) {
            counts[d as usize] += 1;
        }
        counts
    }

    /// Indices of all boards with exactly this depth, ascending.
    pub fn indices_at(&self, depth: u8) -> Vec<usize> {
        self.depths.iter().enumerate().filter(|(_, &d)| d == depth).map(|(i, _)| i).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tileswap_rank_is_a_bijection() {
        let game = TileSwap::new();
        for index in [0, 1, 5000, 362879] {
            assert_eq!(game.index_of(game.state_at(index)), index);
        }
        assert_eq!(game.index_of(game.goal()), 0);
    }

    #[test]
    fn small_lightsout_tables_are_consistent() {
        // 3×3 LightsOut: the press matrix is invertible, so all 512 boards are solvable.
        let game = LightsOut::new(3).unwrap();
        let table = DepthTable::build(&game).unwrap();
        assert_eq!(table.counts().iter().sum::<u64>(), 512);
        assert_eq!(table.counts()[1], 9);
    }

    #[test]
    fn press_set_enumeration_agrees_with_the_move_bfs() {
        for n in 2..=4 {
            let game = LightsOut::new(n).unwrap();
            assert_eq!(game.solution_depths(), reverse_bfs(&game), "lightsout {n}x{n}");
        }
    }

    #[test]
    fn large_boards_are_refused() {
        let err = DepthTable::build(&LightsOut::new(7).unwrap()).err().unwrap().to_string();
        assert!(err.contains("lightsout-7x7") && err.contains("5x5"), "{err}");
    }
}
