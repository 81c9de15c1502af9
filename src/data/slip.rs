//! slip — longitudinal slip from wheel speed:
//! κ = Ω·Re/Vx − 1 with Vx = V·cos α or V per [`super::slip_reference`] (Pacejka, *Tyre and Vehicle
//! Dynamics*, 3rd ed., eq. 2.9/§2.2: κ = −Vsx/Vx with Vsx = Vx − Ω·Re),
//! with the effective rolling radius Re chosen by [`ReChoice`].
//!
//! Rig caveat: flat-belt rigs (Calspan TIRF) report RE as V/Ω. That equals
//! the effective rolling radius only while the tyre rolls freely; under drive
//! or brake torque it follows the slip itself (κ from it would be ≈ 0), which
//! is why the default fits Re(Fz) on the free-rolling samples only.
//!
//! Where the rig also records its own slip ratio SR (TTC), the default reads
//! the radius that SR was computed with, Vx·(1 + SR)/Ω, as a smooth function
//! of load and wheel speed ([`slip_channel_radius`]): κ then follows the
//! recording's slip ratio, as a user of the data reads it (κ is SR itself
//! on the rolling samples, see [`compute_kappa`]), while staying a
//! κ = Ω·Re/Vx − 1 of one radius function the tyre file can carry. Whether
//! that radius is the tyre's own free-rolling radius is a question for the
//! diagnosis (`rolling_radius`), not for the loader.
//!
//! Must never: divide by a zero speed (such samples get κ = NaN and are then
//! dropped and counted by the loader).

use super::{ReChoice, Sample};
use crate::mf::{MfInput, UseMode};

