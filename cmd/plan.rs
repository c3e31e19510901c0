//! `mbrl plan`: model-predictive control with CEM in a simulator.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use mbrl::data::write_dataset;
use mbrl::eval::swingup::{self, SwingupEpisode, SwingupSettings};
use mbrl::models::dlgpd;
use mbrl::util::budget;

use crate::common::{check_output_file, command_line, file_stem, pendulum_variant, run_job, GlobalArgs};
use mbrl::jobs::cem_options::CemOptions;
use mbrl::jobs::model_options::{report_unfinished, ModelOptions};

/// Plan with CEM on a model and execute the plan in the simulator (MPC).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl plan --env pendulum --model true --horizon 20 --candidates 1000 --elites 100 --iters 10 --steps 150
  mbrl plan --env pendulum:heavy --model true --noise colored --beta 0.5 --out datasets/heavy-plan.mcap
  mbrl plan --env pendulum --model models/pets-pendulum --particles 20 --propagation tsinf
  mbrl plan --env pendulum:quadrant --model models/context-pendulum-quadrant --context calib.mcap --instance-seed 3
  mbrl collect --env pendulum:inverted --rollouts 20 --steps 29 --images --out datasets/evidence-inverted.mcap
  mbrl plan --env pendulum:inverted --model models/dlgpd-medium --evidence datasets/evidence-inverted.mcap
  mbrl plan --env unicycle --model models/tradyn-terrain --map datasets/terrain/map050.png --start 0.2,0.3,1.57 --goal 0.7,0.6 --context calib-uni.mcap --instance-seed 4
  mbrl plan --env unicycle --model true --map datasets/terrain/map050.png --start 0.2,0.3,1.57 --goal 0.7,0.6

A DLGPD model plans from its observations (rendered frames, or pole angles for the small preset) in its
latent space, on GPs conditioned on --evidence: rollouts of the system at hand (`collect --rollouts N`,
with --images for image models), encoded without retraining. Its CEM also stops once the first action's
std is ≤ 0.01; `--iters 30 --no-warm-start` is the authors' planner.

The pendulum starts hanging (θ ~ U[π-0.05, π+0.05], θ̇ ~ U[-0.05, 0.05]); success means each of the
last 25 rewards is above -1 (thesis 3.5.2).

The unicycle (TRADYN, thesis 5.4.3) drives from --start x,y,φ at rest to --goal x,y on --map for 50 steps,
minimizing ½Σ throttle² plus the terminal squared distance normalized over the candidates (eq. 5.13);
success means a final distance of at most 5 cm. The robot is the one --instance-seed draws (Table 5.1),
or the nominal robot (mass 2.5, gains 750 and 3π/16) without it. `--model true` plans on the simulator
itself (an oracle); a TRADYN model plans with the mean of q(β | --context), the prior's mean without it.")]
pub struct PlanArgs {
    #[arg(long, help = concat!("Environment: ", mbrl::pendulum_envs!(), " or unicycle"))]
    env: String,
    #[command(flatten)]
    model: ModelOptions,
    /// Steps to execute (pendulum 150; unicycle 50).
    #[arg(long)]
    steps: Option<usize>,
    /// Unicycle: the terrain map (PNG) to drive on.
    #[arg(long)]
    map: Option<PathBuf>,
    /// Unicycle: start pose x,y,φ (position in [0, 1]², heading in radians; the robot starts at rest).
    #[arg(long)]
    start: Option<String>,
    /// Unicycle: goal position x,y in [0, 1]².
    #[arg(long)]
    goal: Option<String>,
    #[command(flatten)]
    cem: CemOptions,
    /// DLGPD models: rollouts to condition the GPs on (a dataset written by `collect`).
    #[arg(long)]
    evidence: Option<PathBuf>,
    /// Plan in the instance (hidden parameters) this seed names, as `calibrate --instance-seed` does.
    #[arg(long)]
    instance_seed: Option<u64>,
    /// Where to save the executed rollout (default: datasets/plan-<env>.mcap).
    #[arg(long)]
    out: Option<PathBuf>,
}

impl PlanArgs {
    fn unicycle(&self) -> crate::plan_unicycle::UnicycleTask {
        crate::plan_unicycle::UnicycleTask {
            map: self.map.clone(),
            start: self.start.clone(),
            goal: self.goal.clone(),
            evidence: self.evidence.is_some(),
            instance_seed: self.instance_seed,
            out: self.out.clone(),
        }
    }
}

