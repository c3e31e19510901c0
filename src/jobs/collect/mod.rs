//! `mbrl collect`: roll out a behaviour policy in a simulator and save the dataset as MCAP.
//!
//! One file per source: random rollouts and instance pairs, replayed actions, embodied board episodes,
//! terrain maps, board sets and ball shots.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::choices::SplitChoice;
use super::{Invocation, Job};
use crate::data::collect_frames::check_frames_size;
use crate::envs::{parse_env, EnvName};
use crate::{refuse, Result};

mod ball;
mod boards;
mod embodied;
mod random;
mod replay;
mod summary;
mod terrain;

pub use summary::CollectSummary;

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Policy {
    /// Random actions: uniform within the action bounds (the unicycle: colored noise, as its authors drew).
    Random,
}

/// Collect rollouts from a simulator into an MCAP dataset.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl collect --env pendulum --rollouts 500 --steps 30 --out datasets/pendulum.mcap
  mbrl collect --env pendulum:quadrant --rollouts 100 --steps 50 --seed 3
  mbrl collect --env pendulum:inverted --images --rollouts 500 --steps 29 --out datasets/pendulum-inverted-images.mcap
  mbrl collect --env toy:inner --instances 5000 --steps 100 --out datasets/toy-inner-train.mcap
  mbrl collect --env mountaincar --instances 1000 --steps 100 --seed 1
  printf '2\n2\n-2\n-2\n' > actions.csv        # one action per row; two columns for two action dimensions
  printf '0.5,0\n0.5,0.2\n' > actions-2d.csv
  mbrl collect --env pendulum --actions actions.csv --init-state 3.14,0 --out datasets/replay.mcap
  mbrl collect --env mountaincar --actions actions.csv --instance-seed 7 --seed 2
  mbrl collect --env lightsout --boards --max-depth 5 --split test --out datasets/lightsout-test.mcap
  mbrl collect --env ball --trajectories 100 --augment-rotations 19 --out datasets/ball-train.mcap
  mbrl collect --env ball --trajectories 30 --orientation unseen-3 --out datasets/ball-unseen-3.mcap
  mbrl collect --env lightsout:cursor --episodes 1000 --seed 1 --out datasets/lightsout-cursor-random.mcap
  mbrl collect --env tileswap:reacher --actions actions-2d.csv --init-state 0.5,1.2,0,0 --board 1,0,2,3,4,5,6,7,8
  mbrl collect --env terrain --maps 100 --out datasets/terrain
  mbrl collect --env unicycle --maps datasets/terrain --split train --instances 10000 --steps 100
  mbrl collect --env unicycle --map datasets/terrain/map050.png --actions actions-2d.csv --init-state 0.2,0.3,0,1.57

Start states: θ ~ U[-π, π], θ̇ ~ U[-8, 8] (pendulum); s ~ N(0, I) (toy); x ~ U[-0.8, 0.8], ẋ ~ U[-2, 2] (mountaincar). Actions uniform in the env's bounds. Parametrized envs (pendulum:quadrant, toy:*, mountaincar) draw a new instance per rollout, or per pair with --instances (rollouts 2k and 2k+1 share instance k); the parameters go into the metadata.

--actions replays a CSV (one row per step, one column per action dimension, optional header) from --init-state or a reset state drawn from --seed, in the instance --instance-seed names (default: --seed); actions beyond the bounds are clipped by the env.

Board sets (lightsout 5x5, tileswap) hold every board of depth 1..D with its train/test split.

Terrain: --maps N writes N random 460 × 460 PNG maps (background colour and Bézier patches) and a manifest, terrain.json, into the new directory --out (default datasets/terrain): maps 0..N/2 train, the rest test. Unicycle: on one --map PNG (any 8-bit RGB image, resized to 460 × 460; x runs down its rows, y along its columns) or on the --split of a map set --maps DIR, a map drawn per instance with the robot (mass, throttle and steer gains of Table 5.1); x, y ~ U[0, 1], v ~ U[-5, 5], φ ~ U[0, 2π); actions colored noise (β 0.5, std 0.5, clipped to [-1, 1]); --init-state x,y,v,φ.

