//! pressure — the MF 6.x inflation-pressure terms of slip stiffness and friction (PPX*, PPY*).
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, is_mf6, key, p, param, ParamCandidate, Spec};
use super::{FX, FY, MZ};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;

fn pressure_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    if !is_mf6(t) {
        return None;
    }
    let q = |k: &'static str| p(k, vec![key(k)], file(t, k), -3.0, 3.0, 0.005);
    Some(Spec {
        params: vec![
            q("PPX1").on(&[FX]),
            q("PPX3").on(&[FX]),
            q("PPX4").on(&[FX]),
            q("PPY1").on(&[FY, MZ]),
            q("PPY3").on(&[FY, MZ]),
            q("PPY4").on(&[FY, MZ]),
        ],
        levels: Some((|g| g.p, 5e3)),
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "pressure",
        physics: "the inflation pressure changes slip stiffness and peak friction",
        n: 6,
        spec: pressure_spec,
        words: |f| {
            let mut parts = Vec::new();
            for (a, b, c, what) in [
                ("PPX1", "PPX3", "PPX4", "Fx"),
                ("PPY1", "PPY3", "PPY4", "Fy"),
            ] {
                let (x, y, z) = (param(f, a), param(f, b), param(f, c));
                if x.is_finite() && y.is_finite() && z.is_finite() {
                    // Slip stiffness ∝ (1 + PP?1·dpi), friction ∝ (1 + PP?3·dpi)
                    // (MF 6.1, Pacejka 3rd ed. eqs 4.E15/4.E25 and 4.E13/4.E23:
                    // (1 + PP?1·dpi), (1 + PP?3·dpi + PP?4·dpi²),
                    // dpi = (p − p0)/p0; PPX2, PPY2 held at 0).
                    parts.push(format!(
                        "{what} slip stiffness {:+.1} % and peak friction {:+.1} % at +10 % pressure, peak friction {:+.1} % at −10 % ({a} = {x:.3}, {b} = {y:.3}, {c} = {z:.3})",
                        10.0 * x,
                        10.0 * y + z,
                        -10.0 * y + z
                    ));
                }
            }
            parts.join("; ")
        },
    }
}
