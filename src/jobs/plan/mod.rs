//! `mbrl plan`: model-predictive control with CEM in a simulator.

mod dlgpd;
mod unicycle;

use std::fmt;
use std::path::{Path, PathBuf};

use clap::Args;

use super::cem_options::CemOptions;
use super::model_options::ModelOptions;
use super::{file_stem, output_file, pendulum_variant, Invocation, Job, STEP_RECORD_BYTES};
use crate::data::write_dataset;
use crate::eval::swingup::{self, SwingupSettings};
use crate::models::dlgpd::job::METHOD as DLGPD;
use crate::util::budget;
use crate::{refuse, Result};

/// Plan with CEM on a model and execute the plan in the simulator (MPC).
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl plan --env pendulum --model true --horizon 20 --candidates 1000 --elites 100 --iters 10 --steps 150
  mbrl plan --env pendulum:heavy --model true --noise colored --beta 0.5 --out datasets/heavy-plan.mcap
  mbrl plan --env pendulum --model models/pets-pendulum --particles 20 --propagation tsinf
  mbrl plan --env pendulum:quadrant --model models/context-pendulum-quadrant --context calib-quadrant.mcap --instance-seed 3   # models and calibration: see `mbrl calibrate --help`
  mbrl collect --env pendulum:inverted --rollouts 20 --steps 29 --images --out datasets/evidence-inverted.mcap
  mbrl plan --env pendulum:inverted --model models/dlgpd-medium --evidence datasets/evidence-inverted.mcap
  mbrl plan --env unicycle --model models/tradyn-terrain --map datasets/terrain/map050.png --start 0.2,0.3,1.57 --goal 0.7,0.6 --context calib-uni.mcap --instance-seed 4
  mbrl plan --env unicycle --model true --map datasets/terrain/map050.png --start 0.2,0.3,1.57 --goal 0.7,0.6

A DLGPD model plans from its observations (rendered frames, or pole angles for the small preset) in its latent space, on GPs conditioned on --evidence: rollouts of the system at hand (`collect --rollouts N`, with --images for image models), encoded without retraining. Its CEM also stops once the first action's std is ≤ 0.01; `--iters 30 --no-warm-start` is the authors' planner.

The pendulum starts hanging (θ ~ U[π-0.05, π+0.05], θ̇ ~ U[-0.05, 0.05]); success means each of the last 25 rewards is above -1 (thesis 3.5.2).

The unicycle (TRADYN, thesis 5.4.3) drives from --start x,y,φ at rest to --goal x,y on --map for 50 steps, minimizing ½Σ throttle² plus the terminal squared distance normalized over the candidates (eq. 5.13); success means a final distance of at most 5 cm. The robot is the one --instance-seed draws (Table 5.1), or the nominal robot (mass 2.5, gains 750 and 3π/16) without it. `--model true` plans on the simulator itself (an oracle); a TRADYN model plans with the mean of q(β | --context), the prior's mean without it.")]
pub struct PlanOptions {
    #[arg(long, value_parser = crate::jobs::names::plan_envs(), hide_possible_values = true, help = concat!("Environment: ", crate::pendulum_envs!(), " or unicycle"))]
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
    /// Where to save the executed rollout (default: datasets/plan-<env>-<model>.mcap, <model> being `true` or the
    /// checkpoint's directory name; when that exists, the first free name ending -2, -3, …).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// How the executed episode went, and where its rollout was saved.
pub enum PlanSummary {
    Swingup {
        total_return: f64,
        success: bool,
        out: PathBuf,
    },
    Dlgpd {
        total_return: f64,
        success: bool,
        /// Mean CEM iterations per step: DLGPD's planner stops early once its action std is small.
        iterations: f64,
        evidence_transitions: usize,
        evidence_env: String,
        unfinished_note: String,
        out: PathBuf,
    },
    Unicycle {
        energy: f64,
        final_distance: f64,
        success: bool,
        success_distance: f64,
        robot: serde_json::Value,
        out: PathBuf,
    },
}

fn yes_no(flag: bool) -> &'static str {
    if flag {
        "yes"
    } else {
        "no"
    }
}

