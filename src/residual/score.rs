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

/// Half-width (s) of the window the noise floor is measured against
/// ([`noise_floor`]): long against sensor noise, even low-passed (rig force
/// channels are filtered at tens of Hz: correlation times of a few 10 ms),
/// short against a test programme's sweeps (≥ 2 s), on which a centred
/// average is exact where they are linear.
pub const NOISE_WINDOW: f64 = 0.1;

/// The noise floor of a measured channel over `mask`: σ of its
/// high-frequency content, the RMS of y minus its centred moving average
/// over ±[`NOISE_WINDOW`] (2k + 1 samples, within runs of consecutive
/// masked samples), divided by √(1 − 1/(2k + 1)) — the share of a white
/// noise's variance that survives subtracting its own average. The
/// programme's slow sweeps contribute only their curvature over ±0.1 s.
/// NaN when the mask holds no full window or the spacing is unknown.
pub fn noise_floor(rec: &Recording, ch: Channel, mask: &[bool]) -> f64 {
    let s = &rec.samples;
    let n = s.len().min(mask.len());
    let t: Vec<f64> = s.iter().map(|x| x.time).collect();
    let h = super::replay::median_spacing(&t);
    if !(h.is_finite() && h > 0.0) {
        return f64::NAN;
    }
    let k = ((NOISE_WINDOW / h).round() as usize).max(1);
    let w = (2 * k + 1) as f64;
    // Prefix sums of the finite masked values and their counts.
    let mut sum = vec![0.0; n + 1];
    let mut cnt = vec![0usize; n + 1];
    for i in 0..n {
        let y = ch.measured(&s[i]);
        let ok = mask[i] && y.is_finite();
        sum[i + 1] = sum[i] + if ok { y } else { 0.0 };
        cnt[i + 1] = cnt[i] + usize::from(ok);
    }
    let (mut ss, mut m) = (0.0, 0usize);
    for (i, x) in s.iter().enumerate().take(n.saturating_sub(k)).skip(k) {
        let (lo, hi) = (i - k, i + k + 1);
        // A full window of masked finite samples only.
        if cnt[hi] - cnt[lo] != 2 * k + 1 {
            continue;
        }
        let d = ch.measured(x) - (sum[hi] - sum[lo]) / w;
        ss += d * d;
        m += 1;
    }
    if m > 0 {
        (ss / m as f64 / (1.0 - 1.0 / w)).sqrt()
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Sample;

    /// White noise of σ = 3 N on a slow sine (a sweep): the floor is σ to
    /// the sampling error of 20 000 squares (≈ 1 %; the tolerance 0.1 N
    /// is about 3 of them) plus the sine's curvature over ±0.1 s (≈
    /// 300·0.5²·0.1²/6 ≈ 0.13 N peak, < 0.01 N in quadrature), not the
    /// sweep's size.
    #[test]
    fn noise_floor_of_white_noise_on_a_sweep() {
        let mut seed = 12345u64;
        let mut gauss = || {
            // Box–Muller on a 64-bit LCG (Knuth's constants).
            let mut u = || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((seed >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
        };
        let samples: Vec<Sample> = (0..20_000)
            .map(|i| {
                let t = i as f64 * 0.01;
                Sample {
                    time: t,
                    fy: 300.0 * (0.5 * t).sin() + 3.0 * gauss(),
                    ..Default::default()
                }
            })
            .collect();
        let rec = Recording {
            samples,
            ..Default::default()
        };
        let mask = vec![true; rec.samples.len()];
        let s = noise_floor(&rec, Channel::Fy, &mask);
        assert!((s - 3.0).abs() < 0.1, "{s}");
    }
}
