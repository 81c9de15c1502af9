//! channels — one Magic Formula channel at a time, for the fit stages: a
//! stage fits one channel (Fx, Fy, Mx, My or Mz), and evaluating only that
//! channel (with dual lanes only for the stage's free parameters) is several
//! times cheaper than the full combined-slip solution with all five.
//!
//! The values are those of [`crate::mf::Model::solve`] (same operations in
//! the same order: `tests/fit_channels.rs` checks bit equality for `f64` and
//! the derivatives against the full solution's).
//!
//! Must never: evaluate anything differently from `Model::solve`, or be used
//! with turn slip (the fitter's use mode has none).

use super::mf_stages::Channel;
use crate::mf::{Conditions, Model, PureTerms, Real};

/// `channel` of `model` at `c`: the same value as `channel.of(&model.solve(c))`.
#[inline]
pub fn eval<T: Real>(model: &Model<T>, c: &Conditions, channel: Channel) -> T {
    match channel {
        Channel::Fx => model.fx_only(c),
        Channel::Fy => model.fy_only(c),
        Channel::Mx => model.mx_only(c),
        Channel::My => model.my_only(c),
        // Mz needs the combined Fx, Fy and the trail: the full solution,
        // without the rolling resistance moment it does not use
        // (`solve_with`: every other field the same bits as `solve`).
        Channel::Mz => model.solve_with(c, 1.0, false, None).mz,
        // Fz is the model's input, not a predicted channel (as `Channel::of`).
        Channel::Fz => T::from(f64::NAN),
    }
}

/// [`eval`] with the force the moment needs already known: `given` is
/// Fy for [`Channel::Mx`] and Fx for [`Channel::My`] (their `f64` values
/// at this sample, valid when no parameter that moves them carries a dual
/// lane); ignored for the other channels. In `f64` the same bits as
/// [`eval`]; with dual lanes the same to rounding (the dual model's own Fy
/// can differ from the `f64` one by ulps; `tests/fit_channels.rs`).
#[inline]
pub fn eval_given<T: Real>(
    model: &Model<T>,
    c: &Conditions,
    channel: Channel,
    given: Option<f64>,
) -> T {
    match (channel, given) {
        (Channel::Mx, Some(fy)) => model.mx_with_fy(c, T::c(fy)),
        (Channel::My, Some(fx)) => model.my_with_fx(c, T::c(fx)),
        _ => eval(model, c, channel),
    }
}

/// [`eval`] from the sample's pure-slip terms ([`Model::pure_terms`] of the
/// `f64` model with the same coefficients): valid when no parameter that
/// moves them carries a dual lane — the aligning-torque and combined-slip
/// coefficients of the Mz and combined stages move none. Only what follows
/// the pure-slip forces is evaluated in `T` (Gxα for Fx, Gyκ and SVyκ for
/// Fy, the aligning torque for Mz). In `f64` the same bits as [`eval`];
/// with dual lanes the same to rounding (`tests/fit_channels.rs`).
#[inline]
pub fn eval_from<T: Real>(model: &Model<T>, c: &Conditions, channel: Channel, t: &PureTerms) -> T {
    match channel {
        Channel::Fx => model.fx_from(c, t),
        Channel::Fy => model.fy_from(c, t),
        Channel::Mz => model.mz_from(c, t),
        Channel::Mx => model.mx_with_fy(c, model.fy_from(c, t)),
        Channel::My => model.my_with_fx(c, model.fx_from(c, t)),
        Channel::Fz => T::from(f64::NAN),
    }
}
