//! `mbrl list embodiments`: the manipulators of the embodiment registry, with their sizes and the
//! `--embodiment` help's own description.

use clap::ValueEnum;

use super::Table;
use crate::envs::boards::LightsOut;
use crate::envs::embodiments::{BoardLayout, Embodiment, EMBODIMENT_NAMES};
use crate::jobs::choices::EmbodimentChoice;

pub fn table() -> Table {
    let mut table = Table::new(&["NAME", "STATE", "ACTION", "DT (s)", "STEPS PER MOVE", "DESCRIPTION"]);
    for name in EMBODIMENT_NAMES {
        let Ok(embodiment) = Embodiment::parse(name) else { continue };
        let help = EmbodimentChoice::from_str(name, false)
            .ok()
            .and_then(|c| c.to_possible_value())
            .and_then(|v| v.get_help().map(ToString::to_string))
            .unwrap_or_default();
        // Sizes do not depend on the board; the Jaco is listed without them where this build cannot run it.
        let sizes = match embodiment.build(&BoardLayout::of(&LightsOut::new(5).expect("5x5 is a LightsOut size"))) {
            Ok((m, _)) => [m.state_names().len(), m.action_low().len()]
                .map(|n| n.to_string())
                .to_vec()
                .into_iter()
                .chain([m.dt().to_string(), m.skill_step_limit().to_string()])
                .collect(),
            Err(_) => vec!["-".to_string(); 4],
        };
        let mut row = vec![name.to_string()];
        row.extend(sizes);
        row.push(help);
        table.row(row);
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
