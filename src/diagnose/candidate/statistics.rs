//! statistics — how a candidate is scored (see the module docs of
//! [`super`]): the fit/score split of the segments, the input smoothing,
//! the channel weights, and [`evaluate`], which fits every candidate on one
//! half and scores it on the other, per channel against the baseline's own
//! error level, with a BIC over both halves.
//!
//! Must never: let a candidate see the held-out half's forces while
//! fitting, or count a channel the recording lacks.

use super::{Candidate, Fitted, REFIT_EVIDENCE};
use crate::data::Recording;
use crate::error::Result;
use crate::mf::{Forces, Tyre};
use crate::residual::{
    channel_sse, inverse_variances, median_spacing, offsets, replay, weighted_sse, Channel,
    ReplayOptions,
};

/// One channel's score of a candidate: the relative drop of the channel's
/// own squared error (offsets removed) against the baseline's.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ChannelScore {
    /// The scored channel (Fx, Fy or Mz; written as its key, "FY").
    pub channel: Channel,
    /// Held-out samples of the channel.
    pub n: usize,
    /// Relative drop of the channel's held-out SSE (1 = all gone, < 0 worse).
    pub oos_gain: f64,
    /// The same on the fit half.
    pub fit_gain: f64,
    /// BIC change of this channel alone over both halves (negative =
    /// better): n_k·ln(SSE_k/SSE_k,base) + p·ln(n_k), n_k = the channel's
    /// recorded seconds ([`DECORRELATION_TIME`]), p = the fitted parameters
    /// that act on the channel ([`Fitted::parameters_on`]; all of them when
    /// the candidate declares none for it). See [`evaluate`].
    pub delta_bic: f64,
    /// Why the baseline's own misfit of this channel leaves the candidate's
    /// gain there no evidence, when it does: the baseline's held-out
    /// residual stands above [`crate::diagnose::report::MISFIT_RATIO`] × the
    /// noise floor the data show and the candidate removes less than
    /// [`crate::diagnose::report::MISFIT_EXPLAINED`] of the excess, or (Fx)
    /// the slip input was computed with a radius that is not the tyre's
    /// (`diagnose::slip_channel`). Such a channel cannot carry the evidence
    /// for a verdict (see `selection`). Set by the diagnosis after the
    /// evaluation; None until then.
    pub baseline_misfit: Option<String>,
    /// Held-out gain of the candidate's reference alone (the baseline with
    /// the keys of [`super::Spec::reference`] fitted again) against the
    /// baseline; 0 for a candidate scored against the baseline itself.
    pub reference_gain: f64,
    /// Whether any of the candidate's fitted parameters acts on this
    /// channel ([`Fitted::parameters_on`], the channels a parameter is
    /// declared on with `Param::on`): where the physics shows first. A
    /// gain in a channel the parameters do not act on is a side effect of
    /// the fit and cannot carry the verdict (see `selection`).
    pub acts: bool,
    /// How far this channel's BIC must fall to carry a verdict: 0 for
    /// physics the baseline lacks; [`super::REFIT_EVIDENCE`] for a candidate
    /// made of keys the baseline fitted itself ([`super::Candidate::refits_baseline`]).
    pub bic_needed: f64,
}

impl ChannelScore {
    /// What the candidate removes of the baseline's held-out error with its
    /// reference: 1 − (1 − [`ChannelScore::oos_gain`])·(1 − [`ChannelScore::reference_gain`]).
    pub fn gain_over_baseline(&self) -> f64 {
        1.0 - (1.0 - self.oos_gain) * (1.0 - self.reference_gain)
    }
}

