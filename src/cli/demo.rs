//! `tyrekit demo` — arguments and dispatch. (Placeholder until its issue lands.)

/// Arguments of `tyrekit demo`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Run the command.
pub fn run(_args: Args) -> crate::Result<()> {
    Err(crate::Error::Other(
        "'tyrekit demo' is not implemented yet".into(),
    ))
}
