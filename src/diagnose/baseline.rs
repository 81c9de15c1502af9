//! baseline — the tyre the diagnosis compares the recordings with when no
//! `--tir` is given: the steady-state MF 6.1 fitted to the recordings
//! themselves through the public fit API ([`crate::fit::mf_fit::fit_mf`]),
//! starting from the built-in tyre ([`TyreParams::builtin`]) with the
//! nominal values (FNOMIN, NOMPRES/INFLPRES, LONGVL) taken from the data.
//!
//! # What is held, and why
//! The baseline must not already contain the physics a candidate is meant to
//! name — a baseline that fitted the pressure terms would hide a pressure
//! effect, one that fitted relaxation lengths would hide a lag. Held at their
//! start values:
//! * the relaxation keys (LONGITUDINAL_STIFFNESS, LATERAL_STIFFNESS, PTX*,
//!   PTY*, PCFX*/PCFY*): the steady fit has no stage for them, and the
//!   baseline is replayed steady;
//! * the pressure terms PPX1–4, PPY1–5 and PPZ1–2: **set to 0** (the
//!   built-in tyre's values describe another tyre, a 205/60R15 at 2.2 bar)
//!   and held by fitting the data at one pressure — every sample's pressure
//!   is set to the median pressure for the fit, so the fit holds the
//!   pressure terms (it holds them whenever the data hold one pressure). The
//!   baseline is thus a tyre without pressure dependence, fitted to all
//!   pressures pooled, and it replays identically at every pressure;
//! * LMUV (speed-dependent friction) and every other scaling factor: the
//!   fitter never moves a scaling factor;
//! * PRESMIN/PRESMAX are widened to the recorded pressures: the replay
//!   applies the file's range limits as the FMU does, and a clipped pressure
//!   would make a candidate's pressure terms act at the wrong pressure;
//! * BREFF, DREFF, FREFF (effective rolling radius) and the vertical keys:
//!   no steady stage fits them (the replay prescribes the recorded slips).
//!
//! # Sensor zeros
//! A load cell's constant zero error is taken out before the comparison:
//! estimated from the first fit's residual and the MF fitted again without
//! it ([`super::sensor_zero`], [`Baseline::zeroed`]); `baseline.tir` stays
//! the first fit.
//!
//! # Speed
//! The fit sees at most [`MAX_FIT_SAMPLES`] samples: a recording is thinned
//! by a constant stride (segments remapped), which keeps every segment and
//! both sweep directions — rig recordings at 100 Hz and more carry far more
//! samples than the 20-odd parameters of a stage need.
//!
//! Must never: fit a parameter a candidate owns (above), change the
//! recordings the diagnosis scores (the fit works on copies), or panic on
//! a recording without some channel (stages without data are skipped and
//! reported).

use super::sensor_zero::{self, SensorZeros};
use crate::data::{Recording, SegmentKind};
use crate::error::Result;
use crate::fit::mf_fit::{fit_mf, MfFitOptions};
use crate::fit::mf_stages::{Channel, StageKind};
use crate::fit::{Holdout, ProgressFn};
use crate::stats::median;
use crate::tir::TyreParams;

/// Largest number of samples the baseline fit sees (all recordings together).
pub const MAX_FIT_SAMPLES: usize = 40_000;

/// Pressure terms set to 0 and held (see the module docs).
pub const HELD_PRESSURE_KEYS: [&str; 11] = [
    "PPX1", "PPX2", "PPX3", "PPX4", "PPY1", "PPY2", "PPY3", "PPY4", "PPY5", "PPZ1", "PPZ2",
];

/// The fitted baseline and what the fit said.
pub struct Baseline {
    /// The MF fitted to the recordings as measured: `baseline.tir`.
    pub tyre: TyreParams,
    /// The sensor zeros found in its residual ([`super::sensor_zero`];
    /// none estimated for a fit from a given start).
    pub zeros: SensorZeros,
    /// The MF fitted again with [`Baseline::zeros`] subtracted from the
    /// recordings: the tyre the diagnosis compares with (`None` when no
    /// zero was estimated, or when removing them gained the fit less than
    /// [`sensor_zero::MIN_FIT_GAIN`]).
    pub zeroed: Option<TyreParams>,
    /// How much better the MF fits without the zeros
    /// ([`sensor_zero::fit_gain`]; `None`: no second fit was made).
    pub zero_fit_gain: Option<f64>,
    /// Stages skipped and why (e.g. "pure Fx: 0 samples").
    pub skipped: Vec<String>,
    /// The fit's report (parameters per stage, σ per channel and condition).
    pub report: crate::fit::FitReport,
    /// Stride the recordings were thinned by for the fit.
    pub stride: usize,
}

