//! cli — the `tyrekit` command line: argument parsing and dispatch only.
//! Each subcommand's arguments and work live in `cli/<command>.rs`, which calls
//! into the module named after the physics.
//! Must never: panic on bad user input (print a clear error, exit non-zero).

use clap::{Parser, Subcommand};

pub mod bench;
pub mod brush;
pub mod completions;
pub mod data;
pub mod demo;
pub mod diagnose;
pub mod eval;
pub mod fit;
pub mod manners;
pub mod package;
pub mod provenance;
pub mod replay;

/// tyrekit: a Magic Formula tyre model, its FMI 2.0 FMU, fitting and diagnosis.
#[derive(Parser, Debug)]
#[command(name = "tyrekit", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands. Names and flags are a public interface: add, never rename.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Evaluate the steady-state Magic Formula over an input CSV (MFeval's columns).
    Eval(eval::Args),
    /// Build the FMI 2.0 co-simulation FMU (.fmu).
    Package(package::Args),
    /// Build the FMU and run a short demonstration simulation of the default tyre.
    Demo(demo::Args),
    /// Print speed figures beside the named peers.
    Bench(bench::Args),
    /// Read, summarise, convert and plot tyre test recordings.
    #[command(subcommand)]
    Data(data::Command),
    /// Fit the Magic Formula to recordings and write a .tir.
    Fit(fit::Args),
    /// Replay a recording's inputs through the tyre model.
    Replay(replay::Args),
    /// Explain why simulation and recording differ.
    Diagnose(diagnose::Args),
    /// The brush model's studies (`tyrekit brush study`).
    #[command(subcommand)]
    Brush(brush::Command),
    /// Print a shell completion script (bash, zsh, fish, …) on stdout.
    Completions(completions::Args),
}

/// Load a `.tir` for a command: [`Tyre::from_file`](crate::mf::Tyre::from_file)
/// (reader and the one validation; refused files are an error) and every
/// warning of the reader and the validation on stderr.
pub(crate) fn load_tyre(path: &std::path::Path) -> crate::Result<crate::mf::Tyre> {
    let t = crate::mf::Tyre::from_file(path)?;
    show_warnings(&path.display().to_string(), t.warnings());
    Ok(t)
}

/// Print a tyre file's warnings on stderr, one a line, naming the file.
pub(crate) fn show_warnings(source: &str, warnings: &[String]) {
    for w in warnings {
        eprintln!("tyrekit: warning: {source}: {w}");
    }
}

/// Entry point used by `src/main.rs`; returns the process exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    let result = match cli.command {
        Command::Eval(a) => eval::run(a),
        Command::Package(a) => package::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Data(c) => data::run(c),
        Command::Fit(a) => fit::run(a),
        Command::Replay(a) => replay::run(a),
        Command::Brush(c) => brush::run(c),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Completions(a) => completions::run(a),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("tyrekit: error: {e}");
            1
        }
    }
}
