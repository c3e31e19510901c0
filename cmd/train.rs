//! `mbrl train`: fit a model to a dataset and write a checkpoint directory.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use mbrl::eval::plot::{line_plot, Series};
use mbrl::models::ball::learn::job::{self as ball_job, BallTrainReport, BallTrainRequest};
use mbrl::models::ball::learn::TrainSettings;
use mbrl::models::ball::BallModelParams;
use mbrl::models::context::{self, ContextConfig};
use mbrl::models::dlgpd::config::{DlgpdConfig, Preset as DlgpdPreset};
use mbrl::models::dlgpd::job as dlgpd;
use mbrl::models::pets::{self, PetsConfig, Preset, RewardSource};
use mbrl::models::seads::{self, EmbodiedGame, SeadsConfig};
use mbrl::models::tradyn;
use mbrl::run::dir::{Provenance, METRICS_FILE};
use mbrl::train::config::apply_toml_file;
use mbrl::train::data_file::scalar_history;
use mbrl::train::{loss_history, Extension, OpenedCheckpoint, Start};
use mbrl::util::table::write_csv;

use crate::common::{command_line, file_stem, run_job, GlobalArgs};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Probabilistic ensemble of MLPs on (state, action) → state change (PETS, Chua et al. 2018), for any
    /// env that `collect` rolls out; plan with it via `mbrl plan --model DIR`.
    Pets,
    /// Gray-box table-tennis ball EKF: learn the impact matrix, noise levels and initial values by
    /// maximizing the filter's marginal likelihood (thesis 6.4.4, eq. 6.24).
    BallEkf,
    /// Context-conditional GRU dynamics with a context encoder (Explore the Context, thesis ch. 4), trained
    /// on instance-pair datasets (`collect --instances N`); calibrate with `mbrl calibrate`.
    Context,
    /// TRADYN (thesis ch. 5): the context model on the unicycle's observation with the terrain under the robot
    /// as input, read from the map at predicted positions; --no-terrain trains the ablation that predicts it.
    /// Data: `collect --env unicycle --maps DIR --split train --instances N --steps 100`.
    Tradyn,
    /// SEADS (thesis ch. 7): skill policies (SAC) and a symbolic forward model learned without reward in an
    /// embodied board game (--env lightsout:cursor|tileswap:cursor|lightsout:reacher|tileswap:reacher); needs no
    /// --data, it collects its own episodes.
    Seads,
    /// DLGPD (thesis ch. 3): a VAE on pendulum frames (`collect --images`) with Gaussian-process latent
    /// dynamics and reward; plan with `mbrl plan --model DIR --evidence E.mcap`. The small preset learns from
    /// the pole angle instead of frames.
    Dlgpd,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum PresetChoice {
    /// 3 hidden layers × 64 SiLU units, 2000 steps (≈ 10 s on 2 cores).
    Small,
    /// 4 × 200 SiLU units, 5000 steps: mbrl-lib's PETS pendulum network.
    Medium,
    /// The paper's scale (context: Table B.1; seads: 500k/10M env steps; dlgpd: batch 1024, 28 000 steps).
    Paper,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum RewardChoice {
    /// The env's closed-form reward (pendulum variants without hidden actuators).
    Known,
    /// An extra output of the network, trained on the dataset's rewards.
    Learned,
}

/// Train a model and write it to a checkpoint directory (config.json, weights, metrics.jsonl).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl collect --env pendulum --rollouts 200 --steps 30 --out datasets/pendulum-random.mcap
  mbrl train --method pets --env pendulum --data datasets/pendulum-random.mcap --out models/pets-pendulum
  mbrl train --method pets --data a.mcap --data b.mcap --preset medium --config pets.toml --out models/pets-big
  mbrl train --resume models/pets-big
  mbrl train --resume models/pets-big --steps 8000
  mbrl collect --env ball --trajectories 108 --augment-rotations 19 --out datasets/ball-train.mcap
  mbrl train --method ball-ekf --data datasets/ball-train.mcap --out models/ball-ekf --steps 2000
  mbrl collect --env toy:inner --instances 1000 --steps 100 --out datasets/toy-inner.mcap
  mbrl train --method context --data datasets/toy-inner.mcap --preset small --out models/context-toy-inner
  mbrl train --method seads --env tileswap:cursor --preset small --out models/seads-tileswap-cursor
  mbrl train --method seads --env lightsout:cursor --preset medium --no-novelty --out models/seads-lo-nonov
  mbrl collect --env pendulum --rollouts 500 --steps 29 --out datasets/pendulum-dlgpd.mcap
  mbrl train --method dlgpd --data datasets/pendulum-dlgpd.mcap --preset small --out models/dlgpd-small
  mbrl collect --env pendulum --images --rollouts 500 --steps 29 --out datasets/pendulum-frames.mcap
  mbrl train --method dlgpd --data datasets/pendulum-frames.mcap --preset medium --out models/dlgpd-medium

A config file (TOML) sets any key of the method's config.json `config` table; unknown keys are errors.
Flags given explicitly override the file. `--resume DIR` continues a stopped run from its last checkpoint
with the config and data it was started with, and ends with the same bytes as an uninterrupted run.
`--resume DIR --steps N` trains a pets or dlgpd run, finished or not, on to N steps in total; its weights
end as those of a run started with N steps, when the old total was a multiple of the validation interval.")]
pub struct TrainArgs {
    /// What to train.
    #[arg(long, value_enum, required_unless_present = "resume")]
    method: Option<Method>,
    /// Training data (repeatable). pets: rollout datasets (.mcap) of one env; ball-ekf: a ball dataset (.mcap)
    /// or a .csv recording. SEADS collects its own episodes and takes none.
    #[arg(long)]
    data: Vec<PathBuf>,
    /// The env the data must come from (pets; default: the dataset's env).
    #[arg(long)]
    env: Option<String>,
    /// Checkpoint directory (default: models/<method>-<env>, models/ball-ekf).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Continue the stopped run in this checkpoint directory.
    #[arg(long, conflicts_with_all = ["method", "data", "env", "out", "config", "preset", "ensemble", "batch", "lr", "reward", "launcher_prior", "skills", "env_steps", "no_relabel", "no_second_best", "no_novelty", "no_terrain"])]
    resume: Option<PathBuf>,
    /// Hyperparameters from a TOML file (pets, context), over the preset's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Network size and training length (pets: small, medium; context, seads, dlgpd: small, medium, paper).
    #[arg(long, value_enum)]
    preset: Option<PresetChoice>,
    /// Ensemble members (pets; default 5).
    #[arg(long)]
    ensemble: Option<usize>,
    /// Optimizer steps (pets, context, dlgpd: the preset's; ball-ekf: 1000). With --resume: train a pets or
    /// dlgpd run, finished or not, on to this many steps in total.
    #[arg(long)]
    steps: Option<u64>,
    /// Batch size: transitions per member (pets, 256), chunks (ball-ekf, thesis 64), transitions (dlgpd: the
    /// preset's; the paper 1024).
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate (pets, dlgpd: 1e-3; ball-ekf: thesis 5e-3).
    #[arg(long, value_parser = crate::common::finite_f64)]
    lr: Option<f64>,
    /// Where the model's reward comes from (pets; default: known where the env has a closed form).
    #[arg(long, value_enum)]
    reward: Option<RewardChoice>,
    /// Frames per chunk (ball-ekf; thesis: 50).
    #[arg(long, default_value_t = 50)]
    chunk: usize,
    /// Learn the spin prior from launcher settings (ball-ekf, thesis C.1.3); recordings need side information.
    #[arg(long)]
    launcher_prior: bool,
    /// Number of skills K (seads; default: the game's move count, 25 LightsOut, 12 TileSwap).
    #[arg(long)]
    skills: Option<usize>,
    /// Budget of environment steps (seads; default: the preset's, paper = 500k Cursor, 10M Reacher).
    #[arg(long)]
    env_steps: Option<u64>,
    /// Ablation: no relabelling of skill labels (seads).
    #[arg(long)]
    no_relabel: bool,
    /// Ablation: no second-best normalization of the reward (seads).
    #[arg(long)]
    no_second_best: bool,
    /// Ablation: no novelty bonus in the reward (seads).
    #[arg(long)]
    no_novelty: bool,
    /// Ablation: no terrain lookup (tradyn "−T"): the terrain features become part of the predicted state.
    #[arg(long)]
    no_terrain: bool,
}

pub fn run(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    if args.steps == Some(0) {
        bail!("--steps must be at least 1");
    }
    if let Some(dir) = &args.resume {
        let extension = args.steps.map(|steps| Extension { steps, command_line: command_line() });
        return resume(global, dir, extension.as_ref());
    }
    match args.method.expect("clap requires --method without --resume") {
        Method::Pets => train_pets(global, args),
        Method::BallEkf => train_ball(global, args),
        Method::Context => train_context(global, args),
        Method::Tradyn => train_tradyn(global, args),
        Method::Seads => train_seads(global, args),
        Method::Dlgpd => train_dlgpd(global, args),
    }
}

/// A fresh run starts by clearing its directory, so pointing it at a stopped run would throw away every hour
/// that run trained (a re-run Makefile target after an interruption, say): that is refused, naming the two
/// ways on. A finished run or a directory without a checkpoint is replaced as before.
fn fresh_run_dir(out: PathBuf) -> anyhow::Result<PathBuf> {
    if let Ok(opened) = OpenedCheckpoint::open(&out) {
        let manifest = &opened.manifest;
        if !manifest.complete {
            bail!(
                "{}: holds a {} run stopped at step {} of {}; continue it with `mbrl train --resume {}`, or remove \
                 the directory to start over",
                out.display(),
                manifest.method,
                manifest.step,
                manifest.total_steps,
                out.display()
            );
        }
    }
    Ok(out)
}

fn resume(global: &GlobalArgs, dir: &Path, extend_to: Option<&Extension>) -> anyhow::Result<()> {
    let method = OpenedCheckpoint::open(dir)?.manifest.method;
    // Training that depends on its total (context's p_ctx schedule, ball-ekf's and seads' budgets) cannot be
    // lengthened without changing what was already trained.
    if extend_to.is_some() && method != pets::METHOD && method != dlgpd::METHOD {
        bail!(
            "{}: --steps with --resume extends a run, which works for {} and {} runs; a {method} run's training \
             depends on its total, so start a new run with the steps you want",
            dir.display(),
            pets::METHOD,
            dlgpd::METHOD
        );
    }
    match method.as_str() {
        pets::METHOD => {
            let report = run_job(global, "train pets (resumed)", |monitor| pets::resume(dir, extend_to, monitor))?;
            print_pets_report(&report, dir)
        }
        ball_job::METHOD => {
            let report = run_job(global, "train ball-ekf (resumed)", |monitor| ball_job::resume(dir, monitor))?;
            finish_ball(&report, dir)
        }
        context::METHOD => {
            let report = run_job(global, "train context (resumed)", |monitor| context::resume(dir, monitor))?;
            print_context_report(&report, dir)
        }
        tradyn::METHOD => {
            let report = run_job(global, "train tradyn (resumed)", |monitor| context::resume(dir, monitor))?;
            print_context_report(&report, dir)
        }
        seads::METHOD => {
            let report = run_job(global, "train seads (resumed)", |monitor| seads::resume(dir, monitor))?;
            print_seads_report(&report, dir)
        }
        dlgpd::METHOD => {
            let report = run_job(global, "train dlgpd (resumed)", |monitor| dlgpd::resume(dir, extend_to, monitor))?;
            print_dlgpd_report(&report, dir)
        }
        other => bail!(
            "{}: '{other}' runs cannot be resumed; resumable methods: {}, {}, {}, {}, {}, {}",
            dir.display(),
            pets::METHOD,
            ball_job::METHOD,
            context::METHOD,
            tradyn::METHOD,
            seads::METHOD,
            dlgpd::METHOD
        ),
    }
}

fn pets_config(args: &TrainArgs) -> anyhow::Result<PetsConfig> {
    let preset = match args.preset.unwrap_or(PresetChoice::Small) {
        PresetChoice::Small => Preset::Small,
        PresetChoice::Medium => Preset::Medium,
        PresetChoice::Paper => bail!("--preset paper is a context-model preset; pets takes small or medium"),
    };
    let mut config = PetsConfig::preset(preset);
    if let Some(path) = &args.config {
        config = apply_toml_file(&config, path)?;
    }
    if let Some(n) = args.ensemble {
        config.ensemble = n;
    }
    if let Some(n) = args.steps {
        config.steps = n;
    }
    if let Some(n) = args.batch {
        config.batch_size = n;
    }
    if let Some(lr) = args.lr {
        config.optimizer.learning_rate = lr;
    }
    if let Some(r) = args.reward {
        config.reward = match r {
            RewardChoice::Known => RewardSource::Known,
            RewardChoice::Learned => RewardSource::Learned,
        };
    }
    if args.launcher_prior {
        bail!("--launcher-prior is a ball-ekf flag; pets has no launcher");
    }
    config.validate()?;
    Ok(config)
}

fn train_pets(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    let mut config = pets_config(&args)?;
    let first = args.data.first().context("--data is required")?;
    // The env names the default output and decides the default reward; without --env it is the dataset's.
    let env = match &args.env {
        Some(env) => env.clone(),
        None => mbrl::data::read_dataset(first)?.meta.env,
    };
    if args.reward.is_none() && args.config.is_none() && mbrl::envs::parse_env(&env)?.known_reward().is_none() {
        config.reward = RewardSource::Learned;
    }
    let out =
        fresh_run_dir(args.out.clone().unwrap_or_else(|| PathBuf::from(format!("models/pets-{}", file_stem(&env)))))?;
    let request = pets::TrainRequest {
        out: out.clone(),
        data: args.data.clone(),
        env: args.env.clone(),
        config,
        seed: global.seed,
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let report = run_job(global, "train pets", |monitor| pets::train(&request, Start::Fresh, monitor))?;
    print_pets_report(&report, &out)
}

fn print_pets_report(report: &pets::TrainReport, out: &Path) -> anyhow::Result<()> {
    write_loss_report(out, "PETS training loss (Gaussian NLL summed over members)", "loss")?;
    let run = &report.run;
    let c = &run.config;
    say!(
        "trained a PETS ensemble of {} ({}×{} {}, {} parameters, reward {}) on {} transitions of {} ({} rollouts; {} held out)",
        c.ensemble,
        c.hidden_layers,
        c.hidden_units,
        c.activation.name(),
        report.parameters,
        match c.reward {
            RewardSource::Known => "known",
            RewardSource::Learned => "learned",
        },
        run.transitions.train,
        run.env,
        run.transitions.train_rollouts,
        run.transitions.valid_rollouts
    );
    let o = &report.outcome;
    if let Some(loss) = o.last_train_loss {
        say!("final training loss (Gaussian NLL) {loss:.4} after {} steps", o.steps);
    }
    if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
        say!("best validation MSE {v:.3e} at step {step} (saved as model.safetensors)");
    }
    say!("checkpoint: {}", out.display());
    Ok(())
}

fn context_config(args: &TrainArgs, env: &mbrl::envs::EnvName) -> anyhow::Result<ContextConfig> {
    for (flag, given) in [("--ensemble", args.ensemble.is_some()), ("--reward", args.reward.is_some())] {
        if given {
            bail!(
                "{flag} is a pets flag; context takes --data, --env, --out, --preset, --config, --steps, --batch, --lr"
            );
        }
    }
    if args.launcher_prior {
        bail!("--launcher-prior is a ball-ekf flag; the context model has no launcher");
    }
    let preset = match args.preset.unwrap_or(PresetChoice::Small) {
        PresetChoice::Small => context::Preset::Small,
        PresetChoice::Medium => context::Preset::Medium,
        PresetChoice::Paper => context::Preset::Paper,
    };
    let preset_config = ContextConfig::preset(preset, context::family_of(env));
    let mut config = preset_config.clone();
    if let Some(path) = &args.config {
        config = apply_toml_file(&config, path)?;
    }
    if let Some(n) = args.steps {
        config.steps = n;
    }
    // The p_ctx-from-A schedule is a share of the run (B.2.1: 30 % and 60 % of it); a run made longer or
    // shorter keeps those shares unless the config file sets the schedule itself.
    if config.context_from_target == preset_config.context_from_target {
        config.context_from_target = preset_config.context_from_target.rescaled(preset_config.steps, config.steps);
    }
    if let Some(n) = args.batch {
        config.batch_size = n;
    }
    if let Some(lr) = args.lr {
        config.optimizer.learning_rate = lr;
    }
    config.validate()?;
    Ok(config)
}

fn train_context(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    let [data] = args.data.as_slice() else {
        bail!("context trains on one --data file (a `collect --instances N` dataset), got {}", args.data.len());
    };
    if args.no_terrain {
        bail!("--no-terrain is the TRADYN ablation (--method tradyn)");
    }
    let env_name = match &args.env {
        Some(env) => env.clone(),
        None => mbrl::data::read_dataset(data)?.meta.env,
    };
    let env = mbrl::envs::parse_env(&env_name)?;
    if matches!(env, mbrl::envs::EnvName::Unicycle(_)) {
        bail!("{}: unicycle data trains TRADYN, which reads the terrain: `mbrl train --method tradyn`", data.display());
    }
    let config = context_config(&args, &env)?;
    let out = fresh_run_dir(
        args.out.clone().unwrap_or_else(|| PathBuf::from(format!("models/context-{}", file_stem(&env_name)))),
    )?;
    let request = context::TrainRequest {
        method: context::METHOD.into(),
        space: context::StateSpace::EnvState,
        out: out.clone(),
        data: data.clone(),
        env: args.env.clone(),
        config,
        seed: global.seed,
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let report = run_job(global, "train context", |monitor| context::train(&request, false, monitor))?;
    print_context_report(&report, &out)
}

fn train_tradyn(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    let [data] = args.data.as_slice() else {
        bail!(
            "tradyn trains on one --data file (`collect --env unicycle --maps DIR --split train --instances N`), got {}",
            args.data.len()
        );
    };
    let env_name = mbrl::data::read_dataset(data)?.meta.env;
    let env = mbrl::envs::parse_env(&env_name)?;
    if !matches!(env, mbrl::envs::EnvName::Unicycle(_)) {
        bail!(
            "{}: holds '{env_name}' data; TRADYN learns the unicycle on terrain (`mbrl collect --env unicycle --maps DIR --instances N`)",
            data.display()
        );
    }
    if args.env.as_deref().is_some_and(|e| e != "unicycle") {
        bail!("--env: TRADYN models the unicycle; got '{}'", args.env.as_deref().unwrap_or_default());
    }
    let config = context_config(&args, &env)?;
    let variant = if args.no_terrain { "no-terrain" } else { "terrain" };
    let out = fresh_run_dir(args.out.clone().unwrap_or_else(|| PathBuf::from(format!("models/tradyn-{variant}"))))?;
    let request = context::TrainRequest {
        method: tradyn::METHOD.into(),
        space: tradyn::state_space(!args.no_terrain),
        out: out.clone(),
        data: data.clone(),
        env: None,
        config,
        seed: global.seed,
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let report = run_job(global, "train tradyn", |monitor| context::train(&request, false, monitor))?;
    print_context_report(&report, &out)
}

fn print_context_report(report: &context::TrainReport, out: &Path) -> anyhow::Result<()> {
    let run = &report.run;
    let (what, loss) = if run.method == tradyn::METHOD {
        let lookup = if run.model.local_dim > 0 {
            "with terrain lookup"
        } else {
            "without terrain lookup (−T: terrain predicted)"
        };
        (format!("a TRADYN model {lookup}"), "TRADYN training loss (eq. 4.32 with terrain input)")
    } else {
        ("a context model".to_string(), "Context-model training loss (eq. 4.32)")
    };
    write_loss_report(out, loss, "loss")?;
    let c = &run.config;
    say!(
        "trained {what} (embedding {}, D_F {}, D_β {}, {} parameters) on {} instances of {} ({} held out), batch {} × {} states",
        c.embedding,
        c.transition_features,
        c.latent_dim,
        report.parameters,
        run.instances.train,
        run.env,
        run.instances.valid,
        c.batch_size,
        run.chunk_states
    );
    let o = &report.outcome;
    if let Some(loss) = o.last_train_loss {
        say!("final training loss {loss:.4} after {} steps", o.steps);
    }
    if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
        say!("best validation loss {v:.4} at step {step} (saved as model.safetensors)");
    }
    say!("checkpoint: {}", out.display());
    Ok(())
}

fn train_ball(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    for (flag, given) in [
        ("--env", args.env.is_some()),
        ("--config", args.config.is_some()),
        ("--preset", args.preset.is_some()),
        ("--ensemble", args.ensemble.is_some()),
        ("--reward", args.reward.is_some()),
    ] {
        if given {
            bail!("{flag} is a pets flag; ball-ekf takes --data, --out, --steps, --batch, --chunk, --lr, --launcher-prior");
        }
    }
    let [data] = args.data.as_slice() else {
        bail!("ball-ekf trains on one --data file, got {}", args.data.len());
    };
    let out = fresh_run_dir(args.out.clone().unwrap_or_else(|| PathBuf::from("models/ball-ekf")))?;
    let steps = args.steps.unwrap_or(1000);
    let batch = args.batch.unwrap_or(64);
    let lr = args.lr.unwrap_or(5e-3);
    let settings = TrainSettings {
        steps,
        batch_size: batch,
        chunk_len: args.chunk,
        learning_rate: lr,
        seed: global.seed,
        launcher_prior: args.launcher_prior,
        ..TrainSettings::default()
    };
    let request = BallTrainRequest {
        out: out.clone(),
        data: data.clone(),
        settings,
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let report = run_job(global, "train ball-ekf", |monitor| ball_job::train_checkpointed(&request, false, monitor))?;
    finish_ball(&report, &out)
}

fn finish_ball(report: &BallTrainReport, out: &Path) -> anyhow::Result<()> {
    let losses = write_loss_report(out, "Training loss (eq. 6.24, per measurement)", "negative log-likelihood")?;
    let p = &report.params;
    let thesis = BallModelParams::thesis_learned();
    let run = &report.run;
    say!("trained on {} chunks of {} frames from {} recordings", run.chunks, run.settings.chunk_len, run.recordings);
    if let (Some(first), Some(last)) = (losses.first(), losses.last()) {
        say!("loss {:.3} -> {:.3}", first.1, last.1);
    }
    say!("learned C (thesis eq. 6.26 in brackets):");
    for (row, thesis_row) in p.c.iter().zip(&thesis.c) {
        let cells: Vec<String> = row.iter().zip(thesis_row).map(|(v, t)| format!("{v:6.2} [{t:5.2}]")).collect();
        say!("  {}", cells.join(" "));
    }
    say!(
        "a_d {:.4} (k_d {:.4}), a_m {:.4} (k_m {:.4})",
        p.a_d0,
        p.a_d0 * p.a_d0 + 0.05,
        p.a_m0,
        p.a_m0 * p.a_m0 + 0.05
    );
    say!("checkpoint: {}", out.display());
    Ok(())
}

/// losses.csv and loss.png of a finished run, from its metrics log (so a resumed run gets the whole curve): the
/// batch loss of every step and, where the method validates, the held-out loss at each validation (the curve
/// that shows overfitting and which snapshot was kept as the best).
fn write_loss_report(out: &Path, title: &str, y_label: &str) -> anyhow::Result<Vec<(u64, f64)>> {
    let metrics = out.join(METRICS_FILE);
    let losses = loss_history(&metrics)?;
    let validation: std::collections::BTreeMap<u64, f64> =
        scalar_history(&metrics, "valid/loss")?.into_iter().collect();
    let rows: Vec<Vec<String>> = losses
        .iter()
        .map(|(k, l)| {
            vec![k.to_string(), format!("{l:.6}"), validation.get(k).map_or(String::new(), |v| format!("{v:.6}"))]
        })
        .collect();
    write_csv(&out.join("losses.csv"), &["step", "loss", "validation_loss"], &rows)?;
    let mut curves =
        vec![Series { name: "batch loss".into(), points: losses.iter().map(|(k, l)| (*k as f64, *l)).collect() }];
    if !validation.is_empty() {
        curves.push(Series {
            name: "validation loss (held out)".into(),
            points: validation.iter().map(|(k, v)| (*k as f64, *v)).collect(),
        });
    }
    line_plot(&out.join("loss.png"), title, "step", y_label, &curves)?;
    Ok(losses)
}

fn seads_config(args: &TrainArgs, env: &EmbodiedGame) -> anyhow::Result<SeadsConfig> {
    for (flag, given) in [
        ("--data", !args.data.is_empty()),
        ("--ensemble", args.ensemble.is_some()),
        ("--reward", args.reward.is_some()),
        ("--steps", args.steps.is_some()),
        ("--batch", args.batch.is_some()),
        ("--lr", args.lr.is_some()),
        ("--launcher-prior", args.launcher_prior),
    ] {
        if given {
            bail!(
                "{flag} does not apply to seads; it takes --env, --out, --preset, --config, --skills, --env-steps, \
                 --no-relabel, --no-second-best, --no-novelty (learning rates and batches via --config)"
            );
        }
    }
    let preset = match args.preset.unwrap_or(PresetChoice::Small) {
        PresetChoice::Small => seads::Preset::Small,
        PresetChoice::Medium => seads::Preset::Medium,
        PresetChoice::Paper => seads::Preset::Paper,
    };
    let cursor = env.embodiment == mbrl::envs::embodiments::Embodiment::Cursor;
    let mut config = SeadsConfig::preset(preset, env.moves(), cursor);
    if let Some(path) = &args.config {
        config = apply_toml_file(&config, path)?;
    }
    if let Some(k) = args.skills {
        config.skills = k;
    }
    if let Some(n) = args.env_steps {
        config.env_steps = n;
    }
    if args.no_relabel {
        config.relabel = false;
    }
    if args.no_second_best {
        config.reward.second_best = false;
    }
    if args.no_novelty {
        config.reward.novelty = false;
    }
    config.validate()?;
    Ok(config)
}

fn train_seads(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    let env_name = args.env.as_deref().context(format!("seads needs --env ({})", seads::ENV_HELP))?;
    let env = EmbodiedGame::parse(env_name)?;
    let config = seads_config(&args, &env)?;
    let out = fresh_run_dir(
        args.out.clone().unwrap_or_else(|| PathBuf::from(format!("models/seads-{}", file_stem(&env.name())))),
    )?;
    let request = seads::TrainRequest {
        out: out.clone(),
        env,
        config,
        seed: global.seed,
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let report = run_job(global, "train seads", |monitor| seads::train(&request, false, monitor))?;
    print_seads_report(&report, &out)
}

fn print_seads_report(report: &seads::TrainReport, out: &Path) -> anyhow::Result<()> {
    write_loss_report(out, "SEADS forward-model NLL per bit on each epoch's new episodes", "nats per bit")?;
    let run = &report.run;
    let c = &run.config;
    say!(
        "trained SEADS on {}: {} skills, {} epochs, {} env steps (budget {}), SAC hidden layers {}, forward model {} units",
        run.env,
        c.skills,
        report.outcome.steps,
        report.env_steps,
        c.env_steps,
        c.sac_hidden.iter().map(usize::to_string).collect::<Vec<_>>().join(" × "),
        c.model_hidden
    );
    let last = &report.last;
    say!(
        "last epoch: the skills execute {} distinct game moves; forward-model NLL {:.4} nats per bit{}",
        last.distinct_moves,
        last.model_loss,
        last.mean_final_reward.map(|r| format!("; mean intrinsic reward {r:.3}")).unwrap_or_default()
    );
    say!("checkpoint: {}", out.display());
    Ok(())
}

fn dlgpd_config(args: &TrainArgs) -> anyhow::Result<DlgpdConfig> {
    for (flag, given) in [
        ("--ensemble", args.ensemble.is_some()),
        ("--reward", args.reward.is_some()),
        ("--launcher-prior", args.launcher_prior),
        ("--skills", args.skills.is_some()),
        ("--env-steps", args.env_steps.is_some()),
        ("--no-relabel", args.no_relabel),
        ("--no-second-best", args.no_second_best),
        ("--no-novelty", args.no_novelty),
    ] {
        if given {
            bail!(
                "{flag} does not apply to dlgpd; it takes --data, --env, --out, --preset, --config, --steps, --batch, --lr"
            );
        }
    }
    let preset = match args.preset.unwrap_or(PresetChoice::Small) {
        PresetChoice::Small => DlgpdPreset::Small,
        PresetChoice::Medium => DlgpdPreset::Medium,
        PresetChoice::Paper => DlgpdPreset::Paper,
    };
    let mut config = DlgpdConfig::preset(preset);
    if let Some(path) = &args.config {
        config = apply_toml_file(&config, path)?;
    }
    if let Some(n) = args.steps {
        config.steps = n;
    }
    if let Some(n) = args.batch {
        config.batch_size = n;
    }
    if let Some(lr) = args.lr {
        config.learning_rate = lr;
    }
    config.validate()?;
    Ok(config)
}

fn train_dlgpd(global: &GlobalArgs, args: TrainArgs) -> anyhow::Result<()> {
    let config = dlgpd_config(&args)?;
    if args.data.is_empty() {
        bail!("dlgpd needs --data: pendulum rollouts (`mbrl collect --env pendulum [--images]`)");
    }
    let out = fresh_run_dir(args.out.clone().unwrap_or_else(|| PathBuf::from("models/dlgpd-pendulum")))?;
    let request = dlgpd::TrainRequest {
        out: out.clone(),
        data: args.data.clone(),
        env: args.env.clone(),
        config,
        seed: global.seed,
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let report = run_job(global, "train dlgpd", |monitor| dlgpd::train(&request, Start::Fresh, monitor))?;
    print_dlgpd_report(&report, &out)
}

fn print_dlgpd_report(report: &dlgpd::TrainReport, out: &Path) -> anyhow::Result<()> {
    write_loss_report(out, "DLGPD training loss (eq. 3.16 with the SNR penalty, per batch)", "loss")?;
    let run = &report.run;
    let c = &run.config;
    let observed = match run.observation {
        mbrl::models::dlgpd::data::ObservationKind::Images { side } => format!("{side}×{side} frames (conv VAE)"),
        mbrl::models::dlgpd::data::ObservationKind::Angles => "pole angles (MLP VAE, small preset)".to_string(),
    };
    say!(
        "trained DLGPD ({} parameters, latent {}) on {} transitions of {} from {observed} ({} rollouts; {} held out), batch {}",
        report.parameters,
        c.latent_dim,
        run.transitions.train,
        run.env,
        run.transitions.train_rollouts,
        run.transitions.valid_rollouts,
        c.batch_size
    );
    let o = &report.outcome;
    if let Some(loss) = o.last_train_loss {
        say!("final training loss {loss:.3} after {} steps", o.steps);
    }
    if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
        say!("best validation loss {v:.3} at step {step} (saved as model.safetensors)");
    }
    say!("checkpoint: {}", out.display());
    Ok(())
}