impl Baseline {
    /// The tyre the diagnosis compares the recordings with: the fit without
    /// the sensor zeros where removing them gained the fit at least
    /// [`sensor_zero::MIN_FIT_GAIN`], else [`Baseline::tyre`].
    pub fn compared(&self) -> &TyreParams {
        self.zeroed.as_ref().unwrap_or(&self.tyre)
    }
    /// (channel, segment kind) pairs of the force and moment channels the
    /// fit fitted ([`crate::fit::FitReport::fitted`]).
    pub fn fitted(&self) -> Vec<(Channel, SegmentKind)> {
        self.report
            .fitted
            .iter()
            .filter_map(|(n, seg)| Channel::parse(n).map(|c| (c, *seg)))
            .filter(|(c, _)| Channel::SCORED.contains(c))
            .collect()
    }
}

/// Every `k`-th sample of `rec` (k ≥ 1), segments, sweep directions, times
/// in segment and extra channels remapped.
pub fn decimate(rec: &Recording, k: usize) -> Recording {
    let k = k.max(1);
    if k == 1 {
        return rec.clone();
    }
    let pick = |i: usize| i.div_ceil(k);
    let every = |v: &[f64]| v.iter().step_by(k).copied().collect::<Vec<f64>>();
    let mut out = Recording {
        source: rec.source.clone(),
        samples: rec.samples.iter().step_by(k).cloned().collect(),
        channels: rec.channels.clone(),
        extra: rec
            .extra
            .iter()
            .map(|(n, v)| (n.clone(), every(v)))
            .collect(),
        segments: Vec::new(),
        sweep_dir: rec.sweep_dir.iter().step_by(k).copied().collect(),
        t_in_segment: every(&rec.t_in_segment),
    };
    for g in &rec.segments {
        let (a, b) = (pick(g.start), pick(g.end).min(out.samples.len()));
        if a < b {
            let mut h = g.clone();
            h.start = a;
            h.end = b;
            out.segments.push(h);
        }
    }
    out
}

/// Blank (NaN) each force channel among Fx, Fy, Mz on the segments of a
/// kind the baseline fit did not fit it on, and drop a channel no stage fit
/// at all (e.g. Fx of a lateral-only test, where Fx is rig crosstalk), as
/// the fit recorded them ([`Baseline::fitted`]; e.g. Mz of a drive/brake
/// run without cornering sweeps, whose shape no stage could fit): elsewhere
/// the baseline's value is the start tyre's, not a fit, and its residual
/// would be named as a missing physics. Returns the channels dropped entirely; the diagnosis
/// skips blanked samples (scores, locate, plots).
pub fn drop_unfitted(recs: &mut [Recording], b: &Baseline) -> Vec<&'static str> {
    let fitted = b.fitted();
    let mut out = Vec::new();
    for c in [Channel::Fx, Channel::Fy, Channel::Mz] {
        if !recs.iter().any(|r| r.has(c.name())) {
            continue;
        }
        let blank = |s: &mut crate::data::Sample| match c {
            Channel::Fx => s.fx = f64::NAN,
            Channel::Fy => s.fy = f64::NAN,
            _ => s.mz = f64::NAN,
        };
        let none = !fitted.iter().any(|f| f.0 == c);
        for r in recs.iter_mut() {
            let n = r.samples.len();
            if none {
                r.channels.retain(|x| !x.eq_ignore_ascii_case(c.name()));
                r.samples.iter_mut().for_each(blank);
                continue;
            }
            let segs = r.segments.clone();
            for g in segs.iter().filter(|g| !fitted.contains(&(c, g.kind))) {
                r.samples[g.start.min(n)..g.end.min(n)]
                    .iter_mut()
                    .for_each(blank);
            }
        }
        if none {
            out.push(c.name());
        }
    }
    out
}

