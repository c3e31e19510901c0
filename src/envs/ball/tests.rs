use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::camera::CameraModel;
use super::flight::{BallState, FlightParams, GRAVITY};
use super::impact::{ImpactModel, BALL_RADIUS, IMPACT_MATRIX, TABLE_CENTER, TABLE_WIDTH};
use super::integrate::{BallPhysics, SUBSTEP};
use super::launcher::{canonical_spin, wheel_rpm, LaunchParams};
use super::orientation::Orientation;
use super::{augmentation_pivot, rotate_about_z, simulate, BallTrajectory};

fn state(p: [f64; 3], v: [f64; 3], w: [f64; 3]) -> BallState {
    [p[0], p[1], p[2], v[0], v[1], v[2], w[0], w[1], w[2]]
}

fn speed(s: &[f64]) -> f64 {
    (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]).sqrt()
}

fn mid_default_launch() -> LaunchParams {
    LaunchParams::from_actuation(Orientation::Default, [0.125, 0.165, 0.165], 0.5, 0.85)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn drag_slows_a_horizontal_ball_and_dissipates_energy() {
    let flight = FlightParams { k_m: 0.0, ..FlightParams::default() };
    let energy = |s: &BallState| 0.5 * speed(s).powi(2) + GRAVITY * s[2];
    let mut s = state([0.0, 0.0, 1.0], [6.0, 0.0, 0.0], [0.0; 3]);
    for _ in 0..900 {
        let next = flight.rk4_step(&s, SUBSTEP);
        assert!(next[3] < s[3], "horizontal speed must fall: {} → {}", s[3], next[3]);
        assert!(energy(&next) < energy(&s));
        s = next;
    }
    assert!(s[3] < 0.8 * 6.0, "half a second of drag at k_d ≈ 0.097 costs more than 20 %: {}", s[3]);
}

#[test]
fn without_drag_and_spin_the_flight_is_the_closed_form_parabola() {
    let flight = FlightParams { k_d: 0.0, k_m: 0.0, ..FlightParams::default() };
    let (p0, v0, t) = ([0.3, 2.9, -0.1], [0.2, -4.0, 2.8], 0.75);
    let s = flight.integrate(&state(p0, v0, [1.0, 2.0, 3.0]), t, 1350);
    let expected = state(
        [p0[0] + v0[0] * t, p0[1] + v0[1] * t, p0[2] + v0[2] * t - 0.5 * GRAVITY * t * t],
        [v0[0], v0[1], v0[2] - GRAVITY * t],
        [1.0, 2.0, 3.0],
    );
    assert!(max_abs_diff(&s, &expected) < 1e-9, "{s:?} vs {expected:?}");
}

#[test]
fn topspin_makes_the_ball_dip_faster_than_no_spin_and_backspin() {
    let flight = FlightParams::default();
    // Flying along +x, spin along +y moves the ball's top forwards: topspin.
    let height = |w_y: f64| flight.integrate(&state([0.0; 3], [5.0, 0.0, 1.0], [0.0, w_y, 0.0]), 0.4, 720)[2];
    let (top, none, back) = (height(5.0), height(0.0), height(-5.0));
    assert!(top < none - 0.01 && none < back - 0.01, "topspin {top}, none {none}, backspin {back}");
}

#[test]
fn rk4_converges_at_fourth_order_and_is_far_finer_than_the_ekf_euler_step() {
    let flight = FlightParams::default();
    let s0 = mid_default_launch().initial_state();
    let t = 0.5;
    let reference = flight.integrate(&s0, t, 7200);
    let error = |steps: usize| max_abs_diff(&flight.integrate(&s0, t, steps), &reference);
    let ratio = error(45) / error(90);
    assert!((12.0..20.0).contains(&ratio), "halving the step should cut the error ~16×, got {ratio}");

    let rk4_error = error(900);
    let euler = (0..90).fold(s0, |s, _| flight.euler_step(&s, 1.0 / 180.0));
    let euler_error = max_abs_diff(&euler, &reference);
    assert!(rk4_error < 1e-9 && euler_error > 1e-4, "rk4 {rk4_error}, euler {euler_error}");
}

#[test]
fn impact_matrix_keeps_the_entries_the_thesis_discusses() {
    // Guards the transcription of eq. 6.26 against the text of thesis lines 5033-5047.
    let c = IMPACT_MATRIX;
    assert_eq!((c[0][0], c[1][1], c[2][2]), (0.54, 0.55, -0.92));
    assert_eq!((c[0][4], c[1][3]), (0.12, -0.11));
    assert_eq!((c[3][1], c[4][0], c[5][2]), (-1.40, 1.44, 0.15));
    assert_eq!((c[3][3], c[4][4], c[5][5]), (-0.20, -0.12, 1.37));
}

#[test]
fn a_dropped_ball_bounces_at_table_height_with_reversed_vertical_velocity() {
    let physics = BallPhysics::default();
    let plane = TABLE_CENTER[2] + BALL_RADIUS;
    let mut s = state([TABLE_CENTER[0], TABLE_CENTER[1], plane + 0.3], [0.5, -1.0, -1.0], [1.0, 0.5, 0.2]);
    let contact = loop {
        if let Some(found) = physics.locate_contact(&s, SUBSTEP) {
            break found;
        }
        s = physics.flight.rk4_step(&s, SUBSTEP);
        assert!(s[2] > plane - 0.01, "fell through the table");
    };
    let (tau, before) = contact;
    assert!(tau > 0.0 && tau <= SUBSTEP);
    assert!((before[2] - plane).abs() < 1e-9, "contact at z = {}, expected {plane}", before[2]);
    assert!(before[5] < 0.0);
    let after = physics.impact.apply(&before);
    assert!(after[5] > 0.0, "vertical velocity must flip: {} → {}", before[5], after[5]);
    for (row, c_row) in IMPACT_MATRIX.iter().enumerate() {
        let expected: f64 = (0..6).map(|col| c_row[col] * before[3 + col]).sum();
        assert!((after[3 + row] - expected).abs() < 1e-12);
    }

    let mut s = state([TABLE_CENTER[0], TABLE_CENTER[1], plane + 0.3], [0.5, -1.0, -1.0], [1.0, 0.5, 0.2]);
    let mut impacts = Vec::new();
    physics.advance(&mut s, 0.3, 0.0, &mut impacts);
    assert_eq!(impacts.len(), 1);
    assert!(s[2] > plane && s[5] > 0.0);
}

#[test]
fn a_ball_beside_the_table_falls_past_it() {
    let physics = BallPhysics::default();
    let x = TABLE_CENTER[0] + 0.5 * TABLE_WIDTH + 0.1;
    let mut s = state([x, TABLE_CENTER[1], TABLE_CENTER[2] + 0.3], [0.0; 3], [0.0; 3]);
    let mut impacts = Vec::new();
    physics.advance(&mut s, 1.0, 0.0, &mut impacts);
    assert!(impacts.is_empty());
    assert!(s[2] < TABLE_CENTER[2] - 1.0);
}

#[test]
fn wheel_speeds_follow_the_measured_motor_curve() {
    assert_eq!(wheel_rpm([0.15, 0.15, 0.15]), [1316.0, 955.0, 1077.0]);
    let mid = wheel_rpm([0.125, 0.125, 0.125]);
    assert!((mid[0] - 0.5 * (896.0 + 1316.0)).abs() < 1e-9);
    assert_eq!(wheel_rpm([0.0, 2.0, 0.05]), [297.0, 4596.0, 0.0]);
}

#[test]
fn the_bottom_wheel_spins_the_ball_backwards_so_that_it_lifts() {
    let w = canonical_spin([0.0, 0.0, 1000.0]);
    let lift = FlightParams { k_d: 0.0, gravity: 0.0, ..FlightParams::default() }.acceleration(&[5.0, 0.0, 0.0], &w);
    assert!(lift[2] > 0.0 && lift[0].abs() < 1e-12 && lift[1].abs() < 1e-12, "{lift:?}");
}

#[test]
fn default_shots_head_along_minus_y_with_the_recordings_side_info() {
    let launch = mid_default_launch();
    assert!((launch.azimuth.to_degrees() + 88.14).abs() < 0.01, "{}", launch.azimuth.to_degrees());
    let v = launch.velocity();
    assert!(v[1] < -3.0 && v[2] > 2.0 && v[0].abs() < 0.3, "{v:?}");
    assert!((launch.speed - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()).abs() < 1e-12);
    let info = launch.side_info();
    assert!(info[0].abs() < 1e-12 && (info[1] - 1.0).abs() < 1e-12);
    assert_eq!(&info[2..], &[0.5, 0.85, 0.125, 0.165, 0.165]);
    for s_theta in [0.7, 0.85, 1.0] {
        let elevation = LaunchParams::from_actuation(Orientation::Default, [0.125; 3], 0.5, s_theta).elevation;
        assert!((30.9..36.8).contains(&elevation.to_degrees()), "{}", elevation.to_degrees());
    }
}

#[test]
fn a_default_mid_shot_looks_like_the_recordings() {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let launch = mid_default_launch();
    let t = simulate(&launch, &CameraModel::perfect(), &mut rng);
    assert_eq!(t.frame_indices[0], 0);
    assert_eq!(t.impact_times.len(), 1, "{:?}", t.impact_times);
    assert!((0.55..0.85).contains(&t.impact_times[0]), "{:?}", t.impact_times);
    assert!((1.0..1.35).contains(&t.duration()), "{}", t.duration());
    let apex = t.true_states.iter().map(|s| s[2]).fold(f64::MIN, f64::max);
    assert!((0.15..0.6).contains(&(apex - launch.exit_position[2])));

    let k = t.impact_frame.unwrap() as usize;
    assert!(t.times[k] >= t.impact_times[0] && t.times[k - 1] < t.impact_times[0]);
    assert!(t.true_states[k][5] > 0.0 && t.true_states[k - 1][5] < 0.0);

    let table = ImpactModel::default().table;
    for s in t.true_states.iter().filter(|s| table.contains_xy(&s[..])) {
        assert!(s[2] - BALL_RADIUS >= table.z() - 1e-9, "ball inside the table: {s:?}");
    }
}

#[test]
fn every_orientation_mostly_bounces_once_and_lasts_about_a_second() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let camera = CameraModel::default();
    for orientation in Orientation::ALL {
        let runs: Vec<BallTrajectory> =
            (0..40).map(|_| simulate(&LaunchParams::sample(orientation, &mut rng), &camera, &mut rng)).collect();
        let single = runs.iter().filter(|t| t.impact_times.len() == 1).count();
        let long = runs.iter().filter(|t| t.duration() > 0.9).count();
        assert!(single >= 20 && long >= 20, "{orientation}: {single}/40 single bounces, {long}/40 longer than 0.9 s");
    }
}

