//! Where the launcher stands. The thesis records one "default" and five "unseen" launcher
//! positions/orientations (section 6.5.1, lines 4805-4812; Figure 6.2d) but gives no coordinates, so the poses
//! below are read off the authors' published plots: ball_model/data/notebooks/graphics/visualization_lp7.png
//! (default) and visualization_lp91.png … lp95.png (unseen-1 … unseen-5, the repository's data groups
//! lp91 … lp95). Each pose's exit point is where the plotted trajectories start (x, y from the top view, z from
//! the z-over-time panel at t = 0); its frame yaw φ_f is the heading of the trajectories' first metre relative
//! to the default's, anchored at the thesis' default φ_f = −90° (lines 4664-4665, 4800-4801). Reading plots
//! this way is good to a few centimetres and a few degrees, which is all "unseen" needs: orientations the
//! default data never showed.
//!
//! The tracker does not always see a ball from the moment it leaves the launcher. A shot with the heads'
//! angles peaks ≈ 0.3 s after leaving; the default, unseen-2 and unseen-3 recordings peak ≈ 0.28 s after their
//! first frame, but unseen-1's peak ≈ 0.24 s and unseen-4's and unseen-5's (which shoot along +y from the
//! robot's end) ≈ 0.18 s after it. For those three the exit point is the plotted start point moved back along
//! a nominal shot by 0.06 s (unseen-1, from (−0.52, 3.05, 0.05)) or 0.1 s (unseen-4 from (0.33, 0.50, 0.22),
//! unseen-5 from (0.71, 0.48, 0.12)).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

use super::vec3::Vec3;

/// Launcher orientation name: `default` or `unseen-1` … `unseen-5`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum Orientation {
    Default,
    /// 1 ..= 5.
    Unseen(u8),
}

/// Placement of the launcher frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LauncherPose {
    /// Where the ball leaves the launcher (m).
    pub exit_position: Vec3,
    /// Rotation φ_f of the launcher frame about z (rad); at φ_f + φ_l = 0 the ball flies along +x.
    pub frame_yaw: f64,
}

/// Exit point and frame yaw (deg) per orientation, in the order default, unseen-1 … unseen-5 (see module
/// docs for how they were read off the authors' plots).
const POSES: [(Vec3, f64); 6] = [
    ([0.54, 3.13, -0.11], -90.0),
    ([-0.63, 3.27, -0.11], -66.0),
    ([0.24, 3.18, -0.10], -92.0),
    ([1.05, 3.15, -0.08], -120.0),
    ([0.35, 0.09, -0.03], 91.0),
    ([0.79, 0.08, -0.13], 100.0),
];

/// Wheel actuation ranges (s_tl, s_tr, s_b) the recordings drew from uniformly (thesis lines 4811-4812): the
/// unseen configurations use slightly faster wheels.
const MOTOR_RANGES_DEFAULT: [(f64, f64); 3] = [(0.095, 0.155), (0.135, 0.195), (0.135, 0.195)];
const MOTOR_RANGES_UNSEEN: [(f64, f64); 3] = [(0.105, 0.165), (0.145, 0.205), (0.145, 0.205)];

const VALID_NAMES: &str = "default, unseen-1, unseen-2, unseen-3, unseen-4, unseen-5";

impl Orientation {
    pub const ALL: [Orientation; 6] = [
        Orientation::Default,
        Orientation::Unseen(1),
        Orientation::Unseen(2),
        Orientation::Unseen(3),
        Orientation::Unseen(4),
        Orientation::Unseen(5),
    ];

    pub fn parse(name: &str) -> Result<Orientation> {
        let trimmed = name.trim();
        let parsed = match trimmed {
            "default" => Some(Orientation::Default),
            _ => trimmed
                .strip_prefix("unseen-")
                .and_then(|n| n.parse::<u8>().ok())
                .filter(|n| (1..=5).contains(n))
                .map(Orientation::Unseen),
        };
        parsed.ok_or_else(|| {
            let names = Orientation::ALL.map(|o| o.name());
            let hint = crate::util::suggest::did_you_mean(trimmed, names.iter().map(String::as_str));
            Error::config(format!("unknown launcher orientation {name:?}{hint}; expected one of: {VALID_NAMES}"))
        })
    }

    pub fn name(&self) -> String {
        match self {
            Orientation::Default => "default".to_string(),
            Orientation::Unseen(n) => format!("unseen-{n}"),
        }
    }

    fn index(&self) -> usize {
        match *self {
            Orientation::Default => 0,
            Orientation::Unseen(n @ 1..=5) => n as usize,
            // Only `parse` builds orientations from user input, and it rejects these.
            Orientation::Unseen(n) => panic!("launcher orientation unseen-{n} does not exist ({VALID_NAMES})"),
        }
    }

    /// Panics for `Unseen(n)` outside 1..=5, which `parse` never returns.
    pub fn pose(&self) -> LauncherPose {
        let (exit_position, yaw_deg) = POSES[self.index()];
        LauncherPose { exit_position, frame_yaw: yaw_deg.to_radians() }
    }

    /// Ranges of (s_tl, s_tr, s_b) for this orientation.
    pub fn motor_ranges(&self) -> [(f64, f64); 3] {
        match self.index() {
            0 => MOTOR_RANGES_DEFAULT,
            _ => MOTOR_RANGES_UNSEEN,
        }
    }
}

impl std::fmt::Display for Orientation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl std::str::FromStr for Orientation {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        Orientation::parse(s)
    }
}

impl TryFrom<String> for Orientation {
    type Error = Error;

    fn try_from(s: String) -> Result<Self> {
        Orientation::parse(&s)
    }
}

impl From<Orientation> for String {
    fn from(o: Orientation) -> String {
        o.name()
    }
}
