//! sanity — plausibility checks on a recording's recorded and derived
//! channels, and the recognition of sign and unit slips.
//!
//! Two kinds of finding:
//! - **A broken channel** (a dead or absurd wheel speed, an effective radius
//!   outside a physical range of the loaded radius, a slip ratio pinned at −1
//!   while the tyre carries lateral force, a force channel that does not
//!   follow its slip (a dead load cell), an aligning moment that does not
//!   follow the lateral force, a moment channel mostly out of range or
//!   saturated) is *rejected*: its values become NaN, it leaves the
//!   recording's channel list, and a warning naming it goes into
//!   [`LoadReport::rejected`]. The rows stay.
//! - **A convention slip** (SAE signs read as ISO-W, a slip angle in degrees
//!   in a column labelled radians, …) cannot be repaired by dropping anything:
//!   loading stops with an error naming the likely cause and the flag or label
//!   that fixes it.
//!
//! Must never: drop rows for a broken channel, reject a channel on a handful
//! of bad values (those rows are dropped and counted by the loader as
//! before), or let a sign or unit slip through silently.

use super::{LoadReport, Sample};
use crate::error::{Error, Result};
use crate::stats::median;

/// Plausible radius (m) implied by a wheel speed, V/Ω, and range of a
/// recorded radius: from a 10-inch kart wheel to an earth-mover tyre.
pub const RADIUS_RANGE: (f64, f64) = (0.05, 5.0);

/// A recorded effective rolling radius must lie within this factor range of
/// the loaded radius (Re sits between Rl and R0: a few % above Rl for car
/// and FSAE tyres, Pacejka 3rd ed. §9.2.1; ±30 % leaves room for any real
/// tyre and catches V/Ω of a dead wheel speed, which is off by orders).
pub const RE_OVER_RL: (f64, f64) = (0.7, 1.3);

/// Share of a channel's values that must be bad (NaN, out of range,
/// saturated) before the channel is rejected instead of its rows dropped.
/// 20 %: a sensor that fails on a fifth of a test is broken, while short
/// drop-outs (a few %) still cost only their rows.
pub const REJECT_SHARE: f64 = 0.2;

/// Sample channels that may be rejected (the rest are the inputs a row cannot
/// be used without: time, speed, load, slip angle, inclination, pressure).
pub const REJECTABLE: [&str; 7] = ["omega", "kappa", "Fx", "Fy", "Mx", "My", "Mz"];

/// A row carries load when Fz exceeds this share of the recording's largest
/// |Fz| (lead-ins and lifted rows are left out of the sign and slip tests).
const LOADED_SHARE: f64 = 0.1;

fn set_channel(samples: &mut [Sample], name: &str, v: f64) {
    for s in samples.iter_mut() {
        match name {
            "omega" => s.omega = v,
            "kappa" => s.kappa = v,
            "Fx" => s.fx = v,
            "Fy" => s.fy = v,
            "Mx" => s.mx = v,
            "My" => s.my = v,
            "Mz" => s.mz = v,
            _ => {}
        }
    }
}

/// Reject sample channel `name`: NaN everywhere, out of `channels`, warning.
pub(crate) fn reject(
    samples: &mut [Sample],
    channels: &mut Vec<String>,
    report: &mut LoadReport,
    name: &str,
    why: String,
) {
    set_channel(samples, name, f64::NAN);
    channels.retain(|c| c != name);
    report
        .rejected
        .push(format!("channel '{name}' rejected: {why}; rows kept"));
}

fn max_abs_fz(samples: &[Sample]) -> f64 {
    samples
        .iter()
        .map(|s| s.fz.abs())
        .filter(|f| f.is_finite())
        .fold(0.0, f64::max)
}

fn loaded(s: &Sample, fmax: f64) -> bool {
    s.fz.is_finite() && s.fz.abs() > LOADED_SHARE * fmax
}

