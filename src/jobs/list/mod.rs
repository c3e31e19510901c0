//! `mbrl list`: the names the other subcommands accept, with what each is, read from the registries those
//! subcommands parse with, so the list cannot name something the command line refuses.

mod embodiments;
mod envs;
mod methods;
mod presets;
mod table;

use clap::{Args, ValueEnum};

pub use table::Table;

use crate::Result;

/// List envs, methods, presets or embodiments with their parameters.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl list envs          # names for --env, with state and action sizes and time step
  mbrl list methods       # names for `mbrl train METHOD`, with the data each trains on
  mbrl list presets       # --preset of each method: network, steps, batch, cost
  mbrl list embodiments   # manipulators for <game>:cursor|reacher|jaco and --embodiment")]
pub struct ListOptions {
    /// What to list.
    #[arg(value_enum)]
    what: ListWhat,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum ListWhat {
    /// Simulators and data sources, as --env names them.
    Envs,
    /// Learning methods, as `mbrl train` names them.
    Methods,
    /// Each method's --preset.
    Presets,
    /// Manipulators that play the board games.
    Embodiments,
}

/// Listing is quick and reads nothing from disk: it runs at once, with no view.
pub fn run(options: ListOptions) -> Result<Table> {
    match options.what {
        ListWhat::Envs => envs::table(),
        ListWhat::Methods => Ok(methods::table()),
        ListWhat::Presets => Ok(presets::table()),
        ListWhat::Embodiments => Ok(embodiments::table()),
    }
}
