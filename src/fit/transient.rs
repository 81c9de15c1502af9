//! transient — the relaxation-length stage of a fit (`--only transient`):
//! the lag between the imposed slip and the force, seen as the hysteresis
//! between rising and falling sweeps of a dynamic test, is fitted by
//! replaying the recording through this project's relaxation model
//! ([`crate::residual::replay`] with [`TransientKind::Relaxation`], the code
//! the FMU runs) and minimising Σ(sim − measured)² of Fy over the pure
//! lateral segments (σα) and of Fx over the pure longitudinal ones (σκ).
//!
//! What is fitted are the standard keys the relaxation lengths come from
//! (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §7.2, eqs. 7.9–7.12;
//! MF-Tyre 6.x σ = K/C, paper eq. 19; see [`crate::transient::tyre_props`]):
//! - MF 6.1/6.2: σα = |Kyα|/Cy, σκ = |Kxκ|/Cx with the carcass stiffnesses
//!   LATERAL_STIFFNESS / LONGITUDINAL_STIFFNESS (their load and pressure
//!   terms PCFY*/PCFX* are kept): the stiffness is fitted, with Kyα, Kxκ
//!   from the steady stages;
//! - MF 5.2 / PAC2002 with PTY1, PTY2 (PTX1) set: PTY1 (PTX1), which scale
//!   σα (σκ) directly; otherwise the stiffness as for MF 6.
//!
//! The cost is one scalar function of one parameter per direction, each
//! evaluation a replay, and the replay has no derivatives: it is minimised
//! over log σ by a grid scan (robust to a cost with more than one dip)
//! followed by golden-section search (Kiefer 1953) — derivative-free, not
//! finite differences. When the best lag does not lower the cost by
//! [`MIN_GAIN`] of the cost at the shortest length searched (the σ → 0
//! limit of the same model), or lies on the short end of the search, the
//! recording shows no resolvable lag and the key is held at its start
//! value, reported as not identified. (The steady model's replay cost is
//! reported too, for comparison.)
//!
//! Must never: change a key it did not fit, approximate a derivative by
//! finite differences, or panic on user data.

use crate::data::{Recording, SegmentKind};
use crate::mf::{MfInput, Tyre, UseMode};
use crate::residual::{replay, ReplayOptions};
use crate::tir::{MfVersion, TyreParams};
use crate::transient::{tyre_props, TransientKind};
use std::ops::Range;

/// Relative cost reduction, against the same model with the shortest
/// relaxation length searched (σ_start/30), below which a lag is "not
/// identified": 0.5 %. A lag is also not identified when its length is
/// shorter than the distance rolled between two samples: it then settles
/// within one sample, and what it fits is the smoothing of noisy slip
/// inputs (a steady rig recording "fits" σκ ≈ 4 cm, σα ≈ 3 cm at 11 cm
/// per sample, lowering the cost by 9 % and 0.6 % through input-noise
/// filtering alone).
pub const MIN_GAIN: f64 = 0.005;

/// Search range of the relaxation-length factor σ/σ_start: 1/30 … 30.
const LN_RANGE: f64 = 3.4;
/// Grid points of the scan over ln(σ/σ_start).
const GRID: usize = 15;
/// Golden-section stop: bracket narrower than 0.4 % in σ.
const LN_TOL: f64 = 0.004;

/// Result of one direction of the relaxation stage.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RelaxationFit {
    /// Fitted channel ("Fy" for σα, "Fx" for σκ).
    pub channel: String,
    /// The `.tir` key fitted.
    pub key: String,
    /// Start value of `key`, SI (N/m for LATERAL_STIFFNESS /
    /// LONGITUDINAL_STIFFNESS, dimensionless for PTY1 / PTX1).
    pub start: f64,
    /// Value written (the start value when not identified).
    pub value: f64,
    /// Relaxation length at FNOMIN, zero slip, NOMPRES and LONGVL (m): at
    /// the start and as fitted.
    pub sigma_start: f64,
    /// Relaxation length as fitted (m), at the same conditions.
    pub sigma: f64,
    /// Σ(sim − measured)² over the fitted samples (N²) with the steady
    /// model (no lag), for comparison.
    pub cost_steady: f64,
    /// Σ(sim − measured)² (N²) with the relaxation model at the start value.
    pub cost_start: f64,
    /// Σ(sim − measured)² (N²) with the relaxation model at `value`.
    pub cost: f64,
    /// Number of samples the cost sums over.
    pub samples: usize,
    /// Replays run.
    pub evaluations: usize,
    /// Whether the recording resolves a lag (gain ≥ [`MIN_GAIN`], not on the
    /// short end of the search); if not, `value` is the start.
    pub identified: bool,
    /// Why not identified (empty when identified).
    pub note: String,
}

