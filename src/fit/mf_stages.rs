//! mf_stages — the Magic Formula as fitting problems: one [`MfStage`] per
//! channel and group of `.tir` parameters (pure Fy, pure Fx, Mz, combined
//! slip, Mx, My), with exact Jacobians: closed forms in `f64` for pure Fx
//! and pure Fy ([`super::grad_pure`], when every parameter of the stage is a
//! pure-slip coefficient of its channel — the default tables are), else
//! forward-mode automatic differentiation: the stage's free parameters are
//! seeded as `num-dual`
//! dual numbers, sixteen at a time (per lane the cheapest width of
//! `DualSVec64` for these equations: 8 lanes ≈ 0.6 µs, 16 ≈ 0.9 µs, 32 ≈
//! 6 µs per pure-Fy sample on the project machine), and only the fitted
//! channel is evaluated ([`super::channels`], the same operations as
//! [`crate::mf::Model::solve`]).
//!
//! Stage contents follow the usual industrial order (Pacejka, *Tyre and
//! Vehicle Dynamics*, 3rd ed., §4.3.2 and Table 4.2): pure slip Fx
//! (eqs. 4.E9–4.E18), pure slip Fy (4.E19–4.E30), aligning moment
//! (4.E31–4.E49), then the combined-slip weighting functions (4.E50–4.E67),
//! then the overturning and rolling-resistance moments where the data carry
//! them (Mx: Besselink's MF 6.1 draft eq. 49; My: paper eq. A48).
//! Scaling factors (λ) are never fitted. A large stage first converges on a
//! subsample ([`fit_stage`], [`COARSE_SAMPLES`]).
//!
//! Must never: fit a scaling factor, move a camber (pressure) term when the
//! fitted data hold one inclination (pressure) only — those are held and
//! reported —, approximate a derivative by finite differences, or allocate
//! per sample.

use super::channels;
use super::grad_pure;
use super::problem::{par_rows, Param, Problem, RowJacobian, Stack};
use super::solve::{fit_global, FitOptions, FitOutcome, ProgressFn};
use super::validity::{Grid, Validity};
use crate::data::{Recording, Sample, SegmentKind};
use crate::mf::{Conditions, Form, MfInput, Model, UseMode};
use crate::tir::keys::key_index;
use crate::tir::MfParams;
use nalgebra::{Const, DMatrixViewMut, U1};
use num_dual::{Derivative, DualSVec64};
use std::ops::Range;

/// A channel the Magic Formula predicts (the residual stage's one typed channel).
pub use crate::residual::Channel;

/// Which fit stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageKind {
    PureFx,
    PureFy,
    Mz,
    Combined,
    /// Overturning moment (QSX*) over the pure lateral segments.
    Mx,
    /// Rolling resistance moment (QSY*) over the pure longitudinal segments.
    My,
}

impl StageKind {
    /// Every stage, in the order a staged fit runs them.
    pub const ALL: [StageKind; 6] = [
        StageKind::PureFx,
        StageKind::PureFy,
        StageKind::Mz,
        StageKind::Combined,
        StageKind::Mx,
        StageKind::My,
    ];

    /// Parse a `--only` word (`fx`, `fy`, `mz`, `combined`).
    pub fn parse(s: &str) -> Option<StageKind> {
        match s.trim().to_ascii_lowercase().as_str() {
            "fx" => Some(StageKind::PureFx),
            "fy" => Some(StageKind::PureFy),
            "mz" => Some(StageKind::Mz),
            "combined" => Some(StageKind::Combined),
            "mx" => Some(StageKind::Mx),
            "my" => Some(StageKind::My),
            _ => None,
        }
    }
    /// Stage name in reports.
    pub fn name(self) -> &'static str {
        match self {
            StageKind::PureFx => "pure Fx",
            StageKind::PureFy => "pure Fy",
            StageKind::Mz => "Mz",
            StageKind::Combined => "combined",
            StageKind::Mx => "Mx",
            StageKind::My => "My",
        }
    }
    /// The segments this stage fits, and the channels.
    pub fn segments_and_channels(self) -> (SegmentKind, &'static [Channel]) {
        match self {
            StageKind::PureFx => (SegmentKind::PureLongitudinal, &[Channel::Fx]),
            StageKind::PureFy => (SegmentKind::PureLateral, &[Channel::Fy]),
            StageKind::Mz => (SegmentKind::PureLateral, &[Channel::Mz]),
            // Mz where recorded (see [`StageKind::optional`]): its combined
            // terms (SSZ*) act only with Fx ≠ 0, and Gyκ, Gxα shape it too.
            StageKind::Combined => (
                SegmentKind::Combined,
                &[Channel::Fx, Channel::Fy, Channel::Mz],
            ),
            StageKind::Mx => (SegmentKind::PureLateral, &[Channel::Mx]),
            StageKind::My => (SegmentKind::PureLongitudinal, &[Channel::My]),
        }
    }
    /// Whether the stage runs without `channel` (fitting the others).
    pub fn optional(self, channel: Channel) -> bool {
        self == StageKind::Combined && channel == Channel::Mz
    }
    /// The stage's parameters: (key, lower, upper, depends on camber, depends on pressure).
    pub fn table(self) -> &'static [(&'static str, f64, f64, bool, bool)] {
        match self {
            StageKind::PureFy => FY,
            StageKind::PureFx => FX,
            StageKind::Mz => MZ,
            StageKind::Combined => COMBINED,
            StageKind::Mx => MX,
            StageKind::My => MY,
        }
    }
}