/// A candidate's evaluation.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Evaluation {
    /// Candidate name ([`Candidate::name`]).
    pub name: String,
    /// Parameters fitted (those acting on a channel with data).
    pub n_params: usize,
    /// Held-out gain over all channels: 1 − the geometric mean (weighted by
    /// samples) of the channels' held-out SSE ratios against the baseline
    /// (1 = all gone). Each channel counts relative to its own error level,
    /// so the worst-fitted channel does not dominate.
    pub oos_gain: f64,
    /// The same on the fit half.
    pub fit_gain: f64,
    /// BIC change against the baseline (negative = better), see [`evaluate`].
    pub delta_bic: f64,
    /// Per-channel gains (channels with data only).
    pub channels: Vec<ChannelScore>,
    /// Fitted parameters by name, in the tyre file's units (SI) ([`Fitted::parameters`]).
    pub parameters: Vec<(String, f64)>,
    /// Fitted parameters that ended at a bound ([`Fitted::at_bound`]).
    pub at_bound: Vec<String>,
    /// The physics in one line ([`Candidate::physics`]).
    pub physics: String,
    /// The fitted extension in words ([`Candidate::describe`]).
    pub describe: String,
    /// Pooled held-out gain of the candidate's reference alone against the
    /// baseline (see [`ChannelScore::reference_gain`]); 0 without one.
    pub reference_gain: f64,
    /// The BIC change against the baseline itself, every fitted parameter
    /// charged (the reference's keys too): what ranks the qualifying
    /// candidates ([`super::select`]), all against the same baseline.
    /// Equal to [`Evaluation::delta_bic`] for a candidate without a
    /// reference.
    pub rank_bic: f64,
}

impl Evaluation {
    /// The pooled held-out gain against the baseline with the reference's
    /// part: 1 − (1 − [`Evaluation::oos_gain`])·(1 − [`Evaluation::reference_gain`]).
    pub fn gain_over_baseline(&self) -> f64 {
        1.0 - (1.0 - self.oos_gain) * (1.0 - self.reference_gain)
    }
    /// The largest and the smallest held-out channel gain (NaN, NaN when
    /// no channel has data).
    pub fn channel_range(&self) -> (f64, f64) {
        self.channels
            .iter()
            .map(|c| c.oos_gain)
            .filter(|g| g.is_finite())
            .fold((f64::NAN, f64::NAN), |(hi, lo), g| (hi.max(g), lo.min(g)))
    }
}

/// The fit and score halves (see the module docs): segments grouped by
/// (kind, load), alternating within each group in time order, each group
/// starting on the other half from the previous group (so that a factor
/// nested inside the groups — pressure, inclination, drive/brake slip angle
/// — also alternates); then any level of load, pressure or inclination with
/// no fit segment gets its first segment moved to the fit half.
pub fn split(rec: &Recording) -> (Vec<bool>, Vec<bool>) {
    use std::collections::HashMap;
    let n = rec.samples.len();
    let mut fzs: Vec<f64> = rec
        .segments
        .iter()
        .map(|g| g.fz)
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    fzs.sort_by(f64::total_cmp);
    let fz_bin = fzs.get(fzs.len() / 2).map_or(100.0, |m| 0.1 * m).max(1.0);
    let bin = |x: f64, w: f64| {
        if x.is_finite() {
            (x / w).round() as i64
        } else {
            i64::MIN
        }
    };
    let levels = |g: &crate::data::Segment| {
        [
            bin(g.fz, fz_bin),
            bin(g.p, 5e3),
            bin(g.gamma, 0.5f64.to_radians()),
        ]
    };
    let mut groups: HashMap<(String, i64), (usize, usize)> = HashMap::new();
    let mut is_fit = Vec::with_capacity(rec.segments.len());
    for g in &rec.segments {
        let k = (format!("{:?}", g.kind), bin(g.fz, fz_bin));
        let ord = groups.len();
        let e = groups.entry(k).or_insert((ord, 0));
        is_fit.push((e.0 + e.1).is_multiple_of(2));
        e.1 += 1;
    }
    for f in 0..3 {
        let mut has_fit: HashMap<i64, bool> = HashMap::new();
        for (g, &b) in rec.segments.iter().zip(&is_fit) {
            *has_fit.entry(levels(g)[f]).or_insert(false) |= b;
        }
        for (i, g) in rec.segments.iter().enumerate() {
            let l = levels(g)[f];
            if has_fit.get(&l) == Some(&false) {
                is_fit[i] = true;
                has_fit.insert(l, true);
            }
        }
    }
    let mut fit = vec![false; n];
    let mut test = vec![false; n];
    for (g, b) in rec.segments.iter().zip(is_fit) {
        let m = if b { &mut fit } else { &mut test };
        for x in m.iter_mut().take(g.end.min(n)).skip(g.start) {
            *x = true;
        }
    }
    (fit, test)
}

