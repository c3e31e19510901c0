//! Turns an environment name from the command line (`family[:variant]`) into a simulator.

use super::pendulum::{Pendulum, PendulumVariant};
use super::Env;
use crate::error::{Error, Result};

pub const KNOWN_ENVS: &str = "pendulum[:light|heavy|mass=<m>|inverted|quadrant]";

#[derive(Clone, Debug, PartialEq)]
pub enum EnvName {
    Pendulum(PendulumVariant),
}

pub fn parse_env(name: &str) -> Result<EnvName> {
    let (family, variant) = name.split_once(':').unwrap_or((name, ""));
    match family {
        "pendulum" => Ok(EnvName::Pendulum(PendulumVariant::parse(variant)?)),
        _ => Err(Error::InvalidInput(format!("unknown env '{name}'; supported: {KNOWN_ENVS}"))),
    }
}

impl EnvName {
    pub fn build(&self) -> Box<dyn Env> {
        match self {
            EnvName::Pendulum(v) => Box::new(Pendulum::new(v.clone())),
        }
    }

    pub fn canonical(&self) -> String {
        match self {
            EnvName::Pendulum(v) => v.env_name(),
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
        for name in ["pendulum", "pendulum:light", "pendulum:heavy", "pendulum:inverted", "pendulum:quadrant"] {
            assert_eq!(parse_env(name).unwrap().canonical(), name);
        }
    }
}
