//! reestimate — once the diagnosis has named an extension, the baseline's
//! Magic Formula fitted again beneath it, for `extended.tir`.
//!
//! The baseline was fitted to data that contain the missing physics, so its
//! MF parameters absorbed part of it: a slip stiffness that grows with load
//! faster than the MF's form allows ends as a compromise of PKY1, PKY2 and
//! the curvature factors, a friction that fades with temperature as a mean
//! friction level. An extension fitted on top of that baseline can only
//! correct what the compromise left. Alternating the two fits — block
//! coordinate descent on the joint model — lets the MF take back the shape
//! the data show once the extension carries its share:
//!
//! 1. replay the extended tyre; per sample take the slips its force model
//!    used (κ′, α′: lagged for a relaxation finding) and the similarity
//!    scales of the step, s and c ([`WheelOutput::friction_scale`],
//!    [`WheelOutput::stiffness_scale`]): the step's forces are
//!    s·F(c·κ′/s, atan(c·tan α′/s)) (Pacejka, *Tyre and Vehicle Dynamics*,
//!    3rd ed., §4.3.2), Mz also × m, the load curve's moment scale;
//! 2. the recording seen through them — κ ← c·κ′/s, tan α ← c·tan α′/s,
//!    Fx, Fy, Mx ← ·/s, Mz ← Mz/(s·m) — is what the plain MF must fit; fit
//!    the baseline again on it from the previous one
//!    ([`super::baseline::fit_baseline_from`], through the caller's
//!    [`RefitBaseline`]);
//! 3. refit the extension on the new baseline ([`refit_on_all`]).
//!
//! Up to [`ROUNDS`] rounds (fewer once a round gains less than
//! [`MIN_ROUND_GAIN`], or the rounds left are expected to in all:
//! [`rest_is_small`]); a round is kept only when it lowers the extended
//! tyre's in-sample error (every segment, each channel weighted by 1/the
//! baseline's mean squared residual as in the candidates' fits, constant
//! offsets removed) and no channel's own error rises by more than the
//! selection allows a named effect ([`MAX_LOSS`]), so the file is never
//! worse than the plain refit on the data it was fitted to.
//!
//! So for candidates that act through slips and similarity scales alone
//! ([`Reestimation::ThroughScales`]: load sensitivity, speed friction,
//! thermal, relaxation). A pressure law is made of the MF's own pressure
//! terms ([`Reestimation::AtRecordedPressure`]): there step 2 is the
//! recording itself at its recorded pressures, fitted from the extended
//! tyre with the candidate's pressure terms held (the baseline pooled every
//! sample at the median pressure, so its curves are a compromise over the
//! pressures the data swept). A rolling-radius finding of the slip channel
//! changes the slip every sample sees ([`beneath_rolling_radius`]): the
//! stages are fitted once more on the recording with that slip. Only when
//! the diagnosis fitted its baseline itself: a baseline given with `--tir`
//! is the user's tyre and stays.
//!
//! [`build_extended`] is the one recipe of the file: the chosen verdict
//! refitted on every segment, then the rounds above (or the rolling-radius
//! refit), for the diagnosis and for the file built again on the recording
//! as measured when the comparison removed sensor zeros
//! ([`super::sensor_zero::extended_as_measured`]).
//!
//! Must never: change the verdict, the held-out scores or `baseline.tir`
//! (they are the baseline's, fitted without any extension), or return a
//! file whose in-sample error is higher than the plain refit's.

use super::baseline::Pressures;
use super::candidate::param::rerolled;
use super::candidate::{
    every_segment, fit_weights, refit_on_all, Candidate, Fitted, Reestimation, MAX_LOSS,
};
use crate::data::Recording;
use crate::error::Result;
use crate::fit::mf_stages::StageKind;
use crate::mf::{Forces, Tyre};
use crate::residual::{channel_sse, offsets, replay, weighted_sse, ReplayOptions};
use crate::tir::TyreParams;
use crate::transient::WheelOutput;

/// Most alternations of the MF fit and the extension's refit. Dev set
/// (in-sample error per round): r12 −5.2, −3.3, −0.8, −0.006 %; r14 −10.6,
/// −0.3, −0.06 %; r19 −0.4, −0.1, −0.1 %: the third round takes nearly all
/// that is left.
pub const ROUNDS: usize = 3;

