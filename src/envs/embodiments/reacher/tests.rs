use std::f64::consts::{PI, TAU};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::envs::embodiments::manipulator::{BoardPoint, Manipulator, ScriptedController};

fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
    (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
}

#[test]
fn derived_masses_and_reach() {
    let i = ArmInertia::dm_control();
    assert!((i.shoulder_link - 2.1411e-4).abs() < 1e-8, "{i:?}");
    assert!((i.wrist_link - 1.8867e-4).abs() < 1e-8, "{i:?}");
    assert!((i.distal_mass - 0.039794).abs() < 1e-6, "{i:?}");
    assert!((i.distal_moment - 2.2829e-3).abs() < 1e-7, "{i:?}");
    assert!((min_reach() - 0.24 * (80.0f64).to_radians().cos()).abs() < 1e-12);
    // Every board corner is within reach.
    assert!(BOARD_HALF_EXTENT * 2f64.sqrt() < MAX_REACH);
}

#[test]
fn forward_kinematics_and_board_frame() {
    let cases = [
        ([0.0, 0.0], [0.24, 0.0]),
        ([PI / 2.0, 0.0], [0.0, 0.24]),
        ([0.0, PI / 2.0], [0.12, 0.12]),
        ([PI / 2.0, -PI / 2.0], [0.12, 0.12]),
        ([PI, 0.0], [-0.24, 0.0]),
    ];
    for (q, p) in cases {
        assert!(close(finger_position(q), p, 1e-12), "{q:?}");
    }
    assert!(close(arm_to_board([0.0, 0.0]), [0.5, 0.5], 1e-12));
    assert!(close(arm_to_board([0.15, 0.15]), [1.0, 1.0], 1e-12), "arm +y is board down (rows grow)");
    assert!(close(arm_to_board([-0.15, -0.15]), [0.0, 0.0], 1e-12));
    assert!(close(arm_to_board([0.15, -0.15]), [1.0, 0.0], 1e-12));
    let b = [0.3, 0.8];
    assert!(close(arm_to_board(board_to_arm(b)), b, 1e-12));
    let mut arm = Reacher::new();
    arm.set_state(&[0.0, PI / 2.0, 0.0, 0.0]);
    assert!(close(arm.effector(), [0.9, 0.9], 1e-12));
    assert_eq!(arm.observe().len(), arm.obs_names().len());
    // Finger velocity matches a finite difference.
    arm.set_state(&[0.3, 0.7, 1.3, -0.4]);
    let v = arm.finger_velocity();
    let eps = 1e-7;
    let p0 = finger_position([0.3, 0.7]);
    let p1 = finger_position([0.3 + 1.3 * eps, 0.7 - 0.4 * eps]);
    assert!(close(v, [(p1[0] - p0[0]) / eps, (p1[1] - p0[1]) / eps], 1e-6));
}

/// Largest relative kinetic-energy error over `duration` seconds of free, undamped motion.
fn energy_error(h: f64, duration: f64) -> f64 {
    let mut arm = Reacher::new();
    arm.damping = 0.0;
    arm.set_state(&[0.4, 0.5, 2.0, 1.0]);
    let e0 = arm.kinetic_energy();
    let mut worst: f64 = 0.0;
    for _ in 0..(duration / h).round() as usize {
        arm.integrate([0.0, 0.0], h);
        assert!(arm.joint_angles()[1].abs() < WRIST_LIMIT, "test motion must not touch the stop");
        worst = worst.max((arm.kinetic_energy() - e0).abs() / e0);
    }
    worst
}

