//! `tyrekit bench` — print the speed figures of every area beside its peers.

use crate::bench::{BenchContext, SECTIONS};

/// Arguments of `tyrekit bench`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Areas to run (mf, fmu, transient, brush, fit, diagnose, data); all when empty.
    pub areas: Vec<String>,
    /// Python interpreter for the peers (default: .venv/bin/python if present, else python3).
    #[arg(long)]
    pub python: Option<std::path::PathBuf>,
    /// Shorter runs, for a smoke check.
    #[arg(long)]
    pub quick: bool,
}

/// Run the command.
pub fn run(args: Args) -> crate::Result<()> {
    for a in &args.areas {
        if !SECTIONS.iter().any(|(n, _)| n == a) {
            return Err(crate::Error::Other(format!(
                "unknown benchmark area '{a}' (known: {})",
                SECTIONS
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
    }
    let python = args.python.or_else(|| {
        let venv = std::path::PathBuf::from(".venv/bin/python");
        Some(if venv.exists() {
            venv
        } else {
            "python3".into()
        })
    });
    let ctx = BenchContext {
        python,
        quick: args.quick,
    };
    for (name, f) in SECTIONS {
        if args.areas.is_empty() || args.areas.iter().any(|a| a == name) {
            f(&ctx)?;
        }
    }
    Ok(())
}
