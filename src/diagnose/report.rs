//! report — the `diagnose` pipeline end to end for one (merged) recording:
//! replay the baseline, locate the residual structure per channel, evaluate
//! the candidates, choose the verdict, explain it in words, score the fit
//! before and after per channel and condition (in-sample and held out), and
//! build `diagnosis.json`. The figures are the `quality` module's, the
//! words the `explain` module's and the judgement of the baseline against
//! the noise floor the `misfit` module's (re-exported here).
//!
//! # Quality figures
//! σ = √(Σ(sim − test)² / Σ test²) and NRMSE = RMS(sim − test) / range(test)
//! ([`crate::fit::metrics`]) of the baseline ("before") and of the verdict's
//! extended model ("after"), per channel (FX, FY, MZ), over all samples and
//! per condition (load, inclination, pressure; and per speed when the
//! recording has more than one), on the segments the candidates were fitted
//! on (`in_sample`) and on those they never saw (`out_of_sample`) — the
//! split of [`super::candidate::split`]. They are `replay`'s residuals less
//! each model's constant channel offset (a sensor zero, estimated on the fit
//! half only, as the candidates' scoring treats it).
//!
//! # Explanation
//! The significant [`locate`] findings of each channel are put in words
//! ("the FY residual changes with the sweep direction (rising − falling
//! +41 N) and follows the force rate"), then the verdict's physics and its
//! fitted parameters in words (`Evaluation::physics`, `Evaluation::describe`
//! of [`crate::diagnose::candidate::Evaluation`]) and the share of the held-out error it removes. For `none` the text
//! says whether the residual showed structure at all and what the best
//! candidate achieved.
//!
//! Must never: name an effect whose held-out improvement is within noise
//! (the selection rule decides), or call a grouping significant that
//! [`locate`] did not.

use super::candidate::param::rerolled;
use super::candidate::{
    all, also_qualifying, channels_in_words, evaluate, evidence, overshadowed_in_words,
    overshadowed_summary, select, why_not, Candidate, ChannelScore, Evidence,
};
use super::locate::{frictional_energy, locate, Finding, LocateOptions, Residuals};
use super::reestimate::{build_extended, FileOf, Refit};
use super::slip_channel;
use crate::data::Recording;
use crate::error::Result;
use crate::mf::{Forces, Tyre};
use crate::residual::{nrmse_per_channel, replay, Channel, ReplayOptions};
use serde::Serialize;
use serde_json::Value;
use std::collections::BTreeMap;
use std::ops::Range;

use super::explain::at_bound_note;
pub use super::explain::{caution, explain, findings_in_words, WORSE};
pub use super::misfit::{
    baseline_fit, excess_removed, misfit_note, BaselineFit, MISFIT_EXPLAINED, MISFIT_RATIO,
};
pub use super::quality::{
    channel_present, channel_series, quality, split, QualityReport, QualityRow,
};

/// Smallest held-out gain that names an effect (the rule: [`super::candidate::select`]).
pub use super::candidate::MIN_GAIN;

/// NRMSE per scored channel of `sim` against the recording over the
/// samples where `mask` is true (`None`: all), keyed "FX", "FY", "MZ"
/// (None where the channel has no data).
pub type NrmseMap = BTreeMap<&'static str, Option<f64>>;

/// Locate findings of one channel.
pub fn locate_channel(
    rec: &Recording,
    sim: &[Forces],
    energy: &[f64],
    channel: Channel,
) -> Vec<Finding> {
    let (meas, simc, slip) = channel_series(rec, sim, channel);
    let r: Vec<f64> = meas.iter().zip(&simc).map(|(m, s)| m - s).collect();
    let d = Residuals {
        r: &r,
        sim: &simc,
        slip: &slip,
        sweep_dir: &rec.sweep_dir,
        t_in_segment: &rec.t_in_segment,
        energy,
        segments: &rec.segments,
        samples: &rec.samples,
    };
    locate(&d, &LocateOptions::default())
}