// Bounds: physically meaningful signs where the ISO-W convention fixes them
// (PKY1 < 0, PKX1 > 0, peaks and shape factors positive, curvature E ≤ 1),
// otherwise wide boxes that only keep the swarm and LM out of overflow.
const C: bool = true; // depends on camber
const P: bool = true; // depends on pressure
#[rustfmt::skip]
const FY: &[(&str, f64, f64, bool, bool)] = &[
    ("pcy1", 0.8, 3.0, false, false), ("pdy1", 0.1, 5.0, false, false),
    ("pdy2", -2.0, 2.0, false, false), ("pky1", -300.0, -0.1, false, false),
    ("pky2", 0.05, 20.0, false, false), ("pky4", 1.01, 5.0, false, false),
    ("pey1", -20.0, 1.0, false, false), ("pey2", -20.0, 20.0, false, false),
    ("pey3", -10.0, 10.0, false, false), ("phy1", -0.1, 0.1, false, false),
    ("phy2", -0.1, 0.1, false, false), ("pvy1", -0.5, 0.5, false, false),
    ("pvy2", -0.5, 0.5, false, false),
    ("pdy3", -50.0, 50.0, C, false), ("pey4", -50.0, 50.0, C, false),
    ("pey5", -500.0, 500.0, C, false), ("pky3", -5.0, 5.0, C, false),
    ("pky5", -500.0, 500.0, C, false), ("pky6", -20.0, 20.0, C, false),
    ("pky7", -20.0, 20.0, C, false), ("pvy3", -5.0, 5.0, C, false),
    ("pvy4", -5.0, 5.0, C, false),
    ("ppy1", -10.0, 10.0, false, P), ("ppy2", -10.0, 10.0, false, P),
    ("ppy3", -10.0, 10.0, false, P), ("ppy4", -10.0, 10.0, false, P),
    ("ppy5", -10.0, 10.0, C, P),
];
// PKX2's box holds MFeval's FSAE default tyre (PKX2 = −80; with ±50 the
// diagnosis's baseline of a control recording of it misfit Fx and Mz by
// 2.9–4× the noise floor, `tests/diagnose_tyres.rs`).
#[rustfmt::skip]
const FX: &[(&str, f64, f64, bool, bool)] = &[
    ("pcx1", 0.8, 3.0, false, false), ("pdx1", 0.1, 5.0, false, false),
    ("pdx2", -2.0, 2.0, false, false), ("pkx1", 0.1, 300.0, false, false),
    ("pkx2", -200.0, 200.0, false, false), ("pkx3", -5.0, 5.0, false, false),
    ("pex1", -20.0, 1.0, false, false), ("pex2", -20.0, 20.0, false, false),
    ("pex3", -20.0, 20.0, false, false), ("pex4", -0.99, 0.99, false, false),
    ("phx1", -0.05, 0.05, false, false), ("phx2", -0.05, 0.05, false, false),
    ("pvx1", -0.5, 0.5, false, false), ("pvx2", -0.5, 0.5, false, false),
    ("pdx3", -50.0, 50.0, C, false),
    ("ppx1", -10.0, 10.0, false, P), ("ppx2", -10.0, 10.0, false, P),
    ("ppx3", -10.0, 10.0, false, P), ("ppx4", -10.0, 10.0, false, P),
];
#[rustfmt::skip]
const MZ: &[(&str, f64, f64, bool, bool)] = &[
    ("qbz1", 0.1, 100.0, false, false), ("qbz2", -50.0, 50.0, false, false),
    ("qbz3", -50.0, 50.0, false, false), ("qbz9", -100.0, 100.0, false, false),
    ("qbz10", -10.0, 10.0, false, false), ("qcz1", 0.3, 3.0, false, false),
    ("qdz1", -1.0, 1.0, false, false), ("qdz2", -1.0, 1.0, false, false),
    ("qdz6", -1.0, 1.0, false, false), ("qdz7", -1.0, 1.0, false, false),
    ("qez1", -50.0, 1.0, false, false), ("qez2", -50.0, 50.0, false, false),
    ("qez3", -50.0, 50.0, false, false), ("qez4", -10.0, 10.0, false, false),
    ("qhz1", -0.1, 0.1, false, false), ("qhz2", -0.1, 0.1, false, false),
    ("qbz5", -50.0, 50.0, C, false), ("qbz6", -50.0, 50.0, C, false),
    ("qdz3", -50.0, 50.0, C, false), ("qdz4", -50.0, 50.0, C, false),
    ("qdz8", -50.0, 50.0, C, false), ("qdz9", -50.0, 50.0, C, false),
    ("qdz10", -50.0, 50.0, C, false), ("qdz11", -50.0, 50.0, C, false),
    ("qez5", -50.0, 50.0, C, false), ("qhz3", -5.0, 5.0, C, false),
    ("qhz4", -5.0, 5.0, C, false),
    ("ppz1", -10.0, 10.0, false, P), ("ppz2", -10.0, 10.0, C, P),
];
#[rustfmt::skip]
const COMBINED: &[(&str, f64, f64, bool, bool)] = &[
    ("rbx1", 0.0, 200.0, false, false), ("rbx2", -200.0, 200.0, false, false),
    ("rcx1", 0.3, 1.0, false, false), ("rex1", -20.0, 1.0, false, false),
    ("rex2", -20.0, 20.0, false, false), ("rhx1", -0.1, 0.1, false, false),
    ("rby1", 0.0, 200.0, false, false), ("rby2", -200.0, 200.0, false, false),
    ("rby3", -1.0, 1.0, false, false), ("rcy1", 0.3, 1.0, false, false),
    ("rey1", -20.0, 1.0, false, false), ("rey2", -20.0, 20.0, false, false),
    ("rhy1", -0.1, 0.1, false, false), ("rhy2", -0.1, 0.1, false, false),
    ("rvy1", -1.0, 1.0, false, false), ("rvy2", -1.0, 1.0, false, false),
    ("rvy4", -200.0, 200.0, false, false), ("rvy5", 0.0, 10.0, false, false),
    ("rvy6", -200.0, 200.0, false, false),
    // Mz's combined-slip moment arm of Fx (4.E76), fitted only here: on
    // pure lateral data Fx ≈ 0 and they are not identified.
    ("ssz1", -0.5, 0.5, false, false), ("ssz2", -0.5, 0.5, false, false),
    ("rbx3", -500.0, 500.0, C, false), ("rby4", -500.0, 500.0, C, false),
    ("rvy3", -50.0, 50.0, C, false),
    ("ssz3", -5.0, 5.0, C, false), ("ssz4", -5.0, 5.0, C, false),
];

