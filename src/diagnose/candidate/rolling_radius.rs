//! rolling_radius — the effective rolling radius Re(Fz) (Q_RE0, FREFF), with κ re-derived from it.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, key, p, param, ParamCandidate, Spec};
use super::FX;
use crate::mf::Tyre;
use crate::residual::ReplayOptions;

fn radius_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let (q, f) = (file(t, "Q_RE0"), file(t, "FREFF"));
    Some(Spec {
        params: vec![
            p("Q_RE0", vec![key("Q_RE0")], q, q - 0.1, q + 0.1, 1e-4).on(&[FX]),
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
        n: 2,
        spec: radius_spec,
        words: |f| {
            format!(
                "effective rolling radius keys Q_RE0 = {:.4}, FREFF = {:.3} (Re(Fz) of the extended file)",
                param(f, "Q_RE0"),
                param(f, "FREFF")
            )
        },
    }
}