/// Half-width (s) of the input smoothing window ([`smoothed_inputs`]).
pub const SMOOTH_HALF_WIDTH: f64 = 0.1;

/// The recording with its measured inputs (Vx, Ω, Fz, κ, α, γ, P) smoothed
/// by a centred moving average of ±[`SMOOTH_HALF_WIDTH`] within each
/// gap-free run (gaps as in replay: steps > 5 median spacings); forces as
/// recorded. Why: κ from wheel speed and belt speed (TTC) and α carry white
/// sensor noise that the force model maps into errors far above the force
/// sensors' noise; a lag model (relaxation, LuGre) low-passes its inputs and
/// would "gain" on a control by filtering that noise. A centred average is
/// zero-phase — it does not create or hide a lag — and exact on the linear
/// sweeps of a test programme; ±0.1 s is far shorter than a sweep (≥ 2 s)
/// and rounds a sweep's turning point by under 0.2° (4°/s) or 0.005 (κ at 0.1/s).
pub fn smoothed_inputs(rec: &Recording) -> Recording {
    let mut out = rec.clone();
    let n = rec.samples.len();
    let t: Vec<f64> = rec.samples.iter().map(|s| s.time).collect();
    let h = median_spacing(&t);
    if !(h.is_finite() && h > 0.0) || n < 3 {
        return out;
    }
    let k = (SMOOTH_HALF_WIDTH / h).round() as usize;
    if k == 0 {
        return out;
    }
    type Get = fn(&crate::data::Sample) -> f64;
    type Put = fn(&mut crate::data::Sample, f64);
    let chans: [(Get, Put); 7] = [
        (|s| s.vx, |s, v| s.vx = v),
        (|s| s.omega, |s, v| s.omega = v),
        (|s| s.fz, |s, v| s.fz = v),
        (|s| s.kappa, |s, v| s.kappa = v),
        (|s| s.alpha, |s, v| s.alpha = v),
        (|s| s.gamma, |s, v| s.gamma = v),
        (|s| s.p, |s, v| s.p = v),
    ];
    // Runs between gaps.
    let mut runs = Vec::new();
    let mut a = 0;
    for i in 1..=n {
        let gap = i == n || {
            let d = t[i] - t[i - 1];
            !(d.is_finite() && d > 0.0 && d <= 5.0 * h)
        };
        if gap {
            runs.push((a, i));
            a = i;
        }
    }
    let mut sum = vec![0.0; n + 1];
    let mut cnt = vec![0.0; n + 1];
    for (get, put) in chans {
        for &(a, b) in &runs {
            for i in a..b {
                let x = get(&rec.samples[i]);
                let ok = x.is_finite();
                sum[i + 1] = sum[i] + if ok { x } else { 0.0 };
                cnt[i + 1] = cnt[i] + if ok { 1.0 } else { 0.0 };
            }
            for i in a..b {
                if !get(&rec.samples[i]).is_finite() {
                    continue;
                }
                // Symmetric window, shrunk near the run's ends (zero phase).
                let w = k.min(i - a).min(b - 1 - i);
                let (lo, hi) = (i - w, i + w + 1);
                let c = cnt[hi] - cnt[lo];
                if c > 0.0 {
                    put(&mut out.samples[i], (sum[hi] - sum[lo]) / c);
                }
            }
        }
    }
    out
}