pub fn run(global: &GlobalArgs, args: PlanArgs) -> anyhow::Result<()> {
    if args.steps == Some(0) {
        bail!("--steps must be at least 1");
    }
    let steps = args.steps.unwrap_or(if args.env == "unicycle" { 50 } else { 150 });
    // The executed rollout and per-step planner records are kept until the file is written.
    budget::check(
        &format!("--steps {steps}"),
        budget::times(&[steps], mbrl::jobs::STEP_RECORD_BYTES),
        "plan fewer steps",
    )?;
    if args.env == "unicycle" {
        return crate::plan_unicycle::run(global, &args.model, &args.cem, steps, args.unicycle());
    }
    for (flag, given) in
        [("--map", args.map.is_some()), ("--start", args.start.is_some()), ("--goal", args.goal.is_some())]
    {
        if given {
            bail!("{flag} sets a unicycle navigation task (--env unicycle); '{}' has none", args.env);
        }
    }
    let variant = pendulum_variant(&args.env)?;
    let mut settings = SwingupSettings::thesis(variant);
    settings.steps = steps;
    settings.instance_seed = args.instance_seed;
    settings.cem = args.cem.config(&settings.cem.action_low, &settings.cem.action_high);
    settings.cem.validate()?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("datasets/plan-{}.mcap", file_stem(&settings.variant.env_name()))));
    check_output_file("--out", &out, "mcap")?;
    let env = mbrl::envs::parse_env(&args.env)?;
    // With --evidence the model can only be DLGPD, so its loader reports why a checkpoint does not open.
    let is_dlgpd = args.model.model != "true"
        && (args.evidence.is_some()
            || mbrl::train::OpenedCheckpoint::open(std::path::Path::new(&args.model.model))
                .is_ok_and(|c| c.manifest.method == dlgpd::job::METHOD));
    if is_dlgpd {
        return plan_dlgpd(global, &args, settings, &out);
    }
    if args.evidence.is_some() {
        bail!("--evidence conditions a DLGPD model's GPs; {} is not a DLGPD checkpoint", args.model.model);
    }
    let model = args.model.load(&env)?;
    let model = model.as_deref();
    let seed = global.seed;
    let title = format!("plan: pendulum swing-up with {}", swingup::model_description(model));
    let episode = run_job(global, "plan: pendulum swing-up", |monitor| {
        monitor.emit(&swingup::layout(&title, model.is_some()));
        let episode = swingup::run_episode(&settings, model, seed, 0, monitor)?;
        write_dataset(
            &out,
            &swingup::episodes_dataset(&settings, seed, &command_line(), std::slice::from_ref(&episode)),
        )?;
        Ok(episode)
    })?;
    say!(
        "return {:.2}, success: {} (last 25 rewards > -1); rollout saved to {}",
        episode.total_return,
        if episode.success { "yes" } else { "no" },
        out.display()
    );
    Ok(())
}

fn plan_dlgpd(
    global: &GlobalArgs,
    args: &PlanArgs,
    settings: SwingupSettings,
    out: &std::path::Path,
) -> anyhow::Result<()> {
    let Some(evidence_path) = &args.evidence else {
        bail!(
            "{} is a DLGPD model: pass --evidence ROLLOUTS.mcap (rollouts of the system at hand, e.g. `mbrl collect \
             --env {} --rollouts 20 --steps 29`, adding --images for a model trained on frames)",
            args.model.model,
            args.env
        );
    };
    if args.instance_seed.is_some() || args.model.context.is_some() {
        bail!("--instance-seed and --context are for context models; a DLGPD model adapts through --evidence");
    }
    let model_dir = std::path::Path::new(&args.model.model);
    let trained = dlgpd::job::load(model_dir, args.model.accept())?;
    report_unfinished(model_dir, &trained.progress);
    let evidence = mbrl::data::read_dataset(evidence_path)?;
    let seed = global.seed;
    let dynamics = dlgpd::control::condition_on(&trained, &evidence, seed)
        .map_err(|e| anyhow::anyhow!("{}: {e}", evidence_path.display()))?;
    if dynamics.jitter() > 0.0 {
        eprintln!(
            "warning: the evidence's kernel matrix needed diagonal jitter {:.1e} to factor (near-duplicate \
             evidence points)",
            dynamics.jitter()
        );
    }
    let mut control = dlgpd::control::ControlSettings::authors(settings.variant.clone());
    control.steps = settings.steps;
    control.cem = mbrl::planning::CemConfig { stop_std: Some(dlgpd::control::STOP_STD), ..settings.cem.clone() };
    let title = format!(
        "plan: {} swing-up with DLGPD on {} evidence transitions from {}{}",
        settings.variant.env_name(),
        dynamics.evidence_len(),
        evidence.meta.env,
        trained.progress.unfinished_note()
    );
    let episode = run_job(global, "plan: DLGPD swing-up", |monitor| {
        monitor.emit(&swingup::layout(&title, false));
        dlgpd::control::swing_up(&trained, &dynamics, &control, seed, monitor)
    })?;
    let iterations = episode.iterations.iter().sum::<usize>() as f64 / episode.iterations.len().max(1) as f64;
    let record = SwingupEpisode {
        episode: 0,
        instance: serde_json::json!({}),
        rollout: episode.rollout,
        total_return: episode.total_return,
        success: episode.success,
    };
    write_dataset(out, &swingup::episodes_dataset(&settings, seed, &command_line(), std::slice::from_ref(&record)))?;
    say!(
        "return {:.2}, success: {} (last 25 rewards > -1); {:.1} CEM iterations per step; evidence: {} transitions of {}{}; rollout saved to {}",
        record.total_return,
        if record.success { "yes" } else { "no" },
        iterations,
        dynamics.evidence_len(),
        evidence.meta.env,
        trained.progress.unfinished_note(),
        out.display()
    );
    Ok(())
}
