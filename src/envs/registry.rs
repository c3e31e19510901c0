//! Turns an environment name from the command line (`family[:variant]`) into a simulator.

use super::boards::spec::GAME_HELP;
use super::boards::GameSpec;
use super::pendulum::{Pendulum, PendulumVariant};
use super::Env;
use crate::error::{Error, Result};

pub const KNOWN_ENVS: &str = "pendulum[:light|heavy|mass=<m>|inverted|quadrant], lightsout[:<n>x<n>], tileswap, ball";

#[derive(Clone, Debug, PartialEq)]
pub enum EnvName {
    Pendulum(PendulumVariant),
    /// A board game on its own: board sets and symbolic planning, no simulator to step.
    Board(GameSpec),
    /// The table-tennis ball simulator: recorded as camera trajectories, not stepped by actions.
    Ball,
}

pub fn parse_env(name: &str) -> Result<EnvName> {
    let (family, variant) = name.split_once(':').unwrap_or((name, ""));
    match family {
        "pendulum" => Ok(EnvName::Pendulum(PendulumVariant::parse(variant)?)),
        "lightsout" | "tileswap" => Ok(EnvName::Board(GameSpec::parse(name)?)),
        "ball" if variant.is_empty() => Ok(EnvName::Ball),
        _ => Err(Error::config(format!("unknown env '{name}'; supported: {KNOWN_ENVS}"))),
    }
}

impl EnvName {
    /// The simulator for this name. Board games alone have none: they are played symbolically
    /// (`solve-board`) or collected as board sets (`collect --boards`).
    pub fn build(&self) -> Result<Box<dyn Env>> {
        match self {
            EnvName::Pendulum(v) => Ok(Box::new(Pendulum::new(v.clone()))),
            EnvName::Board(g) => Err(Error::config(format!(
                "'{}' is a board game, not a simulator to roll out; use `mbrl collect --env {} --boards --max-depth D` \
                 for board sets (games: {GAME_HELP})",
                g.name(),
                g.name()
            ))),
            EnvName::Ball => Err(Error::config(
                "'ball' is recorded as camera trajectories: use `mbrl collect --env ball --trajectories N`",
            )),
        }
    }

    /// The reward in closed form, where the env has one that learned models may use instead of learning it.
    pub fn known_reward(&self) -> Option<Box<dyn super::RewardFn>> {
        match self {
            EnvName::Pendulum(v) => super::pendulum::dynamics::PendulumReward::for_params(&v.fixed_params())
                .map(|r| Box::new(r) as Box<dyn super::RewardFn>),
            EnvName::Board(_) | EnvName::Ball => None,
        }
    }

    pub fn canonical(&self) -> String {
        match self {
            EnvName::Pendulum(v) => v.env_name(),
            EnvName::Board(g) => g.name(),
            EnvName::Ball => "ball".into(),
        }
    }
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
    fn variant_round_trips_through_canonical_name() {
        for name in [
            "pendulum",
            "pendulum:light",
            "pendulum:heavy",
            "pendulum:inverted",
            "pendulum:quadrant",
            "lightsout",
            "lightsout:7x7",
            "tileswap",
        ] {
            assert_eq!(parse_env(name).unwrap().canonical(), name);
        }
    }
}