/// The key that sets the relaxation length of a direction (see module docs).
fn key_for(tyre: &TyreParams, lateral: bool) -> &'static str {
    let legacy = matches!(tyre.version, MfVersion::Mf52 | MfVersion::Pac2002);
    let v = |k: &str| tyre.get(k).unwrap_or(0.0);
    match (lateral, legacy) {
        (true, true) if v("PTY1") != 0.0 && v("PTY2") != 0.0 => "PTY1",
        (false, true) if v("PTX1") != 0.0 => "PTX1",
        (true, _) => "LATERAL_STIFFNESS",
        (false, _) => "LONGITUDINAL_STIFFNESS",
    }
}

/// The key's value for a relaxation-length factor `f` = σ/σ_start: the
/// stiffness keys are inversely proportional to σ, PTX1/PTY1 proportional.
fn value_for(key: &str, start: f64, f: f64) -> f64 {
    if key.ends_with("STIFFNESS") {
        start / f
    } else {
        start * f
    }
}

/// Relaxation length (m) of `tyre` at FNOMIN, NOMPRES, LONGVL, zero slip.
pub fn nominal_sigma(tyre: &Tyre, lateral: bool) -> f64 {
    let p = &tyre.params().p;
    let inp = MfInput {
        fz: p.fnomin,
        vx: if p.longvl > 0.0 { p.longvl } else { 10.0 },
        p: p.nompres,
        ..Default::default()
    };
    let o = tyre.slip_properties(&inp, UseMode::default());
    let t = tyre_props(tyre, &o, inp.fz, inp.vx);
    if lateral {
        t.sigma_y
    } else {
        t.sigma_x
    }
}

/// The samples of `kind` segments inside `train` (None: all) of `rec`, as
/// a recording of their own (time kept, so the replay resets and settles
/// at every jump between them).
fn sub_recording(rec: &Recording, kind: SegmentKind, train: Option<&[Range<usize>]>) -> Recording {
    let mut samples = Vec::new();
    for seg in rec.segments.iter().filter(|s| s.kind == kind) {
        for i in seg.start..seg.end.min(rec.samples.len()) {
            if train.is_none_or(|t| t.iter().any(|r| r.contains(&i))) {
                samples.push(rec.samples[i]);
            }
        }
    }
    Recording {
        source: rec.source.clone(),
        samples,
        channels: rec.channels.clone(),
        ..Default::default()
    }
}

/// Median distance rolled between samples (m): median |Vx| × median time step.
fn rolled_per_sample(subs: &[Recording]) -> f64 {
    let mut v: Vec<f64> = subs
        .iter()
        .flat_map(|r| r.samples.iter().map(|s| s.vx.abs()))
        .filter(|v| v.is_finite())
        .collect();
    let t: Vec<f64> = subs
        .iter()
        .flat_map(|r| r.samples.iter().map(|s| s.time))
        .collect();
    let h = crate::residual::median_spacing(&t);
    if v.is_empty() || !h.is_finite() {
        return 0.0;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f64::total_cmp).1 * h
}

/// Σ(sim − measured)² of the channel over the sub-recordings, replayed
/// through `tyre` with `kind`, and the number of samples compared.
fn replay_cost(
    subs: &[Recording],
    tyre: &Tyre,
    kind: TransientKind,
    lateral: bool,
) -> crate::Result<(f64, usize)> {
    let opts = ReplayOptions {
        kind,
        ..Default::default()
    };
    let mut cost = 0.0;
    let mut n = 0;
    for rec in subs {
        let rp = replay(rec, tyre, &opts)?;
        for (s, f) in rec.samples.iter().zip(&rp.sim) {
            let (m, y) = if lateral { (s.fy, f.fy) } else { (s.fx, f.fx) };
            if m.is_finite() && y.is_finite() {
                cost += (y - m) * (y - m);
                n += 1;
            }
        }
    }
    Ok((cost, n))
}

/// Fit the relaxation lengths of `tyre` (already fitted for the steady
/// channels) to `recs`, on the samples in `train` (per recording; None:
/// all). Writes the identified keys into `tyre` and returns one result per
/// direction the data have (lateral: Fy in pure lateral segments;
/// longitudinal: Fx in pure longitudinal ones) and the directions skipped.
pub fn fit_relaxation(
    recs: &[Recording],
    tyre: &mut TyreParams,
    train: Option<&[Vec<Range<usize>>]>,
    min_samples: usize,
) -> crate::Result<(Vec<RelaxationFit>, Vec<String>)> {
    let mut out = Vec::new();
    let mut skipped = Vec::new();
    for lateral in [true, false] {
        let (kind, channel) = if lateral {
            (SegmentKind::PureLateral, "Fy")
        } else {
            (SegmentKind::PureLongitudinal, "Fx")
        };
        let subs: Vec<Recording> = recs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.has(channel) && r.samples.iter().any(|s| s.time.is_finite()))
            .map(|(k, r)| sub_recording(r, kind, train.map(|t| t[k].as_slice())))
            .filter(|r| !r.samples.is_empty())
            .collect();
        let n: usize = subs.iter().map(|r| r.samples.len()).sum();
        if n < min_samples {
            skipped.push(format!(
                "transient ({channel}): {n} timed samples in {} segments (need {min_samples})",
                kind.label()
            ));
            continue;
        }
        out.push(fit_direction(&subs, tyre, lateral, channel)?);
    }
    Ok((out, skipped))
}

