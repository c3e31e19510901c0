//! Turns an environment name from the command line (`family[:variant]`) into a simulator.

use super::boards::spec::GAME_HELP;
use super::boards::{BoardGame, GameSpec, LightsOut, TileSwap};
use super::embodiments::embodied::EmbodiedBoard;
use super::embodiments::{BoardLayout, Embodiment};
use super::mountaincar::MountainCar;
use super::pendulum::{Pendulum, PendulumVariant};
use super::toy::{Squash, Toy};
use super::unicycle::{Unicycle, UnicycleTerrain};
use super::Env;
use crate::error::{Error, Result};
use crate::util::seeding::rng_for;
use crate::util::suggest::{did_you_mean, nearest};
use std::sync::Arc;

/// The pendulum family as a flag's help text names it; a macro so `concat!` can build help strings from it.
#[macro_export]
macro_rules! pendulum_envs {
    () => {
        "pendulum[:light|heavy|mass=<m>|inverted|quadrant]"
    };
}

/// Every env name `parse_env` accepts, for error messages and every subcommand's help (one list, so they
/// cannot drift apart).
#[macro_export]
macro_rules! known_envs {
    () => {
        concat!(
            $crate::pendulum_envs!(),
            ", toy:inner|outer, mountaincar, unicycle (with --map or --maps), terrain (map sets), lightsout[:<n>x<n>], tileswap, <game>:cursor|reacher|jaco (a board game \
             played by a manipulator, e.g. lightsout:cursor), ball"
        )
    };
}

pub const KNOWN_ENVS: &str = known_envs!();

/// Every env name without a number in it, as completion offers them and typos are matched against. The
/// numbered forms (`pendulum:mass=<m>`, `lightsout:<n>x<n>[:cursor|reacher|jaco]`) are typed: a list of every
/// mass cannot be written, and the 36 sizes would bury the names. A test keeps this list in step with the
/// variant lists of each family and with [`parse_env`].
pub const ENV_NAMES: [&str; 19] = [
    "pendulum",
    "pendulum:light",
    "pendulum:heavy",
    "pendulum:inverted",
    "pendulum:quadrant",
    "toy:inner",
    "toy:outer",
    "mountaincar",
    "unicycle",
    "terrain",
    "lightsout",
    "tileswap",
    "lightsout:cursor",
    "lightsout:reacher",
    "tileswap:cursor",
    "tileswap:reacher",
    "lightsout:jaco",
    "tileswap:jaco",
    "ball",
];

/// What to give when the unicycle is named without maps.
pub const UNICYCLE_NEEDS_MAPS: &str = "'unicycle' drives on terrain maps: give --map MAP.png, or --maps DIR --split \
                                       train|test with a map set from `mbrl collect --env terrain --maps 100 --out DIR`";

/// The random stream, under an instance seed, that draws an instance's hidden parameters. Fixed forever:
/// changing it would change which instance every recorded `--instance-seed` names.
pub const INSTANCE_STREAM: u64 = u64::from_be_bytes(*b"instance");

#[derive(Clone, Debug, PartialEq)]
pub enum EnvName {
    Pendulum(PendulumVariant),
    /// The linear toy system of Explore the Context (eq. 4.40) with its action squashing.
    Toy(Squash),
    /// MountainCar over random Gaussian-bump terrain (eq. 4.41).
    MountainCar,
    /// A board game on its own: board sets and symbolic planning, no simulator to step.
    Board(GameSpec),
    /// A board game played through a manipulator (`lightsout:cursor`, `tileswap:reacher`, …): stepped by
    /// the manipulator's actions, its state the manipulator's ⊕ board bits ⊕ remaining skill time.
    Embodied(GameSpec, Embodiment),
    /// The table-tennis ball simulator: recorded as camera trajectories, not stepped by actions.
    Ball,
    /// TRADYN's unicycle robot on terrain maps. The name alone carries no maps (`None`); the subcommand attaches
    /// them from `--map` / `--maps` with [`EnvName::with_terrain`].
    Unicycle(Option<Arc<UnicycleTerrain>>),
    /// Terrain map sets for the unicycle: made by `collect --env terrain --maps N`, never stepped.
    Terrain,
}

