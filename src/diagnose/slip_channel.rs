//! slip_channel — whether the recorded slip ratio was computed with the
//! tyre's own effective rolling radius: the `rolling_radius` finding that the
//! forces alone cannot make.
//!
//! A rig reports its slip ratio as SR = Ω·R/V − 1 with some radius R of its
//! own (a constant, the loaded radius, a nominal Re(Fz)). The tyre's
//! effective rolling radius is what the wheel shows when nothing drives it:
//! Re = V/Ω at free rolling (Pacejka, *Tire and Vehicle Dynamics*, 3rd ed.,
//! §2.2 and §9.2.1). On the pure lateral sweeps (no drive or brake torque),
//! at |α| < 1°, SR therefore reads Re_R/Re − 1 ≈ (R − Re)/Re: constant over
//! the loads when R follows the tyre's radius (a constant offset is a zero
//! error of the rig), and varying with load when it does not. A drive/brake
//! run has no such sweeps; there free rolling is where a sweep's Fx crosses
//! zero, and SR there reads the same (see [`check`]).
//!
//! Read as slip by a model, that load-dependent SR is a longitudinal force
//! error of K_x(Fz)·ΔSR (K_x the slip stiffness). A Magic Formula fit hides
//! most of it in its horizontal shift S_Hx = PHX1 + PHX2·dfz (Pacejka eq.
//! 4.E17): a slip offset and a radius error are the same to the forces, so
//! no force residual names it; the two radius measurements do.
//!
//! The finding ([`check`]): per load level of the free-rolling samples, the
//! median SR and the median V/Ω; found when the load-dependent part of SR,
//! weighted by the baseline tyre's own K_x/Fz at that load, exceeds
//! [`FORCE_SHARE`] at some level. The extension ([`SlipChannel::extended`]):
//! the effective-rolling-radius keys (Q_RE0, DREFF, FREFF) fitted to the
//! free-rolling V/Ω, and PHX1, PHX2 re-centred by the slip the new radius
//! takes away, so that the FMU fed the wheel speed gives the slip the tyre
//! sees and the forces the fit found.
//!
//! Must never: read a radius from samples under drive or brake torque (the
//! pure lateral sweeps; without enough of them only the zero-Fx point of
//! the drive/brake sweeps), judge a recording with fewer than
//! [`MIN_LEVELS`] load levels, or call a constant SR offset a radius.

use crate::data::{Recording, SegmentKind};
use crate::error::Result;
use crate::mf::{MfInput, Tyre, UseMode};
use crate::stats::median;
use serde::Serialize;

/// Largest load-dependent slip-channel error, in longitudinal force per
/// load (K_x·|SR − mean SR|/Fz at some level), that is not a finding: 5 % of
/// Fz, a force error no fitted tyre hides (a measured slip stiffness is
/// good to a few %), and ten times the quantisation of a four-decimal SR
/// channel at K_x = 20·Fz.
pub const FORCE_SHARE: f64 = 0.05;
/// Fewest load levels: two levels cannot tell a load law from an offset.
pub const MIN_LEVELS: usize = 3;
/// Fewest free-rolling samples per load level.
const MIN_SAMPLES: usize = 50;

/// One load level of the free-rolling samples.
#[derive(Clone, Debug, Serialize)]
pub struct Level {
    /// Median load (N).
    pub fz: f64,
    /// Samples.
    pub n: usize,
    /// Median recorded slip ratio.
    pub sr: f64,
    /// Median V/Ω: the tyre's effective rolling radius (m).
    pub re_free: f64,
    /// The radius SR was computed with, V·(1 + SR)/Ω (m).
    pub re_slip: f64,
    /// The baseline file's Re at this level (m): the FMU's radius.
    pub re_base: f64,
    /// The extended file's Re (m; NaN until [`SlipChannel::set_extended`]).
    pub re_extended: f64,
    /// The baseline's longitudinal slip stiffness at this load (N).
    pub kx: f64,
    /// K_x·|SR − mean SR|/Fz.
    pub force_share: f64,
    #[serde(skip)]
    vx: f64,
    #[serde(skip)]
    omega: f64,
    #[serde(skip)]
    p: f64,
    #[serde(skip)]
    gamma: f64,
}

