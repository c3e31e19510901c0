//! `mbrl list embodiments`: the manipulators of the embodiment registry, with their sizes and the
//! `--embodiment` help's own description.

use clap::ValueEnum;

use super::Table;
use crate::envs::embodiments::{Embodiment, EMBODIMENT_NAMES};
use crate::jobs::choices::EmbodimentChoice;

pub fn table() -> Table {
    let mut table = Table::new(&["NAME", "STATE", "ACTION", "DT (s)", "STEPS PER MOVE", "DESCRIPTION"]);
    for name in EMBODIMENT_NAMES {
        let Ok(embodiment) = Embodiment::parse(name) else { continue };
        let (manipulator, _) = embodiment.build();
        let help = EmbodimentChoice::from_str(name, false)
            .ok()
            .and_then(|c| c.to_possible_value())
            .and_then(|v| v.get_help().map(ToString::to_string))
            .unwrap_or_default();
        table.row(vec![
            name.to_string(),
            manipulator.state_names().len().to_string(),
            manipulator.action_low().len().to_string(),
            manipulator.dt().to_string(),
            manipulator.skill_step_limit().to_string(),
            help,
        ]);
    }
    table.note("");
    table.note(
        "Play a board game with one: --env lightsout:cursor (collect, train seads) or --embodiment (solve-board).",
    );
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embodiment_is_listed_and_parses_both_ways() {
        let table = table();
        assert_eq!(table.names().collect::<Vec<_>>(), EMBODIMENT_NAMES);
        for name in table.names() {
            Embodiment::parse(name).unwrap();
            EmbodimentChoice::from_str(name, false).unwrap();
        }
        assert!(table.rows().iter().all(|r| !r[5].is_empty()));
    }
}
