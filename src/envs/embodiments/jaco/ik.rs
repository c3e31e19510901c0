//! Inverse kinematics of the grip site and the random reset pose, after dm_control's
//! `qpos_from_site_pose` (damped least squares on position and orientation error) and
//! `ToolCenterPointInitializer` (uniform TCP target and yaw, IK from the current joints and then from random
//! joints, rejection of poses in collision).

use std::f64::consts::{PI, TAU};

use mujoco_rs::prelude::*;
use nalgebra::{Matrix6, Vector6};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::{ARM_JOINTS, TCP_HIGH, TCP_LOW};

pub type Data = MjData<std::sync::Arc<MjModel>>;

/// The hand pointing straight down (dm_control's `DOWN_QUATERNION`, w x y z).
pub const DOWN_QUATERNION: [f64; 4] = [0.0, std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2, 0.0];
/// Joint ranges the reset samples from: the limited joints' ranges, [0, 2π] for the unlimited ones.
pub const JOINT_LOW: [f64; 6] = [0.0, 0.820305, 0.331613, 0.0, 0.0, 0.0];
pub const JOINT_HIGH: [f64; 6] = [TAU, 5.462881, 5.951573, TAU, TAU, TAU];

/// dm_control's solver settings (`qpos_from_site_pose` defaults, `rot_weight=2` as the arm calls it).
const ROT_WEIGHT: f64 = 2.0;
const REGULARIZATION_THRESHOLD: f64 = 0.1;
const REGULARIZATION_STRENGTH: f64 = 3e-2;
const MAX_UPDATE_NORM: f64 = 2.0;
const MAX_STEPS: usize = 100;
/// Stricter than needed for a start pose and looser than dm_control's 1e-14, which a double-precision
/// Newton iteration reaches or stalls just above.
const TOLERANCE: f64 = 1e-10;
const MAX_IK_ATTEMPTS: usize = 10;
/// dm_control gives up after 10 targets; a reset here must end with a pose, so it tries longer.
const MAX_TARGETS: usize = 200;

pub fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Rotation matrix (row-major, as MuJoCo's xmat) to a unit quaternion.
fn mat_to_quat(m: &[f64; 9]) -> [f64; 4] {
    let trace = m[0] + m[4] + m[8];
    let q = if trace > 0.0 {
        let s = 0.5 / (trace + 1.0).sqrt();
        [0.25 / s, (m[7] - m[5]) * s, (m[2] - m[6]) * s, (m[3] - m[1]) * s]
    } else if m[0] > m[4] && m[0] > m[8] {
        let s = 2.0 * (1.0 + m[0] - m[4] - m[8]).sqrt();
        [(m[7] - m[5]) / s, 0.25 * s, (m[1] + m[3]) / s, (m[2] + m[6]) / s]
    } else if m[4] > m[8] {
        let s = 2.0 * (1.0 + m[4] - m[0] - m[8]).sqrt();
        [(m[2] - m[6]) / s, (m[1] + m[3]) / s, 0.25 * s, (m[5] + m[7]) / s]
    } else {
        let s = 2.0 * (1.0 + m[8] - m[0] - m[4]).sqrt();
        [(m[3] - m[1]) / s, (m[2] + m[6]) / s, (m[5] + m[7]) / s, 0.25 * s]
    };
    let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / norm)
}

/// Angular velocity that turns `from` into `to` in unit time (MuJoCo's `mju_subQuat` convention).
fn rotation_error(to: [f64; 4], from: [f64; 4]) -> [f64; 3] {
    let conj = [from[0], -from[1], -from[2], -from[3]];
    let mut d = quat_mul(to, conj);
    if d[0] < 0.0 {
        d = d.map(|v| -v);
    }
    let sin = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
    if sin < 1e-15 {
        return [0.0; 3];
    }
    let angle = 2.0 * sin.atan2(d[0]);
    [d[1] / sin * angle, d[2] / sin * angle, d[3] / sin * angle]
}

/// Position and orientation Jacobian rows of `site` for the arm joints (the first six dofs).
pub fn site_jacobian(data: &Data, site: usize) -> (Vec<f64>, Vec<f64>) {
    let nv = data.model().ffi().nv as usize;
    let (p, r) = data.jac_site(true, true, site);
    let pick = |full: Vec<f64>| {
        (0..3).flat_map(|i| (0..ARM_JOINTS).map(move |j| (i, j))).map(|(i, j)| full[i * nv + j]).collect()
    };
    (pick(p), pick(r))
}