// Mx: Besselink's MF 6.1 draft eq. (49) as evaluated in `Model::mx`; My:
// paper eq. A48 (MF 6.x) / the MF-Tyre 5.2 manual form. Speed terms of My
// (QSY3, QSY4) are listed after QSY1: at one rig speed they are collinear
// with it and held.
#[rustfmt::skip]
const MX: &[(&str, f64, f64, bool, bool)] = &[
    ("qsx1", -0.2, 0.2, false, false), ("qsx3", -2.0, 2.0, false, false),
    ("qsx13", -2.0, 2.0, false, false), ("qsx4", -20.0, 20.0, false, false),
    ("qsx5", -100.0, 100.0, false, false), ("qsx6", -100.0, 100.0, false, false),
    ("qsx8", -100.0, 100.0, false, false), ("qsx9", -100.0, 100.0, false, false),
    ("qsx2", -20.0, 20.0, C, false), ("qsx7", -100.0, 100.0, C, false),
    ("qsx10", -100.0, 100.0, C, false), ("qsx11", -100.0, 100.0, C, false),
    ("qsx12", -100.0, 100.0, C, false), ("qsx14", -20.0, 20.0, C, false),
    ("ppmx1", -10.0, 10.0, C, P),
];
#[rustfmt::skip]
const MY: &[(&str, f64, f64, bool, bool)] = &[
    ("qsy1", -0.2, 0.2, false, false), ("qsy2", -1.0, 1.0, false, false),
    ("qsy3", -0.2, 0.2, false, false), ("qsy4", -0.2, 0.2, false, false),
    ("qsy7", -2.0, 3.0, false, false),
    ("qsy5", -5.0, 5.0, C, false), ("qsy6", -5.0, 5.0, C, false),
    ("qsy8", -3.0, 3.0, false, P),
];

/// Spread of the fitted data below which camber (pressure) terms are held:
/// 0.5° (5 kPa), well below any test plan's steps.
pub const CAMBER_SPREAD: f64 = 0.5 * std::f64::consts::PI / 180.0;
pub const PRESSURE_SPREAD: f64 = 5000.0;

/// Conditioned inputs and measured values of the samples one stage fits.
#[derive(Clone, Debug, Default)]
pub struct StageData {
    pub conds: Vec<Conditions>,
    /// Measured channel per sample, one vector per channel of the stage.
    pub meas: Vec<Vec<f64>>,
    /// Spread (max − min) of inclination and pressure over the samples.
    pub gamma_spread: f64,
    pub p_spread: f64,
    /// The range the MF's validity conditions must hold on
    /// ([`super::validity`]); `None`: no validity rows.
    pub grid: Option<Grid>,
}

impl StageData {
    /// Append the samples of `other` (same channels); spreads widen to
    /// cover both.
    pub fn append(&mut self, other: StageData) {
        self.conds.extend(other.conds);
        for (m, o) in self.meas.iter_mut().zip(other.meas) {
            m.extend(o);
        }
        self.gamma_spread = self.gamma_spread.max(other.gamma_spread);
        self.p_spread = self.p_spread.max(other.p_spread);
    }
    /// Every `k`-th sample (spreads kept: they decide which terms are held).
    pub fn every(&self, k: usize) -> StageData {
        let k = k.max(1);
        StageData {
            conds: self.conds.iter().step_by(k).copied().collect(),
            meas: self
                .meas
                .iter()
                .map(|m| m.iter().step_by(k).copied().collect())
                .collect(),
            gamma_spread: self.gamma_spread,
            p_spread: self.p_spread,
            grid: self.grid.clone(),
        }
    }
}

/// Size of the subsample a large stage first converges on
/// ([`crate::fit::FitOptions::coarse_first`]): stages with more than twice
/// this many samples use every k-th sample with k = m / `COARSE_SAMPLES`.
/// 10 000 samples determine ≈ 30 parameters to well within the sampling
/// error of the full data's solution, so the full-data polish that follows
/// takes two or three iterations.
pub const COARSE_SAMPLES: usize = 10_000;

/// Size of the subsample the starts of a multi-start stage race on
/// (`best_start`; stages with more than twice this many samples use every
/// k-th sample with k = m / `RACE_SAMPLES`). The race only decides which
/// basin the winner comes from — it is judged on the full data and then
/// converged on the [`COARSE_SAMPLES`] subsample and the full data — so it
/// needs the curve shapes, not the last digit: 3 000 samples are still
/// ≈ 100 per parameter of the largest stage (combined, ≈ 30), and every
/// sweep of a 100 Hz recording keeps a point each ≈ 0.1 s. On the dev set's
/// 84 000-line recordings the two Mz starts took 5 of a fit's 14 s
/// racing on 11 500 samples. Only stages evaluated through num-dual race
/// on it (Mz, combined, Mx, My); the closed-form pure-slip stages race on
/// the coarse subsample (on dev-set r03, whose pure-Fy valley of collinear
/// PKY2/PKY4/PKY5 makes the end point depend on the path, the small race
/// had moved held-out pure Fy 0.91 → 0.96× the answer's baseline).
pub const RACE_SAMPLES: usize = 3_000;

/// Fit one Magic Formula stage: the `channels` of `data` (channel k ↔
/// `data.meas[k]`; several channels are stacked with weights 1/mean(y²), so
/// newtons and newton-metres compare) over `params`, from `base`, on
/// `threads` threads; a stage with more than 2·[`COARSE_SAMPLES`] samples
/// first converges on a subsample unless `opts.coarse_first` is off.
#[allow(clippy::too_many_arguments)]
pub fn fit_stage(
    form: Form,
    base: &MfParams<f64>,
    params: &[Param],
    data: &StageData,
    channels: &[Channel],
    threads: usize,
    opts: &FitOptions,
    name: &str,
    progress: Option<&mut ProgressFn>,
) -> crate::Result<FitOutcome> {
    fit_stage_from(
        form,
        base,
        params,
        data,
        channels,
        threads,
        opts,
        name,
        progress,
        &[],
    )
}

