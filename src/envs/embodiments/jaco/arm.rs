//! The Jaco as a board manipulator: actions, state, observation, the push rule and resets.

use std::sync::Arc;

use mujoco_rs::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::ik::{random_tcp_pose, Data};
use super::scene::{compile, Touch, ARM_PREFIX, HAND_PREFIX};
use super::{
    kinova_dir, ARM_JOINTS, ARM_MAX_VELOCITY, CONTROL_TIMESTEP, FIELD_HALF, FINGER_MAX_VELOCITY, JOINTS,
    SKILL_STEP_LIMIT, SUBSTEPS, TOUCH_THRESHOLD,
};
use crate::envs::embodiments::manipulator::{BoardPoint, Manipulator};
use crate::envs::embodiments::BoardLayout;
use crate::error::Result;
use crate::util::domain::Domain;

const STATE_NAMES: [&str; 2 * JOINTS] = [
    "joint_1",
    "joint_2",
    "joint_3",
    "joint_4",
    "joint_5",
    "joint_6",
    "finger_1",
    "finger_2",
    "finger_3",
    "joint_1_velocity",
    "joint_2_velocity",
    "joint_3_velocity",
    "joint_4_velocity",
    "joint_5_velocity",
    "joint_6_velocity",
    "finger_1_velocity",
    "finger_2_velocity",
    "finger_3_velocity",
];

const OBS_NAMES: [&str; 42] = [
    "joint_1_sin",
    "joint_1_cos",
    "joint_2_sin",
    "joint_2_cos",
    "joint_3_sin",
    "joint_3_cos",
    "joint_4_sin",
    "joint_4_cos",
    "joint_5_sin",
    "joint_5_cos",
    "joint_6_sin",
    "joint_6_cos",
    "joint_1_torque",
    "joint_2_torque",
    "joint_3_torque",
    "joint_4_torque",
    "joint_5_torque",
    "joint_6_torque",
    "joint_1_velocity",
    "joint_2_velocity",
    "joint_3_velocity",
    "joint_4_velocity",
    "joint_5_velocity",
    "joint_6_velocity",
    "finger_1",
    "finger_2",
    "finger_3",
    "finger_1_velocity",
    "finger_2_velocity",
    "finger_3_velocity",
    "pinch_x",
    "pinch_y",
    "pinch_z",
    "pinch_r00",
    "pinch_r01",
    "pinch_r02",
    "pinch_r10",
    "pinch_r11",
    "pinch_r12",
    "pinch_r20",
    "pinch_r21",
    "pinch_r22",
];

/// Where the touch sensing and the board's geoms are in the model.
struct Board {
    layout: BoardLayout,
    touch: Touch,
    /// Geom id of field (row, col), row-major.
    fields: Vec<usize>,
}

pub struct Jaco {
    model: Arc<MjModel>,
    data: Data,
    board: Board,
    /// The grip site (dm_control's tool centre point for the hand).
    tcp: usize,
    /// The pinch site, whose pose the authors' agent observes.
    pinch: usize,
    /// Where each arm joint's 3-axis torque sensor reads in `sensordata`, and the joint's axis (local frame,
    /// which the sensor's site shares).
    torque_sensors: Vec<(usize, [f64; 3])>,
    /// The touch sensors' readings: the first `touch_readings` values of `sensordata`.
    touch_readings: usize,
    hand_bodies: Vec<usize>,
    /// Draws the resets after moves; reseeded from the episode's stream at every [`Manipulator::reset`].
    rng: ChaCha8Rng,
}

impl Jaco {
    pub fn new(layout: &BoardLayout) -> Result<Self> {
        let touch = if layout.field_sensors { Touch::PerField } else { Touch::Whole };
        let model = compile(layout.side, touch, &kinova_dir())?;
        Ok(Self::with_model(model, layout.clone()))
    }

