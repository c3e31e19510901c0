//! Board games of SEADS (thesis chapter 7): LightsOut and TileSwap, their symbolic observations, solution
//! depths and the train/test split.

pub mod depth;
pub mod gf2;
pub mod lightsout;
pub mod sets;
pub mod spec;
pub mod split;
pub mod tileswap;

use std::fmt::Debug;
use std::hash::Hash;

pub use lightsout::{LightsOut, LightsOutState};
pub use spec::GameSpec;
pub use split::{split_of, Split};
pub use tileswap::{TileSwap, TileSwapState};

use super::embodiments::manipulator::BoardPoint;
use crate::error::Result;

/// The rules of a board game in the form planners and embodiments need.
pub trait BoardGame: Clone + Send + Sync + 'static {
    type State: Copy + Eq + Hash + Send + Sync + Debug;

    /// `lightsout-5x5`, `tileswap-3x3`.
    fn name(&self) -> String;
    fn num_moves(&self) -> usize;
    fn apply(&self, state: Self::State, mv: usize) -> Self::State;
    fn goal(&self) -> Self::State;
    /// The thesis' symbolic observation: {0,1}^(n·n) for LightsOut, a row-major 9×9 one-hot
    /// "chip j on field i" matrix for TileSwap.
    fn symbolic(&self, state: Self::State) -> Vec<f64>;
    /// Inverse of [`symbolic`](Self::symbolic); `None` when the bits are not a board of this game.
    fn decode_symbolic(&self, bits: &[f64]) -> Option<Self::State>;
    /// The comma-separated canonical string used for the train/test hash (appendix D.1.4).
    fn canonical_string(&self, state: Self::State) -> String;
    /// Parses the canonical comma-separated form, with a one-line error on bad input.
    fn parse(&self, text: &str) -> Result<Self::State>;
    /// A multi-line picture of the board for terminals.
    fn render(&self, state: Self::State) -> String;
    /// Board point at which a push performs `mv`.
    fn move_target(&self, mv: usize) -> BoardPoint;
    /// The move a push at `point` performs, if any.
    fn move_at(&self, point: BoardPoint) -> Option<usize>;
    fn move_name(&self, mv: usize) -> String;
    /// Whether some sequence of moves reaches the goal from `state`.
    fn is_solvable(&self, _state: Self::State) -> bool {
        true
    }
}

/// Field index (row, col) under a point on an n×n board in [0, 1]² (numpy `digitize` with edges
/// 1/n, …, (n−1)/n, as in the original Cursor environment).
pub fn field_at(point: BoardPoint, n: usize) -> Option<(usize, usize)> {
    let inside = |v: f64| (0.0..=1.0).contains(&v);
    if !inside(point[0]) || !inside(point[1]) {
        return None;
    }
    let index = |v: f64| ((v * n as f64).floor() as usize).min(n - 1);
    Some((index(point[1]), index(point[0])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_lookup_uses_equal_bins() {
        assert_eq!(field_at([0.1, 0.9], 5), Some((4, 0)));
        assert_eq!(field_at([0.2, 0.0], 5), Some((0, 1)), "an edge belongs to the next field like digitize");
        assert_eq!(field_at([1.0, 1.0], 5), Some((4, 4)));
        assert_eq!(field_at([1.01, 0.5], 5), None);
    }
}