/// Channel weights for fitting the candidates: 1 / the baseline's mean
/// squared residual per channel on the fit half (offsets removed) — each
/// channel's error level, the weights of the Gaussian likelihood with one
/// unknown variance per channel, evaluated at the baseline (one step of
/// iteratively reweighted least squares). A channel is then fitted relative
/// to how well the baseline already fits it: a badly fitted channel (Mz of a
/// pooled real-data fit) cannot buy its gain by spoiling a well fitted one.
/// 0 for a channel without data in `mask`.
pub fn fit_weights(rec: &Recording, base: &[Forces], mask: &[bool]) -> [f64; 3] {
    let o = offsets(rec, base, mask);
    let var = inverse_variances(rec, mask);
    let mut w = [0.0; 3];
    for (k, (e, n)) in channel_sse(rec, base, mask, &o).into_iter().enumerate() {
        if n > 1 && var[k] > 0.0 {
            // Floor: 10⁻⁶ of the measured variance (a baseline that fits a
            // channel exactly, e.g. noise-free data).
            w[k] = 1.0 / (e / n as f64).max(1e-6 / var[k]);
        }
    }
    w
}

/// Decorrelation time (s) of the residuals: one independent observation
/// per second of recording. Test programmes sweep a slip region in a few
/// seconds (rig slip-angle sweeps ≈ 4°/s) and residuals, model error and
/// low-passed sensor noise alike, stay correlated over a good part of that
/// (TyreData.csv, 5 Hz: the baseline's residual has an integrated
/// autocorrelation time of 1.1 s in Mz, 2.2 s in Fy); counting samples
/// instead would let a 1 kHz recording claim 20× the evidence of the same
/// test at 50 Hz. (For the 50 Hz rig recordings of the proof this is the
/// n/50 used before.)
pub const DECORRELATION_TIME: f64 = 1.0;

/// One candidate's outcome, by its index in the catalogue.
type Scored = (usize, Result<(Evaluation, Box<dyn Fitted>)>);