/// [`fit_stage`] from the parameters' start and the `extra_starts` (θ
/// vectors over `params`): the candidate with the least full-data cost after
/// converging on the subsample is polished (`best_start`).
#[allow(clippy::too_many_arguments)]
pub fn fit_stage_from(
    form: Form,
    base: &MfParams<f64>,
    params: &[Param],
    data: &StageData,
    channels: &[Channel],
    threads: usize,
    opts: &FitOptions,
    name: &str,
    progress: Option<&mut ProgressFn>,
    extra_starts: &[Vec<f64>],
) -> crate::Result<FitOutcome> {
    let m = data.conds.len();
    let t_build = super::timing::span(|| format!("  {name}: build ({m} samples)"));
    let coarse =
        (opts.coarse_first && m > 2 * COARSE_SAMPLES).then(|| data.every(m / COARSE_SAMPLES));
    let weights: Vec<f64> = data
        .meas
        .iter()
        .map(|y| {
            let ms = y.iter().map(|v| v * v).sum::<f64>() / y.len().max(1) as f64;
            if channels.len() > 1 && ms > 0.0 {
                1.0 / ms
            } else {
                1.0
            }
        })
        .collect();
    fn parts_of<'d>(
        form: Form,
        base: &MfParams<f64>,
        params: &[Param],
        d: &'d StageData,
        channels: &[Channel],
        weights: &[f64],
        threads: usize,
    ) -> crate::Result<Vec<MfStage<'d>>> {
        channels
            .iter()
            .enumerate()
            .map(|(k, &c)| {
                Ok(MfStage::new(form, base, params.to_vec(), d, k, c)?
                    .with_weight(weights[k])
                    .with_threads(threads))
            })
            .collect()
    }
    let parts = parts_of(form, base, params, data, channels, &weights, threads)?;
    let coarse_parts = match &coarse {
        Some(d) => parts_of(form, base, params, d, channels, &weights, threads)?,
        None => Vec::new(),
    };
    // Stages with closed-form Jacobians (pure Fx, pure Fy) race on the
    // coarse subsample: there the race costs little (≈ 0.1–0.4 s), and the
    // smaller subsample would trade start choice for nothing worth having.
    let dual = parts.iter().any(|p| p.analytic.is_none());
    let race = (opts.coarse_first && !extra_starts.is_empty() && m > 2 * RACE_SAMPLES && dual)
        .then(|| data.every(m / RACE_SAMPLES));
    // The same for the quick full-data polish (`FitOptions::quick_polish`).
    let mut opts = opts.clone();
    opts.quick_polish |= dual;
    let opts = &opts;
    let race_parts = match &race {
        Some(d) => parts_of(form, base, params, d, channels, &weights, threads)?,
        None => Vec::new(),
    };
    // The validity rows, scaled to the weighted energy of the data they join.
    let validity = |d: &StageData| -> crate::Result<Option<Validity>> {
        let Some(grid) = &d.grid else { return Ok(None) };
        let energy: f64 = d
            .meas
            .iter()
            .zip(&weights)
            .map(|(y, w)| w * y.iter().map(|v| v * v).sum::<f64>())
            .sum();
        Ok(Some(Validity::new(form, base, params, grid, energy)?))
    };
    let valid = validity(data)?;
    let coarse_valid = match &coarse {
        Some(d) => validity(d)?,
        None => None,
    };
    let race_valid = match &race {
        Some(d) => validity(d)?,
        None => None,
    };
    // `soft` scales the validity rows' weight (the penalty continuation).
    fn stacked<'p>(
        parts: &'p [MfStage<'_>],
        valid: &'p Option<Validity>,
        soft: f64,
    ) -> crate::Result<Option<Stack<'p>>> {
        if parts.is_empty() || (parts.len() == 1 && valid.is_none()) {
            return Ok(None);
        }
        let mut v: Vec<(&dyn Problem, f64)> =
            parts.iter().map(|p| (p as &dyn Problem, 1.0)).collect();
        if let Some(val) = valid {
            v.push((val as &dyn Problem, soft));
        }
        Ok(Some(Stack::new(v)?))
    }
    let stack = stacked(&parts, &valid, 1.0)?;
    let coarse_stack = stacked(&coarse_parts, &coarse_valid, 1.0)?;
    let race_stack = stacked(&race_parts, &race_valid, 1.0)?;
    let problem: &dyn Problem = match &stack {
        Some(s) => s,
        None => &parts[0],
    };
    fn one_of<'p>(
        stack: &'p Option<Stack<'_>>,
        parts: &'p [MfStage<'_>],
    ) -> Option<&'p dyn Problem> {
        match (stack, parts.first()) {
            (Some(s), _) => Some(s),
            (None, Some(p)) => Some(p),
            (None, None) => None,
        }
    }
    let coarse_problem = one_of(&coarse_stack, &coarse_parts);
    let race_problem = one_of(&race_stack, &race_parts);
    // The penalty continuation's ladder on the level the starts race on.
    let (on_parts, on_valid) = if race.is_some() {
        (&race_parts, &race_valid)
    } else if coarse.is_some() {
        (&coarse_parts, &coarse_valid)
    } else {
        (&parts, &valid)
    };
    let bound = !extra_starts.is_empty() && on_valid.as_ref().is_some_and(|v| v.n_residuals() > 0);
    let ladder: Vec<Stack> = if bound {
        CONTINUATION
            .iter()
            .filter_map(|&f| stacked(on_parts, on_valid, f).transpose())
            .collect::<crate::Result<_>>()?
    } else {
        Vec::new()
    };
    drop(t_build);
    let mut start = None;
    if !extra_starts.is_empty() {
        let _t =
            super::timing::span(|| format!("  {name}: best_start ({})", extra_starts.len() + 1));
        start = Some(best_start(
            problem,
            race_problem.or(coarse_problem),
            extra_starts,
            &ladder,
            opts,
            name,
        )?);
    }
    fit_global(
        problem,
        coarse_problem,
        start.as_deref(),
        None,
        opts,
        name,
        progress,
    )
}

