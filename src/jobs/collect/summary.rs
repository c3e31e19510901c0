//! What `collect` wrote, one variant per source, printed as one line.

use std::fmt;
use std::path::PathBuf;

pub enum CollectSummary {
    /// Random rollouts; `pairs` when drawn as instance pairs (`--instances`), `frames` with `--images`.
    Rollouts {
        transitions: usize,
        rollouts: usize,
        pairs: Option<usize>,
        env: String,
        frames: usize,
        out: PathBuf,
    },
    Replay {
        actions: usize,
        env: String,
        out: PathBuf,
    },
    /// Skill episodes of a board game played by a manipulator.
    Episodes {
        steps: usize,
        episodes: usize,
        env: String,
        out: PathBuf,
    },
    Terrain {
        maps: usize,
        out: PathBuf,
    },
    /// `per_depth[d - 1]` boards of solution depth d.
    Boards {
        boards: usize,
        game: String,
        out: PathBuf,
        per_depth: Vec<usize>,
    },
    /// `trajectories` = the `shots` simulated plus their rotated copies.
    Ball {
        trajectories: usize,
        shots: usize,
        orientation: String,
        frames: usize,
        out: PathBuf,
    },
}

impl fmt::Display for CollectSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            CollectSummary::Rollouts { transitions, rollouts, pairs, env, frames, out } => {
                write!(f, "wrote {transitions} transitions in {rollouts} rollouts")?;
                if let Some(n) = pairs {
                    write!(f, " ({n} instance pairs)")?;
                }
                write!(f, " of {env}")?;
                if *frames > 0 {
                    write!(f, " with {frames} frames")?;
                }
                write!(f, " to {}", out.display())
            }
            CollectSummary::Replay { actions, env, out } => {
                write!(f, "wrote a replay of {actions} actions in {env} to {}", out.display())
            }
            CollectSummary::Episodes { steps, episodes, env, out } => {
                write!(f, "wrote {steps} steps in {episodes} skill episodes of {env} to {}", out.display())
            }
            CollectSummary::Terrain { maps, out } => {
                let train = maps.div_ceil(2);
                write!(f, "wrote {maps} terrain maps ({train} train, {} test) to {}", maps - train, out.display())
            }
            CollectSummary::Boards { boards, game, out, per_depth } => {
                let counts: Vec<String> = per_depth.iter().enumerate().map(|(i, n)| format!("{}: {n}", i + 1)).collect();
                write!(f, "wrote {boards} boards of {game} to {} (per depth {})", out.display(), counts.join(", "))
            }
            CollectSummary::Ball { trajectories, shots, orientation, frames, out } => write!(
                f,
                "wrote {trajectories} ball trajectories ({shots} shots from the {orientation} pose, {} rotated copies), \
                 {frames} frames, to {}",
                trajectories - shots,
                out.display()
            ),
        }
    }
}
