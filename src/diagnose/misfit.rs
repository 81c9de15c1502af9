//! misfit — the baseline against the noise floor the data show: a
//! baseline that stands well above the floor misfits by itself, and the
//! diagnosis then names no physics (issue #15, "no verdict on a bad
//! baseline").
//!
//! Must never: judge a channel the recording lacks, or use the held-out
//! half to estimate the offsets it removes.

use super::explain::sig3;
use super::quality::channel_present;
use crate::data::Recording;
use crate::mf::Forces;
use crate::residual::{channel_sse, noise_floor, offsets, Channel};
use serde::Serialize;

/// Ratio of the baseline's held-out residual RMS to the data's noise floor
/// above which the baseline itself is judged to misfit: a model within the
/// noise has a ratio near 1 (white sensor noise; filtered, coloured noise
/// reads up to about 2 with the second-difference estimate); 3 leaves that
/// margin and still flags a residual with most of its energy in structure.
pub const MISFIT_RATIO: f64 = 3.0;

/// The baseline against the noise floor the data show, per channel.
#[derive(Clone, Debug, Serialize)]
pub struct BaselineFit {
    pub channel: Channel,
    /// RMS of the baseline's held-out residual, offset removed (N, N m).
    pub rms_residual: f64,
    /// σ of the channel's high-frequency content ([`noise_floor`]).
    pub noise_floor: f64,
    /// rms_residual / noise_floor.
    pub ratio: f64,
}

/// Per present channel: the baseline's held-out residual against the noise
/// floor (offsets estimated on the fit half, as everywhere in the scoring).
pub fn baseline_fit(
    rec: &Recording,
    base: &[Forces],
    fit: &[bool],
    test: &[bool],
) -> Vec<BaselineFit> {
    let o = offsets(rec, base, fit);
    let sse = channel_sse(rec, base, test, &o);
    Channel::SCORED
        .iter()
        .enumerate()
        .filter(|(_, &ch)| channel_present(rec, ch))
        .filter_map(|(k, &ch)| {
            let (e, n) = sse[k];
            if n == 0 {
                return None;
            }
            let rms = (e / n as f64).sqrt();
            let floor = noise_floor(rec, ch, test);
            Some(BaselineFit {
                channel: ch,
                rms_residual: rms,
                noise_floor: floor,
                ratio: rms / floor,
            })
        })
        .collect()
}

/// "Baseline misfit: …" when no effect is named and a channel's baseline
/// residual stands above [`MISFIT_RATIO`] × its noise floor; None otherwise.
pub fn misfit_note(fits: &[BaselineFit]) -> Option<String> {
    let bad: Vec<String> = fits
        .iter()
        .filter(|f| f.ratio > MISFIT_RATIO)
        .map(|f| {
            format!(
                "{} residual RMS {} {u} is {:.1}× the noise floor ({} {u})",
                f.channel.name(),
                sig3(f.rms_residual, false),
                f.ratio,
                sig3(f.noise_floor, false),
                u = f.channel.unit()
            )
        })
        .collect();
    if bad.is_empty() {
        return None;
    }
    Some(format!(
        "Baseline misfit: the baseline's held-out {} — more than {MISFIT_RATIO:.0}× the sensor noise the data show, and no candidate physics removes it; the structure below is the baseline's own fit (or physics outside the candidates), so no effect is named.",
        bad.join("; ")
    ))
}