/// A round that lowers the in-sample error by less than this fraction ends
/// the alternation (it is still kept), and so does a round after which the
/// rounds left are expected to gain less than it in all ([`rest_is_small`]).
pub const MIN_ROUND_GAIN: f64 = 1e-3;

/// Whether the rounds after one that gained `gain` (a fraction of the
/// in-sample error), following one that gained `prev`, are expected to gain
/// less than [`MIN_ROUND_GAIN`] in all. Block coordinate descent converges
/// linearly near its minimum: each round's gain is about ρ times the last
/// one's, ρ = gain/prev < 1, so the rounds left gain about
/// gain·ρ/(1 − ρ) (the geometric series' tail). Dev set (in-sample error per
/// round, see [`ROUNDS`]): r12 −5.2, −3.3 % gives ρ = 0.63 and a tail of
/// 5.7 %: go on; r14 (2 Dec 2026) −13.6, −0.15 % gives ρ = 0.011 and a tail
/// of 0.002 %: stop. The third round r14 used to run cost 21 s of a 95 s
/// diagnosis on a slow VM; with the rule no dev-set gap figure moved by more
/// than 0.1 point (r04 1.6 → 1.7 %, r11 58.2 → 58.1 %). Without a previous
/// gain (`prev` NaN) or with ρ ≥ 1, nothing is inferred.
pub fn rest_is_small(prev: f64, gain: f64) -> bool {
    let rho = gain / prev;
    rho.is_finite() && rho > 0.0 && rho < 1.0 && gain * rho / (1.0 - rho) < MIN_ROUND_GAIN
}

/// The stages fitted again: the pure-slip curves and the aligning moment,
/// which the named physics reshapes, and the combined-slip weights, which
/// the pure curves' new shape moves. The combined stage fits the side force
/// of the drive/brake runs too (the purest evidence of the κ-induced side
/// force S_Vyκ, Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., eqs.
/// 4.E67–4.E68), which the diagnosis blanks ([`Refit::fitted_on`] keeps
/// it): refitted without it, S_Vyκ moved far — RVY1 0.0016 → 0.033 on dev
/// r17, 0.046 → 0 on r12 — and that side force came out 1.2–2× the
/// baseline's error. With it, dev set (28 Nov 2026): gap recovered r19
/// 44 → 48 %, r14 52 → 56 %, r05 34 → 38 %, no file's channel above 1.005×
/// the baseline's error on the last 30 % of its rows.
pub const REESTIMATED_STAGES: [StageKind; 4] = [
    StageKind::PureFx,
    StageKind::PureFy,
    StageKind::Mz,
    StageKind::Combined,
];

/// Fits the baseline again: (the recording as the plain MF must see it,
/// the tyre to start from, the pressures the fit sees) → the new baseline.
pub type RefitBaseline<'a> =
    dyn Fn(&Recording, &TyreParams, Pressures) -> Result<TyreParams> + Sync + 'a;

/// What the re-estimation needs of the diagnosis's own baseline fit.
#[derive(Clone, Copy)]
pub struct Refit<'a> {
    /// The fit ([`refit_fitted_baseline`]).
    pub fit: &'a RefitBaseline<'a>,
    /// The recording the baseline was fitted on: the diagnosed one before
    /// [`super::baseline::drop_unfitted`] blanked the channels it does not
    /// diagnose (same samples). The combined-slip stage fits the side
    /// force of the drive/brake runs, which the diagnosis leaves out.
    pub fitted_on: &'a Recording,
}

/// The [`RefitBaseline`] of a baseline the diagnosis fitted itself
/// ([`super::baseline::fit_baseline`]): the same fit from the previous
/// baseline, [`REESTIMATED_STAGES`] only.
pub fn refit_fitted_baseline(
    threads: usize,
) -> impl Fn(&Recording, &TyreParams, Pressures) -> Result<TyreParams> + Sync {
    move |r, start, pressures| {
        super::baseline::fit_baseline_from(
            std::slice::from_ref(r),
            Some(start.clone()),
            Some(&REESTIMATED_STAGES),
            pressures,
            threads,
            None,
        )
        .map(|b| b.tyre)
    }
}