/// Least-squares line y = a + b·x (b = 0 when x has no spread).
pub fn fit_line(x: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = x.len() as f64;
    if x.is_empty() {
        return None;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let b = if sxx > 1e-12 * n * (mx * mx + 1.0) {
        sxy / sxx
    } else {
        0.0
    };
    Some((my - b * mx, b))
}

/// Re(Fz) = a + b·Fz fitted on free-rolling samples (|α| < 1°, |Fx| < 5 % Fz,
/// finite RE). Needs at least 20 such samples.
pub fn free_rolling_re(samples: &[Sample], re: &[f64]) -> Option<(f64, f64)> {
    let lim = 1f64.to_radians();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (s, &r) in samples.iter().zip(re) {
        let fx_ok = !s.fx.is_finite() || s.fx.abs() < 0.05 * s.fz.abs();
        if s.alpha.abs() < lim && fx_ok && r.is_finite() && r > 0.0 && s.fz > 0.0 {
            x.push(s.fz);
            y.push(r);
        }
    }
    if x.len() < 20 {
        return None;
    }
    fit_line(&x, &y)
}

/// Effective and loaded radius (Re, Rl) from a model evaluation, with
/// fallbacks where the model reports none (non-finite, implausible, or
/// exactly the unloaded radius under load): Rl = R0 − Fz/Cz and
/// Re = R0 − Fz/(3·Cz) (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed.,
/// §9.2.1: Re lies about a third of the deflection below R0).
pub fn model_radii(tyre: &crate::mf::Tyre, fz: f64, re: f64, rl: f64) -> (f64, f64) {
    let p = &tyre.params().p;
    let r0 = p.unloaded_radius;
    let cz = if p.vertical_stiffness > 0.0 {
        p.vertical_stiffness
    } else {
        2e5
    };
    let defl = fz.max(0.0) / cz;
    let rl = if rl.is_finite() && rl > 0.2 * r0 {
        rl
    } else {
        r0 - defl
    };
    let re = if re.is_finite() && re > 0.2 * r0 && ((re - r0).abs() > 1e-12 || defl == 0.0) {
        re
    } else {
        r0 - defl / 3.0
    };
    (re, rl)
}

/// Most departure (RMS, relative) of the radius a slip-ratio channel implies
/// from its smooth fit for the channel to count as computed from one radius
/// function. The departure holds the wheel-speed and belt-speed noise (the
/// dev-set rigs: 0.11–0.12 %, random, averaging out over a sweep) beside
/// any systematic part; 3e-3 leaves room for that noise while a channel
/// that is not a Ω·R/V − 1 of the wheel speed (the wrong speed reference:
/// 0.5 % on the same rigs; coarse quantisation; another slip definition) is
/// not used.
pub const SLIP_CHANNEL_RMS: f64 = 3e-3;

/// Number of distinct load levels among loads given as fractions of the
/// largest (Fz/Fz,max): bins of 5 % of it holding at least 10 samples.
pub(crate) fn load_levels(fractions: impl Iterator<Item = f64>) -> usize {
    let mut bins = std::collections::BTreeMap::<i64, usize>::new();
    for f in fractions {
        *bins.entry((f / 0.05).round() as i64).or_default() += 1;
    }
    bins.values().filter(|&&k| k >= 10).count()
}

/// Highest degree in load of [`slip_channel_radius`]'s radius.
const SLIP_RADIUS_MAX_DEGREE: usize = 4;
/// Columns of [`slip_channel_radius`]'s least squares: fᵏ up to the degree, Ω².
const RADIUS_COLUMNS: usize = SLIP_RADIUS_MAX_DEGREE + 2;

/// The radius a recorded slip ratio implies, R = Vx·(1 + SR)/Ω, fitted over
/// the rolling samples as R = Σₖ cₖ·fᵏ + d·Ω² (f = Fz/Fz,max: a radius that
/// varies smoothly with load and, through the centrifugal growth, with
/// wheel speed). The degree in load, 1 to 4 and
/// below the number of distinct load levels, is the one of least BIC
/// (Schwarz 1978): a rig's radius is no quadratic in load — on the dev
/// set's rigs a quadratic missed it by ±0.06 % between load levels, a
/// slip error of 6·10⁻⁴ that moved a car tyre's Fx by ≈ 75 N near free
/// rolling in every replay, where the noise alone sets 0.12 % per sample
/// and a quartic comes within 0.004 %. The fit is evaluated with the load
/// held within the fitted range (a polynomial does not extrapolate).
/// Returns the fitted radius per sample and the RMS relative departure;
/// None when fewer than 20 samples roll, the channel carries no information
/// (SR ≡ 0 with slip in the data), or the departure exceeds
/// [`SLIP_CHANNEL_RMS`].
pub fn slip_channel_radius(samples: &[Sample], sr: &[f64]) -> Option<(Vec<f64>, f64)> {
    let ok = |s: &Sample, r: f64| {
        s.omega.is_finite()
            && s.omega > 1.0
            && s.vx.is_finite()
            && s.vx > 1.0
            && s.fz.is_finite()
            && s.fz > 0.0
            && r.is_finite()
            && r.abs() < 0.3
    };
    let fmax = samples
        .iter()
        .filter(|s| s.fz.is_finite())
        .map(|s| s.fz)
        .fold(0.0, f64::max);
    let wmax = samples
        .iter()
        .filter(|s| s.omega.is_finite())
        .map(|s| s.omega)
        .fold(0.0, f64::max);
    if fmax <= 0.0 || wmax <= 0.0 {
        return None;
    }
    let kept: Vec<(&Sample, f64)> = samples
        .iter()
        .zip(sr.iter().copied())
        .filter(|(s, r)| ok(s, *r) && s.fz >= 0.05 * fmax)
        .collect();
    let n = kept.len();
    let moving = kept.iter().filter(|(_, r)| *r != 0.0).count();
    // (f, w, R) per sample: load and wheel speed scaled to O(1), the radius.
    let used: Vec<(f64, f64, f64)> = kept
        .iter()
        .map(|(s, r)| (s.fz / fmax, s.omega / wmax, s.vx * (1.0 + r) / s.omega))
        .collect();
    if n < 20 || moving < n / 10 {
        return None;
    }
    let (f_lo, f_hi) = used
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, u| {
            (a.0.min(u.0), a.1.max(u.0))
        });
    let levels = load_levels(used.iter().map(|u| u.0));
    // Columns scaled to O(1) for the normal equations: fᵏ, then Ω². A row
    // lives on the stack (one per sample and degree, a million samples in a
    // large recording): its first `deg + 2` entries are used.
    let row = |f: f64, w: f64, deg: usize| -> [f64; RADIUS_COLUMNS] {
        let f = f.clamp(f_lo, f_hi);
        let mut v = [0.0; RADIUS_COLUMNS];
        for (k, x) in v.iter_mut().enumerate().take(deg + 1) {
            *x = f.powi(k as i32);
        }
        v[deg + 1] = w * w;
        v
    };
    let dot =
        |c: &[f64], a: &[f64; RADIUS_COLUMNS]| c.iter().zip(a).fold(0.0, |s, (c, a)| s + c * a);
    let fit_degree = |deg: usize| -> Option<(Vec<f64>, f64)> {
        let k = deg + 2;
        let mut ata = [[0.0; RADIUS_COLUMNS]; RADIUS_COLUMNS];
        let mut aty = [0.0; RADIUS_COLUMNS];
        for &(f, w, y) in &used {
            let a = row(f, w, deg);
            for i in 0..k {
                for j in 0..k {
                    ata[i][j] += a[i] * a[j];
                }
                aty[i] += a[i] * y;
            }
        }
        let ata = nalgebra::DMatrix::from_fn(k, k, |i, j| ata[i][j]);
        let aty = nalgebra::DVector::from_column_slice(&aty[..k]);
        let c: Vec<f64> = ata.lu().solve(&aty)?.iter().copied().collect();
        let ss: f64 = used
            .iter()
            .map(|&(f, w, y)| ((dot(&c, &row(f, w, deg)) - y) / y).powi(2))
            .sum();
        (c.iter().all(|x| x.is_finite()) && ss.is_finite()).then_some((c, ss))
    };
    let bic = |ss: f64, deg: usize| {
        n as f64 * (ss / n as f64).max(1e-300).ln() + (deg + 2) as f64 * (n as f64).ln()
    };
    let top = SLIP_RADIUS_MAX_DEGREE.min(levels.saturating_sub(1)).max(1);
    let (deg, c, ss) = (1..=top)
        .filter_map(|d| fit_degree(d).map(|(c, ss)| (d, c, ss)))
        .min_by(|a, b| bic(a.2, a.0).total_cmp(&bic(b.2, b.0)))?;
    let rms = (ss / n as f64).sqrt();
    if !(rms <= SLIP_CHANNEL_RMS) {
        return None;
    }
    let radii: Vec<f64> = samples
        .iter()
        .map(|s| {
            if s.fz.is_finite() && s.omega.is_finite() {
                dot(&c, &row(s.fz / fmax, s.omega / wmax, deg))
            } else {
                f64::NAN
            }
        })
        .collect();
    radii
        .iter()
        .all(|r| !r.is_finite() || *r > 0.0)
        .then_some((radii, rms))
}

