//! candidate — the extensions the diagnosis can name: each a parametrised
//! model with a physical meaning, fitted to a recording on top of a baseline
//! tyre, written into the tyre file (standard keys or a documented section,
//! see [`crate::transient::extension`]) so that the FMU and `replay` simulate
//! exactly what was scored, and scored out of sample with an information
//! criterion so that extra parameters alone never win.
//!
//! # Candidates ([`all`])
//! | name | parameters (tyre file) | fitted how |
//! |------|------------------------|------------|
//! | `none` | – | the baseline |
//! | `relaxation` | LONGITUDINAL_STIFFNESS, LATERAL_STIFFNESS (σ = K/C; LSGKP, LSGAL for MF 5.2/PAC2002) | LM, replayed transient |
//! | `lugre` | `[LUGRE]` SIGMA0X, SIGMA0Y (bristle stiffness), MUS (Stribeck ratio) | LM, replayed transient |
//! | `thermal` | `[THERMAL]` CAPACITY (time constant with COOLING ∝ Fz0, SHARE = 0.5), MU_T0..2; LMUX; LXAL, LYKA as a reference ([`Spec::reference`]) | LM, replayed (tread-temperature state) |
//! | `load_sensitivity` | `[LOAD_SENSITIVITY]` FZ1..3 (knot loads from the fit half), MU_FZ1..3, K_FZ1..3 (natural splines of friction and slip stiffness over the load) | LM on a subsample (static), backward elimination ([`Spec::eliminate`]) |
//! | `pressure` | PPX1, PPX3 (with Fx data), PPY1, PPY3 (with Fy/Mz data), PPZ1 (with Mz data) (MF 6.x only: MF 5.2/PAC2002 have no pressure terms; needs a recorded pressure that varies beyond its noise, [`crate::diagnose::factor`]) | LM, static (no elimination: on the proof's tvd3 pressure recordings it dropped terms worth 7 % of the gap) |
//! | `speed_friction` | `[SPEED_FRICTION]` DMU, VC, VREF (s = g(Vs)/g(σ·VREF), g(v) = 1 − DMU·x/(1 + x), x = v/VC) | LM from two starts, static |
//! | `rolling_radius` | Q_RE0, DREFF, FREFF (Re(Fz)); κ re-derived as (1+κ)·Re/Re_baseline − 1 | LM, static |
//! | `camber` | PDY3, PKY6, PKY7 (PKY3, PHY3 for MF 5.2/PAC2002), PVY3, QHZ3, QDZ8, QDZ9 | LM, static, backward elimination |
//!
//! LM = the crate's one Levenberg–Marquardt ([`crate::fit::lm`], bounded by
//! projection) behind [`crate::fit::Problem`]; the candidate's Jacobian is
//! a forward difference of the replay (the transient models are `f64`
//! code, see [`param`]), ≤ 7 parameters. Each trial replays as little of
//! the recording as the model's memory allows ([`work`]): static
//! candidates (no state) at most [`STATIC_SAMPLES`] fit-half samples, never
//! a transient; relaxation and LuGre the fit half's runs, each from a
//! warm-up of three of the longest lag lengths their ranges allow; thermal
//! the whole recording on a coarser time grid.
//!
//! # Files
//! One file per candidate (its [`Spec`] and its description in words),
//! [`param`] (the parametrised candidate and its fit), [`work`] (what a
//! fit replays at each trial), the statistics
//! ([`statistics`]: split, input smoothing, weights, evaluation) and the
//! verdict rule ([`selection`]).
//!
//! # Scoring ([`evaluate`]) and the verdict ([`select`])
//! * Split ([`split`]): segments are grouped by (kind, load) and alternate
//!   between the fit and the score half within each group in time order,
//!   successive groups starting on opposite halves, so that the factors
//!   nested inside (pressure, inclination, drive/brake slip angle) alternate
//!   too; a level of load, pressure or inclination left without a fit
//!   segment gets one. A condition-level effect (pressure, load) is thus
//!   fitted on every level and scored on the others' combinations, and
//!   time-dependent effects see early and late segments in both halves.
//!   (Plain even/odd parity puts every segment of a level on one side when
//!   the programme's inner loop has an even length.)
//! * Channels Fx, Fy, Mz, each scored against its own error level.
//!   Constant per-channel offsets (sensor zero offsets) are nuisance, not
//!   physics: each model's offsets are estimated on the fit half and removed
//!   on both halves, for the baseline too.
//! * Fitting ([`fit_weights`]): each channel's squared residual weighted by
//!   1/the baseline's mean squared residual in that channel (the Gaussian
//!   likelihood with one variance per channel, at the baseline). Only the
//!   parameters acting on a channel with data are fitted ([`Param::channels`]:
//!   PPX* need Fx), `pressure` and `camber` only when the fit half spans two
//!   levels of inclination ([`Spec::levels`]) or a recorded pressure that varies beyond its noise ([`Spec::varies`]); a fitted
//!   parameter ending at a bound is reported ([`Fitted::at_bound`]).
//! * Gains: per channel, the relative drop of its held-out (and fit-half)
//!   SSE against the baseline's ([`ChannelScore`]); pooled, 1 − the
//!   sample-weighted geometric mean of the channels' SSE ratios (the
//!   per-sample log-likelihood ratio), so a badly fitted channel cannot
//!   dominate a well fitted one. BIC over both halves,
//!   n_eff·ln(SSE ratio) + k·ln(n_eff), n_eff = recorded seconds
//!   ([`DECORRELATION_TIME`]), k = parameters fitted (per channel: those
//!   acting on the channel, [`Fitted::parameters_on`]).
//! * Verdict ([`select`], [`qualifies`]): a candidate qualifies when some
//!   channel's held-out error falls by more than [`MIN_GAIN`] and that
//!   channel's own BIC falls (by [`REFIT_EVIDENCE`] for a candidate made of
//!   keys the baseline fitted, [`Candidate::refits_baseline`]: camber) (an
//!   effect may live in one channel), none rises
//!   by more than [`MAX_LOSS`] (physics that is missing makes no channel
//!   worse; a candidate that trades one channel for another absorbs a
//!   misfit), and the pooled held-out and in-sample gains are positive;
//!   among those the lowest pooled BIC against the baseline itself wins
//!   ([`Evaluation::rank_bic`]), otherwise `none` — unless a
//!   candidate that does not qualify removes more than [`OVERSHADOW`] times
//!   as much of the winner's evidence channel ([`overshadowed`]). The held-out
//!   test keeps over-fitting out, the channel's BIC asks for evidence in
//!   proportion to the parameters and the seconds of data, and the pooled
//!   BIC then prefers the fewer parameters between explanations that
//!   generalise alike.
//!
//! * The file ([`refit_on_all`]): once named, the verdict's candidate is
//!   fitted again on both halves for `extended.tir` (the half fit chose
//!   it; all segments estimate it). The scores stay the half fit's. When
//!   the diagnosis fitted the baseline itself, a candidate that acts
//!   through slips and similarity scales, or through the MF's pressure
//!   terms ([`Candidate::reestimation`]), then has the baseline fitted
//!   again beneath it ([`crate::diagnose::reestimate`]).
//!
//! Must never: let a candidate see the held-out segments' forces while
//! fitting (their inputs may drive a state), or panic on a recording with
//! missing channels.

