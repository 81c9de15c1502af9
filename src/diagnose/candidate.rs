//! candidate — the extensions the diagnosis can name: each a parametrised
//! model with a physical meaning, fitted to a recording on top of a baseline
//! tyre, and scored out of sample with an information criterion so that
//! extra parameters alone never win.
//!
//! Scoring ([`evaluate`]): the recording's segments are split by parity
//! (even segments fit, odd ones score — neighbouring segments differ in
//! condition, so both halves span the programme); the out-of-sample gain is
//! the relative drop of the held-out sum of squared residuals (Fx, Fy, Mz,
//! each normalised by its measured variance); BIC over the whole recording,
//! n·ln(SSE/n) + k·ln(n) with n the effective sample count (samples / 50,
//! rig channels being strongly autocorrelated), must fall as well.
//!
//! Implemented: `none` (the baseline, 0 parameters) and `relaxation` (one
//! parameter: a scale λ on the tyre's relaxation lengths through the
//! standard keys, see [`RelaxationCandidate`]; replayed with the relaxation
//! transient model).
//!
//! Must never: let a candidate see the held-out segments while fitting.

use super::replay::{replay, Replay, ReplayOptions};
use crate::data::Recording;
use crate::error::Result;
use crate::mf::{Forces, Tyre};
use crate::tir::MfVersion;
use crate::transient::TransientKind;

/// A fitted extension: its parameters and its predictions.
pub trait Fitted {
    /// Named physical parameters (SI).
    fn parameters(&self) -> Vec<(String, f64)>;
    /// Simulated forces for every sample of `rec`.
    fn predict(&self, rec: &Recording) -> Result<Vec<Forces>>;
    /// The extended tyre to write as `extended.tir`.
    fn tyre(&self) -> &Tyre;
}

/// A candidate extension.
pub trait Candidate {
    fn name(&self) -> &'static str;
    fn n_params(&self) -> usize;
    /// The physics in one line, as a tyre engineer would say it
    /// ("transient slip lag"): used in the explanation of a verdict.
    fn physics(&self) -> &'static str {
        self.name()
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
    /// Fit on the samples where `mask` is true (the rest is never looked at).
    fn fit(
        &self,
        rec: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        mask: &[bool],
    ) -> Result<Box<dyn Fitted>>;
}

/// A force channel: its name, simulated value and measured value.
pub type Channel = (
    &'static str,
    fn(&Forces) -> f64,
    fn(&crate::data::Sample) -> f64,
);

/// The channels the diagnosis scores: Fx, Fy, Mz.
pub const CHANNELS: [Channel; 3] = [
    ("FX", |f| f.fx, |s| s.fx),
    ("FY", |f| f.fy, |s| s.fy),
    ("MZ", |f| f.mz, |s| s.mz),
];

/// Weighted SSE of Fx, Fy, Mz over masked samples (each channel normalised by
/// its measured variance over the mask; channels the recording lacks skipped).
pub fn sse(rec: &Recording, sim: &[Forces], mask: &[bool]) -> f64 {
    let mut total = 0.0;
    for (_, fs, fm) in CHANNELS {
        let (mut e, mut m1, mut m2, mut n) = (0.0, 0.0, 0.0, 0.0);
        for ((s, f), &k) in rec.samples.iter().zip(sim).zip(mask) {
            let (y, p) = (fm(s), fs(f));
            if k && y.is_finite() && p.is_finite() {
                e += (y - p) * (y - p);
                m1 += y;
                m2 += y * y;
                n += 1.0;
            }
        }
        let var = if n > 1.0 {
            m2 / n - (m1 / n).powi(2)
        } else {
            0.0
        };
        if var > 0.0 {
            total += e / var;
        }
    }
    total
}

/// The baseline itself.
pub struct NoneCandidate;

struct Plain {
    tyre: Tyre,
    opts: ReplayOptions,
    params: Vec<(String, f64)>,
}

impl Fitted for Plain {
    fn parameters(&self) -> Vec<(String, f64)> {
        self.params.clone()
    }
    fn predict(&self, rec: &Recording) -> Result<Vec<Forces>> {
        Ok(replay(rec, &self.tyre, &self.opts)?.sim)
    }
    fn tyre(&self) -> &Tyre {
        &self.tyre
    }
}

impl Candidate for NoneCandidate {
    fn name(&self) -> &'static str {
        "none"
    }
    fn n_params(&self) -> usize {
        0
    }
    fn fit(
        &self,
        _: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        _: &[bool],
    ) -> Result<Box<dyn Fitted>> {
        Ok(Box::new(Plain {
            tyre: baseline.clone(),
            opts: *opts,
            params: vec![],
        }))
    }
}

/// Transient slip lag: the relaxation model with the tyre's relaxation
/// lengths scaled by λ (Pacejka 3rd ed. §7.2; LSGKP/LSGAL scale factors).
pub struct RelaxationCandidate;

