//! `platen completions SHELL`: the shell completion script of platen's verbs and options.

use clap::CommandFactory;

use crate::Cli;

/// The arguments of `platen completions`.
#[derive(clap::Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, elvish or powershell.
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

/// Prints the completion script for SHELL.
pub fn run(args: &CompletionsArgs) -> anyhow::Result<()> {
    let mut command = Cli::command();
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, "platen", &mut script);
    out!("{}", String::from_utf8_lossy(&script));
    Ok(())
}