/// Most LM iterations per round of one start in `best_start`: the starts
/// race, and the winner is polished to convergence afterwards, so the limit
/// decides only which start wins when one of them crawls: a start still
/// descending after 50 steps on the subsample is then judged where it
/// stands (rig recording of `tyrekit bench diagnose`, combined stage: the
/// own start took 200 iterations, 40 s, to reach a cost of 90.6; the
/// neutral start 82.7 in 22).
pub const START_ITERATIONS: usize = 50;

/// The penalty continuation (a homotopy on the validity rows' weight):
/// factors on the weight of [`Validity`]'s rows, in the order they are
/// solved, before the full weight (1). A minimum of the fit that sits on a
/// validity bound (E = 1 at some load) is where the hinge penalty stops LM:
/// a step along the bound leaves it on one side and is rejected on the
/// other. Solved first with the bound softened (violations cost 10⁴ and
/// 10² times less), the fit moves towards the unconstrained minimum and
/// comes back to the bound where the data put it, which may lie in another
/// basin (Nocedal & Wright, *Numerical Optimization*, 2nd ed., §17.1, the
/// quadratic penalty method with an increasing weight). TyreData's pure Fy
/// (28 Nov 2026): from the race's winner (σ_Fy 4.47 %, Ey = 1 at the top
/// load) to σ_Fy 4.13 %, the best of a 62-start global search with the
/// bounds imposed exactly (SLSQP), with Ey falling with load instead.
pub const CONTINUATION: [f64; 2] = [1e-4, 1e-2];

/// Several starts (issue #14 item 3): the problem's own and `extra`, each
/// converged on the subsample `coarse` (to 1e-6; the [`RACE_SAMPLES`] or
/// the [`COARSE_SAMPLES`] subsample when the stage is large, the problem
/// itself when it is not), judged by the full problem's cost — with a
/// subsample that is the error on the (k − 1)/k samples the candidate was
/// not fitted on, a held-out figure. Then, when the stage has validity
/// rows, the best is carried through the penalty continuation (`ladder`:
/// the subsample's problem with the rows' weight at each factor of
/// [`CONTINUATION`], then at full weight) and replaced by the result when
/// that costs less by more than one part in 10⁶ (a minimum off the bounds
/// comes back to itself). Returns the best converged point.
fn best_start(
    problem: &dyn Problem,
    coarse: Option<&dyn Problem>,
    extra: &[Vec<f64>],
    ladder: &[Stack],
    opts: &FitOptions,
    name: &str,
) -> crate::Result<Vec<f64>> {
    let own: Vec<f64> = problem.params().iter().map(|p| p.start).collect();
    let mut loose = opts.clone();
    loose.lm.ftol = loose.lm.ftol.max(1e-6);
    loose.lm.xtol = loose.lm.xtol.max(1e-6);
    loose.lm.gtol = loose.lm.gtol.max(1e-6);
    loose.lm.max_iter = loose.lm.max_iter.min(START_ITERATIONS);
    loose.coarse_first = false;
    let on = coarse.unwrap_or(problem);
    let mut r = vec![0.0; problem.n_residuals()];
    let mut best: Option<(f64, Vec<f64>)> = None;
    for s in std::iter::once(&own).chain(extra) {
        // A start the model cannot evaluate is skipped.
        let Ok(o) = fit_global(on, None, Some(s), None, &loose, name, None) else {
            continue;
        };
        problem.residuals(&o.theta, &mut r);
        let c = opts.lm.loss.cost(&r, problem.weights());
        if c.is_finite() && best.as_ref().is_none_or(|b| c < b.0) {
            best = Some((c, o.theta));
        }
    }
    if let (Some((c0, theta0)), false) = (&best, ladder.is_empty()) {
        let mut cont = opts.clone();
        cont.coarse_first = false;
        let mut theta = theta0.clone();
        let mut ok = true;
        for step in ladder
            .iter()
            .map(|p| p as &dyn Problem)
            .chain(std::iter::once(on))
        {
            match fit_global(step, None, Some(&theta), None, &cont, name, None) {
                Ok(o) => theta = o.theta,
                Err(_) => {
                    ok = false;
                    break;
                }
            }
        }
        if ok {
            problem.residuals(&theta, &mut r);
            let c = opts.lm.loss.cost(&r, problem.weights());
            if c.is_finite() && c < c0 * (1.0 - 1e-6) {
                best = Some((c, theta));
            }
        }
    }
    Ok(best.map_or(own, |b| b.1))
}

/// The neutral start of a stage's free parameters: the shape, shift,
/// curvature and camber terms at 0, only the primary factors (C, D, K and
/// their load terms, Bt, Ct, Dt of the trail, the combined weights' B and C)
/// kept — a second start far from a poor minimum the first may sit in
/// (a curvature factor driven to a bound, a trail shape fitted by camber
/// terms). Fixed parameters keep their values.
pub fn neutral_start(kind: StageKind, params: &[Param]) -> Vec<f64> {
    const KEEP: &[&str] = &[
        "pcy1", "pdy1", "pdy2", "pky1", "pky2", "pky4", "pcx1", "pdx1", "pdx2", "pkx1", "pkx2",
        "qbz1", "qcz1", "qdz1", "qdz2", "rbx1", "rbx2", "rcx1", "rby1", "rby2", "rcy1",
    ];
    let _ = kind;
    params
        .iter()
        .map(|p| {
            if !p.free || KEEP.contains(&p.name.as_str()) {
                p.start
            } else {
                p.clamp(0.0)
            }
        })
        .collect()
}