mod camber;
mod load_sensitivity;
mod lugre;
pub mod param;
mod pressure;
mod relaxation;
mod rolling_radius;
pub mod selection;
mod speed_friction;
pub mod statistics;
mod thermal;
pub mod work;

/// Index of Fx, Fy, Mz in [`crate::residual::Channel::SCORED`] (and in the weights).
pub use crate::residual::{FX, FY, MZ};
pub use param::{NoneCandidate, Param, ParamCandidate, ReferenceOf, Spec, Target, STATIC_SAMPLES};
pub use selection::{
    also_qualifying, channels_in_words, evidence, overshadowed, overshadowed_in_words,
    overshadowed_summary, qualifies, select, why_not, Evidence, EvidenceGrade, MAX_LOSS, MIN_GAIN,
    OVERSHADOW, REFIT_EVIDENCE,
};
pub use statistics::{
    evaluate, every_segment, fit_weights, held_out_sse, refit_on_all, smoothed_inputs, split,
    ChannelScore, Evaluation, DECORRELATION_TIME, SMOOTH_HALF_WIDTH,
};

use crate::data::Recording;
use crate::error::Result;
use crate::mf::{Forces, Tyre};
use crate::residual::ReplayOptions;
use crate::transient::WheelOutput;

/// A fitted extension: its parameters and its predictions.
pub trait Fitted: Send + Sync {
    /// Named physical parameters (SI).
    fn parameters(&self) -> Vec<(String, f64)>;
    /// Simulated forces for every sample of `rec`.
    fn predict(&self, rec: &Recording) -> Result<Vec<Forces>>;
    /// The full step outputs behind [`Fitted::predict`] (the slips the
    /// force model used, the similarity scales), one per sample; None
    /// where the prediction is not a plain replay of [`Fitted::tyre`].
    fn outputs(&self, _rec: &Recording) -> Result<Option<Vec<WheelOutput>>> {
        Ok(None)
    }
    /// The extended tyre to write as `extended.tir`.
    fn tyre(&self) -> &Tyre;
    /// Fitted parameters that ended at a bound of their range, in words
    /// ("PPY3 = -3 (its lower bound)"): the data pushed them beyond what the
    /// candidate allows, so the value is a limit, not an estimate.
    fn at_bound(&self) -> Vec<String> {
        Vec::new()
    }
    /// Parameters the candidate has but the fit held at the file's value
    /// because the fit half's evidence did not pay for them
    /// ([`Spec::eliminate`]).
    fn held(&self) -> Vec<String> {
        Vec::new()
    }
    /// How many of [`Fitted::parameters`] act on channel `j` (index into
    /// [`crate::residual::Channel::SCORED`]): what that channel's own BIC
    /// charges ([`ChannelScore::delta_bic`]). By default all of them.
    fn parameters_on(&self, _j: usize) -> usize {
        self.parameters().len()
    }
}