pub fn parse_env(name: &str) -> Result<EnvName> {
    if let Some(alias) = gym_alias(name) {
        return parse_env(alias?);
    }
    if let Some((game, manipulator)) = name.rsplit_once(':') {
        if let Ok(embodiment) = Embodiment::parse(manipulator) {
            return Ok(EnvName::Embodied(GameSpec::parse(game)?, embodiment));
        }
    }
    let unknown =
        || Error::config(format!("unknown env '{name}'{}; supported: {KNOWN_ENVS}", did_you_mean(name, ENV_NAMES)));
    let (family, variant) = name.split_once(':').unwrap_or((name, ""));
    match family {
        "pendulum" => Ok(EnvName::Pendulum(PendulumVariant::parse(variant)?)),
        "toy" => Ok(EnvName::Toy(Squash::parse(variant)?)),
        "mountaincar" if variant.is_empty() => Ok(EnvName::MountainCar),
        // A mistyped manipulator (`lightsout:cursr`) reads as a board size; name the env it was meant to be.
        "lightsout" | "tileswap" => {
            GameSpec::parse(name).map(EnvName::Board).map_err(|e| match nearest(name, ENV_NAMES) {
                Some(_) => unknown(),
                None => e,
            })
        }
        "ball" if variant.is_empty() => Ok(EnvName::Ball),
        "unicycle" if variant.is_empty() => Ok(EnvName::Unicycle(None)),
        "terrain" if variant.is_empty() => Ok(EnvName::Terrain),
        _ => Err(unknown()),
    }
}

/// Gym / Gymnasium ids that users bring from Python. The one whose dynamics mbrl reproduces step for step
/// names that env; the others are refused with the nearest mbrl env and how it differs.
fn gym_alias(name: &str) -> Option<Result<&'static str>> {
    let lower = name.to_ascii_lowercase();
    match lower.as_str() {
        "pendulum-v0" => Some(Ok("pendulum")),
        "pendulum-v1" => Some(Err(Error::config(format!(
            "'{name}': mbrl's pendulum is gym's Pendulum-v0 (the version of the thesis and its authors' code), which \
             clips the angular velocity after the angle update; Pendulum-v1 clips it before, so the two part above \
             8 rad/s. Use --env pendulum"
        )))),
        _ if lower.starts_with("mountaincar") && lower.contains("-v") => Some(Err(Error::config(format!(
            "'{name}': gym's MountainCar is not provided; mbrl's mountaincar is the thesis' variant (eq. 4.41) over a \
             random Gaussian-bump terrain per instance. Use --env mountaincar"
        )))),
        _ => None,
    }
}

impl EnvName {
    /// The simulator for this name. Board games alone have none: they are played symbolically
    /// (`solve-board`) or collected as board sets (`collect --boards`).
    pub fn build(&self) -> Result<Box<dyn Env>> {
        match self {
            EnvName::Pendulum(v) => Ok(Box::new(Pendulum::new(v.clone()))),
            EnvName::Toy(squash) => Ok(Box::new(Toy::new(*squash))),
            EnvName::MountainCar => Ok(Box::new(MountainCar::new())),
            EnvName::Board(g) => Err(Error::config(format!(
                "'{}' is a board game, not a simulator to roll out; use `mbrl collect --env {} --boards --max-depth D` \
                 for board sets (games: {GAME_HELP})",
                g.name(),
                g.name()
            ))),
            EnvName::Embodied(game, embodiment) => match game {
                GameSpec::LightsOut(n) => embodied(LightsOut::new(*n)?, *embodiment),
                GameSpec::TileSwap => embodied(TileSwap::new(), *embodiment),
            },
            EnvName::Ball => Err(Error::config(
                "'ball' is recorded as camera trajectories: use `mbrl collect --env ball --trajectories N`",
            )),
            EnvName::Unicycle(Some(terrain)) => Ok(Box::new(Unicycle::new(terrain.clone()))),
            EnvName::Unicycle(None) => Err(Error::config(UNICYCLE_NEEDS_MAPS)),
            EnvName::Terrain => Err(Error::config(
                "'terrain' makes map sets, it is not stepped: use `mbrl collect --env terrain --maps N --out DIR`",
            )),
        }
    }

