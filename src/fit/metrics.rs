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

use crate::data::structure::SegmentOptions;
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

/// A test condition: the set points of a segment, or the mean set points of
/// the segments that share one.
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
    /// One test condition: every set point within the tolerance the
    /// segmenter bins its levels with ([`SegmentOptions::default`]: load
    /// max(60 N, 8 %), inclination 0.6°, pressure 5 kPa). A segment's set
    /// points are the medians of its samples, so the repeats of one
    /// load-controlled set point differ by a few newtons (221.4, 221.7,
    /// 222.0 N) and must not count as three conditions. A set point missing
    /// in both (NaN) is equal.
    pub fn same(&self, o: &Condition) -> bool {
        let t = SegmentOptions::default();
        let near = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol || (a.is_nan() && b.is_nan());
        (same_load_level(self.fz, o.fz) || (self.fz.is_nan() && o.fz.is_nan()))
            && near(self.gamma, o.gamma, t.gamma_tol)
            && near(self.p, o.p, t.p_tol)
    }
    fn order(&self, o: &Condition) -> std::cmp::Ordering {
        self.fz
            .total_cmp(&o.fz)
            .then(self.gamma.total_cmp(&o.gamma))
            .then(self.p.total_cmp(&o.p))
    }
}

/// Whether two loads (N) are one load level: within the tolerance the
/// segmenter bins load set points with, max(60 N, 8 %) of the larger
/// ([`SegmentOptions::default`]; a programme's set points differ by ≥ 30 %,
/// load control holds a level within a few %). False when either is NaN.
pub fn same_load_level(a: f64, b: f64) -> bool {
    let t = SegmentOptions::default();
    (a - b).abs() <= t.fz_abs.max(t.fz_rel * a.abs().max(b.abs()))
}

/// One test condition and the segments (indices into `rec.segments`) run at it.
#[derive(Clone, Debug, PartialEq)]
pub struct ConditionGroup {
    /// The members' set points, weighted by their sample counts.
    pub condition: Condition,
    /// Indices of the member segments, in time order.
    pub segments: Vec<usize>,
}

/// The test conditions of a recording, sorted by (load level, inclination,
/// pressure). Segments join a condition by [`Condition::same`] with its
/// first member in that order (its lightest), so a slow drift cannot chain
/// distinct set points into one.
pub fn condition_groups(rec: &Recording) -> Vec<ConditionGroup> {
    let segs = &rec.segments;
    let mut order: Vec<usize> = (0..segs.len()).collect();
    order.sort_by(|&a, &b| Condition::of(&segs[a]).order(&Condition::of(&segs[b])));
    let mut groups: Vec<(Condition, Vec<usize>)> = Vec::new();
    for i in order {
        let c = Condition::of(&segs[i]);
        match groups.iter_mut().find(|g| g.0.same(&c)) {
            Some(g) => g.1.push(i),
            None => groups.push((c, vec![i])),
        }
    }
    let out: Vec<ConditionGroup> = groups
        .into_iter()
        .map(|(_, mut members)| {
            members.sort_unstable();
            let mean = |f: fn(&crate::data::Segment) -> f64| {
                let (mut s, mut w) = (0.0, 0.0);
                for &i in &members {
                    let (x, n) = (f(&segs[i]), segs[i].len().max(1) as f64);
                    if x.is_finite() {
                        s += n * x;
                        w += n;
                    }
                }
                if w > 0.0 {
                    s / w
                } else {
                    f64::NAN
                }
            };
            ConditionGroup {
                condition: Condition {
                    fz: mean(|g| g.fz),
                    gamma: mean(|g| g.gamma),
                    p: mean(|g| g.p),
                },
                segments: members,
            }
        })
        .collect();
    // Order by load level (the loads of one level differ by a few newtons
    // between inclinations), then inclination, then pressure; conditions
    // without a load last.
    let (loaded, unloaded): (Vec<_>, Vec<_>) =
        out.into_iter().partition(|g| g.condition.fz.is_finite());
    let mut ordered: Vec<ConditionGroup> =
        crate::stats::anchored_levels(loaded, |g| g.condition.fz, same_load_level)
            .into_iter()
            .flat_map(|mut level| {
                level.sort_by(|a, b| {
                    a.condition
                        .gamma
                        .total_cmp(&b.condition.gamma)
                        .then(a.condition.p.total_cmp(&b.condition.p))
                });
                level
            })
            .collect();
    ordered.extend(unloaded);
    ordered
}

/// Distinct conditions of a recording ([`condition_groups`] without the members).
pub fn conditions(rec: &Recording) -> Vec<Condition> {
    condition_groups(rec)
        .into_iter()
        .map(|g| g.condition)
        .collect()
}