/// One candidate in `diagnosis.json` ("effects", the verdict first).
#[derive(Clone, Debug, Serialize)]
pub struct EffectReport {
    /// Candidate name as in [`crate::diagnose::candidate::all`] (`none`, `relaxation`, …).
    pub name: String,
    /// Pooled held-out gain ([`Evaluation::oos_gain`](crate::diagnose::candidate::Evaluation::oos_gain)).
    pub score: f64,
    /// Pooled BIC change against the baseline over both halves
    /// (dimensionless; negative = better), see [`crate::diagnose::candidate::evaluate`].
    pub delta_bic: f64,
    /// Parameters fitted (those acting on a channel with data).
    pub n_params: usize,
    /// The evaluation in words: physics, fitted values, gains, why (not) named.
    pub evidence: String,
    /// Per-channel held-out and fit-half gains and BIC changes (channels
    /// with data only).
    pub channels: Vec<ChannelScore>,
    /// Fitted parameters that ended at a bound of their range, in words
    /// ("PPY3 = -3 (its lower bound)"): limits, not estimates.
    pub at_bound: Vec<String>,
    /// Fitted parameters by name (SI; NaN written as null).
    pub parameters: BTreeMap<String, f64>,
    /// NRMSE (RMS(sim − test)/range(test), dimensionless) of the baseline
    /// per channel over all samples.
    pub nrmse_before: NrmseMap,
    /// The same of this candidate's fitted model (the baseline for `none`).
    pub nrmse_after: NrmseMap,
    /// NRMSE of the baseline over the held-out samples only.
    pub nrmse_before_held_out: NrmseMap,
    /// NRMSE of this candidate's fitted model over the held-out samples only.
    pub nrmse_after_held_out: NrmseMap,
}

/// The re-estimation's outcome ([`crate::diagnose::reestimate`]).
#[derive(Clone, Debug, Serialize)]
pub struct BaselineReestimated {
    /// Rounds kept (0: none lowered the error; extended.tir holds the
    /// extension on the unchanged baseline).
    pub rounds: usize,
    /// Relative change of the extended tyre's in-sample weighted error
    /// against the extension on the unchanged baseline (−0.1 = 10 % lower).
    pub error_change: f64,
}

impl BaselineReestimated {
    /// The report entry of a re-estimation's (rounds, plain cost, cost,
    /// error that stopped it) ([`super::reestimate::BuiltExtension`]), and
    /// the explanation's words for it (leading space; empty when no round
    /// was kept and nothing failed).
    pub fn of(r: Option<&(usize, f64, f64, Option<String>)>) -> (Option<Self>, String) {
        let Some((rounds, plain, after, failed)) = r else {
            return (None, String::new());
        };
        let mut w = String::new();
        if let Some(e) = failed {
            w.push_str(&format!(
                " Re-estimating the baseline beneath the extension stopped on an error ({e}); extended.tir holds the best before it."
            ));
        }
        if *rounds > 0 {
            w.push_str(&format!(
                " In extended.tir the baseline's Magic Formula was fitted again beneath the extension ({} round{}), which lowers the in-sample error by a further {:.1} %: the baseline had absorbed part of the effect. The held-out figures above compare the baseline as fitted without it.",
                rounds,
                if *rounds == 1 { "" } else { "s" },
                -100.0 * (after / plain - 1.0)
            ));
        }
        let entry = BaselineReestimated {
            rounds: *rounds,
            error_change: after / plain - 1.0,
        };
        (Some(entry), w)
    }
}

