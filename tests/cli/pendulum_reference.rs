//! Pendulum stepping against gym Pendulum-v0 reference values.
//!
//! `fixtures/pendulum_reference.csv` is written by `fixtures/pendulum_reference.py`, which evaluates the
//! published Pendulum-v0 equations directly in Python floats (its docstring has the derivation):
//!   u = clip(f·u, −2, 2); r = −(angle_normalize(θ)² + 0.1·θ̇² + 0.001·u²);
//!   θ̇' = θ̇ + (−3g/(2l)·sin(θ + π) + 3/(m l²)·u)·dt; θ' = θ + θ̇'·dt; θ̇' = clip(θ̇', −8, 8)
//! for 60-step random action sequences (actions in [−3, 3] to exercise clipping) of the standard,
//! light (m = 0.2), heavy (m = 1.5) and inverted (f = −1) pendulum.

use mbrl::envs::pendulum::{env_step, PendulumVariant};

struct Row {
    variant: String,
    sequence: u32,
    t: u32,
    state: [f64; 2],
    action: f64,
    reward: f64,
    next: [f64; 2],
}

fn rows() -> Vec<Row> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/pendulum_reference.csv");
    let mut reader = csv::Reader::from_path(path).unwrap();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            let f = |i: usize| r[i].parse::<f64>().unwrap();
            Row {
                variant: r[0].to_string(),
                sequence: r[1].parse().unwrap(),
                t: r[2].parse().unwrap(),
                state: [f(3), f(4)],
                action: f(5),
                reward: f(6),
                next: [f(7), f(8)],
            }
        })
        .collect()
}

fn params(variant: &str) -> mbrl::envs::pendulum::PendulumParams {
    let (_, v) = variant.split_once(':').unwrap_or((variant, ""));
    PendulumVariant::parse(v).unwrap().fixed_params()
}

#[test]
fn single_steps_match_reference_to_1e_12() {
    let rows = rows();
    assert_eq!(rows.len(), 720);
    for row in &rows {
        let mut state = row.state;
        let reward = env_step(&params(&row.variant), &mut state, row.action);
        let ctx = format!("{} seq {} t {}", row.variant, row.sequence, row.t);
        assert!((reward - row.reward).abs() <= 1e-12, "{ctx}: reward {reward} vs {}", row.reward);
        assert!((state[0] - row.next[0]).abs() <= 1e-12, "{ctx}: theta {} vs {}", state[0], row.next[0]);
        assert!((state[1] - row.next[1]).abs() <= 1e-12, "{ctx}: theta_dot {} vs {}", state[1], row.next[1]);
    }
}

#[test]
fn whole_sequences_match_reference_to_1e_12() {
    let rows = rows();
    let mut state = [0.0; 2];
    for row in &rows {
        if row.t == 0 {
            state = row.state;
        }
        let reward = env_step(&params(&row.variant), &mut state, row.action);
        assert!((reward - row.reward).abs() <= 1e-12);
        assert!(
            (state[0] - row.next[0]).abs() <= 1e-12 && (state[1] - row.next[1]).abs() <= 1e-12,
            "{} seq {} drifted at t {}",
            row.variant,
            row.sequence,
            row.t
        );
    }
}

#[test]
fn clipping_cases_are_covered_by_the_fixture() {
    let rows = rows();
    assert!(rows.iter().any(|r| r.action.abs() > 2.0), "actions beyond the torque limit");
    assert!(rows.iter().any(|r| r.next[1].abs() == 8.0), "velocities at the speed limit");
}