Embodied boards (<game>:cursor|reacher|jaco) are recorded as skill episodes, one rollout each: an episode ends when the board changes or after 10 (cursor) / 50 (reacher, jaco) steps. --episodes N: random actions, each episode from a uniformly scrambled board and a reset manipulator. --actions: one run through the CSV (3 columns: dx,dy,push for cursor; two torques,push for reacher; 9 target joint velocities in rad/s for jaco), split into episodes the same way, from --board (default: the solved board) and --init-state (cursor: x,y in [0,1]; reacher: shoulder,wrist angles in rad (|wrist| <= 160 deg) and their velocities; jaco: 9 joint angles and 9 velocities; default: a reset drawn from --seed).

Ball shots: launcher settings drawn as in thesis 6.5.1, 180 Hz camera with ~1 mm noise and dropouts.")]
pub struct CollectOptions {
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true, help = concat!("Environment: ", crate::known_envs!()))]
    env: String,
    /// Number of rollouts, each in its own instance of a parametrized env.
    #[arg(long, default_value_t = 100)]
    rollouts: usize,
    /// Instead of --rollouts: N instances with two rollouts each (ids 2k, 2k+1), for context models.
    #[arg(long, value_name = "N", conflicts_with = "rollouts")]
    instances: Option<usize>,
    /// Replay these actions (CSV: one row per step, one column per action dimension) instead of random ones.
    #[arg(long, value_name = "CSV", conflicts_with_all = ["rollouts", "instances", "steps", "trajectories", "boards"])]
    actions: Option<PathBuf>,
    /// With --actions: the start state, comma-separated (pendulum: θ,θ̇; toy: s1,s2; mountaincar: x,ẋ;
    /// unicycle: x,y,v,φ; <game>:cursor: x,y; <game>:reacher: shoulder,wrist,shoulder velocity,wrist velocity; <game>:jaco: 9 angles, 9 velocities).
    #[arg(long, value_name = "X1,X2,…", requires = "actions", allow_hyphen_values = true)]
    init_state: Option<String>,
    /// With --actions: which instance of a parametrized env (default: --seed); the same seed names the same
    /// instance in every subcommand.
    #[arg(long, value_name = "S", requires = "actions")]
    instance_seed: Option<u64>,
    /// With --actions on <game>:cursor|reacher|jaco: the start board, comma-separated as solve-board takes it
    /// (default: the solved board).
    #[arg(long, value_name = "BOARD", requires = "actions")]
    board: Option<String>,
    /// For <game>:cursor|reacher|jaco: N skill episodes of random actions, each from a scrambled board.
    #[arg(long, value_name = "N", conflicts_with_all = ["rollouts", "instances", "steps", "actions", "boards"])]
    episodes: Option<usize>,
    /// Steps per rollout.
    #[arg(long, default_value_t = 30)]
    steps: usize,
    /// Pendulum: also store a 64 × 64 RGB frame of every state (gym's rendering, DLGPD's observations), shown
    /// by Foxglove's Image panel on /frames.
    #[arg(long, conflicts_with_all = ["trajectories", "boards", "episodes"])]
    images: bool,
    /// Behaviour policy.
    #[arg(long, value_enum, default_value_t = Policy::Random)]
    policy: Policy,
    /// Output file (default: datasets/<env>-random.mcap, <env>-pairs.mcap, <env>-replay.mcap, or
    /// <game>-boards-d<D>.mcap; when that exists, the first free name ending -2, -3, …). An existing --out is
    /// replaced only with --force.
    #[arg(long)]
    out: Option<PathBuf>,
    /// For the ball: number of simulated shots (each with exactly one table bounce).
    #[arg(long)]
    trajectories: Option<usize>,
    /// For the ball: launcher pose, default or unseen-1..unseen-5 (thesis 6.5.1).
    #[arg(long, default_value = "default", requires = "trajectories", value_parser = crate::jobs::names::orientations(), hide_possible_values = true)]
    orientation: String,
    /// For the ball: rotated copies added per shot, about z through its lowest point (19 in the thesis).
    #[arg(long, default_value_t = 0, requires = "trajectories")]
    augment_rotations: usize,
    /// For board games: write the set of all boards of solution depth 1..=--max-depth with their split.
    #[arg(long, requires = "max_depth")]
    boards: bool,
    /// Deepest solution depth in a board set.
    #[arg(long, requires = "boards")]
    max_depth: Option<u8>,
    /// Only boards of this split (--boards), or the maps of this split of a map set (--maps DIR).
    #[arg(long, value_enum)]
    split: Option<SplitChoice>,
    /// For --env terrain: how many maps to make. For --env unicycle: a map set directory (with terrain.json)
    /// whose --split maps the instances are drawn on.
    #[arg(long, value_name = "N|DIR", conflicts_with = "map")]
    maps: Option<String>,
    /// For --env unicycle: drive on this terrain map (an 8-bit RGB PNG).
    #[arg(long, value_name = "PNG")]
    map: Option<PathBuf>,
}

