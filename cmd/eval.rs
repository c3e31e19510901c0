//! `mbrl eval`: reproduce the thesis' experiments and write reports.

use std::path::PathBuf;

use anyhow::bail;
use clap::{Args, Subcommand};
use mbrl::envs::boards::{GameSpec, LightsOut, TileSwap};
use mbrl::envs::pendulum::PendulumVariant;
use mbrl::envs::EnvName;
use mbrl::eval::ball::{self, BallEvalSettings};
use mbrl::eval::boards::{self, EmbodiedSettings};
use mbrl::eval::dataset_report;
use mbrl::eval::quick::run_quick;
use mbrl::eval::seads::{compare_runs, seads_report, variant_label, ComparedRun, SeadsEvalSettings};
use mbrl::eval::swingup::{self, SwingupSettings};
use mbrl::models::ball::checkpoint::{load_ball_model, report_name};
use mbrl::run::dir::Provenance;

use crate::cem_args::CemArgs;
use crate::common::{command_line, pendulum_variant, run_job, GlobalArgs};
use crate::model_args::{accepting, report_unfinished, ModelArgs};
use crate::solve_board::{EmbodimentChoice, SplitChoice};

/// Run an evaluation protocol and write a report directory (report.md, CSV, PNG).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl eval quick
  mbrl eval dataset --input datasets/pendulum-random.mcap
  mbrl eval boards
  mbrl eval ball --model thesis --model initial
  mbrl eval embodied --game lightsout --embodiment cursor --max-depth 5 --boards 200
  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup")]
pub struct EvalArgs {
    #[command(subcommand)]
    protocol: Protocol,
}

#[derive(Subcommand, Debug)]
enum Protocol {
    /// Small reproduction of every implemented method (about a minute).
    #[command(after_help = "Example:\n  mbrl eval quick --out reports/quick")]
    Quick {
        /// Report directory.
        #[arg(long, default_value = "reports/quick")]
        out: PathBuf,
    },
    /// Summarise a dataset: rollouts, returns, state ranges, plots.
    #[command(after_help = "Examples:\n  mbrl eval dataset --input datasets/pendulum-random.mcap\n  \
                            mbrl eval dataset --input datasets/pendulum-heavy-random.mcap --out reports/heavy-data")]
    Dataset {
        /// Dataset file written by `mbrl collect` or `mbrl plan`.
        #[arg(long)]
        input: PathBuf,
        /// Report directory.
        #[arg(long, default_value = "reports/dataset")]
        out: PathBuf,
    },
    /// Depth and train/test split tables of LightsOut 5x5 and TileSwap (thesis Tables 7.1, 7.2).
    #[command(after_help = "Example:\n  mbrl eval boards --out reports/boards")]
    Boards {
        /// Report directory.
        #[arg(long, default_value = "reports/boards")]
        out: PathBuf,
    },
    /// A manipulator's scripted controller plays optimal plans of boards of depth 1..D.
    #[command(
        after_help = "Examples:\n  mbrl eval embodied --game lightsout --embodiment cursor --max-depth 5 --boards 200\n  \
                            mbrl eval embodied --game tileswap --embodiment reacher --max-depth 5 --boards 100"
    )]
    Embodied(EmbodiedArgs),
    /// Ball prediction error vs horizon on simulated shots, default and unseen launcher poses (thesis 6.5).
    #[command(after_help = "Examples:\n  mbrl eval ball --model thesis --model initial\n  \
                            mbrl eval ball --model models/ball-ekf --train-shots 108 --test-shots 163 --unseen-shots 30")]
    Ball(BallArgs),
    /// Explore the Context (thesis 4.5): calibration strategies compared by prediction error after calibration.
    #[command(
        after_help = "Examples:\n  mbrl eval context --model models/context-toy-inner --env toy:inner --transitions 1\n  \
                            mbrl eval context --model models/context-pendulum-quadrant --env pendulum:quadrant --contexts 50 --transitions 30 --horizon 20 --swingup"
    )]
    Context(ContextArgs),
    /// TRADYN (thesis 5.5): ±terrain lookup × ±calibration on navigation tasks on test maps: energy, final
    /// distance, failures (Table 5.2), Wilcoxon on energies (Fig. 5.7), prediction error (Fig. 5.5), paths (Fig. 5.6).
    #[command(
        after_help = "Examples:\n  mbrl eval tradyn --model-terrain models/tradyn-terrain --model-no-terrain models/tradyn-no-terrain --maps datasets/terrain --tasks 20\n  \
                            mbrl eval tradyn --model-terrain models/tradyn-terrain --model-no-terrain models/tradyn-no-terrain --maps datasets/terrain --tasks 150 --candidates 1000 --iters 20"
    )]
    Tradyn(TradynArgs),
    /// SEADS (thesis 7.4): skill coverage, boards solved per depth with and without replanning, planning time.
    #[command(
        after_help = "Example:\n  mbrl eval seads --model models/seads-tileswap-cursor --boards 20 --out reports/seads-tileswap"
    )]
    Seads(SeadsArgs),
    /// DLGPD (thesis 3.5.3): swing-up success and return vs evidence rollouts on the standard, inverted, light
    /// and heavy pendulum, with matching and mismatching evidence (Figs. 3.4/3.5 analogues).
    #[command(
        after_help = "Examples:\n  mbrl eval dlgpd --model models/dlgpd-small --evidence-rollouts 5,10 --runs 2\n  \
                            mbrl eval dlgpd --model models/dlgpd-medium --env pendulum:inverted --evidence-rollouts 10,20,50 --runs 3 --candidates 1000 --elites 100"
    )]
    Dlgpd(DlgpdArgs),
    /// Pendulum swing-up with MPC: success rate, returns, angle plots.
    #[command(
        after_help = "Example:\n  mbrl eval pendulum-swingup --model true --episodes 10 --out reports/swingup\n  \
                            mbrl eval pendulum-swingup --model models/pets-pendulum --episodes 10"
    )]
    PendulumSwingup(SwingupArgs),
}