/// Metrics of one channel over one set of samples.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChannelMetric {
    /// Channel name (`Fx`, `Fy`, `Mz` …).
    pub channel: String,
    /// `None` for the row over all samples.
    pub condition: Option<Condition>,
    /// Samples with a finite measured value.
    pub n: usize,
    /// Normalised residual √(Σ(sim − test)² / Σ test²) ([`sigma`]), dimensionless.
    pub sigma: f64,
    /// RMS error over the measured range, max − min ([`nrmse`]), dimensionless.
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
/// first the row over all selected samples, then one row per condition
/// ([`condition_groups`]) with a measured value in the selection.
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
    for g in condition_groups(rec) {
        let (mut s, mut t) = (Vec::new(), Vec::new());
        for seg in g.segments.iter().map(|&k| &rec.segments[k]) {
            for i in seg.start.min(n)..seg.end.min(n) {
                if selected(i) {
                    s.push(sim[i]);
                    t.push(test_of(i));
                }
            }
        }
        // A condition without a measured value of the channel in the
        // selection (e.g. Fx at a cornering-only condition) has no row.
        if t.iter().any(|y| y.is_finite()) {
            out.push(metric(channel, Some(g.condition), &s, &t));
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

    fn seg(start: usize, end: usize, fz: f64, gamma_deg: f64, p_kpa: f64) -> crate::data::Segment {
        crate::data::Segment {
            start,
            end,
            kind: crate::data::SegmentKind::PureLateral,
            fz,
            gamma: gamma_deg.to_radians(),
            p: p_kpa * 1e3,
            vx: 11.1,
            alpha: 0.0,
        }
    }

    /// The repeats of one load-controlled set point (medians 221.4 / 222.0 /
    /// 221.7 N, as an FSAE programme's 50 lb level records) are one
    /// condition; the next inclination (1°, beyond the segmenter's 0.6°),
    /// the next pressure (69 vs 83 kPa) and the next load (331 N) are not;
    /// a pressure drifting 243 → 246.5 kPa stays one.
    #[test]
    fn repeats_of_a_set_point_are_one_condition() {
        let mut rec = Recording {
            samples: vec![Sample::default(); 100],
            ..Default::default()
        };
        for (k, (fz, g, p)) in [
            (221.4, 0.0, 83.0),
            (331.0, 0.0, 83.0),
            (222.0, 0.0, 83.0),
            (222.2, 1.0, 83.0),
            (221.7, 0.0, 83.0),
            (221.9, 0.0, 69.0),
            (1550.0, 0.0, 243.0),
            (1561.0, 0.0, 246.5),
        ]
        .into_iter()
        .enumerate()
        {
            rec.segments.push(seg(10 * k, 10 * k + 10, fz, g, p));
        }
        let g = condition_groups(&rec);
        let members: Vec<&[usize]> = g.iter().map(|g| g.segments.as_slice()).collect();
        // Load level first, then inclination, then pressure.
        assert_eq!(members, [&[5][..], &[0, 2, 4], &[3], &[1], &[6, 7]]);
        let c = g[1].condition;
        assert!((c.fz - (221.4 + 222.0 + 221.7) / 3.0).abs() < 1e-9);
        assert_eq!(g[2].condition.gamma, 1f64.to_radians());
        assert!((g[4].condition.p - 244_750.0).abs() < 1e-6);
        assert_eq!(conditions(&rec).len(), 5);
        // The metrics have one row per condition with data, the repeats pooled.
        let mut fy = vec![f64::NAN; 100];
        for (i, s) in rec.samples.iter_mut().enumerate() {
            s.fy = if i < 60 {
                1.0 + (i % 3) as f64
            } else {
                f64::NAN
            };
            fy[i] = s.fy;
        }
        let m = evaluate(&rec, "Fy", &fy, None).unwrap();
        assert_eq!(m.len(), 1 + 4, "the 1550 N condition has no Fy: no row");
        assert_eq!(m[2].n, 30);
        // No chaining: 100, 106, 112 … N each within 8 % of the last are not one level.
        let mut drift = Recording {
            samples: vec![Sample::default(); 100],
            ..Default::default()
        };
        for k in 0..10 {
            let fz = 1000.0 * 1.06f64.powi(k);
            drift
                .segments
                .push(seg(10 * k as usize, 10 * k as usize + 10, fz, 0.0, 83.0));
        }
        assert!(condition_groups(&drift).len() >= 5);
        // A recording without a pressure channel (NaN set points) is one condition, not ten.
        for s in &mut drift.segments {
            s.fz = 1000.0;
            s.p = f64::NAN;
        }
        let g = condition_groups(&drift);
        assert_eq!(g.len(), 1);
        assert!(g[0].condition.p.is_nan());
    }
}