#[test]
fn kinetic_energy_is_conserved_without_torque_and_damping() {
    // 100 control steps (4 s). Semi-implicit Euler with a configuration-dependent mass matrix (MuJoCo's
    // Euler, too) slowly gains energy in undamped motion, about 2.5 %/s here, negligible next to the
    // real damping (time constants 0.02 to 0.15 s). The error shrinks in proportion to the step (first
    // order), which it would not if the equations of motion were wrong.
    let duration = 100.0 * TIMESTEP * ACTION_REPEAT as f64;
    let coarse = energy_error(TIMESTEP, duration);
    let fine = energy_error(TIMESTEP / 8.0, duration);
    assert!(coarse < 0.15, "relative energy error {coarse}");
    assert!(fine < 0.02 && fine < coarse / 5.0, "error {fine} at h/8 vs {coarse}");
    // A rigid spin of the stretched arm keeps its energy exactly.
    let mut arm = Reacher::new();
    arm.damping = 0.0;
    arm.set_state(&[0.0, 0.0, 3.0, 0.0]);
    let e0 = arm.kinetic_energy();
    for _ in 0..100 {
        arm.step(&[0.0, 0.0, -1.0]);
    }
    assert!((arm.kinetic_energy() - e0).abs() < 1e-12 * e0);
    // With damping the energy only decreases.
    let mut arm = Reacher::new();
    arm.set_state(&[0.4, 0.5, 2.0, 1.0]);
    let mut e = arm.kinetic_energy();
    for _ in 0..50 {
        arm.step(&[0.0, 0.0, -1.0]);
        let next = arm.kinetic_energy();
        assert!(next <= e);
        e = next;
    }
    assert!(e < 0.01 * e0);
}

#[test]
fn full_torque_reaches_the_damping_limited_speed() {
    // Terminal joint speed gear/damping = 5 rad/s.
    let mut arm = Reacher::new();
    for _ in 0..100 {
        arm.step(&[1.0, 0.0, -1.0]);
    }
    let v = arm.joint_velocities();
    assert!((v[0] - GEAR / DAMPING).abs() < 0.01, "{v:?}");
}

#[test]
fn full_torque_holds_the_wrist_where_the_limit_spring_balances_it() {
    // Static balance of MuJoCo's limit row: torque = K·d·violation / R, with K = 1/(0.95·0.04)², d = 0.95
    // and R = (0.05/0.95)·(M⁻¹)₂₂ at rest, so the wrist rests 0.083 rad (4.75°) past each stop.
    let inverse_at_rest = {
        let m = Reacher::new().mass_matrix(0.0);
        m[0][0] / (m[0][0] * m[1][1] - m[0][1] * m[1][0])
    };
    let stiffness = 1.0 / (0.95f64 * 0.04).powi(2);
    let expected = GEAR * (0.05 / 0.95 * inverse_at_rest) / (stiffness * 0.95);
    assert!((expected - 0.08296).abs() < 1e-4, "{expected}");
    for side in [1.0, -1.0] {
        let mut arm = Reacher::new();
        arm.set_state(&[0.0, side * 2.5, 0.0, side * 4.0]);
        for _ in 0..100 {
            arm.step(&[0.0, side, -1.0]);
        }
        let violation = side * arm.joint_angles()[1] - WRIST_LIMIT;
        assert!((violation - expected).abs() < 1e-3, "side {side}: {violation} past the stop, expected {expected}");
        assert!(arm.joint_velocities()[1].abs() < 1e-3);
    }
}

#[test]
fn reset_leaves_the_wrist_draw_past_the_stop_and_the_limit_brings_it_back() {
    let mut arm = Reacher::new();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut beyond = 0;
    for _ in 0..1000 {
        arm.reset(&mut rng);
        let q = arm.joint_angles();
        assert!((0.0..TAU).contains(&q[1]) && (0.0..TAU).contains(&q[0]));
        beyond += (q[1] > WRIST_LIMIT) as usize;
    }
    // (360 − 160)/360 = 56 % of draws.
    assert!((500..620).contains(&beyond), "{beyond}");
    arm.set_state(&[1.0, 6.0, 0.0, 0.0]);
    for _ in 0..30 {
        arm.step(&[0.0, 0.0, -1.0]);
    }
    assert!(arm.joint_angles()[1] <= WRIST_LIMIT + 1e-3, "{:?}", arm.joint_angles());
}