#[derive(Args, Debug)]
struct EmbodiedArgs {
    /// Game: lightsout (5x5) or tileswap.
    #[arg(long)]
    game: String,
    /// Manipulator.
    #[arg(long, value_enum)]
    embodiment: EmbodimentChoice,
    /// Boards of depth 1..=max-depth are evaluated.
    #[arg(long, default_value_t = 5)]
    max_depth: u8,
    /// Boards drawn per depth (fewer when the split has fewer).
    #[arg(long, default_value_t = 100)]
    boards: usize,
    /// Split the boards come from.
    #[arg(long, value_enum, default_value_t = SplitChoice::Test)]
    split: SplitChoice,
    /// Report directory.
    #[arg(long, default_value = "reports/embodied")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct SeadsArgs {
    /// A SEADS checkpoint directory (`mbrl train seads`); repeat it to compare runs (seeds of the full
    /// method and of ablations: one-sided Mann-Whitney U tests of each ablation against `full`).
    #[arg(long, required = true)]
    model: Vec<PathBuf>,
    /// Boards of depth 1..=max-depth are solved.
    #[arg(long, default_value_t = 5)]
    max_depth: u8,
    /// Boards per depth (thesis: 20).
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// Boards every skill is executed from for the coverage table.
    #[arg(long, default_value_t = 100)]
    coverage_boards: usize,
    /// Replans allowed per board (thesis: 10).
    #[arg(long, default_value_t = 10)]
    max_replans: usize,
    /// Split the boards come from.
    #[arg(long, value_enum, default_value_t = SplitChoice::Test)]
    split: SplitChoice,
    /// A search storing more states than this counts as a failure (a model lacking a move can make the goal
    /// unreachable).
    #[arg(long, default_value_t = 2_000_000)]
    max_nodes: usize,
    /// Report directory (default: reports/seads-<checkpoint name>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Take runs still in training (the weights of their last checkpoint); the report says how far each got.
    #[arg(long)]
    allow_incomplete: bool,
}