#[test]
fn trajectories_are_deterministic_per_seed() {
    let run = |seed: u64| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let launch = LaunchParams::sample(Orientation::Unseen(3), &mut rng);
        simulate(&launch, &CameraModel::default(), &mut rng)
    };
    assert_eq!(run(42), run(42));
    assert_ne!(run(42), run(43));
}

#[test]
fn dropouts_occur_at_the_configured_rate() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let single = CameraModel { dropout_prob: 0.05, burst_prob: 0.0, ..CameraModel::default() };
    let mut tracker = single.tracker();
    let seen: Vec<bool> = (0..20_000).map(|_| tracker.next_observed(&mut rng)).collect();
    assert!(seen[0]);
    let rate = seen.iter().filter(|&&s| !s).count() as f64 / seen.len() as f64;
    assert!((0.045..0.055).contains(&rate), "{rate}");

    let bursts = CameraModel { dropout_prob: 0.0, burst_prob: 0.02, burst_len: (3, 5), ..CameraModel::default() };
    let mut tracker = bursts.tracker();
    let seen: Vec<bool> = (0..20_000).map(|_| tracker.next_observed(&mut rng)).collect();
    let runs: Vec<usize> = seen.split(|&s| s).map(|run| run.len()).filter(|&len| len > 0).collect();
    assert!(runs.len() > 100 && runs.iter().all(|&len| len >= 3), "{:?}", &runs[..runs.len().min(20)]);
    let rate = seen.iter().filter(|&&s| !s).count() as f64 / seen.len() as f64;
    assert!((0.05..0.10).contains(&rate), "{rate}");
}