/// Fit every candidate on the fit half, score on the other (see the module
/// docs), all on the recording with smoothed inputs ([`smoothed_inputs`]).
/// Two threads. Sorted best first (held-out gain).
///
/// Scores per channel k (Fx, Fy, Mz, those with data): SSE_k of the model
/// and of the baseline, each with its offsets estimated on the fit half and
/// removed. The pooled gain over a half is 1 − exp(Σ n_k·ln(SSE_k/SSE_k,base)
/// / Σ n_k): the log-likelihood ratio of the Gaussian model with one
/// variance per channel, per sample. ΔBIC = n_eff·ln(1 − gain_all) +
/// k·ln(n_eff) over both halves, n_eff = duration / [`DECORRELATION_TIME`]:
/// the recording's seconds counted once for all channels together (Fy and
/// Mz residuals of one sweep are not independent evidence), so a channel's
/// gain enters with its share of the samples. Per channel
/// ([`ChannelScore::delta_bic`]) the same with the channel's own seconds,
/// SSE ratio and the parameters acting on it: the evidence of an effect
/// that lives in one channel (a friction law of the sliding speed in the
/// drive/brake sweeps' Fx), which the pooled figure dilutes by the channels
/// it does not act on. A parameter that cannot move a channel's prediction
/// (PPX1 in Fy) is not part of that channel's model, so it is not charged
/// there; the pooled BIC, which ranks the qualifying candidates, charges
/// every parameter. A candidate that fits some of the baseline's own keys
/// again ([`super::Spec::reference`]) is measured, in every figure above,
/// against the baseline with those keys alone fitted again on the same
/// half ([`Candidate::reference`]), and charged only its own parameters.
pub fn evaluate(
    rec: &Recording,
    baseline: &Tyre,
    opts: &ReplayOptions,
    candidates: &[&dyn Candidate],
) -> Result<Vec<(Evaluation, Box<dyn Fitted>)>> {
    let smooth = smoothed_inputs(rec);
    let rec = &smooth;
    let (fit_mask, test_mask) = split(rec);
    let all = either(&fit_mask, &test_mask);
    // Per channel: (fit, test, all) SSE and counts, offsets from the fit half.
    let score = |sim: &[Forces]| {
        let o = offsets(rec, sim, &fit_mask);
        [&fit_mask, &test_mask, &all].map(|m| channel_sse(rec, sim, m, &o))
    };
    let base = replay(rec, baseline, opts)?.sim;
    let w = fit_weights(rec, &base, &fit_mask);
    let sb = score(&base);
    let t: Vec<f64> = rec.samples.iter().map(|s| s.time).collect();
    let h = median_spacing(&t);
    let h = if h.is_finite() && h > 0.0 { h } else { 0.02 };
    let n_all = all.iter().filter(|x| **x).count() as f64;
    let n_eff = (n_all * h / DECORRELATION_TIME).max(2.0);
    // Pooled gain of half `m` (0 fit, 1 test, 2 all), and the channel gains.
    let pooled = |s: &[[(f64, usize); 3]; 3], sb: &[[(f64, usize); 3]; 3], m: usize| {
        let (mut l, mut n) = (0.0, 0.0);
        for k in 0..3 {
            let ((e, c), (eb, _)) = (s[m][k], sb[m][k]);
            if c > 0 && eb > 0.0 && e > 0.0 {
                l += c as f64 * (e / eb).ln();
                n += c as f64;
            }
        }
        if n > 0.0 {
            1.0 - (l / n).exp()
        } else {
            0.0
        }
    };
    let gain = |b: f64, x: f64| if b > 0.0 { 1.0 - x / b } else { 0.0 };
    let next = std::sync::atomic::AtomicUsize::new(0);
    let run = || -> Vec<Scored> {
        let mut got = Vec::new();
        loop {
            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let Some(c) = candidates.get(i) else {
                break;
            };
            let _t = crate::fit::timing::span(|| format!("candidate {}", c.name()));
            // The candidate's reference: the baseline, or the baseline
            // with the keys the candidate fits again beside its own
            // parameters alone fitted again (`Spec::reference`).
            let reference = c
                .reference(baseline, opts)
                .map(|r| -> Result<_> {
                    let f = r.fit(rec, baseline, opts, &fit_mask, &w)?;
                    let on: [usize; 3] = std::array::from_fn(|j| f.parameters_on(j));
                    Ok((score(&f.predict(rec)?), f.parameters().len(), on))
                })
                .transpose();
            let r = reference.and_then(|reference| {
                let base = sb;
                let (sb, k_ref, on_ref) = reference.unwrap_or((sb, 0, [0; 3]));
                c.fit(rec, baseline, opts, &fit_mask, &w)
                    .and_then(|fitted| {
                        let sim = fitted.predict(rec)?;
                        let s = score(&sim);
                        let k_all = fitted.parameters().len();
                        let k = k_all.saturating_sub(k_ref);
                        let all_gain = pooled(&s, &sb, 2);
                        let channels = (0..3)
                            .filter(|&j| sb[1][j].1 > 0 && sb[1][j].0 > 0.0)
                            .map(|j| ChannelScore {
                                channel: Channel::SCORED[j],
                                n: sb[1][j].1,
                                oos_gain: gain(sb[1][j].0, s[1][j].0),
                                fit_gain: gain(sb[0][j].0, s[0][j].0),
                                delta_bic: {
                                    let n = (s[2][j].1 as f64 * h / DECORRELATION_TIME).max(2.0);
                                    let kj = match fitted.parameters_on(j) {
                                        0 => k,
                                        kj => kj.saturating_sub(on_ref[j]).min(k),
                                    };
                                    n * (s[2][j].0 / sb[2][j].0).max(1e-300).ln()
                                        + kj as f64 * n.ln()
                                },
                                baseline_misfit: None,
                                reference_gain: gain(base[1][j].0, sb[1][j].0),
                                acts: fitted.parameters_on(j) > 0,
                                bic_needed: if c.refits_baseline() {
                                    REFIT_EVIDENCE
                                } else {
                                    0.0
                                },
                            })
                            .collect();
                        Ok((
                            Evaluation {
                                name: c.name().into(),
                                n_params: k,
                                oos_gain: pooled(&s, &sb, 1),
                                fit_gain: pooled(&s, &sb, 0),
                                delta_bic: n_eff * (1.0 - all_gain).max(1e-300).ln()
                                    + k as f64 * n_eff.ln(),
                                channels,
                                parameters: fitted.parameters(),
                                at_bound: fitted.at_bound(),
                                physics: c.physics().into(),
                                describe: c.describe(fitted.as_ref()),
                                reference_gain: pooled(&sb, &base, 1),
                                rank_bic: n_eff * (1.0 - pooled(&s, &base, 2)).max(1e-300).ln()
                                    + k_all as f64 * n_eff.ln(),
                            },
                            fitted,
                        ))
                    })
            });
            got.push((i, r));
        }
        got
    };
    let mut results: Vec<Scored> = std::thread::scope(|s| {
        let h = s.spawn(run);
        let mut mine = run();
        mine.extend(h.join().unwrap_or_default());
        mine
    });
    results.sort_by_key(|(i, _)| *i);
    let mut out = Vec::with_capacity(results.len());
    for (_, r) in results {
        out.push(r?);
    }
    out.sort_by(|a, b| b.0.oos_gain.total_cmp(&a.0.oos_gain));
    Ok(out)
}

