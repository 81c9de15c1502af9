//! The `tyrekit` command line: argument parsing, the benchmarks, the FMU
//! packaging and the small FMU importer used by `demo` and `bench` live here,
//! in the binary, so the FMU's shared library (`src/lib.rs`, the cdylib) holds
//! only the model and the FMI layer.
//!
//! The library's modules are re-exported at this crate's root, so the binary's
//! modules name them as `crate::data`, `crate::fmi`, … exactly as inside the
//! library; `crate::fmi` adds the binary-only `master` and `packaging`.
//! Must never: put model or FMI logic here (it belongs in the library).

pub use tyrekit::{
    brush, data, diagnose, error, fit, mf, residual, rig, tir, transient, Error, Result,
};

/// `tyrekit::fmi` plus the binary-only FMU importer and packaging.
pub mod fmi {
    pub use tyrekit::fmi::*;
    #[path = "master.rs"]
    pub mod master;
    #[path = "../../packaging/mod.rs"]
    pub mod packaging;
}

mod bench;
mod cli;

fn main() {
    // A command line whose output is piped into `head` ends quietly when
    // the reader closes the pipe, as Unix tools do: Rust's runtime ignores
    // SIGPIPE, which turns every later `println!` into a panic.
    #[cfg(unix)]
    // SAFETY: called once, before any thread starts; restores the default
    // disposition of one signal.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(cli::main());
}