#[test]
fn recordings_keep_lost_frames_visible_and_noise_near_a_millimetre() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let camera = CameraModel::default();
    let mut residuals = Vec::new();
    let mut lost = 0;
    let mut frames = 0;
    for _ in 0..20 {
        let t = simulate(&LaunchParams::sample(Orientation::Default, &mut rng), &camera, &mut rng);
        assert!(t.frame_indices.windows(2).all(|w| w[1] == w[0] + 1));
        assert_eq!((t.times.len(), t.positions.len(), t.true_states.len()), (t.len(), t.len(), t.len()));
        assert!(t.positions[0].is_some());
        assert!(camera.in_bounds(&t.true_states[t.len() - 1][..]));
        for (m, s) in t.positions.iter().zip(&t.true_states) {
            match m {
                Some(m) => residuals.extend((0..3).map(|i| m[i] - s[i])),
                None => lost += 1,
            }
        }
        frames += t.len();
    }
    let std = (residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64).sqrt();
    assert!((0.9e-3..1.1e-3).contains(&std), "noise std {std}");
    let rate = lost as f64 / frames as f64;
    assert!((0.03..0.12).contains(&rate), "lost {rate}");
}

#[test]
fn rotation_preserves_speeds_spins_and_the_lowest_point() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let t = simulate(&LaunchParams::sample(Orientation::Default, &mut rng), &CameraModel::default(), &mut rng);
    let pivot = augmentation_pivot(&t);
    let angle = 1.234;
    let r = rotate_about_z(&t, angle, pivot);
    assert_eq!(augmentation_pivot(&r), pivot);
    for (a, b) in t.true_states.iter().zip(&r.true_states) {
        assert!((speed(a) - speed(b)).abs() < 1e-12);
        assert!((speed(&a[3..]) - speed(&b[3..])).abs() < 1e-12, "spin magnitude");
        assert!((a[2] - b[2]).abs() < 1e-12 && (a[5] - b[5]).abs() < 1e-12 && (a[8] - b[8]).abs() < 1e-12);
    }
    for (a, b) in t.positions.iter().zip(&r.positions) {
        assert_eq!(a.is_some(), b.is_some());
    }
    assert_eq!((&r.frame_indices, r.impact_frame), (&t.frame_indices, t.impact_frame));
    assert!((r.launch.frame_yaw - (t.launch.frame_yaw + angle)).abs() < 1e-12);
    let v0 = r.launch.initial_state();
    assert!(max_abs_diff(&v0[..6], &r.true_states[0][..6]) < 1e-9 || t.frame_indices[0] > 0);

    let back = rotate_about_z(&r, -angle, pivot);
    assert!(t.true_states.iter().zip(&back.true_states).all(|(a, b)| max_abs_diff(a, b) < 1e-12));
}