/// What [`reestimate`] returns.
pub struct Reestimated {
    /// The extension on the re-estimated baseline (or the plain refit when
    /// no round lowered the error).
    pub fitted: Box<dyn Fitted>,
    /// Rounds kept (0: the plain refit).
    pub rounds: usize,
    /// In-sample weighted error of the plain refit (dimensionless: each
    /// channel's SSE over the baseline's mean square; NaN when the replay
    /// behind it failed).
    pub cost_plain: f64,
    /// The same of the result.
    pub cost: f64,
    /// Why the rounds stopped early on an error (the result is the best
    /// before it).
    pub failed: Option<String>,
}

/// The recording as the plain MF must see it for `tyre`'s extension to
/// reproduce `rec` (step 2 of the module docs), from the step outputs `out`
/// of a replay of `tyre`. A sample whose step failed keeps its inputs and
/// loses its forces (NaN: no stage fits it).
pub fn through_extension(rec: &Recording, tyre: &Tyre, out: &[WheelOutput]) -> Recording {
    let mut r = rec.clone();
    let ext = tyre.extension();
    for (s, o) in r.samples.iter_mut().zip(out) {
        let (sc, cc) = (o.friction_scale, o.stiffness_scale);
        let ok = o.fx.is_finite()
            && sc.is_finite()
            && sc > 0.0
            && cc.is_finite()
            && cc > 0.0
            && o.kappa.is_finite()
            && o.alpha.is_finite();
        if !ok {
            s.fx = f64::NAN;
            s.fy = f64::NAN;
            s.mx = f64::NAN;
            s.mz = f64::NAN;
            continue;
        }
        let m = ext.map_or(1.0, |e| e.moment_scale(s.fz));
        let k = cc / sc;
        // The step reports κ in the MF's convention (the sign of Vx).
        let dir = if s.vx < 0.0 { -1.0 } else { 1.0 };
        s.kappa = dir * o.kappa * k;
        s.alpha = (o.alpha.tan() * k).atan();
        s.fx /= sc;
        s.fy /= sc;
        s.mx /= sc;
        s.mz /= sc * m;
    }
    r
}

/// In-sample error of `sim` on every segment of `rec`: (the sum with
/// channel weights `w`, each channel's own SSE), constant offsets removed.
fn cost(rec: &Recording, sim: &[Forces], all: &[bool], w: &[f64; 3]) -> (f64, [f64; 3]) {
    let o = offsets(rec, sim, all);
    let per = channel_sse(rec, sim, all, &o).map(|(e, _)| e);
    (weighted_sse(rec, sim, all, w, &o), per)
}

/// Whether a re-estimated file with in-sample error `(c, per channel)` is
/// kept against the best so far (`best`) and the plain refit's channels
/// (`plain`): the error falls and no channel's rises beyond what the
/// selection allows a named effect ([`MAX_LOSS`]).
fn kept((c, per): (f64, &[f64; 3]), best: f64, plain: &[f64; 3]) -> bool {
    let worse = per
        .iter()
        .zip(plain)
        .any(|(a, b)| a.is_nan() || *a > (1.0 + MAX_LOSS) * b);
    c.is_finite() && c < best && !worse
}

/// Alternate the baseline's MF fit and the extension's refit (see the
/// module docs), starting from `plain`, the extension refitted on
/// `baseline` ([`refit_on_all`]). Never fails: a step that fails ends the
/// rounds, keeps the best so far and says why ([`Reestimated::failed`]).
pub fn reestimate(
    rec: &Recording,
    baseline: &Tyre,
    opts: &ReplayOptions,
    candidate: &dyn Candidate,
    plain: Box<dyn Fitted>,
    refit: Refit,
) -> Reestimated {
    let mut best = Reestimated {
        fitted: plain,
        rounds: 0,
        cost_plain: f64::NAN,
        cost: f64::NAN,
        failed: None,
    };
    if candidate.reestimable() {
        if let Err(e) = rounds(rec, baseline, opts, candidate, refit, &mut best) {
            best.failed = Some(e.to_string());
        }
    }
    best
}