/// The slip channel against the free-rolling radius (see the module docs).
#[derive(Clone, Debug, Serialize)]
pub struct SlipChannel {
    /// Where free rolling was read: "pure lateral sweeps, |α| < 1°" or, in a
    /// recording without enough of them, "zero-Fx crossings of the drive/brake
    /// sweeps, |α| < 1°".
    pub from: &'static str,
    /// The Fx sensor zero error fitted out of a drive/brake read (N; None
    /// on the lateral sweeps, which do not read Fx) ([`check`]).
    pub fx_zero: Option<f64>,
    /// Free rolling per load level, lightest first (at least [`MIN_LEVELS`]).
    pub levels: Vec<Level>,
    /// Largest minus smallest level SR.
    pub sr_span: f64,
    /// Largest [`Level::force_share`].
    pub force_share: f64,
    /// Whether this is a finding ([`FORCE_SHARE`]).
    pub found: bool,
}

/// Compare the recorded slip ratio with the free-rolling radius; None when
/// the recording has no SR channel, no wheel speed, or fewer than
/// [`MIN_LEVELS`] load levels of free rolling. Free rolling is read on the
/// pure lateral sweeps; a recording with fewer than [`MIN_LEVELS`] levels
/// of them (a drive/brake run) is read at the zero-Fx crossings of its pure
/// drive/brake sweeps instead ([`SlipChannel::from`] says which).
pub fn check(rec: &Recording, tyre: &Tyre) -> Option<SlipChannel> {
    let sr = rec.extra("SR")?;
    if !rec.has("omega") {
        return None;
    }
    let fmax = rec
        .samples
        .iter()
        .filter(|s| s.fz.is_finite())
        .map(|s| s.fz)
        .fold(0.0, f64::max);
    let mut levels = lateral_levels(rec, sr, fmax, tyre);
    let mut from = "pure lateral sweeps, |α| < 1°";
    let mut fx_zero = None;
    if levels.len() < MIN_LEVELS {
        levels = drive_brake_levels(rec, sr, fmax, tyre);
        from = "zero-Fx crossings of the drive/brake sweeps, |α| < 1°";
        // The Fx zero error is fitted beside the load law: one level more.
        if levels.len() <= MIN_LEVELS || levels.iter().any(|l| !(l.kx > 0.0)) {
            return None;
        }
        fx_zero = Some(remove_fx_zero(&mut levels)?);
    }
    if levels.len() < MIN_LEVELS || levels.iter().any(|l| !l.kx.is_finite()) {
        return None;
    }
    let mean = levels.iter().map(|l| l.sr).sum::<f64>() / levels.len() as f64;
    for l in &mut levels {
        l.re_base = SlipChannel::re(tyre, l);
        l.force_share = (l.kx * (l.sr - mean) / l.fz).abs();
    }
    let share = levels.iter().map(|l| l.force_share).fold(0.0, f64::max);
    let (lo, hi) = levels
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, l| {
            (a.0.min(l.sr), a.1.max(l.sr))
        });
    Some(SlipChannel {
        from,
        fx_zero,
        levels,
        sr_span: hi - lo,
        force_share: share,
        found: share > FORCE_SHARE,
    })
}

/// The free-rolling samples' load levels of the pure lateral sweeps: per
/// level the median SR and V/Ω of the samples at |α| < 1° (no drive or
/// brake torque, so V/Ω is the effective rolling radius).
fn lateral_levels(rec: &Recording, sr: &[f64], fmax: f64, tyre: &Tyre) -> Vec<Level> {
    // (fz, sr, V/Ω, vx, Ω, p, γ) of each level's free-rolling samples.
    let groups = by_level(rec, SegmentKind::PureLateral, fmax, |i| {
        let s = &rec.samples[i];
        let r = sr.get(i).copied().unwrap_or(f64::NAN);
        upright_rolling(s, r, fmax, 0.1)
            .then(|| [s.fz, r, s.vx / s.omega, s.vx, s.omega, s.p, s.gamma])
    });
    let col = |g: &[[f64; 7]], k: usize| median(g.iter().map(|x| x[k])).unwrap_or(f64::NAN);
    groups
        .iter()
        .filter(|g| g.len() >= MIN_SAMPLES)
        .map(|g| {
            let (fz, srm, re, vx, om) = (col(g, 0), col(g, 1), col(g, 2), col(g, 3), col(g, 4));
            level(tyre, g.len(), [fz, srm, re, vx, om, col(g, 5), col(g, 6)])
        })
        .collect()
}