    pub(super) fn with_model(model: Arc<MjModel>, layout: BoardLayout) -> Self {
        let id =
            |kind, name: &str| model.name_to_id(kind, name).unwrap_or_else(|| panic!("the Jaco scene has '{name}'"));
        let side = layout.side;
        let fields =
            (0..side * side).map(|k| id(MjtObjBase::mjOBJ_GEOM, &format!("field_{}_{}", k / side, k % side))).collect();
        let tcp = id(MjtObjBase::mjOBJ_SITE, &format!("{ARM_PREFIX}{HAND_PREFIX}gripsite"));
        let pinch = id(MjtObjBase::mjOBJ_SITE, &format!("{ARM_PREFIX}{HAND_PREFIX}pinchsite"));
        let torque_sensors = (1..=ARM_JOINTS)
            .map(|k| {
                let sensor = id(MjtObjBase::mjOBJ_SENSOR, &format!("joint_{k}_torque"));
                let joint = id(MjtObjBase::mjOBJ_JOINT, &format!("{ARM_PREFIX}joint_{k}"));
                (model.sensor_adr()[sensor] as usize, model.jnt_axis()[joint])
            })
            .collect();
        let touch_readings = if layout.field_sensors { side * side } else { 1 };
        let hand_prefix = format!("{ARM_PREFIX}{HAND_PREFIX}");
        let hand_bodies = (0..model.ffi().nbody as usize)
            .filter(|&b| model.id_to_name(MjtObjBase::mjOBJ_BODY, b).is_some_and(|n| n.starts_with(&hand_prefix)))
            .collect();
        let touch = if layout.field_sensors { Touch::PerField } else { Touch::Whole };
        let mut data = MjData::new(model.clone());
        data.forward();
        Jaco {
            model,
            data,
            board: Board { layout, touch, fields },
            tcp,
            pinch,
            torque_sensors,
            touch_readings,
            hand_bodies,
            rng: ChaCha8Rng::seed_from_u64(0),
        }
    }

    pub fn model(&self) -> &Arc<MjModel> {
        &self.model
    }

    pub fn tcp_site(&self) -> usize {
        self.tcp
    }

    /// Grip site position (world, metres).
    pub fn tcp_position(&self) -> [f64; 3] {
        self.data.site_xpos()[self.tcp]
    }

    /// Board width (metres).
    pub fn board_width(&self) -> f64 {
        2.0 * FIELD_HALF * self.board.layout.side as f64
    }

    /// World x, y → board coordinates, as the authors' boards normalize contact positions.
    pub fn world_to_board(&self, p: [f64; 2]) -> BoardPoint {
        board_point(self.board_width(), p)
    }

    /// The push this physics step made, judged from the sensors now and the contacts of before the step.
    fn push(&self, before: &[(i32, i32, [f64; 3])]) -> Option<BoardPoint> {
        let contact_of =
            |geom: usize| before.iter().find(|c| c.0 as usize == geom || c.1 as usize == geom).map(|c| c.2);
        let readings = &self.data.sensordata()[..self.touch_readings];
        let width = self.board_width();
        match self.board.touch {
            Touch::PerField => {
                // numpy's argmax: the first of equal maxima.
                let (k, &most) =
                    readings
                        .iter()
                        .enumerate()
                        .fold((0, &f64::NEG_INFINITY), |best, r| if *r.1 > *best.1 { r } else { best });
                if most <= TOUCH_THRESHOLD {
                    return None;
                }
                contact_of(self.board.fields[k])?;
                let side = self.board.layout.side as f64;
                let (row, col) = ((k / self.board.layout.side) as f64, (k % self.board.layout.side) as f64);
                // The pressed field's centre: the game then makes that field's move.
                Some([(col + 0.5) / side, (row + 0.5) / side])
            }
            Touch::Whole => {
                if readings[0] < TOUCH_THRESHOLD {
                    return None;
                }
                let p = self.board.fields.iter().find_map(|&g| contact_of(g))?;
                let point = board_point(width, [p[0], p[1]]);
                (self.board.layout.makes_move)(point).then_some(point)
            }
        }
    }

    fn contacts(&self) -> Vec<(i32, i32, [f64; 3])> {
        self.data.contact().iter().map(|c| (c.geom1, c.geom2, c.pos)).collect()
    }

    fn reset_arm(&mut self) {
        let mut rng = self.rng.clone();
        random_tcp_pose(&mut self.data, self.tcp, &self.hand_bodies, &mut rng);
        self.rng = rng;
    }
}

pub fn board_point(width: f64, p: [f64; 2]) -> BoardPoint {
    [(p[0] + 0.5 * width) / width, 1.0 - (p[1] + 0.5 * width) / width]
}

