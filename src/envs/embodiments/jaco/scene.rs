//! The MuJoCo scene: arena and board written as MJCF here, Kinova's arm and hand loaded from their files
//! and attached (hand at the arm's wrist site, arm at a frame 0.4 m along +y), as dm_control's composer
//! attaches them.

use std::fmt::Write;
use std::path::Path;
use std::sync::Arc;

use mujoco_rs::prelude::*;

use super::{ARM_JOINTS, ARM_MAX_VELOCITY, ARM_OFFSET, FIELD_HALF, FINGER_MAX_VELOCITY, TIMESTEP};
use crate::error::{Error, Result};

/// Prefixes the attached models' names get.
pub const ARM_PREFIX: &str = "arm/";
pub const HAND_PREFIX: &str = "hand/";

/// Which touch sensing the board has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Touch {
    /// One sensor per field (LightsOut): a push presses the field of the most strongly pressed sensor.
    PerField,
    /// One sensor over the whole board (TileSwap): a push is at the first board contact's position.
    Whole,
}

/// Joint torque limits (N·m) of the arm's velocity actuators.
const ARM_MAX_TORQUE: [f64; 6] = [30.5, 30.5, 30.5, 6.8, 6.8, 6.8];
const ARM_KV: f64 = 500.0;
const FINGER_KV: f64 = 10.0;
const FINGER_MAX_TORQUE: f64 = 1.0;

/// Centre of field (row, col) on a board of `side` fields, in world x, y: columns along +x, row 0 at +y.
pub fn field_centre(side: usize, row: usize, col: usize) -> [f64; 2] {
    let offset = |k: usize| (k as f64 - 0.5 * (side as f64 - 1.0)) * 2.0 * FIELD_HALF;
    [offset(col), -offset(row)]
}

