//! param — the parametrised candidate: a [`Spec`] (which tyre-file keys or
//! project-section values it fits, their ranges, the transient model to
//! replay with) applied to a baseline tyre, fitted by the crate's one
//! Levenberg–Marquardt ([`crate::fit::lm`]) through a [`crate::fit::Problem`]
//! whose residuals are the replayed model's, and the baseline itself
//! ([`NoneCandidate`]).
//!
//! Must never: look at a sample outside the fit mask while fitting, fit a
//! parameter whose channels carry no data, or report a value at a bound
//! without saying so ([`Fitted::at_bound`]).

use super::work::{work, Memory};
use super::{Candidate, Fitted, Reestimation, ALL_CHANNELS};
use crate::data::Recording;
use crate::error::Result;
use crate::mf::{Forces, MfInput, Tyre};
use crate::residual::{mf_input, replay, Channel, ReplayOptions};
use crate::tir::MfVersion;
use crate::transient::extension::set_file_transient;
use crate::transient::{LuGreParams, TransientKind, WheelOutput};

/// Most fit-half samples a static candidate is fitted on.
pub const STATIC_SAMPLES: usize = 4000;

/// A fitted model: a tyre, how to replay it, and (rolling radius) whether κ
/// is re-derived from the tyre's effective rolling radius.
struct Model {
    tyre: Tyre,
    base: Tyre,
    opts: ReplayOptions,
    kappa_re: bool,
    params: Vec<(String, f64)>,
    /// How many of `params` act on each channel ([`Param::on`]).
    params_on: [usize; 3],
    at_bound: Vec<String>,
    held: Vec<String>,
}

/// The recording with κ re-derived from `tyre`'s effective rolling radius:
/// κ' = (1 + κ)·Re(tyre)/Re(base) − 1, i.e. the slip the tyre sees at the
/// recorded wheel speed Ω = (1 + κ)·Vx/Re(base) when the recording's κ was
/// derived with the baseline's radius (what the FMU does from velocities).
pub(crate) fn rerolled(
    rec: &Recording,
    base: &Tyre,
    tyre: &Tyre,
    opts: &ReplayOptions,
) -> Recording {
    let mut out = rec.clone();
    for s in &mut out.samples {
        if !(s.fz.is_finite() && s.vx.is_finite() && s.kappa.is_finite()) {
            continue;
        }
        // Re depends on load, speed, pressure, wheel speed; not on slip.
        let mi = MfInput {
            kappa: 0.0,
            alpha: 0.0,
            phit: 0.0,
            ..mf_input(s)
        };
        let rb = base.slip_properties(&mi, opts.use_mode).re;
        let rt = tyre.slip_properties(&mi, opts.use_mode).re;
        let k = (1.0 + s.kappa) * rt / rb - 1.0;
        if k.is_finite() {
            s.kappa = k;
        }
    }
    out
}

impl Model {
    fn sim(&self, rec: &Recording) -> Result<Vec<Forces>> {
        if self.kappa_re {
            let r = rerolled(rec, &self.base, &self.tyre, &self.opts);
            Ok(replay(&r, &self.tyre, &self.opts)?.sim)
        } else {
            Ok(replay(rec, &self.tyre, &self.opts)?.sim)
        }
    }
}

impl Fitted for Model {
    fn parameters(&self) -> Vec<(String, f64)> {
        self.params.clone()
    }
    fn predict(&self, rec: &Recording) -> Result<Vec<Forces>> {
        self.sim(rec)
    }
    fn outputs(&self, rec: &Recording) -> Result<Option<Vec<WheelOutput>>> {
        if self.kappa_re {
            return Ok(None);
        }
        Ok(Some(replay(rec, &self.tyre, &self.opts)?.out))
    }
    fn tyre(&self) -> &Tyre {
        &self.tyre
    }
    fn at_bound(&self) -> Vec<String> {
        self.at_bound.clone()
    }
    fn held(&self) -> Vec<String> {
        self.held.clone()
    }
    fn parameters_on(&self, j: usize) -> usize {
        self.params_on.get(j).copied().unwrap_or(self.params.len())
    }
}

/// The baseline itself.
pub struct NoneCandidate;

impl Candidate for NoneCandidate {
    fn name(&self) -> &'static str {
        "none"
    }
    fn n_params(&self) -> usize {
        0
    }
    fn physics(&self) -> &'static str {
        "nothing beyond the baseline: what is left is noise"
    }
    fn describe(&self, _: &dyn Fitted) -> String {
        "the baseline model as it is".into()
    }
    fn fit(
        &self,
        _: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        _: &[bool],
        _: &[f64; 3],
    ) -> Result<Box<dyn Fitted>> {
        Ok(Box::new(Model {
            tyre: baseline.clone(),
            base: baseline.clone(),
            opts: *opts,
            kappa_re: false,
            params: vec![],
            params_on: [0; 3],
            at_bound: vec![],
            held: vec![],
        }))
    }
}