/// A use mode with no range limits, no α*, no turn slip (211): what the fit
/// used before it evaluated the way the FMU does; kept for comparisons.
pub const FIT_MODE: UseMode = UseMode {
    limits: false,
    alpha_star: false,
    turn_slip: false,
};

/// The use mode the fit evaluates in: the FMU's default, 111 (range limits
/// on — `fit_mf` widens the file's ranges to the data first —, no α*, no
/// turn slip), so every figure the fit reports is what the written file
/// gives where it is used; [`super::validity`] keeps the caps of 1xx from
/// acting, so 211 agrees on the data range.
pub const USE_MODE: UseMode = UseMode {
    limits: true,
    alpha_star: false,
    turn_slip: false,
};

/// The conditioned inputs of a sample in [`USE_MODE`] (pressure NaN → the
/// file's INFLPRES).
pub fn conditions_of(p: &MfParams<f64>, s: &Sample) -> Conditions {
    let inp = MfInput {
        fz: s.fz,
        kappa: s.kappa,
        alpha: s.alpha,
        gamma: s.gamma,
        phit: 0.0,
        vx: s.vx,
        p: s.p,
        omega: 0.0,
    };
    Conditions::new(p, &inp, USE_MODE).0
}

/// Gather the samples of `kind` segments inside `train` (None: everything)
/// of every recording where all `channels` are finite and Fz > 0.
pub fn gather(
    p: &MfParams<f64>,
    recs: &[Recording],
    train: Option<&[Vec<Range<usize>>]>,
    kind: SegmentKind,
    channels: &[Channel],
) -> StageData {
    let mut d = StageData {
        meas: vec![Vec::new(); channels.len()],
        ..Default::default()
    };
    let (mut gammas, mut pressures) = (Vec::new(), Vec::new());
    for (r, rec) in recs.iter().enumerate() {
        let keep = |i: usize| train.is_none_or(|t| t[r].iter().any(|rg| rg.contains(&i)));
        for seg in rec.segments.iter().filter(|s| s.kind == kind) {
            for i in seg.start..seg.end.min(rec.samples.len()) {
                let s = &rec.samples[i];
                let ok = keep(i)
                    && s.fz > 0.0
                    && s.fz.is_finite()
                    && [s.vx, s.kappa, s.alpha, s.gamma]
                        .iter()
                        .all(|v| v.is_finite())
                    && channels.iter().all(|c| c.measured(s).is_finite());
                if !ok {
                    continue;
                }
                d.conds.push(conditions_of(p, s));
                for (k, c) in channels.iter().enumerate() {
                    d.meas[k].push(c.measured(s));
                }
                gammas.push(s.gamma);
                if s.p.is_finite() && s.p > 0.0 {
                    pressures.push(s.p);
                }
            }
        }
    }
    d.gamma_spread = robust_spread(&mut gammas);
    d.p_spread = robust_spread(&mut pressures);
    d
}

/// Share of samples left out at each end of [`robust_spread`].
const SPREAD_TAIL: f64 = 0.01;

/// The spread of `v` between its 1st and 99th percentiles (0 when empty):
/// the conditions a stage's data cover, not a few stray samples. On a rig
/// control of MFeval's FSAE tyre the upright drive/brake segments (0 ±
/// 0.04°) held samples up to 1.0° where a block's inclination changed:
/// max − min passed [`CAMBER_SPREAD`] and freed camber terms the data
/// cannot determine (PDX3 at its bound −50, standard error 10⁴). A
/// condition held by at least 1 % of the samples still counts.
fn robust_spread(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let lo = crate::stats::quantile_in_place(v, SPREAD_TAIL);
    let hi = crate::stats::quantile_in_place(v, 1.0 - SPREAD_TAIL);
    (hi - lo).max(0.0)
}

/// One channel of a Magic Formula stage as a least-squares [`Problem`]:
/// residual = model(θ, sample) − measured. Pure Fx and pure Fy stages whose
/// every parameter is a pure-slip coefficient of the channel use the closed
/// forms of [`super::grad_pure`] (value and gradient in `f64`); every other
/// stage, or one built [`MfStage::with_analytic`]`(false)`, uses num-dual.
pub struct MfStage<'a> {
    form: Form,
    base: MfParams<f64>,
    params: Vec<Param>,
    /// Key index (in [`MfParams::as_slice`] order) of every θ entry.
    keys: Vec<usize>,
    conds: &'a [Conditions],
    meas: &'a [f64],
    channel: Channel,
    weights: Option<Vec<f64>>,
    /// The closed-form path, when it applies and is on.
    analytic: Option<Analytic>,
    /// Mx (My) stages whose every parameter is an Mx (My) coefficient: the
    /// combined-slip Fy (Fx) of every sample, which θ cannot move
    /// ([`channels::eval_given`]).
    given: Option<Vec<f64>>,
    /// Threads for evaluation (results do not depend on it).
    pub threads: usize,
}

/// What the closed-form path needs besides θ: the local gradient index
/// ([`grad_pure::local_index`]) of every θ entry and the combined-slip
/// factors of every sample (constant: the table holds no combined-slip
/// coefficient).
struct Analytic {
    local: Vec<usize>,
    factors: Vec<grad_pure::Weights>,
}

/// The parameter table of a stage, starting from `base`: camber terms held
/// when `hold_camber`, pressure terms when `hold_pressure`; the start value
/// is clamped into the bounds (widening them if the start lies outside, so a
/// start tyre is never changed without a fit).
pub fn stage_params(
    kind: StageKind,
    base: &MfParams<f64>,
    hold_camber: bool,
    hold_pressure: bool,
) -> Vec<Param> {
    kind.table()
        .iter()
        .filter_map(|&(name, lo, hi, cam, pre)| {
            let v = base.get(name)?;
            let mut p = Param::new(name, v, lo.min(v), hi.max(v));
            if (cam && hold_camber) || (pre && hold_pressure) {
                p = p.fixed();
            }
            Some(p)
        })
        .collect()
}