#[test]
fn orientation_names_round_trip_and_bad_names_fail_in_one_line() {
    for o in Orientation::ALL {
        assert_eq!(Orientation::parse(&o.name()).unwrap(), o);
        let json = serde_json::to_string(&o).unwrap();
        assert_eq!(serde_json::from_str::<Orientation>(&json).unwrap(), o);
    }
    assert_eq!("unseen-4".parse::<Orientation>().unwrap(), Orientation::Unseen(4));
    for bad in ["", "unseen-0", "unseen-6", "unseen-", "Default", "unseen-1x", "foo"] {
        let message = Orientation::parse(bad).unwrap_err().to_string();
        assert!(!message.contains('\n'), "{message}");
        assert!(
            message.contains("default") && message.contains("unseen-1") && message.contains("unseen-5"),
            "{message}"
        );
    }
    assert!(serde_json::from_str::<Orientation>("\"unseen-7\"").is_err());
}

#[test]
fn launch_params_and_trajectories_round_trip_through_json() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let t = simulate(&LaunchParams::sample(Orientation::Unseen(5), &mut rng), &CameraModel::default(), &mut rng);
    let json = serde_json::to_string(&t).unwrap();
    let back: BallTrajectory = serde_json::from_str(&json).unwrap();
    assert_eq!(
        (&back.frame_indices, &back.launch.orientation, back.impact_frame),
        (&t.frame_indices, &t.launch.orientation, t.impact_frame)
    );
    assert!(t.true_states.iter().zip(&back.true_states).all(|(a, b)| max_abs_diff(a, b) < 1e-12));
    assert!(t.positions.iter().zip(&back.positions).all(|(a, b)| match (a, b) {
        (Some(a), Some(b)) => max_abs_diff(a, b) < 1e-12,
        (a, b) => a.is_none() && b.is_none(),
    }));
}
