//! metrics — how well simulated channels match measured ones, overall and per
//! test condition (load, inclination, pressure).
//!
//! - normalised residual σ = √(Σ(sim − test)² / Σ test²), the measure used in
//!   the tyre-identification literature (e.g. van Oosten & Bakker's TYDEX-based
//!   identification; Besselink, Schmeitz & Pacejka, VSD 48 (2010));
//! - NRMSE = RMS(sim − test) / (max(test) − min(test)).
//!
//! Must never: silently drop a sample whose simulated value is not finite (a
//! model failure shows as NaN metrics); samples whose *measured* value is
//! missing (NaN) are skipped, as the recording contract says missing
//! channels are NaN.
// Index loops over parallel per-sample arrays read clearer than zips.
#![allow(clippy::needless_range_loop, clippy::single_range_in_vec_init)]

use crate::data::{Recording, Sample};
use std::ops::Range;

/// Normalised residual σ = √(Σ(sim − test)² / Σ test²) over pairs with a
/// finite test value. NaN when there are none or Σ test² = 0.
pub fn sigma(sim: &[f64], test: &[f64]) -> f64 {
    let (mut e, mut t) = (0.0, 0.0);
    for (&s, &y) in sim.iter().zip(test) {
        if y.is_finite() {
            e += (s - y) * (s - y);
            t += y * y;
        }
    }
    if t > 0.0 {
        (e / t).sqrt()
    } else {
        f64::NAN
    }
}

/// RMS of (sim − test) over pairs with a finite test value.
pub fn rms_error(sim: &[f64], test: &[f64]) -> f64 {
    let (mut e, mut n) = (0.0, 0usize);
    for (&s, &y) in sim.iter().zip(test) {
        if y.is_finite() {
            e += (s - y) * (s - y);
            n += 1;
        }
    }
    if n > 0 {
        (e / n as f64).sqrt()
    } else {
        f64::NAN
    }
}

/// NRMSE = RMS(sim − test) / (max test − min test). NaN for an empty or flat channel.
pub fn nrmse(sim: &[f64], test: &[f64]) -> f64 {
    let (lo, hi) = test
        .iter()
        .filter(|y| y.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &y| {
            (l.min(y), h.max(y))
        });
    let range = hi - lo;
    if range > 0.0 {
        rms_error(sim, test) / range
    } else {
        f64::NAN
    }
}

/// The measured value of a force/moment or input channel of a sample, by
/// name (case-insensitive): Fx Fy Fz Mx My Mz, alpha kappa gamma p vx.
pub fn channel_value(s: &Sample, channel: &str) -> Option<f64> {
    Some(match channel.to_ascii_lowercase().as_str() {
        "fx" => s.fx,
        "fy" => s.fy,
        "fz" => s.fz,
        "mx" => s.mx,
        "my" => s.my,
        "mz" => s.mz,
        "alpha" => s.alpha,
        "kappa" => s.kappa,
        "gamma" => s.gamma,
        "p" => s.p,
        "vx" => s.vx,
        _ => return None,
    })
}

/// A test condition: the set points of a segment.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Condition {
    /// Normal load (N).
    pub fz: f64,
    /// Inclination (rad).
    pub gamma: f64,
    /// Pressure (Pa).
    pub p: f64,
}

impl Condition {
    /// The set points of a segment.
    pub fn of(seg: &crate::data::Segment) -> Condition {
        Condition {
            fz: seg.fz,
            gamma: seg.gamma,
            p: seg.p,
        }
    }
    /// Equal set points (relative tolerance 1e-9: they are binned values).
    pub fn same(&self, o: &Condition) -> bool {
        let eq = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-9);
        eq(self.fz, o.fz) && eq(self.gamma, o.gamma) && eq(self.p, o.p)
    }
    fn key(&self) -> (f64, f64, f64) {
        (self.fz, self.gamma, self.p)
    }
}