/// The samples in either half: every segment of [`split`].
fn either(fit: &[bool], test: &[bool]) -> Vec<bool> {
    fit.iter().zip(test).map(|(a, b)| *a || *b).collect()
}

/// Every segment of `rec` (both halves of [`split`]) as a sample mask.
pub fn every_segment(rec: &Recording) -> Vec<bool> {
    let (fit, test) = split(rec);
    either(&fit, &test)
}

/// The named candidate refitted on every segment (both halves of
/// [`split`]) once the selection is made: the held-out scores of
/// [`evaluate`] choose the model, and its parameters are then estimated on
/// all the data, as the baseline is. The rig's run-to-run scatter varies
/// the forces segment by segment, so an estimate from half of the segments
/// carries that scatter twice as strongly. Same inputs ([`smoothed_inputs`])
/// and channel weights ([`fit_weights`], here over both halves) as the
/// evaluation. Its predictions are in-sample throughout: the report's
/// held-out figures stay those of the half fit.
pub fn refit_on_all(
    rec: &Recording,
    baseline: &Tyre,
    opts: &ReplayOptions,
    candidate: &dyn Candidate,
) -> Result<Box<dyn Fitted>> {
    let smooth = smoothed_inputs(rec);
    let (fit_mask, test_mask) = split(&smooth);
    let all = either(&fit_mask, &test_mask);
    let base = replay(&smooth, baseline, opts)?.sim;
    let w = fit_weights(&smooth, &base, &all);
    candidate.fit(&smooth, baseline, opts, &all, &w)
}

/// Held-out SSE of `sim` over Fx, Fy, Mz, each channel weighted by 1/its
/// measured variance over both halves (halves of [`split`], offsets
/// estimated on the fit half): a fixed yardstick for comparing models with
/// a reference (the proof's share of the gap to the truth). [`evaluate`]
/// scores each channel against the baseline's own error level instead.
pub fn held_out_sse(rec: &Recording, sim: &[Forces]) -> f64 {
    let (fit, test) = split(rec);
    let all = either(&fit, &test);
    let w = inverse_variances(rec, &all);
    weighted_sse(rec, sim, &test, &w, &offsets(rec, sim, &fit))
}