/// Golden-section minimum of `f` on [lo, hi] in ln-space (n evaluations).
pub(super) fn golden_log(lo: f64, hi: f64, n: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo.ln(), hi.ln());
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c.exp()), f(d.exp()));
    for _ in 0..n {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c.exp());
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d.exp());
        }
    }
    (0.5 * (a + b)).exp()
}

/// Zero-slip properties of `t` at its nominal load, 60 km/h, no camber.
pub(super) fn nominal_props(t: &Tyre, opts: &ReplayOptions) -> crate::mf::SlipProps {
    let p = &t.params().p;
    let fz0 = if p.fnomin > 0.0 { p.fnomin } else { 4000.0 };
    t.slip_properties(
        &MfInput {
            fz: fz0,
            vx: 16.7,
            ..Default::default()
        },
        opts.use_mode,
    )
}

/// A fitted parameter's value by name (NaN if absent).
pub(super) fn param(f: &dyn Fitted, name: &str) -> f64 {
    f.parameters()
        .iter()
        .find(|(k, _)| k == name)
        .map_or(f64::NAN, |(_, v)| *v)
}

/// Where a parameter lives in the tyre file.
#[derive(Clone, Copy, Debug)]
pub enum Target {
    /// A key of the MF key table (PPY3, LMUV, FREFF …).
    Key(&'static str),
    /// A key of a section of this project's own (`[THERMAL]` …).
    Section(&'static str, &'static str),
}

/// One fitted parameter: its name, where it goes, start, bounds, the
/// finite-difference step (also its natural scale) and the channels it acts
/// on (indices into [`Channel::SCORED`]): a parameter is fitted only when one of
/// them carries data in the fit half — PPX* of the pressure candidate on a
/// cornering-only recording would otherwise wander to a bound, fitted to
/// nothing.
#[derive(Clone, Debug)]
pub struct Param {
    /// Name in the report (usually the tyre-file key, e.g. "PPY3").
    pub name: &'static str,
    /// Where the value is written; every target gets the same value.
    pub targets: Vec<Target>,
    /// Start value (usually the file's), also the value held when backward
    /// elimination drops the parameter; in the key's own unit.
    pub init: f64,
    /// Lower bound of the fitted range (same unit as `init`).
    pub lo: f64,
    /// Upper bound of the fitted range (same unit as `init`).
    pub hi: f64,
    /// Forward-difference step of the Jacobian, also the parameter's
    /// natural scale (same unit as `init`).
    pub h: f64,
    /// Scored channels it acts on (indices into [`Channel::SCORED`]).
    pub channels: &'static [usize],
    /// The lower bound is a physical value the parameter may take (VREF =
    /// 0: the file's friction is the one at zero sliding speed), not a
    /// limit of the range: a fit ending there is not reported at a bound.
    pub natural_lo: bool,
}

impl Param {
    /// The same parameter acting on `channels` only.
    pub fn on(mut self, channels: &'static [usize]) -> Param {
        self.channels = channels;
        self
    }
    /// The same parameter with a lower bound that is a value, not a limit
    /// ([`Param::natural_lo`]).
    pub fn natural_lo(mut self) -> Param {
        self.natural_lo = true;
        self
    }
}

/// A condition's value on one segment (pressure, inclination): see [`Spec::levels`].
pub type SegmentValue = fn(&crate::data::Segment) -> f64;

/// Fixed values a candidate takes from the fit half: see [`Spec::from_data`].
pub type FromData = fn(&Recording, &[bool]) -> Option<Vec<(Target, f64)>>;

/// How a parametrised candidate applies to one baseline tyre.
#[derive(Clone, Debug, Default)]
pub struct Spec {
    /// Parameters to fit; those acting on no channel with data in the fit
    /// half stay at their `init`.
    pub params: Vec<Param>,
    /// Values written as they are (not fitted).
    pub fixed: Vec<(Target, f64)>,
    /// Transient model to replay with (None: the baseline's).
    pub kind: Option<TransientKind>,
    /// What the model remembers between samples: how much of the
    /// recording each trial replays ([`super::work`]). A static or slow
    /// candidate replayed under a transient model of the diagnosis's
    /// options (`--transient`) replays the whole recording.
    pub memory: Memory,
    /// Re-derive κ from the tyre's effective rolling radius.
    pub kappa_re: bool,
    /// Before LM, scan one common factor on the start values of the first
    /// `prescan` parameters (golden section in ln-space, ×0.1…×10): for
    /// parameters that set a length scale together (relaxation lengths,
    /// bristle stiffnesses), where the cost is far from quadratic around the
    /// file's values. 0: no scan.
    pub prescan: usize,
    /// A condition the parameters act through (inflation pressure,
    /// inclination): (its value on a segment, the width of one level). The
    /// candidate is fitted only when the fit half spans at least two levels
    /// — at one pressure the pressure terms can only fit sensor noise on the
    /// recorded pressure and end at a bound.
    pub levels: Option<(SegmentValue, f64)>,
    /// Further start points (parameter name, start value overriding
    /// [`Param::init`]): LM runs from the plain start and from each of
    /// these, and the fit with the lowest fit-half cost is kept — for a
    /// parameter whose cost has two valleys LM cannot cross (VREF of the
    /// speed law: at 0 or at the recorded belt speeds).
    pub restarts: Vec<Vec<(&'static str, f64)>>,
    /// A condition recorded per sample that the parameters act through,
    /// continuous (a drifting or leaking pressure): the candidate is fitted
    /// only when its values over the fit half span clearly more than their
    /// noise ([`crate::diagnose::factor::varies_beyond_noise`]).
    pub varies: Option<fn(&crate::data::Sample) -> f64>,
    /// Values taken from the fit half and written as they are (with
    /// [`Spec::fixed`]), e.g. the knot loads of a curve over the recorded
    /// load range; None from the function: the fit half cannot carry the
    /// candidate (one load level), which is then the baseline itself.
    pub from_data: Option<FromData>,
    /// The parameters are separate terms, each of which the physics may
    /// lack (the knot values of the load curves, the camber terms): after
    /// the full fit,
    /// drop them one at a time while that lowers the fit half's evidence
    /// statistic (`eliminate`), holding a dropped one at its start value.
    pub eliminate: bool,
    /// Keys of the baseline's own Magic Formula that the candidate fits
    /// again beside its parameters, because the baseline may have taken
    /// up part of the effect through them (the thermal candidate: the
    /// combined-slip weights, which absorb a temperature step between
    /// drive/brake blocks run at one slip angle after another). They are
    /// written to the extended file with the rest, but the candidate is
    /// scored against the baseline with these keys alone fitted again on
    /// the same half ([`ReferenceOf`], [`Candidate::reference`]), so that
    /// the freedom they add never names the physics by itself.
    pub reference: Vec<Param>,
}

/// Whether `get` varies beyond its noise over the segments overlapping `mask`.
fn varies(rec: &Recording, mask: &[bool], get: fn(&crate::data::Sample) -> f64) -> bool {
    use crate::diagnose::factor;
    let segs: Vec<&crate::data::Segment> = rec
        .segments
        .iter()
        .filter(|g| mask.get(g.start).copied().unwrap_or(false))
        .collect();
    factor::varies_beyond_noise(
        factor::span(&rec.samples, &segs, get),
        factor::noise(&rec.samples, &segs, get),
    )
}

/// Distinct levels of `levels` among the segments overlapping `mask`.
fn level_count(
    rec: &Recording,
    mask: &[bool],
    levels: (fn(&crate::data::Segment) -> f64, f64),
) -> usize {
    let (get, width) = levels;
    let mut seen: Vec<i64> = rec
        .segments
        .iter()
        .filter(|g| mask.get(g.start).copied().unwrap_or(false))
        .map(get)
        .filter(|x| x.is_finite())
        .map(|x| (x / width).round() as i64)
        .collect();
    seen.sort_unstable();
    seen.dedup();
    seen.len()
}

fn set(p: &mut crate::tir::TyreParams, t: Target, v: f64) -> Result<()> {
    match t {
        Target::Key(k) => p.set(k, v),
        Target::Section(s, k) => {
            p.extra_section(s).set(k, v);
            Ok(())
        }
    }
}

/// The baseline with the spec's fixed values and parameters `theta`.
fn apply(base: &Tyre, spec: &Spec, theta: &[f64]) -> Result<Tyre> {
    let mut p = base.params().clone();
    for (t, v) in &spec.fixed {
        set(&mut p, *t, *v)?;
    }
    for (q, v) in spec.params.iter().zip(theta) {
        for t in &q.targets {
            set(&mut p, *t, *v)?;
        }
    }
    // The file names the transient model it needs, so the FMU and `replay`
    // run it by default.
    if let Some(k) = spec.kind {
        set_file_transient(&mut p, k);
    }
    Tyre::new(p)
}

/// Most outer iterations (Jacobians) of a candidate's fit: each is one
/// replay per free parameter, and the candidates start at the file's
/// values or a scanned common factor, a few steps from their optimum.
pub const LM_ITERATIONS: usize = 12;

/// Relative cost reduction below which a candidate's fit stops: 10⁻⁵ of
/// the weighted SSE is far below what any held-out gain of
/// [`super::MIN_GAIN`] = 2 % needs.
pub const LM_FTOL: f64 = 1e-5;

/// A candidate's least-squares problem for the crate's LM: r(θ) is the
/// weighted, per-channel centred residual of the replayed model; ∂r/∂θ is
/// a forward difference with each parameter's own step [`Param::h`]
/// (backward when the forward step would leave the range) — stated here,
/// not hidden: the replay runs the FMU's `f64` transient models, which have
/// no dual-number form, and a forward difference of a deterministic replay
/// is accurate to ~h relative to the curvature, plenty for ≤ 7 parameters
/// (Madsen, Nielsen & Tingleff, *Methods for non-linear least squares
/// problems*, 2004, §3.3). A θ whose model cannot be built or replayed has
/// non-finite residuals (LM rejects the step); its difference column is 0.
/// The last replay's (θ, r) is kept: LM linearises at the trial it has just
/// accepted, whose residuals the Jacobian then reuses instead of replaying
/// again (the replay is deterministic, so the same numbers).
struct FdProblem<F: Fn(&[f64]) -> Option<Vec<f64>>> {
    params: Vec<crate::fit::Param>,
    steps: Vec<f64>,
    m: usize,
    resid: F,
    last: std::cell::RefCell<Option<(Vec<f64>, Vec<f64>)>>,
}

impl<F: Fn(&[f64]) -> Option<Vec<f64>>> FdProblem<F> {
    /// r(θ), from the last replay when it was at this θ (bit for bit).
    fn at(&self, theta: &[f64]) -> Option<Vec<f64>> {
        if let Some((t, r)) = self.last.borrow().as_ref() {
            if t.iter().zip(theta).all(|(a, b)| a.to_bits() == b.to_bits()) {
                return Some(r.clone());
            }
        }
        let r = (self.resid)(theta)?;
        *self.last.borrow_mut() = Some((theta.to_vec(), r.clone()));
        Some(r)
    }
}

impl<F: Fn(&[f64]) -> Option<Vec<f64>>> crate::fit::Problem for FdProblem<F> {
    fn params(&self) -> &[crate::fit::Param] {
        &self.params
    }
    fn n_residuals(&self) -> usize {
        self.m
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) {
        match self.at(theta) {
            Some(v) if v.len() == r.len() => r.copy_from_slice(&v),
            _ => r.fill(f64::NAN),
        }
    }
    fn jacobian(
        &self,
        theta: &[f64],
        cols: &[usize],
        r: &mut [f64],
        jac: &mut nalgebra::DMatrixViewMut<f64>,
    ) {
        self.residuals(theta, r);
        let mut t = theta.to_vec();
        for (k, &j) in cols.iter().enumerate() {
            let q = &self.params[j];
            let h = if theta[j] + self.steps[j] <= q.upper {
                self.steps[j]
            } else {
                -self.steps[j]
            };
            t[j] = theta[j] + h;
            let col = (self.resid)(&t).filter(|v| v.len() == r.len());
            t[j] = theta[j];
            for i in 0..r.len() {
                jac[(i, k)] = col.as_ref().map_or(0.0, |v| (v[i] - r[i]) / h);
            }
        }
    }
}

/// Minimise Σ r(θ)² over `params` (start [`Param::init`] clamped into its
/// range) with [`crate::fit::lm::minimize`]; the start when the start
/// cannot be replayed or LM refuses the problem.
fn fit_lm(params: &[Param], resid: impl Fn(&[f64]) -> Option<Vec<f64>>) -> Vec<f64> {
    let start: Vec<f64> = params.iter().map(|q| q.init.clamp(q.lo, q.hi)).collect();
    let Some(r0) = resid(&start) else {
        return start;
    };
    let problem = FdProblem {
        params: params
            .iter()
            .zip(&start)
            .map(|(q, &v)| crate::fit::Param::new(q.name, v, q.lo, q.hi))
            .collect(),
        steps: params.iter().map(|q| q.h).collect(),
        m: r0.len(),
        resid,
        last: std::cell::RefCell::new(Some((start.clone(), r0))),
    };
    let opts = crate::fit::LmOptions {
        max_iter: LM_ITERATIONS,
        ftol: LM_FTOL,
        lambda0: 1e-3,
        ..Default::default()
    };
    let free = vec![true; params.len()];
    match crate::fit::lm::minimize(&problem, &start, &free, &opts, None) {
        Ok(r) => {
            crate::fit::timing::note(|| {
                format!(
                    "    LM: {} linearisations, {} trials, {:?}, cost {:.4e} -> {:.4e}",
                    r.iterations, r.residual_evals, r.termination, r.initial_cost, r.cost
                )
            });
            r.theta
        }
        Err(_) => start,
    }
}

/// Per channel block of a candidate's residual vector (blocks of `n`, the
/// channels with data in [`Channel::SCORED`] order): its sum of squares.
fn channel_sums(r: &[f64], n: usize) -> Vec<f64> {
    r.chunks(n.max(1))
        .map(|c| c.iter().map(|x| x * x).sum())
        .collect()
}

/// Per channel with weight (the blocks of [`channel_sums`]): the samples
/// of `idx` with a finite measurement.
fn channel_counts(rec: &Recording, idx: &[usize], w: &[f64; 3]) -> Vec<usize> {
    Channel::SCORED
        .iter()
        .zip(w)
        .filter(|(_, w)| **w != 0.0)
        .map(|(ch, _)| {
            idx.iter()
                .filter(|&&i| ch.measured(&rec.samples[i]).is_finite())
                .count()
        })
        .collect()
}

/// The evidence statistic of a fit with `k` parameters: the AIC change of
/// the channels taken as independent Gaussian observations, Σ_c
/// n_c·ln(SSE_c/SSE_c,base) + 2k, n_c the channel's seconds
/// ([`super::DECORRELATION_TIME`]). Each channel's evidence counts in full,
/// so a term acting on Mz alone (a camber moment) stays when Mz needs it,
/// however well another channel is already explained. AIC, not BIC: the
/// elimination picks the terms that predict (Akaike's criterion estimates
/// the expected held-out error; Burnham & Anderson, *Model Selection and
/// Multimodel Inference*, 2nd ed., 2002, §2.2), and the verdict then asks
/// the stricter BIC of what is left ([`super::ChannelScore::delta_bic`]).
/// With BIC here the project's own proof lost real small terms (camber
/// moment terms: 91–96 % → 45–66 % of the gap recovered).
fn evidence(sse: &[f64], base: &[f64], secs: &[f64], k: usize) -> f64 {
    let mut sum = 0.0;
    let mut n_all = 0.0;
    for ((e, b), s) in sse.iter().zip(base).zip(secs) {
        let n = s / super::DECORRELATION_TIME;
        if *b > 0.0 && n > 0.0 {
            sum += n * (e / b).max(1e-300).ln();
            n_all += n;
        }
    }
    if n_all >= 2.0 {
        sum + 2.0 * k as f64
    } else {
        f64::INFINITY
    }
}

/// The entries of `v` whose `keep` is true.
fn kept<T>(v: Vec<T>, keep: &[bool]) -> Vec<T> {
    v.into_iter()
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|(x, _)| x)
        .collect()
}

/// Backward elimination ([`Spec::eliminate`]): from the full fit `theta`,
/// refit without each active parameter in turn (held at its start) and drop
/// the one whose removal gives the lowest [`evidence`], as long as that is
/// no higher than with it; at least one parameter stays. Fit half only
/// (the residuals `resid` see nothing else), so the held-out score still
/// judges the result. Returns which parameters stay and the refitted θ
/// (a held parameter at its start value).
fn eliminate(
    params: &[Param],
    mut theta: Vec<f64>,
    secs: &[f64],
    base: &[f64],
    resid: &impl Fn(&[f64]) -> Option<Vec<f64>>,
    block: usize,
) -> (Vec<bool>, Vec<f64>) {
    let mut keep = vec![true; params.len()];
    let score = |th: &[f64], k: usize| {
        resid(th).map_or(f64::INFINITY, |r| {
            evidence(&channel_sums(&r, block), base, secs, k)
        })
    };
    let mut current = score(&theta, params.len());
    loop {
        let active: Vec<usize> = (0..params.len()).filter(|&i| keep[i]).collect();
        if active.len() <= 1 {
            break;
        }
        let mut best: Option<(usize, Vec<f64>, f64)> = None;
        for &j in &active {
            let rest: Vec<usize> = active.iter().copied().filter(|&i| i != j).collect();
            let sub: Vec<Param> = rest
                .iter()
                .map(|&i| Param {
                    init: theta[i],
                    ..params[i].clone()
                })
                .collect();
            let mut full = theta.clone();
            full[j] = params[j].init;
            let expand = |ts: &[f64]| {
                let mut t = full.clone();
                for (&i, v) in rest.iter().zip(ts) {
                    t[i] = *v;
                }
                t
            };
            let ts = fit_lm(&sub, |ts: &[f64]| resid(&expand(ts)));
            let t = expand(&ts);
            let e = score(&t, rest.len());
            if best.as_ref().is_none_or(|b| e < b.2) {
                best = Some((j, t, e));
            }
        }
        match best {
            Some((j, t, e)) if e <= current => {
                keep[j] = false;
                theta = t;
                current = e;
            }
            _ => break,
        }
    }
    (keep, theta)
}

/// A candidate fitted by Levenberg–Marquardt (`fit_lm`) over the parameters of a
/// [`Spec`] (built per baseline tyre; None: not applicable to that tyre, the
/// fit is then the baseline itself).
#[derive(Clone, Copy)]
pub struct ParamCandidate {
    /// See [`Candidate::name`].
    pub name: &'static str,
    /// See [`Candidate::physics`].
    pub physics: &'static str,
    /// Parameters the candidate has ([`Candidate::n_params`]).
    pub n: usize,
    /// Builds the [`Spec`] for a baseline tyre (None: not applicable to it).
    pub spec: fn(&Tyre, &ReplayOptions) -> Option<Spec>,
    /// The fitted extension in words ([`Candidate::describe`], before the
    /// note on held parameters).
    pub words: fn(&dyn Fitted) -> String,
    /// See [`Candidate::reestimation`].
    pub reestimation: Reestimation,
    /// See [`Candidate::refits_baseline`].
    pub refits_baseline: bool,
}

impl Candidate for ParamCandidate {
    fn name(&self) -> &'static str {
        self.name
    }
    fn n_params(&self) -> usize {
        self.n
    }
    fn physics(&self) -> &'static str {
        self.physics
    }
    fn reestimation(&self) -> Reestimation {
        self.reestimation
    }
    fn refits_baseline(&self) -> bool {
        self.refits_baseline
    }
    fn describe(&self, f: &dyn Fitted) -> String {
        let held = f.held();
        if f.parameters().is_empty() {
            // The fit fell back to the baseline (nothing applicable):
            // no value to describe.
            "not fitted".to_string()
        } else if held.is_empty() {
            (self.words)(f)
        } else {
            format!(
                "{} ({} held at the file's values: the fit half's evidence did not pay for them)",
                (self.words)(f),
                held.join(", ")
            )
        }
    }
    fn reference(&self, baseline: &Tyre, opts: &ReplayOptions) -> Option<Box<dyn Candidate>> {
        (self.spec)(baseline, opts)
            .filter(|s| !s.reference.is_empty())
            .map(|_| Box::new(ReferenceOf(*self)) as Box<dyn Candidate>)
    }
    fn fit(
        &self,
        rec: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        mask: &[bool],
        w: &[f64; 3],
    ) -> Result<Box<dyn Fitted>> {
        self.fit_part(rec, baseline, opts, mask, w, false)
    }
}