/// The rounds of [`reestimate`], improving `best` in place.
fn rounds(
    rec: &Recording,
    baseline: &Tyre,
    opts: &ReplayOptions,
    candidate: &dyn Candidate,
    refit: Refit,
    best: &mut Reestimated,
) -> Result<()> {
    let all = every_segment(rec);
    let w = fit_weights(rec, &replay(rec, baseline, opts)?.sim, &all);
    let (cost_plain, per_plain) = cost(rec, &best.fitted.predict(rec)?, &all, &w);
    best.cost_plain = cost_plain;
    best.cost = cost_plain;
    if !cost_plain.is_finite() {
        return Ok(());
    }
    let mut mf = baseline.params().clone();
    let mut prev_gain = f64::NAN;
    for round in 1..=ROUNDS {
        let _t = crate::fit::timing::span(|| format!("re-estimation round {round}"));
        mf = match candidate.reestimation() {
            Reestimation::No => break,
            Reestimation::ThroughScales => {
                let Some(out) = best.fitted.outputs(rec)? else {
                    break;
                };
                let seen = through_extension(refit.fitted_on, best.fitted.tyre(), &out);
                (refit.fit)(&seen, &mf, Pressures::Pooled)?
            }
            Reestimation::AtRecordedPressure => (refit.fit)(
                refit.fitted_on,
                best.fitted.tyre().params(),
                Pressures::Recorded,
            )?,
        };
        let next = refit_on_all(rec, &Tyre::new(mf.clone())?, opts, candidate)?;
        let (c, per) = cost(rec, &next.predict(rec)?, &all, &w);
        if !kept((c, &per), best.cost, &per_plain) {
            crate::fit::timing::note(|| {
                format!(
                    "  round {round} not kept (in-sample error {c:.6e} against {:.6e})",
                    best.cost
                )
            });
            break;
        }
        let gain = 1.0 - c / best.cost;
        crate::fit::timing::note(|| {
            format!(
                "  round {round} kept: in-sample error -{:.3} %",
                100.0 * gain
            )
        });
        best.fitted = next;
        best.rounds = round;
        best.cost = c;
        if gain < MIN_ROUND_GAIN || rest_is_small(prev_gain, gain) {
            break;
        }
        prev_gain = gain;
    }
    Ok(())
}

/// What [`beneath_rolling_radius`] returns: the tyre for `extended.tir`
/// and the same account as [`Reestimated`].
pub struct RadiusReestimated {
    /// The tyre for `extended.tir`: the finding `ext`, or the MF re-estimated
    /// beneath its radius keys when the round was kept.
    pub tyre: Tyre,
    /// Rounds kept (0: the finding on the unchanged baseline).
    pub rounds: usize,
    /// In-sample weighted error of the finding on the unchanged baseline
    /// (dimensionless, as [`Reestimated::cost_plain`]; NaN when its replay failed).
    pub cost_plain: f64,
    /// The same of the result.
    pub cost: f64,
    /// Why the rounds stopped early on an error (the result is the best before it).
    pub failed: Option<String>,
}

/// The MF fitted again beneath a rolling-radius finding `ext` (the
/// baseline with the tyre's own Re(Fz) and Fx's horizontal shift
/// re-centred, [`super::slip_channel`]). The baseline's stages were fitted
/// on the recording's slip, computed through another radius; the finding
/// changes the slip every sample sees (κ′ = (1 + κ)·Re_ext/Re_base − 1,
/// `rerolled`), and the [`REESTIMATED_STAGES`] are fitted again on the
/// recording (as fitted, [`Refit::fitted_on`]) with that κ′ from `ext`,
/// whose radius keys the fit keeps
/// ([`super::baseline::fit_baseline_from`] from a given start runs no
/// geometry step). One round: there is no
/// extension parameter to alternate with. Kept under the guards of
/// [`reestimate`] (in-sample error on the recording as the finding sees it
/// falls, no channel's rises by more than [`MAX_LOSS`]); otherwise `ext`.
/// Never fails.
pub fn beneath_rolling_radius(
    rec: &Recording,
    baseline: &Tyre,
    ext: &Tyre,
    opts: &ReplayOptions,
    refit: Refit,
) -> RadiusReestimated {
    let mut out = RadiusReestimated {
        tyre: ext.clone(),
        rounds: 0,
        cost_plain: f64::NAN,
        cost: f64::NAN,
        failed: None,
    };
    let mut once = || -> Result<()> {
        let seen = rerolled(rec, baseline, ext, opts);
        let all = every_segment(rec);
        let w = fit_weights(rec, &replay(rec, baseline, opts)?.sim, &all);
        let (c0, per0) = cost(&seen, &replay(&seen, ext, opts)?.sim, &all, &w);
        out.cost_plain = c0;
        out.cost = c0;
        if !c0.is_finite() {
            return Ok(());
        }
        let fit_on = rerolled(refit.fitted_on, baseline, ext, opts);
        let t = Tyre::new((refit.fit)(&fit_on, ext.params(), Pressures::Pooled)?)?;
        let (c, per) = cost(&seen, &replay(&seen, &t, opts)?.sim, &all, &w);
        if kept((c, &per), c0, &per0) {
            out.tyre = t;
            out.rounds = 1;
            out.cost = c;
        }
        Ok(())
    };
    if let Err(e) = once() {
        out.failed = Some(e.to_string());
    }
    out
}

