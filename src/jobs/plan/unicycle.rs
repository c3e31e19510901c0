//! `mbrl plan --env unicycle`: energy-efficient navigation on a terrain map (TRADYN, thesis 5.4.3) with a
//! TRADYN model or the simulator itself.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{PlanOptions, PlanSummary};
use crate::control::BatchDynamics;
use crate::data::{write_dataset, Dataset};
use crate::envs::terrain::TerrainMap;
use crate::envs::unicycle::UnicycleTerrain;
use crate::envs::{instance_env, EnvName};
use crate::jobs::model_options::{report_unfinished, ModelOptions};
use crate::jobs::{output_file, parse_floats, Invocation, Job};
use crate::models::context::calibration::read_context;
use crate::models::tradyn::navigation::{layout, navigate, NavigationSettings, NavigationTask};
use crate::models::tradyn::{self, TradynDynamics, TradynModel};
use crate::train::OpenedCheckpoint;
use crate::{refuse, Result};

fn task(options: &PlanOptions) -> Result<NavigationTask> {
    let (Some(start), Some(goal)) = (&options.start, &options.goal) else {
        refuse!("--env unicycle: give --start x,y,φ and --goal x,y (positions in [0, 1]²)");
    };
    let start = parse_floats("--start", start)?;
    let goal = parse_floats("--goal", goal)?;
    let ([x, y, phi], [gx, gy]) = (start.as_slice(), goal.as_slice()) else {
        refuse!("--start takes x,y,φ (3 numbers) and --goal x,y (2 numbers); got {} and {}", start.len(), goal.len());
    };
    let task = NavigationTask { start: [*x, *y, *phi], goal: [*gx, *gy] };
    task.validate()?;
    Ok(task)
}

fn load_dynamics(
    model: &ModelOptions,
    map: &Arc<TerrainMap>,
    truth: Box<dyn crate::envs::Dynamics>,
) -> Result<Box<dyn BatchDynamics>> {
    if model.model == "true" {
        if model.context.is_some() {
            refuse!("--context conditions a TRADYN model; `--model true` plans with the simulator itself");
        }
        return Ok(Box::new(truth));
    }
    let dir = Path::new(&model.model);
    if !dir.is_dir() {
        refuse!("--model '{}': no such checkpoint directory; expected `true` or a TRADYN model", model.model);
    }
    let method = OpenedCheckpoint::open(dir)?.manifest.method;
    if method != tradyn::METHOD {
        refuse!(
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

pub(super) fn prepare(
    options: PlanOptions,
    steps: usize,
    invocation: &Invocation,
) -> Result<Job<'static, PlanSummary>> {
    if options.evidence.is_some() {
        refuse!("--evidence conditions a DLGPD model; the unicycle adapts through --context (`mbrl calibrate`)");
    }
    let Some(map_path) = &options.map else {
        refuse!(
            "--env unicycle: give --map PNG, the terrain to drive on (e.g. a test map of `mbrl collect --env terrain`)"
        );
    };
    let task = task(&options)?;
    let map = Arc::new(TerrainMap::read_png(map_path)?);
    let env_name = EnvName::Unicycle(None).with_terrain(UnicycleTerrain { maps: vec![map.clone()] })?;
    // The robot the instance seed draws (the nominal one without it); built again inside the job, which runs on
    // its own thread.
    let instance_seed = options.instance_seed;
    let make_env = move || match instance_seed {
        Some(seed) => instance_env(&env_name, seed),
        None => env_name.build(),
    };
    let env = make_env()?;
    let truth = env.dynamics().expect("the unicycle has closed-form dynamics");
    let dynamics = load_dynamics(&options.model, &map, truth)?;
    let mut settings = NavigationSettings::thesis();
    settings.steps = steps;
    settings.cem = options.cem.over(settings.cem);
    settings.horizon = settings.cem.horizon;
    settings.validate()?;
    let default = || PathBuf::from(format!("datasets/plan-unicycle-{}.mcap", super::model_tag(&options.model.model)));
    let out = output_file("--out", options.out.as_deref(), default, "mcap", invocation)?;
    let robot = env.params();
    let title = format!("plan: unicycle navigation with {}", dynamics.describe());
    let seed = invocation.seed;
    let command_line = invocation.command_line.clone();
    Ok(Job::new("plan: unicycle navigation", move |monitor| {
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
                &command_line,
            ),
        )?;
        Ok(PlanSummary::Unicycle {
            energy: episode.energy,
            final_distance: episode.final_distance,
            success: episode.success,
            success_distance: settings.success_distance,
            robot,
            out,
        })
    }))
}