/// Widen PRESMIN/PRESMAX to the recorded pressures (±20 %): the replay
/// runs with the file's range limits on (use mode 111, as the FMU), and a
/// pressure below PRESMIN would be clipped — the built-in tyre's range
/// (186–255 kPa) would clip a 0.7–1 bar FSAE tyre to another pressure.
fn widen_pressure_range(tyre: &mut TyreParams, recs: &[Recording]) -> Result<()> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in recs.iter().flat_map(|r| &r.samples) {
        if s.p.is_finite() && s.p > 0.0 {
            lo = lo.min(s.p);
            hi = hi.max(s.p);
        }
    }
    if lo.is_finite() {
        if tyre.get("PRESMIN").is_some_and(|v| lo < v) {
            tyre.set("PRESMIN", 0.8 * lo)?;
        }
        if tyre.get("PRESMAX").is_some_and(|v| hi > v) {
            tyre.set("PRESMAX", 1.2 * hi)?;
        }
    }
    Ok(())
}

/// Fit the baseline MF 6.1 to `recs` (see the module docs), then estimate
/// the channels' sensor zeros from its residual and fit it again with them
/// removed ([`super::sensor_zero`]; [`Baseline::zeroed`]). `threads` for
/// the fits' evaluation; `progress` receives the fitter's reports.
pub fn fit_baseline(
    recs: &[Recording],
    threads: usize,
    mut progress: Option<&mut ProgressFn>,
) -> Result<Baseline> {
    let mut b = fit_baseline_from(
        recs,
        None,
        None,
        Pressures::Pooled,
        threads,
        progress.as_deref_mut(),
    )?;
    // The residual the fit minimised: on the data as it saw them.
    let seen = fit_data(recs, b.stride, true);
    let zeros = sensor_zero::estimate(&seen, &b.tyre, &b.fitted())?;
    if zeros.any() {
        let corrected: Vec<Recording> = recs
            .iter()
            .map(|r| sensor_zero::subtract(r, &zeros))
            .collect();
        // From the built-in tyre as the first fit, with the geometry of the
        // recording as measured ([`MfFitOptions::geometry_recordings`]):
        // the two fits differ in what the force stages see only. Measured on
        // the dev set with the zero errors doubled (29 Nov 2026): from the
        // first fit instead, the stages stayed near its compromise (r07 named
        // `load_sensitivity`, r04 `none`); from the built-in tyre all 21
        // verdicts held. (That warm start did give r14's thermal file 56 %
        // of its gap against 46 % here: another local compromise of the MF.)
        let z = fit_with_geometry_of(
            &corrected,
            Some(recs),
            None,
            None,
            Pressures::Pooled,
            threads,
            progress,
        )?;
        // Only a zero that bent the first fit is worth the second baseline
        // ([`sensor_zero::MIN_FIT_GAIN`]).
        let gain = sensor_zero::fit_gain(&b.report.metrics, &z.report.metrics, &zeros);
        b.zero_fit_gain = Some(gain);
        if gain >= sensor_zero::MIN_FIT_GAIN {
            b.zeroed = Some(z.tyre);
        }
    }
    b.zeros = zeros;
    Ok(b)
}

/// Which pressure the baseline fit sees per sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pressures {
    /// Every sample at the recordings' median pressure, the pressure terms
    /// set to 0 and held: a tyre without pressure dependence (the baseline,
    /// see the module docs).
    Pooled,
    /// Each sample at its recorded pressure, the start's pressure terms and
    /// nominal values (INFLPRES is the pressure terms' reference) held: the
    /// MF fitted again beneath a named pressure law
    /// ([`crate::diagnose::reestimate`]).
    Recorded,
}

/// [`fit_baseline`] from `start` instead of the built-in tyre (None: the
/// built-in one; given, its radii and vertical keys are kept — the
/// geometry step runs only from the built-in tyre) and, given `stages`,
/// only those; the samples' pressures as `pressures` says; the same held
/// keys, options and thinning otherwise. The re-estimation
/// ([`crate::diagnose::reestimate`]) fits the baseline again from the
/// extended tyre or the previous baseline.
pub fn fit_baseline_from(
    recs: &[Recording],
    from: Option<TyreParams>,
    stages: Option<&[StageKind]>,
    pressures: Pressures,
    threads: usize,
    progress: Option<&mut ProgressFn>,
) -> Result<Baseline> {
    fit_with_geometry_of(recs, None, from, stages, pressures, threads, progress)
}