#[derive(Args, Debug)]
struct BallArgs {
    /// EKF models to compare (repeatable): thesis, initial, or checkpoint directories.
    #[arg(long, default_values_t = ["thesis".to_string(), "initial".to_string()])]
    model: Vec<String>,
    /// Default-pose shots the black-box baseline is fitted on.
    #[arg(long, default_value_t = 108)]
    train_shots: usize,
    /// Rotated copies per training shot.
    #[arg(long, default_value_t = 19)]
    augment_rotations: usize,
    /// Default-pose test shots.
    #[arg(long, default_value_t = 163)]
    test_shots: usize,
    /// Test shots per unseen pose (5 poses).
    #[arg(long, default_value_t = 30)]
    unseen_shots: usize,
    /// Report directory.
    #[arg(long, default_value = "reports/ball")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct SwingupArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Number of episodes (each with its own start state).
    #[arg(long, default_value_t = 10)]
    episodes: usize,
    #[arg(long, default_value = "pendulum", help = concat!("Environment variant: ", mbrl::pendulum_envs!()))]
    env: String,
    /// Steps per episode.
    #[arg(long, default_value_t = 150)]
    steps: usize,
    #[command(flatten)]
    cem: CemArgs,
    /// Report directory.
    #[arg(long, default_value = "reports/pendulum-swingup")]
    out: PathBuf,
}

pub fn run(global: &GlobalArgs, args: EvalArgs) -> anyhow::Result<()> {
    let provenance = Provenance::new(command_line(), global.seed, global.thread_count());
    match args.protocol {
        Protocol::Quick { out } => {
            let summary = run_job(global, "eval quick", |monitor| run_quick(&provenance, &out, monitor))?;
            for line in summary.lines {
                say!("{line}");
            }
            say!("report: {}", out.join("report.md").display());
        }
        Protocol::Context(a) => eval_context(global, &provenance, a)?,
        Protocol::Tradyn(a) => eval_tradyn(global, &provenance, a)?,
        Protocol::Seads(a) => eval_seads(global, &provenance, a)?,
        Protocol::Dlgpd(a) => eval_dlgpd(global, &provenance, a)?,
        Protocol::Boards { out } => {
            let rows = run_job(global, "eval boards", |monitor| boards::depth_report(&provenance, &out, monitor))?;
            say!("game        depth   boards    train     test   thesis");
            for r in &rows {
                let thesis = r.thesis.map(|t| t.to_string()).unwrap_or_else(|| "-".into());
                say!("{:<11} {:>5} {:>8} {:>8} {:>8} {:>8}", r.game, r.depth, r.boards, r.train, r.test, thesis);
            }
            say!("report: {}", out.join("report.md").display());
        }
        Protocol::Embodied(a) => {
            let settings = EmbodiedSettings {
                embodiment: a.embodiment.into(),
                max_depth: a.max_depth,
                boards_per_depth: a.boards,
                split: a.split.into(),
            };
            if a.max_depth == 0 || a.boards == 0 {
                bail!("--max-depth and --boards must be at least 1");
            }
            let rows = run_job(global, "eval embodied", |monitor| match GameSpec::parse(&a.game)? {
                GameSpec::LightsOut(n) => {
                    boards::embodied_report(&LightsOut::new(n)?, &settings, &provenance, &a.out, monitor)
                }
                GameSpec::TileSwap => {
                    boards::embodied_report(&TileSwap::new(), &settings, &provenance, &a.out, monitor)
                }
            })?;
            for r in &rows {
                say!(
                    "depth {}: {}/{} solved ({:.1} %), {:.1} control steps per board",
                    r.depth,
                    r.solved,
                    r.boards,
                    100.0 * r.solved as f64 / r.boards.max(1) as f64,
                    r.mean_control_steps
                );
            }
            say!("report: {}", a.out.join("report.md").display());
        }
        Protocol::Ball(a) => {
            let models = a
                .model
                .iter()
                .map(|m| Ok((report_name(m), load_ball_model(m)?)))
                .collect::<anyhow::Result<Vec<_>>>()?;
            if a.train_shots == 0 || a.test_shots == 0 || a.unseen_shots == 0 {
                bail!("--train-shots, --test-shots and --unseen-shots must be at least 1");
            }
            let settings = BallEvalSettings {
                train_shots: a.train_shots,
                augment_rotations: a.augment_rotations,
                test_shots_default: a.test_shots,
                test_shots_unseen: a.unseen_shots,
                ..BallEvalSettings::default()
            };
            let summary = run_job(global, "eval ball", |monitor| {
                ball::evaluate(&settings, models, &provenance, &a.out, monitor)
            })?;
            say!("median prediction error at 1 s horizon:");
            for r in summary.rows.iter().filter(|r| (r.horizon_s - 1.0).abs() < 1e-9) {
                say!(
                    "  {:<32} {:<8} {:6.1} cm  (10-90 %: {:.1}-{:.1} cm, n = {}, failed {}, too short {})",
                    r.method,
                    r.group,
                    100.0 * r.median,
                    100.0 * r.q10,
                    100.0 * r.q90,
                    r.count,
                    r.failed,
                    r.too_short
                );
            }
            say!("report: {}", a.out.join("report.md").display());
        }
        Protocol::Dataset { input, out } => {
            let s = run_job(global, "eval dataset", |_| dataset_report::report(&input, &provenance, &out))?;
            say!(
                "{}: {} rollouts, {} transitions of {}, mean return {:.2}; report: {}",
                input.display(),
                s.rollouts,
                s.transitions,
                s.env,
                s.mean_return,
                out.join("report.md").display()
            );
        }
        Protocol::PendulumSwingup(a) => {
            let variant = pendulum_variant(&a.env)?;
            let model = a.model.load(&mbrl::envs::parse_env(&a.env)?)?;
            let model = model.as_deref();
            if a.episodes == 0 || a.steps < mbrl::envs::pendulum::swingup::SUCCESS_WINDOW {
                bail!(
                    "--episodes must be at least 1 and --steps at least {}",
                    mbrl::envs::pendulum::swingup::SUCCESS_WINDOW
                );
            }
            mbrl::util::budget::check(
                &format!("--episodes {} × --steps {}", a.episodes, a.steps),
                mbrl::util::budget::times(&[a.episodes, a.steps], crate::plan::STEP_RECORD_BYTES),
                "evaluate fewer or shorter episodes",
            )?;
            let settings = swingup_settings(variant, a.steps, &a.cem);
            settings.cem.validate()?;
            let summary = run_job(global, "eval pendulum-swingup", |monitor| {
                swingup::evaluate(&settings, model, a.episodes, &provenance, &a.out, monitor)
            })?;
            say!(
                "{}/{} episodes succeeded; mean return {:.1}; report: {}",
                summary.successes,
                summary.episodes,
                summary.returns.iter().sum::<f64>() / summary.episodes as f64,
                a.out.join("report.md").display()
            );
        }
    }
    Ok(())
}