/// The arena and board as MJCF, with the actuators and touch sensors (their joints are the attached arm's).
pub fn scene_xml(side: usize, touch: Touch) -> String {
    let mut fields = String::new();
    let mut sensors = String::new();
    for row in 0..side {
        for col in 0..side {
            let [x, y] = field_centre(side, row, col);
            // Board geoms keep MuJoCo's default contact parameters, as the board's own MJCF model does.
            let _ = writeln!(
                fields,
                r#"<geom name="field_{row}_{col}" type="box" size="{FIELD_HALF} {FIELD_HALF} 0.01" pos="{x} {y} 0.01"/>"#
            );
            if touch == Touch::PerField {
                let half = 0.7 * FIELD_HALF;
                let _ = writeln!(
                    fields,
                    r#"<site name="touch_{row}_{col}" type="box" size="{half} {half} 0.005" pos="{x} {y} 0.02"/>"#
                );
                let _ = writeln!(sensors, r#"<touch name="touch_{row}_{col}" site="touch_{row}_{col}"/>"#);
            }
        }
    }
    if touch == Touch::Whole {
        let half = side as f64 * FIELD_HALF;
        let _ = writeln!(fields, r#"<site name="touch" type="box" size="{half} {half} 0.005" pos="0 0 0.02"/>"#);
        let _ = writeln!(sensors, r#"<touch name="touch" site="touch"/>"#);
    }
    // dm_control's JacoArm senses each arm joint with a 3-axis torque sensor at a site on the joint's body;
    // the sites are added to the arm's model before it is attached (see `compile`), hence the prefix.
    for k in 1..=ARM_JOINTS {
        let _ = writeln!(sensors, r#"<torque name="joint_{k}_torque" site="{ARM_PREFIX}joint_{k}_site"/>"#);
    }
    let mut actuators = String::new();
    for (k, (velocity, torque)) in ARM_MAX_VELOCITY.iter().zip(ARM_MAX_TORQUE).enumerate() {
        let joint = format!("{ARM_PREFIX}joint_{}", k + 1);
        let _ = writeln!(
            actuators,
            r#"<velocity name="{joint}" joint="{joint}" kv="{ARM_KV}" ctrllimited="true" ctrlrange="{} {velocity}" forcelimited="true" forcerange="{} {torque}"/>"#,
            -velocity, -torque
        );
    }
    for k in 1..=3 {
        let joint = format!("{ARM_PREFIX}{HAND_PREFIX}finger_{k}");
        let _ = writeln!(
            actuators,
            r#"<velocity name="{joint}" joint="{joint}" kv="{FINGER_KV}" ctrllimited="true" ctrlrange="-{FINGER_MAX_VELOCITY} {FINGER_MAX_VELOCITY}" forcelimited="true" forcerange="-{FINGER_MAX_TORQUE} {FINGER_MAX_TORQUE}"/>"#
        );
    }
    let [ax, ay, az] = ARM_OFFSET;
    format!(
        r#"<mujoco model="jaco_board">
<compiler angle="radian" boundmass="1e-5" boundinertia="1e-11"/>
<option timestep="{TIMESTEP}" cone="elliptic" noslip_iterations="5" noslip_tolerance="0"><flag nativeccd="disable"/></option>
<worldbody>
<geom name="ground" type="plane" size="1 1 0.1" friction="0.4" solimp="0.95 0.99 0.001" solref="0.002 1"/>
{fields}<frame name="arm_mount" pos="{ax} {ay} {az}"/>
</worldbody>
<actuator>
{actuators}</actuator>
<sensor>
{sensors}</sensor>
</mujoco>
"#
    )
}

fn mujoco_error(what: &str, e: impl std::fmt::Display) -> Error {
    Error::config(format!("MuJoCo could not build the Jaco scene ({what}): {e}"))
}

/// Compiles the scene with Kinova's files from `kinova` (see [`super::kinova_dir`]).
pub fn compile(side: usize, touch: Touch, kinova: &Path) -> Result<Arc<MjModel>> {
    let arm_file = kinova.join("jaco_arm.xml");
    if !arm_file.is_file() {
        return Err(Error::config(format!(
            "the Jaco arm's model {} is missing: run `make mujoco` (it fetches dm_control's Kinova files), or set \
             MBRL_KINOVA_DIR to a folder holding jaco_arm.xml, jaco_hand.xml and meshes_decimated/",
            arm_file.display()
        )));
    }
    let mut arm = MjSpec::from_xml(&arm_file).map_err(|e| mujoco_error("jaco_arm.xml", e))?;
    for k in 1..=ARM_JOINTS {
        arm.body_mut(&format!("b_{k}"))
            .ok_or_else(|| mujoco_error("jaco_arm.xml", format!("no body 'b_{k}'")))?
            .add_site()
            .with_name(&format!("joint_{k}_site"))
            .with_size([1e-3, 0.0, 0.0]);
    }
    let mut hand = MjSpec::from_xml(kinova.join("jaco_hand.xml")).map_err(|e| mujoco_error("jaco_hand.xml", e))?;
    let hand_root = hand.body_mut("hand").ok_or_else(|| mujoco_error("jaco_hand.xml", "no body 'hand'"))?;
    arm.site_mut("wristsite")
        .ok_or_else(|| mujoco_error("jaco_arm.xml", "no site 'wristsite'"))?
        .attach_by_deep_copy(hand_root, HAND_PREFIX, "")
        .map_err(|e| mujoco_error("attaching the hand", e))?;
    let mut scene = MjSpec::from_xml_string(&scene_xml(side, touch)).map_err(|e| mujoco_error("scene", e))?;
    let arm_root = arm.body_mut("b_base").ok_or_else(|| mujoco_error("jaco_arm.xml", "no body 'b_base'"))?;
    scene
        .frame_mut("arm_mount")
        .ok_or_else(|| mujoco_error("scene", "no frame 'arm_mount'"))?
        .attach_by_deep_copy(arm_root, ARM_PREFIX, "")
        .map_err(|e| mujoco_error("attaching the arm", e))?;
    let model = scene.compile().map_err(|e| mujoco_error("compile", e))?;
    Ok(Arc::new(model))
}