fn fit_direction(
    subs: &[Recording],
    tyre: &mut TyreParams,
    lateral: bool,
    channel: &str,
) -> crate::Result<RelaxationFit> {
    let key = key_for(tyre, lateral);
    let start = match tyre.get(key) {
        Some(v) if v.is_finite() && v > 0.0 => v,
        // No usable start: the format's default stiffness, or 1 for PTX1/PTY1.
        _ if key == "LATERAL_STIFFNESS" => 1e5,
        _ if key == "LONGITUDINAL_STIFFNESS" => 3e5,
        _ => 1.0,
    };
    let base = tyre.clone();
    let mut evaluations = 0;
    let mut eval = |u: f64| -> crate::Result<f64> {
        let mut t = base.clone();
        t.set(key, value_for(key, start, u.exp()))?;
        evaluations += 1;
        Ok(replay_cost(subs, &Tyre::new(t)?, TransientKind::Relaxation, lateral)?.0)
    };
    // Grid scan over ln f, then golden section in the best cell's bracket.
    let us: Vec<f64> = (0..GRID)
        .map(|k| -LN_RANGE + 2.0 * LN_RANGE * k as f64 / (GRID - 1) as f64)
        .collect();
    let mut costs = Vec::with_capacity(GRID);
    for &u in &us {
        costs.push(eval(u)?);
    }
    let best = (0..GRID)
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
        .unwrap_or(GRID / 2);
    let (mut a, mut b) = (us[best.saturating_sub(1)], us[(best + 1).min(GRID - 1)]);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (eval(c)?, eval(d)?);
    while b - a > LN_TOL {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = eval(c)?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = eval(d)?;
        }
    }
    let (mut u, mut cost) = if fc <= fd { (c, fc) } else { (d, fd) };
    if costs[best] < cost {
        (u, cost) = (us[best], costs[best]);
    }
    let start_tyre = Tyre::new(base.clone())?;
    let (cost_start, samples) = replay_cost(subs, &start_tyre, TransientKind::Relaxation, lateral)?;
    let (cost_steady, _) = replay_cost(subs, &start_tyre, TransientKind::Steady, lateral)?;
    let sigma_start = nominal_sigma(&start_tyre, lateral);
    let sigma_fit = {
        let mut t = base.clone();
        t.set(key, value_for(key, start, u.exp()))?;
        nominal_sigma(&Tyre::new(t)?, lateral)
    };
    let travel = rolled_per_sample(subs);
    // Reference "no lag": the same model at the shortest length searched
    // (the steady model's own replay path differs — range limits, speed
    // handling — so it is reported but not compared against).
    let gain = 1.0 - cost / costs[0];
    // (A NaN gain — a non-finite cost — is "not identified" as well.)
    let note = if gain.is_nan() || gain < MIN_GAIN {
        format!(
            "no lag resolved: the best relaxation length lowers the cost by {:.2} % of that at σ/30 (need {:.1} %)",
            100.0 * gain,
            100.0 * MIN_GAIN
        )
    } else if best == 0 && u <= us[1] {
        format!(
            "no lag resolved: the best relaxation length is at the short end of the search (σ/σ_start = {:.3})",
            u.exp()
        )
    } else if sigma_fit < travel {
        format!(
            "no lag resolved: σ = {sigma_fit:.3} m is shorter than the {travel:.3} m rolled between samples (a lag that settles within one sample only smooths input noise)"
        )
    } else {
        String::new()
    };
    let identified = note.is_empty();
    let value = if identified {
        value_for(key, start, u.exp())
    } else {
        start
    };
    if identified {
        tyre.set(key, value)?;
    }
    let sigma = nominal_sigma(&Tyre::new(tyre.clone())?, lateral);
    Ok(RelaxationFit {
        channel: channel.to_string(),
        key: key.to_string(),
        start,
        value,
        sigma_start,
        sigma,
        cost_steady,
        cost_start,
        cost: if identified { cost } else { cost_start },
        samples,
        evaluations,
        identified,
        note,
    })
}