impl<'a> MfStage<'a> {
    /// A stage over `channel` of `data` (channel number `k` of the data).
    pub fn new(
        form: Form,
        base: &MfParams<f64>,
        params: Vec<Param>,
        data: &'a StageData,
        k: usize,
        channel: Channel,
    ) -> crate::Result<MfStage<'a>> {
        let keys = params
            .iter()
            .map(|p| {
                key_index(&p.name).ok_or_else(|| {
                    crate::Error::Input(format!("fit: '{}' is not a .tir key", p.name))
                })
            })
            .collect::<crate::Result<Vec<_>>>()?;
        let meas = data.meas.get(k).ok_or_else(|| {
            crate::Error::Input(format!("fit: the stage data have no channel {k}"))
        })?;
        // The force an Mx (My) stage's moment needs, once: its table moves
        // no force coefficient (checked by name, so a custom table that
        // does falls back to evaluating the force per pass).
        let force = match channel {
            Channel::Mx => Some((MX, Channel::Fy)),
            Channel::My => Some((MY, Channel::Fx)),
            _ => None,
        };
        let given = force
            .filter(|(table, _)| params.iter().all(|p| table.iter().any(|t| t.0 == p.name)))
            .map(|(_, f)| {
                let model = Model::new(base.clone(), form);
                data.conds
                    .iter()
                    .map(|c| channels::eval(&model, c, f))
                    .collect()
            });
        let stage = MfStage {
            form,
            base: base.clone(),
            params,
            keys,
            conds: &data.conds,
            meas,
            channel,
            weights: None,
            analytic: None,
            given,
            threads: 1,
        };
        Ok(stage.with_analytic(true))
    }

    /// Use the closed-form gradients of [`super::grad_pure`] where they apply
    /// (`true`, the default), or num-dual for every stage (`false`, the
    /// reference the closed forms are tested against).
    pub fn with_analytic(mut self, on: bool) -> Self {
        let local: Option<Vec<usize>> = self
            .params
            .iter()
            .map(|p| grad_pure::local_index(self.channel, &p.name))
            .collect();
        self.analytic = match local {
            Some(local) if on => {
                let model = Model::new(self.base.clone(), self.form);
                let factors = self
                    .conds
                    .iter()
                    .map(|c| grad_pure::weights(&model, c, self.channel))
                    .collect();
                Some(Analytic { local, factors })
            }
            _ => None,
        };
        self
    }

    /// Whether the closed-form gradient path is in use.
    pub fn is_analytic(&self) -> bool {
        self.analytic.is_some()
    }

    /// Weight every residual by `w` (1/σ² of the channel when stacking).
    pub fn with_weight(mut self, w: f64) -> Self {
        self.weights = (w != 1.0).then(|| vec![w; self.meas.len()]);
        self
    }

    /// Evaluate on `threads` threads.
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads.max(1);
        self
    }

    /// The base parameters with θ written in.
    pub fn params_at(&self, theta: &[f64]) -> MfParams<f64> {
        params_with(&self.base, &self.keys, theta)
    }

    /// The channel simulated at every stage sample.
    pub fn simulate(&self, theta: &[f64]) -> Vec<f64> {
        let model = Model::new(self.params_at(theta), self.form);
        self.conds
            .iter()
            .map(|c| self.channel.of(&model.solve(c)))
            .collect()
    }

    /// The dual-number model of one Jacobian pass: the columns `chunk` (at
    /// most `N`) seeded as the lanes of an `N`-lane dual number.
    fn dual_model<const N: usize>(
        &self,
        p: &MfParams<f64>,
        chunk: &[usize],
    ) -> Model<DualSVec64<N>> {
        let mut lane_of = [usize::MAX; N];
        for (l, &c) in chunk.iter().enumerate() {
            lane_of[l] = self.keys[c];
        }
        let pd: MfParams<DualSVec64<N>> =
            p.map(|i, v| match lane_of.iter().position(|&k| k == i) {
                Some(l) => DualSVec64::new(v, Derivative::derivative_generic(Const::<N>, U1, l)),
                None => DualSVec64::from(v),
            });
        Model::new(pd, self.form)
    }
}

/// `base` with θ written in at the key indices `keys`
/// ([`MfParams::as_slice`] order).
pub(crate) fn params_with(base: &MfParams<f64>, keys: &[usize], theta: &[f64]) -> MfParams<f64> {
    let mut p = base.clone();
    let s = p.as_mut_slice();
    for (&k, &v) in keys.iter().zip(theta) {
        s[k] = v;
    }
    p
}

/// The closed-form row Jacobian of an [`MfStage`] at one θ.
struct AnalyticRows<'s> {
    grad: grad_pure::PureGrad,
    /// Local gradient index of every requested column.
    map: Vec<usize>,
    conds: &'s [Conditions],
    meas: &'s [f64],
    factors: &'s [grad_pure::Weights],
}

impl RowJacobian for AnalyticRows<'_> {
    fn rows(&self, first: usize, r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        // Gradients row by row into a small row-major buffer, then column by
        // column into `jac` (no per-entry index arithmetic on the view).
        const ROWS: usize = 64;
        let mut buf = [[0.0; grad_pure::MAX_KEYS]; ROWS];
        let mut k0 = 0;
        while k0 < r.len() {
            let nb = ROWS.min(r.len() - k0);
            for (k, g) in buf[..nb].iter_mut().enumerate() {
                let i = first + k0 + k;
                let y = self.grad.eval(&self.conds[i], self.factors[i], Some(g));
                r[k0 + k] = y - self.meas[i];
            }
            for (j, &l) in self.map.iter().enumerate() {
                let mut col = jac.column_mut(j);
                for (v, g) in col.rows_mut(k0, nb).iter_mut().zip(&buf[..nb]) {
                    *v = g[l];
                }
            }
            k0 += nb;
        }
    }
}

