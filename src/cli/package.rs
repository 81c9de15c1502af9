//! `tyrekit package` — build the FMI 2.0 co-simulation FMU (`target/fmu/TyreKit.fmu`).
//! Arguments only; the work is `tyrekit::fmi::packaging`.
//! Must never: leave a half-written .fmu or ship a .tir the FMU cannot load.

use std::path::PathBuf;

/// Arguments of `tyrekit package`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Tyre property file to ship as resources/tyre.tir (default: the built-in tyre).
    #[arg(long, value_name = "FILE")]
    pub tir: Option<PathBuf>,
    /// Where to write the .fmu (default: target/fmu/TyreKit.fmu).
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// Shared library to ship (default: target/release/libtyrekit.so, built if missing or stale).
    #[arg(long, value_name = "SO")]
    pub library: Option<PathBuf>,
    /// Default of the FMU's `force_model` parameter: mf (Magic Formula) or brush.
    #[arg(long, value_name = "MODEL")]
    pub force_model: Option<String>,
}

/// Run the command.
pub fn run(args: Args) -> crate::Result<()> {
    let path = crate::fmi::packaging::package(&crate::fmi::packaging::Options {
        tir: args.tir,
        out: args.out,
        library: args.library,
        force_model: args.force_model,
    })?;
    println!("{}", path.display());
    Ok(())
}