/// `diagnosis.json`, typed.
#[derive(Clone, Debug, Serialize)]
pub struct DiagnosisReport {
    /// The named effect: a candidate's name, `rolling_radius` when named
    /// from the slip channel, or `none`.
    pub verdict: String,
    /// The verdict, its evidence and its caveats in words.
    pub explanation: String,
    /// The channel that carries the verdict's evidence and its grade
    /// ([`crate::diagnose::candidate::evidence`]); absent without a
    /// candidate verdict (`none`, or `rolling_radius` named from the slip
    /// channel, whose evidence is that channel).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict_evidence: Option<Evidence>,
    /// Other candidates that also qualify ([`also_qualifying`]), lowest
    /// BIC first: findings the data support besides the verdict.
    pub also_qualifying: Vec<String>,
    /// Every candidate evaluated, the verdict first.
    pub effects: Vec<EffectReport>,
    /// σ and NRMSE before and after the verdict, per channel and
    /// condition, in sample and held out ([`QualityReport`]).
    pub quality: QualityReport,
    /// Findings per channel key ("FY").
    pub locate: BTreeMap<&'static str, Vec<Finding>>,
    /// Names of every candidate the diagnosis weighs
    /// ([`crate::diagnose::candidate::all`] order, `none` first).
    pub candidates_implemented: Vec<&'static str>,
    /// The baseline against the data's noise floor ([`baseline_fit`]).
    pub baseline_fit: Vec<BaselineFit>,
    /// The parameters written to `extended.tir`: the verdict's candidate
    /// refitted on every segment after the selection
    /// ([`crate::diagnose::candidate::refit_on_all`]); its entry in
    /// `effects` holds the half fit that was scored. Absent without a
    /// candidate verdict.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub extended_parameters: Option<BTreeMap<String, f64>>,
    /// The baseline's MF fitted again beneath the extension for
    /// `extended.tir` ([`crate::diagnose::reestimate`]); absent when it was
    /// not tried (a given `--tir`, a candidate that cannot carry it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline_reestimated: Option<BaselineReestimated>,
    /// The recorded slip ratio against the free-rolling radius
    /// ([`slip_channel::check`]); absent without an SR channel.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slip_channel: Option<slip_channel::SlipChannel>,
    /// Samples in the (merged) recording.
    pub samples: usize,
    /// Test segments recognised in the recording.
    pub segments: usize,
    /// How the baseline was obtained (set by the command).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<String>,
    /// The sensor zeros removed before the comparison (set by the command;
    /// [`super::sensor_zero`]); absent with `--tir` or when none could be
    /// estimated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_zeros: Option<super::sensor_zero::ZeroFinding>,
    /// The plots drawn (set by the command).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Value>,
}

