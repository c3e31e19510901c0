//! `mbrl completions`: shell completion scripts generated from the flag definitions.

use clap::{Args, CommandFactory};
use clap_complete::Shell;

/// Print a shell completion script.
#[derive(Args, Debug)]
#[command(after_help = "\
Examples:
  mbrl completions bash > ~/.local/share/bash-completion/completions/mbrl
  mbrl completions zsh > ~/.zfunc/_mbrl
  mbrl completions fish > ~/.config/fish/completions/mbrl.fish")]
pub struct CompletionsArgs {
    /// Target shell.
    #[arg(value_parser = ["bash", "zsh", "fish"])]
    shell: String,
}

pub fn run(args: CompletionsArgs) -> anyhow::Result<()> {
    let shell = match args.shell.as_str() {
        "bash" => Shell::Bash,
        "zsh" => Shell::Zsh,
        _ => Shell::Fish,
    };
    let mut command = crate::Cli::command();
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut command, "mbrl", &mut script);
    use std::io::Write;
    crate::common::write_stdout(std::io::stdout().lock().write_all(&script));
    Ok(())
}