    /// The unicycle on these maps; other envs take no maps.
    pub fn with_terrain(&self, terrain: UnicycleTerrain) -> Result<EnvName> {
        match self {
            EnvName::Unicycle(_) => Ok(EnvName::Unicycle(Some(Arc::new(terrain)))),
            other => {
                Err(Error::config(format!("--map and --maps are for --env unicycle, not '{}'", other.canonical())))
            }
        }
    }

    /// The reward in closed form, where the env has one that learned models may use instead of learning it
    /// (the pendulum family's; `control::known_reward` hands it to models as a reward seam).
    pub fn known_reward(&self) -> Option<super::pendulum::dynamics::PendulumReward> {
        match self {
            EnvName::Pendulum(v) => super::pendulum::dynamics::PendulumReward::for_params(&v.fixed_params()),
            // The toy has no task; MountainCar's reward depends on the hidden terrain.
            EnvName::Toy(_)
            | EnvName::MountainCar
            | EnvName::Board(_)
            | EnvName::Embodied(..)
            | EnvName::Ball
            | EnvName::Unicycle(_)
            | EnvName::Terrain => None,
        }
    }

    pub fn canonical(&self) -> String {
        match self {
            EnvName::Pendulum(v) => v.env_name(),
            EnvName::Toy(squash) => format!("toy:{}", squash.name()),
            EnvName::MountainCar => "mountaincar".into(),
            EnvName::Board(g) => g.name(),
            EnvName::Embodied(g, e) => format!("{}:{}", g.name(), e.name()),
            EnvName::Ball => "ball".into(),
            EnvName::Unicycle(_) => "unicycle".into(),
            EnvName::Terrain => "terrain".into(),
        }
    }
}

/// The game on its solved board, the manipulator at its default pose until reset.
fn embodied<G: BoardGame>(game: G, embodiment: Embodiment) -> Result<Box<dyn Env>> {
    let goal = game.goal();
    let manipulator = embodiment.build(&BoardLayout::of(&game))?.0;
    Ok(Box::new(EmbodiedBoard::new(game, manipulator, goal)))
}