#[test]
fn same_seed_same_trajectory() {
    let run = |seed: u64| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut arm = Reacher::new();
        arm.reset(&mut rng);
        let mut states = vec![];
        for _ in 0..40 {
            let a = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
            arm.step(&a);
            states.push(arm.state());
        }
        states
    };
    assert_eq!(run(3), run(3));
    assert_ne!(run(3), run(4));
    // set_state restores the trajectory exactly.
    let mut a = Reacher::new();
    a.set_state(&[1.0, -0.5, 2.0, 3.0]);
    let saved = a.state();
    a.step(&[0.2, -0.7, 0.0]);
    let after = a.state();
    let mut b = Reacher::new();
    b.set_state(&saved);
    b.step(&[0.2, -0.7, 0.0]);
    assert_eq!(b.state(), after);
}

#[test]
fn pushes_count_only_on_the_board_and_above_the_threshold() {
    let mut arm = Reacher::new();
    // Stretched along +x: finger at x = 0.24 > 0.15, off the board.
    arm.set_state(&[0.0, 0.0, 0.0, 0.0]);
    assert_eq!(arm.step(&[0.0, 0.0, 1.0]), None);
    assert!(arm.effector()[0] > 1.0);
    // Folded to (0.12, 0.12): on the board.
    arm.set_state(&[0.0, PI / 2.0, 0.0, 0.0]);
    assert_eq!(arm.step(&[0.0, 0.0, PUSH_THRESHOLD]), None, "threshold is strict");
    let p = arm.step(&[0.0, 0.0, 0.61]).expect("on the board");
    assert!(close(p, [0.9, 0.9], 1e-12));
}

/// The authors' map: finger at arm (x, y) → ((x + 0.15)/0.3, (y + 0.15)/0.3), then their LightsOut
/// digitize. A finger at (0.12, 0.12) (shoulder 0, wrist 90°) is at board (0.9, 0.9): row 4, column 4;
/// one at (0.12, −0.12) (shoulder −90°, wrist 90°) at (0.9, 0.1): row 0, column 4.
#[test]
fn finger_maps_to_the_authors_field() {
    use crate::envs::boards::{BoardGame, LightsOut};
    let game = LightsOut::new(5).unwrap();
    let mut arm = Reacher::new();
    arm.set_state(&[0.0, PI / 2.0, 0.0, 0.0]);
    assert_eq!(game.move_at(arm.effector()), Some(4 * 5 + 4));
    arm.set_state(&[-PI / 2.0, PI / 2.0, 0.0, 0.0]);
    assert!(close(arm.finger(), [0.12, -0.12], 1e-12));
    assert_eq!(game.move_at(arm.effector()), Some(4));
    // Shoulder 90°, stretched: finger at (0, 0.24), beyond the board's +y edge (0.15): row index > 1.
    arm.set_state(&[PI / 2.0, 0.0, 0.0, 0.0]);
    assert!(arm.effector()[1] > 1.0);
}

/// Runs the controller from `start` to `target`; returns the push point and steps, if it pushed.
fn episode(ctrl: &mut ReacherController, start: &[f64], target: BoardPoint) -> Option<(BoardPoint, usize)> {
    let mut arm = Reacher::new();
    arm.set_state(start);
    ctrl.reset();
    (1..=SKILL_STEP_LIMIT).find_map(|step| {
        let a = ctrl.act(&arm, target);
        arm.step(&a).map(|p| (p, step))
    })
}

