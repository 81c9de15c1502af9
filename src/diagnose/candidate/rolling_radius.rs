//! rolling_radius — the effective rolling radius Re(Fz) (Q_RE0, DREFF,
//! FREFF: a level, a saturating and a linear fall with load, Pacejka, *Tire
//! and Vehicle Dynamics*, 3rd ed., eq. A3.3), with κ re-derived from it at
//! the recorded wheel speed.
//!
//! The baseline's κ follows the recording's own slip ratio where one is
//! recorded ([`crate::data::slip`]); when the rig computed that slip ratio
//! with a radius that is not the tyre's (a constant, or another load law),
//! the free-rolling wheel shows drive or brake force that varies with load,
//! and this candidate finds the radius that removes it.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, key, p, param, ParamCandidate, Spec};
use super::Reestimation;
use super::FX;
use crate::mf::Tyre;
use crate::residual::ReplayOptions;

fn radius_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let (q, d, f) = (file(t, "Q_RE0"), file(t, "DREFF"), file(t, "FREFF"));
    Some(Spec {
        params: vec![
            p("Q_RE0", vec![key("Q_RE0")], q, q - 0.1, q + 0.1, 1e-4).on(&[FX]),
            p("DREFF", vec![key("DREFF")], d, d - 1.0, d + 1.0, 2e-3).on(&[FX]),
            p("FREFF", vec![key("FREFF")], f, f - 2.0, f + 2.0, 2e-3).on(&[FX]),
        ],
        kappa_re: true,
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "rolling_radius",
        physics: "the effective rolling radius varies with load differently from the model, which shifts the slip ratio the tyre sees",
        n: 3,
        spec: radius_spec,
        words: |f| {
            format!(
                "effective rolling radius keys Q_RE0 = {:.4}, DREFF = {:.3}, FREFF = {:.3} (Re(Fz) of the extended file)",
                param(f, "Q_RE0"),
                param(f, "DREFF"),
                param(f, "FREFF")
            )
        },
        reestimation: Reestimation::No,
        refits_baseline: false,
    }
}