/// Distinct conditions of a recording's segments, sorted by (load, inclination, pressure).
pub fn conditions(rec: &Recording) -> Vec<Condition> {
    let mut out: Vec<Condition> = Vec::new();
    for s in &rec.segments {
        let c = Condition::of(s);
        if !out.iter().any(|o| o.same(&c)) {
            out.push(c);
        }
    }
    out.sort_by(|a, b| {
        a.key()
            .partial_cmp(&b.key())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

/// Metrics of one channel over one set of samples.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChannelMetric {
    pub channel: String,
    /// `None` for the row over all samples.
    pub condition: Option<Condition>,
    pub n: usize,
    pub sigma: f64,
    pub nrmse: f64,
    /// RMS error in the channel's SI unit.
    pub rms: f64,
}

fn metric(channel: &str, condition: Option<Condition>, sim: &[f64], test: &[f64]) -> ChannelMetric {
    ChannelMetric {
        channel: channel.to_string(),
        condition,
        n: test.iter().filter(|y| y.is_finite()).count(),
        sigma: sigma(sim, test),
        nrmse: nrmse(sim, test),
        rms: rms_error(sim, test),
    }
}

/// Metrics of `channel` with simulated values `sim` (one per sample of `rec`):
/// first the row over all selected samples, then one row per condition.
/// `subset` restricts to these sample ranges (e.g. a hold-out split);
/// `None` = all samples.
pub fn evaluate(
    rec: &Recording,
    channel: &str,
    sim: &[f64],
    subset: Option<&[Range<usize>]>,
) -> crate::Result<Vec<ChannelMetric>> {
    let n = rec.samples.len();
    if sim.len() != n {
        return Err(crate::Error::Input(format!(
            "metrics for '{channel}' of {}: {} simulated values for {n} samples",
            rec.source,
            sim.len()
        )));
    }
    if channel_value(&Sample::default(), channel).is_none() {
        return Err(crate::Error::Input(format!(
            "metrics: unknown channel '{channel}' (expected Fx, Fy, Fz, Mx, My, Mz …)"
        )));
    }
    let full = [0..n];
    let subset = subset.unwrap_or(&full);
    let selected = |i: usize| subset.iter().any(|r| r.contains(&i));
    let test_of = |i: usize| channel_value(&rec.samples[i], channel).unwrap_or(f64::NAN);
    let (mut s_all, mut t_all) = (Vec::new(), Vec::new());
    for r in subset {
        for i in r.start.min(n)..r.end.min(n) {
            s_all.push(sim[i]);
            t_all.push(test_of(i));
        }
    }
    let mut out = vec![metric(channel, None, &s_all, &t_all)];
    for c in conditions(rec) {
        let (mut s, mut t) = (Vec::new(), Vec::new());
        for seg in &rec.segments {
            if !Condition::of(seg).same(&c) {
                continue;
            }
            for i in seg.start.min(n)..seg.end.min(n) {
                if selected(i) {
                    s.push(sim[i]);
                    t.push(test_of(i));
                }
            }
        }
        if !t.is_empty() {
            out.push(metric(channel, Some(c), &s, &t));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand-computed: sim − test = (0, 1, −1, 2), Σe² = 6; Σtest² = 1+4+9+16 = 30
    /// → σ = √(6/30) = √0.2; RMS = √(6/4); range = 4 − 1 = 3.
    #[test]
    fn sigma_and_nrmse_by_hand() {
        let test = [1.0, 2.0, 3.0, 4.0];
        let sim = [1.0, 3.0, 2.0, 6.0];
        assert!((sigma(&sim, &test) - 0.2f64.sqrt()).abs() < 1e-15);
        assert!((rms_error(&sim, &test) - 1.5f64.sqrt()).abs() < 1e-15);
        assert!((nrmse(&sim, &test) - 1.5f64.sqrt() / 3.0).abs() < 1e-15);
        // perfect match
        assert_eq!(sigma(&test, &test), 0.0);
        // missing measured values are skipped: same as the first three pairs
        let t2 = [1.0, 2.0, 3.0, f64::NAN];
        // Σe² = 2, Σt² = 14
        assert!((sigma(&sim, &t2) - (2.0f64 / 14.0).sqrt()).abs() < 1e-15);
        // flat or empty channel → NaN, not a division by zero
        assert!(nrmse(&[1.0], &[2.0]).is_nan());
        assert!(sigma(&[1.0], &[0.0]).is_nan());
    }
}
