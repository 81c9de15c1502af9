//! factor — how far a recorded test condition (inflation pressure, speed,
//! load, inclination) really varies, measured against its own noise: the
//! rule that a dependence on a condition is only looked for (by [`super::locate`])
//! or fitted (by the `pressure` candidate) when the condition spans clearly
//! more than what its sensor noise alone would give. A pressure that drifts,
//! leaks or saw-tooths by a few kPa is a continuous factor; a regulated
//! pressure whose reading wanders by its noise is not, nor are two binned
//! "levels" of one belt speed.
//!
//! A condition that varies may still vary *with time in the run* alone (a
//! pressure that rises as the tyre warms, never let down): then a dependence
//! on it cannot be told from any other slow drift, and a verdict `none` must
//! say so ([`drift_with_time`]).
//!
//! Must never: call a condition varying when its span is within
//! [`MIN_SPAN_NOISE`] times its noise, or read a sample outside the
//! segments (or the mask) it is given.

use crate::data::{Sample, Segment};

/// Smallest span of a condition, in units of its noise ([`noise`]), that
/// counts as variation. The 2nd–98th percentile span of pure Gaussian noise
/// is ≈ 4.1 σ; 10 σ leaves a factor 2.4 above that, so noise alone (also
/// mildly autocorrelated noise, whose short-record span is smaller still)
/// never passes, while a drift of a few kPa against a ~0.1 kPa pressure
/// sensor passes with a wide margin.
pub const MIN_SPAN_NOISE: f64 = 10.0;

/// The samples of one segment (clipped to the recording).
fn of<'a>(samples: &'a [Sample], g: &Segment) -> &'a [Sample] {
    let a = g.start.min(samples.len());
    &samples[a..g.end.clamp(a, samples.len())]
}

/// Fewest finite samples of a segment that give it a noise estimate.
const MIN_SEGMENT_SAMPLES: usize = 10;

/// The noise of a recorded condition: the median over `segments` of the
/// standard deviation of `get` about a straight line in time within the
/// segment (a set point held, or a slow drift, leaves only the noise; the
/// median keeps a few segments with a step inside from inflating it).
/// NaN when no segment has `MIN_SEGMENT_SAMPLES` finite values.
pub fn noise(samples: &[Sample], segments: &[&Segment], get: fn(&Sample) -> f64) -> f64 {
    let mut sd: Vec<f64> = segments
        .iter()
        .filter_map(|g| detrended_sd(of(samples, g), get))
        .collect();
    if sd.is_empty() {
        return f64::NAN;
    }
    sd.sort_by(f64::total_cmp);
    sd[sd.len() / 2]
}

/// Means of (t, v) pairs and their centred sums of squares and products.
struct Moments {
    mt: f64,
    mv: f64,
    /// Σ(t − t̄)².
    stt: f64,
    /// Σ(t − t̄)(v − v̄).
    stv: f64,
    /// Σ(v − v̄)².
    svv: f64,
}

fn moments(pts: &[(f64, f64)]) -> Moments {
    let n = pts.len() as f64;
    let (mt, mv) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, v)| (a + t / n, b + v / n));
    let (mut stt, mut stv, mut svv) = (0.0, 0.0, 0.0);
    for (t, v) in pts {
        stv += (t - mt) * (v - mv);
        stt += (t - mt) * (t - mt);
        svv += (v - mv) * (v - mv);
    }
    Moments {
        mt,
        mv,
        stt,
        stv,
        svv,
    }
}

/// Standard deviation of `get` about its least-squares line in time (None
/// with fewer than [`MIN_SEGMENT_SAMPLES`] finite values).
fn detrended_sd(s: &[Sample], get: fn(&Sample) -> f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = s
        .iter()
        .map(|x| (x.time, get(x)))
        .filter(|(t, v)| t.is_finite() && v.is_finite())
        .collect();
    if pts.len() < MIN_SEGMENT_SAMPLES {
        return None;
    }
    let n = pts.len() as f64;
    let Moments {
        mt, mv, stt, stv, ..
    } = moments(&pts);
    let k = if stt > 0.0 { stv / stt } else { 0.0 };
    let ss: f64 = pts
        .iter()
        .map(|(t, v)| {
            let e = v - mv - k * (t - mt);
            e * e
        })
        .sum();
    Some((ss / (n - 2.0)).sqrt())
}

/// The 2nd–98th percentile span of `get` over the samples of `segments`
/// (robust against single spikes; NaN without finite values).
pub fn span(samples: &[Sample], segments: &[&Segment], get: fn(&Sample) -> f64) -> f64 {
    percentiles(samples, segments, get).map_or(f64::NAN, |(lo, hi)| hi - lo)
}

