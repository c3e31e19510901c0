//! The verdict rules applied to slices: numbers that should and should not reproduce each claim.

use super::super::ball_compare::HorizonComparison;
use super::super::quick::*;
use super::super::verdict::Verdict;

fn ball(lose_at: &[(&str, f64)], p: f64) -> BallSlice {
    let mut horizons = Vec::new();
    for group in ["default", "unseen"] {
        for k in 1..=10 {
            let h = k as f64 / 10.0;
            let lost = lose_at.iter().any(|&(g, at)| g == group && (at - h).abs() < 1e-9);
            horizons.push(HorizonComparison {
                group: group.into(),
                horizon_s: h,
                n: 30,
                ekf_median: if lost { 0.2 } else { 0.1 },
                baseline_median: 0.15,
                oracle_median: Some(0.05),
                p_value: Some(if lost { 0.9 } else { p }),
            });
        }
    }
    BallSlice {
        train_steps: 150,
        first_loss: -7.0,
        last_loss: -8.0,
        trained: Some(0.1),
        ridge: Some(0.15),
        oracle: Some(0.05),
        horizons,
        claim: None,
    }
}

#[test]
fn the_ekf_must_win_at_1s_on_both_pose_sets_and_at_every_unseen_horizon() {
    let all = ball(&[], 1e-4).judge();
    assert_eq!(all.verdict, Verdict::Reproduced);
    assert_eq!(all.reason, "all 11 comparisons (p ≤ 1.0e-4, n ≥ 30)");
    // Fig. 6.6 is drawn on unseen poses only: losing at a short horizon on default poses decides nothing...
    let b = ball(&[("default", 0.3)], 1e-4);
    assert_eq!(b.judge().verdict, Verdict::Reproduced);
    // ...but the summary still says where the baseline wins.
    assert_eq!(
        b.horizon_summary(),
        "EKF median lower at 9/10 on default poses (ridge lower at 0.3 s) and 10/10 on unseen poses"
    );
    let miss = ball(&[("default", 1.0)], 1e-4).judge();
    assert_eq!(miss.verdict, Verdict::NotAtThisScale);
    assert!(miss.reason.contains("default 1.0 s"), "{}", miss.reason);
    assert_eq!(ball(&[("unseen", 0.4)], 1e-4).judge().verdict, Verdict::NotAtThisScale);
    // Lower everywhere, but not significantly.
    assert_eq!(ball(&[], 0.2).judge().verdict, Verdict::NotAtThisScale);
    // A summary from before the per-horizon comparison has nothing to test.
    let old = BallSlice { horizons: Vec::new(), ..ball(&[], 1e-4) };
    assert_eq!(old.judge().verdict, Verdict::SmokeTestOnly);
}

#[test]
fn one_dlgpd_run_per_setting_is_a_smoke_test_whatever_it_shows() {
    let run = |success| Some(DlgpdRun { total_return: if success { -400.0 } else { -1200.0 }, success });
    for success in [true, false] {
        let d = DlgpdSlice {
            transitions: 100,
            matching: run(success),
            mismatching: run(false),
            runs_per_setting: 1,
            claim: None,
        };
        let claim = d.judge();
        assert_eq!(claim.verdict, Verdict::SmokeTestOnly);
        assert!(claim.scale.starts_with("1 run per setting"), "{}", claim.scale);
    }
}

fn tradyn(tasks: usize, failures: usize, p: f64) -> TradynSlice {
    let variant = |name: &str, energy| TradynVariantSlice {
        variant: name.into(),
        median_energy: energy,
        median_distance: 0.02,
        failures: if name == "+T,+C" { failures } else { 0 },
    };
    TradynSlice {
        variants: vec![variant("−T,−C", 6.0), variant("−T,+C", 7.0), variant("+T,−C", 5.0), variant("+T,+C", 4.0)],
        tasks,
        p_energy_vs_no_terrain: Some(p),
        p_energy_vs_no_calibration: Some(p),
        claim: None,
    }
}

