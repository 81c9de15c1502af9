//! manners — the flags every long-running command shares (`fit`, `diagnose`):
//! `--json` (the machine-readable result on stdout, everything else on
//! stderr), `--quiet` (no progress, no human-readable text; errors still go to
//! stderr) and `--threads N` (worker threads of the fitter and the diagnosis,
//! default all cores). Flattened into each command's arguments.
//! Must never: print the JSON anywhere but stdout, or mix human text into it.

use std::io::IsTerminal;
use std::num::NonZeroUsize;

/// Output and parallelism flags (`#[command(flatten)]`).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct Manners {
    /// Print the result as JSON on stdout; tables and logs go to stderr.
    #[arg(long)]
    pub json: bool,
    /// No progress bars and no human-readable output (errors are still printed).
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Worker threads for the fitter and the diagnosis (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<NonZeroUsize>,
}

impl Manners {
    /// Threads to use: `--threads`, else every core the process may use.
    pub fn threads(&self) -> usize {
        self.threads
            .or_else(|| std::thread::available_parallelism().ok())
            .map_or(1, NonZeroUsize::get)
    }

    /// Draw progress bars (not with --quiet, and only on a terminal).
    pub fn progress(&self) -> bool {
        !self.quiet && std::io::stderr().is_terminal()
    }

    /// Human-readable text: stdout, stderr under --json, nothing under --quiet.
    pub fn say(&self, text: impl std::fmt::Display) {
        if self.quiet {
        } else if self.json {
            eprintln!("{text}");
        } else {
            println!("{text}");
        }
    }

    /// The machine-readable result, on stdout, only under --json.
    pub fn result(&self, value: &serde_json::Value) -> crate::Result<()> {
        if self.json {
            let text = serde_json::to_string_pretty(value)
                .map_err(|e| crate::Error::Other(format!("cannot serialise the result: {e}")))?;
            println!("{text}");
        }
        Ok(())
    }
}