#[derive(Args, Debug)]
struct TradynArgs {
    /// The TRADYN model with terrain lookup (`mbrl train tradyn`): the +T variants.
    #[arg(long)]
    model_terrain: PathBuf,
    /// The ablation trained with `--no-terrain`: the −T variants.
    #[arg(long)]
    model_no_terrain: PathBuf,
    /// The map set (`mbrl collect --env terrain`); tasks are drawn on its test maps.
    #[arg(long)]
    maps: PathBuf,
    /// Navigation tasks (thesis: 150 per model seed).
    #[arg(long, default_value_t = 20)]
    tasks: usize,
    /// Random colored calibration transitions from each start (thesis 10).
    #[arg(long, default_value_t = 10)]
    transitions: usize,
    /// Executed steps per task (thesis 50).
    #[arg(long, default_value_t = 50)]
    steps: usize,
    /// Longest planning horizon (thesis 30; it shrinks to the steps left).
    #[arg(long, default_value_t = 30)]
    horizon: usize,
    /// CEM candidates per iteration (thesis 1000; the default trades it for time on a CPU).
    #[arg(long, default_value_t = 300)]
    candidates: usize,
    /// CEM elites (thesis 50).
    #[arg(long, default_value_t = 30)]
    elites: usize,
    /// CEM iterations (thesis 20).
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// Length of the random rollout per task whose open-loop prediction is scored (thesis 50).
    #[arg(long, default_value_t = 50)]
    prediction_steps: usize,
    /// Report directory.
    #[arg(long, default_value = "reports/tradyn")]
    out: PathBuf,
    /// Take runs still in training (their best-validation weights so far); the report says how far each got.
    #[arg(long)]
    allow_incomplete: bool,
}