/// The simulator for `env` with the hidden parameters that `instance_seed` names. Every subcommand that takes
/// `--instance-seed` goes through here, so one seed means one instance everywhere. Fixed environments
/// (plain pendulum and its fixed variants) ignore the seed.
pub fn instance_env(env: &EnvName, instance_seed: u64) -> Result<Box<dyn Env>> {
    let mut sim = env.build()?;
    sim.sample_instance(&mut rng_for(instance_seed, &[INSTANCE_STREAM]));
    Ok(sim)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_family_names_supported_envs() {
        let err = parse_env("cartpole").unwrap_err().to_string();
        assert!(err.contains("cartpole") && err.contains("pendulum"), "{err}");
    }

    #[test]
    fn typos_are_answered_with_the_nearest_name() {
        for (typo, meant) in [
            ("pendlum", "'pendulum'"),
            ("mountaincat", "'mountaincar'"),
            ("lightsout:cursr", "'lightsout:cursor'"),
            ("tilswap", "'tileswap'"),
            ("pendulum:haevy", "'heavy'"),
            ("toy:iner", "'inner'"),
        ] {
            let err = parse_env(typo).unwrap_err().to_string();
            assert!(err.contains(&format!("did you mean {meant}?")), "{typo}: {err}");
            assert!(err.contains("expected one of") || err.contains("supported: pendulum"), "{err}");
        }
        let err = parse_env("lightsout:8x9").unwrap_err().to_string();
        assert!(err.contains("unknown board game 'lightsout:8x9'"), "{err}");
    }

    #[test]
    fn every_listed_name_parses_to_itself_and_every_named_variant_is_listed() {
        for name in ENV_NAMES {
            assert_eq!(parse_env(name).unwrap().canonical(), name);
        }
        let families = [
            crate::envs::pendulum::variant::VARIANT_NAMES.map(|v| format!("pendulum:{v}")).to_vec(),
            crate::envs::toy::SQUASH_NAMES.map(|v| format!("toy:{v}")).to_vec(),
            crate::envs::boards::spec::GAME_NAMES.map(String::from).to_vec(),
        ];
        let embodied = crate::envs::boards::spec::GAME_NAMES
            .iter()
            .flat_map(|g| crate::envs::embodiments::EMBODIMENT_NAMES.map(|e| format!("{g}:{e}")));
        for name in families.into_iter().flatten().chain(embodied) {
            assert!(ENV_NAMES.contains(&name.as_str()), "{name} is missing from ENV_NAMES");
        }
    }

    #[test]
    fn gym_ids_name_the_same_dynamics_or_say_which_mbrl_env_is_nearest() {
        assert_eq!(parse_env("Pendulum-v0").unwrap().canonical(), "pendulum");
        for (id, suggestion) in [("Pendulum-v1", "--env pendulum"), ("MountainCarContinuous-v0", "--env mountaincar")] {
            let err = parse_env(id).unwrap_err().to_string();
            assert!(err.contains(id) && err.contains(suggestion), "{err}");
        }
    }

    #[test]
    fn variant_round_trips_through_canonical_name() {
        for name in [
            "pendulum",
            "pendulum:light",
            "pendulum:heavy",
            "pendulum:inverted",
            "pendulum:quadrant",
            "toy:inner",
            "toy:outer",
            "mountaincar",
            "lightsout",
            "lightsout:7x7",
            "tileswap",
            "lightsout:cursor",
            "lightsout:7x7:reacher",
            "tileswap:reacher",
        ] {
            assert_eq!(parse_env(name).unwrap().canonical(), name);
        }
    }

    #[test]
    fn embodied_boards_are_steppable_envs() {
        let env = parse_env("tileswap:cursor").unwrap();
        assert_eq!(env, EnvName::Embodied(GameSpec::TileSwap, Embodiment::Cursor));
        let spec = env.build().unwrap().spec();
        assert_eq!(spec.state_names[..2], ["cursor_x", "cursor_y"]);
        assert_eq!(spec.state_dim(), 2 + 81 + 1);
        let err = parse_env("lightsout:9x8:cursor").unwrap_err().to_string();
        assert!(err.contains("lightsout:9x8"), "{err}");
    }

    #[test]
    fn instance_seed_names_one_instance() {
        for name in ["toy:inner", "mountaincar", "pendulum:quadrant"] {
            let env = parse_env(name).unwrap();
            let params = |seed| instance_env(&env, seed).unwrap().params();
            assert_eq!(params(4), params(4), "{name}");
            assert_ne!(params(4), params(5), "{name}");
        }
        let plain = parse_env("pendulum").unwrap();
        assert_eq!(instance_env(&plain, 4).unwrap().params(), plain.build().unwrap().params());
    }

    #[test]
    fn bare_toy_and_mountaincar_variants_are_explained() {
        let err = parse_env("toy").unwrap_err().to_string();
        assert!(err.contains("toy:inner"), "{err}");
        let err = parse_env("mountaincar:steep").unwrap_err().to_string();
        assert!(err.contains("mountaincar:steep") && err.contains("toy:inner|outer"), "{err}");
        assert!(parse_env("toy:inner").unwrap().known_reward().is_none());
        assert!(parse_env("mountaincar").unwrap().known_reward().is_none());
    }
}
