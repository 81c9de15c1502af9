//! residual — the residual stage of the data flow recordings → samples →
//! model → **residuals** → report: a recording's inputs replayed through the
//! model the FMU runs ([`replay`]), the one typed [`Channel`], the one
//! adapter from a sample to the model's inputs ([`mf_input`],
//! [`wheel_input`]) and the per-channel scores ([`channel_sse`],
//! [`channel_nrmse`] …). Used by `fit` (transient fitting), `diagnose`
//! and the `replay` command; it imports neither `fit`'s solvers nor
//! `diagnose`.
//!
//! Must never: depend on `crate::diagnose` (the stage sits below it), or
//! judge what a residual means (that is `diagnose`'s).

mod channel;
mod input;
mod replay;
mod score;

pub use channel::Channel;
pub use input::{has_core_inputs, mf_input, wheel_input};
pub use replay::{input_mode, median_spacing, replay, write_csv, Replay, ReplayOptions};
pub use score::{
    channel_nrmse, channel_sse, inverse_variances, noise_floor, nrmse_per_channel, offsets, sse,
    weighted_sse, PerChannel, FX, FY, MZ, NOISE_WINDOW,
};