/// The tyre with relaxation-length scale λ: MF 6.1/6.2 derive σ = K/C from
/// the carcass stiffnesses (LONGITUDINAL_STIFFNESS, LATERAL_STIFFNESS: ÷ λ);
/// MF 5.2 / PAC2002 from PTX*/PTY* with the scale factors LSGKP, LSGAL (× λ).
fn with_relaxation_scale(t: &Tyre, lambda: f64) -> Result<Tyre> {
    let mut p = t.params().clone();
    if matches!(t.version(), MfVersion::Mf52 | MfVersion::Pac2002) {
        p.p.lsgkp *= lambda;
        p.p.lsgal *= lambda;
    } else {
        p.p.longitudinal_stiffness /= lambda;
        p.p.lateral_stiffness /= lambda;
    }
    Tyre::new(p)
}

/// Golden-section minimum of `f` on [lo, hi] in ln-space (n evaluations).
fn golden_log(lo: f64, hi: f64, n: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
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

impl Candidate for RelaxationCandidate {
    fn name(&self) -> &'static str {
        "relaxation"
    }
    fn n_params(&self) -> usize {
        1
    }
    fn fit(
        &self,
        rec: &Recording,
        baseline: &Tyre,
        opts: &ReplayOptions,
        mask: &[bool],
    ) -> Result<Box<dyn Fitted>> {
        let ro = ReplayOptions {
            kind: TransientKind::Relaxation,
            ..*opts
        };
        let cost = |l: f64| -> f64 {
            with_relaxation_scale(baseline, l)
                .and_then(|t| replay(rec, &t, &ro))
                .map(|r: Replay| sse(rec, &r.sim, mask))
                .unwrap_or(f64::INFINITY)
        };
        let lambda = golden_log(0.05, 10.0, 18, cost);
        let tyre = with_relaxation_scale(baseline, lambda)?;
        let q = &tyre.params().p;
        let params = vec![
            ("relaxation_scale".into(), lambda),
            ("LSGKP".into(), q.lsgkp),
            ("LSGAL".into(), q.lsgal),
            ("LONGITUDINAL_STIFFNESS".into(), q.longitudinal_stiffness),
            ("LATERAL_STIFFNESS".into(), q.lateral_stiffness),
        ];
        Ok(Box::new(Plain {
            tyre,
            opts: ro,
            params,
        }))
    }
}

/// Every candidate the diagnosis weighs, `none` first. The one registry:
/// the report, the CLI and the proof tests all take their list from here.
pub fn all() -> Vec<Box<dyn Candidate>> {
    vec![Box::new(NoneCandidate), Box::new(RelaxationCandidate)]
}

/// A candidate's evaluation.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Evaluation {
    pub name: String,
    pub n_params: usize,
    /// Relative drop of the held-out SSE against the baseline (1 = all gone).
    pub oos_gain: f64,
    /// BIC change against the baseline (negative = better).
    pub delta_bic: f64,
    pub parameters: Vec<(String, f64)>,
}

/// Fit every candidate on the even segments, score on the odd ones, and
/// report BIC on everything (see the module docs). Sorted best first.
pub fn evaluate(
    rec: &Recording,
    baseline: &Tyre,
    opts: &ReplayOptions,
    candidates: &[&dyn Candidate],
) -> Result<Vec<(Evaluation, Box<dyn Fitted>)>> {
    let n = rec.samples.len();
    let mut fit_mask = vec![false; n];
    let mut test_mask = vec![false; n];
    for (k, g) in rec.segments.iter().enumerate() {
        let m = if k % 2 == 0 {
            &mut fit_mask
        } else {
            &mut test_mask
        };
        for x in m.iter_mut().take(g.end.min(n)).skip(g.start) {
            *x = true;
        }
    }
    let all: Vec<bool> = fit_mask
        .iter()
        .zip(&test_mask)
        .map(|(a, b)| *a || *b)
        .collect();
    let base = replay(rec, baseline, opts)?.sim;
    let (base_test, base_all) = (sse(rec, &base, &test_mask), sse(rec, &base, &all));
    let n_eff = (all.iter().filter(|x| **x).count() as f64 / 50.0).max(2.0);
    let bic = |s: f64, k: usize| n_eff * (s / n_eff).max(1e-300).ln() + k as f64 * n_eff.ln();
    let mut out = Vec::new();
    for c in candidates {
        let fitted = c.fit(rec, baseline, opts, &fit_mask)?;
        let sim = fitted.predict(rec)?;
        let (t, a) = (sse(rec, &sim, &test_mask), sse(rec, &sim, &all));
        out.push((
            Evaluation {
                name: c.name().into(),
                n_params: c.n_params(),
                oos_gain: if base_test > 0.0 {
                    1.0 - t / base_test
                } else {
                    0.0
                },
                delta_bic: bic(a, c.n_params()) - bic(base_all, 0),
                parameters: fitted.parameters(),
            },
            fitted,
        ));
    }
    out.sort_by(|a, b| b.0.oos_gain.total_cmp(&a.0.oos_gain));
    Ok(out)
}
