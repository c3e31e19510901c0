//! Need `make mujoco` (the feature's build does); they run with `cargo test --features mujoco --lib jaco`.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::scene::{field_centre, scene_xml, Touch};
use crate::envs::boards::{BoardGame, LightsOut, TileSwap};
use crate::envs::embodiments::embodied::EmbodiedBoard;
use crate::envs::embodiments::{BoardLayout, Embodiment, Manipulator};
use crate::envs::Env;

fn lightsout_jaco() -> (Box<dyn Manipulator>, Box<dyn crate::envs::embodiments::ScriptedController>) {
    Embodiment::Jaco.build(&BoardLayout::of(&LightsOut::new(5).unwrap())).unwrap()
}

#[test]
fn scene_has_the_authors_board_geometry() {
    // Row 0 lies on the arm's side (+y), columns grow along +x; 5 fields of 0.1 m centred on the origin.
    assert_eq!(field_centre(5, 0, 0), [-0.2, 0.2]);
    assert_eq!(field_centre(5, 4, 4), [0.2, -0.2]);
    assert_eq!(field_centre(3, 1, 1), [0.0, 0.0]);
    let xml = scene_xml(5, Touch::PerField);
    assert_eq!(xml.matches("<touch ").count(), 25);
    let half = 0.7 * 0.05;
    assert!(xml.contains(&format!(r#"size="{half} {half} 0.005""#)), "sensor sites cover 70 % of a field");
    assert_eq!(scene_xml(3, Touch::Whole).matches("<touch ").count(), 1);
}

#[test]
fn model_has_nine_velocity_actuated_joints_and_the_arena_timestep() {
    let (arm, _) = lightsout_jaco();
    assert_eq!(arm.state_names().len(), 18);
    assert_eq!(arm.action_high().len(), 9);
    assert!((arm.action_high()[0] - 36f64.to_radians()).abs() < 1e-12);
    assert!((arm.action_high()[5] - 48f64.to_radians()).abs() < 1e-12);
    assert_eq!(arm.action_high()[8], 5.0);
    assert_eq!((arm.dt(), arm.skill_step_limit()), (0.1, 50));
}

#[test]
fn reset_puts_the_grip_site_in_the_box_pointing_down() {
    let (mut arm, _) = lightsout_jaco();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..5 {
        arm.reset(&mut rng);
        let obs = arm.observe();
        let n = obs.len();
        // The pinch site's height (its offset from the grip site is 3.4 cm along the downward axis) and its
        // z axis (the rotation matrix's last row's last entry) downwards.
        let (height, down) = (obs[n - 10] + 0.034, -obs[n - 1]);
        // Board coordinates of the box (−0.1, 0.1) on a 0.5 m board: [0.3, 0.7].
        let b = arm.effector();
        assert!((0.3 - 1e-6..=0.7 + 1e-6).contains(&b[0]) && (0.3 - 1e-6..=0.7 + 1e-6).contains(&b[1]), "{b:?}");
        assert!((0.2 - 1e-6..=0.4 + 1e-6).contains(&height), "{height}");
        assert!(down > 1.0 - 1e-6, "hand points down: {down}");
    }
}

#[test]
fn same_seed_same_trajectory_and_state_round_trips() {
    let run = || {
        let (mut arm, mut ctrl) = lightsout_jaco();
        arm.reset(&mut ChaCha8Rng::seed_from_u64(9));
        for _ in 0..5 {
            let a = ctrl.act(arm.as_ref(), [0.1, 0.9]);
            arm.step(&a);
        }
        arm.state()
    };
    let a = run();
    assert_eq!(a, run());
    let (mut arm, _) = lightsout_jaco();
    arm.set_state(&a);
    assert_eq!(arm.state(), a);
}

#[test]
fn zero_action_holds_the_arm_off_the_board() {
    let (mut arm, _) = lightsout_jaco();
    arm.reset(&mut ChaCha8Rng::seed_from_u64(1));
    let start = arm.effector();
    for _ in 0..10 {
        assert_eq!(arm.step(&[0.0; 9]), None);
    }
    let end = arm.effector();
    assert!((end[0] - start[0]).hypot(end[1] - start[1]) < 0.02, "{start:?} -> {end:?}");
}

#[test]
fn scripted_controller_presses_corner_and_centre_fields() {
    let game = LightsOut::new(5).unwrap();
    let (arm, mut ctrl) = lightsout_jaco();
    let mut env = EmbodiedBoard::new(game.clone(), arm, game.goal());
    env.reset(&mut ChaCha8Rng::seed_from_u64(2));
    for mv in [0, 12, 24, 4, 20] {
        let out = env.execute(ctrl.as_mut(), mv);
        assert_eq!(out.performed, Some(mv), "move {mv}: {out:?}");
    }
    assert_eq!(env.board(), game.pressed(&[0, 12, 24, 4, 20]));
}

#[test]
fn tileswap_pushes_swap_at_pivots() {
    let game = TileSwap::new();
    let (arm, mut ctrl) = Embodiment::Jaco.build(&BoardLayout::of(&game)).unwrap();
    let mut env = EmbodiedBoard::new(game.clone(), arm, game.goal());
    env.reset(&mut ChaCha8Rng::seed_from_u64(4));
    for mv in [0, game.num_moves() - 1] {
        let out = env.execute(ctrl.as_mut(), mv);
        assert_eq!(out.performed, Some(mv), "move {mv}: {out:?}");
    }
}

#[test]
fn observation_is_the_authors_proprioception() {
    let (mut arm, _) = lightsout_jaco();
    arm.reset(&mut ChaCha8Rng::seed_from_u64(5));
    // Let the velocity actuators hold the arm against gravity for a control step.
    arm.step(&[0.0; 9]);
    let obs = arm.observe();
    // 6 × (sin, cos), 6 torques, 6 velocities, 3 + 3 fingers, pinch position 3, rotation 9 (dm_control's order).
    assert_eq!((obs.len(), arm.obs_names().len()), (42, 42));
    assert_eq!((arm.obs_names()[12], arm.obs_names()[41]), ("joint_1_torque", "pinch_r22"));
    // The shoulder and elbow carry the arm's weight; the base joint turns about the vertical and carries none of it.
    let torque = &obs[12..18];
    assert!(torque[1].abs() > 1.0 && torque[2].abs() > 0.5, "{torque:?}");
    assert!(torque[0].abs() < 0.1 * torque[1].abs(), "{torque:?}");
    let r = &obs[33..42];
    for i in 0..3 {
        let norm: f64 = (0..3).map(|j| r[3 * i + j] * r[3 * i + j]).sum();
        assert!((norm - 1.0).abs() < 1e-9, "rows of the rotation matrix are unit vectors: {r:?}");
    }
    let p = &obs[30..33];
    assert!((0.15..0.4).contains(&p[2]), "the pinch site is above the board: {p:?}");
}
