//! Reacher (thesis 7.4.1, D.1.2): dm_control's planar two-link arm without its target, over a 0.3 × 0.3
//! board; a third action component pushes at the finger.
//!
//! The physics is our own rigid-body simulation of the MJCF model `dm_control/suite/reacher.xml`, which
//! the authors' environment (`seads_envs/hybrid/reacher/xmls/reacher.xml`) copies unchanged apart from
//! removing the target and adding the board. Facts taken from those files:
//!
//! - `<option timestep="0.02">` with contacts disabled and no integrator given (MuJoCo's default Euler);
//! - joints: hinges about z, `damping="0.01"`, no armature; the wrist `limited="true" range="-160 160"`
//!   (degrees, the MJCF default unit); the shoulder unlimited;
//! - motors: `gear=".05" ctrlrange="-1 1" ctrllimited="true"` on both joints;
//! - body `arm` at the origin with capsule geom `fromto="0 0 0 0.12 0 0" size=".01"`; body `hand` at
//!   `pos=".12 0 0"` with capsule `fromto="0 0 0 0.1 0 0" size=".01"`; body `finger` at `pos=".12 0 0"` in
//!   the hand frame with a sphere geom of radius 0.01. Gravity acts along −z, normal to the plane of
//!   motion, so it does no work.
//!
//! From the authors' SEADS environment (`seads_envs/hybrid/reacher/common.py`): action repeat 2, joints
//! reset to U(0, 2π) with zero velocity, push threshold `-1 + 0.8·2 = 0.6` on the third action component,
//! finger position normalized as (xy + 0.15)/0.3, and a push counts only with the normalized finger
//! position inside [0, 1]², checked after the physics steps of that action.
//!
//! Masses and inertias follow from MuJoCo's defaults (`inertiafromgeom`, geom density 1000 kg/m³), see
//! [`ArmInertia::dm_control`]. The dynamics are the standard planar two-link equations
//! M(q) q̈ + C(q, q̇) q̇ + B q̇ = gear·u, stepped like MuJoCo's Euler integrator: the velocity first, with the
//! joint damping taken implicitly ((M + h·B) q̈ = gear·u − C q̇ − B q̇, as `mj_Euler` does whenever a dof has
//! damping), then the position with the new velocity.
//!
//! The wrist's range is MuJoCo's soft joint limit (see [`limit`]): past ±160° a spring-damper with
//! time constant 2·timestep pushes back, so under full torque the wrist sinks about 2° past the stop and
//! a wrist set far beyond it returns over a few steps, as in the reference.

mod board;
mod controller;
mod limit;
mod physics;
#[cfg(test)]
mod tests;

use std::f64::consts::PI;

pub use board::{arm_to_board, board_to_arm};
pub use controller::ReacherController;
pub use physics::{
    capsule_mass_inertia, finger_position, min_reach, pressed_reach, pressed_wrist_angle, sphere_mass_inertia,
    ArmInertia, Reacher,
};

/// Physics timestep of `reacher.xml` (seconds).
pub const TIMESTEP: f64 = 0.02;
/// Physics steps per control step (thesis D.1.2).
pub const ACTION_REPEAT: usize = 2;
/// Motor gear: joint torque = GEAR · ctrl, ctrl ∈ [−1, 1].
pub const GEAR: f64 = 0.05;
/// Joint damping of both hinges (N·m·s/rad).
pub const DAMPING: f64 = 0.01;
/// Shoulder to wrist (position of body `hand` in body `arm`; also the length of the `arm` capsule).
pub const ARM_LENGTH: f64 = 0.12;
/// Length of the `hand` capsule's segment (it ends short of the finger).
pub const HAND_LENGTH: f64 = 0.1;
/// Wrist to finger centre (position of body `finger` in body `hand`).
pub const FINGER_OFFSET: f64 = 0.12;
/// Radius of both capsules.
pub const CAPSULE_RADIUS: f64 = 0.01;
/// Radius of the finger sphere.
pub const FINGER_RADIUS: f64 = 0.01;
/// MuJoCo's default geom density (kg/m³).
pub const DENSITY: f64 = 1000.0;
/// Wrist range ±160°.
pub const WRIST_LIMIT: f64 = 160.0 * PI / 180.0;
/// A push happens when the third action component exceeds this. The authors' code writes it as
/// −1 + 0.8·2, which in floating point is 0.6000000000000001, so an action of exactly that value does
/// not push.
pub const PUSH_THRESHOLD: f64 = -1.0 + 0.8 * 2.0;
/// The board covers [−0.15, 0.15]² in the arm's plane (thesis D.1.2).
pub const BOARD_HALF_EXTENT: f64 = 0.15;
/// Skill step limit for Reacher (thesis 7.4.1).
pub const SKILL_STEP_LIMIT: usize = 50;

/// Farthest the finger gets from the shoulder.
pub const MAX_REACH: f64 = ARM_LENGTH + FINGER_OFFSET;
