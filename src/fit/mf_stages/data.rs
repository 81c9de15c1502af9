//! data — the samples one stage fits ([`StageData`], [`gather`]): each
//! recording sample conditioned in the use mode the fit evaluates in
//! ([`USE_MODE`]), the measured channels beside it, and the spreads of
//! inclination and pressure that decide which terms the data can move.
//!
//! Must never: keep a sample with a non-finite input or channel, or let a
//! few stray samples widen a spread ([`robust_spread`]).

use super::Channel;
use crate::data::{Recording, Sample, SegmentKind};
use crate::fit::validity::Grid;
use crate::mf::{Conditions, MfInput, UseMode};
use crate::tir::MfParams;
use std::ops::Range;

/// Spread of the fitted data below which camber (pressure) terms are held:
/// 0.5° (5 kPa), well below any test plan's steps.
pub const CAMBER_SPREAD: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// Spread of inflation pressure below which pressure terms (PP*) are held:
/// 5 kPa, in Pa.
pub const PRESSURE_SPREAD: f64 = 5000.0;

/// Conditioned inputs and measured values of the samples one stage fits.
#[derive(Clone, Debug, Default)]
pub struct StageData {
    /// Inputs of each sample as conditioned in [`USE_MODE`] (limits applied),
    /// ISO-W, SI.
    pub conds: Vec<Conditions>,
    /// Measured channel per sample, one vector per channel of the stage.
    pub meas: Vec<Vec<f64>>,
    /// Spread of inclination over the samples (rad), between its 1st and
    /// 99th percentiles (a few stray samples do not widen it).
    pub gamma_spread: f64,
    /// Spread of inflation pressure over the samples (Pa), likewise.
    pub p_spread: f64,
    /// The range the MF's validity conditions must hold on
    /// ([`crate::fit::validity`]); `None`: no validity rows.
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
    /// Keep the samples whose conditions satisfy `keep` (spreads kept).
    pub fn retain(&mut self, keep: impl Fn(&Conditions) -> bool) {
        let on: Vec<bool> = self.conds.iter().map(&keep).collect();
        let pick = |v: &mut Vec<f64>| {
            let mut k = on.iter();
            v.retain(|_| *k.next().unwrap_or(&false));
        };
        self.meas.iter_mut().for_each(pick);
        let mut k = on.iter();
        self.conds.retain(|_| *k.next().unwrap_or(&false));
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
/// gives where it is used; [`crate::fit::validity`] keeps the caps of 1xx from
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