fn eval_tradyn(global: &GlobalArgs, provenance: &Provenance, a: TradynArgs) -> anyhow::Result<()> {
    use mbrl::eval::tradyn::{evaluate, variant_name, TradynEvalModels, TradynEvalSettings, VARIANTS};
    use mbrl::models::tradyn::navigation::NavigationSettings;
    if !(2..=100_000).contains(&a.tasks)
        || !(1..=10_000).contains(&a.steps)
        || !(1..=10_000).contains(&a.prediction_steps)
    {
        bail!("--tasks must be 2..=100000, --steps and --prediction-steps 1..=10000");
    }
    if !(1..=1000).contains(&a.transitions) {
        bail!("--transitions must be 1..=1000");
    }
    for (flag, dir) in [("--model-terrain", &a.model_terrain), ("--model-no-terrain", &a.model_no_terrain)] {
        if !dir.is_dir() {
            bail!("{flag} {}: no such checkpoint directory", dir.display());
        }
    }
    let models = TradynEvalModels {
        terrain: mbrl::models::tradyn::TradynModel::load(&a.model_terrain, accepting(a.allow_incomplete))?,
        no_terrain: mbrl::models::tradyn::TradynModel::load(&a.model_no_terrain, accepting(a.allow_incomplete))?,
    };
    for model in [&models.terrain, &models.no_terrain] {
        report_unfinished(&model.loaded.dir, &model.loaded.progress);
    }
    models.check()?;
    let maps = mbrl::data::terrain_set::read_terrain_set(&a.maps, Some(mbrl::envs::terrain::TerrainSplit::Test))?;
    let mut navigation = NavigationSettings::thesis();
    navigation.steps = a.steps;
    navigation.horizon = a.horizon;
    navigation.cem.candidates = a.candidates;
    navigation.cem.elites = a.elites;
    navigation.cem.iterations = a.iters;
    let settings = TradynEvalSettings {
        tasks: a.tasks,
        calibration_transitions: a.transitions,
        navigation,
        prediction_steps: a.prediction_steps,
        example_tasks: 3,
    };
    settings.validate()?;
    let summary =
        run_job(global, "eval tradyn", |monitor| evaluate(&models, maps, &settings, provenance, &a.out, monitor))?;
    for (v, variant) in VARIANTS.iter().enumerate() {
        say!(
            "{:<6} median energy {:.4}, median final distance {:.2} mm, failed {}/{}, mean position error {:.4} m",
            variant_name(*variant),
            summary.median_energy[v],
            summary.median_distance[v] * 1000.0,
            summary.failures[v],
            summary.tasks,
            summary.mean_position_error[v]
        );
    }
    say!(
        "Wilcoxon: terrain lookup lowers the mean position error: p = {:.3e} without calibration, {:.3e} with it",
        summary.prediction_tests[0],
        summary.prediction_tests[1]
    );
    for (r, c, p) in &summary.energy_tests {
        if r > c {
            say!(
                "Wilcoxon: {} less energy than {}: p = {p:.3e}",
                variant_name(VARIANTS[*r]),
                variant_name(VARIANTS[*c])
            );
        }
    }
    say!("report: {}", a.out.join("report.md").display());
    Ok(())
}

#[derive(Args, Debug)]
struct ContextArgs {
    /// A context-model checkpoint (`mbrl train context`).
    #[arg(long)]
    model: PathBuf,
    /// The env the model was trained on.
    #[arg(long)]
    env: String,
    /// Unseen contexts (instances) to calibrate in (thesis: 50).
    #[arg(long, default_value_t = 20)]
    contexts: usize,
    /// Random validation rollouts per context (thesis: 20).
    #[arg(long, default_value_t = 20)]
    validation_rollouts: usize,
    /// Steps per validation rollout (thesis: 50).
    #[arg(long, default_value_t = 50)]
    validation_steps: usize,
    /// Calibration transitions N (toy 1–3, pendulum 30, MountainCar 50).
    #[arg(long, default_value_t = 30)]
    transitions: usize,
    /// H_max of MPC calibration (pendulum 20, MountainCar 30).
    #[arg(long, default_value_t = 20)]
    horizon: usize,
    /// Strategies to compare (repeatable; default: all three).
    #[arg(long, value_enum)]
    strategy: Vec<crate::calibrate::StrategyChoice>,
    /// CEM candidates per iteration (thesis 1000).
    #[arg(long, default_value_t = 1000)]
    candidates: usize,
    /// CEM elites (thesis 100).
    #[arg(long, default_value_t = 100)]
    elites: usize,
    /// CEM iterations (thesis 10).
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// β samples of the information gain (thesis 20).
    #[arg(long, default_value_t = 20)]
    beta_samples: usize,
    /// Pendulum: after each calibration, swing up with MPC on the calibrated model (thesis 4.5.3), and once on
    /// the true equations as the reference.
    #[arg(long)]
    swingup: bool,
    /// Agent steps of each swing-up (thesis 50; the quadrant pendulum repeats each action twice).
    #[arg(long, default_value_t = 50, requires = "swingup")]
    swingup_steps: usize,
    /// CEM candidates of the swing-up planner (thesis 1000; elites are a tenth, 10 iterations, horizon 20).
    #[arg(long, default_value_t = 1000, requires = "swingup")]
    swingup_candidates: usize,
    /// Take a run still in training (its best-validation weights so far); the report says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Report directory.
    #[arg(long, default_value = "reports/context")]
    out: PathBuf,
}

