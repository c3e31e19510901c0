//! Manipulators that play the board games physically (thesis 7.4, appendix D.1): the state is the
//! manipulator's state followed by the symbolic board.

pub mod cursor;
pub mod embodied;
pub mod manipulator;
pub mod reacher;
#[cfg(test)]
mod reference_cases;
#[cfg(test)]
mod reference_tests;

pub use manipulator::{BoardPoint, Manipulator, ScriptedController};

use crate::error::{Error, Result};
use crate::util::suggest::did_you_mean;

pub const EMBODIMENT_HELP: &str = "cursor, reacher";

/// Every manipulator's name, as `<game>:<name>` and `--embodiment` take it.
pub const EMBODIMENT_NAMES: [&str; 2] = ["cursor", "reacher"];

/// The manipulators a user can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Embodiment {
    Cursor,
    Reacher,
}

impl Embodiment {
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "cursor" => Ok(Embodiment::Cursor),
            "reacher" => Ok(Embodiment::Reacher),
            other => Err(Error::config(format!(
                "unknown embodiment '{other}'{}; supported: {EMBODIMENT_HELP}",
                did_you_mean(other, EMBODIMENT_NAMES)
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Embodiment::Cursor => "cursor",
            Embodiment::Reacher => "reacher",
        }
    }

    /// The manipulator and its scripted controller.
    pub fn build(self) -> (Box<dyn Manipulator>, Box<dyn ScriptedController>) {
        match self {
            Embodiment::Cursor => (Box::new(cursor::Cursor::new()), Box::new(cursor::CursorController)),
            Embodiment::Reacher => (Box::new(reacher::Reacher::new()), Box::new(reacher::ReacherController::new())),
        }
    }
}