impl DiagnosisReport {
    /// `extended_parameters` as "K = v, …" (`None` without a candidate verdict).
    pub fn extended_parameters_in_words(&self) -> Option<String> {
        self.extended_parameters.as_ref().map(|ps| {
            ps.iter()
                .map(|(k, v)| format!("{k} = {v:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        })
    }

    /// As JSON (serialising plain data cannot fail; `Null` if it ever did).
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }
}

/// The diagnosis: its report, the chosen extended tyre and the series the
/// plots need.
pub struct Diagnosis {
    /// The report ([`DiagnosisReport`]; as JSON: [`Diagnosis::json`]).
    pub report: DiagnosisReport,
    /// The verdict is the slip channel's rolling-radius finding
    /// ([`slip_channel`]), not a force candidate's.
    pub by_slip: bool,
    /// The extended tyre written as `extended.tir` (the baseline for `none`).
    pub extended: Tyre,
    /// The baseline's simulation (ISO-W; N, N·m), one per sample.
    pub baseline_sim: Vec<Forces>,
    /// The simulation of `extended` (what `extended.tir` does), one per sample.
    pub extended_sim: Vec<Forces>,
    /// Findings per channel (FY, FX, MZ where present).
    pub findings: Vec<(Channel, Vec<Finding>)>,
    /// Accumulated frictional energy per sample (J).
    pub energy: Vec<f64>,
}

impl Diagnosis {
    /// The report as JSON (`diagnosis.json` before the command adds the
    /// baseline note and the plots), derived from [`Diagnosis::report`]
    /// each time, so that it cannot fall behind a change of the report.
    pub fn json(&self) -> Value {
        self.report.to_json()
    }
    /// The verdict: a candidate's name or `none` (the explanation then
    /// says why: nothing missing, or the baseline's own misfit).
    pub fn verdict(&self) -> &str {
        &self.report.verdict
    }
    /// The verdict and its evidence in words.
    pub fn explanation(&self) -> &str {
        &self.report.explanation
    }
}

/// Run the diagnosis of `rec` against the baseline `tyre`.
pub fn diagnose(rec: &Recording, tyre: &Tyre, opts: &ReplayOptions) -> Result<Diagnosis> {
    diagnose_with(rec, tyre, opts, None, &mut |_| {})
}

/// [`diagnose`], reporting each step's name to `step` before it runs.
pub fn diagnose_with(
    rec: &Recording,
    tyre: &Tyre,
    opts: &ReplayOptions,
    refit_baseline: Option<Refit>,
    step: &mut dyn FnMut(&str),
) -> Result<Diagnosis> {
    step("replay baseline");
    let base = replay(rec, tyre, opts)?;
    let energy = frictional_energy(rec);
    let channels: Vec<Channel> = [Channel::Fy, Channel::Fx, Channel::Mz]
        .into_iter()
        .filter(|c| channel_present(rec, *c))
        .collect();
    // Guard: an empty analysis must not read as "Nothing is missing".
    if channels.is_empty() || rec.segments.is_empty() {
        return Err(crate::Error::Input(format!(
            "diagnose: {}: {} — the recording cannot be analysed",
            rec.source,
            if channels.is_empty() {
                "no usable Fx, Fy or Mz channel"
            } else {
                "no test segments (no load/slip programme recognised)"
            }
        )));
    }
    step("locate + candidates");
    let owned = all();
    let cands: Vec<&dyn Candidate> = owned.iter().map(|c| c.as_ref()).collect();
    // Locate (permutation tests) on a second thread while the candidates fit.
    let (findings, ev) = std::thread::scope(|s| {
        let h = s.spawn(|| {
            let _t = crate::fit::timing::span(|| "locate (every channel)".into());
            channels
                .iter()
                .map(|&ch| (ch, locate_channel(rec, &base.sim, &energy, ch)))
                .collect::<Vec<_>>()
        });
        let _t = crate::fit::timing::span(|| "candidates (fit on half, scored)".into());
        let ev = evaluate(rec, tyre, opts, &cands);
        drop(_t);
        (h.join(), ev)
    });
    let findings =
        findings.map_err(|_| crate::Error::Other("diagnose: the locate thread failed".into()))?;
    let mut ev = ev?;
    step("report");
    // The baseline against the noise floor, before any verdict: a channel
    // the baseline itself misfits carries a candidate's evidence only when
    // the candidate takes a good part of the misfit away (MISFIT_EXPLAINED).
    let (fit_r, test_r) = split(rec);
    let mask = |rs: &[Range<usize>]| {
        let mut m = vec![false; rec.samples.len()];
        for r in rs {
            m[r.clone()].iter_mut().for_each(|x| *x = true);
        }
        m
    };
    let test_mask = mask(&test_r);
    let fit_mask = mask(&fit_r);
    let base_fit = baseline_fit(rec, &base.sim, &fit_mask, &test_mask);
    // The slip channel against the free-rolling radius: a rolling-radius
    // finding the force residuals cannot make (see [`slip_channel`]). It
    // names the verdict when no force candidate qualifies, and is added to
    // the explanation otherwise. With a radius error, Fx is read at a slip
    // off by a load-dependent K_x·ΔSR of more than `FORCE_SHARE` of Fz
    // (the baseline's horizontal shift takes up only its linear part): no
    // evidence for another effect.
    let mut slip = slip_channel::check(rec, tyre);
    let slip_found = slip.as_ref().is_some_and(|s| s.found);
    for (e, _) in ev.iter_mut() {
        for c in e.channels.iter_mut() {
            let ratio = base_fit
                .iter()
                .find(|f| f.channel == c.channel)
                .map_or(1.0, |f| f.ratio);
            let removed = excess_removed(c.oos_gain, ratio);
            c.baseline_misfit = if ratio > MISFIT_RATIO && removed < MISFIT_EXPLAINED {
                Some(format!(
                    "the baseline's held-out residual there stands at {ratio:.1}× the noise floor, and this candidate removes {:.0} % of what stands above the noise (at least {:.0} % for evidence)",
                    100.0 * removed,
                    100.0 * MISFIT_EXPLAINED
                ))
            } else if slip_found && c.channel == Channel::Fx {
                Some("the recorded slip ratio was computed with a rolling radius that is not the tyre's (the slip-channel check), so Fx is read at the wrong slip".to_string())
            } else {
                None
            };
        }
    }
    let verdict_i = select(&ev);
    let slip_ext = match slip.as_ref().filter(|s| s.found) {
        Some(s) => Some(s.extended(tyre)?),
        None => None,
    };
    if let (Some(s), Some(t)) = (slip.as_mut(), slip_ext.as_ref()) {
        s.set_extended(t);
    }
    let slip_words = slip
        .as_ref()
        .zip(slip_ext.as_ref())
        .map(|(s, t)| s.words(tyre, t));
    let slip_verdict = verdict_i.is_none() && slip_ext.is_some();
    let slip_sim = match (&slip_ext, slip_verdict) {
        (Some(t), true) => Some(replay(&rerolled(rec, tyre, t, opts), t, opts)?.sim),
        _ => None,
    };
    // extended.tir: the verdict refitted on all segments once chosen
    // ([`refit_on_all`]); the held-out figures below stay the half fit's.
    // A refit that fails leaves the half fit in the file, and says so.
    let of = match (&slip_ext, slip_verdict) {
        (Some(t), true) => Some(FileOf::Radius(t)),
        _ => verdict_i
            .and_then(|i| owned.iter().find(|c| c.name() == ev[i].0.name))
            .map(|c| FileOf::Candidate(c.as_ref())),
    };
    let built = of.map(|of| build_extended(rec, tyre, opts, of, refit_baseline, step));
    let (refit, slip_file, reestimated, refit_failed) = match built {
        Some(b) => (b.fitted, b.radius, b.reestimated, b.refit_failed),
        None => (None, None, None, None),
    };
    let verdict = if slip_verdict {
        "rolling_radius".to_string()
    } else {
        verdict_i.map_or("none".to_string(), |i| ev[i].0.name.clone())
    };
    let mut effects = Vec::new();
    let mut order: Vec<usize> = (0..ev.len()).collect();
    order.sort_by_key(|&i| usize::from(ev[i].0.name != verdict));
    let before = nrmse_per_channel(rec, &base.sim, None);
    let before_oos = nrmse_per_channel(rec, &base.sim, Some(&test_mask));
    let mut extended_sim = slip_sim.clone().unwrap_or_else(|| base.sim.clone());
    for i in order {
        let (e, fitted) = &ev[i];
        let by_slip = slip_verdict && e.name == "rolling_radius";
        let sim = if e.name == "none" {
            base.sim.clone()
        } else if let (true, Some(s)) = (by_slip, &slip_sim) {
            s.clone()
        } else {
            fitted.predict(rec)?
        };
        effects.push(EffectReport {
            name: e.name.clone(),
            score: e.oos_gain,
            delta_bic: e.delta_bic,
            n_params: e.n_params,
            evidence: format!(
                "{}{}fitted on one half of the segments, scored on the other: removes {:.1} % of the baseline's held-out squared error (per channel: {}; BIC change {:+.1}){}{}",
                match (&slip_words, by_slip) {
                    (Some(w), true) => format!(
                        "Named from the slip channel, not from the force residuals: {w} The radius keys alone, "
                    ),
                    _ => String::new(),
                },
                if e.name == "none" {
                    String::new()
                } else if e.n_params == 0 {
                    // Nothing was fitted: no values to describe.
                    format!("{}: not fitted; ", e.physics)
                } else {
                    format!("{}: {}; ", e.physics, e.describe)
                },
                100.0 * e.oos_gain,
                channels_in_words(e),
                e.delta_bic,
                if e.name == "none" {
                    String::new()
                } else {
                    match (why_not(e), overshadowed_in_words(&ev, i)) {
                        (Some(w), _) => format!(". Not named: {w}."),
                        (None, Some(w)) => format!(". Qualifies, but is not named: {w}."),
                        (None, None) => ". Qualifies as a verdict.".to_string(),
                    }
                },
                at_bound_note(e)
            ),
            channels: e.channels.clone(),
            at_bound: e.at_bound.clone(),
            parameters: e.parameters.iter().cloned().collect(),
            nrmse_before: before.clone(),
            nrmse_after: nrmse_per_channel(rec, &sim, None),
            nrmse_before_held_out: before_oos.clone(),
            nrmse_after_held_out: nrmse_per_channel(rec, &sim, Some(&test_mask)),
        });
        if Some(i) == verdict_i {
            extended_sim = sim;
        }
    }
    let best_other = ev.iter().find(|(e, _)| e.name != "none").map(|(e, _)| e);
    let alpha = LocateOptions::default().alpha;
    let in_sample = quality(rec, &base.sim, &extended_sim, &fit_r, &fit_r)?;
    let out_of_sample = quality(rec, &base.sim, &extended_sim, &fit_r, &test_r)?;
    let misfit = misfit_note(&base_fit);
    // What the recording cannot tell apart when nothing is named: a recorded
    // pressure that moves with time in the run alone.
    // Or time the data do not cover (a history cannot be followed).
    let unseparable = if verdict_i.is_none() && !slip_verdict {
        let segs: Vec<&crate::data::Segment> = rec.segments.iter().collect();
        let words: Vec<String> = [
            super::factor::drift_with_time(&rec.samples, &segs, |s| s.p)
                .map(|d| super::explain::time_drift_in_words(&d)),
            super::factor::missing_time(&rec.samples)
                .map(|(gap, share)| super::explain::missing_time_in_words(gap, share)),
        ]
        .into_iter()
        .flatten()
        .collect();
        (!words.is_empty()).then(|| words.join(" Also, "))
    } else {
        None
    };
    let mut explanation = explain(
        &findings,
        verdict_i.map(|i| &ev[i].0),
        best_other,
        alpha,
        misfit.is_some() || slip_verdict,
        unseparable.as_deref(),
    );
    // A qualifier another candidate overshadows is not named: say which, and why.
    if let Some(w) = overshadowed_summary(&ev) {
        explanation.push_str(&format!(" {w}"));
    }
    if verdict_i.is_none() && !slip_verdict {
        if let Some(m) = misfit {
            explanation = format!("{m} {explanation}");
        }
    } else {
        let left: Vec<String> = baseline_fit(rec, &extended_sim, &fit_mask, &test_mask)
            .iter()
            .filter(|f| f.ratio > MISFIT_RATIO)
            .map(|f| format!("{} {:.1}×", f.channel.name(), f.ratio))
            .collect();
        if !left.is_empty() {
            explanation.push_str(&format!(
                " With the extension the held-out residual still stands above {MISFIT_RATIO:.0}× the noise floor ({}): the finding explains part of the misfit, the rest is the baseline's own fit or physics outside the candidates.",
                left.join(", ")
            ));
        }
    }
    if let Some(e) = &refit_failed {
        explanation.push_str(&format!(
            " extended.tir holds the half fit scored above: its refit on every segment failed ({e})."
        ));
    }
    let (baseline_reestimated, w) = BaselineReestimated::of(reestimated.as_ref());
    explanation.push_str(&w);
    if let Some(w) = &slip_words {
        explanation = if slip_verdict {
            format!("{w} (The force residuals alone name nothing. {explanation})")
        } else {
            format!("{explanation} Also: {w}")
        };
    }
    // What could not be checked: a radius that is not the tyre's hides in the
    // baseline's horizontal shift of Fx, and only the recorded slip ratio
    // shows it (`slip_channel`).
    if verdict_i.is_none() && slip.is_none() && rec.has("omega") && rec.extra("SR").is_none() {
        explanation.push_str(
            " The recording has no slip ratio channel (SR), so the rolling-radius check (the slip the rig recorded at free rolling against the wheel's own V/Ω) could not run: a rolling radius that is not the tyre's would stay hidden in the baseline's horizontal shift of Fx.",
        );
    }
    // Empty without a verdict: `select` names one whenever any qualifies.
    let also = also_qualifying(&ev, verdict_i);
    if !also.is_empty() {
        let words: Vec<String> = also
            .iter()
            .map(|&i| {
                let e = &ev[i].0;
                format!(
                    "{} ({}; BIC {:+.1})",
                    e.name,
                    channels_in_words(e),
                    e.delta_bic
                )
            })
            .collect();
        explanation.push_str(&format!(
            " Also supported by the data, with a higher BIC: {}. Each explains part of the same residual; the verdict is the one the evidence prefers.",
            words.join("; ")
        ));
    }
    if verdict_i.is_some() {
        if let Some(c) = caution(&out_of_sample) {
            explanation.push(' ');
            explanation.push_str(&c);
        }
    }
    if let Some(w) = super::explain::one_channel_lag(&findings) {
        explanation.push(' ');
        explanation.push_str(&w);
    }
    let locate = findings
        .iter()
        .map(|(ch, f)| (ch.key(), f.clone()))
        .collect();
    let extended = match (&slip_ext, slip_verdict, &refit) {
        (Some(t), true, _) => slip_file.unwrap_or_else(|| t.clone()),
        (_, _, Some(r)) => r.tyre().clone(),
        _ => verdict_i.map_or_else(|| tyre.clone(), |i| ev[i].1.tyre().clone()),
    };
    // The series the plots draw are what extended.tir does.
    if let Some(r) = &refit {
        extended_sim = r.predict(rec)?;
    } else if slip_verdict && baseline_reestimated.as_ref().is_some_and(|r| r.rounds > 0) {
        extended_sim = replay(&rerolled(rec, tyre, &extended, opts), &extended, opts)?.sim;
    }
    let extended_parameters = refit
        .as_ref()
        .map(|r| r.parameters().into_iter().collect::<BTreeMap<_, _>>());
    let report = DiagnosisReport {
        verdict: verdict.clone(),
        explanation,
        verdict_evidence: verdict_i.and_then(|i| evidence(&ev[i].0)),
        also_qualifying: also.iter().map(|&i| ev[i].0.name.clone()).collect(),
        effects,
        quality: QualityReport {
            model_after: verdict,
            split: "candidates fitted on one half of the segments (in_sample), scored on the other (out_of_sample); halves alternate within each (kind, load) group",
            in_sample,
            out_of_sample,
        },
        locate,
        candidates_implemented: owned.iter().map(|c| c.name()).collect(),
        baseline_fit: base_fit,
        extended_parameters,
        baseline_reestimated,
        slip_channel: slip,
        samples: rec.samples.len(),
        segments: rec.segments.len(),
        baseline: None,
        sensor_zeros: None,
        plots: None,
    };
    Ok(Diagnosis {
        report,
        by_slip: slip_verdict,
        extended,
        baseline_sim: base.sim,
        extended_sim,
        findings,
        energy,
    })
}

/// Concatenate recordings (each later one shifted in time behind a gap, so
/// the replay resets between them), extra channels included.
pub fn merge(recs: Vec<Recording>) -> Recording {
    let mut out = Recording::default();
    let mut t_end = f64::NEG_INFINITY;
    // Extra channels (the rig's SR, radii, temperatures) by name, NaN on the
    // recordings that lack one.
    for r in &recs {
        for (n, _) in &r.extra {
            if !out.extra.iter().any(|(m, _)| m == n) {
                out.extra.push((n.clone(), Vec::new()));
            }
        }
    }
    for r in recs {
        for (n, v) in out.extra.iter_mut() {
            match r.extra.iter().find(|(m, _)| m == n) {
                Some((_, w)) if w.len() == r.samples.len() => v.extend_from_slice(w),
                _ => v.extend(std::iter::repeat_n(f64::NAN, r.samples.len())),
            }
        }
        let off = if out.samples.is_empty() {
            0.0
        } else {
            let t0 = r.samples.first().map_or(0.0, |s| s.time);
            t_end + 100.0 - t0
        };
        let base = out.samples.len();
        out.source = if out.source.is_empty() {
            r.source.clone()
        } else {
            format!("{} + {}", out.source, r.source)
        };
        for mut s in r.samples {
            s.time += off;
            t_end = t_end.max(s.time);
            out.samples.push(s);
        }
        for c in r.channels {
            if !out.channels.contains(&c) {
                out.channels.push(c);
            }
        }
        for mut g in r.segments {
            g.start += base;
            g.end += base;
            out.segments.push(g);
        }
        out.sweep_dir.extend(r.sweep_dir);
        out.t_in_segment.extend(r.t_in_segment);
    }
    out
}
