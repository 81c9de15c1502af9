//! structure — the test programme inside a recording: set-point segments,
//! their kind, the warm-up before the programme, and per-sample sweep
//! direction and time since the segment began.
//!
//! Method:
//! 1. Set-point channels (Fz, γ, P, Vx) are smoothed with a running median
//!    and binned: levels are the dense clusters of the smoothed values
//!    (histogram peaks merged within a tolerance), each sample gets the
//!    nearest level within tolerance or none (transition).
//! 2. A segment is a maximal run of one level combination, without time gaps;
//!    short runs are transitions. Within drive/brake runs the slip-angle set
//!    point is binned the same way.
//! 3. Kind from the swept ranges: α swept and κ ≈ const → pure lateral;
//!    κ swept at α ≈ 0 → pure longitudinal; κ swept at α ≠ 0 or both
//!    swept → combined.
//! 4. Warm-up: leading segments whose sweep signature (slip range within
//!    15 %, duration at least half) does not match the programme's typical
//!    segment of the same kind, or whose load no other segment uses, are cut;
//!    if the first programme segment is longer than the typical one by more
//!    than half, its surplus beginning (extra sweeps at the same set point) is
//!    cut too. What was cut is reported.
//!
//! Must never: drop samples other than the reported warm-up, or panic on
//! recordings without the set-point channels (they become one segment).

use super::{LoadReport, Recording, Sample, Segment, SegmentKind};
use crate::stats::median_in_place;

/// Tolerances used for binning set points.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SegmentOptions {
    /// Absolute part of the load tolerance max(`fz_abs`, `fz_rel`·Fz) (N).
    pub fz_abs: f64,
    /// Relative part of the load tolerance (–, fraction of Fz).
    pub fz_rel: f64,
    /// Inclination tolerance (rad).
    pub gamma_tol: f64,
    /// Pressure tolerance (Pa).
    pub p_tol: f64,
    /// Absolute part of the speed tolerance max(`v_abs`, `v_rel`·V) (m/s).
    pub v_abs: f64,
    /// Relative part of the speed tolerance (–, fraction of V).
    pub v_rel: f64,
    /// Slip-angle set-point tolerance for drive/brake runs (rad).
    pub alpha_tol: f64,
    /// Minimum segment duration (s).
    pub min_duration: f64,
    /// A time step larger than this many median steps (and > 1 s) splits segments.
    pub gap_factor: f64,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        SegmentOptions {
            fz_abs: 60.0,
            fz_rel: 0.08,
            gamma_tol: 0.6f64.to_radians(),
            p_tol: 5_000.0,
            v_abs: 0.8,
            v_rel: 0.05,
            alpha_tol: 0.75f64.to_radians(),
            min_duration: 2.0,
            gap_factor: 5.0,
        }
    }
}

/// What the warm-up cut removed.
#[derive(Clone, Debug, serde::Serialize, PartialEq)]
pub struct WarmupCut {
    /// Samples removed from the beginning.
    pub samples: usize,
    /// Time of the first sample removed (s).
    pub t_start: f64,
    /// Time of the first sample kept (s); the cut is `t_start` ≤ t < `t_end`.
    pub t_end: f64,
    /// Why, in words.
    pub reason: String,
}

/// Piecewise-constant smoothing in O(n): every sample gets the median of its
/// block of `b` samples (NaN-aware). Used for set-point channels, whose
/// levels only need to be found, not tracked sample by sample.
fn block_median(x: &[f64], b: usize) -> Vec<f64> {
    let b = b.max(1);
    let mut out = Vec::with_capacity(x.len());
    let mut buf = Vec::with_capacity(b);
    for chunk in x.chunks(b) {
        buf.clear();
        buf.extend(chunk.iter().copied().filter(|v| v.is_finite()));
        let m = median_in_place(&mut buf);
        out.extend(std::iter::repeat_n(m, chunk.len()));
    }
    out
}