fn eval_context(global: &GlobalArgs, provenance: &Provenance, a: ContextArgs) -> anyhow::Result<()> {
    use mbrl::models::context::calibration::{CalibrationSettings, Strategy};
    let env = mbrl::envs::parse_env(&a.env)?;
    if !a.model.is_dir() {
        bail!("--model {}: no such checkpoint directory", a.model.display());
    }
    let strategies: Vec<Strategy> =
        if a.strategy.is_empty() { Strategy::ALL.to_vec() } else { a.strategy.iter().map(|s| s.strategy()).collect() };
    let mut settings = mbrl::eval::context::ContextEvalSettings {
        contexts: a.contexts,
        validation_rollouts: a.validation_rollouts,
        validation_steps: a.validation_steps,
        strategies: strategies.clone(),
        calibration: CalibrationSettings {
            strategy: Strategy::Random,
            transitions: a.transitions,
            horizon_max: a.horizon,
            candidates: a.candidates,
            elites: a.elites,
            iterations: a.iters,
            beta_samples: a.beta_samples,
        },
        swingup: None,
    };
    settings.calibration.validate()?;
    if a.swingup {
        let EnvName::Pendulum(variant) = &env else {
            bail!("--swingup needs a pendulum env (pendulum:quadrant in the thesis), not '{}'", env.canonical());
        };
        if !(2..=100_000).contains(&a.swingup_candidates) || !(1..=10_000).contains(&a.swingup_steps) {
            bail!("--swingup-candidates must be 2..=100000 and --swingup-steps 1..=10000");
        }
        let mut swingup = SwingupSettings::thesis(variant.clone());
        swingup.steps = a.swingup_steps;
        swingup.cem.candidates = a.swingup_candidates;
        swingup.cem.elites = (a.swingup_candidates / 10).max(2);
        settings.swingup = Some(swingup);
    }
    if !(2..=100_000).contains(&a.contexts)
        || !(1..=10_000).contains(&a.validation_rollouts)
        || !(1..=10_000).contains(&a.validation_steps)
    {
        bail!("--contexts must be 2..=100000, --validation-rollouts and --validation-steps 1..=10000");
    }
    let model = mbrl::models::context::load(&a.model, &env, accepting(a.allow_incomplete))?;
    report_unfinished(&a.model, &model.progress);
    let summary = run_job(global, "eval context", |monitor| {
        mbrl::eval::context::evaluate(&model, &env, &settings, provenance, &a.out, monitor)
    })?;
    for ((s, m), r) in strategies.iter().zip(&summary.mean_mse).zip(&summary.action_response) {
        say!("{:<10} mean prediction MSE {m:.4e}, action response {r:.3}", s.name());
    }
    say!(
        "no calibration (empty context, reference) mean prediction MSE {:.4e}, action response {:.3}",
        summary.empty_context_mse,
        summary.empty_context_action_response
    );
    say!("(action response: the model's one-step response to the action over the simulator's; 1 right, 0 ignored)");
    for (better, worse, p) in &summary.tests {
        say!("Wilcoxon: {} lower than {}: p = {p:.3e}", better.name(), worse.name());
    }
    if let Some(sw) = &summary.swingup {
        for (s, r) in strategies.iter().zip(&sw.mean_return) {
            say!("{:<10} mean swing-up return {r:.1}", s.name());
        }
        say!("ground truth mean swing-up return {:.1}", sw.ground_truth_mean_return);
        for (better, worse, p) in &sw.tests {
            say!("Wilcoxon: {} higher swing-up return than {}: p = {p:.3e}", better.name(), worse.name());
        }
    }
    if let Some((informative, non_informative)) = summary.toy_entropy {
        say!("entropy after one transition: informative actions {informative:.3}, non-informative {non_informative:.3} nats");
    }
    say!("report: {}", a.out.join("report.md").display());
    Ok(())
}