#[test]
fn four_tradyn_tasks_are_too_few_and_thirty_can_reproduce_or_miss() {
    assert_eq!(tradyn(4, 0, 0.0625).judge().verdict, Verdict::SmokeTestOnly);
    assert_eq!(tradyn(4, 2, 0.3).judge().verdict, Verdict::SmokeTestOnly);
    assert_eq!(tradyn(30, 0, 0.01).judge().verdict, Verdict::Reproduced);
    assert_eq!(tradyn(30, 1, 0.01).judge().verdict, Verdict::NotAtThisScale);
    assert_eq!(tradyn(30, 0, 0.2).judge().verdict, Verdict::NotAtThisScale);
}

#[test]
fn swing_ups_seads_boards_and_the_scripted_reacher() {
    let swing =
        |successes| SwingupSlice { candidates: 1000, horizon: 20, iterations: 10, successes, episodes: 5, claim: None };
    assert_eq!(swing(5).judge().verdict, Verdict::Reproduced);
    assert_eq!(swing(4).judge().verdict, Verdict::NotAtThisScale);
    let pets = PetsSlice {
        train_steps: 1500,
        transitions: 5400,
        best_valid_loss: None,
        candidates: 400,
        horizon: 20,
        iterations: 10,
        particles: 5,
        successes: 3,
        episodes: 3,
        mean_return: -360.0,
        claim: None,
    };
    assert_eq!(pets.judge().verdict, Verdict::SmokeTestOnly);
    let seads = |solved, distinct_moves| SeadsSlice {
        env_steps: 60_000,
        distinct_moves,
        moves: 12,
        solved,
        boards: 25,
        claim: None,
    };
    assert_eq!(seads(25, 12).judge().verdict, Verdict::Reproduced);
    assert_eq!(seads(25, 11).judge().verdict, Verdict::NotAtThisScale);
    assert_eq!(seads(24, 12).judge().verdict, Verdict::NotAtThisScale);
    let boards = |differing| BoardsSlice { depths: 33, differing, split_depths: 10, split_differing: 0, claim: None };
    assert_eq!(boards(0).judge().verdict, Verdict::Reproduced);
    assert_eq!(boards(1).judge().verdict, Verdict::NotAtThisScale);
    let reacher = EmbodiedSlice { solved: 98, boards: 98, claim: None };
    assert_eq!(reacher.judge().verdict, Verdict::SmokeTestOnly);
}

#[test]
fn context_needs_the_test_and_the_entropy_order() {
    let ctx = |p, entropy| ContextSlice {
        env: "toy:inner".into(),
        train_steps: 1200,
        mse_random: 0.08,
        mse_open_loop: 0.003,
        p_value: Some(p),
        entropy: Some(entropy),
        contexts: 30,
        claim: None,
    };
    assert_eq!(ctx(4e-6, (-0.35, 0.67)).judge().verdict, Verdict::Reproduced);
    assert_eq!(ctx(4e-6, (0.7, 0.6)).judge().verdict, Verdict::NotAtThisScale);
    assert_eq!(ctx(0.2, (-0.35, 0.67)).judge().verdict, Verdict::NotAtThisScale);
}

#[test]
fn summaries_from_before_verdicts_still_read_and_new_ones_record_the_claim() {
    let old = r#"{"train_steps": 150, "first_loss": -7.0, "last_loss": -8.1, "trained": 0.18, "ridge": 0.19, "oracle": 0.09}"#;
    let slice: BallSlice = serde_json::from_str(old).unwrap();
    assert!(slice.horizons.is_empty() && slice.claim.is_none());
    let judged = BallSlice { claim: Some(ball(&[], 1e-4).judge()), ..ball(&[], 1e-4) };
    let json = serde_json::to_value(&judged).unwrap();
    assert_eq!(json["claim"]["verdict"], "reproduced");
    assert!(json["claim"]["target"].as_str().unwrap().contains("Figs. 6.4/6.6"));
    assert_eq!(json["horizons"].as_array().unwrap().len(), 20);
    let dlgpd: DlgpdSlice =
        serde_json::from_str(r#"{"transitions": 1, "matching": null, "mismatching": null}"#).unwrap();
    assert_eq!(dlgpd.runs_per_setting, 1);
}
