//! What a manipulator knows of the board it plays on. Cursor and Reacher need nothing of it; the Jaco's MuJoCo
//! scene contains the board, with the touch sensing of the authors' LightsOut or TileSwap board.

use std::fmt;
use std::sync::Arc;

use super::manipulator::BoardPoint;
use crate::envs::boards::{BoardGame, GameSpec, LightsOut, TileSwap};
use crate::error::Result;

#[derive(Clone)]
pub struct BoardLayout {
    /// Fields per side.
    pub side: usize,
    /// One touch sensor per field (the authors' LightsOut board), else one over the whole board (TileSwap).
    pub field_sensors: bool,
    /// Whether a push at a board point makes a move: a touch that makes none is not a push, and the
    /// authors' task keeps looking for one in the same control step.
    pub makes_move: Arc<dyn Fn(BoardPoint) -> bool + Send + Sync>,
}

impl BoardLayout {
    pub fn of<G: BoardGame>(game: &G) -> Self {
        let rules = game.clone();
        BoardLayout {
            side: game.side(),
            // LightsOut presses the field under a push, TileSwap swaps around the pivot nearest to it.
            field_sensors: game.name().starts_with("lightsout"),
            makes_move: Arc::new(move |p| rules.move_at(p).is_some()),
        }
    }
}

impl BoardLayout {
    pub fn of_spec(game: GameSpec) -> Result<Self> {
        Ok(match game {
            GameSpec::LightsOut(n) => Self::of(&LightsOut::new(n)?),
            GameSpec::TileSwap => Self::of(&TileSwap::new()),
        })
    }
}

impl fmt::Debug for BoardLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BoardLayout").field("side", &self.side).field("field_sensors", &self.field_sensors).finish()
    }
}
