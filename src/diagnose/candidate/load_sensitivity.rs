//! load_sensitivity — friction, slip stiffness and aligning moment depending
//! on load beyond the Magic Formula's own load forms, as curves of general
//! shape over the recorded load range (`[LOAD_SENSITIVITY]` FZ1…, MU_FZ1…,
//! K_FZ1…, MZ_FZ1…; see [`crate::transient::extension::LoadCurve`]).
//!
//! Shape: multipliers of friction s and slip stiffness c, each a natural
//! cubic spline through [`KNOTS`] knot loads placed at quantiles of the fit
//! half's loads (lowest level, median, highest level) and constant beyond —
//! a smooth curve that may rise, fall, level off or peak anywhere in the
//! range (linear, saturating, power-law, a hump), where the earlier form
//! (1 + a·dfz + b·dfz², one stiffness slope, all about the file's Fz0)
//! fixed its shape. The parameter count (3 per curve) is what the
//! information criterion charges ([`super::evaluate`]: k·ln n_eff), so the
//! freedom must pay for itself on held-out segments: on the dev set four
//! knots per curve gained more held-out error (r12 Fy 11.6 % against
//! 10.3 %) but lost the BIC (+2.6 against −5.4), so three it is. The file
//! format also carries an aligning-moment curve (`MZ_FZi`), which this
//! candidate does not fit: on r11/r12 it came out within 1 % except at the
//! lowest load and cost the BIC more than it gained.
//!
//! Must never: fit a parameter outside the range written here, place a
//! knot outside the recorded loads, or describe a value the fit did not
//! produce.

use super::param::{p, ParamCandidate, Spec, Target};
use super::Fitted;
use super::Reestimation;
use crate::data::Recording;
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::transient::extension::{
    LOAD_FZ_KEYS, LOAD_K_KEYS, LOAD_MU_KEYS, LOAD_MZ_KEYS, LOAD_SECTION,
};

/// Knots per curve: the low, middle and high load of the programme — the
/// fewest that let a curve bend (two would be a straight line in Fz).
pub const KNOTS: usize = 3;
/// Quantiles of the fit half's loads at which the knots sit: 5 % and 95 %
/// keep load-transition samples out of the outer knots, which then sit on
/// the lowest and highest load levels of a stepped programme.
const QUANTILES: [f64; KNOTS] = [0.05, 0.5, 0.95];
/// Smallest ratio of the highest to the lowest knot load: below it the fit
/// half has one load level and a load curve has nothing to resolve.
const MIN_LOAD_RATIO: f64 = 1.3;
/// Range of the relative friction change at a knot: ±50 % (a baseline
/// further off at some load is a misfit, not this physics).
const MU_RANGE: (f64, f64) = (-0.5, 0.5);
/// Range of the relative slip-stiffness change at a knot (−60 %…+100 %).
const K_RANGE: (f64, f64) = (-0.6, 1.0);

/// Knot loads from the fit half (see [`QUANTILES`]); None when its loads
/// span less than [`MIN_LOAD_RATIO`].
fn knots(rec: &Recording, mask: &[bool]) -> Option<Vec<(Target, f64)>> {
    let mut fz: Vec<f64> = rec
        .samples
        .iter()
        .zip(mask)
        .filter(|(s, m)| **m && s.fz.is_finite() && s.fz > 0.0)
        .map(|(s, _)| s.fz)
        .collect();
    if fz.len() < 10 {
        return None;
    }
    fz.sort_by(f64::total_cmp);
    let q = |x: f64| fz[((x * (fz.len() - 1) as f64).round() as usize).min(fz.len() - 1)];
    let n = KNOTS;
    let (lo, hi) = (q(QUANTILES[0]), q(QUANTILES[2]));
    if !(hi > MIN_LOAD_RATIO * lo) {
        return None;
    }
    let mut at: Vec<f64> = (0..n)
        .map(|i| q(QUANTILES[0] + (QUANTILES[2] - QUANTILES[0]) * i as f64 / (n - 1) as f64))
        .collect();
    // Interior knots strictly inside and apart (a programme with fewer
    // levels than knots puts quantiles on one level): evenly spaced then.
    let gap = 0.1 * (hi - lo) / (n - 1) as f64;
    if at.windows(2).any(|w| !(w[1] - w[0] > gap)) {
        at = (0..n)
            .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
            .collect();
    }
    Some(
        at.iter()
            .zip(LOAD_FZ_KEYS)
            .map(|(&f, k)| (Target::Section(LOAD_SECTION, k), f))
            .collect(),
    )
}

fn load_spec(_: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let l = |k| vec![Target::Section(LOAD_SECTION, k)];
    let mut params = Vec::with_capacity(2 * KNOTS);
    for i in 0..KNOTS {
        params.push(p(
            LOAD_MU_KEYS[i],
            l(LOAD_MU_KEYS[i]),
            0.0,
            MU_RANGE.0,
            MU_RANGE.1,
            0.002,
        ));
        params.push(p(
            LOAD_K_KEYS[i],
            l(LOAD_K_KEYS[i]),
            0.0,
            K_RANGE.0,
            K_RANGE.1,
            0.002,
        ));
    }
    Some(Spec {
        params,
        from_data: Some(knots),
        eliminate: true,
        ..Spec::default()
    })
}

/// The fitted curves in words: per knot load (kN), the change of each
/// multiplier that was fitted.
fn words(f: &dyn Fitted) -> String {
    let t = f.tyre().params();
    let fitted = f.parameters();
    let at = |keys: &[&str; 5], what: &str| -> Option<String> {
        let parts: Vec<String> = (0..keys.len())
            .filter_map(|i| {
                let v = fitted.iter().find(|(k, _)| k == keys[i])?.1;
                let fz = t.extra_number(LOAD_SECTION, LOAD_FZ_KEYS[i])?;
                Some(format!("{:+.1} % at {:.2} kN", 100.0 * v, fz / 1000.0))
            })
            .collect();
        (!parts.is_empty()).then(|| format!("{what} {}", parts.join(", ")))
    };
    let all: Vec<String> = [
        at(&LOAD_MU_KEYS, "peak friction"),
        at(&LOAD_K_KEYS, "slip stiffness"),
        at(&LOAD_MZ_KEYS, "aligning moment"),
    ]
    .into_iter()
    .flatten()
    .collect();
    if all.is_empty() {
        "no load curve fitted".into()
    } else {
        format!(
            "{} (a smooth curve through these loads, against the baseline)",
            all.join("; ")
        )
    }
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "load_sensitivity",
        physics: "peak friction and slip stiffness depend on load beyond the Magic Formula's forms",
        n: 2 * KNOTS,
        spec: load_spec,
        words,
        reestimation: Reestimation::ThroughScales,
        refits_baseline: false,
    }
}
