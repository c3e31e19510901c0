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
    /// Fields per side of the square board.
    fn side(&self) -> usize;
    /// Board point at which a push performs `mv`.
    fn move_target(&self, mv: usize) -> BoardPoint;
    /// The move a push at `point` performs, if any.
    fn move_at(&self, point: BoardPoint) -> Option<usize>;
    fn move_name(&self, mv: usize) -> String;
    /// A board drawn uniformly from all boards the moves reach from the goal (every such board is
    /// solvable, each equally likely).
    fn scramble(&self, rng: &mut rand_chacha::ChaCha8Rng) -> Self::State;
    /// Whether some sequence of moves reaches the goal from `state`.
    fn is_solvable(&self, _state: Self::State) -> bool {
        true
    }
}

/// Field index (row, col) under a point on an n×n board in [0, 1]², as the authors' touch board computes
/// it: numpy `digitize(v, edges, right=True)` with `edges = linspace(0, 1, n + 1)[1:]`
/// (`seads_envs/hybrid/touch_board.py`). `right=True` means a field is the half-open interval
/// (e_{k−1}, e_k], so a point exactly on an interior edge belongs to the LOWER field, 0 lies in field 0 and
/// 1 in field n − 1; the authors raise on points outside [0, 1]², here they are no field.
///
/// The edges are computed as numpy's linspace does (k · (1/n), last edge exactly 1) rather than as a floor
/// of v·n: the two differ in the last bit for some n (3 · (1/5) = 0.6000000000000001), and only the
/// former puts every edge value in the same field as the original.
pub fn field_at(point: BoardPoint, n: usize) -> Option<(usize, usize)> {
    let inside = |v: f64| (0.0..=1.0).contains(&v);
    if !inside(point[0]) || !inside(point[1]) {
        return None;
    }
    let step = 1.0 / n as f64;
    // digitize(right=True) = the number of edges strictly below v; the last edge (1) never is.
    let index = |v: f64| (1..n).filter(|&k| k as f64 * step < v).count();
    Some((index(point[1]), index(point[0])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_lookup_uses_equal_bins() {
        assert_eq!(field_at([0.1, 0.9], 5), Some((4, 0)));
        assert_eq!(field_at([1.0, 1.0], 5), Some((4, 4)));
        assert_eq!(field_at([0.0, 0.0], 5), Some((0, 0)), "0 lies in the first field");
        assert_eq!(field_at([1.01, 0.5], 5), None);
        assert_eq!(field_at([0.5, -1e-12], 5), None);
    }

    /// numpy.digitize(v, linspace(0, 1, 6)[1:], right=True) for v = 0.2, 0.4, 0.6, 0.8 is 0, 1, 2, 3: an
    /// edge belongs to the field below it (values checked with numpy 2.4).
    #[test]
    fn edges_belong_to_the_lower_field_like_digitize_right() {
        for (k, edge) in [0.2, 0.4, 0.6, 0.8].into_iter().enumerate() {
            assert_eq!(field_at([edge, 0.5], 5), Some((2, k)), "x = {edge}");
            assert_eq!(field_at([0.5, edge], 5), Some((k, 2)), "y = {edge}");
            assert_eq!(field_at([edge + 1e-9, edge], 5), Some((k, k + 1)), "just past {edge}");
        }
        // linspace's third edge is 0.6000000000000001: both that value and 0.6 fall below it.
        assert_eq!(field_at([3.0 * 0.2, 0.0], 5), Some((0, 2)));
        assert_eq!(field_at([1.0 / 3.0, 2.0 / 3.0], 3), Some((1, 0)));
        assert_eq!(field_at([0.5, 0.5], 2), Some((0, 0)));
    }
}