/// The baseline with a candidate's [`Spec::reference`] keys alone fitted
/// again (on the same half, with the same weights): what the candidate's
/// gains are measured against ([`Candidate::reference`]). Never named.
pub struct ReferenceOf(pub ParamCandidate);

impl Candidate for ReferenceOf {
    fn name(&self) -> &'static str {
        "reference"
    }
    fn n_params(&self) -> usize {
        0
    }
    fn fit(
        &self,
        rec: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        mask: &[bool],
        w: &[f64; 3],
    ) -> Result<Box<dyn Fitted>> {
        self.0.fit_part(rec, baseline, opts, mask, w, true)
    }
}

impl ParamCandidate {
    /// [`Candidate::fit`] of the whole candidate (its parameters and its
    /// [`Spec::reference`] keys), or with `reference_only` of the
    /// reference keys alone on the baseline ([`ReferenceOf`]).
    fn fit_part(
        &self,
        rec: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        mask: &[bool],
        w: &[f64; 3],
        reference_only: bool,
    ) -> Result<Box<dyn Fitted>> {
        let Some(mut spec) = (self.spec)(baseline, opts) else {
            return NoneCandidate.fit(rec, baseline, opts, mask, w);
        };
        if reference_only {
            spec = Spec {
                params: std::mem::take(&mut spec.reference),
                ..Spec::default()
            };
        } else {
            let reference = std::mem::take(&mut spec.reference);
            spec.params.extend(reference);
        }
        if let Some(f) = spec.from_data {
            match f(rec, mask) {
                Some(v) => spec.fixed.extend(v),
                None => return NoneCandidate.fit(rec, baseline, opts, mask, w),
            }
        }
        // Only the parameters acting on a channel with data are fitted; the
        // others stay at their start (the file's value).
        let free: Vec<usize> = (0..spec.params.len())
            .filter(|&i| spec.params[i].channels.iter().any(|&c| w[c] > 0.0))
            .collect();
        let one_level = spec.levels.is_some_and(|l| level_count(rec, mask, l) < 2)
            || spec.varies.is_some_and(|g| !varies(rec, mask, g));
        if free.is_empty() || one_level {
            return NoneCandidate.fit(rec, baseline, opts, mask, w);
        }
        let mut ro = *opts;
        if let Some(k) = spec.kind {
            ro.kind = k;
        }
        let memory = match spec.memory {
            Memory::None | Memory::Slow if ro.kind != TransientKind::Steady => Memory::Whole,
            m => m,
        };
        let (work, idx) = work(rec, mask, memory);
        // The full parameter vector from the free ones.
        let full = |th: &[f64]| -> Vec<f64> {
            let mut t: Vec<f64> = spec.params.iter().map(|q| q.init).collect();
            for (&i, v) in free.iter().zip(th) {
                t[i] = *v;
            }
            t
        };
        let model_of = |theta: &[f64]| -> Result<Model> {
            let tyre = apply(baseline, &spec, &full(theta))?;
            let mut o = ro;
            if o.kind == TransientKind::LuGre {
                o.options.lugre = LuGreParams::from_tyre_params(tyre.params())?;
            }
            Ok(Model {
                tyre,
                base: baseline.clone(),
                opts: o,
                kappa_re: spec.kappa_re,
                params: vec![],
                params_on: [0; 3],
                at_bound: vec![],
                held: vec![],
            })
        };
        let replays = std::sync::atomic::AtomicUsize::new(0);
        let resid = |theta: &[f64]| -> Option<Vec<f64>> {
            replays.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let m = model_of(theta).ok()?;
            let sim = m.sim(&work).ok()?;
            let mut out = Vec::with_capacity(3 * idx.len());
            for (k, ch) in Channel::SCORED.iter().enumerate() {
                if w[k] == 0.0 {
                    continue;
                }
                let sw = w[k].sqrt();
                let start = out.len();
                for &i in &idx {
                    let r = ch.measured(&work.samples[i]) - ch.of_forces(&sim[i]);
                    out.push(if r.is_finite() { sw * r } else { 0.0 });
                }
                // Offsets are nuisance: centre each channel.
                let n = (out.len() - start).max(1) as f64;
                let mean = out[start..].iter().sum::<f64>() / n;
                for x in &mut out[start..] {
                    *x -= mean;
                }
            }
            Some(out)
        };
        let mut params: Vec<Param> = free.iter().map(|&i| spec.params[i].clone()).collect();
        let np = free.iter().filter(|&&i| i < spec.prescan).count();
        if np > 0 {
            let cost = |f: f64| {
                let t: Vec<f64> = (0..params.len())
                    .map(|i| params[i].init * if i < np { f } else { 1.0 })
                    .collect();
                resid(&t).map_or(f64::INFINITY, |r| r.iter().map(|x| x * x).sum())
            };
            let f = golden_log(0.1, 10.0, 14, cost);
            for q in params.iter_mut().take(np) {
                q.init *= f;
            }
        }
        let cost = |t: &[f64]| resid(t).map_or(f64::INFINITY, |r| r.iter().map(|x| x * x).sum());
        let mut theta = fit_lm(&params, resid);
        if !spec.restarts.is_empty() {
            let mut best = cost(&theta);
            for over in &spec.restarts {
                let mut q = params.clone();
                for (name, v) in over {
                    if let Some(x) = q.iter_mut().find(|x| x.name == *name) {
                        x.init = *v;
                    }
                }
                let t = fit_lm(&q, resid);
                let c = cost(&t);
                if c < best {
                    (theta, best) = (t, c);
                }
            }
        }
        let mut keep = vec![true; params.len()];
        if spec.eliminate && params.len() > 1 {
            let n_fit = mask.iter().filter(|x| **x).count();
            let t: Vec<f64> = rec.samples.iter().map(|s| s.time).collect();
            let h = crate::residual::median_spacing(&t);
            let fit_secs = n_fit as f64 * if h.is_finite() && h > 0.0 { h } else { 0.02 };
            let start: Vec<f64> = params.iter().map(|q| q.init).collect();
            if let Some(base) = resid(&start).map(|r| channel_sums(&r, idx.len())) {
                let counts = channel_counts(&work, &idx, w);
                let secs: Vec<f64> = counts
                    .iter()
                    .map(|&c| fit_secs * c as f64 / idx.len().max(1) as f64)
                    .collect();
                (keep, theta) = eliminate(&params, theta, &secs, &base, &resid, idx.len());
            }
        }
        crate::fit::timing::note(|| {
            format!(
                "  {}: {} replays of {} samples ({} read)",
                self.name,
                replays.load(std::sync::atomic::Ordering::Relaxed),
                work.samples.len(),
                idx.len()
            )
        });
        let mut m = model_of(&theta)?;
        m.held = params
            .iter()
            .zip(&keep)
            .filter(|(_, k)| !**k)
            .map(|(q, _)| q.name.to_string())
            .collect();
        let (params, theta) = (kept(params, &keep), kept(theta, &keep));
        m.params = params
            .iter()
            .zip(&theta)
            .map(|(q, v)| (q.name.to_string(), *v))
            .collect();
        m.params_on =
            std::array::from_fn(|j| params.iter().filter(|q| q.channels.contains(&j)).count());
        m.at_bound = params
            .iter()
            .zip(&theta)
            .filter_map(|(q, &v)| {
                // Within 0.1 % of the range of a bound (LM clamps onto it).
                let tol = 1e-3 * (q.hi - q.lo).abs();
                let which = if (v - q.lo).abs() <= tol && !q.natural_lo {
                    "lower"
                } else if (q.hi - v).abs() <= tol {
                    "upper"
                } else {
                    return None;
                };
                Some(format!("{} = {v:.4} (its {which} bound)", q.name))
            })
            .collect();
        Ok(Box::new(m))
    }
}

