//! speed_friction — friction falling with sliding speed (the MF's LMUV).
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, key, p, param, ParamCandidate, Spec};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;

fn speed_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    Some(Spec {
        params: vec![p(
            "LMUV",
            vec![key("LMUV")],
            file(t, "LMUV").max(0.0),
            0.0,
            10.0,
            0.005,
        )],
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "speed_friction",
        physics: "friction falls with the sliding speed",
        n: 1,
        spec: speed_spec,
        words: |f| {
            let v0 = f.tyre().params().p.longvl;
            let l = param(f, "LMUV");
            format!(
                "LMUV = {l:.3}: friction {:.1} % lower at 5 m/s sliding speed (V0 = {v0:.1} m/s)",
                100.0 * (1.0 - 1.0 / (1.0 + l * 5.0 / v0))
            )
        },
    }
}