impl fmt::Display for PlanSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            PlanSummary::Swingup { total_return, success, out } => write!(
                f,
                "return {total_return:.2}, success: {} (last 25 rewards > -1); rollout saved to {}",
                yes_no(*success),
                out.display()
            ),
            PlanSummary::Dlgpd {
                total_return,
                success,
                iterations,
                evidence_transitions,
                evidence_env,
                unfinished_note,
                out,
            } => write!(
                f,
                "return {total_return:.2}, success: {} (last 25 rewards > -1); {iterations:.1} CEM iterations per \
                 step; evidence: {evidence_transitions} transitions of {evidence_env}{unfinished_note}; rollout saved \
                 to {}",
                yes_no(*success),
                out.display()
            ),
            PlanSummary::Unicycle { energy, final_distance, success, success_distance, robot, out } => write!(
                f,
                "energy Σ throttle² {energy:.3}, final distance {final_distance:.4} m, success: {} (≤ \
                 {success_distance} m); robot {robot}; rollout saved to {}",
                yes_no(*success),
                out.display()
            ),
        }
    }
}

pub fn prepare(options: PlanOptions, invocation: &Invocation) -> Result<Job<'static, PlanSummary>> {
    if options.steps == Some(0) {
        refuse!("--steps must be at least 1");
    }
    let steps = options.steps.unwrap_or(if options.env == "unicycle" { 50 } else { 150 });
    // The executed rollout and per-step planner records are kept until the file is written.
    budget::check(&format!("--steps {steps}"), budget::times(&[steps], STEP_RECORD_BYTES), "plan fewer steps")?;
    if options.env == "unicycle" {
        return unicycle::prepare(options, steps, invocation);
    }
    for (flag, given) in
        [("--map", options.map.is_some()), ("--start", options.start.is_some()), ("--goal", options.goal.is_some())]
    {
        if given {
            refuse!("{flag} sets a unicycle navigation task (--env unicycle); '{}' has none", options.env);
        }
    }
    let variant = pendulum_variant(&options.env)?;
    let mut settings = SwingupSettings::thesis(variant);
    settings.steps = steps;
    settings.instance_seed = options.instance_seed;
    settings.cem = options.cem.config(&settings.cem.action_low, &settings.cem.action_high);
    settings.cem.validate()?;
    let default = || {
        let (env, model) = (file_stem(&settings.variant.env_name()), model_tag(&options.model.model));
        PathBuf::from(format!("datasets/plan-{env}-{model}.mcap"))
    };
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    let env = crate::envs::parse_env(&options.env)?;
    // With --evidence the model can only be DLGPD, so its loader reports why a checkpoint does not open.
    let is_dlgpd = options.model.model != "true"
        && (options.evidence.is_some()
            || crate::train::OpenedCheckpoint::open(std::path::Path::new(&options.model.model))
                .is_ok_and(|c| c.manifest.method == DLGPD));
    if is_dlgpd {
        return dlgpd::prepare(&options, settings, out, invocation);
    }
    if options.evidence.is_some() {
        refuse!("--evidence conditions a DLGPD model's GPs; {} is not a DLGPD checkpoint", options.model.model);
    }
    let model = options.model.load(&env)?;
    let seed = invocation.seed;
    let command_line = invocation.command_line.clone();
    let title = format!("plan: pendulum swing-up with {}", swingup::model_description(model.as_deref()));
    Ok(Job::new("plan: pendulum swing-up", move |monitor| {
        let model = model.as_deref();
        monitor.emit(&swingup::layout(&title, model.is_some()));
        let episode = swingup::run_episode(&settings, model, seed, 0, monitor)?;
        write_dataset(
            &out,
            &swingup::episodes_dataset(&settings, seed, &command_line, std::slice::from_ref(&episode)),
        )?;
        Ok(PlanSummary::Swingup { total_return: episode.total_return, success: episode.success, out })
    }))
}

/// What a default output name says about the dynamics planned with: `true`, or the checkpoint's directory name.
fn model_tag(model: &str) -> String {
    let name = Path::new(model).file_name().map_or_else(|| model.to_string(), |n| n.to_string_lossy().into_owned());
    file_stem(&name)
}
