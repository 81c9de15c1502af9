//! camber — the MF's inclination terms of Fy and Mz.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, is_mf6, key, p, ParamCandidate, Spec};
use super::Reestimation;
use super::{FY, MZ};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;

/// The MF's camber terms: friction loss with γ² (PDY3), camber stiffness
/// (MF 6.x: PKY6 and its load dependence PKY7, eq. 4.E30; MF 5.2/PAC2002:
/// PKY3, the cornering-stiffness change with γ, and the horizontal shift
/// PHY3), the vertical shift (PVY3), the shift of the pneumatic trail's
/// slip angle with γ (QHZ3, eq. 4.E35: a camber that acts as extra slip
/// angle moves the trail curve with the force curve; MF 6.1's trail term
/// multiplies the γ = 0 lateral force, so Fy's camber terms do not carry
/// over to Mz) and the residual torque's camber terms (QDZ8, QDZ9 with
/// load, eq. 4.E47). Without PKY7, QHZ3 and QDZ9 the proof's
/// camber-as-slip-angle truth was recovered to 44–59 %; with them 88–97 %.
fn camber_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let q = |k: &'static str, h: f64| p(k, vec![key(k)], file(t, k), -50.0, 50.0, h);
    let (stiff, stiff2) = if is_mf6(t) {
        ("PKY6", "PKY7")
    } else {
        ("PKY3", "PHY3")
    };
    Some(Spec {
        params: vec![
            q("PDY3", 0.02).on(&[FY, MZ]),
            q(stiff, 0.01).on(&[FY, MZ]),
            q(stiff2, 0.01).on(&[FY, MZ]),
            q("PVY3", 0.005).on(&[FY, MZ]),
            q("QHZ3", 0.002).on(&[MZ]),
            q("QDZ8", 0.005).on(&[MZ]),
            q("QDZ9", 0.005).on(&[MZ]),
        ],
        levels: Some((|g| g.gamma, 0.5f64.to_radians())),
        eliminate: true,
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "camber",
        physics: "inclination acts on the forces differently from the model (camber thrust, camber friction loss, camber moment)",
        n: 7,
        spec: camber_spec,
        words: |f| {
            f.parameters()
                .iter()
                .map(|(k, v)| format!("{k} = {v:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        },
        reestimation: Reestimation::No,
        refits_baseline: true,
    }
}
