//! tyrekit — a Magic Formula tyre model with transient dynamics, shipped as an
//! FMI 2.0 co-simulation FMU, plus tools that read tyre test recordings, fit the
//! model to them and diagnose why simulation and measurement differ.
//!
//! Data flows one way:
//! recordings ([`data`]) → ISO-W SI samples → model ([`tir`], [`mf`], [`transient`])
//! → residuals ([`fit`]) → report ([`diagnose`]).
//!
//! The command line, the benchmarks, the FMU packaging and the small FMU
//! importer of `demo`/`bench` are the binary's (`src/main.rs`): this library is
//! what the FMU's shared library (cdylib) is built from.
//!
//! Conventions: ISO-W (TYDEX W) axes and SI units everywhere inside the crate.
//! Conversions happen only at the edges (`.tir` `[UNITS]`, SAE/TTC recordings).

// Every public item says what it is (CI's clippy runs with -D warnings).
#![warn(missing_docs)]

pub mod brush;
pub mod data;
pub mod diagnose;
pub mod error;
pub mod fit;
pub mod fmi;
pub mod mf;
pub mod residual;
pub mod rig;
pub(crate) mod stats;
pub mod tir;
pub mod transient;

pub use error::{Error, Result};
