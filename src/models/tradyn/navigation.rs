//! Energy-efficient navigation (thesis 5.4.3, eq. 5.13): receding-horizon CEM that trades the throttle energy
//! ½Σu² against the terminal squared distance to the goal, normalized over the candidates of each iteration so
//! that neither term's scale depends on the task. The planner's dynamics may be a TRADYN model or the simulator
//! itself (an oracle).

use crate::control::Objective;
use crate::control::{run_episode, Agent, BatchDynamics};
use crate::data::Rollout;
use crate::envs::terrain::TerrainMap;
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::planning::mpc::planning_failed;
use crate::planning::{Cem, CemConfig, NoiseKind};
use crate::run::{Background, Event, Monitor, PanelSpec, PathView};
use crate::util::seeding::derive_seed;

/// Start pose (x, y, φ; the robot is at rest) and goal position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavigationTask {
    pub start: [f64; 3],
    pub goal: [f64; 2],
}

impl NavigationTask {
    pub fn validate(&self) -> Result<()> {
        let on_map = |p: &[f64]| p.iter().all(|c| (0.0..=1.0).contains(c));
        if !on_map(&self.start[..2]) || !self.start[2].is_finite() {
            return Err(Error::config(format!(
                "the start ({}, {}, φ {}) must lie in [0, 1]² with a finite heading",
                self.start[0], self.start[1], self.start[2]
            )));
        }
        if !on_map(&self.goal) {
            return Err(Error::config(format!("the goal ({}, {}) must lie in [0, 1]²", self.goal[0], self.goal[1])));
        }
        Ok(())
    }

    /// The env state the task starts in.
    pub fn start_state(&self) -> [f64; 4] {
        [self.start[0], self.start[1], 0.0, self.start[2]]
    }
}

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct NavigationSettings {
    /// Actions executed (50).
    pub steps: usize,
    /// The longest horizon; it shrinks to the steps left near the end (30).
    pub horizon: usize,
    /// CEM; its horizon is set per step.
    pub cem: CemConfig,
    /// Success: the final distance to the goal is at most this (5 cm).
    pub success_distance: f64,
}

impl NavigationSettings {
    /// The authors' planner: CEM 1000 candidates / 50 elites / 20 iterations, initial std 0.5, colored noise
    /// β 0.5 drawn afresh with the current horizon, no warm start; 50 steps, horizon min(30, 50 − t).
    pub fn thesis() -> Self {
        NavigationSettings {
            steps: 50,
            horizon: 30,
            cem: CemConfig {
                horizon: 30,
                candidates: 1000,
                elites: 50,
                iterations: 20,
                action_low: vec![-1.0, -1.0],
                action_high: vec![1.0, 1.0],
                init_std: vec![0.5, 0.5],
                noise: NoiseKind::Colored { beta: 0.5 },
                warm_start: false,
                stop_std: None,
            },
            success_distance: 0.05,
        }
    }

    pub fn validate(&self) -> Result<()> {
        if self.steps == 0 || self.horizon == 0 {
            return Err(Error::config("navigation needs at least one step and a horizon of at least 1"));
        }
        CemConfig { horizon: self.horizon, ..self.cem.clone() }.validate()
    }
}

/// Eq. 5.13 for a batch of candidates: ½Σ throttle² (the dynamics' return is its negative) plus the z-score of
/// the terminal squared distance among the candidates (population std; all equal → 0).
pub struct NavigationObjective<'a> {
    pub dynamics: &'a dyn BatchDynamics,
    pub init: &'a [f64],
    pub goal: [f64; 2],
}

impl Objective for NavigationObjective<'_> {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
        let d = self.dynamics.state_dim();
        let n = costs.len();
        let mut returns = vec![0.0; n];
        let mut states = vec![0.0; n * horizon * d];
        self.dynamics.rollout(self.init, candidates, horizon, 0, &mut returns, Some(&mut states));
        let distances: Vec<f64> = (0..n)
            .map(|i| {
                let last = &states[(i * horizon + horizon - 1) * d..];
                (last[0] - self.goal[0]).powi(2) + (last[1] - self.goal[1]).powi(2)
            })
            .collect();
        let mean = distances.iter().sum::<f64>() / n as f64;
        let std = (distances.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        for ((c, r), dist) in costs.iter_mut().zip(&returns).zip(&distances) {
            let z = if std > 0.0 { (dist - mean) / std } else { 0.0 };
            *c = -r + z;
        }
    }
}

/// One executed step, with the plan it came from.
pub struct NavigationStep<'a> {
    pub t: usize,
    pub state: &'a [f64],
    pub action: &'a [f64],
    pub next_state: &'a [f64],
    /// The planned sequence's predicted states (horizon × 4).
    pub planned: &'a [f64],
}

#[derive(Clone, Debug, PartialEq)]
pub struct NavigationEpisode {
    pub rollout: Rollout,
    /// E = Σ throttle² over the executed actions (thesis 5.5.3).
    pub energy: f64,
    pub final_distance: f64,
    pub success: bool,
}

pub fn distance(state: &[f64], goal: [f64; 2]) -> f64 {
    ((state[0] - goal[0]).powi(2) + (state[1] - goal[1]).powi(2)).sqrt()
}

/// Cells per side of the map drawn under the live view's paths.
const VIEW_CELLS: u32 = 64;

/// The map as a coarse colour grid (cell centres), x along the first index as on the map.
pub fn map_background(map: &TerrainMap) -> Background {
    Background { cells: VIEW_CELLS, rgb: map.coarse_rgb(VIEW_CELLS as usize) }
}

