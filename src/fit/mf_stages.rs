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
//! [`crate::mf::Model::solve`]). The Mz and combined-slip stages move no
//! pure-slip coefficient, so each sample's pure-slip terms are computed once
//! in `f64` ([`crate::mf::Model::pure_terms`]) and only what follows them
//! carries dual lanes ([`super::channels::eval_from`]); likewise the Mx
//! (My) stage takes the sample's Fy (Fx) as given.
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
//! This file holds the stage as a [`Problem`] ([`MfStage`]); which stages
//! there are and their parameter tables live in `kind`, the samples a stage
//! fits in `data`, and how a stage is solved (subsamples, starts, the
//! penalty continuation) in `strategy`.
//!
//! Must never: fit a scaling factor, move a camber (pressure) term when the
//! fitted data hold one inclination (pressure) only — those are held and
//! reported —, approximate a derivative by finite differences, or allocate
//! per sample.

use super::channels;
use super::grad_pure;
use super::problem::{par_rows, Param, Problem, RowJacobian};
use crate::mf::{Conditions, Form, Model, PureTerms, Real};
use crate::tir::keys::key_index;
use crate::tir::MfParams;
use nalgebra::{Const, DMatrixViewMut, U1};
use num_dual::{Derivative, DualSVec64};

mod data;
mod kind;
mod strategy;

pub use data::{
    conditions_of, gather, StageData, CAMBER_SPREAD, FIT_MODE, PRESSURE_SPREAD, USE_MODE,
};
pub use kind::StageKind;
pub use strategy::{
    fit_stage, neutral_start, COARSE_SAMPLES, CONTINUATION, RACE_SAMPLES, START_ITERATIONS,
};

/// A channel the Magic Formula predicts (the residual stage's one typed channel).
pub use crate::residual::Channel;

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
    /// Fx, Fy and Mz stages whose every parameter is an aligning-torque or
    /// combined-slip coefficient (the Mz and combined tables): the
    /// pure-slip terms of every sample, which θ cannot move
    /// ([`channels::eval_from`]).
    pure: Option<Vec<PureTerms>>,
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
            Channel::Mx => Some((StageKind::Mx.table(), Channel::Fy)),
            Channel::My => Some((StageKind::My.table(), Channel::Fx)),
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
        let pure = (given.is_none()
            && matches!(channel, Channel::Fx | Channel::Fy | Channel::Mz)
            && moves_no_pure_term(&params))
        .then(|| {
            let model = Model::new(base.clone(), form);
            data.conds.iter().map(|c| model.pure_terms(c)).collect()
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
            pure,
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

/// Whether every parameter is an aligning-torque or combined-slip
/// coefficient (the Mz and combined stages' tables, by name): none of them
/// enters [`Model::pure_terms`] (`tests/fit_channels.rs` perturbs each).
fn moves_no_pure_term(params: &[Param]) -> bool {
    let tables = [StageKind::Mz.table(), StageKind::Combined.table()];
    params.iter().all(|p| {
        tables
            .iter()
            .any(|t| t.iter().any(|e| e.0.eq_ignore_ascii_case(&p.name)))
    })
}

/// A stage's `channel` at its sample `i` (conditions `c`), from the
/// sample's pure-slip terms or the force its moment needs where the stage
/// keeps them ([`MfStage`]'s `pure`, `given`).
#[inline(always)]
fn channel_at<T: Real>(
    model: &Model<T>,
    c: &Conditions,
    channel: Channel,
    given: Option<&[f64]>,
    pure: Option<&[PureTerms]>,
    i: usize,
) -> T {
    match pure {
        Some(t) => channels::eval_from(model, c, channel, &t[i]),
        None => channels::eval_given(model, c, channel, given.map(|g| g[i])),
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
    pure: Option<&'s [PureTerms]>,
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
            let y = channel_at(
                model,
                &self.conds[i],
                self.channel,
                self.given,
                self.pure,
                i,
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
        let pure = self.pure.as_deref();
        par_rows(self.threads, 0, r, None, &|first, r: &mut [f64], _| {
            for (k, rk) in r.iter_mut().enumerate() {
                let i = first + k;
                let y = channel_at(&model, &self.conds[i], self.channel, given, pure, i);
                *rk = y - self.meas[i];
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
            pure: self.pure.as_deref(),
        }))
    }
    fn threads(&self) -> usize {
        self.threads
    }
}