/// Damped least squares for `J x = e` (6 × 6 over the arm joints).
pub fn solve_dls(jp: &[f64], jr: &[f64], e: [f64; 6], rot_weight: f64, damping: f64) -> [f64; 6] {
    let jac =
        Matrix6::from_fn(|i, j| if i < 3 { jp[i * ARM_JOINTS + j] } else { rot_weight * jr[(i - 3) * ARM_JOINTS + j] });
    let err = Vector6::from_fn(|i, _| if i < 3 { e[i] } else { rot_weight * e[i] });
    let lhs = jac.transpose() * jac + Matrix6::identity() * damping;
    let rhs = jac.transpose() * err;
    lhs.lu().solve(&rhs).map(|x| [x[0], x[1], x[2], x[3], x[4], x[5]]).unwrap_or([0.0; 6])
}

/// Moves the arm joints so that `site` reaches `pos` with orientation `quat`; true on success.
fn solve_pose(data: &mut Data, site: usize, pos: [f64; 3], quat: [f64; 4]) -> bool {
    for _ in 0..MAX_STEPS {
        data.kinematics();
        data.com_pos();
        let (err, norm) = pose_error(data, site, pos, quat);
        if norm < TOLERANCE {
            return true;
        }
        let (jp, jr) = site_jacobian(data, site);
        let damping = if norm >= REGULARIZATION_THRESHOLD { REGULARIZATION_STRENGTH } else { 0.0 };
        let mut update = solve_dls(&jp, &jr, err, ROT_WEIGHT, damping);
        let size = update.iter().map(|u| u * u).sum::<f64>().sqrt();
        if size > MAX_UPDATE_NORM {
            update = update.map(|u| u * MAX_UPDATE_NORM / size);
        }
        let qpos = data.qpos_mut();
        for (q, u) in qpos.iter_mut().zip(update) {
            *q += u;
        }
    }
    data.kinematics();
    pose_error(data, site, pos, quat).1 < TOLERANCE
}

fn pose_error(data: &Data, site: usize, pos: [f64; 3], quat: [f64; 4]) -> ([f64; 6], f64) {
    let x = data.site_xpos()[site];
    let r = rotation_error(quat, mat_to_quat(&data.site_xmat()[site]));
    let e = [pos[0] - x[0], pos[1] - x[1], pos[2] - x[2], r[0], r[1], r[2]];
    let norm = (e[..3].iter().map(|v| v * v).sum::<f64>()
        + ROT_WEIGHT * ROT_WEIGHT * e[3..].iter().map(|v| v * v).sum::<f64>())
    .sqrt();
    (e, norm)
}

/// IK with restarts from random joints; the joints end canonicalized into [`JOINT_LOW`], [`JOINT_HIGH`].
fn set_site_pose(data: &mut Data, site: usize, pos: [f64; 3], quat: [f64; 4], rng: &mut ChaCha8Rng) -> bool {
    for _ in 0..MAX_IK_ATTEMPTS {
        if solve_pose(data, site, pos, quat) {
            let qpos = data.qpos_mut();
            let canonical = (0..ARM_JOINTS).all(|j| {
                qpos[j] = JOINT_LOW[j] + (qpos[j] - JOINT_LOW[j]).rem_euclid(TAU);
                qpos[j] <= JOINT_HIGH[j]
            });
            if canonical {
                return true;
            }
        }
        let qpos = data.qpos_mut();
        for j in 0..ARM_JOINTS {
            qpos[j] = rng.random_range(JOINT_LOW[j]..JOINT_HIGH[j]);
        }
    }
    false
}

/// Puts the grip site at a random pose of the reset box, pointing down with a uniform yaw, without
/// collisions other than between the hand's own parts. Returns false (joints unchanged) when no pose was
/// found.
pub fn random_tcp_pose(data: &mut Data, site: usize, hand_bodies: &[usize], rng: &mut ChaCha8Rng) -> bool {
    let start: Vec<f64> = data.qpos()[..ARM_JOINTS].to_vec();
    for _ in 0..MAX_TARGETS {
        let pos: [f64; 3] = std::array::from_fn(|i| rng.random_range(TCP_LOW[i]..TCP_HIGH[i]));
        let yaw: f64 = rng.random_range(-PI..PI);
        let turn = [(0.5 * yaw).cos(), 0.0, 0.0, (0.5 * yaw).sin()];
        if set_site_pose(data, site, pos, quat_mul(turn, DOWN_QUATERNION), rng) {
            data.forward();
            if !in_collision(data, hand_bodies) {
                return true;
            }
        }
        data.qpos_mut()[..ARM_JOINTS].copy_from_slice(&start);
    }
    data.forward();
    false
}

/// Whether any touching contact involves something other than two of the hand's parts.
fn in_collision(data: &Data, hand_bodies: &[usize]) -> bool {
    let body_of = data.model().geom_bodyid();
    data.contact().iter().any(|c| {
        let in_hand = |g: i32| hand_bodies.contains(&(body_of[g as usize] as usize));
        c.dist <= 0.0 && !(in_hand(c.geom1) && in_hand(c.geom2))
    })
}
