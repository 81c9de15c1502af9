//! `tyrekit fit` — arguments and dispatch. (Placeholder until its issue lands.)

/// Arguments of `tyrekit fit`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Run the command.
pub fn run(_args: Args) -> crate::Result<()> {
    Err(crate::Error::Other(
        "'tyrekit fit' is not implemented yet".into(),
    ))
}