/// Wheel speed: on rows rolling faster than 1 m/s the implied radius V/Ω
/// must lie in [`RADIUS_RANGE`]. A channel failing on most of them (a dead
/// N ≈ 0 rpm export, a wrong unit) is rejected.
pub(crate) fn check_wheel_speed(
    samples: &mut [Sample],
    channels: &mut Vec<String>,
    report: &mut LoadReport,
) {
    if !channels.iter().any(|c| c == "omega") {
        return;
    }
    let (mut moving, mut bad) = (0usize, 0usize);
    for s in samples
        .iter()
        .filter(|s| s.vx.is_finite() && s.vx.abs() > 1.0)
    {
        moving += 1;
        let r = s.vx.abs() / s.omega;
        if !(r.is_finite() && (RADIUS_RANGE.0..=RADIUS_RANGE.1).contains(&r)) {
            bad += 1;
        }
    }
    // Half the moving rows: a locked wheel (Ω = 0 at κ = −1) is real on a
    // few rows of a brake sweep, never on most of a test.
    if moving > 0 && bad * 2 > moving {
        let med = median(samples.iter().map(|s| s.omega)).unwrap_or(f64::NAN);
        reject(
            samples,
            channels,
            report,
            "omega",
            format!(
                "wheel speed implies a radius V/Ω outside [{}, {}] m on {:.1} % of the rows rolling faster than 1 m/s (median Ω {med:.3} rad/s): dead or absurd wheel speed; κ cannot be computed from it",
                RADIUS_RANGE.0,
                RADIUS_RANGE.1,
                100.0 * bad as f64 / moving as f64
            ),
        );
    }
}

/// Recorded radii (extra channels `Rl`, `Re`): values outside
/// [`RADIUS_RANGE`] (and Re outside [`RE_OVER_RL`] of Rl where both exist)
/// become NaN; a radius channel failing on most loaded rows is removed.
pub(crate) fn check_radii(
    samples: &[Sample],
    extra: &mut Vec<(String, Vec<f64>)>,
    report: &mut LoadReport,
) {
    let fmax = max_abs_fz(samples);
    let rl: Option<Vec<f64>> = extra
        .iter()
        .find(|(n, _)| n == "Rl")
        .map(|(_, v)| v.clone());
    let mut remove = Vec::new();
    for (name, v) in extra.iter_mut() {
        if name != "Rl" && name != "Re" {
            continue;
        }
        let (mut n_loaded, mut bad) = (0usize, 0usize);
        for (i, x) in v.iter_mut().enumerate() {
            let mut ok = x.is_finite() && (RADIUS_RANGE.0..=RADIUS_RANGE.1).contains(x);
            if name == "Re" {
                if let Some(l) = rl.as_ref().map(|r| r[i]).filter(|l| l.is_finite()) {
                    ok &= (RE_OVER_RL.0 * l..=RE_OVER_RL.1 * l).contains(x);
                }
            }
            if samples.get(i).is_some_and(|s| loaded(s, fmax)) {
                n_loaded += 1;
                bad += usize::from(!ok);
            }
            if !ok {
                *x = f64::NAN;
            }
        }
        if n_loaded > 0 && bad * 2 > n_loaded {
            remove.push(name.clone());
            let range = if name == "Re" && rl.is_some() {
                format!("[{}, {}]·Rl", RE_OVER_RL.0, RE_OVER_RL.1)
            } else {
                format!("[{}, {}] m", RADIUS_RANGE.0, RADIUS_RANGE.1)
            };
            report.rejected.push(format!(
                "channel '{name}' rejected: outside {range} on {:.1} % of the loaded rows (a radius from a dead wheel speed?); rows kept",
                100.0 * bad as f64 / n_loaded as f64
            ));
        }
    }
    extra.retain(|(n, _)| !remove.contains(n));
    report.extra_units.retain(|(n, _)| !remove.contains(n));
}

/// Slip ratios pinned at −1 while the tyre carries lateral force (|Fy| >
/// 10 % Fz: it is rolling and cornering, so it cannot be locked): a
/// recorded κ (sample channel) or TTC's SR/SL extras computed from a dead
/// wheel speed. Rejected when the median over such rows is below −0.9.
pub(crate) fn check_pinned_slip(
    samples: &mut [Sample],
    channels: &mut Vec<String>,
    extra: &mut Vec<(String, Vec<f64>)>,
    report: &mut LoadReport,
) {
    let cornering: Vec<usize> = (0..samples.len())
        .filter(|&i| {
            let s = &samples[i];
            s.fy.is_finite() && s.fz.is_finite() && s.fz > 0.0 && s.fy.abs() > 0.1 * s.fz
        })
        .collect();
    if cornering.len() < 20 {
        return;
    }
    let pinned = |v: &dyn Fn(usize) -> f64| {
        median(cornering.iter().map(|&i| v(i))).is_some_and(|m| m < -0.9)
    };
    if channels.iter().any(|c| c == "kappa") && pinned(&|i| samples[i].kappa) {
        reject(
            samples,
            channels,
            report,
            "kappa",
            "the recorded slip ratio is pinned near −1 while the tyre carries lateral force (median < −0.9): it was computed from a dead wheel speed".into(),
        );
    }
    let mut remove = Vec::new();
    for (name, v) in extra.iter() {
        let n = name.to_ascii_lowercase();
        if (n == "sr" || n == "sl") && pinned(&|i| v[i]) {
            remove.push(name.clone());
            report.rejected.push(format!(
                "channel '{name}' rejected: pinned near −1 while the tyre carries lateral force (median < −0.9): computed from a dead wheel speed; rows kept"
            ));
        }
    }
    extra.retain(|(n, _)| !remove.contains(n));
    report.extra_units.retain(|(n, _)| !remove.contains(n));
}

