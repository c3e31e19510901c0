//! Jaco (thesis 7.4.1, D.1.3): dm_control's 9-DoF Kinova Jaco arm (six arm joints and three fingers) over a
//! LightsOut or TileSwap board, simulated by MuJoCo 3.17.0 (feature `mujoco`, set up by `make mujoco`).
//!
//! The scene is the one the authors' `seads_envs/hybrid/jaco/` builds with dm_control's composer, written
//! here as MJCF with Kinova's model files attached by path (see [`scene`]):
//!
//! - dm_control's composer arena: `timestep="0.002"`, elliptic friction cones, 5 noslip iterations, and a
//!   ground plane (friction 0.4, `solimp="0.95 0.99 0.001" solref="0.002 1"`);
//! - the board: fields of 0.1 × 0.1 m (boxes of half-height 0.01 on the ground), centred on the origin, row 0
//!   on the arm's side (+y); LightsOut has one touch sensor per field (a box site 70 % of the field wide on its
//!   top face), TileSwap one over the whole board;
//! - the arm `jaco_arm.xml` with `jaco_hand.xml` attached at its wrist site, its base at (0, 0.4, 0);
//! - actuators as dm_control's `kinova/jaco_arm.py` and `jaco_hand.py` add them: one velocity actuator per
//!   joint, arm `kv=500` with torque limits ±30.5 N·m (joints 1-3) and ±6.8 N·m (4-6) and control ranges
//!   ±36°/s and ±48°/s, fingers `kv=10`, torque ±1, control ±5 rad/s;
//! - control timestep 0.1 s (50 physics steps per action).
//!
//! The push rule is the authors' (`ManipulatorBoardTask.after_substep` with the boards' `get_contact_info`):
//! after every physics step, while no move was made in this control step, a touch sensor reading above
//! 1e-3 N makes a push. LightsOut takes the field of the most strongly pressed sensor, TileSwap the first
//! board contact's position (found, as theirs, in the contacts from before that physics step); the push
//! counts only when it makes a move. After a move the arm is reset to a new random pose at once (the
//! remaining physics steps of the action run from there), as `reset_arm_after_move=True` does.
//!
//! Reset (theirs, from dm_control's `ToolCenterPointInitializer`): the tool centre point (the hand's grip
//! site) is placed by inverse kinematics at a uniform point of (−0.1, −0.1, 0.2)-(0.1, 0.1, 0.4) pointing down
//! with a uniform yaw, rejecting poses in collision; see [`ik`].
//!
//! MuJoCo 3.17 is not the MuJoCo 2.0 the thesis ran: its contact solver defaults, collision detection and
//! noslip differ in detail, so trajectories and success rates are close to but not bit-equal with the
//! authors'. The scene asks for libccd (`nativeccd="disable"`, as dm_control's Kinova files do), the
//! collision code MuJoCo 2.0 had.

mod arm;
mod controller;
pub mod ik;
pub mod scene;
#[cfg(test)]
mod tests;

pub use arm::Jaco;
pub use controller::JacoController;

/// Physics timestep of dm_control's composer arena (seconds).
pub const TIMESTEP: f64 = 0.002;
/// Control timestep of the authors' Jaco envs (seconds).
pub const CONTROL_TIMESTEP: f64 = 0.1;
/// Physics steps per action.
pub const SUBSTEPS: usize = 50;
/// Arm base position in the arena (`_ARM_Y_OFFSET`).
pub const ARM_OFFSET: [f64; 3] = [0.0, 0.4, 0.0];
/// Tool-centre-point reset box, lower and upper corner (`_TCP_LOWER_BOUNDS`, `_TCP_UPPER_BOUNDS`).
pub const TCP_LOW: [f64; 3] = [-0.1, -0.1, 0.2];
pub const TCP_HIGH: [f64; 3] = [0.1, 0.1, 0.4];
/// Half the width of one board field (`square_halfwidth`).
pub const FIELD_HALF: f64 = 0.05;
/// Touch sensor activation threshold (N).
pub const TOUCH_THRESHOLD: f64 = 1e-3;
/// Skill step limit for Jaco (thesis 7.4.1).
pub const SKILL_STEP_LIMIT: usize = 50;
/// Velocity limits of the arm joints (rad/s): 36°/s for joints 1-3, 48°/s for 4-6.
pub const ARM_MAX_VELOCITY: [f64; 6] = {
    let large = 36.0 * std::f64::consts::PI / 180.0;
    let small = 48.0 * std::f64::consts::PI / 180.0;
    [large, large, large, small, small, small]
};
/// Velocity limit of the finger joints (rad/s).
pub const FINGER_MAX_VELOCITY: f64 = 5.0;
/// Arm joints and fingers.
pub const ARM_JOINTS: usize = 6;
pub const JOINTS: usize = 9;

/// Where MuJoCo finds Kinova's model files: `MBRL_KINOVA_DIR` at run time, else the `.mujoco/kinova` folder
/// `make mujoco` filled, as build.rs compiled its path in.
pub fn kinova_dir() -> std::path::PathBuf {
    std::env::var_os("MBRL_KINOVA_DIR").map(Into::into).unwrap_or_else(|| env!("MBRL_KINOVA_DIR").into())
}