impl Manipulator for Jaco {
    fn name(&self) -> &'static str {
        "jaco"
    }

    /// Target joint velocities (rad/s) of the six arm joints and three fingers, the actuators' control ranges.
    fn action_low(&self) -> Vec<f64> {
        self.action_high().iter().map(|v| -v).collect()
    }

    fn action_high(&self) -> Vec<f64> {
        ARM_MAX_VELOCITY.iter().copied().chain([FINGER_MAX_VELOCITY; 3]).collect()
    }

    /// The proprioception the authors' agent sees (dm_control's Jaco observables in their order): sin/cos of the
    /// arm joints (most turn without limit), the joint torques about their axes (N·m), the arm joints'
    /// velocities, the fingers' angles and velocities, and the pinch site's world position (m) and rotation
    /// matrix (row-major).
    fn obs_names(&self) -> Vec<&'static str> {
        OBS_NAMES.to_vec()
    }

    fn observe(&self) -> Vec<f64> {
        let q = self.data.qpos();
        let v = self.data.qvel();
        let readings = self.data.sensordata();
        let mut obs = Vec::with_capacity(OBS_NAMES.len());
        for &angle in &q[..ARM_JOINTS] {
            obs.extend([angle.sin(), angle.cos()]);
        }
        obs.extend(
            self.torque_sensors.iter().map(|&(adr, axis)| (0..3).map(|i| readings[adr + i] * axis[i]).sum::<f64>()),
        );
        obs.extend_from_slice(&v[..ARM_JOINTS]);
        obs.extend_from_slice(&q[ARM_JOINTS..JOINTS]);
        obs.extend_from_slice(&v[ARM_JOINTS..JOINTS]);
        obs.extend_from_slice(&self.data.site_xpos()[self.pinch]);
        obs.extend_from_slice(&self.data.site_xmat()[self.pinch]);
        obs
    }

    fn state_names(&self) -> Vec<&'static str> {
        STATE_NAMES.to_vec()
    }

    /// Joint angles (rad) then velocities (rad/s), arm joints 1-6 then fingers 1-3.
    fn state(&self) -> Vec<f64> {
        self.data.qpos().iter().chain(self.data.qvel()).copied().collect()
    }

    fn state_problem(&self, state: &[f64]) -> Option<String> {
        let limited = [
            (1, super::ik::JOINT_LOW[1], super::ik::JOINT_HIGH[1]),
            (2, super::ik::JOINT_LOW[2], super::ik::JOINT_HIGH[2]),
        ];
        let out_of_range =
            limited.into_iter().chain((ARM_JOINTS..JOINTS).map(|j| (j, 0.15, 1.35))).find_map(|(j, low, high)| {
                let v = *state.get(j)?;
                (!(low..=high).contains(&v)).then(|| {
                    format!(
                        "{} = {v} is outside the joint's range; expected radians in [{low}, {high}]",
                        STATE_NAMES[j]
                    )
                })
            });
        // The joints that turn without limit still need angles a double resolves (sin and cos of 1e300 are
        // noise), and a start faster than ten times what the velocity servos drive is no arm's state: MuJoCo
        // turns it into huge accelerations.
        let turning = [0, 3, 4, 5].map(|j| (j, Domain::closed(-1e3, 1e3).in_unit("rad")));
        let speeds = (0..JOINTS).map(|j| {
            let servo = if j < ARM_JOINTS { ARM_MAX_VELOCITY[j] } else { FINGER_MAX_VELOCITY };
            (JOINTS + j, Domain::closed(-10.0 * servo, 10.0 * servo).in_unit("rad/s"))
        });
        out_of_range.or_else(|| {
            turning.into_iter().chain(speeds).find_map(|(index, domain)| {
                domain.check(STATE_NAMES[index], *state.get(index)?).err().map(|e| e.to_string())
            })
        })
    }

    fn set_state(&mut self, state: &[f64]) {
        self.data.qpos_mut().copy_from_slice(&state[..JOINTS]);
        self.data.qvel_mut().copy_from_slice(&state[JOINTS..2 * JOINTS]);
        self.data.ctrl_mut().fill(0.0);
        self.data.forward();
    }

    /// A fresh simulation (joints at the model's zero pose, at rest) with the arm then placed at a random
    /// TCP pose; the draws for the resets after moves come from a stream seeded here.
    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        self.data.reset();
        self.rng = ChaCha8Rng::seed_from_u64(rng.random());
        random_tcp_pose(&mut self.data, self.tcp, &self.hand_bodies, rng);
    }

    fn step(&mut self, action: &[f64]) -> Option<BoardPoint> {
        let high = self.action_high();
        for ((c, a), h) in self.data.ctrl_mut().iter_mut().zip(action).zip(&high) {
            *c = if a.is_finite() { a.clamp(-h, *h) } else { 0.0 };
        }
        let mut pushed = None;
        for _ in 0..SUBSTEPS {
            let before = if pushed.is_none() { self.contacts() } else { Vec::new() };
            self.data.step();
            if pushed.is_none() {
                pushed = self.push(&before);
                if pushed.is_some() {
                    self.reset_arm();
                }
            }
        }
        pushed
    }

    /// The grip site over the board, in board coordinates.
    fn effector(&self) -> BoardPoint {
        let p = self.tcp_position();
        self.world_to_board([p[0], p[1]])
    }

    fn skill_step_limit(&self) -> usize {
        SKILL_STEP_LIMIT
    }

    fn dt(&self) -> f64 {
        CONTROL_TIMESTEP
    }
}