/// Smallest difference of the median F/Fz between the rows slipping one
/// way and the rows slipping the other (`check_dead_forces`) that a live
/// force channel shows. A tyre at |κ| ≥ 0.05 or |α| ≥ 3° carries at least
/// min(slip stiffness · slip, μ)·Fz of force: slip stiffnesses of 5–30 Fz
/// per unit slip and a friction of 0.05 or more even on ice give a
/// difference of 0.1 or more between the two sides; 0.02 leaves a factor
/// five below that, while a dead, disconnected or constant channel — or one
/// in a unit a thousand times larger than its label (kN read as N) —
/// differs by noise only.
pub const DEAD_FORCE: f64 = 0.02;

/// Slip beyond which, either side of its recording's median, a row counts
/// as slipping for [`check_dead_forces`]: κ 0.05 (a drive/brake sweep of
/// ±0.1 or more passes it for seconds) and α 3° (every cornering sweep
/// passes it; a steer of 3° is past the linear range on no tyre).
const DEAD_KAPPA: f64 = 0.05;
const DEAD_ALPHA_DEG: f64 = 3.0;

/// Fewest loaded rows on each side of the slip before a force channel is
/// judged dead: a median of 20 values is not moved by a few spikes, and a
/// steady-state TYDEX sweep of a few points per side is left unjudged.
const DEAD_MIN_ROWS: usize = 20;

/// How channels per unit load change across a recording's slip, the
/// statistic of the dead-channel checks: over the loaded rows with finite
/// values, those whose slip lies `lo ≤ ±(slip − median slip) ≤ hi` above
/// and below the median; for each of `values` (divided by Fz) the median
/// above minus the median below, and the two row counts. `None` when
/// either side holds fewer than [`DEAD_MIN_ROWS`] rows (unjudged).
fn change_across_slip<const N: usize>(
    samples: &[Sample],
    slip: fn(&Sample) -> f64,
    values: [fn(&Sample) -> f64; N],
    (lo, hi): (f64, f64),
) -> Option<([f64; N], usize, usize)> {
    let fmax = max_abs_fz(samples);
    let rows: Vec<(f64, [f64; N])> = samples
        .iter()
        .filter(|s| loaded(s, fmax) && s.fz > 0.0)
        .map(|s| (slip(s), values.map(|v| v(s) / s.fz)))
        .filter(|(x, v)| x.is_finite() && v.iter().all(|y| y.is_finite()))
        .collect();
    let mid = median(rows.iter().map(|r| r.0))?;
    let side = |sign: f64| -> Vec<&[f64; N]> {
        rows.iter()
            .filter(|(x, _)| (lo..=hi).contains(&(sign * (x - mid))))
            .map(|(_, v)| v)
            .collect()
    };
    let (pos, neg) = (side(1.0), side(-1.0));
    if pos.len() < DEAD_MIN_ROWS || neg.len() < DEAD_MIN_ROWS {
        return None;
    }
    let med = |v: &[&[f64; N]], k: usize| median(v.iter().map(|r| r[k])).unwrap_or(f64::NAN);
    let change = std::array::from_fn(|k| med(&pos, k) - med(&neg, k));
    Some((change, pos.len(), neg.len()))
}