/// The 2nd and 98th percentiles of `get` over the samples of `segments`
/// (`None` without finite values).
fn percentiles(
    samples: &[Sample],
    segments: &[&Segment],
    get: fn(&Sample) -> f64,
) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = segments
        .iter()
        .flat_map(|g| of(samples, g).iter())
        .map(get)
        .filter(|x| x.is_finite())
        .collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)];
    Some((at(0.02), at(0.98)))
}

/// Whether `get` varies over `segments` by more than [`MIN_SPAN_NOISE`]
/// times its noise, judged on `x` (the values compared: samples or
/// segment means) against the samples' noise. A condition without noise
/// (a simulated set point) varies when its values differ at all.
pub fn varies_beyond_noise(x_span: f64, noise: f64) -> bool {
    let sigma = if noise.is_finite() { noise } else { 0.0 };
    x_span.is_finite() && x_span > 0.0 && x_span > MIN_SPAN_NOISE * sigma
}

/// Mean of `get` over one segment's finite samples (NaN without any).
pub fn segment_mean(samples: &[Sample], g: &Segment, get: fn(&Sample) -> f64) -> f64 {
    let (sum, n) = of(samples, g)
        .iter()
        .map(get)
        .filter(|x| x.is_finite())
        .fold((0.0, 0usize), |(a, n), x| (a + x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// Correlation of a condition's segment means with the segments' mid-times
/// at or above which the condition is taken to vary with time alone: time
/// then explains ≥ 81 % of its variance between segments, leaving under a
/// fifth to tell a dependence on the condition from a drift in time. A
/// pressure let down once in the run (dev-set r04, r09) stays well below;
/// one that only rises with the tyre's warming (r20) is near 1.
pub const TIME_CONFOUNDED_R: f64 = 0.9;

/// A condition that varies beyond its noise, and with time in the run alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeDrift {
    /// The 2nd percentile of the condition over the segments' samples
    /// (the condition's unit: Pa for pressure).
    pub from: f64,
    /// The 98th percentile, likewise.
    pub to: f64,
    /// Correlation of the segment means with the segments' mid-times.
    pub r: f64,
}

/// Share of the run's time that must be missing before
/// [`missing_time`] reports it: a few dropped rows do not hide a history.
const MISSING_SHARE: f64 = 0.05;

/// Time (s) of the run the samples do not cover, and its share of the run:
/// the steps the replay takes for gaps (longer than
/// `ReplayOptions::gap_factor`, five, median intervals; it resets the
/// transient state there), less one interval each, where time advances.
/// `None` below 5 % of the run. A state built up over the run (a tread
/// temperature) cannot be followed across such gaps.
pub fn missing_time(samples: &[Sample]) -> Option<(f64, f64)> {
    use crate::residual::{median_spacing, ReplayOptions};
    let t: Vec<f64> = samples.iter().map(|s| s.time).collect();
    let step = median_spacing(&t);
    let gap = ReplayOptions::default().gap_factor * step;
    let dt = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.is_finite() && *d > 0.0);
    let run: f64 = dt.clone().sum();
    let gaps: f64 = dt.filter(|d| *d > gap).map(|d| d - step).sum();
    (step.is_finite() && gaps >= MISSING_SHARE * run).then_some((gaps, gaps / run))
}

/// `Some` when `get` varies over `segments` beyond its noise
/// ([`varies_beyond_noise`]) and its segment means follow the segments'
/// mid-times with |correlation| ≥ [`TIME_CONFOUNDED_R`]; `None` otherwise
/// (also with fewer than three segments of finite values).
pub fn drift_with_time(
    samples: &[Sample],
    segments: &[&Segment],
    get: fn(&Sample) -> f64,
) -> Option<TimeDrift> {
    if !varies_beyond_noise(span(samples, segments, get), noise(samples, segments, get)) {
        return None;
    }
    let pts: Vec<(f64, f64)> = segments
        .iter()
        .map(|g| {
            let s = of(samples, g);
            let t = s
                .first()
                .zip(s.last())
                .map_or(f64::NAN, |(a, b)| 0.5 * (a.time + b.time));
            (t, segment_mean(samples, g, get))
        })
        .filter(|(t, v)| t.is_finite() && v.is_finite())
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let Moments { stt, stv, svv, .. } = moments(&pts);
    let r = stv / (stt * svv).sqrt();
    if !(r.abs() >= TIME_CONFOUNDED_R) {
        return None;
    }
    let (from, to) = percentiles(samples, segments, get)?;
    Some(TimeDrift { from, to, r })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::SegmentKind;

    /// Rows dropped from the middle of a run are time it does not cover;
    /// a jittering sample clock, a few dropped rows or a clock restarting
    /// for a second run are not.
    #[test]
    fn time_a_run_does_not_cover_is_found() {
        let at = |t: &[f64]| -> Vec<Sample> {
            t.iter()
                .map(|&time| Sample {
                    time,
                    ..Default::default()
                })
                .collect()
        };
        let steady: Vec<f64> = (0..10_000).map(|i| 0.01 * i as f64).collect();
        assert_eq!(missing_time(&at(&steady)), None);
        let jitter: Vec<f64> = (0..10_000)
            .map(|i| 0.01 * i as f64 + if i % 2 == 0 { 0.002 } else { 0.0 })
            .collect();
        assert_eq!(missing_time(&at(&jitter)), None);
        // 30 s of 100 taken out of the middle, and a separate 1 s.
        let cut: Vec<f64> = steady
            .iter()
            .copied()
            .filter(|t| !(40.0..70.0).contains(t) && !(80.0..81.0).contains(t))
            .collect();
        let (gap, share) = missing_time(&at(&cut)).expect("gaps");
        assert!((gap - 31.0).abs() < 0.05, "{gap}");
        assert!((share - 0.31).abs() < 0.005, "{share}");
        // 2 s of 100 are under the 5 % that hides a history.
        let few: Vec<f64> = steady
            .iter()
            .copied()
            .filter(|t| !(40.0..42.0).contains(t))
            .collect();
        assert_eq!(missing_time(&at(&few)), None);
        // Two runs one after the other, each with its clock from 0.
        let restarted: Vec<f64> = steady.iter().map(|t| t % 50.0).collect();
        assert_eq!(missing_time(&at(&restarted)), None);
    }

    fn seg(start: usize, end: usize) -> Segment {
        Segment {
            start,
            end,
            kind: SegmentKind::PureLateral,
            fz: 1000.0,
            gamma: 0.0,
            p: 2e5,
            vx: 11.0,
            alpha: f64::NAN,
        }
    }

    /// A pressure drifting 4 kPa over the recording with a ±0.1 kPa
    /// alternating "noise" varies; the same noise on a held pressure does not.
    #[test]
    fn drift_varies_noise_does_not() {
        let n = 2000;
        let mk = |drift: f64| -> Vec<Sample> {
            (0..n)
                .map(|i| Sample {
                    time: i as f64 * 0.01,
                    p: 2e5 + drift * i as f64 / n as f64 + if i % 2 == 0 { 100.0 } else { -100.0 },
                    ..Default::default()
                })
                .collect()
        };
        let segs: Vec<Segment> = (0..10).map(|k| seg(200 * k, 200 * (k + 1))).collect();
        let refs: Vec<&Segment> = segs.iter().collect();
        let get: fn(&Sample) -> f64 = |s| s.p;
        let held = mk(0.0);
        let sigma = noise(&held, &refs, get);
        // The alternating ±100 Pa has standard deviation 100 Pa.
        assert!((sigma - 100.0).abs() < 2.0, "{sigma}");
        assert!(!varies_beyond_noise(span(&held, &refs, get), sigma));
        let drifting = mk(4000.0);
        let sigma = noise(&drifting, &refs, get);
        // The line in time removes the drift: still the noise.
        assert!((sigma - 100.0).abs() < 2.0, "{sigma}");
        assert!(varies_beyond_noise(span(&drifting, &refs, get), sigma));
    }

    /// A pressure that only rises through the run varies with time alone;
    /// one let down once (a saw-tooth), or one held at its set point, not.
    #[test]
    fn a_pressure_rising_through_the_run_drifts_with_time() {
        let n = 4000;
        let mk = |p: &dyn Fn(f64) -> f64| -> Vec<Sample> {
            (0..n)
                .map(|i| Sample {
                    time: i as f64 * 0.01,
                    p: p(i as f64 / n as f64) + if i % 2 == 0 { 100.0 } else { -100.0 },
                    ..Default::default()
                })
                .collect()
        };
        let segs: Vec<Segment> = (0..20).map(|k| seg(200 * k, 200 * (k + 1))).collect();
        let refs: Vec<&Segment> = segs.iter().collect();
        let get: fn(&Sample) -> f64 = |s| s.p;
        // 243 → 249 kPa, rising as a warming tyre's does (fast, then levelling).
        let rising = mk(&|x| 243e3 + 6e3 * (1.0 - (-2.5 * x).exp()) / (1.0 - (-2.5f64).exp()));
        let d = drift_with_time(&rising, &refs, get).expect("drifts with time");
        assert!(d.r > 0.9, "{d:?}");
        assert!(
            (d.from - 243e3).abs() < 400.0 && (d.to - 249e3).abs() < 400.0,
            "{d:?}"
        );
        // Let down once, at 60 % of the run, to its start, then rising again.
        let saw = mk(&|x| 69e3 + 3.6e3 * if x < 0.6 { x / 0.6 } else { (x - 0.6) / 0.6 });
        assert!(varies_beyond_noise(
            span(&saw, &refs, get),
            noise(&saw, &refs, get)
        ));
        assert_eq!(drift_with_time(&saw, &refs, get), None);
        // Held at its set point: no drift at all.
        assert_eq!(drift_with_time(&mk(&|_| 2.6e5), &refs, get), None);
    }
}