/// Centred running mean over `w` samples in O(n) (prefix sums; NaN → skipped).
fn running_mean(x: &[f64], w: usize) -> Vec<f64> {
    let h = w / 2;
    let mut ps = Vec::with_capacity(x.len() + 1);
    let mut pc = Vec::with_capacity(x.len() + 1);
    let (mut s, mut c) = (0.0, 0usize);
    ps.push(0.0);
    pc.push(0);
    for v in x {
        if v.is_finite() {
            s += v;
            c += 1;
        }
        ps.push(s);
        pc.push(c);
    }
    (0..x.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(h), (i + h + 1).min(x.len()));
            let n = pc[b] - pc[a];
            if n == 0 {
                f64::NAN
            } else {
                (ps[b] - ps[a]) / n as f64
            }
        })
        .collect()
}

/// Levels of a set-point channel: the dense clusters of its values.
/// Sorted values are put into bins of width tol/2; bins holding at least
/// `min_count` samples are dense (a ramp between set points spreads thinly
/// over many bins and is not); adjacent dense bins form one level, whose
/// centre is the median of its samples. `tol(x)` is the tolerance at x.
fn levels(x: &[f64], tol: &dyn Fn(f64) -> f64, min_count: usize) -> Vec<f64> {
    let mut v: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return vec![];
    }
    v.sort_by(|a, b| a.total_cmp(b));
    // Bins: [start index, end index) into v.
    let mut bins: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < v.len() {
        let hi = v[i] + 0.5 * tol(v[i]).max(1e-12);
        let j = i + v[i..].partition_point(|y| *y < hi);
        bins.push((i, j.max(i + 1)));
        i = j.max(i + 1);
    }
    let mut out: Vec<f64> = Vec::new();
    let mut k = 0;
    while k < bins.len() {
        if bins[k].1 - bins[k].0 < min_count {
            k += 1;
            continue;
        }
        let first = k;
        k += 1;
        // Adjacent in value (not just in sorted order): the next bin begins
        // within half a tolerance of this one's last value.
        while k < bins.len()
            && bins[k].1 - bins[k].0 >= min_count
            && v[bins[k].0] - v[bins[k - 1].1 - 1] <= 0.5 * tol(v[bins[k - 1].1 - 1])
        {
            k += 1;
        }
        // A chain may hold two levels whose noise overlaps: split it at
        // valleys deeper than a third of the lower neighbouring peak.
        let mut parts = vec![(first, k)];
        let mut done = Vec::new();
        while let Some((a, b)) = parts.pop() {
            let cnt = |i: usize| bins[i].1 - bins[i].0;
            let split = (a + 1..b.saturating_sub(1))
                .min_by_key(|&i| cnt(i))
                .filter(|&m| {
                    let left = (a..m).map(cnt).max().unwrap_or(0);
                    let right = (m + 1..b).map(cnt).max().unwrap_or(0);
                    3 * cnt(m) < left.min(right)
                });
            match split {
                Some(m) => {
                    parts.push((a, m));
                    parts.push((m + 1, b));
                }
                None => done.push((a, b)),
            }
        }
        done.sort();
        for (a, b) in done {
            out.push(v[(bins[a].0 + bins[b - 1].1) / 2]);
        }
    }
    // Merge levels closer than their tolerance.
    let mut merged: Vec<f64> = Vec::new();
    for l in out {
        match merged.last_mut() {
            Some(m) if (l - *m).abs() <= tol(*m) => *m = 0.5 * (*m + l),
            _ => merged.push(l),
        }
    }
    merged
}

fn assign(x: f64, lv: &[f64], tol: &dyn Fn(f64) -> f64) -> Option<u16> {
    if !x.is_finite() {
        return if lv.is_empty() { Some(u16::MAX) } else { None };
    }
    // Nearest level, if within its tolerance — widened up to 3× where the
    // neighbouring levels leave room (half the gap), so that slow set-point
    // wander does not break a segment.
    let k = (0..lv.len()).min_by(|&a, &b| (x - lv[a]).abs().total_cmp(&(x - lv[b]).abs()))?;
    let l = lv[k];
    let gap = |j: Option<usize>| {
        j.and_then(|j| lv.get(j))
            .map_or(f64::INFINITY, |n| (n - l).abs())
    };
    let room = 0.5 * gap(k.checked_sub(1)).min(gap(Some(k + 1)));
    let lim = tol(l).max(room.min(3.0 * tol(l)));
    ((x - l).abs() <= lim).then_some(k as u16)
}

