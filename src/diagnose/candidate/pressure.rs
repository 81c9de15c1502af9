//! pressure — the inflation pressure changes slip stiffness, peak friction
//! and the pneumatic trail, fitted on the pressure recorded per sample
//! (discrete set points, a drift, a leak or a saw-tooth alike) with the
//! MF 6.1 first-order pressure terms, written as the standard keys so that
//! the FMU and `replay` apply them with the recorded `p`:
//! * PPX1: Kxκ ∝ (1 + PPX1·dpi) (Pacejka, *Tyre and Vehicle Dynamics*,
//!   3rd ed., eq. 4.E15), PPX3: μx ∝ (1 + PPX3·dpi) (eq. 4.E13, PPX4 = 0);
//! * PPY1: Kyα ∝ (1 + PPY1·dpi) (eq. 4.E25, PPY2 held), PPY3: μy ∝
//!   (1 + PPY3·dpi) (eq. 4.E23, PPY4 = 0);
//! * PPZ1: the pneumatic trail Dt ∝ (1 − PPZ1·dpi) (eq. 4.E42);
//!
//! dpi = (p − p0)/p0, p0 = NOMPRES (eq. 4.E2b). The quadratic terms PPX4, PPY4 are not
//! fitted: a drift of a few % of the pressure cannot tell a curvature from
//! a slope (on r04 of the dev set they ended at their bounds), and the
//! linear law is what a pressure set point ±15 % supports as well.
//! Fitted only when the recorded pressure over the fit half spans clearly
//! more than its noise ([`crate::diagnose::factor`]); at one regulated
//! pressure the terms could only fit sensor noise.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, is_mf6, key, p, param, ParamCandidate, Spec};
use super::Reestimation;
use super::{FX, FY, MZ};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;

/// Range of every fitted pressure term (per unit dpi). The MF 6.1 files of
/// `../shared/data/tir` carry first-order terms up to |4.9| (PPX1 of a
/// racing tyre); ±5 admits them, and a value at ±5 — a 5 % change of
/// stiffness or friction per 1 % of pressure — is reported as a limit.
const RANGE: f64 = 5.0;

/// The fitted terms: (key, channels it acts on).
const TERMS: [(&str, &[usize]); 5] = [
    ("PPX1", &[FX]),
    ("PPX3", &[FX]),
    ("PPY1", &[FY, MZ]),
    ("PPY3", &[FY, MZ]),
    ("PPZ1", &[MZ]),
];

fn pressure_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    if !is_mf6(t) {
        return None;
    }
    Some(Spec {
        params: TERMS
            .iter()
            .map(|&(k, ch)| p(k, vec![key(k)], file(t, k), -RANGE, RANGE, 0.005).on(ch))
            .collect(),
        varies: Some(|s| s.p),
        ..Spec::default()
    })
}

/// Pressure step (Pa) the fitted law is stated at: 10 kPa, the unit of a
/// tyre engineer's pressure sweep, within the span of a set-point ladder
/// or a drift on car and FSAE tyres alike (a 10 % step would state a car
/// tyre's drift of a few % far outside what was recorded).
const WORDS_STEP: f64 = 10e3;

/// The fitted law in words at +[`WORDS_STEP`] over the file's nominal
/// pressure (NOMPRES, whose share dpi the terms multiply).
fn words(f: &dyn super::Fitted) -> String {
    let p0 = f.tyre().params().get("NOMPRES").filter(|p| *p > 0.0);
    let (dpi, at) = match p0 {
        Some(p0) => (
            WORDS_STEP / p0,
            format!(
                "at +{:.0} kPa over {:.0} kPa (+{:.1} %)",
                WORDS_STEP / 1e3,
                p0 / 1e3,
                100.0 * WORDS_STEP / p0
            ),
        ),
        None => (0.1, "at +10 % inflation pressure".to_string()),
    };
    let mut parts = Vec::new();
    let mut term = |k: &str, what: &str, sign: f64| {
        let v = param(f, k);
        if v.is_finite() {
            parts.push(format!(
                "{what} {:+.1} % ({k} = {v:.3})",
                sign * 100.0 * dpi * v
            ));
        }
    };
    term("PPX1", "Fx slip stiffness", 1.0);
    term("PPX3", "Fx peak friction", 1.0);
    term("PPY1", "Fy cornering stiffness", 1.0);
    term("PPY3", "Fy peak friction", 1.0);
    // Dt ∝ (1 − PPZ1·dpi).
    term("PPZ1", "pneumatic trail", -1.0);
    if parts.is_empty() {
        return "no pressure term fitted".into();
    }
    format!("{at}: {}", parts.join(", "))
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "pressure",
        physics: "the inflation pressure changes slip stiffness, peak friction and pneumatic trail",
        n: TERMS.len(),
        spec: pressure_spec,
        words,
        reestimation: Reestimation::AtRecordedPressure,
        refits_baseline: false,
    }
}