/// The num-dual row Jacobian of an [`MfStage`] at one θ: passes of 16 lanes
/// (the last one of 8 when that suffices; per lane the 16-lane dual is the
/// cheapest num-dual width for these equations, see the module docs), each
/// with its model prepared once.
struct DualRows<'s> {
    wide: Vec<(usize, usize, Model<DualSVec64<16>>)>,
    narrow: Option<(usize, usize, Model<DualSVec64<8>>)>,
    conds: &'s [Conditions],
    meas: &'s [f64],
    channel: Channel,
    given: Option<&'s [f64]>,
}

impl DualRows<'_> {
    /// Columns `col0..col0 + width` from `model` (and r when `col0` is 0).
    fn pass<const N: usize>(
        &self,
        model: &Model<DualSVec64<N>>,
        col0: usize,
        width: usize,
        first: usize,
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        for (k, rk) in r.iter_mut().enumerate() {
            let i = first + k;
            let y = channels::eval_given(
                model,
                &self.conds[i],
                self.channel,
                self.given.map(|g| g[i]),
            );
            if col0 == 0 {
                *rk = y.re - self.meas[i];
            }
            let g = y.eps.unwrap_generic(Const::<N>, U1);
            for l in 0..width {
                jac[(k, col0 + l)] = g[l];
            }
        }
    }
}

impl RowJacobian for DualRows<'_> {
    fn rows(&self, first: usize, r: &mut [f64], jac: &mut DMatrixViewMut<f64>) {
        for (col0, width, m) in &self.wide {
            self.pass(m, *col0, *width, first, r, jac);
        }
        if let Some((col0, width, m)) = &self.narrow {
            self.pass(m, *col0, *width, first, r, jac);
        }
    }
}

impl Problem for MfStage<'_> {
    fn params(&self) -> &[Param] {
        &self.params
    }
    fn n_residuals(&self) -> usize {
        self.meas.len()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        let p = self.params_at(theta);
        if let Some(an) = &self.analytic {
            if let Some(grad) = grad_pure::PureGrad::new(&p, self.form, self.channel) {
                par_rows(self.threads, 0, r, None, &|first, r: &mut [f64], _| {
                    for (k, rk) in r.iter_mut().enumerate() {
                        let i = first + k;
                        *rk = grad.eval(&self.conds[i], an.factors[i], None) - self.meas[i];
                    }
                });
                return;
            }
        }
        let model = Model::new(p, self.form);
        let given = self.given.as_deref();
        par_rows(self.threads, 0, r, None, &|first, r: &mut [f64], _| {
            for (k, rk) in r.iter_mut().enumerate() {
                let i = first + k;
                *rk =
                    channels::eval_given(&model, &self.conds[i], self.channel, given.map(|g| g[i]))
                        - self.meas[i];
            }
        });
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut DMatrixViewMut<f64>,
    ) {
        if cols.is_empty() {
            self.residuals(theta, r);
            return;
        }
        let Some(rows) = self.row_jacobian(theta, cols) else {
            return;
        };
        par_rows(
            self.threads,
            0,
            r,
            Some(jac),
            &|first, r: &mut [f64], jac| {
                if let Some(jac) = jac {
                    rows.rows(first, r, jac);
                }
            },
        );
    }
    fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    fn row_jacobian<'s>(
        &'s self,
        theta: &[f64],
        cols: &[usize],
    ) -> Option<Box<dyn RowJacobian + 's>> {
        let p = self.params_at(theta);
        if let Some(an) = &self.analytic {
            if let Some(grad) = grad_pure::PureGrad::new(&p, self.form, self.channel) {
                return Some(Box::new(AnalyticRows {
                    grad,
                    map: cols.iter().map(|&c| an.local[c]).collect(),
                    conds: self.conds,
                    meas: self.meas,
                    factors: &an.factors,
                }));
            }
        }
        let mut wide = Vec::new();
        let mut narrow = None;
        let mut col0 = 0;
        while col0 < cols.len() {
            let rest = &cols[col0..];
            if rest.len() <= 8 {
                narrow = Some((col0, rest.len(), self.dual_model::<8>(&p, rest)));
                col0 += rest.len();
            } else {
                let chunk = &rest[..rest.len().min(16)];
                wide.push((col0, chunk.len(), self.dual_model::<16>(&p, chunk)));
                col0 += chunk.len();
            }
        }
        Some(Box::new(DualRows {
            wide,
            narrow,
            conds: self.conds,
            meas: self.meas,
            channel: self.channel,
            given: self.given.as_deref(),
        }))
    }
    fn threads(&self) -> usize {
        self.threads
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inclinations as the rig control of the FSAE tyre recorded them in its
    /// drive/brake segments: upright with ±0.04° noise and a few samples at
    /// 1° where a block's inclination changed. The spread must stay below
    /// [`CAMBER_SPREAD`] (camber terms held), while a second level held by
    /// 2 % of the samples (a short camber block) must count.
    #[test]
    fn robust_spread_ignores_stray_samples_not_short_blocks() {
        let noise = |i: usize| 0.0007 * ((i * 7919 % 1000) as f64 / 500.0 - 1.0);
        let mut upright: Vec<f64> = (0..4000).map(noise).collect();
        upright.extend([0.0177; 20]); // 0.5 % of the samples at 1°
        let s = robust_spread(&mut upright);
        assert!(s < CAMBER_SPREAD, "stray samples set the spread: {s}");
        let mut two: Vec<f64> = (0..4000).map(noise).collect();
        two.extend((0..80).map(|i| 2f64.to_radians() + noise(i))); // 2 %
        let s = robust_spread(&mut two);
        assert!(
            (s - 2f64.to_radians()).abs() < 0.002,
            "a 2 % block at 2° not seen: spread {s}"
        );
        assert_eq!(robust_spread(&mut []), 0.0);
    }
}
