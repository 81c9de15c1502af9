//! work — what a candidate's fit replays at every trial of its parameters,
//! and which of those samples its residual reads: as little of the
//! recording as the model's memory allows.
//!
//! A fit replays the candidate's model tens of times (a scan, then every
//! Levenberg–Marquardt trial and finite-difference column). The residual
//! reads at most [`FIT_SAMPLES`] fit-half samples, thinned evenly; what has
//! to be replayed around them depends on what the model remembers
//! ([`Memory`]):
//!
//! * **nothing** (static candidates): the thinned samples themselves, at
//!   most [`super::STATIC_SAMPLES`] — order and gaps do not matter;
//! * **a rolled distance** (slip lag, bristles: the relaxation and LuGre
//!   candidates): each run of fit-half samples from a warm-up of
//!   [`WARM_UP_LAGS`] times the longest lag length the candidate's
//!   parameter ranges allow before it (less where a replay gap comes
//!   first, since the replay starts afresh there anyway). The replay
//!   settles the state on a window's first sample
//!   ([`crate::residual::replay`]); a lag state forgets that start as
//!   e^(−s/σ) over the rolled distance s, so after 3 lag lengths at the
//!   range's end (e^−3 = 5 % of the start's deviation from the true state,
//!   which sits between segments, near rest, where a rig runs quietly) and
//!   far less at the lags a fit meets (a 0.3 m lag forgets 18 m of
//!   warm-up to e^−60). The test half between two windows is not
//!   replayed: about half a recording;
//! * **the whole run** (a tread temperature, whose time constant is at
//!   least 5 s and whose state remembers every earlier sweep): every k-th
//!   sample of the whole recording, k such that the fit half keeps about
//!   [`FIT_SAMPLES`] samples. The temperature is integrated exactly for a
//!   held power ([`crate::transient::extension`]), so a step of k samples
//!   (k·10 ms on a 100 Hz rig) holds the power over it; against a time
//!   constant of seconds that is the same heating history. Only under the
//!   steady force model: a slip lag under it would not survive the long
//!   step, and the fit then replays every sample.
//!
//! Must never: give the residual a sample outside the fit mask, or cut a
//! window so that a sample the residual reads lacks its warm-up when the
//! recording has one before it.

use super::STATIC_SAMPLES;
use crate::data::Recording;
use crate::diagnose::baseline::decimate;
use crate::residual::median_spacing;

/// Most fit-half samples the residual of a candidate with a state reads.
pub const FIT_SAMPLES: usize = 4 * STATIC_SAMPLES;

/// Warm-up before each window of a [`Memory::Rolled`] fit, in the longest
/// lag length the candidate's ranges allow (see the module docs).
pub const WARM_UP_LAGS: f64 = 3.0;

/// What a candidate's model remembers between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Memory {
    /// Nothing: each sample's forces follow from its own inputs.
    #[default]
    None,
    /// A state that forgets its start over a rolled distance: the value is
    /// the longest lag length (m) the candidate's parameter ranges allow at
    /// the nominal load (relaxation lengths, LuGre's bristle length).
    Rolled(f64),
    /// A slow state that remembers the whole run (a tread temperature of
    /// time constant ≥ 5 s), replayed on a coarser time grid.
    Slow,
    /// A state of unknown reach: every sample of the whole recording.
    Whole,
}

impl Memory {
    /// [`Memory::Rolled`] with the longest lag `lag` (m), or
    /// [`Memory::Whole`] when the tyre gives no finite positive lag.
    pub fn rolled(lag: f64) -> Memory {
        if lag.is_finite() && lag > 0.0 {
            Memory::Rolled(lag)
        } else {
            Memory::Whole
        }
    }
}