/// Force channels that do not follow their slip: Fx against κ, Fy against
/// α. On the loaded rows with finite values, the rows at slip ≥ median +
/// threshold and ≤ median − threshold (κ 0.05, α 3°) are compared; where
/// both sides hold [`DEAD_MIN_ROWS`] rows and their median F/Fz differ by
/// less than [`DEAD_FORCE`], the channel is rejected with the figures (a
/// dead or disconnected load cell, or a unit slip of a factor 1000): fitted,
/// it would give a tyre without that force and any verdict read from it
/// would be the channel's noise. A recording whose slip is never swept both
/// ways leaves the channel unjudged. Runs after κ is known.
pub(crate) fn check_dead_forces(
    samples: &mut [Sample],
    channels: &mut Vec<String>,
    report: &mut LoadReport,
) {
    type Get = fn(&Sample) -> f64;
    type Show = fn(f64) -> String;
    let checks: [(&str, &str, Get, Get, f64, &str, Show); 2] = [
        (
            "Fx",
            "kappa",
            |s| s.fx,
            |s| s.kappa,
            DEAD_KAPPA,
            "κ",
            |t| format!("{t:.2}"),
        ),
        (
            "Fy",
            "alpha",
            |s| s.fy,
            |s| s.alpha,
            DEAD_ALPHA_DEG.to_radians(),
            "α",
            |t| format!("{:.0}°", t.to_degrees()),
        ),
    ];
    for (force, slip_ch, f, slip, threshold, symbol, show) in checks {
        let has = |c: &str| channels.iter().any(|x| x == c);
        if !has(force) || !has(slip_ch) {
            continue;
        }
        let Some(([d], np, nn)) =
            change_across_slip(samples, slip, [f], (threshold, f64::INFINITY))
        else {
            continue;
        };
        if d.abs() < DEAD_FORCE {
            let step = show(threshold);
            reject(
                samples,
                channels,
                report,
                force,
                format!(
                    "it does not follow the slip: its median {force}/Fz differs by {d:+.4} between the {np} loaded rows at {symbol} ≥ +{step} and the {nn} at {symbol} ≤ −{step} from the median {symbol}, where a tyre gives 0.1 or more even on ice (at most {DEAD_FORCE} counts as dead): a dead or disconnected force channel, or one in a unit far larger than its label (kN read as N?)"
                ),
            );
        }
    }
}

/// Smallest ratio (m) of the aligning moment's change to the lateral
/// force's change across the straight-running slip angles that a live Mz
/// channel shows (`check_dead_moment`): the pneumatic trail, |ΔMz| / |ΔFy|
/// between the rows at α 1–3° either side of the median α. A rolling tyre's
/// trail at small slip is a sixth to a third of its contact length — about
/// 1 cm on a kart tyre, 2–4 cm on FSAE and car tyres, more on trucks
/// (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §1.2.2, §4.3.2) —, and it
/// does not scale with friction (on ice both changes shrink together); 1 mm
/// leaves a factor ten below the smallest, while a dead, disconnected or
/// constant moment channel — or one a thousand times too small (kN·m read
/// as N·m) — changes by noise only.
pub const DEAD_TRAIL: f64 = 1e-3;

/// The band of slip angle (degrees from the recording's median α) whose
/// rows [`check_dead_moment`] compares: inside the linear range of every
/// tyre (the trail has not yet collapsed towards the force's peak), wide
/// enough that a cornering sweep crosses it for a second or more.
const DEAD_MZ_ALPHA_DEG: (f64, f64) = (1.0, 3.0);

/// An aligning-moment channel that does not follow the lateral force: on
/// the loaded rows at α 1–3° either side of the median α ([`DEAD_MZ_ALPHA_DEG`],
/// at least [`DEAD_MIN_ROWS`] each side), the medians of Mz/Fz and Fy/Fz
/// are compared; where Fy changes by at least [`DEAD_FORCE`] and Mz by less
/// than [`DEAD_TRAIL`] times Fy's change, Mz is rejected with the figures.
/// Fitted, a dead channel gives a tyre without aligning moment (a zero
/// trail) and reads as a successful fit. A recording whose slip angle never
/// crosses the band both ways, or whose Fy is missing or itself dead,
/// leaves Mz unjudged. Runs after [`check_dead_forces`].
pub(crate) fn check_dead_moment(
    samples: &mut [Sample],
    channels: &mut Vec<String>,
    report: &mut LoadReport,
) {
    let has = |c: &str| channels.iter().any(|x| x == c);
    if !has("Mz") || !has("Fy") || !has("alpha") {
        return;
    }
    let band = (
        DEAD_MZ_ALPHA_DEG.0.to_radians(),
        DEAD_MZ_ALPHA_DEG.1.to_radians(),
    );
    let Some(([dy, dz], np, nn)) =
        change_across_slip(samples, |s| s.alpha, [|s| s.fy, |s| s.mz], band)
    else {
        return;
    };
    if dy.abs() < DEAD_FORCE || !dy.is_finite() {
        return;
    }
    let trail = (dz / dy).abs();
    if trail < DEAD_TRAIL {
        reject(
            samples,
            channels,
            report,
            "Mz",
            format!(
                "it does not follow the lateral force: between the {np} loaded rows at α 1–3° above the median α and the {nn} below it, the median Fy/Fz changes by {dy:+.3} while Mz/Fz changes by {:+.5} m — a pneumatic trail of {:.2} mm, where a rolling tyre has 10 mm or more (at most {:.0} mm counts as dead): a dead or disconnected moment channel, or one in a unit far larger than its label (kN·m read as N·m?)",
                dz,
                1e3 * trail,
                1e3 * DEAD_TRAIL
            ),
        );
    }
}