/// Whether sample `s`, with recorded slip ratio `sr`, can be read for the
/// radius: |α| < 1°, loaded above 10 % of the largest load, rolling (Ω and
/// V above 1), and |SR| below `sr_max`.
fn upright_rolling(s: &crate::data::Sample, sr: f64, fmax: f64, sr_max: f64) -> bool {
    s.alpha.abs() < 1f64.to_radians()
        && s.fz > 0.1 * fmax
        && s.omega > 1.0
        && s.vx > 1.0
        && sr.is_finite()
        && sr.abs() < sr_max
}

/// Half-width of the slip window about free rolling in which a drive/brake
/// sweep's Fx is taken as linear in SR: 2 %, inside the linear range of
/// any tyre's Fx(κ) (the peak lies at 5–20 %).
const LINEAR_SR: f64 = 0.02;

/// The free-rolling point of the pure drive/brake sweeps at |α| < 1°, for
/// a recording without free-rolling lateral sweeps (a drive/brake run):
/// per load level, the SR at which Fx crosses zero (a straight line
/// Fx = a + b·SR through the samples with |SR| < [`LINEAR_SR`]; zero
/// longitudinal force is free rolling) and the radius SR was computed with,
/// R = V·(1 + SR)/Ω, which does not move with the slip (median over the
/// same samples); the tyre's effective rolling radius there is
/// R/(1 + SR₀). The samples under torque are used only through that line.
fn drive_brake_levels(rec: &Recording, sr: &[f64], fmax: f64, tyre: &Tyre) -> Vec<Level> {
    // (fz, sr, V(1+SR)/Ω, vx, fx, p, γ) of each level's near-zero-slip samples.
    let groups = by_level(rec, SegmentKind::PureLongitudinal, fmax, |i| {
        let s = &rec.samples[i];
        let r = sr.get(i).copied().unwrap_or(f64::NAN);
        (upright_rolling(s, r, fmax, LINEAR_SR) && s.fx.is_finite()).then(|| {
            [
                s.fz,
                r,
                s.vx * (1.0 + r) / s.omega,
                s.vx,
                s.fx,
                s.p,
                s.gamma,
            ]
        })
    });
    let col = |g: &[[f64; 7]], k: usize| median(g.iter().map(|x| x[k])).unwrap_or(f64::NAN);
    groups
        .iter()
        .filter(|g| g.len() >= MIN_SAMPLES)
        .filter_map(|g| {
            // Least squares Fx = a + b·SR.
            let n = g.len() as f64;
            let (mx, my) = (
                g.iter().map(|x| x[1]).sum::<f64>() / n,
                g.iter().map(|x| x[4]).sum::<f64>() / n,
            );
            let sxx: f64 = g.iter().map(|x| (x[1] - mx).powi(2)).sum();
            let sxy: f64 = g.iter().map(|x| (x[1] - mx) * (x[4] - my)).sum();
            // The line needs slip spread (a sweep, not a hold) and a
            // positive slope (drive force with drive slip).
            if !(sxx > n * (0.25 * LINEAR_SR).powi(2) && sxy > 0.0) {
                return None;
            }
            let b = sxy / sxx;
            let sr0 = mx - my / b;
            if !(sr0.abs() < LINEAR_SR) {
                return None;
            }
            let (fz, r, vx) = (col(g, 0), col(g, 2), col(g, 3));
            let re = r / (1.0 + sr0);
            Some(level(
                tyre,
                g.len(),
                [fz, sr0, re, vx, vx / re, col(g, 5), col(g, 6)],
            ))
        })
        .collect()
}