fn swingup_settings(variant: PendulumVariant, steps: usize, cem: &CemArgs) -> SwingupSettings {
    let mut settings = SwingupSettings::thesis(variant);
    settings.steps = steps;
    settings.cem = cem.config(&settings.cem.action_low, &settings.cem.action_high);
    settings
}

fn eval_seads(global: &GlobalArgs, provenance: &Provenance, a: SeadsArgs) -> anyhow::Result<()> {
    if a.max_depth == 0 || a.max_depth > 10 || a.boards == 0 || a.coverage_boards == 0 {
        bail!("--max-depth must be 1..=10 and --boards, --coverage-boards at least 1");
    }
    let name_of = |dir: &std::path::Path| dir.file_name().and_then(|n| n.to_str()).unwrap_or("model").to_string();
    let out = a.out.clone().unwrap_or_else(|| {
        PathBuf::from(if a.model.len() == 1 {
            format!("reports/seads-{}", name_of(&a.model[0]))
        } else {
            "reports/seads-compare".into()
        })
    });
    let mut names: Vec<String> = a.model.iter().map(|m| name_of(m)).collect();
    names.sort();
    if a.model.len() > 1 && names.windows(2).any(|w| w[0] == w[1]) {
        bail!("--model directories to compare need distinct names (each gets a report subdirectory of that name)");
    }
    let loaded: Vec<_> = a
        .model
        .iter()
        .map(|m| mbrl::models::seads::planner::load(m, accepting(a.allow_incomplete)))
        .collect::<Result<_, _>>()?;
    for model in &loaded {
        report_unfinished(&model.dir, &model.progress);
    }
    let settings = SeadsEvalSettings {
        max_depth: a.max_depth,
        boards_per_depth: a.boards,
        coverage_boards: a.coverage_boards,
        max_replans: a.max_replans,
        split: a.split.into(),
        max_search_nodes: a.max_nodes,
    };
    let mut runs = Vec::new();
    for (dir, model) in a.model.iter().zip(&loaded) {
        let report_dir = if a.model.len() == 1 { out.clone() } else { out.join(name_of(dir)) };
        let s =
            run_job(global, "eval seads", |monitor| seads_report(model, &settings, provenance, &report_dir, monitor))?;
        say!(
            "{} ({}): the skills' most frequent moves cover {} of {} game moves",
            name_of(dir),
            s.env,
            s.distinct_moves,
            s.moves
        );
        for r in &s.depths {
            let n = r.boards.max(1) as f64;
            say!(
                "  depth {}: {:.1} % solved with ≤ {} replans, {:.1} % without; planning {:.4} s per board",
                r.depth,
                100.0 * r.solved_with_replanning as f64 / n,
                a.max_replans,
                100.0 * r.solved_without_replanning as f64 / n,
                r.mean_planning_seconds
            );
        }
        runs.push(ComparedRun {
            name: name_of(dir),
            variant: variant_label(&model.run.config),
            seed: model.run.seed,
            summary: s,
        });
    }
    if runs.len() > 1 {
        let envs: Vec<&str> = runs.iter().map(|r| r.summary.env.as_str()).collect();
        if envs.iter().any(|e| *e != envs[0]) {
            bail!("runs to compare must share one env, got {}", envs.join(", "));
        }
        for t in compare_runs(&runs, &out)? {
            say!(
                "{} > {} on {}: Mann-Whitney U = {}, one-sided p = {:.3e}",
                t.better,
                t.worse,
                t.metric,
                t.u,
                t.p_value
            );
        }
    }
    say!("report: {}", out.join("report.md").display());
    Ok(())
}

