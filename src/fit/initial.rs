//! initial — data-driven initial estimates of the pure-slip Magic Formula
//! coefficients, as MF-Tool and OptimumTire make them: per load bin of the
//! pure-slip samples (near-zero inclination), the peak D, the slope at zero
//! slip K, the asymptote at large slip and the slip of the peak; from them
//! C, B = K/(CD) and E, then the load trends (D/Fz and E linear in dfz, K by
//! its MF 6.1 load law). One more start for a stage's multi-start
//! ([`super::mf_stages::fit_stage`]), far from the start tyre's basin
//! when the start tyre is a different tyre.
//!
//! Equations: Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., pure slip
//! 4.E9–4.E18 (Fx), 4.E19–4.E30 (Fy); the C from the asymptote ya and the E
//! from the peak slip xm are Pacejka §4.3.2, eqs. 4.8 and 4.9
//! (C = 1 ± (1 − 2/π·asin(ya/D)), E = (B·xm − tan(π/2C))/(B·xm − atan(B·xm))).
//!
//! Must never: return a start outside the stage's bounds, invent a value the
//! data do not show (a coefficient it cannot estimate keeps its current
//! value), or allocate per sample of the hot path (it runs once per stage).

use super::mf_stages::{StageData, StageKind};
use super::problem::Param;
use crate::tir::MfParams;
use std::f64::consts::PI;

/// Slip below which a sweep is taken as linear for the slope K: 1.5° of α,
/// 1.5 % of κ (both well inside the linear range of car and FSAE tyres,
/// whose peaks lie at 4–12° and 8–15 %).
const LINEAR_SLIP: f64 = 1.5 * PI / 180.0;
/// Inclination below which a sample counts as upright (0.5°: below any
/// test plan's camber step).
const UPRIGHT: f64 = 0.5 * PI / 180.0;
/// Fewest samples for a load bin (its peak and slope need a sweep).
const BIN_MIN: usize = 100;
/// A gap in the sorted loads wider than this fraction of the largest load
/// separates two load bins (test plans step the load by ≥ 20 %).
const BIN_GAP: f64 = 0.08;
/// A load cell ([`BIN_GAP`]/2 of the largest load wide) holding fewer
/// samples than this share of the fullest cell is a ramp between set
/// points, not a set point: its samples are left out of the bins. A sweep
/// at a set point fills one or two cells with thousands of samples; the
/// rig's load ramps cross a cell in a fraction of a sweep (a few % of a
/// set point's count per cell) yet close every gap between set points.
const RAMP_SHARE: f64 = 0.1;

/// One load bin's estimates.
struct Bin {
    fz: f64,
    d: f64,
    k: f64,
    c: Option<f64>,
    /// |slip| of the peak.
    xm: f64,
    /// |slip| of the peak on the positive and on the negative side of the
    /// slip (None where a side has no samples near its peak).
    xm_side: [Option<f64>; 2],
}

/// Estimates for a pure Fx or Fy stage over `params` (θ over the stage's
/// table, the current values where nothing is estimated): the estimate,
/// then — for a curve whose two sides' curvatures differ by more than
/// [`SIDE_SPREAD`] — the same with its flatter side's E at the estimate's
/// largest (see [`flat_top`]). Empty for other stages or when no usable
/// load bin is found.
pub fn estimate(
    kind: StageKind,
    p: &MfParams<f64>,
    data: &StageData,
    params: &[Param],
) -> Vec<Vec<f64>> {
    estimate_sets(kind, p, data)
        .unwrap_or_default()
        .into_iter()
        .filter(|set| set.iter().all(|(_, v)| v.is_finite()))
        .map(|set| {
            params
                .iter()
                .map(
                    |q| match set.iter().find(|(k, _)| q.name.eq_ignore_ascii_case(k)) {
                        Some((_, v)) if q.free => q.clamp(*v),
                        _ => q.start,
                    },
                )
                .collect()
        })
        .collect()
}

/// Difference between the two sides' estimated curvatures E₊, E₋ above
/// which [`estimate`] adds the flat-top start (0.2: well above the
/// scatter of E read from the peak slip of a symmetric curve's two sides).
pub const SIDE_SPREAD: f64 = 0.2;

/// The largest curvature an estimate gives (E read from the peak slip is
/// clamped to it; 1 is the validity bound).
const E_MAX: f64 = 0.9;

