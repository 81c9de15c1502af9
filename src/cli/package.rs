//! `tyrekit package` — arguments and dispatch. (Placeholder until its issue lands.)

/// Arguments of `tyrekit package`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Run the command.
pub fn run(_args: Args) -> crate::Result<()> {
    Err(crate::Error::Other(
        "'tyrekit package' is not implemented yet".into(),
    ))
}