pub(super) fn key(k: &'static str) -> Target {
    Target::Key(k)
}

pub(super) fn p(
    name: &'static str,
    targets: Vec<Target>,
    init: f64,
    lo: f64,
    hi: f64,
    h: f64,
) -> Param {
    Param {
        name,
        targets,
        init,
        lo,
        hi,
        h,
        channels: ALL_CHANNELS,
        natural_lo: false,
    }
}

/// A key of the file's table as its start value.
pub(super) fn file(t: &Tyre, k: &str) -> f64 {
    t.params().get(k).unwrap_or(0.0)
}

pub(super) fn is_mf6(t: &Tyre) -> bool {
    matches!(t.version(), MfVersion::Mf61 | MfVersion::Mf62)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One channel, y = 0.5·x + noise, and three candidate terms x, z, u
    /// of which only x is in the data (z, u uncorrelated with the noise
    /// pattern): the elimination holds z and u at their start and keeps
    /// the slope of x; a fit whose terms all matter keeps them all.
    #[test]
    fn elimination_drops_the_terms_the_data_do_not_hold() {
        let n = 400;
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.05).sin()).collect();
        let z: Vec<f64> = (0..n).map(|i| (i as f64 * 0.031 + 1.0).cos()).collect();
        let u: Vec<f64> = (0..n).map(|i| i as f64 / n as f64 - 0.5).collect();
        // Deterministic "noise": a fast oscillation no term can follow.
        let e: Vec<f64> = (0..n).map(|i| 0.05 * (i as f64 * 2.7).sin()).collect();
        let params: Vec<Param> = ["A", "B", "C"]
            .iter()
            .map(|&k| p(k, vec![], 0.0, -5.0, 5.0, 1e-4))
            .collect();
        let run = |y: &[f64]| {
            let resid = |t: &[f64]| -> Option<Vec<f64>> {
                Some(
                    (0..n)
                        .map(|i| y[i] - t[0] * x[i] - t[1] * z[i] - t[2] * u[i])
                        .collect(),
                )
            };
            let theta = fit_lm(&params, resid);
            let base = channel_sums(&resid(&[0.0; 3]).unwrap(), n);
            eliminate(&params, theta, &[n as f64], &base, &resid, n)
        };
        let y: Vec<f64> = (0..n).map(|i| 0.5 * x[i] + e[i]).collect();
        let (keep, theta) = run(&y);
        assert_eq!(keep, vec![true, false, false]);
        assert!((theta[0] - 0.5).abs() < 0.01, "{theta:?}");
        assert_eq!((theta[1], theta[2]), (0.0, 0.0));
        let y: Vec<f64> = (0..n)
            .map(|i| 0.5 * x[i] + 0.3 * z[i] - 0.4 * u[i] + e[i])
            .collect();
        let (keep, theta) = run(&y);
        assert_eq!(keep, vec![true; 3], "{theta:?}");
    }
}