/// What `collect` hands the binary. A replay of a CSV is quick and runs at once with no view, as it always
/// has (a live view would only flash); every other source is long work shown in the view the flags pick.
pub enum Collection {
    Now(Job<'static, CollectSummary>),
    Viewed(Job<'static, CollectSummary>),
}

pub fn prepare(options: CollectOptions, invocation: &Invocation) -> Result<Collection> {
    let mut env = parse_env(&options.env)?;
    if env == EnvName::Terrain {
        return terrain::prepare_maps(options, invocation).map(Collection::Viewed);
    }
    if let EnvName::Unicycle(_) = env {
        env = env.with_terrain(terrain::unicycle_terrain(
            options.map.as_deref(),
            options.maps.as_deref(),
            options.split,
        )?)?;
    } else if options.map.is_some() || options.maps.is_some() {
        refuse!(
            "--map and --maps are for --env unicycle (maps) and --env terrain (--maps N), not '{}'",
            env.canonical()
        );
    }
    if options.split.is_some() && !options.boards && options.maps.is_none() {
        refuse!("--split needs --boards (board sets) or --maps DIR (a terrain map set)");
    }
    if options.images {
        check_frames_size(&env, 0.0)?;
    }
    if env == EnvName::Ball {
        let Some(trajectories) = options.trajectories else {
            refuse!("'ball' is recorded as camera trajectories: give --trajectories N");
        };
        return ball::prepare(trajectories, options, invocation).map(Collection::Viewed);
    }
    if options.trajectories.is_some() {
        refuse!("--trajectories is for --env ball, not '{}'", env.canonical());
    }
    if let EnvName::Embodied(game, embodiment) = env {
        return embodied::prepare(game, embodiment, options, invocation);
    }
    if options.episodes.is_some() || options.board.is_some() {
        let flag = if options.episodes.is_some() { "--episodes" } else { "--board" };
        refuse!("{flag} is for board games played by a manipulator (e.g. lightsout:cursor), not '{}'", env.canonical());
    }
    if let EnvName::Board(game) = env {
        if !options.boards {
            refuse!("'{}' is a board game: collect its board sets with --boards --max-depth D", game.name());
        }
        return boards::prepare(game, options, invocation).map(Collection::Viewed);
    }
    if options.boards {
        refuse!("--boards is for board games (lightsout, tileswap), not '{}'", env.canonical());
    }
    if let Some(actions) = options.actions.clone() {
        return replay::prepare(env, &actions, options, invocation).map(Collection::Now);
    }
    random::prepare(env, options, invocation).map(Collection::Viewed)
}
