//! `tyrekit data …` — arguments and dispatch. (Placeholder until its issue lands.)

/// `tyrekit data` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Print the test matrix of recordings.
    Summary {
        /// Recording files.
        files: Vec<std::path::PathBuf>,
    },
}

/// Run the command.
pub fn run(_cmd: Command) -> crate::Result<()> {
    Err(crate::Error::Other(
        "'tyrekit data' is not implemented yet".into(),
    ))
}