/// The recording a fit replays and the indices (into it) of the samples
/// its residual reads, for a model with `memory` on `rec`'s fit half
/// `mask` (see the module docs).
pub fn work(rec: &Recording, mask: &[bool], memory: Memory) -> (Recording, Vec<usize>) {
    match memory {
        Memory::None => {
            let idx = thin(mask, STATIC_SAMPLES);
            let sub = Recording {
                samples: idx.iter().map(|&i| rec.samples[i]).collect(),
                ..Default::default()
            };
            let n = idx.len();
            (sub, (0..n).collect())
        }
        Memory::Whole => (rec.clone(), thin(mask, FIT_SAMPLES)),
        Memory::Slow => {
            let n_fit = mask.iter().filter(|x| **x).count();
            let k = n_fit.div_ceil(FIT_SAMPLES).max(1);
            let sub_mask: Vec<bool> = mask.iter().step_by(k).copied().collect();
            (decimate(rec, k), thin(&sub_mask, FIT_SAMPLES))
        }
        Memory::Rolled(lag) => {
            let read = thin(mask, FIT_SAMPLES);
            let kept = windows(rec, mask, WARM_UP_LAGS * lag);
            // Every read sample lies in a window (its run is one); its
            // position among the kept samples.
            let mut pos = Vec::with_capacity(read.len());
            let mut j = 0;
            for &i in &read {
                while kept[j] < i {
                    j += 1;
                }
                pos.push(j);
            }
            (pick(rec, &kept), pos)
        }
    }
}

/// Fit-half sample indices, thinned to at most `max` (evenly).
pub fn thin(mask: &[bool], max: usize) -> Vec<usize> {
    let idx: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
    let step = idx.len().div_ceil(max.max(1)).max(1);
    idx.into_iter().step_by(step).collect()
}

/// Indices of the samples in the windows of a [`Memory::Rolled`] fit:
/// each run of `mask` from `warm_up` metres of rolling before it (the
/// rolled distance Σ|Vx|·dt; a replay gap ends the warm-up early), in
/// time order, overlapping windows merged.
fn windows(rec: &Recording, mask: &[bool], warm_up: f64) -> Vec<usize> {
    let s = &rec.samples;
    let t: Vec<f64> = s.iter().map(|x| x.time).collect();
    let h = median_spacing(&t);
    let gap = crate::residual::ReplayOptions::default().gap_factor * h;
    // A step the replay treats as a gap (see `crate::residual::replay`).
    let is_gap = |i: usize| {
        let d = t[i] - t[i - 1];
        !(d.is_finite() && d > 0.0 && (!h.is_finite() || d <= gap))
    };
    let mut kept: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < mask.len() {
        if !mask[i] {
            i += 1;
            continue;
        }
        let mut end = i;
        while end < mask.len() && mask[end] {
            end += 1;
        }
        // Walk back from the run's start over `warm_up` metres.
        let mut a = i;
        let mut rolled = 0.0;
        while a > 0 && rolled < warm_up && !is_gap(a) {
            let d = (t[a] - t[a - 1]) * s[a].vx.abs();
            rolled += if d.is_finite() { d } else { 0.0 };
            a -= 1;
        }
        let from = kept.last().map_or(a, |&l| a.max(l + 1));
        kept.extend(from..end);
        i = end;
    }
    kept
}