/// Name of the derived extra channel holding, per sample, the radius the
/// recorded slip ratio SR was computed with ([`slip_channel_radius`]):
/// `replay` in the velocities input mode turns it back into the wheel speed
/// the rig's slip implies (see [`compute_kappa`]).
pub const SLIP_RADIUS_CHANNEL: &str = "Re_SR";

/// What [`compute_kappa`] did: the description for the load report, and the
/// per-sample radius of the rig's slip channel when κ was taken from it.
pub struct KappaComputed {
    /// How κ was obtained, in words.
    pub how: String,
    /// [`SLIP_RADIUS_CHANNEL`]'s values, when κ follows the recorded SR.
    pub slip_radius: Option<Vec<f64>>,
}

/// κ for one sample given Re.
#[inline]
pub fn kappa(omega: f64, re: f64, vx: f64) -> f64 {
    if vx.abs() < 1e-3 || !re.is_finite() || !omega.is_finite() {
        return f64::NAN;
    }
    omega * re / vx - 1.0
}

/// Whether a recorded slip-ratio channel reads as a ratio: finite on most
/// rows and |SR| < 0.5 on 95 % of them (drive/brake sweeps stay within
/// ±0.3; a channel in percent, or one computed from a dead wheel speed,
/// does not).
pub(crate) fn plausible_slip_ratio(sr: &[f64]) -> bool {
    let mut a: Vec<f64> = sr
        .iter()
        .filter(|x| x.is_finite())
        .map(|x| x.abs())
        .collect();
    if a.len() < 2 || a.len() * 2 < sr.len() {
        return false;
    }
    a.sort_by(f64::total_cmp);
    a[(a.len() * 95 / 100).min(a.len() - 1)] < 0.5
}