/// The recordings as the fit sees them: every `stride`-th sample, and with
/// `pooled` every pressure at the recordings' median one.
fn fit_data(recs: &[Recording], stride: usize, pooled: bool) -> Vec<Recording> {
    let p_med = median(
        recs.iter()
            .flat_map(|r| r.samples.iter().step_by(10).map(|s| s.p)),
    )
    .filter(|_| pooled);
    recs.iter()
        .map(|r| {
            let mut d = decimate(r, stride);
            if let Some(p) = p_med {
                for s in &mut d.samples {
                    if s.p.is_finite() {
                        s.p = p;
                    }
                }
                for g in &mut d.segments {
                    if g.p.is_finite() {
                        g.p = p;
                    }
                }
            }
            d
        })
        .collect()
}

/// [`fit_baseline_from`], the geometry step (from the built-in tyre only)
/// reading `geometry_of` (the same samples as `recs`, other force values)
/// where given.
fn fit_with_geometry_of(
    recs: &[Recording],
    geometry_of: Option<&[Recording]>,
    from: Option<TyreParams>,
    stages: Option<&[StageKind]>,
    pressures: Pressures,
    threads: usize,
    progress: Option<&mut ProgressFn>,
) -> Result<Baseline> {
    let n: usize = recs.iter().map(|r| r.samples.len()).sum();
    let stride = n.div_ceil(MAX_FIT_SAMPLES).max(1);
    let pooled = pressures == Pressures::Pooled;
    let data = fit_data(recs, stride, pooled);
    let geometry = from.is_none();
    let mut start = from.unwrap_or_else(TyreParams::builtin);
    if pooled {
        for k in HELD_PRESSURE_KEYS {
            start.set(k, 0.0)?;
        }
    }
    let mut opts = MfFitOptions {
        holdout: Holdout::None,
        nominal_from_data: pooled,
        hold_pressure: !pooled,
        // The tyre's own radii from the recording: `replay` and the FMU
        // derive κ from the wheel speed through the file's Re(Fz), so a
        // baseline with another tyre's geometry would misfit every channel
        // (dev set r01: Fy NRMSE 0.099 against 0.008 with the recording's Re).
        // From a previous baseline they are the data's already, and a
        // rolling-radius finding's own Re(Fz) must stay.
        geometry,
        geometry_recordings: geometry_of
            .filter(|_| geometry)
            .map(|g| std::sync::Arc::new(fit_data(g, stride, pooled))),
        threads: threads.max(1),
        ..Default::default()
    };
    // Initial LM damping 1e-3, the value this baseline was validated with
    // (rig recordings, TyreData.csv). `tyrekit fit` now defaults to 1e-2
    // (better on its pure-Fy benchmark); on TyreData.csv that default lands
    // in a worse minimum of this baseline (held-out σ_Fy 11.7 % against
    // 4.7 %), which an in-sample criterion over Fy and Mz did not catch.
    opts.fit.lm.lambda0 = 1e-3;
    if let Some(only) = stages {
        opts.only = only.to_vec();
    }
    let mut fit = fit_mf(&data, start, &opts, progress)?;
    widen_pressure_range(&mut fit.tyre, recs)?;
    Ok(Baseline {
        tyre: fit.tyre,
        zeros: SensorZeros::default(),
        zeroed: None,
        zero_fit_gain: None,
        skipped: fit.skipped,
        report: fit.report,
        stride,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Sample, Segment, SegmentKind};

    /// Thinning by 3 keeps samples 0, 3, 6 …; a segment [4, 10) holds
    /// original samples 4..9, of which 6 and 9 survive → new indices 2, 3,
    /// i.e. [ceil(4/3), ceil(10/3)) = [2, 4).
    #[test]
    fn decimate_remaps_segments() {
        let rec = Recording {
            samples: (0..12)
                .map(|i| Sample {
                    time: i as f64,
                    ..Default::default()
                })
                .collect(),
            segments: vec![Segment {
                start: 4,
                end: 10,
                kind: SegmentKind::PureLateral,
                fz: 1.0,
                gamma: 0.0,
                p: 0.0,
                vx: 1.0,
                alpha: 0.0,
            }],
            sweep_dir: vec![1; 12],
            t_in_segment: (0..12).map(|i| i as f64).collect(),
            ..Default::default()
        };
        let d = decimate(&rec, 3);
        assert_eq!(d.samples.len(), 4);
        assert_eq!((d.segments[0].start, d.segments[0].end), (2, 4));
        let times: Vec<f64> = d.samples[2..4].iter().map(|s| s.time).collect();
        assert_eq!(times, vec![6.0, 9.0]);
        assert_eq!(d.t_in_segment.len(), 4);
    }
}