#[derive(Args, Debug)]
struct DlgpdArgs {
    /// A DLGPD checkpoint (`mbrl train dlgpd`).
    #[arg(long)]
    model: PathBuf,
    /// Settings to swing up (repeatable; default: the thesis' pendulum, pendulum:inverted, pendulum:light,
    /// pendulum:heavy).
    #[arg(long)]
    env: Vec<String>,
    /// Evidence sizes in rollouts of 30 frames (thesis: 10, 20, 30, 50, 70, 100, 200).
    #[arg(long, value_delimiter = ',', default_value = "5,10,20")]
    evidence_rollouts: Vec<usize>,
    /// Runs per point, each with its own evidence pool and start state (thesis: 27).
    #[arg(long, default_value_t = 2)]
    runs: usize,
    /// Steps per swing-up.
    #[arg(long, default_value_t = 150)]
    steps: usize,
    /// CEM candidates per iteration (the authors': 1000, about 1.5 s a step on 2 cores at 10 evidence rollouts).
    #[arg(long, default_value_t = 300)]
    candidates: usize,
    /// CEM elites (the authors': 100).
    #[arg(long, default_value_t = 30)]
    elites: usize,
    /// At most this many CEM iterations per step (the authors': 30, stopping at first-action std ≤ 0.01).
    #[arg(long, default_value_t = 10)]
    iters: usize,
    /// Skip the swing-ups: only check the conditioned models' reward predictions on held-out rollouts
    /// (seconds instead of an hour; tells a model that cannot see the pendulum from a planner that fails).
    #[arg(long, conflicts_with_all = ["runs", "steps", "candidates", "elites", "iters"])]
    prediction_only: bool,
    /// Take a run still in training (its best-validation weights so far); the report says how far it got.
    #[arg(long)]
    allow_incomplete: bool,
    /// Report directory.
    #[arg(long, default_value = "reports/dlgpd")]
    out: PathBuf,
}

fn eval_dlgpd(global: &GlobalArgs, provenance: &Provenance, a: DlgpdArgs) -> anyhow::Result<()> {
    use mbrl::eval::dlgpd::{evaluate, DlgpdEvalSettings};
    use mbrl::models::dlgpd::control::ControlSettings;
    let variants = if a.env.is_empty() {
        DlgpdEvalSettings::thesis_variants()
    } else {
        a.env.iter().map(|e| pendulum_variant(e)).collect::<anyhow::Result<Vec<_>>>()?
    };
    if !(1..=1000).contains(&a.runs) || !(1..=10_000).contains(&a.steps) || !(2..=100_000).contains(&a.candidates) {
        bail!("--runs must be 1..=1000, --steps 1..=10000 and --candidates 2..=100000");
    }
    let mut cem = ControlSettings::authors(PendulumVariant::Standard).cem;
    cem.candidates = a.candidates;
    cem.elites = a.elites;
    cem.iterations = a.iters;
    let settings = DlgpdEvalSettings {
        variants,
        evidence_rollouts: a.evidence_rollouts,
        runs: a.runs,
        steps: a.steps,
        cem,
        swing_ups: !a.prediction_only,
    };
    let trained = mbrl::models::dlgpd::job::load(&a.model, accepting(a.allow_incomplete))?;
    report_unfinished(&a.model, &trained.progress);
    let summary = run_job(global, "eval dlgpd", |monitor| evaluate(&trained, &settings, provenance, &a.out, monitor))?;
    if !summary.points.is_empty() {
        say!("env                   evidence     rollouts  mean return  successes");
    }
    for p in &summary.points {
        say!(
            "{:<21} {:<12} {:>8} {:>12.1} {:>7}/{}",
            p.env,
            p.evidence,
            p.rollouts,
            p.mean_return,
            p.successes,
            p.runs
        );
    }
    if !summary.predictions.is_empty() {
        say!(
            "{:<34} {:>8} {:>14} {:>6} {:>10} {:>9} {:>20}",
            "reward RMSE, held-out rollouts",
            "encoded",
            "open loop h=1",
            "h=10",
            "constant",
            "θ̇ R²",
            "action response h=5"
        );
    }
    for p in &summary.predictions {
        let at = |h: usize| p.prediction.errors.open_loop_rmse.get(h).copied().unwrap_or(f64::NAN);
        let response = p.prediction.action_response.iter().find(|r| r.horizon == 5).map_or(f64::NAN, |r| r.response);
        say!(
            "{:<21} {:<12} {:>8.2} {:>14.2} {:>6.2} {:>10.2} {:>9.2} {:>20.2}",
            p.env,
            p.evidence,
            p.prediction.errors.encoded_rmse,
            at(1),
            at(10),
            p.prediction.errors.constant_rmse,
            p.prediction.linear_probe_r2[2],
            response
        );
    }
    for t in &summary.tests {
        say!(
            "Wilcoxon: {} with {} rollouts, matching evidence higher return than mismatching: p = {:.3e} ({} pairs)",
            t.env,
            t.rollouts,
            t.p_value,
            t.pairs
        );
    }
    say!("report: {}", a.out.join("report.md").display());
    Ok(())
}