/// How the baseline's MF can be fitted again beneath a named extension
/// ([`crate::diagnose::reestimate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reestimation {
    /// It cannot: the extension changes what no MF stage fits (the source
    /// of the slip for the rolling radius, LuGre's bristles) or shares keys
    /// with it (camber).
    No,
    /// On the recording seen through the step's slips and similarity
    /// scales: an extension that acts through them alone (load
    /// sensitivity, speed friction, thermal, relaxation).
    ThroughScales,
    /// On the recording at its recorded pressures with the candidate's
    /// pressure terms held: an extension made of the MF's own pressure
    /// terms.
    AtRecordedPressure,
}

/// A candidate extension.
pub trait Candidate: Send + Sync {
    /// Name in the report and the CLI (`relaxation`, `pressure`, …; the
    /// table of the module docs).
    fn name(&self) -> &'static str;
    /// Parameters the candidate has (0 for `none`), before any is held for
    /// lack of data.
    fn n_params(&self) -> usize;
    /// The physics in one line, as a tyre engineer would say it
    /// ("transient slip lag"): used in the explanation of a verdict.
    fn physics(&self) -> &'static str {
        self.name()
    }
    /// Whether the candidate's parameters are keys the baseline's own fit
    /// moved (camber: the MF's inclination terms), so that it adds no
    /// physics the baseline lacks and its gain may come from scoring the
    /// same keys under the diagnosis's objective instead of the baseline
    /// fit's: its evidence channel's BIC must then fall by
    /// [`REFIT_EVIDENCE`] (see `selection`).
    fn refits_baseline(&self) -> bool {
        false
    }
    /// How the baseline can be fitted again beneath the extension
    /// ([`crate::diagnose::reestimate`]).
    fn reestimation(&self) -> Reestimation {
        Reestimation::No
    }
    /// What the candidate is scored against when it fits some of the
    /// baseline's own keys again beside its parameters
    /// ([`Spec::reference`]): the baseline with those keys alone fitted
    /// again on the same half. None: the baseline itself.
    fn reference(&self, _baseline: &Tyre, _opts: &ReplayOptions) -> Option<Box<dyn Candidate>> {
        None
    }
    /// Whether the baseline can be fitted again beneath the extension at all.
    fn reestimable(&self) -> bool {
        self.reestimation() != Reestimation::No
    }
    /// The fitted extension in words with its key parameter(s), e.g.
    /// "a relaxation length of 0.31 m (×1.2 the file's)".
    fn describe(&self, fitted: &dyn Fitted) -> String {
        fitted
            .parameters()
            .iter()
            .map(|(k, v)| format!("{k} = {v:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
    /// Fit on the samples where `mask` is true (the rest is never looked
    /// at), each channel's squared residual weighted by `w` (in
    /// [`crate::residual::Channel::SCORED`] order; see [`fit_weights`]).
    /// A channel of weight 0 carries no data: parameters acting only on it
    /// are not fitted.
    fn fit(
        &self,
        rec: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        mask: &[bool],
        w: &[f64; 3],
    ) -> Result<Box<dyn Fitted>>;
}

/// All three scored channels.
pub const ALL_CHANNELS: &[usize] = &[FX, FY, MZ];

/// Weighted SSE of Fx, Fy, Mz over masked samples (see [`crate::residual::sse`]).
pub use crate::residual::sse;

/// Every candidate the diagnosis weighs, `none` first. The one registry:
/// the report, the CLI and the proof tests all take their list from here.
pub fn all() -> Vec<Box<dyn Candidate>> {
    vec![
        Box::new(NoneCandidate),
        Box::new(relaxation::candidate()),
        Box::new(lugre::candidate()),
        Box::new(thermal::candidate()),
        Box::new(load_sensitivity::candidate()),
        Box::new(pressure::candidate()),
        Box::new(speed_friction::candidate()),
        Box::new(rolling_radius::candidate()),
        Box::new(camber::candidate()),
    ]
}