/// Takes the Fx sensor zero error out of drive/brake levels; returns it
/// (N). A zero error ΔFx moves the zero-Fx crossing by −ΔFx/K_x, most at
/// the smallest load (−44 N reads as a 0.4 % slip at 0.8 kN on a car
/// tyre: a radius "found" from a sensor zero), while a radius that is not
/// the tyre's moves it by R/Re(Fz) − 1, smooth in the load (Re falls about
/// linearly with Fz over a test's loads: Pacejka, *Tire and Vehicle
/// Dynamics*, 3rd ed., eq. 9.236 with ρ = Fz/C_z). So the levels' SR is
/// fitted as c + d·(Fz − F̄z) − ΔFx/K_x (least squares; c a zero error of
/// SR, as on the lateral sweeps) and ΔFx/K_x is added back at each level,
/// with the free-rolling radius re-read there. None when the three terms
/// cannot be told apart (a singular fit).
fn remove_fx_zero(levels: &mut [Level]) -> Option<f64> {
    use nalgebra::{DMatrix, DVector};
    let n = levels.len();
    let fbar = levels.iter().map(|l| l.fz).sum::<f64>() / n as f64;
    let cols = |l: &Level| [1.0, l.fz - fbar, 1.0 / l.kx];
    // Columns scaled to unit norm, so that one tolerance fits all three.
    let norm: Vec<f64> = (0..3)
        .map(|j| {
            levels
                .iter()
                .map(|l| cols(l)[j].powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    if norm.iter().any(|v| !(*v > 0.0)) {
        return None;
    }
    let a = DMatrix::from_fn(n, 3, |i, j| cols(&levels[i])[j] / norm[j]);
    let y = DVector::from_fn(n, |i, _| levels[i].sr);
    let svd = a.svd(true, true);
    // Columns that one load law and one Fx zero cannot tell apart.
    if svd.singular_values.min() < 1e-6 * svd.singular_values.max() {
        return None;
    }
    let x = svd.solve(&y, 0.0).ok()?;
    // SR measured = SR true − ΔFx/K_x: the 1/K_x coefficient is −ΔFx.
    let zero = -x[2] / norm[2];
    if !zero.is_finite() {
        return None;
    }
    for l in levels.iter_mut() {
        l.sr += zero / l.kx;
        l.re_free = l.re_slip / (1.0 + l.sr);
    }
    Some(zero)
}

/// The rows `keep` gives for the samples of the segments of `kind`, grouped
/// by the segments' load set points (within 5 % of the largest load) and
/// ordered by load.
fn by_level(
    rec: &Recording,
    kind: SegmentKind,
    fmax: f64,
    keep: impl Fn(usize) -> Option<[f64; 7]>,
) -> Vec<Vec<[f64; 7]>> {
    let mut groups: Vec<(f64, Vec<[f64; 7]>)> = Vec::new();
    for g in rec
        .segments
        .iter()
        .filter(|g| g.kind == kind && g.fz.is_finite())
    {
        let k = match groups
            .iter()
            .position(|(f, _)| (f - g.fz).abs() < 0.05 * fmax)
        {
            Some(k) => k,
            None => {
                groups.push((g.fz, Vec::new()));
                groups.len() - 1
            }
        };
        groups[k]
            .1
            .extend((g.start..g.end.min(rec.samples.len())).filter_map(&keep));
    }
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    groups.into_iter().map(|(_, v)| v).collect()
}

/// A level from its `n` samples' [fz, SR, V/Ω, vx, Ω, p, γ] at free
/// rolling, with the baseline's slip stiffness there.
fn level(tyre: &Tyre, n: usize, v: [f64; 7]) -> Level {
    let [fz, srm, re, vx, om, p, gamma] = v;
    let fx = |k: f64| {
        tyre.evaluate(
            &MfInput {
                fz,
                kappa: k,
                alpha: 0.0,
                gamma: if gamma.is_finite() { gamma } else { 0.0 },
                phit: 0.0,
                vx,
                p: if p.is_finite() { p } else { 0.0 },
                omega: om,
            },
            UseMode::default(),
        )
        .fx
    };
    let kx = (fx(0.002) - fx(-0.002)) / 0.004;
    Level {
        fz,
        n,
        sr: srm,
        re_free: re,
        re_slip: re * (1.0 + srm),
        re_base: f64::NAN,
        re_extended: f64::NAN,
        kx,
        force_share: f64::NAN,
        vx,
        omega: om,
        p,
        gamma,
    }
}

impl SlipChannel {
    /// Record the extended file's Re at every level (for the report).
    pub fn set_extended(&mut self, ext: &Tyre) {
        for k in 0..self.levels.len() {
            let r = Self::re(ext, &self.levels[k]);
            self.levels[k].re_extended = r;
        }
    }

    /// The effective rolling radius of `t` at a level (m).
    fn re(t: &Tyre, l: &Level) -> f64 {
        t.slip_properties(
            &MfInput {
                fz: l.fz,
                kappa: 0.0,
                alpha: 0.0,
                gamma: if l.gamma.is_finite() { l.gamma } else { 0.0 },
                phit: 0.0,
                vx: l.vx,
                p: if l.p.is_finite() { l.p } else { 0.0 },
                omega: l.omega,
            },
            UseMode::default(),
        )
        .re
    }

    /// The baseline with the tyre's own Re(Fz) (Q_RE0, DREFF, FREFF fitted
    /// to the levels' V/Ω for each BREFF of a grid; Re is linear in them, so
    /// one least-squares step on a finite-difference Jacobian is exact; the
    /// BREFF of least error kept) and PHX1, PHX2 re-centred by
    /// the free-rolling slip the new radius changes (see the module docs).
    pub fn extended(&self, base: &Tyre) -> Result<Tyre> {
        let keys: Vec<&str> = ["Q_RE0", "DREFF", "FREFF"]
            .into_iter()
            .filter(|k| base.params().get(k).is_some())
            .collect();
        let with = |breff: f64, vals: &[f64]| -> Result<Tyre> {
            let mut p = base.params().clone();
            if p.get("BREFF").is_some() {
                p.set("BREFF", breff)?;
            }
            for (k, v) in keys.iter().zip(vals) {
                p.set(k, *v)?;
            }
            Tyre::new(p)
        };
        let x0: Vec<f64> = keys
            .iter()
            .map(|k| base.params().get(k).unwrap_or(0.0))
            .collect();
        let m = self.levels.len();
        // BREFF (the saturation load of DREFF's term) on a grid, the file's
        // own first; Q_RE0, DREFF, FREFF by least squares at each.
        let b0 = base.params().get("BREFF").unwrap_or(0.0);
        let mut best: Option<(f64, Tyre)> = None;
        for breff in [b0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0] {
            let t0 = with(breff, &x0)?;
            let r0: Vec<f64> = self.levels.iter().map(|l| Self::re(&t0, l)).collect();
            let mut jac = nalgebra::DMatrix::<f64>::zeros(m, keys.len());
            for j in 0..keys.len() {
                let mut x = x0.clone();
                x[j] += 1e-3;
                let t = with(breff, &x)?;
                for (i, l) in self.levels.iter().enumerate() {
                    jac[(i, j)] = (Self::re(&t, l) - r0[i]) / 1e-3;
                }
            }
            let y = nalgebra::DVector::from_iterator(
                m,
                self.levels.iter().zip(&r0).map(|(l, r)| l.re_free - r),
            );
            // Columns that do not act (DREFF with BREFF = 0) are dropped by
            // the SVD's tolerance.
            let Ok(step) = jac.svd(true, true).solve(&y, 1e-12) else {
                continue;
            };
            let x: Vec<f64> = x0.iter().zip(step.iter()).map(|(a, d)| a + d).collect();
            let t = with(breff, &x)?;
            let sse: f64 = self
                .levels
                .iter()
                .map(|l| (Self::re(&t, l) - l.re_free).powi(2))
                .sum();
            if sse.is_finite() && best.as_ref().is_none_or(|b| sse < b.0) {
                best = Some((sse, t));
            }
        }
        let Some((_, mut t)) = best else {
            return Err(crate::Error::Other(
                "rolling radius fit: no least-squares solution".into(),
            ));
        };
        let r0: Vec<f64> = self.levels.iter().map(|l| Self::re(base, l)).collect();
        // Re-centre the horizontal shift of Fx: at free rolling the FMU's κ
        // changes by Δ = Re_base/V·Ω − Re_new/V·Ω; S_Hx takes it back.
        let p = t.params();
        let fz0 = p.p.fnomin * p.get("LFZO").unwrap_or(1.0);
        let lhx = p.get("LHX").unwrap_or(1.0);
        if fz0 > 0.0 && lhx != 0.0 {
            let (mut xs, mut ds) = (Vec::new(), Vec::new());
            for (l, rb) in self.levels.iter().zip(&r0) {
                xs.push((l.fz - fz0) / fz0);
                ds.push((rb - Self::re(&t, l)) / l.re_free);
            }
            if let Some((c0, c1)) = crate::data::slip::fit_line(&xs, &ds) {
                let mut q = t.params().clone();
                let (h1, h2) = (q.get("PHX1").unwrap_or(0.0), q.get("PHX2").unwrap_or(0.0));
                q.set("PHX1", h1 + c0 / lhx)?;
                q.set("PHX2", h2 + c1 / lhx)?;
                t = Tyre::new(q)?;
            }
        }
        Ok(t)
    }

    /// The finding in words, with the figures a tyre engineer checks.
    pub fn words(&self, base: &Tyre, ext: &Tyre) -> String {
        let (first, last) = (&self.levels[0], &self.levels[self.levels.len() - 1]);
        let worst = self
            .levels
            .iter()
            .max_by(|a, b| a.force_share.total_cmp(&b.force_share))
            .unwrap_or(first);
        let g = |t: &Tyre, k: &str| t.params().get(k).unwrap_or(f64::NAN);
        format!(
            "rolling_radius: the recorded slip ratio SR was computed with a rolling radius that is not the tyre's. At free rolling ({}{}) SR reads {:+.2} % at {:.2} kN and {:+.2} % at {:.2} kN, while the wheel's own effective radius V/Ω goes from {:.1} to {:.1} mm and the radius SR assumes from {:.1} to {:.1} mm. Read as slip, that is a load-dependent Fx of up to {:.0} % of Fz (K_x·ΔSR at {:.2} kN); the baseline absorbed it in its horizontal shift of Fx (PHX1 {:.4}, PHX2 {:.4}: a slip offset and a radius are the same to the forces). The extended file carries the tyre's own Re(Fz) (Q_RE0 {:.4} → {:.4}, DREFF {:.3} → {:.3}, FREFF {:.3} → {:.3}) with PHX1 {:.4}, PHX2 {:.4}, so the FMU fed the wheel speed gives the slip the tyre sees.",
            self.from,
            self.fx_zero.map_or(String::new(), |z| format!(
                "; an Fx zero error of {z:+.0} N fitted beside the load law and taken out"
            )),
            100.0 * first.sr,
            first.fz / 1e3,
            100.0 * last.sr,
            last.fz / 1e3,
            1e3 * first.re_free,
            1e3 * last.re_free,
            1e3 * first.re_slip,
            1e3 * last.re_slip,
            100.0 * self.force_share,
            worst.fz / 1e3,
            g(base, "PHX1"),
            g(base, "PHX2"),
            g(base, "Q_RE0"),
            g(ext, "Q_RE0"),
            g(base, "DREFF"),
            g(ext, "DREFF"),
            g(base, "FREFF"),
            g(ext, "FREFF"),
            g(ext, "PHX1"),
            g(ext, "PHX2"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Sample, Segment};
    use crate::tir::TyreParams;

    /// Pure lateral sweeps at `loads`, 200 samples each around α = 0, the
    /// wheel rolling freely at the radius `re(Fz)`, SR computed by the rig
    /// with the radius `r_rig(Fz)`.
    fn rig(loads: &[f64], re: impl Fn(f64) -> f64, r_rig: impl Fn(f64) -> f64) -> Recording {
        let (mut samples, mut sr, mut segments) = (Vec::new(), Vec::new(), Vec::new());
        let v = 11.0;
        for &fz in loads {
            let start = samples.len();
            for k in 0..200 {
                let alpha = (k as f64 / 200.0 - 0.5).to_radians();
                let omega = v / re(fz);
                samples.push(Sample {
                    time: samples.len() as f64 * 0.01,
                    vx: v,
                    omega,
                    fz,
                    alpha,
                    p: 2.2e5,
                    ..Default::default()
                });
                sr.push(omega * r_rig(fz) / v - 1.0);
            }
            segments.push(Segment {
                start,
                end: samples.len(),
                kind: SegmentKind::PureLateral,
                fz,
                gamma: 0.0,
                p: 2.2e5,
                vx: v,
                alpha: 0.0,
            });
        }
        let n = samples.len();
        Recording {
            source: "test".into(),
            samples,
            channels: ["time", "Vx", "omega", "Fz", "alpha", "P", "Fy"]
                .map(String::from)
                .to_vec(),
            extra: vec![("SR".into(), sr)],
            segments,
            sweep_dir: vec![0; n],
            t_in_segment: vec![0.0; n],
        }
    }

    fn tyre() -> Tyre {
        Tyre::new(TyreParams::builtin()).unwrap()
    }

    /// SR from a constant radius while the tyre's radius falls 2 mm per kN:
    /// a finding, and the extension gives the tyre's radius (within 0.05 mm
    /// at every level: Re is linear in the fitted keys) and, at free
    /// rolling, the same Fx as the baseline fed its own slip (within 3 % of
    /// Fz: S_Hx is linear in dfz, the baseline's Re is not quite).
    #[test]
    fn a_constant_rig_radius_is_a_finding() {
        let re = |fz: f64| 0.31 - 2e-6 * fz;
        let rec = rig(&[1000.0, 3000.0, 5000.0], re, |_| 0.304);
        let t = tyre();
        let c = check(&rec, &t).unwrap();
        assert_eq!(c.levels.len(), 3);
        assert!((c.sr_span - (0.304 / 0.300 - 0.304 / 0.308)).abs() < 1e-9);
        assert!(c.found, "share {}", c.force_share);
        let e = c.extended(&t).unwrap();
        for l in &c.levels {
            assert!((SlipChannel::re(&e, l) - re(l.fz)).abs() < 5e-5);
            let fx = |t: &Tyre| {
                let k = SlipChannel::re(t, l) / l.re_free - 1.0;
                t.evaluate(
                    &MfInput {
                        fz: l.fz,
                        kappa: k,
                        vx: l.vx,
                        p: l.p,
                        omega: l.omega,
                        ..Default::default()
                    },
                    UseMode::default(),
                )
                .fx
            };
            assert!(
                (fx(&e) - fx(&t)).abs() < 0.03 * l.fz,
                "Fz {}: {} vs {}",
                l.fz,
                fx(&e),
                fx(&t)
            );
        }
        assert!(c.words(&t, &e).contains("rolling_radius"));
    }

    /// SR computed with the tyre's own radius, plus a constant rig offset:
    /// no finding.
    #[test]
    fn the_tyres_own_radius_with_an_offset_is_not() {
        let re = |fz: f64| 0.31 - 2e-6 * fz;
        let rec = rig(&[1000.0, 3000.0, 5000.0], re, |fz| re(fz) * 0.996);
        let c = check(&rec, &tyre()).unwrap();
        assert!(c.sr_span < 1e-9);
        assert!(!c.found && c.force_share < 1e-6, "{}", c.force_share);
    }

    /// A drive/brake run (no lateral sweeps): per load, a slip sweep at
    /// α = 0 through true slip κ ∈ [−5 %, +5 %] with Fx = K_x·κ + `zero`
    /// (K_x the test tyre's own, so that the zero error's slip is exactly
    /// −zero/K_x), the wheel at Ω = V·(1 + κ)/Re(Fz) and the SR the rig
    /// computes with its radius.
    fn drive_rig(
        loads: &[f64],
        re: impl Fn(f64) -> f64,
        r_rig: impl Fn(f64) -> f64,
        zero: f64,
    ) -> Recording {
        let mut rec = rig(&[], &re, &r_rig);
        let mut sr = Vec::new();
        let v = 11.0;
        for &fz in loads {
            let kx = level(&tyre(), 1, [fz, 0.0, re(fz), v, v / re(fz), 2.2e5, 0.0]).kx;
            let start = rec.samples.len();
            for k in 0..400 {
                let kappa = 0.1 * (k as f64 / 400.0 - 0.5);
                let omega = v * (1.0 + kappa) / re(fz);
                rec.samples.push(Sample {
                    time: rec.samples.len() as f64 * 0.01,
                    vx: v,
                    omega,
                    fz,
                    fx: kx * kappa + zero,
                    p: 2.2e5,
                    ..Default::default()
                });
                sr.push(omega * r_rig(fz) / v - 1.0);
            }
            rec.segments.push(Segment {
                start,
                end: rec.samples.len(),
                kind: SegmentKind::PureLongitudinal,
                fz,
                gamma: 0.0,
                p: 2.2e5,
                vx: v,
                alpha: 0.0,
            });
        }
        let n = rec.samples.len();
        rec.extra = vec![("SR".into(), sr)];
        rec.sweep_dir = vec![0; n];
        rec.t_in_segment = vec![0.0; n];
        rec
    }

    /// Without lateral sweeps the radius is read where the drive/brake
    /// sweeps' Fx crosses zero, with an Fx zero error fitted beside the load
    /// law: a constant rig radius against an Re falling 3 % over the loads
    /// is found whatever the zero error, with the tyre's own radius at every
    /// level within 0.2 mm and the zero error within 10 N (R/Re(Fz) − 1 is
    /// not quite linear in Fz, and the 1/K_x term takes up some of its
    /// curvature: −5.7 N without a zero error); the tyre's own radius with
    /// a constant SR offset is not found, though a 60 N zero error alone
    /// moves the crossing at 0.8 kN by K_x·ΔSR = 60 N, 7.5 % of its load —
    /// the zero error comes back within 0.3 N there (SR = 0.996·(1 + κ) − 1
    /// scales κ by 0.996, and the crossing's 1/K_x term with it).
    #[test]
    fn a_drive_brake_run_is_read_at_zero_fx() {
        let re = |fz: f64| 0.31 - 2e-6 * fz;
        let loads = [800.0, 1600.0, 2400.0, 4000.0, 5600.0];
        for zero in [0.0, 60.0] {
            let c = check(&drive_rig(&loads, re, |_| 0.304, zero), &tyre()).unwrap();
            assert!(c.from.contains("drive/brake"), "{}", c.from);
            assert_eq!(c.levels.len(), 5);
            for l in &c.levels {
                assert!(
                    (l.re_free - re(l.fz)).abs() < 2e-4,
                    "{} vs {}",
                    l.re_free,
                    re(l.fz)
                );
                assert!((l.re_slip - 0.304).abs() < 1e-6);
            }
            assert!(c.found, "share {}", c.force_share);
            assert!((c.fx_zero.unwrap() - zero).abs() < 10.0, "{:?}", c.fx_zero);
            let c = check(&drive_rig(&loads, re, |fz| re(fz) * 0.996, zero), &tyre()).unwrap();
            assert!(!c.found && c.force_share < 1e-3, "{}", c.force_share);
            assert!((c.fx_zero.unwrap() - zero).abs() < 0.3, "{:?}", c.fx_zero);
        }
        // Four levels fit three terms with one to spare; three do not.
        assert!(check(&drive_rig(&loads[..3], re, |_| 0.304, 0.0), &tyre()).is_none());
    }

    /// Two load levels cannot tell a load law from an offset.
    #[test]
    fn two_levels_are_not_judged() {
        let rec = rig(&[1000.0, 5000.0], |fz| 0.31 - 2e-6 * fz, |_| 0.304);
        assert!(check(&rec, &tyre()).is_none());
    }
}