/// Compute κ for all samples; returns how (the Re used), or `None` when Ω
/// or V is missing or no radius is available.
///
/// Where the rig's slip ratio SR is recorded and was computed from one
/// smooth radius ([`slip_channel_radius`]), κ is SR itself on the rolling
/// samples: the rig derives it from its own measurements, and its noise can
/// be lower than that of the ratio of the recorded speeds (the dev-set rigs'
/// belt-speed channel V carries 0.1 % white noise that SR does not: κ from
/// Ω·R/V − 1 scattered by 0.001, i.e. ±100 N on the slip-stiffness slope of a
/// car tyre, and cost the replay of a fitted tyre 15–20 % of its pure-Fx
/// NRMSE). The radius is kept as [`SLIP_RADIUS_CHANNEL`] so that a
/// velocities-input replay feeds the wheel speed that slip implies,
/// Vx·(1 + SR)/R_SR: the tyre file's own Re(Fz) then decides κ, as in the FMU.
pub fn compute_kappa(
    samples: &mut [Sample],
    re: Option<&[f64]>,
    rl: Option<&[f64]>,
    sr: Option<&[f64]>,
    choice: &ReChoice,
) -> Option<KappaComputed> {
    let plain = |how: String| KappaComputed {
        how,
        slip_radius: None,
    };
    if samples.iter().all(|s| !s.omega.is_finite()) || samples.iter().all(|s| !s.vx.is_finite()) {
        return None;
    }
    let mut choice = choice.clone();
    if let ReChoice::FreeRolling = choice {
        if let Some(sr) = sr {
            if let Some((radii, rms)) = slip_channel_radius(samples, sr) {
                for ((s, r), &x) in samples.iter_mut().zip(&radii).zip(sr) {
                    let rolling = s.vx.is_finite() && s.vx > 1.0 && s.omega > 1.0;
                    s.kappa = if rolling && x.is_finite() && x.abs() < 0.3 {
                        x
                    } else {
                        kappa(s.omega, *r, s.vx)
                    };
                }
                return Some(KappaComputed {
                    how: format!(
                        "κ = the recorded slip ratio SR on the rolling samples (computed by the rig with one radius: Vx·(1 + SR)/Ω fitted smooth in load and wheel speed departs {:.2} % RMS; that radius is kept as {SLIP_RADIUS_CHANNEL} for the wheel speed a velocities-input replay feeds), Ω·{SLIP_RADIUS_CHANNEL}/Vx − 1 elsewhere",
                        100.0 * rms
                    ),
                    slip_radius: Some(radii),
                });
            }
        }
        if let Some((a, b)) = re.and_then(|r| free_rolling_re(samples, r)) {
            for s in samples.iter_mut() {
                s.kappa = kappa(s.omega, a + b * s.fz, s.vx);
            }
            return Some(plain(format!(
                "κ = Ω·Re/Vx − 1 with Re(Fz) = {a:.5} m {} {:.3e} m/N·Fz fitted to the recorded RE on free-rolling samples",
                if b < 0.0 { "−" } else { "+" },
                b.abs()
            )));
        }
        choice = if re.is_some() {
            ReChoice::Recorded
        } else {
            ReChoice::Loaded
        };
    }
    match choice {
        ReChoice::Recorded => {
            let re = re?;
            for (s, r) in samples.iter_mut().zip(re) {
                s.kappa = kappa(s.omega, *r, s.vx);
            }
            Some(plain(
                "κ = Ω·Re/Vx − 1 with the recorded RE (disturbed by slip in drive/brake runs)"
                    .into(),
            ))
        }
        ReChoice::Loaded => {
            let rl = rl?;
            for (s, r) in samples.iter_mut().zip(rl) {
                s.kappa = kappa(s.omega, *r, s.vx);
            }
            Some(plain(
                "κ = Ω·Rl/Vx − 1 with the recorded loaded radius (κ biased low by Re − Rl)".into(),
            ))
        }
        ReChoice::Model(tyre) => {
            for s in samples.iter_mut() {
                let inp = MfInput {
                    fz: s.fz,
                    kappa: 0.0,
                    alpha: 0.0,
                    gamma: s.gamma,
                    phit: 0.0,
                    vx: s.vx,
                    p: s.p,
                    omega: s.omega,
                };
                let o = tyre.evaluate(&inp, UseMode::default());
                let r = model_radii(&tyre, s.fz, o.re, o.rl).0;
                s.kappa = kappa(s.omega, r, s.vx);
            }
            Some(plain(format!(
                "κ = Ω·Re/Vx − 1 with the model's Re(Fz) ({})",
                tyre.params().source
            )))
        }
        ReChoice::FreeRolling => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rig whose belt-speed channel carries 0.1 % noise that its slip
    /// ratio SR does not (the dev-set rigs): κ is SR, the rig's radius is
    /// recovered smooth, and the wheel speed a velocities-input replay feeds
    /// gives back SR with that radius.
    /// `n` rolling samples of a rig with radius `rig(Fz)` at the load
    /// `load(i)`, slip swept ±0.1, the belt speed 11 m/s with a
    /// deterministic ±0.17 % (0.1 % RMS) noise the slip ratio does not carry.
    fn rig_samples(
        n: usize,
        load: impl Fn(usize) -> f64,
        rig: impl Fn(f64) -> f64,
    ) -> (Vec<Sample>, Vec<f64>) {
        let (mut samples, mut sr) = (Vec::new(), Vec::new());
        for i in 0..n {
            let fz = load(i);
            let slip = 0.1 * ((i as f64) * 0.01).sin();
            let noise = 1.7e-3 * (((i * 7919) % 1000) as f64 / 500.0 - 1.0);
            let v = 11.0;
            samples.push(Sample {
                vx: v * (1.0 + noise),
                omega: v * (1.0 + slip) / rig(fz),
                fz,
                ..Sample::default()
            });
            sr.push(slip);
        }
        (samples, sr)
    }

    #[test]
    fn kappa_follows_a_clean_slip_channel_over_noisy_speeds() {
        let rig_radius = |fz: f64| 0.300 - 4e-6 * fz;
        let (mut samples, sr) =
            rig_samples(4000, |i| [500.0, 1500.0, 2500.0, 3500.0][i % 4], rig_radius);
        let naive = samples
            .iter()
            .zip(&sr)
            .map(|(s, r)| (kappa(s.omega, rig_radius(s.fz), s.vx) - r).abs())
            .fold(0.0, f64::max);
        assert!(naive > 1e-3, "the test's noise must matter: {naive}");
        let got = compute_kappa(&mut samples, None, None, Some(&sr), &ReChoice::FreeRolling)
            .expect("κ from SR");
        let radius = got.slip_radius.expect("the rig's radius is kept");
        for ((s, r), rr) in samples.iter().zip(&sr).zip(&radius) {
            assert_eq!(s.kappa, *r);
            assert!(
                (rr - rig_radius(s.fz)).abs() < 2e-4,
                "{rr} vs {}",
                rig_radius(s.fz)
            );
            // The replay's wheel speed, Vx·(1 + SR)/R_SR, with the file's
            // Re equal to R_SR, gives back SR exactly.
            let w = s.vx * (1.0 + s.kappa) / rr;
            assert!((kappa(w, *rr, s.vx) - r).abs() < 1e-12);
        }
        assert!(got.how.contains(SLIP_RADIUS_CHANNEL));
    }

    /// A rig radius of the MF's own shape in load (an arctangent and a
    /// line, Pacejka 3rd ed. eq. A3.3's Re), at five load levels with
    /// 0.1 % noise: a quadratic in load misses it between the levels by
    /// more than the slip accuracy a stiff tyre needs (10⁻⁴), the chosen
    /// degree does not; at two load levels the fit stays a line.
    #[test]
    fn the_slip_radius_follows_a_radius_that_is_no_quadratic() {
        let rig = |fz: f64| 0.31 - 0.0025 * (4.0 * fz / 4000.0).atan() - 0.0012 * fz / 4000.0;
        let build = |loads: &[f64]| rig_samples(20_000, |i| loads[(i / 500) % loads.len()], rig);
        let loads = [800.0, 1600.0, 2400.0, 4000.0, 5600.0];
        let (samples, sr) = build(&loads);
        let (radii, _) = slip_channel_radius(&samples, &sr).expect("one smooth radius");
        // The quadratic this replaced, fitted on the same samples.
        let quad = {
            let fmax = 5600.0;
            let mut ata = nalgebra::Matrix3::<f64>::zeros();
            let mut aty = nalgebra::Vector3::<f64>::zeros();
            for (s, r) in samples.iter().zip(&sr) {
                let f = s.fz / fmax;
                let a = nalgebra::Vector3::new(1.0, f, f * f);
                ata += a * a.transpose();
                aty += a * (s.vx * (1.0 + r) / s.omega);
            }
            let c = ata.lu().solve(&aty).expect("quadratic");
            move |fz: f64| c.dot(&nalgebra::Vector3::new(1.0, fz / fmax, (fz / fmax).powi(2)))
        };
        let worst = |f: &dyn Fn(&Sample, usize) -> f64| {
            loads
                .iter()
                .map(|&fz| {
                    let (sum, n) = samples
                        .iter()
                        .enumerate()
                        .filter(|(_, s)| s.fz == fz)
                        .fold((0.0, 0.0), |a, (i, s)| {
                            (a.0 + f(s, i) / rig(fz) - 1.0, a.1 + 1.0)
                        });
                    (sum / n).abs()
                })
                .fold(0.0, f64::max)
        };
        let ours = worst(&|_, i| radii[i]);
        let quadratic = worst(&|s, _| quad(s.fz));
        assert!(
            quadratic > 2e-4,
            "the test's shape must defeat a quadratic: {quadratic}"
        );
        assert!(ours < 2e-5, "fitted radius off by {ours} at a load level");
        // Two load levels: a line through them, finite and in range between.
        let (samples, sr) = build(&[1000.0, 3000.0]);
        let (radii, _) = slip_channel_radius(&samples, &sr).expect("one smooth radius");
        for (s, r) in samples.iter().zip(&radii) {
            assert!((r / rig(s.fz) - 1.0).abs() < 1e-4, "{r} vs {}", rig(s.fz));
        }
    }
}
