//! diagnose — why simulation and recording differ: replay a recording's
//! measured inputs through the tyre model the FMU runs ([`replay`]), locate
//! where the residuals concentrate with a statistic and a significance for
//! each grouping ([`locate`]), fit the baseline when none is given
//! ([`baseline`]), name, model and fit the physics left out ([`candidate`]),
//! explain and score it ([`report`]) and draw it ([`plots`], [`html`]).
//!
//! Must never: judge structure without a significance (noise must not look
//! like physics), key detection to the rig simulator's exact formulas (the
//! statistics look at physical signatures: sweep direction, load, time,
//! frictional energy), or panic on a recording with missing channels.

pub mod baseline;
pub mod candidate;
pub mod html;
pub mod locate;
pub mod plots;
pub mod replay;
pub mod report;