/// The flat-top variant of an estimate's curvature: both sides' E moved
/// by the same amount until the flatter side reaches [`E_MAX`], returned
/// as (E0 shift, sign term). E read from the peak slip (4.9) depends on
/// the C and B estimated with it, so its level is uncertain while the
/// difference between the sides is what the sweep shows directly — and the
/// level decides the branch: E = E0·(1 − a·sgn x) with the sides of
/// opposite signs (|a| > 1) is reached by LM only from a start with E0 of
/// the right sign, since between the branches lies E0 = 0, where a is not
/// identified. A side whose force still rises at the end of the sweep (a
/// TTC-fitted FSAE tyre's driving side: E = +0.99 against −0.08 braking)
/// reads as the flatter side with too low an E.
fn flat_top(e_pos: f64, e_neg: f64) -> Option<(f64, f64)> {
    let shift = E_MAX - e_pos.max(e_neg);
    let (p, n) = (e_pos + shift, e_neg + shift);
    ((e_pos - e_neg).abs() > SIDE_SPREAD && shift > 0.05 && (p + n).abs() > 1e-3)
        .then(|| (shift, (n - p) / (n + p)))
}

/// The (key, value) sets behind [`estimate`].
fn estimate_sets(
    kind: StageKind,
    p: &MfParams<f64>,
    data: &StageData,
) -> Option<Vec<Vec<(&'static str, f64)>>> {
    let lateral = match kind {
        StageKind::PureFy => true,
        StageKind::PureFx => false,
        _ => return None,
    };
    let y = data.meas.first()?;
    let slip = |i: usize| {
        if lateral {
            data.conds[i].alpha
        } else {
            data.conds[i].kappa
        }
    };
    let mut idx: Vec<usize> = (0..data.conds.len())
        .filter(|&i| data.conds[i].gamma.abs() < UPRIGHT && y[i].is_finite())
        .collect();
    if idx.len() < BIN_MIN {
        idx = (0..data.conds.len())
            .filter(|&i| y[i].is_finite())
            .collect();
    }
    idx.sort_by(|&a, &b| data.conds[a].fz.total_cmp(&data.conds[b].fz));
    let fz_max = idx.last().map(|&i| data.conds[i].fz)?;
    let fz = |i: usize| data.conds[i].fz;
    let idx = without_ramps(&idx, &fz, fz_max);
    let cell = |i: usize| load_cell(fz(i), fz_max);
    let mut bins = Vec::new();
    let mut lo = 0;
    for j in 1..=idx.len() {
        let split = j == idx.len()
            || fz(idx[j]) - fz(idx[j - 1]) > BIN_GAP * fz_max
            || cell(idx[j]) > cell(idx[j - 1]) + 1;
        if split {
            if j - lo >= BIN_MIN {
                if let Some(b) = bin(&idx[lo..j], &|i| slip(i), y, &fz, lateral) {
                    bins.push(b);
                }
            }
            lo = j;
        }
    }
    if bins.is_empty() {
        return None;
    }
    let fz0 = p.get("fnomin")? * p.get("lfzo").unwrap_or(1.0);
    let dfz = |fz: f64| (fz - fz0) / fz0;
    let mut set: Vec<(&'static str, f64)> = Vec::new();
    let (c_key, d1, d2, e1, e2, e_sign) = if lateral {
        ("pcy1", "pdy1", "pdy2", "pey1", "pey2", "pey3")
    } else {
        ("pcx1", "pdx1", "pdx2", "pex1", "pex2", "pex4")
    };
    // C: the mean over bins whose sweep reached the asymptote; else current.
    let cs: Vec<f64> = bins.iter().filter_map(|b| b.c).collect();
    let c = if cs.is_empty() {
        p.get(c_key)?
    } else {
        cs.iter().sum::<f64>() / cs.len() as f64
    };
    set.push((c_key, c));
    // μ = D/Fz linear in dfz (4.E14, 4.E23 at nominal pressure, upright).
    let mu: Vec<(f64, f64)> = bins.iter().map(|b| (dfz(b.fz), b.d / b.fz)).collect();
    let (m0, m1) = line(&mu);
    set.push((d1, m0));
    if bins.len() > 1 {
        set.push((d2, m1));
    }
    // E from the peak slip per bin (B = K/(CD)), linear in dfz, from the
    // peak slip pooled over both sides; where the sweep reached both
    // sides' peaks, E on each side too (for the flat-top start below).
    let e_at = |b: &Bin, xm: f64| {
        let bx = (b.k / (c * b.d)).abs() * xm;
        ((bx - (PI / (2.0 * c)).tan()) / (bx - bx.atan())).clamp(-5.0, 0.9)
    };
    let side_es = |b: &Bin| match b.xm_side {
        [Some(p), Some(n)] => Some((e_at(b, p), e_at(b, n))),
        _ => None,
    };
    let sides: Vec<(f64, f64)> = bins.iter().filter_map(side_es).collect();
    let es: Vec<(f64, f64)> = bins.iter().map(|b| (dfz(b.fz), e_at(b, b.xm))).collect();
    let (ea, eb) = line(&es);
    set.push((e1, ea));
    if bins.len() > 1 {
        set.push((e2, eb));
    }
    let n_sides = sides.len().max(1) as f64;
    let (ep, en) = sides.iter().fold((0.0, 0.0), |(a, b), (p, n)| {
        (a + p / n_sides, b + n / n_sides)
    });
    let flat = (!sides.is_empty()).then(|| flat_top(ep, en)).flatten();
    if lateral {
        // Kya = PKY1·Fz0·sin(PKY4·atan(Fz/(PKY2·Fz0))) (4.E25, upright):
        // PKY4 kept, PKY2 on a grid, PKY1 by least squares for each.
        let pky4 = p.get("pky4")?;
        let fit_k = |pky2: f64| {
            let g: Vec<(f64, f64)> = bins
                .iter()
                .map(|b| (fz0 * (pky4 * (b.fz / (pky2 * fz0)).atan()).sin(), b.k))
                .collect();
            let gg: f64 = g.iter().map(|(a, _)| a * a).sum();
            let pky1 = g.iter().map(|(a, k)| a * k).sum::<f64>() / gg;
            let sse: f64 = g.iter().map(|(a, k)| (pky1 * a - k).powi(2)).sum();
            (sse, pky1, pky2)
        };
        let best = if bins.len() > 1 {
            (0..40)
                .map(|i| fit_k(0.3 + 0.15 * i as f64))
                .min_by(|a, b| a.0.total_cmp(&b.0))?
        } else {
            fit_k(p.get("pky2")?)
        };
        set.push(("pky1", best.1));
        set.push(("pky2", best.2));
    } else {
        // Kxκ = Fz·(PKX1 + PKX2·dfz)·exp(PKX3·dfz) (4.E15), PKX3 = 0 start.
        let k: Vec<(f64, f64)> = bins.iter().map(|b| (dfz(b.fz), b.k / b.fz)).collect();
        let (k0, k1) = line(&k);
        set.push(("pkx1", k0));
        if bins.len() > 1 {
            set.push(("pkx2", k1));
            set.push(("pkx3", 0.0));
        }
    }
    // The flat-top start: the sign term (PEX4 in 4.E14, PEY3 in 4.E24),
    // E = E0·(1 − a·sgn x), from the two sides' shifted curvatures, and
    // E0 their mean. A tyre whose curvature has opposite signs driving and
    // braking (|a| > 1) is reached only from a start on its side: from
    // a = 0 the fit would have to take E0 through zero, where a is not
    // identified. The main estimate keeps the pooled E and the current
    // sign term: the per-side E is the less certain reading (fewer
    // samples near each side's peak), and a start built on it alone
    // misled the fit of symmetric curves.
    let mut sets = vec![set.clone()];
    if let Some((shift, a)) = flat {
        set.retain(|(k, _)| *k != e_sign && *k != e1);
        set.push((e_sign, a));
        set.push((e1, 0.5 * (ep + en) + shift));
        sets.push(set);
    }
    Some(sets)
}

/// `idx` (sorted by load) without the samples of sparse load cells — the
/// ramps between set points ([`RAMP_SHARE`]). Two kept samples whose
/// cells are not adjacent have a ramp removed between them and belong to
/// different bins.
fn without_ramps(idx: &[usize], fz: &dyn Fn(usize) -> f64, fz_max: f64) -> Vec<usize> {
    let mut counts: std::collections::BTreeMap<i64, usize> = Default::default();
    for &i in idx {
        *counts.entry(load_cell(fz(i), fz_max)).or_default() += 1;
    }
    let fullest = counts.values().copied().max().unwrap_or(0) as f64;
    idx.iter()
        .copied()
        .filter(|&i| counts[&load_cell(fz(i), fz_max)] as f64 >= RAMP_SHARE * fullest)
        .collect()
}

/// The load cell of `fz` ([`without_ramps`]): width [`BIN_GAP`]/2 of `fz_max`.
fn load_cell(fz: f64, fz_max: f64) -> i64 {
    (fz / (0.5 * BIN_GAP * fz_max.abs().max(f64::MIN_POSITIVE))).floor() as i64
}

/// Least-squares line y = a + b·x through `pts` (a flat line through one
/// point or identical x).
fn line(pts: &[(f64, f64)]) -> (f64, f64) {
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx > 1e-12 {
        let b = sxy / sxx;
        (my - b * mx, b)
    } else {
        (my, 0.0)
    }
}

/// Peak, slope, C and peak slip of one load bin (samples `ix`).
fn bin(
    ix: &[usize],
    slip: &dyn Fn(usize) -> f64,
    y: &[f64],
    fz: &dyn Fn(usize) -> f64,
    lateral: bool,
) -> Option<Bin> {
    let n = ix.len() as f64;
    let fz_mean = ix.iter().map(|&i| fz(i)).sum::<f64>() / n;
    // Peaks: the 1st and 99th percentiles (robust to noise spikes), half
    // their span is D; the signed sweep must reach both sides.
    let mut ys: Vec<f64> = ix.iter().map(|&i| y[i]).collect();
    ys.sort_by(|a, b| a.total_cmp(b));
    let q = |f: f64| ys[((ys.len() - 1) as f64 * f) as usize];
    let (ylo, yhi) = (q(0.01), q(0.99));
    if !(ylo < 0.0 && yhi > 0.0) {
        return None;
    }
    let d = 0.5 * (yhi - ylo);
    // Slope at zero slip: least squares over |slip| < LINEAR_SLIP.
    let lin: Vec<(f64, f64)> = ix
        .iter()
        .filter(|&&i| slip(i).abs() < LINEAR_SLIP)
        .map(|&i| (slip(i), y[i]))
        .collect();
    if lin.len() < 20 {
        return None;
    }
    let (_, k) = line(&lin);
    let sign_ok = if lateral { k < 0.0 } else { k > 0.0 };
    if !sign_ok {
        return None;
    }
    // Peak slip: median |slip| of the samples within 3 % of their side's peak.
    let mut near: Vec<f64> = ix
        .iter()
        .filter(|&&i| y[i] >= 0.97 * yhi || y[i] <= 0.97 * ylo)
        .map(|&i| slip(i).abs())
        .collect();
    near.sort_by(|a, b| a.total_cmp(b));
    let xm = *near.get(near.len() / 2)?;
    let side = |positive: bool| {
        let on_side = |i: &&usize| (slip(**i) > 0.0) == positive;
        let mut v: Vec<f64> = ix
            .iter()
            .filter(|&&i| y[i] >= 0.97 * yhi || y[i] <= 0.97 * ylo)
            .filter(on_side)
            .map(|&i| slip(i).abs())
            .collect();
        v.sort_by(|a, b| a.total_cmp(b));
        v.get(v.len() / 2).copied()
    };
    let xm_side = [side(true), side(false)];
    // Asymptote: mean |F| over the largest 5 % of |slip|; C only where the
    // force there has fallen clearly below the peak (else the sweep ended
    // near the peak and C is not seen).
    let mut by_slip: Vec<usize> = ix.to_vec();
    by_slip.sort_by(|&a, &b| slip(b).abs().total_cmp(&slip(a).abs()));
    let tail = &by_slip[..(by_slip.len() / 20).max(1)];
    let xmax = slip(tail[tail.len() - 1]).abs();
    let ya = tail.iter().map(|&i| y[i].abs()).sum::<f64>() / tail.len() as f64;
    let c = (xmax > 1.5 * xm && ya < 0.95 * d)
        .then(|| 1.0 + (1.0 - 2.0 / PI * (ya / d).asin()))
        .map(|c| c.clamp(1.0, 2.0));
    (d > 0.0 && xm > 0.0).then_some(Bin {
        fz: fz_mean,
        d,
        k,
        c,
        xm,
        xm_side,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::mf_stages::{stage_params, USE_MODE};
    use crate::mf::{form_of, Conditions, MfInput, Model};
    use crate::tir::TyreParams;

    /// The pure-slip stage of Fy (`lateral`) or Fx.
    fn pure_kind(lateral: bool) -> StageKind {
        if lateral {
            StageKind::PureFy
        } else {
            StageKind::PureFx
        }
    }

    /// Noise-free sweeps of a known tyre (the built-in 205/60R15) at three
    /// loads; returns the data and the curve of a parameter set.
    fn sweeps(p: &MfParams<f64>, lateral: bool) -> StageData {
        let model = Model::new(p.clone(), form_of(TyreParams::builtin().version));
        let fz0 = p.get("fnomin").unwrap();
        let mut d = StageData {
            meas: vec![Vec::new()],
            ..Default::default()
        };
        for load in [0.5, 1.0, 1.5] {
            for j in 0..=960 {
                let s = -1.0 + j as f64 / 480.0; // −1 … 1
                let inp = MfInput {
                    fz: load * fz0,
                    kappa: if lateral { 0.0 } else { 0.25 * s },
                    alpha: if lateral { s * 12f64.to_radians() } else { 0.0 },
                    vx: 16.7,
                    ..Default::default()
                };
                let c = Conditions::new(p, &inp, USE_MODE).0;
                let sol = model.solve(&c);
                d.meas[0].push(if lateral { sol.fy } else { sol.fx });
                d.conds.push(c);
            }
        }
        d
    }

    /// The estimate, written into the tyre, reproduces the sweeps it came
    /// from within 8 % of the peak force (RMS): the per-bin D, K, C, E are
    /// read from the curve (D from the 1st/99th percentiles, K from the
    /// chord over |slip| < 1.5° / 1.5 % which the curvature lowers by a
    /// few %), so an estimate is not a fit — 8 % is the quality of a
    /// start that lies in the right basin (a start tyre scaled ×2 in D and
    /// ×0.5 in K lies at > 10 %, checked first).
    #[test]
    fn estimates_recover_known_curves() {
        for lateral in [true, false] {
            let truth = TyreParams::builtin().p;
            let kind = pure_kind(lateral);
            let data = sweeps(&truth, lateral);
            // Start far from the truth: D ×2, K ×0.5, C and E off.
            let mut start = truth.clone();
            let keys = if lateral {
                ["pdy1", "pky1", "pcy1", "pey1"]
            } else {
                ["pdx1", "pkx1", "pcx1", "pex1"]
            };
            for (k, f) in keys.iter().zip([2.0, 0.5, 0.8, 0.0]) {
                start.set(k, start.get(k).unwrap() * f);
            }
            let params = stage_params(kind, &start, true, true);
            let theta = estimate(kind, &start, &data, &params)
                .into_iter()
                .next()
                .expect("an estimate");
            let rms = |p: &MfParams<f64>| {
                let d2 = sweeps(p, lateral);
                let peak = data.meas[0].iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let e2: f64 = d2.meas[0]
                    .iter()
                    .zip(&data.meas[0])
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    / data.meas[0].len() as f64;
                e2.sqrt() / peak
            };
            let mut est = start.clone();
            for (q, v) in params.iter().zip(&theta) {
                est.set(&q.name, *v);
                assert!(*v >= q.lower && *v <= q.upper, "{} out of bounds", q.name);
            }
            let (r_start, r_est) = (rms(&start), rms(&est));
            eprintln!("{kind:?}: start RMS {r_start:.3}, estimate {r_est:.3} of the peak");
            assert!(
                r_start > 0.1,
                "{kind:?}: the far start is not far ({r_start:.3})"
            );
            assert!(
                r_est < 0.08,
                "{kind:?}: estimate RMS {r_est:.3} of the peak"
            );
        }
    }

    /// A curve flatter on one side: Fx with Ex +0.99 driving and −0.08
    /// braking (a TTC-fitted FSAE tyre's PEX1 0.46, PEX4 −1.17 on the
    /// built-in tyre). The estimate reads the driving side as the flatter
    /// one (E₊ > E₋) and adds a second start whose mean curvature is
    /// positive — the file's branch — with E₊ > E₋ kept; a curve with equal
    /// sides (PEX4 = 0) gets one start only.
    #[test]
    fn a_curve_flatter_on_one_side_gets_a_flat_top_start() {
        let mut truth = TyreParams::builtin().p;
        for (k, v) in [
            ("pex1", 0.458),
            ("pex2", 0.0),
            ("pex3", 0.0),
            ("pex4", -1.1726),
        ] {
            truth.set(k, v);
        }
        let data = sweeps(&truth, false);
        let start = TyreParams::builtin().p;
        let params = stage_params(StageKind::PureFx, &start, true, true);
        let at = |theta: &[f64], k: &str| {
            theta[params
                .iter()
                .position(|q| q.name.eq_ignore_ascii_case(k))
                .unwrap()]
        };
        let starts = estimate(StageKind::PureFx, &start, &data, &params);
        assert_eq!(starts.len(), 2, "a flat-top start for a one-sided flat top");
        let (e0, a) = (at(&starts[1], "pex1"), at(&starts[1], "pex4"));
        let (e_drive, e_brake) = (e0 * (1.0 - a), e0 * (1.0 + a));
        eprintln!("flat-top start: PEX1 {e0:.3}, PEX4 {a:.3}: Ex {e_drive:.3} / {e_brake:.3}");
        assert!(e0 > 0.0, "mean curvature {e0} not on the file's branch");
        assert!(
            e_drive > e_brake,
            "the flatter side lost: {e_drive} / {e_brake}"
        );
        assert!(e_drive <= E_MAX + 1e-9);
        truth.set("pex4", 0.0);
        let data = sweeps(&truth, false);
        assert_eq!(estimate(StageKind::PureFx, &start, &data, &params).len(), 1);
    }

    /// Load ramps between the set points (as a rig drives them, at zero
    /// slip, 150 samples per ramp) close every gap in the sorted loads; the
    /// estimate must still see three load bins and so the load trends:
    /// the start from the sweeps alone, to 1 % (0.001 on a coefficient
    /// below 0.1) — the ramp samples inside a set point's own load cell stay
    /// in its bin and move its percentiles and mean load slightly (measured:
    /// 0.6 % at most, PDY2). Without the ramp
    /// filter the three loads merge into one bin and PDX2/PDY2 stay at the
    /// start's value (checked: the comparison then fails, PDY1 1.27 with
    /// the ramps against 0.88 without).
    #[test]
    fn load_ramps_do_not_merge_the_load_bins() {
        for lateral in [true, false] {
            let truth = TyreParams::builtin().p;
            let kind = pure_kind(lateral);
            let clean = sweeps(&truth, lateral);
            let mut ramped = clean.clone();
            let fz0 = truth.get("fnomin").unwrap();
            let model = Model::new(truth.clone(), form_of(TyreParams::builtin().version));
            for (a, b) in [(0.5, 1.0), (1.0, 1.5)] {
                for j in 0..150 {
                    let inp = MfInput {
                        fz: fz0 * (a + (b - a) * j as f64 / 150.0),
                        vx: 16.7,
                        ..Default::default()
                    };
                    let c = Conditions::new(&truth, &inp, USE_MODE).0;
                    let sol = model.solve(&c);
                    ramped.meas[0].push(if lateral { sol.fy } else { sol.fx });
                    ramped.conds.push(c);
                }
            }
            let mut start = truth.clone();
            for k in ["pdx2", "pdy2"] {
                start.set(k, 0.0);
            }
            let params = stage_params(kind, &start, true, true);
            let a = estimate(kind, &start, &clean, &params).swap_remove(0);
            let b = estimate(kind, &start, &ramped, &params).swap_remove(0);
            for ((q, x), y) in params.iter().zip(&a).zip(&b) {
                assert!(
                    (x - y).abs() <= 0.01 * x.abs().max(0.1),
                    "{kind:?}: {} {y} with ramps, {x} without",
                    q.name
                );
            }
            let d2 = if lateral { "pdy2" } else { "pdx2" };
            let i = params
                .iter()
                .position(|q| q.name.eq_ignore_ascii_case(d2))
                .unwrap();
            assert!(a[i] != 0.0, "{kind:?}: {d2} not estimated from three loads");
        }
    }
}
