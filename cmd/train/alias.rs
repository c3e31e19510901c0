//! `mbrl train --method X …`, the spelling of scripts and Makefiles from before the subcommands, read as
//! `mbrl train X …`.

use std::ffi::OsString;

/// The arguments with `train --method X` (or `--method=X`) moved to `train X`, where clap parses the method's
/// own flags; any other command line is returned as it is. Run configs record the process's own arguments,
/// so a run started with the old spelling records what was typed, byte for byte as before.
pub fn rewrite(mut args: Vec<OsString>, command: &clap::Command) -> Vec<OsString> {
    let Some(train) = subcommand_position(&args, command, "train") else {
        return args;
    };
    let mut i = train + 1;
    while i < args.len() {
        let Some(arg) = args[i].to_str() else {
            i += 1;
            continue;
        };
        if arg == "--" {
            break;
        }
        if arg == "--method" && i + 1 < args.len() {
            let method = args.remove(i + 1);
            args.remove(i);
            args.insert(train + 1, method);
            break;
        }
        if let Some(method) = arg.strip_prefix("--method=") {
            let method = OsString::from(method);
            args.remove(i);
            args.insert(train + 1, method);
            break;
        }
        i += 1;
    }
    args
}

/// Where `name` stands as the subcommand: the first argument that is neither a global flag nor its value.
fn subcommand_position(args: &[OsString], command: &clap::Command, name: &str) -> Option<usize> {
    let takes_value = |flag: &str| {
        command.get_arguments().any(|a| {
            let named = match flag.strip_prefix("--") {
                Some(long) => a.get_long() == Some(long),
                None => flag.len() == 2 && a.get_short().is_some_and(|s| flag.ends_with(s)),
            };
            named && a.get_action().takes_values()
        })
    };
    let mut i = 1;
    while i < args.len() {
        let arg = args[i].to_str()?;
        if arg == "--" {
            return None;
        }
        if arg.starts_with('-') {
            i += if !arg.contains('=') && takes_value(arg) { 2 } else { 1 };
            continue;
        }
        return (arg == name).then_some(i);
    }
    None
}