/// The samples of `rec` at `kept` (increasing), with the channels the
/// replay reads: named channels and extra channels; segments and sweep
/// annotations are not carried (a fit reads none of them).
fn pick(rec: &Recording, kept: &[usize]) -> Recording {
    Recording {
        source: rec.source.clone(),
        samples: kept.iter().map(|&i| rec.samples[i]).collect(),
        channels: rec.channels.clone(),
        extra: rec
            .extra
            .iter()
            .map(|(n, v)| (n.clone(), kept.iter().map(|&i| v[i]).collect()))
            .collect(),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Sample;

    /// A 100 Hz recording at `vx` with a run of the fit half at `runs`.
    fn rec(n: usize, vx: f64) -> Recording {
        Recording {
            samples: (0..n)
                .map(|i| Sample {
                    time: i as f64 * 0.01,
                    vx,
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        }
    }

    fn mask(n: usize, runs: &[(usize, usize)]) -> Vec<bool> {
        let mut m = vec![false; n];
        for &(a, b) in runs {
            m[a..b].iter_mut().for_each(|x| *x = true);
        }
        m
    }

    /// At 10 m/s a 100 Hz sample rolls 0.1 m: a lag just under 1 m (a
    /// warm-up just under 3 m, clear of rounding in the rolled sum)
    /// adds 30 samples before each run; the residual reads the same
    /// samples as a whole replay would; runs closer than their warm-up
    /// merge into one window; a window never reaches back past a gap.
    #[test]
    fn rolled_windows_hold_each_run_and_its_warm_up() {
        let r = rec(1000, 10.0);
        let m = mask(1000, &[(100, 200), (215, 300), (600, 700)]);
        let (w, idx) = work(&r, &m, Memory::Rolled(0.995));
        let times: Vec<f64> = w.samples.iter().map(|s| s.time).collect();
        // 70..300 (the second run's warm-up reaches into the first) and 570..700.
        assert_eq!(w.samples.len(), 230 + 130);
        assert!((times[0] - 0.70).abs() < 1e-9 && (times[230] - 5.70).abs() < 1e-9);
        let read: Vec<f64> = idx.iter().map(|&j| times[j]).collect();
        let whole: Vec<f64> = thin(&m, FIT_SAMPLES)
            .iter()
            .map(|&i| r.samples[i].time)
            .collect();
        assert_eq!(read, whole);
        // A gap (1 s without samples) 10 samples before a run ends its warm-up.
        let mut g = rec(1000, 10.0);
        for s in &mut g.samples[490..] {
            s.time += 1.0;
        }
        let (w, _) = work(&g, &mask(1000, &[(500, 600)]), Memory::Rolled(0.995));
        assert_eq!(w.samples.len(), 110);
    }

    /// The slow grid keeps about FIT_SAMPLES of the fit half and only
    /// fit-half samples are read.
    #[test]
    fn slow_grid_thins_the_whole_recording_evenly() {
        let n = 100_000;
        let r = rec(n, 10.0);
        let m = mask(n, &[(0, 20_000), (50_000, 90_000)]);
        let (w, idx) = work(&r, &m, Memory::Slow);
        assert_eq!(w.samples.len(), n.div_ceil(4));
        assert!(idx.len() <= FIT_SAMPLES && idx.len() > FIT_SAMPLES * 9 / 10);
        for &j in &idx {
            let t = w.samples[j].time;
            assert!(t < 200.0 || (500.0..900.0).contains(&t), "{t}");
        }
    }

    /// The physics the windows rely on: on a swept recording (α and κ
    /// never at rest), the relaxation and LuGre models replayed on the
    /// windows give the forces of the whole replay on every sample the
    /// residual reads, to 1e-9 of the largest force, with the warm-up the
    /// candidates use (three of their longest lags: 20× the built-in tyre's
    /// relaxation length) — the state has forgotten the window's settled
    /// start; with no warm-up at all (runs starting mid-sweep) they do not
    /// (the check can fail).
    #[test]
    fn window_replays_agree_with_the_whole_replay_where_the_residual_reads() {
        use crate::mf::Tyre;
        use crate::residual::{replay, ReplayOptions};
        use crate::transient::TransientKind;
        let tyre = Tyre::builtin();
        let n = 3000;
        let r = Recording {
            samples: (0..n)
                .map(|i| {
                    let t = i as f64 * 0.01;
                    let tau = std::f64::consts::TAU;
                    Sample {
                        time: t,
                        vx: 11.0,
                        omega: f64::NAN,
                        fz: 3000.0 + 800.0 * (tau * t / 7.0).sin(),
                        kappa: 0.05 * (tau * t / 3.0).sin(),
                        alpha: 6f64.to_radians() * (tau * t / 4.0).sin(),
                        p: f64::NAN,
                        ..Default::default()
                    }
                })
                .collect(),
            ..Default::default()
        };
        let m = mask(n, &[(530, 900), (1510, 2000), (2470, 2900)]);
        let o = ReplayOptions::default();
        let props = super::super::param::nominal_props(&tyre, &o);
        let lag = 20.0 * props.sigmax.max(props.sigmay);
        for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
            let o = ReplayOptions { kind, ..o };
            let whole = replay(&r, &tyre, &o).unwrap().sim;
            let fmax = whole
                .iter()
                .map(|f| f.fx.abs().max(f.fy.abs()))
                .fold(0.0, f64::max);
            let worst = |lag: f64| {
                let (w, idx) = work(&r, &m, Memory::Rolled(lag));
                let sim = replay(&w, &tyre, &o).unwrap().sim;
                let read = thin(&m, FIT_SAMPLES);
                idx.iter()
                    .zip(&read)
                    .map(|(&j, &i)| {
                        let (a, b) = (sim[j], whole[i]);
                        (a.fx - b.fx)
                            .abs()
                            .max((a.fy - b.fy).abs())
                            .max((a.mz - b.mz).abs())
                    })
                    .fold(0.0, f64::max)
            };
            let (with, without) = (worst(lag), worst(1e-9));
            assert!(with <= 1e-9 * fmax, "{kind:?}: {with} N of {fmax} N");
            assert!(
                without > 1e-3 * fmax,
                "{kind:?}: {without} N without warm-up"
            );
        }
    }
}