/// What `extended.tir` is built on once the verdict is chosen.
#[derive(Clone, Copy)]
pub enum FileOf<'a> {
    /// A force candidate, refitted on every segment ([`refit_on_all`]).
    Candidate(&'a dyn Candidate),
    /// A rolling-radius finding of the slip channel: the baseline with the
    /// tyre's own Re(Fz) ([`super::slip_channel::SlipChannel::extended`]).
    Radius(&'a Tyre),
}

/// The extended tyre of [`build_extended`].
pub struct BuiltExtension {
    /// A candidate verdict: the extension refitted on every segment (on the
    /// re-estimated baseline where that lowered the error); `None` when the
    /// refit failed ([`Self::refit_failed`]).
    pub fitted: Option<Box<dyn Fitted>>,
    /// A slip-channel radius finding with the MF fitted again beneath it
    /// (`None` without a [`Refit`]: the finding's tyre itself is the file).
    pub radius: Option<Tyre>,
    /// The re-estimation's (rounds, plain cost, cost, error that stopped it).
    pub reestimated: Option<(usize, f64, f64, Option<String>)>,
    /// Why the candidate's refit on every segment failed.
    pub refit_failed: Option<String>,
}

impl BuiltExtension {
    /// The tyre for `extended.tir` (`None` when the candidate's refit failed).
    pub fn tyre(&self) -> Option<&Tyre> {
        self.fitted
            .as_ref()
            .map(|f| f.tyre())
            .or(self.radius.as_ref())
    }
}

/// `extended.tir`'s tyre for a chosen verdict `of` on `rec` against the
/// baseline `tyre`: the extension refitted on every segment
/// ([`refit_on_all`]), and — when the diagnosis fitted the baseline itself
/// (`refit`) — the baseline's MF fitted again beneath it
/// (this module). One recipe for the diagnosis and for
/// a file built on another baseline (the command's sensor zeros:
/// [`super::sensor_zero`]). `step` hears "re-estimate baseline" before that
/// part runs.
pub fn build_extended(
    rec: &Recording,
    tyre: &Tyre,
    opts: &ReplayOptions,
    of: FileOf,
    refit: Option<Refit>,
    step: &mut dyn FnMut(&str),
) -> BuiltExtension {
    let mut b = BuiltExtension {
        fitted: None,
        radius: None,
        reestimated: None,
        refit_failed: None,
    };
    match of {
        FileOf::Candidate(c) => {
            let t_refit = crate::fit::timing::span(|| format!("refit {} on all", c.name()));
            let plain = refit_on_all(rec, tyre, opts, c);
            drop(t_refit);
            let plain = match plain {
                Ok(p) => p,
                Err(e) => {
                    b.refit_failed = Some(e.to_string());
                    return b;
                }
            };
            // The baseline fitted again beneath the extension when the
            // diagnosis fitted it.
            b.fitted = Some(match refit.filter(|_| c.reestimable()) {
                Some(f) => {
                    step("re-estimate baseline");
                    let _t =
                        crate::fit::timing::span(|| format!("re-estimate beneath {}", c.name()));
                    let r = reestimate(rec, tyre, opts, c, plain, f);
                    b.reestimated = Some((r.rounds, r.cost_plain, r.cost, r.failed));
                    r.fitted
                }
                None => plain,
            });
        }
        // A rolling-radius finding: the MF fitted again beneath the tyre's
        // own Re(Fz) ([`beneath_rolling_radius`]).
        FileOf::Radius(t) => {
            if let Some(f) = refit {
                step("re-estimate baseline");
                let r = beneath_rolling_radius(rec, tyre, t, opts, f);
                b.reestimated = Some((r.rounds, r.cost_plain, r.cost, r.failed));
                b.radius = Some(r.tyre);
            }
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Sample;
    use crate::mf::UseMode;
    use crate::transient::{InputMode, TransientConfig, TransientKind, TransientModel};

    /// Step 2 inverts the similarity method: the plain MF at the samples
    /// seen through a load curve gives the extended tyre's forces divided
    /// by s (Fx, Fy) — checked on a tyre whose load curve raises friction
    /// 10 % and stiffness 20 % at the high load, at a combined-slip point.
    #[test]
    fn the_transformed_samples_make_the_plain_mf_reproduce_the_extension() {
        let plain = Tyre::builtin();
        let mut p = plain.params().clone();
        let s = p.extra_section(crate::transient::extension::LOAD_SECTION);
        for (k, v) in [
            ("FZ1", 2000.0),
            ("FZ2", 6000.0),
            ("MU_FZ1", 0.0),
            ("MU_FZ2", 0.1),
            ("K_FZ1", 0.0),
            ("K_FZ2", 0.2),
        ] {
            s.set(k, v);
        }
        let ext = Tyre::new(p).unwrap();
        let sample = Sample {
            time: 0.0,
            vx: 20.0,
            omega: f64::NAN,
            fz: 6000.0,
            kappa: 0.03,
            alpha: 0.05,
            gamma: 0.0,
            phit: 0.0,
            p: f64::NAN,
            fx: 0.0,
            fy: 0.0,
            mx: 0.0,
            my: 0.0,
            mz: 0.0,
        };
        let mut model = TransientModel::new(TransientConfig {
            kind: TransientKind::Steady,
            input_mode: InputMode::Slips,
            use_mode: UseMode::default(),
        });
        let inp = crate::residual::wheel_input(&ext, &sample, None).unwrap();
        let o = model.step(&ext, &inp, 0.01).unwrap();
        assert!(
            (o.friction_scale - 1.1).abs() < 1e-12,
            "s = {}",
            o.friction_scale
        );
        assert!(
            (o.stiffness_scale - 1.2).abs() < 1e-12,
            "c = {}",
            o.stiffness_scale
        );
        // The "measurement" is the extended tyre's own output.
        let rec = Recording {
            samples: vec![Sample {
                fx: o.fx,
                fy: o.fy,
                mz: o.mz,
                ..sample
            }],
            ..Default::default()
        };
        let seen = through_extension(&rec, &ext, &[o]);
        let t = &seen.samples[0];
        let inp = crate::residual::wheel_input(&plain, t, None).unwrap();
        let q = TransientModel::new(TransientConfig {
            kind: TransientKind::Steady,
            input_mode: InputMode::Slips,
            use_mode: UseMode::default(),
        })
        .step(&plain, &inp, 0.01)
        .unwrap();
        for (a, b) in [(q.fx, t.fx), (q.fy, t.fy), (q.mz, t.mz)] {
            assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "{a} vs {b}");
        }
    }

    /// The tail estimate stops a converging alternation and only it: a
    /// sharp fall of the gain (10.6 % then 0.3 %, r14's rounds) ends it, a
    /// slow one (5.2 % then 3.3 %, r12's) goes on, and neither a first
    /// round (no previous gain) nor a growing gain infers anything.
    #[test]
    fn the_rounds_stop_when_the_geometric_tail_is_below_the_minimum_gain() {
        assert!(rest_is_small(0.106, 0.003));
        assert!(!rest_is_small(0.052, 0.033));
        assert!(!rest_is_small(f64::NAN, 0.05));
        assert!(!rest_is_small(0.01, 0.02));
        // The tail is gain·ρ/(1 − ρ): 0.02·0.5/0.5 = 0.01 against 1e-3.
        assert!(!rest_is_small(0.04, 0.02));
        // A gain above the minimum whose tail is below it: 0.002·0.25.
        assert!(rest_is_small(0.01, 0.002));
    }
}