/// The live view of a navigation: the robot's path and its current plan over the map, the distance to the
/// goal, and the CEM costs of the current step.
pub fn layout(title: &str, map: &TerrainMap, goal: [f64; 2]) -> Event {
    let panel = |title: &str, x_label: &str, series: &[&str], restart: bool| PanelSpec {
        title: title.into(),
        x_label: x_label.into(),
        series: series.iter().map(|s| s.to_string()).collect(),
        restart_on_rewind: restart,
        path: None,
    };
    let map_title =
        format!("map, goal ({:.2}, {:.2}): driven path (cyan), plan (magenta); x right, y up", goal[0], goal[1]);
    let mut map_panel = panel(&map_title, "x", &["robot/x", "robot/y", "plan/x", "plan/y"], true);
    map_panel.path =
        Some(PathView { x: [0.0, 1.0], y: [0.0, 1.0], grid: 0, y_down: false, background: Some(map_background(map)) });
    Event::Layout {
        title: title.into(),
        panels: vec![
            map_panel,
            panel("distance to goal (m)", "step", &["navigation/distance"], false),
            panel("CEM (current step)", "iteration", &["cem/best_cost", "cem/elite_mean_cost"], true),
        ],
    }
}

/// Receding-horizon CEM on eq. 5.13: at step `t` a fresh CEM with horizon min(H, steps − t) plans from the
/// env state, and the planned sequence's predicted states are kept for the caller (the live view draws them).
pub struct NavigationAgent<'a> {
    dynamics: &'a dyn BatchDynamics,
    goal: [f64; 2],
    settings: &'a NavigationSettings,
    seed: u64,
    monitor: &'a dyn Monitor,
    planned: Vec<f64>,
}

impl<'a> NavigationAgent<'a> {
    pub fn new(
        dynamics: &'a dyn BatchDynamics,
        goal: [f64; 2],
        settings: &'a NavigationSettings,
        seed: u64,
        monitor: &'a dyn Monitor,
    ) -> Self {
        NavigationAgent { dynamics, goal, settings, seed, monitor, planned: Vec::new() }
    }

    /// The last plan's predicted states (horizon × state dim).
    pub fn planned(&self) -> &[f64] {
        &self.planned
    }
}

impl Agent for NavigationAgent<'_> {
    fn act(&mut self, t: usize, state: &[f64], _observation: &[f64]) -> Result<Vec<f64>> {
        let (settings, monitor) = (self.settings, self.monitor);
        let horizon = settings.horizon.min(settings.steps - t);
        let objective = NavigationObjective { dynamics: self.dynamics, init: state, goal: self.goal };
        let mut cem = Cem::new(CemConfig { horizon, ..settings.cem.clone() }, derive_seed(self.seed, &[t as u64]))?;
        let phase = format!("step {}/{}: planning", t + 1, settings.steps);
        let plan = cem.plan(&objective, |it| {
            monitor.scalar("cem/best_cost", it.iteration as u64, it.best_cost);
            monitor.scalar("cem/elite_mean_cost", it.iteration as u64, it.elite_mean_cost);
            monitor.progress(&phase, it.iteration as u64 + 1, settings.cem.iterations as u64);
        });
        let plan = plan.map_err(|e| planning_failed(t, e))?;
        let d = self.dynamics.state_dim();
        self.planned = vec![0.0; horizon * d];
        self.dynamics.rollout(state, &plan, horizon, 0, &mut [0.0], Some(&mut self.planned));
        monitor.scalar("plan/x", 0, state[0]);
        monitor.scalar("plan/y", 0, state[1]);
        for (k, p) in self.planned.chunks(d).enumerate() {
            monitor.scalar("plan/x", k as u64 + 1, p[0]);
            monitor.scalar("plan/y", k as u64 + 1, p[1]);
        }
        Ok(plan[..2].to_vec())
    }
}

/// Puts `env` at the task's start and drives it for `settings.steps` steps with CEM on `dynamics`.
pub fn navigate(
    env: &mut dyn Env,
    dynamics: &dyn BatchDynamics,
    task: &NavigationTask,
    settings: &NavigationSettings,
    seed: u64,
    monitor: &dyn Monitor,
    mut on_step: impl FnMut(&NavigationStep),
) -> Result<NavigationEpisode> {
    task.validate()?;
    settings.validate()?;
    env.set_state(&task.start_state());
    let start = env.state();
    monitor.scalar("robot/x", 0, start[0]);
    monitor.scalar("robot/y", 0, start[1]);
    monitor.scalar("navigation/distance", 0, distance(&start, task.goal));
    let mut agent = NavigationAgent::new(dynamics, task.goal, settings, seed, monitor);
    let rollout = run_episode(env, &mut agent, settings.steps, monitor, |step, _, agent| {
        let (t, next_state) = (step.t, &step.next_state);
        on_step(&NavigationStep { t, state: &step.state, action: &step.action, next_state, planned: agent.planned() });
        monitor.scalar("robot/x", t as u64 + 1, next_state[0]);
        monitor.scalar("robot/y", t as u64 + 1, next_state[1]);
        monitor.scalar("navigation/distance", t as u64 + 1, distance(next_state, task.goal));
        monitor.progress("navigation steps", t as u64 + 1, settings.steps as u64);
        Ok(())
    })?;
    let energy = rollout.actions.iter().map(|a| crate::envs::unicycle::clip_action(a[0]).powi(2)).sum();
    let final_distance = distance(rollout.states.last().expect("a rollout has a start"), task.goal);
    Ok(NavigationEpisode { rollout, energy, final_distance, success: final_distance <= settings.success_distance })
}
