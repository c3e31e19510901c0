//! The numeric flags of a target's command, read from the library's own clap definitions of the subcommands
//! (the binary's top-level parser lives in `cmd/`, out of reach; its subcommands are the library's option
//! structs).

use clap::builder::ValueParser;
use clap::{value_parser, Args, Command};

/// The subcommands as `cmd/main.rs` declares them (`watch`, `list` and `completions` read no numbers that
/// reach a reader).
fn mbrl() -> Command {
    use mbrl::jobs::*;
    let sub = |name: &'static str, augment: fn(Command) -> Command| augment(Command::new(name));
    Command::new("mbrl")
        .subcommand(sub("collect", collect::CollectOptions::augment_args))
        .subcommand(sub("plan", plan::PlanOptions::augment_args))
        .subcommand(sub("train", train::TrainOptions::augment_args))
        .subcommand(sub("calibrate", calibrate::CalibrateOptions::augment_args))
        .subcommand(sub("filter", filter::FilterOptions::augment_args))
        .subcommand(sub("predict", predict::PredictOptions::augment_args))
        .subcommand(sub("solve-board", solve_board::SolveBoardOptions::augment_args))
        .subcommand(sub("eval", eval::EvalOptions::augment_args))
        .subcommand(sub("export", export::ExportOptions::augment_args))
        .subcommand(sub("sweep", sweep::SweepOptions::augment_args))
}

/// Whether the flag's value is parsed as a plain number.
fn numeric(arg: &clap::Arg) -> bool {
    let parsers: [ValueParser; 10] = [
        value_parser!(f64).into(),
        value_parser!(f32).into(),
        value_parser!(u64).into(),
        value_parser!(u32).into(),
        value_parser!(u16).into(),
        value_parser!(u8).into(),
        value_parser!(usize).into(),
        value_parser!(i64).into(),
        value_parser!(i32).into(),
        value_parser!(isize).into(),
    ];
    let id = arg.get_value_parser().type_id();
    arg.get_long().is_some() && arg.get_action().takes_values() && parsers.iter().any(|p| p.type_id() == id)
}

/// The long names (`--steps`) of every numeric flag of the subcommand `args` runs (`train --method pets …` is
/// `train pets`), in declaration order, those of the enclosing commands first.
pub(crate) fn numeric_flags(args: &str) -> Vec<String> {
    let root = mbrl();
    let mut command = &root;
    let mut flags = Vec::new();
    let mut tokens = args.split_whitespace().peekable();
    let collect = |command: &Command, flags: &mut Vec<String>| {
        for arg in command.get_arguments().filter(|a| numeric(a)) {
            flags.push(format!("--{}", arg.get_long().unwrap()));
        }
    };
    while let Some(token) = tokens.next() {
        let name = if token == "--method" { tokens.next() } else { Some(token) };
        let Some(name) = name.filter(|n| !n.starts_with('-')) else { continue };
        if let Some(sub) = command.find_subcommand(name) {
            command = sub;
            collect(command, &mut flags);
        }
    }
    flags.dedup();
    flags
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Flags of the subcommand and of its method or protocol are found; paths and names are not numbers.
    #[test]
    fn numeric_flags_of_commands() {
        let pets = numeric_flags("train --method pets --data {in} --steps 1 --out {out}");
        assert!(pets.iter().any(|f| f == "--steps"), "{pets:?}");
        assert!(!pets.iter().any(|f| f == "--data" || f == "--out"), "{pets:?}");
        let collect = numeric_flags("collect --env pendulum --actions {in} --out {out}");
        assert!(collect.iter().any(|f| f == "--rollouts"), "{collect:?}");
        assert!(numeric_flags("watch {in}").is_empty());
    }

    /// Every numeric flag of every subcommand (a method's or eval protocol's own, or one it inherits from its
    /// command) is a site of some target, so each gets the extremes.
    #[test]
    fn every_numeric_flag_of_every_subcommand_is_fuzzed() {
        fn declared(command: &Command, path: String, found: &mut Vec<(String, String)>) {
            for arg in command.get_arguments().filter(|a| numeric(a)) {
                found.push((path.clone(), format!("--{}", arg.get_long().unwrap())));
            }
            for sub in command.get_subcommands() {
                declared(sub, format!("{path} {}", sub.get_name()), found);
            }
        }
        let root = mbrl();
        let mut all = Vec::new();
        declared(&root, String::new(), &mut all);
        // Each target's command path (` eval tradyn`) with the flags it reaches there, its ancestors' included.
        let mut reached = Vec::new();
        for target in crate::targets::targets() {
            let (mut command, mut path) = (&root, String::new());
            let mut tokens = target.args.split_whitespace();
            while let Some(token) = tokens.next() {
                let name = if token == "--method" { tokens.next() } else { Some(token) };
                if let Some(sub) = name.filter(|n| !n.starts_with('-')).and_then(|n| command.find_subcommand(n)) {
                    command = sub;
                    path = format!("{path} {}", sub.get_name());
                }
            }
            reached.push((path, numeric_flags(target.args)));
        }
        let missed: Vec<String> = all
            .iter()
            .filter(|(path, flag)| {
                !reached.iter().any(|(p, flags)| p.starts_with(path.as_str()) && flags.contains(flag))
            })
            .map(|(path, flag)| format!("{path} {flag}"))
            .collect();
        assert!(missed.is_empty(), "numeric flags no target reaches: {missed:?}");
    }
}
