//! `mbrl plan --env unicycle`: energy-efficient navigation on a terrain map (TRADYN, thesis 5.4.3) with a
//! TRADYN model or the simulator itself.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::bail;
use mbrl::control::BatchDynamics;
use mbrl::data::{write_dataset, Dataset};
use mbrl::envs::terrain::TerrainMap;
use mbrl::envs::unicycle::UnicycleTerrain;
use mbrl::envs::{instance_env, EnvName};
use mbrl::models::context::calibration::read_context;
use mbrl::models::tradyn::navigation::{layout, navigate, NavigationSettings, NavigationTask};
use mbrl::models::tradyn::{self, TradynDynamics, TradynModel};
use mbrl::train::OpenedCheckpoint;

use crate::common::{check_output_file, command_line, parse_floats, run_job, GlobalArgs};
use mbrl::jobs::cem_options::CemOptions;
use mbrl::jobs::model_options::{report_unfinished, ModelOptions};

/// The unicycle flags of `plan`.
pub struct UnicycleTask {
    pub map: Option<PathBuf>,
    pub start: Option<String>,
    pub goal: Option<String>,
    pub evidence: bool,
    pub instance_seed: Option<u64>,
    pub out: Option<PathBuf>,
}

fn task(flags: &UnicycleTask) -> anyhow::Result<NavigationTask> {
    let (Some(start), Some(goal)) = (&flags.start, &flags.goal) else {
        bail!("--env unicycle: give --start x,y,φ and --goal x,y (positions in [0, 1]²)");
    };
    let start = parse_floats("--start", start)?;
    let goal = parse_floats("--goal", goal)?;
    let ([x, y, phi], [gx, gy]) = (start.as_slice(), goal.as_slice()) else {
        bail!("--start takes x,y,φ (3 numbers) and --goal x,y (2 numbers); got {} and {}", start.len(), goal.len());
    };
    let task = NavigationTask { start: [*x, *y, *phi], goal: [*gx, *gy] };
    task.validate()?;
    Ok(task)
}

fn load_dynamics(
    model: &ModelOptions,
    map: &Arc<TerrainMap>,
    truth: Box<dyn mbrl::envs::Dynamics>,
) -> anyhow::Result<Box<dyn BatchDynamics>> {
    if model.model == "true" {
        if model.context.is_some() {
            bail!("--context conditions a TRADYN model; `--model true` plans with the simulator itself");
        }
        return Ok(Box::new(truth));
    }
    let dir = Path::new(&model.model);
    if !dir.is_dir() {
        bail!("--model '{}': no such checkpoint directory; expected `true` or a TRADYN model", model.model);
    }
    let method = OpenedCheckpoint::open(dir)?.manifest.method;
    if method != tradyn::METHOD {
        bail!(
            "{}: is a '{method}' checkpoint; unicycle navigation plans with a TRADYN model (`mbrl train tradyn`) or --model true",
            dir.display()
        );
    }
    let trained = TradynModel::load(dir, model.accept())?;
    report_unfinished(dir, &trained.loaded.progress);
    let rows = match &model.context {
        Some(path) => read_context(&trained.loaded, path)?,
        None => Vec::new(),
    };
    Ok(Box::new(TradynDynamics::new(trained, map.clone(), &rows)))
}

pub fn run(
    global: &GlobalArgs,
    model: &ModelOptions,
    cem: &CemOptions,
    steps: usize,
    flags: UnicycleTask,
) -> anyhow::Result<()> {
    if flags.evidence {
        bail!("--evidence conditions a DLGPD model; the unicycle adapts through --context (`mbrl calibrate`)");
    }
    let Some(map_path) = &flags.map else {
        bail!(
            "--env unicycle: give --map PNG, the terrain to drive on (e.g. a test map of `mbrl collect --env terrain`)"
        );
    };
    let task = task(&flags)?;
    let map = Arc::new(TerrainMap::read_png(map_path)?);
    let env_name = EnvName::Unicycle(None).with_terrain(UnicycleTerrain { maps: vec![map.clone()] })?;
    // The robot the instance seed draws (the nominal one without it); built again inside the job, which runs on
    // its own thread.
    let make_env = || match flags.instance_seed {
        Some(seed) => instance_env(&env_name, seed),
        None => env_name.build(),
    };
    let env = make_env()?;
    let truth = env.dynamics().expect("the unicycle has closed-form dynamics");
    let dynamics = load_dynamics(model, &map, truth)?;
    let mut settings = NavigationSettings::thesis();
    settings.steps = steps;
    settings.cem = cem.over(settings.cem);
    settings.horizon = settings.cem.horizon;
    settings.validate()?;
    let out = flags.out.clone().unwrap_or_else(|| PathBuf::from("datasets/plan-unicycle.mcap"));
    check_output_file("--out", &out, "mcap")?;
    let robot = env.params();
    let title = format!("plan: unicycle navigation with {}", dynamics.describe());
    let seed = global.seed;
    let episode = run_job(global, "plan: unicycle navigation", |monitor| {
        monitor.emit(&layout(&title, &map, task.goal));
        let mut env = make_env()?;
        let episode = navigate(env.as_mut(), dynamics.as_ref(), &task, &settings, seed, monitor, |_| {})?;
        let spec = env.spec();
        write_dataset(
            &out,
            &Dataset::of_rollouts(
                &spec,
                vec![robot.clone()],
                std::slice::from_ref(&episode.rollout),
                seed,
                &command_line(),
            ),
        )?;
        Ok(episode)
    })?;
    say!(
        "energy Σ throttle² {:.3}, final distance {:.4} m, success: {} (≤ {} m); robot {}; rollout saved to {}",
        episode.energy,
        episode.final_distance,
        if episode.success { "yes" } else { "no" },
        settings.success_distance,
        robot,
        out.display()
    );
    Ok(())
}
