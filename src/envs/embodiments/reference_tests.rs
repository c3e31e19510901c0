//! Replays the reference recordings ([`super::reference_cases`]) through mbrl's embodied games: same
//! manipulator states, same pushed fields, same remaining time and skill ends, step for step.

use super::embodied::EmbodiedBoard;
use super::layout::BoardLayout;
use super::reference_cases::{Pushed, ReferenceCase, REFERENCE_CASES};
use super::Embodiment;
use crate::envs::boards::{BoardGame, LightsOut, TileSwap};
use crate::envs::Env;

/// The Reacher's angles and velocities agree with MuJoCo's to 1e-12 over every recorded sequence, except
/// for an arm coming to rest inside the limit's first millimetre-radian (solimp's sigmoid band), where
/// velocities of 1e-10 rad/s differ in their last digits.
const REACHER_TOLERANCE: f64 = 1e-10;

fn replay<G: BoardGame>(
    game: G,
    embodiment: Embodiment,
    case: &ReferenceCase,
    pushed: impl Fn(usize) -> Pushed,
) -> Vec<String> {
    let goal = game.goal();
    let manipulator = embodiment.build(&BoardLayout::of(&game)).unwrap().0;
    let mut env = EmbodiedBoard::new(game, manipulator, goal);
    env.set_manipulator_state(case.start);
    env.start_skill();
    let tolerance = if embodiment == Embodiment::Reacher { REACHER_TOLERANCE } else { 0.0 };
    let mut problems = Vec::new();
    for (t, expected) in case.steps.iter().enumerate() {
        if expected.new_skill {
            env.start_skill();
        }
        let before = env.board();
        let step = env.step(&expected.action);
        let state = env.state();
        let manipulator = &state[..expected.state.len()];
        let worst = manipulator.iter().zip(expected.state).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        if worst > tolerance || manipulator.iter().any(|v| !v.is_finite()) {
            problems.push(format!("step {}: state {manipulator:?}, reference {:?}", t + 1, expected.state));
        }
        let did = if env.board() == before {
            Pushed::Nothing
        } else {
            let mv = (0..env.game().num_moves()).find(|&m| env.game().apply(before, m) == env.board());
            mv.map_or(Pushed::Nothing, &pushed)
        };
        if did != expected.pushed {
            problems.push(format!("step {}: pushed {did:?}, reference {:?}", t + 1, expected.pushed));
        }
        let remaining = *step.obs.last().unwrap();
        if remaining != expected.remaining || step.done != expected.done {
            problems.push(format!(
                "step {}: remaining {remaining}, done {}; reference {}, {}",
                t + 1,
                step.done,
                expected.remaining,
                expected.done
            ));
        }
    }
    problems
}

#[test]
fn every_reference_step_is_reproduced() {
    let mut failures = Vec::new();
    for case in REFERENCE_CASES {
        let (game, embodiment) = case.env.split_once(':').unwrap();
        let embodiment = Embodiment::parse(embodiment).unwrap();
        let problems = match game {
            "lightsout" => replay(LightsOut::new(5).unwrap(), embodiment, case, Pushed::Field),
            "tileswap" => {
                let game = TileSwap::new();
                let pairs: Vec<_> = (0..game.num_moves()).map(|m| game.pair(m)).collect();
                replay(game, embodiment, case, |m| {
                    let (a, b) = pairs[m];
                    Pushed::Swap(a.min(b), a.max(b))
                })
            }
            other => panic!("unknown game {other}"),
        };
        failures.extend(problems.into_iter().map(|p| format!("{}: {p}", case.name)));
    }
    assert!(failures.is_empty(), "{} mismatch(es):\n{}", failures.len(), failures.join("\n"));
}

/// The cases the reference cares about most, checked by name so that a regenerated table cannot drop them.
#[test]
fn the_table_covers_clipping_threshold_time_and_the_wrist_stop() {
    let names: Vec<&str> = REFERENCE_CASES.iter().map(|c| c.name).collect();
    for wanted in [
        "cursor_x0_three_clips_push",
        "cursor_x1_three_clips_push",
        "cursor_threshold_exact_no_push",
        "remaining_time_cursor_two_skills",
        "remaining_time_reacher_change_at_step7",
        "reacher_r1_plus_stop_and_back",
        "reacher_r2_minus_stop_and_back",
        "reacher_r3_fast_plus_stop_both_full",
        "reacher_start_beyond_plus_stop",
    ] {
        assert!(names.contains(&wanted), "{wanted} missing");
    }
}
