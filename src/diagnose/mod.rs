//! diagnose — why simulation and recording differ: replay a recording's
//! measured inputs through the tyre model the FMU runs ([`replay`]), locate
//! where the residuals concentrate with a statistic and a significance for
//! each grouping ([`locate`]), and (in later steps) name, model and fit the
//! physics left out.
//!
//! Must never: judge structure without a significance (noise must not look
//! like physics), key detection to the rig simulator's exact formulas (the
//! statistics look at physical signatures: sweep direction, load, time,
//! frictional energy), or panic on a recording with missing channels.

pub mod candidate;
pub mod locate;
pub mod replay;
pub mod report;