/// How far Fx/Fz may stray from the recording's free-rolling level on a
/// freely rolling row: half the 2–98 % spread of Fx/Fz beyond which the
/// segmenter takes Fx for swept ([`super::structure::FX_SWEPT`]), so rows
/// count as free rolling where a segment of them would not count as a
/// slip-ratio sweep. A drive/brake sweep leaves the band at |κ| ≈ 0.006
/// on car and FSAE tyres (slip stiffness 20–30 Fz per unit κ).
pub(crate) const FREE_ROLLING_FX: f64 = 0.5 * super::structure::FX_SWEPT;

/// Shortest stretch (s) of free rolling inside a drive/brake recording
/// (see [`free_rolling_stretches`]): a cornering sweep lasts far longer (a
/// 4°/s sweep to ±12° takes over 10 s, TTC's several seconds), while a
/// slip-ratio sweep crosses the free-rolling band in well under a second
/// at any programmed rate (0.06 s at 0.1/s).
pub(crate) const FREE_ROLLING_STRETCH_S: f64 = 2.0;

/// Longest excursion (s) out of the free-rolling band that does not end a
/// stretch: a noise spike at the lightest load, not a slip-ratio sweep
/// (which stays out for seconds).
const FREE_ROLLING_GAP_S: f64 = 0.25;

/// Share of the loaded rows the free-rolling stretches must hold before a
/// recording without any slip information is used on them alone: below
/// it the recording is a drive/brake test whose dwells would be all that
/// is left, and it is better refused with the reason.
pub(crate) const FREE_ROLLING_SHARE: f64 = 0.25;

/// The recording's free-rolling Fx/Fz: the median of the loaded rows in the
/// densest band of width 2·[`FREE_ROLLING_FX`] among those within
/// 2·[`FREE_ROLLING_FX`] of zero (a mode), held within ±[`FREE_ROLLING_FX`].
/// Rolling resistance, the tyre's own Fx at κ = 0 and a force-sensor zero
/// put it anywhere near 0 — 1–2 % of Fz for rolling resistance, −9 % on one
/// FSAE tyre of the dev set —, and drive/brake rows spread far either side;
/// the bound keeps a held brake force (a dense band near −1) from passing
/// for it. `None` without loaded rows with Fx.
fn free_rolling_level(samples: &[Sample]) -> Option<f64> {
    let fmax = max_abs_fz(samples);
    let mut r: Vec<f64> = samples
        .iter()
        .filter(|s| loaded(s, fmax) && s.fx.is_finite())
        .map(|s| s.fx / s.fz.abs())
        .collect();
    if r.is_empty() {
        return None;
    }
    r.retain(|x| x.abs() <= 2.0 * FREE_ROLLING_FX);
    r.sort_by(f64::total_cmp);
    let (mut best, mut lo) = ((0, 0), 0);
    for hi in 0..r.len() {
        while r[hi] - r[lo] > 2.0 * FREE_ROLLING_FX {
            lo += 1;
        }
        if hi + 1 - lo > best.1 - best.0 {
            best = (lo, hi + 1);
        }
    }
    let level = if best.1 > best.0 {
        r[(best.0 + best.1) / 2]
    } else {
        0.0
    };
    Some(level.clamp(-FREE_ROLLING_FX, FREE_ROLLING_FX))
}

