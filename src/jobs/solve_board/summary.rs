//! What `solve-board` prints: the board, the plan, the search and how the plan played out. The game's
//! pictures and move names are drawn when the job ends, so the summary holds no game type.

use std::fmt;

use crate::planning::bfs::SearchStats;
use crate::{Error, Result};

/// A board as its canonical string, its game (or embodied game) and its picture.
pub struct ShownBoard {
    pub id: String,
    pub game: String,
    pub picture: String,
}

/// How a plan over the game's rules played out.
pub enum Ending {
    /// No manipulator: the plan is applied to the board symbolically.
    Symbolic {
        goal: String,
        solved: bool,
    },
    Embodied {
        embodiment: &'static str,
        performed: usize,
        control_steps: usize,
        final_board: String,
        solved: bool,
    },
}

pub enum SolveBoardSummary {
    /// `--model true`: one plan by the game's rules.
    Rules { board: ShownBoard, moves: Vec<String>, bidirectional: bool, stats: SearchStats, ending: Ending },
    /// A SEADS checkpoint: plans over its forward model, played by its skills.
    Learned {
        board: ShownBoard,
        plans: Vec<Vec<usize>>,
        /// Per executed skill: `skill k → move (n steps)`.
        executed: Vec<String>,
        bidirectional: bool,
        planning_seconds: f64,
        control_steps: usize,
        final_board: String,
        solved: bool,
        max_replans: usize,
    },
}

impl SolveBoardSummary {
    /// An error when the plan was played and did not reach the goal: printed after the summary, it makes the
    /// command fail.
    pub fn verdict(&self) -> Result<()> {
        match self {
            SolveBoardSummary::Rules { ending: Ending::Embodied { embodiment, solved: false, .. }, .. } => {
                Err(Error::data(format!("the {embodiment} controller did not reach the goal board")))
            }
            SolveBoardSummary::Learned { solved: false, max_replans, .. } => Err(Error::data(format!(
                "the learned skills did not reach the goal board within {max_replans} replans"
            ))),
            _ => Ok(()),
        }
    }
}

fn yes_no(flag: bool) -> &'static str {
    if flag {
        "yes"
    } else {
        "no"
    }
}

impl fmt::Display for ShownBoard {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "board {} ({}):\n{}", self.id, self.game, self.picture)
    }
}

impl fmt::Display for SolveBoardSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            SolveBoardSummary::Rules { board, moves, bidirectional, stats, ending } => {
                writeln!(f, "{board}")?;
                let plural = if moves.len() == 1 { "" } else { "s" };
                writeln!(f, "plan ({} move{plural}): {}", moves.len(), moves.join(", "))?;
                writeln!(
                    f,
                    "search: {}, {} states expanded, {} generated, {} stored, {:.1} MiB",
                    if *bidirectional { "bidirectional BFS" } else { "one-sided BFS" },
                    stats.expanded,
                    stats.generated,
                    stats.stored,
                    stats.peak_memory_bytes as f64 / (1u64 << 20) as f64
                )?;
                match ending {
                    Ending::Symbolic { goal, solved } => {
                        write!(f, "solved board:\n{goal}\nsolved: {}", yes_no(*solved))
                    }
                    Ending::Embodied { performed, control_steps, final_board, solved, .. } => write!(
                        f,
                        "embodiment: {performed} of {} moves performed in {control_steps} control steps; final \
                         board:\n{final_board}\nsolved: {}",
                        moves.len(),
                        yes_no(*solved)
                    ),
                }
            }
            SolveBoardSummary::Learned {
                board,
                plans,
                executed,
                bidirectional,
                planning_seconds,
                control_steps,
                final_board,
                solved,
                ..
            } => {
                writeln!(f, "{board}")?;
                for (i, plan) in plans.iter().enumerate() {
                    let skills: Vec<String> = plan.iter().map(|k| k.to_string()).collect();
                    writeln!(f, "plan {} ({} skills): {}", i + 1, plan.len(), skills.join(", "))?;
                }
                writeln!(f, "executed: {}", executed.join(", "))?;
                write!(
                    f,
                    "search: {}, planning {planning_seconds:.3} s; {} replans; {control_steps} control steps; final \
                     board:\n{final_board}\nsolved: {}",
                    if *bidirectional { "bidirectional (model verified self-inverse)" } else { "breadth-first" },
                    plans.len().saturating_sub(1),
                    yes_no(*solved)
                )
            }
        }
    }
}
