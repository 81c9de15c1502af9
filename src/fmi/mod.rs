//! fmi — the FMI 2.0 co-simulation C ABI of the `cdylib` (issue #3).
//!
//! Layout: [`types`] (the C types), [`vars`] (the variable table generated from
//! `modelDescription/modelDescription.xml` by build.rs), [`logging`] (the
//! master's logger callback), [`resources`] (`fmuResourceLocation` URIs),
//! [`instance`] (one FMU instance: state machine, parameters, the step),
//! [`snapshot`] (FMU states and their byte format), [`start`] (the
//! tyre-dependent start values: free rolling at FNOMIN) and `exports` (the 34
//! `extern "C"` functions, each a thin guarded wrapper). The packaging and the
//! small importer of `demo`/`bench` (`master.rs`) belong to the binary
//! (`src/main.rs` mounts them under its own `crate::fmi`).
//!
//! The step itself is [`crate::transient::TransientModel::step`]: this layer never
//! computes slips or forces, it only moves numbers across the boundary, checks
//! them, mirrors for the vehicle side, and enforces the FMI rules.
//!
//! Must never: let a panic unwind into the master, keep global mutable state,
//! allocate in the fmi2SetReal → fmi2DoStep → fmi2GetReal path, pass user text
//! to the logger as a format string, or trust a pointer it can check.

pub mod exports;
pub mod instance;
pub mod logging;
pub mod resources;
pub mod snapshot;
pub mod spec;
pub mod start;
pub mod types;
pub mod vars;

pub use instance::Instance;
pub use vars::{GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};