/// 2000 random targets in [0.05, 0.95]²; the arm is reset before every fourth move and otherwise
/// starts where the previous push left it (the game does not reset it after a move).
#[test]
fn controller_pushes_random_targets_within_the_skill_limit() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut ctrl = ReacherController::new();
    let mut arm = Reacher::new();
    let (trials, mut ok, mut steps, mut unreachable) = (2000, 0, 0, 0);
    for trial in 0..trials {
        if trial % 4 == 0 {
            arm.reset(&mut rng);
        }
        let target = [rng.random_range(0.05..0.95), rng.random_range(0.05..0.95)];
        let t = board_to_arm(target);
        let reachable = t[0].hypot(t[1]) >= min_reach();
        unreachable += !reachable as usize;
        ctrl.reset();
        let pushed = (1..=SKILL_STEP_LIMIT).find_map(|step| {
            let a = ctrl.act(&arm, target);
            arm.step(&a).map(|p| (p, step))
        });
        let Some((p, n)) = pushed else { continue };
        let good = if reachable {
            (p[0] - target[0]).hypot(p[1] - target[1]) <= ctrl.tolerance
        } else {
            // The nearest reachable point lies at most r_min/√2 from the target in the max-norm.
            let bound = min_reach() / 2f64.sqrt() / (2.0 * BOARD_HALF_EXTENT);
            (p[0] - target[0]).abs().max((p[1] - target[1]).abs()) <= bound + ReacherController::SHORTFALL_SLACK
        };
        if good {
            ok += 1;
            steps += n;
        }
    }
    let rate = ok as f64 / trials as f64;
    eprintln!(
        "reacher controller: {ok}/{trials} pushed ({unreachable} targets out of reach), mean {:.1} steps",
        steps as f64 / ok as f64
    );
    assert!(rate >= 0.995, "success rate {rate}");
}

#[test]
fn controller_performs_every_lightsout_and_tileswap_move() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut ctrl = ReacherController::new();
    let mut arm = Reacher::new();
    let field = |v: f64| ((v * 5.0).floor() as usize).min(4);
    let mut failures = vec![];
    // LightsOut 5×5: field centres, including the centre field, whose middle is out of reach.
    for r in 0..5 {
        for c in 0..5 {
            let target = [(c as f64 + 0.5) / 5.0, (r as f64 + 0.5) / 5.0];
            for _ in 0..20 {
                arm.reset(&mut rng);
                match episode(&mut ctrl, &arm.state(), target) {
                    Some((p, _)) if field(p[0]) == c && field(p[1]) == r => {}
                    other => failures.push((target, other)),
                }
            }
        }
    }
    // TileSwap 3×3: pivots at the midpoints of interior edges, L1 ≤ 1/6.
    let mut pivots = vec![];
    for i in 0..3 {
        for j in 1..3 {
            pivots.push([(i as f64 + 0.5) / 3.0, j as f64 / 3.0]);
            pivots.push([j as f64 / 3.0, (i as f64 + 0.5) / 3.0]);
        }
    }
    for &target in &pivots {
        for _ in 0..20 {
            arm.reset(&mut rng);
            match episode(&mut ctrl, &arm.state(), target) {
                Some((p, _)) if (p[0] - target[0]).abs() + (p[1] - target[1]).abs() <= 1.0 / 6.0 => {}
                other => failures.push((target, other)),
            }
        }
    }
    assert!(failures.is_empty(), "{} failures: {:?}", failures.len(), &failures[..failures.len().min(5)]);
}

/// The real games through [`EmbodiedBoard`](crate::envs::embodiments::embodied::EmbodiedBoard): every
/// move, one after another without resetting the arm, performs exactly that move.
#[test]
fn executes_every_move_of_the_real_games() {
    use crate::envs::boards::{BoardGame, LightsOut, TileSwap};
    use crate::envs::embodiments::embodied::EmbodiedBoard;
    use crate::envs::Env;

    fn check<G: BoardGame>(game: G) {
        let mut env = EmbodiedBoard::new(game.clone(), Box::new(Reacher::new()), game.goal());
        let mut ctrl = ReacherController::new();
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        for round in 0..4 {
            env.reset(&mut rng);
            for mv in 0..game.num_moves() {
                let before = env.board();
                let out = env.execute(&mut ctrl, mv);
                assert_eq!(out.performed, Some(mv), "{} move {mv}, round {round}", game.name());
                assert_eq!(env.board(), game.apply(before, mv));
            }
        }
    }
    check(LightsOut::new(5).unwrap());
    check(TileSwap::new());
}