/// Slip-angle spread (rad, 2–98 %) beyond which α counts as swept: 2°, a
/// small fraction of any cornering sweep, well above a held set point's
/// sensor noise and steering play.
const ALPHA_SWEPT: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Slip-ratio spread (2–98 %) beyond which κ counts as swept: 0.03, several
/// times the scatter of a freely rolling wheel's κ and a fraction of any
/// slip-ratio sweep (to ±0.1 … ±0.2).
const KAPPA_SWEPT: f64 = 0.03;

/// Spread of Fx/Fz (2–98 %) beyond which Fx counts as swept where κ is
/// unknown: 0.3, the Fx/Fz a κ spread of [`KAPPA_SWEPT`] gives at a slip
/// stiffness of 10 Fz per unit κ; at the 20–30 Fz of car and FSAE tyres a κ
/// spread of 0.010–0.015 already reaches it, so no sweep is missed for want
/// of κ.
/// Free rolling is judged against half of it
/// ([`super::sanity::FREE_ROLLING_FX`]).
pub(crate) const FX_SWEPT: f64 = 0.3;

/// Robust spread: 98th − 2nd percentile.
fn spread(x: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = x.filter(|v| v.is_finite()).collect();
    if v.len() < 2 {
        return 0.0;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    q(0.98) - q(0.02)
}

fn pct(x: impl Iterator<Item = f64>, p: f64) -> f64 {
    let mut v: Vec<f64> = x.filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn med_of(s: &[Sample], f: impl Fn(&Sample) -> f64) -> f64 {
    let mut v: Vec<f64> = s.iter().map(f).filter(|v| v.is_finite()).collect();
    median_in_place(&mut v)
}

/// Segment the samples (no warm-up logic): the segments, in order.
pub fn segment(samples: &[Sample], o: &SegmentOptions) -> Vec<Segment> {
    let n = samples.len();
    if n == 0 {
        return vec![];
    }
    let mut dts: Vec<f64> = samples
        .windows(2)
        .map(|w| w[1].time - w[0].time)
        .filter(|d| *d > 0.0)
        .collect();
    let dt = median_in_place(&mut dts).max(1e-6);
    let dt = if dt.is_finite() { dt } else { 0.01 };
    let w = ((0.5 / dt).round() as usize).clamp(1, 201) | 1;
    let min_len = ((o.min_duration / dt).round() as usize).max(3);
    let gap = (o.gap_factor * dt).max(1.0);

    let ch = |f: &dyn Fn(&Sample) -> f64| -> Vec<f64> {
        block_median(&samples.iter().map(f).collect::<Vec<_>>(), w)
    };
    let fz = ch(&|s| s.fz);
    let ga = ch(&|s| s.gamma);
    let pp = ch(&|s| s.p);
    let vv = ch(&|s| s.vx / s.alpha.cos().max(0.5));
    let tfz = |x: f64| o.fz_abs.max(o.fz_rel * x.abs());
    let tga = |_: f64| o.gamma_tol;
    let tp = |_: f64| o.p_tol;
    let tv = |x: f64| o.v_abs.max(o.v_rel * x.abs());
    let mc = min_len;
    // Levels come from locally steady samples only, so that the ramps
    // between set points (which pass through every value) never form one.
    // Long recordings are thinned (every `stride`-th sample, min count scaled
    // alike) so that finding levels costs a sort of at most ~10^5 values.
    let stride = (n / 100_000).max(1);
    let mcs = (mc / stride).max(2);
    let steady = |x: &[f64], tol: &dyn Fn(f64) -> f64| -> Vec<f64> {
        let h = w.max(3);
        (0..x.len())
            .step_by(stride)
            .filter(|&i| {
                let (a, b) = (i.saturating_sub(h), (i + h).min(x.len() - 1));
                (x[b] - x[a]).abs() <= 0.25 * tol(x[i])
            })
            .map(|i| x[i])
            .collect()
    };
    let (lfz, lga, lp, lv) = (
        levels(&steady(&fz, &tfz), &tfz, mcs),
        levels(&steady(&ga, &tga), &tga, mcs),
        levels(&steady(&pp, &tp), &tp, mcs),
        levels(&steady(&vv, &tv), &tv, mcs),
    );
    // Per-sample key (None = transition).
    let keys: Vec<Option<[u16; 4]>> = (0..n)
        .map(|i| {
            Some([
                assign(fz[i], &lfz, &tfz)?,
                assign(ga[i], &lga, &tga)?,
                assign(pp[i], &lp, &tp)?,
                assign(vv[i], &lv, &tv)?,
            ])
        })
        .collect();
    // Unloaded samples are never part of a segment.
    let loaded = |i: usize| samples[i].fz > 50.0;
    // Runs of equal keys, split at time gaps.
    let mut runs: Vec<(usize, usize, [u16; 4])> = Vec::new();
    let mut i = 0;
    while i < n {
        let Some(k) = keys[i].filter(|_| loaded(i)) else {
            i += 1;
            continue;
        };
        let mut j = i + 1;
        let mut last_good = i;
        while j < n {
            let dtj = samples[j].time - samples[j - 1].time;
            if !(0.0..=gap).contains(&dtj) {
                break;
            }
            match keys[j] {
                Some(kj) if kj == k && loaded(j) => {
                    last_good = j;
                    j += 1;
                }
                // Short excursions (noise outliers) are bridged.
                _ if j - last_good < min_len / 4 + 1 => j += 1,
                _ => break,
            }
        }
        let end = last_good + 1;
        if end - i >= min_len {
            runs.push((i, end, k));
        }
        i = end.max(i + 1);
    }
    let mut segs = Vec::new();
    for (a, b, _) in runs {
        split_by_alpha_setpoint(samples, a, b, o, min_len, &mut segs);
    }
    segs
}

/// Within a run of fixed load/γ/P/V: if α holds set points (drive/brake
/// runs), split where the set point changes; then classify.
fn split_by_alpha_setpoint(
    s: &[Sample],
    a: usize,
    b: usize,
    o: &SegmentOptions,
    min_len: usize,
    out: &mut Vec<Segment>,
) {
    let al: Vec<f64> = s[a..b].iter().map(|x| x.alpha).collect();
    let w = (min_len / 4).max(1) | 1;
    let am = block_median(&al, w);
    let ta = |_: f64| o.alpha_tol;
    let lv = levels(&am, &ta, min_len);
    // α is a set point only if nearly all samples sit on levels.
    let on = am
        .iter()
        .filter(|x| strict_assign(**x, &lv, o.alpha_tol).is_some())
        .count();
    let kappa_swept = spread(s[a..b].iter().map(|x| x.kappa)) > KAPPA_SWEPT
        || spread(s[a..b].iter().map(|x| x.fx / x.fz.max(1.0))) > FX_SWEPT
            && spread(al.iter().copied()) < ALPHA_SWEPT;
    if !lv.is_empty() && kappa_swept && on as f64 > 0.8 * (b - a) as f64 {
        // Runs of one α set point (strict tolerance); samples off every set
        // point (α ramping between them) belong to no segment.
        let key = |i: usize| strict_assign(am[i - a], &lv, o.alpha_tol);
        let mut i = a;
        while i < b {
            let Some(k) = key(i) else {
                i += 1;
                continue;
            };
            let mut j = i + 1;
            while j < b && key(j) == Some(k) {
                j += 1;
            }
            if j - i >= min_len {
                out.push(make_segment(s, i, j, o));
            }
            i = j;
        }
    } else {
        out.push(make_segment(s, a, b, o));
    }
}

/// Nearest level within exactly `tol`.
fn strict_assign(x: f64, lv: &[f64], tol: f64) -> Option<u16> {
    let k = (0..lv.len()).min_by(|&a, &b| (x - lv[a]).abs().total_cmp(&(x - lv[b]).abs()))?;
    ((x - lv[k]).abs() <= tol).then_some(k as u16)
}

fn make_segment(s: &[Sample], a: usize, b: usize, o: &SegmentOptions) -> Segment {
    let seg = &s[a..b];
    let a_spread = spread(seg.iter().map(|x| x.alpha));
    let has_kappa = seg.iter().any(|x| x.kappa.is_finite());
    let kappa_swept = if has_kappa {
        spread(seg.iter().map(|x| x.kappa)) > KAPPA_SWEPT
    } else {
        // Without κ, a swept Fx at fixed α stands for a slip-ratio sweep.
        spread(seg.iter().map(|x| x.fx / x.fz.max(1.0))) > FX_SWEPT
    };
    let alpha_med = med_of(seg, |x| x.alpha);
    let alpha_swept = a_spread > ALPHA_SWEPT;
    let kind = match (alpha_swept, kappa_swept) {
        (true, false) => SegmentKind::PureLateral,
        (false, true) if alpha_med.abs() <= o.alpha_tol => SegmentKind::PureLongitudinal,
        (false, true) | (true, true) => SegmentKind::Combined,
        (false, false) => SegmentKind::Other,
    };
    Segment {
        start: a,
        end: b,
        kind,
        fz: med_of(seg, |x| x.fz),
        gamma: med_of(seg, |x| x.gamma),
        p: med_of(seg, |x| x.p),
        vx: med_of(seg, |x| x.vx / x.alpha.cos().max(0.5)),
        alpha: if alpha_swept { f64::NAN } else { alpha_med },
    }
}

/// Sweep signature of a segment: (low, high) of the swept slip, duration.
fn signature(s: &[Sample], g: &Segment) -> (f64, f64, f64) {
    let seg = &s[g.start..g.end];
    let f = |x: &Sample| {
        if g.kind == SegmentKind::PureLateral {
            x.alpha
        } else {
            x.kappa
        }
    };
    let dur = seg.last().map_or(0.0, |l| l.time) - seg[0].time;
    (
        pct(seg.iter().map(f), 0.02),
        pct(seg.iter().map(f), 0.98),
        dur,
    )
}

/// Detect the warm-up: returns the index of the first programme sample and why.
pub fn detect_warmup(s: &[Sample], segs: &[Segment]) -> Option<(usize, String)> {
    if segs.len() < 4 {
        return None;
    }
    let typical = |kind: SegmentKind| -> Option<(f64, f64, f64)> {
        let sig: Vec<_> = segs
            .iter()
            .filter(|g| g.kind == kind)
            .map(|g| signature(s, g))
            .collect();
        if sig.len() < 3 {
            return None;
        }
        let m = |k: usize| {
            let mut v: Vec<f64> = sig.iter().map(|x| [x.0, x.1, x.2][k]).collect();
            median_in_place(&mut v)
        };
        Some((m(0), m(1), m(2)))
    };
    let mut first = 0;
    let mut why = Vec::new();
    for g in segs {
        let Some((lo, hi, dur)) = typical(g.kind) else {
            break;
        };
        let (l, h, d) = signature(s, g);
        let range = (hi - lo).abs().max(1e-9);
        // A load no other segment runs at is not part of the matrix either.
        let lone = !segs
            .iter()
            .any(|o| !std::ptr::eq(o, g) && (o.fz - g.fz).abs() <= 0.08 * g.fz.abs().max(750.0));
        let off =
            (l - lo).abs() > 0.15 * range || (h - hi).abs() > 0.15 * range || d < 0.5 * dur || lone;
        if !off {
            // Conforming segment: cut its surplus beginning if much longer.
            if d > 1.5 * dur && dur > 0.0 {
                let t_cut = s[g.end - 1].time - dur * 1.05;
                let k = s[g.start..g.end].partition_point(|x| x.time < t_cut) + g.start;
                why.push(format!(
                    "the first programme segment ran {d:.1} s against a typical {dur:.1} s: its first {:.1} s (extra sweeps at the same set point) cut",
                    s[k].time - s[g.start].time
                ));
                return Some((k, why.join("; ")));
            }
            first = g.start;
            break;
        }
        why.push(format!(
            "segment at t = {:.1}–{:.1} s swept {:.3}…{:.3} over {d:.1} s, unlike the programme's {lo:.3}…{hi:.3} over {dur:.1} s",
            s[g.start].time,
            s[g.end - 1].time,
            l,
            h
        ));
    }
    if why.is_empty() {
        // Samples before the first segment: warm-up only if they contain sweeps.
        let g = &segs[0];
        if g.start > 0 && spread(s[..g.start].iter().map(|x| x.alpha)) > ALPHA_SWEPT {
            return Some((
                g.start,
                "slip sweeps before the first set-point segment".into(),
            ));
        }
        return None;
    }
    (first > 0).then(|| (first, why.join("; ")))
}

/// Per-sample sweep direction and time in segment.
pub fn sweep_and_time(s: &[Sample], segs: &[Segment]) -> (Vec<i8>, Vec<f64>) {
    let n = s.len();
    let mut dir = vec![0i8; n];
    let mut t = vec![f64::NAN; n];
    for g in segs {
        let seg = &s[g.start..g.end];
        let lateral = g.kind == SegmentKind::PureLateral
            || (g.kind == SegmentKind::Other && g.alpha.is_nan());
        let x: Vec<f64> = seg
            .iter()
            .map(|v| if lateral { v.alpha } else { v.kappa })
            .collect();
        let thr = if lateral { 0.2f64.to_radians() } else { 0.004 }; // per second
                                                                     // Central difference over ±h samples (≈ 0.1 s) of a lightly smoothed signal.
        let dts: Vec<f64> = seg.windows(2).map(|w| w[1].time - w[0].time).collect();
        let dt = if dts.is_empty() {
            0.01
        } else {
            dts.iter().sum::<f64>() / dts.len() as f64
        };
        let h = ((0.1 / dt.max(1e-6)).round() as usize).max(1);
        let xs = running_mean(&x, 2 * h + 1);
        let mut last = 0i8;
        for i in 0..seg.len() {
            let (a, b) = (i.saturating_sub(h), (i + h).min(seg.len() - 1));
            let dtt = seg[b].time - seg[a].time;
            let rate = if dtt > 0.0 {
                (xs[b] - xs[a]) / dtt
            } else {
                0.0
            };
            if rate > thr {
                last = 1;
            } else if rate < -thr {
                last = -1;
            }
            dir[g.start + i] = last;
            t[g.start + i] = seg[i].time - seg[0].time;
        }
        // Leading samples before the first clear direction take the first one.
        if let Some(first) = dir[g.start..g.end].iter().copied().find(|d| *d != 0) {
            for d in dir[g.start..g.end].iter_mut() {
                if *d != 0 {
                    break;
                }
                *d = first;
            }
        }
    }
    (dir, t)
}

/// Segment the recording, cut the warm-up (if asked), fill sweep direction
/// and time-in-segment; record what was done in `report`.
pub fn apply(
    rec: &mut Recording,
    remove_warmup: bool,
    o: &SegmentOptions,
    report: &mut LoadReport,
) {
    let mut segs = segment(&rec.samples, o);
    if remove_warmup {
        if let Some((k, why)) = detect_warmup(&rec.samples, &segs) {
            if k > 0 && k < rec.samples.len() {
                report.warmup = Some(WarmupCut {
                    samples: k,
                    t_start: rec.samples[0].time,
                    t_end: rec.samples[k].time,
                    reason: why,
                });
                rec.samples.drain(..k);
                for (_, v) in rec.extra.iter_mut() {
                    v.drain(..k.min(v.len()));
                }
                // Shift the segments instead of segmenting again.
                segs.retain(|g| g.end > k + 1);
                for g in segs.iter_mut() {
                    g.start = g.start.max(k) - k;
                    g.end -= k;
                }
            }
        }
    }
    let (d, t) = sweep_and_time(&rec.samples, &segs);
    rec.segments = segs;
    rec.sweep_dir = d;
    rec.t_in_segment = t;
}
