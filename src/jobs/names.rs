//! Value parsers for flags that take a name from a registry (`--env`, `--game`, …): they accept the value as
//! typed, so the registry's own parser still reads the full grammar (`pendulum:mass=0.7`, `lightsout:7x7`) and
//! words its errors (with "did you mean …"), and they report the registry's names as clap's possible values,
//! which is where the generated shell completions take their candidates from.

use std::ffi::OsStr;

use clap::builder::{PossibleValue, StringValueParser, TypedValueParser};

use crate::envs::boards::spec::GAME_NAMES;
use crate::envs::ENV_NAMES;

/// Names offered for a flag: the registry list `names`, those `keep` admits.
#[derive(Clone, Copy)]
pub struct Names {
    names: &'static [&'static str],
    keep: fn(&str) -> bool,
}

impl Names {
    pub fn offered(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.names.iter().copied().filter(|n| (self.keep)(n))
    }
}

impl TypedValueParser for Names {
    type Value = String;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<String, clap::Error> {
        StringValueParser::new().parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.offered().map(PossibleValue::new)))
    }
}

/// Every env name (`collect`, and the flags that name the env a dataset or model comes from).
pub fn envs() -> Names {
    Names { names: &ENV_NAMES, keep: |_| true }
}

/// The pendulum family (`eval pendulum-swingup`).
pub fn pendulum_envs() -> Names {
    Names { names: &ENV_NAMES, keep: |n| n.starts_with("pendulum") }
}

/// What `plan` plans in: the pendulum family and the unicycle.
pub fn plan_envs() -> Names {
    Names { names: &ENV_NAMES, keep: |n| n.starts_with("pendulum") || n == "unicycle" }
}

/// Board games played by a manipulator (`train seads`).
pub fn embodied_envs() -> Names {
    Names { names: &ENV_NAMES, keep: |n| n.ends_with(":cursor") || n.ends_with(":reacher") }
}

/// Board games (`--game`).
pub fn games() -> Names {
    Names { names: &GAME_NAMES, keep: |_| true }
}

/// Launcher orientations of the ball (`collect --orientation`).
pub fn orientations() -> Names {
    const ORIENTATIONS: [&str; 6] = ["default", "unseen-1", "unseen-2", "unseen-3", "unseen-4", "unseen-5"];
    Names { names: &ORIENTATIONS, keep: |_| true }
}

/// Export formats (`export --format`).
pub fn export_formats() -> Names {
    const FORMATS: [&str; 2] = ["csv", "npz"];
    Names { names: &FORMATS, keep: |_| true }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::ball::orientation::Orientation;
    use crate::envs::boards::spec::GameSpec;
    use crate::envs::{parse_env, EnvName};

    #[test]
    fn every_offered_name_is_accepted_by_the_parser_it_names() {
        for name in envs().offered() {
            parse_env(name).unwrap();
        }
        for name in pendulum_envs().offered() {
            assert!(matches!(parse_env(name).unwrap(), EnvName::Pendulum(_)), "{name}");
        }
        for name in plan_envs().offered() {
            assert!(matches!(parse_env(name).unwrap(), EnvName::Pendulum(_) | EnvName::Unicycle(_)), "{name}");
        }
        assert_eq!(embodied_envs().offered().count(), 4);
        for name in embodied_envs().offered() {
            crate::models::seads::EmbodiedGame::parse(name).unwrap();
        }
        for name in games().offered() {
            GameSpec::parse(name).unwrap();
        }
        let all: Vec<String> = Orientation::ALL.iter().map(Orientation::name).collect();
        assert_eq!(orientations().offered().collect::<Vec<_>>(), all);
        for name in export_formats().offered() {
            assert!(crate::data::export::ExportFormat::parse(name).is_some(), "{name}");
        }
    }

    #[test]
    fn values_outside_the_list_still_reach_the_registry() {
        let cmd = clap::Command::new("t");
        let parsed = envs().parse_ref(&cmd, None, OsStr::new("pendulum:mass=0.7")).unwrap();
        assert_eq!(parsed, "pendulum:mass=0.7");
        assert_eq!(parse_env(&parsed).unwrap().canonical(), "pendulum:mass=0.7");
    }
}
