//! Named choices several subcommands share, as clap value enums over the engine's own types.

use clap::ValueEnum;

use crate::envs::boards::Split;
use crate::envs::embodiments::Embodiment;
use crate::envs::terrain::TerrainSplit;
use crate::models::context::calibration::Strategy;

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SplitChoice {
    Train,
    Test,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SearchChoice {
    /// From both ends (moves undo themselves); far fewer states.
    Bidirectional,
    /// From the start only, as the thesis' planner.
    Bfs,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum EmbodimentChoice {
    /// A point moved by steps of at most 0.2, pushing where it stands (10 steps per move).
    Cursor,
    /// A torque-driven two-link arm over a 0.3 m board (50 steps per move).
    Reacher,
    /// The 9-DoF Kinova Jaco arm on MuJoCo, target joint velocities at 10 Hz (50 steps per move; needs a build
    /// with `make mujoco`).
    Jaco,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum StrategyChoice {
    /// Uniformly random actions (the baseline).
    Random,
    /// One action sequence maximizing the expected information gain, planned at the start (eq. 4.36).
    OpenLoop,
    /// Replan the EIG-optimal sequence after every transition, horizon min(H_max, N − n) (eq. 4.37).
    Mpc,
}

impl From<SplitChoice> for TerrainSplit {
    fn from(choice: SplitChoice) -> Self {
        match choice {
            SplitChoice::Train => Self::Train,
            SplitChoice::Test => Self::Test,
        }
    }
}

impl From<SplitChoice> for Split {
    fn from(choice: SplitChoice) -> Split {
        match choice {
            SplitChoice::Train => Split::Train,
            SplitChoice::Test => Split::Test,
        }
    }
}

impl From<EmbodimentChoice> for Embodiment {
    fn from(choice: EmbodimentChoice) -> Embodiment {
        match choice {
            EmbodimentChoice::Cursor => Embodiment::Cursor,
            EmbodimentChoice::Reacher => Embodiment::Reacher,
            EmbodimentChoice::Jaco => Embodiment::Jaco,
        }
    }
}

impl From<StrategyChoice> for Strategy {
    fn from(choice: StrategyChoice) -> Strategy {
        match choice {
            StrategyChoice::Random => Strategy::Random,
            StrategyChoice::OpenLoop => Strategy::OpenLoop,
            StrategyChoice::Mpc => Strategy::Mpc,
        }
    }
}
