//! `mbrl list methods`: every method of the model registry, with the data it trains on and its presets. The
//! descriptions are the `mbrl train METHOD` help's own first paragraph.

use clap::{Command, Subcommand, ValueEnum};

use super::Table;
use crate::jobs::train::{ContextPreset, DlgpdPresetChoice, MethodOptions, PetsPreset, SeadsPreset, TradynPreset};
use crate::models::registry::METHODS;

pub fn table() -> Table {
    let train = MethodOptions::augment_subcommands(Command::new("train"));
    let mut table = Table::new(&["NAME", "TRAINS ON", "PRESETS", "DESCRIPTION"]);
    for method in METHODS {
        let name = method.name();
        let about = train.find_subcommand(name).and_then(Command::get_about).map(|a| a.to_string()).unwrap_or_default();
        table.row(vec![name.into(), trains_on(name).into(), presets(name), about]);
    }
    table.note("");
    table.note("Train with `mbrl train NAME --help` for its flags; `mbrl list presets` for what each preset sets.");
    table
}

/// What `collect` must have made for the method, by checkpoint name.
pub fn trains_on(method: &str) -> &'static str {
    match method {
        "pets" => "rollouts of any stepped env (collect --rollouts)",
        "context" => "instance pairs (collect --instances)",
        "tradyn" => "unicycle rollouts on a map set (collect --env unicycle --maps DIR)",
        "dlgpd" => "pendulum rollouts, with frames for medium/paper (collect --images)",
        "seads" => "nothing: plays <game>:cursor|reacher itself",
        "ball-ekf" => "ball trajectories (collect --env ball --trajectories)",
        _ => "?",
    }
}

/// The `--preset` values `mbrl train METHOD` takes.
pub fn presets(method: &str) -> String {
    fn names<E: ValueEnum>() -> String {
        let values = E::value_variants().iter().filter_map(ValueEnum::to_possible_value);
        values.map(|v| v.get_name().to_string()).collect::<Vec<_>>().join(", ")
    }
    match method {
        "pets" => names::<PetsPreset>(),
        "context" => names::<ContextPreset>(),
        "tradyn" => names::<TradynPreset>(),
        "dlgpd" => names::<DlgpdPresetChoice>(),
        "seads" => names::<SeadsPreset>(),
        _ => "— (the thesis' settings)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registered_method_is_a_train_subcommand_with_its_data_named() {
        let train = MethodOptions::augment_subcommands(Command::new("train"));
        let table = table();
        assert_eq!(table.names().count(), METHODS.len());
        for name in table.names() {
            assert!(train.find_subcommand(name).is_some(), "`mbrl train {name}` is not a subcommand");
            assert_ne!(trains_on(name), "?", "{name}");
        }
        for row in table.rows() {
            assert!(!row[3].is_empty(), "{} has no description", row[0]);
        }
    }

    #[test]
    fn listed_presets_are_the_ones_the_method_takes() {
        let train = MethodOptions::augment_subcommands(Command::new("train"));
        for name in table().names() {
            let sub = train.find_subcommand(name).unwrap();
            let taken: Vec<String> = sub
                .get_arguments()
                .find(|a| a.get_id() == "preset")
                .map(|a| a.get_possible_values().iter().map(|v| v.get_name().to_string()).collect())
                .unwrap_or_default();
            if taken.is_empty() {
                assert!(presets(name).starts_with('—'), "{name}");
            } else {
                assert_eq!(presets(name), taken.join(", "), "{name}");
            }
        }
    }
}