/// Whether the recording rolls freely throughout: no Fx channel, or Fx/Fz
/// within [`FREE_ROLLING_FX`] of its free-rolling level on 95 % of the
/// loaded rows (a cornering-only test: the induced drag of a cornering
/// tyre and the noise at the lightest load stay within it; a drive/brake
/// sweep to κ = 0.1 does not).
pub(crate) fn free_rolling_run(samples: &[Sample], has_fx: bool) -> bool {
    if !has_fx {
        return true;
    }
    let Some(level) = free_rolling_level(samples) else {
        return true;
    };
    let fmax = max_abs_fz(samples);
    let mut r: Vec<f64> = samples
        .iter()
        .filter(|s| loaded(s, fmax) && s.fx.is_finite())
        .map(|s| (s.fx / s.fz.abs() - level).abs())
        .collect();
    r.sort_by(f64::total_cmp);
    r[(r.len() * 95 / 100).min(r.len() - 1)] < FREE_ROLLING_FX
}

/// Per row, whether it lies in a stretch of at least
/// [`FREE_ROLLING_STRETCH_S`] over which the loaded rows hold Fx/Fz within
/// [`FREE_ROLLING_FX`] of the free-rolling level (excursions up to
/// [`FREE_ROLLING_GAP_S`] bridged): the cornering blocks and dwells of a
/// recording that also brakes and drives, where κ = 0 is known without a
/// wheel speed. `None` when such stretches hold less than
/// [`FREE_ROLLING_SHARE`] of the loaded rows. A stretch ends where time
/// does not advance.
pub(crate) fn free_rolling_stretches(samples: &[Sample]) -> Option<Vec<bool>> {
    let level = free_rolling_level(samples)?;
    let fmax = max_abs_fz(samples);
    let free = |s: &Sample| {
        !loaded(s, fmax)
            || (s.fx.is_finite() && (s.fx / s.fz.abs() - level).abs() < FREE_ROLLING_FX)
    };
    let n = samples.len();
    // Runs of rows (start, end) in the band, excursions up to the gap bridged.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < n {
        if !free(&samples[i]) {
            i += 1;
            continue;
        }
        let mut j = i + 1;
        while j < n && free(&samples[j]) && samples[j].time > samples[j - 1].time {
            j += 1;
        }
        match runs.last_mut() {
            Some(last)
                if samples[i].time > samples[last.1 - 1].time
                    && samples[i].time - samples[last.1 - 1].time <= FREE_ROLLING_GAP_S
                    && samples[last.1..i].windows(2).all(|w| w[1].time > w[0].time) =>
            {
                last.1 = j
            }
            _ => runs.push((i, j)),
        }
        i = j;
    }
    let mut mask = vec![false; n];
    for (a, b) in runs {
        if samples[b - 1].time - samples[a].time >= FREE_ROLLING_STRETCH_S {
            mask[a..b].iter_mut().for_each(|m| *m = true);
        }
    }
    let (mut total, mut kept) = (0usize, 0usize);
    for (s, &m) in samples.iter().zip(&mask) {
        if loaded(s, fmax) {
            total += 1;
            kept += usize::from(m);
        }
    }
    (total > 0 && kept as f64 >= FREE_ROLLING_SHARE * total as f64).then_some(mask)
}

