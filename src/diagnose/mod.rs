//! diagnose — why simulation and recording differ: with the residuals of
//! the residual stage ([`crate::residual`]: replay, channels, scores), locate
//! where the residuals concentrate with a statistic and a significance for
//! each grouping ([`locate`]), fit the baseline when none is given
//! ([`baseline`]) without the sensor zeros its residual shows
//! ([`sensor_zero`]), name, model and fit the physics left out ([`candidate`];
//! a rolling radius the forces cannot show, from the recorded slip ratio
//! against the free-rolling radius: [`slip_channel`]), fit a fitted
//! baseline again beneath the named extension for the file ([`reestimate`]),
//! explain and score it ([`report`]) and draw it ([`plots`], [`html`]).
//!
//! Must never: judge structure without a significance (noise must not look
//! like physics), key detection to the rig simulator's exact formulas (the
//! statistics look at physical signatures: sweep direction, load, time,
//! frictional energy), or panic on a recording with missing channels.

pub mod baseline;
pub mod candidate;
pub mod case;
mod explain;
pub mod factor;
pub mod html;
pub mod locate;
mod misfit;
pub mod plots;
mod quality;
pub mod reestimate;
/// The residual stage's replay, kept at its former path for callers
/// ([`crate::residual`] is its home).
pub mod replay {
    pub use crate::residual::{
        median_spacing, replay, wheel_input, write_csv, Replay, ReplayOptions,
    };
}
pub mod report;
pub mod sensor_zero;
pub mod slip_channel;
