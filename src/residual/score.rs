//! score — residuals of a simulation against a recording, per
//! [`Channel`] of [`Channel::SCORED`] (Fx, Fy, Mz; arrays are indexed in
//! that order): constant offsets (sensor zeros, a nuisance), squared
//! errors, the channels' measured variances, and the user-facing figures
//! NRMSE and σ ([`crate::fit::metrics`]).
//!
//! Must never: count a non-finite residual (a channel the recording lacks,
//! a sample the replay skipped), or mix up the channels' order.

use super::channel::Channel;
use crate::data::Recording;
use crate::fit::metrics::nrmse;
use crate::mf::Forces;

/// Per-channel values, in [`Channel::SCORED`] order.
pub type PerChannel<T> = [T; 3];

/// Index of Fx, Fy, Mz in [`Channel::SCORED`] (and in every [`PerChannel`]).
pub const FX: usize = 0;
/// See [`FX`].
pub const FY: usize = 1;
/// See [`FX`].
pub const MZ: usize = 2;

/// Per-channel weights 1/variance of the measured channel over `mask`
/// (0 for a channel the recording lacks).
pub fn inverse_variances(rec: &Recording, mask: &[bool]) -> PerChannel<f64> {
    let mut w = [0.0; 3];
    for (k, ch) in Channel::SCORED.iter().enumerate() {
        let (mut m1, mut m2, mut n) = (0.0, 0.0, 0.0);
        for (s, &b) in rec.samples.iter().zip(mask) {
            let y = ch.measured(s);
            if b && y.is_finite() {
                m1 += y;
                m2 += y * y;
                n += 1.0;
            }
        }
        let var = if n > 1.0 {
            m2 / n - (m1 / n).powi(2)
        } else {
            0.0
        };
        w[k] = if var > 0.0 { 1.0 / var } else { 0.0 };
    }
    w
}

/// Mean residual (measured − simulated) per channel over `mask`: the
/// nuisance offsets.
pub fn offsets(rec: &Recording, sim: &[Forces], mask: &[bool]) -> PerChannel<f64> {
    let mut o = [0.0; 3];
    for (k, ch) in Channel::SCORED.iter().enumerate() {
        let (mut sum, mut n) = (0.0, 0.0);
        for ((s, f), &b) in rec.samples.iter().zip(sim).zip(mask) {
            let r = ch.measured(s) - ch.of_forces(f);
            if b && r.is_finite() {
                sum += r;
                n += 1.0;
            }
        }
        o[k] = if n > 0.0 { sum / n } else { 0.0 };
    }
    o
}

/// Per channel: squared residual less offset `o[k]` over `mask`, and the
/// number of finite residuals.
pub fn channel_sse(
    rec: &Recording,
    sim: &[Forces],
    mask: &[bool],
    o: &PerChannel<f64>,
) -> PerChannel<(f64, usize)> {
    let mut out = [(0.0, 0); 3];
    for (k, ch) in Channel::SCORED.iter().enumerate() {
        for ((s, f), &b) in rec.samples.iter().zip(sim).zip(mask) {
            let r = ch.measured(s) - ch.of_forces(f) - o[k];
            if b && r.is_finite() {
                out[k].0 += r * r;
                out[k].1 += 1;
            }
        }
    }
    out
}

/// Σ_k w_k·SSE_k over `mask` of the residuals less offsets `o` (channels
/// of weight 0 skipped).
pub fn weighted_sse(
    rec: &Recording,
    sim: &[Forces],
    mask: &[bool],
    w: &PerChannel<f64>,
    o: &PerChannel<f64>,
) -> f64 {
    channel_sse(rec, sim, mask, o)
        .iter()
        .zip(w)
        .filter(|(_, w)| **w != 0.0)
        .map(|((e, _), w)| w * e)
        .sum()
}

/// Weighted SSE of Fx, Fy, Mz over masked samples (each channel normalised by
/// its measured variance over the mask, offsets not removed; channels the
/// recording lacks skipped).
pub fn sse(rec: &Recording, sim: &[Forces], mask: &[bool]) -> f64 {
    weighted_sse(rec, sim, mask, &inverse_variances(rec, mask), &[0.0; 3])
}

/// NRMSE (RMS(sim − measured) / range(measured), [`crate::fit::metrics::nrmse`])
/// of `ch` over the samples where `mask` is true (`None`: all); NaN when
/// the channel has no data there.
pub fn channel_nrmse(rec: &Recording, sim: &[Forces], ch: Channel, mask: Option<&[bool]>) -> f64 {
    let on = |i: usize| mask.is_none_or(|k| k.get(i).copied().unwrap_or(false));
    let (y, p): (Vec<f64>, Vec<f64>) = rec
        .samples
        .iter()
        .zip(sim)
        .enumerate()
        .filter(|(i, _)| on(*i))
        .map(|(_, (s, f))| (ch.measured(s), ch.of_forces(f)))
        .unzip();
    nrmse(&p, &y)
}

/// NRMSE per scored channel, as (channel, value or None) — the
/// `nrmse_*` maps of `diagnosis.json`.
pub fn nrmse_per_channel(
    rec: &Recording,
    sim: &[Forces],
    mask: Option<&[bool]>,
) -> std::collections::BTreeMap<&'static str, Option<f64>> {
    Channel::SCORED
        .iter()
        .map(|&ch| {
            let v = channel_nrmse(rec, sim, ch, mask);
            (ch.key(), v.is_finite().then_some(v))
        })
        .collect()
}