/// Sign and unit slips that make every later number wrong: stop with the
/// likely cause and the fix. `axes` is the axis system the file was read
/// in, `unit_of` the unit label a sample channel was given (None: none).
pub(crate) fn check_conventions(
    samples: &[Sample],
    channels: &[String],
    axes: super::conventions::AxisSystem,
    unit_of: &dyn Fn(&str) -> Option<String>,
    file: &str,
) -> Result<()> {
    use super::conventions::AxisSystem;
    let err = |loc: &str, msg: String| Error::Recording {
        file: file.to_string(),
        location: format!("channel '{loc}'"),
        message: msg,
    };
    let has = |c: &str| channels.iter().any(|x| x == c);
    let label = |c: &str| unit_of(c).map_or("no unit".to_string(), |u| format!("unit '{u}'"));
    // Angles: a degree column labelled (or defaulted to) radians shows values
    // far beyond any physical slip angle (|α| ≤ π/2) or inclination (0.6 rad).
    for (c, lim, what, eg) in [
        ("alpha", std::f64::consts::FRAC_PI_2, "π/2", "SA [deg]"),
        ("gamma", 0.6, "0.6 rad (34°)", "IA [deg]"),
    ] {
        // Only a column read as radians (labelled so, or without a unit); a
        // value beyond the limit in a degree column is an out-of-range row.
        let as_rad = unit_of(c).is_none_or(|u| {
            matches!(
                u.trim().to_ascii_lowercase().as_str(),
                "rad" | "radian" | "radians"
            )
        });
        if !has(c) || !as_rad {
            continue;
        }
        let vals: Vec<f64> = samples
            .iter()
            .map(|s| s.get(c))
            .filter(|v| v.is_finite())
            .collect();
        let over = vals.iter().filter(|v| v.abs() > lim).count();
        if !vals.is_empty() && over as f64 > 0.05 * vals.len() as f64 {
            let max = vals.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            return Err(err(
                c,
                format!(
                    "{:.1} % of the values exceed {what} (largest {max:.3} after conversion, {}): the column is most likely in degrees but read as radians; give its unit in the header (e.g. '{eg}'), or in a TTC/TYDEX file fix the units row",
                    100.0 * over as f64 / vals.len() as f64,
                    label(c)
                ),
            ));
        }
    }
    // Pressure: a gauge pressure in Pa below 1000 is no tyre's; kPa or bar
    // labelled Pa.
    if has("P") {
        if let Some(m) = median(samples.iter().map(|s| s.p)) {
            if m > 0.0 && m < 1000.0 {
                let likely = if m < 20.0 { "bar" } else { "kPa or psi" };
                return Err(err(
                    "P",
                    format!(
                        "median pressure {m:.3} Pa ({}) is no tyre's inflation pressure: the column is most likely in {likely}; give its unit in the header (e.g. 'P [kPa]')",
                        label("P")
                    ),
                ));
            }
        }
    }
    // Signs. Fz > 0 when loaded in ISO-W.
    let fmax = max_abs_fz(samples);
    let loaded_rows: Vec<&Sample> = samples.iter().filter(|s| loaded(s, fmax)).collect();
    let neg = loaded_rows.iter().filter(|s| s.fz < 0.0).count();
    if !loaded_rows.is_empty() && neg * 2 > loaded_rows.len() {
        let (cause, fix) = match axes {
            AxisSystem::Sae => (
                "the file's Fz is positive when loaded, so its signs are ISO-W/TYDEX, not SAE",
                "--axes iso-w",
            ),
            _ => (
                "the file's Fz is negative when loaded, as in SAE (TTC) axes, but it was read as ISO-W",
                "--axes sae",
            ),
        };
        return Err(err(
            "Fz",
            format!(
                "{:.0} % of the loaded rows have Fz < 0 after conversion from {} to ISO-W (where a loaded tyre has Fz > 0): {cause}; read it with {fix}",
                100.0 * neg as f64 / loaded_rows.len() as f64,
                axes.name()
            ),
        ));
    }
    // Fy–α: in ISO-W (and SAE) Fy falls with α near zero slip (Kyα < 0 in
    // ISO-W: Pacejka 3rd ed. §4.3, e.g. PKY1 < 0); a rising Fy means α's sign
    // is reversed (adapted ISO).
    if has("Fy") && has("alpha") {
        let lim = 2f64.to_radians();
        let (x, y): (Vec<f64>, Vec<f64>) = loaded_rows
            .iter()
            .filter(|s| {
                s.alpha.abs() < lim && s.fy.is_finite() && s.alpha.is_finite() && s.fz > 0.0
            })
            .map(|s| (s.alpha, s.fy / s.fz))
            .unzip();
        let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| {
            (a.0.min(*v), a.1.max(*v))
        });
        if x.len() >= 50 && hi - lo > 1f64.to_radians() {
            if let Some((_, b)) = super::slip::fit_line(&x, &y) {
                // b is Fy/Fz per rad; a real tyre's |Kyα|/Fz is 5–40 /rad.
                // Demand a clear positive slope (> 1 /rad) so that noise on a
                // camber-only or nearly flat run cannot trip it.
                if b > 1.0 {
                    let fix = match axes {
                        AxisSystem::AdaptedIso => "--axes iso-w",
                        _ => "--axes adapted-iso",
                    };
                    return Err(err(
                        "Fy",
                        format!(
                            "Fy rises with the slip angle near α = 0 (slope {b:+.2} Fz/rad after conversion from {} to ISO-W, where it falls): the slip angle's sign is reversed relative to the force's; read it with {fix}",
                            axes.name()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}
