//! Manipulators that play the board games physically (thesis 7.4, appendix D.1): the state is the
//! manipulator's state followed by the symbolic board.

pub mod cursor;
pub mod embodied;
#[cfg(feature = "mujoco")]
pub mod jaco;
pub mod layout;
pub mod manipulator;
pub mod reacher;
#[cfg(test)]
mod reference_cases;
#[cfg(test)]
mod reference_tests;

pub use layout::BoardLayout;
pub use manipulator::{BoardPoint, Manipulator, ScriptedController};

use crate::error::{Error, Result};
use crate::util::suggest::did_you_mean;

pub const EMBODIMENT_HELP: &str = "cursor, reacher, jaco (needs a build with `make mujoco`)";

/// Every manipulator's name, as `<game>:<name>` and `--embodiment` take it.
pub const EMBODIMENT_NAMES: [&str; 3] = ["cursor", "reacher", "jaco"];

/// Why `jaco` cannot run in a build without MuJoCo.
pub const JACO_NEEDS_MUJOCO: &str =
    "the Jaco arm runs on MuJoCo, which this mbrl was built without: build it with `make mujoco` (fetches MuJoCo \
     3.17.0 and the Kinova model into .mujoco/ and runs `cargo build --release --features mujoco`)";

/// The manipulators a user can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Embodiment {
    Cursor,
    Reacher,
    /// The Kinova Jaco arm on MuJoCo; named in every build, built only with the `mujoco` feature.
    Jaco,
}

impl Embodiment {
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "cursor" => Ok(Embodiment::Cursor),
            "reacher" => Ok(Embodiment::Reacher),
            "jaco" => Ok(Embodiment::Jaco),
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
            Embodiment::Jaco => "jaco",
        }
    }

    /// Refuses the Jaco in a build without MuJoCo, so that a command fails before its work, not at its first
    /// move.
    pub fn ensure_buildable(self) -> Result<()> {
        if self == Embodiment::Jaco && !cfg!(feature = "mujoco") {
            return Err(Error::config(JACO_NEEDS_MUJOCO));
        }
        Ok(())
    }

    /// The manipulator over `board` and its scripted controller. Cursor and Reacher play every board alike;
    /// the Jaco's scene holds the board, so it is built for one. Fails for the Jaco in a build without
    /// MuJoCo, or when MuJoCo cannot load its model.
    pub fn build(self, board: &BoardLayout) -> Result<(Box<dyn Manipulator>, Box<dyn ScriptedController>)> {
        match self {
            Embodiment::Cursor => Ok((Box::new(cursor::Cursor::new()), Box::new(cursor::CursorController))),
            Embodiment::Reacher => Ok((Box::new(reacher::Reacher::new()), Box::new(reacher::ReacherController::new()))),
            Embodiment::Jaco => build_jaco(board),
        }
    }
}

#[cfg(feature = "mujoco")]
fn build_jaco(board: &BoardLayout) -> Result<(Box<dyn Manipulator>, Box<dyn ScriptedController>)> {
    let arm = jaco::Jaco::new(board)?;
    let controller = jaco::JacoController::new(arm.model().clone(), arm.tcp_site(), board.side);
    Ok((Box::new(arm), Box::new(controller)))
}

#[cfg(not(feature = "mujoco"))]
fn build_jaco(_board: &BoardLayout) -> Result<(Box<dyn Manipulator>, Box<dyn ScriptedController>)> {
    Err(Error::config(JACO_NEEDS_MUJOCO))
}
