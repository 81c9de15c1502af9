//! relaxation — transient slip lag: relaxation lengths through the standard carcass-stiffness keys, replayed with the relaxation transient model.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{file, key, nominal_props, p, ParamCandidate, Spec};
use super::work::Memory;
use super::Reestimation;
use super::{FX, FY, MZ};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::tir::MfVersion;
use crate::transient::TransientKind;

/// Lowest carcass stiffness fitted, as a fraction of the file's.
const LOWEST: f64 = 0.05;

/// Relaxation lengths through the standard keys: MF 6.1/6.2 derive
/// σ = K/C from the carcass stiffnesses (LONGITUDINAL_STIFFNESS,
/// LATERAL_STIFFNESS; Pacejka 3rd ed. §7.2, eqs 7.9–7.12), MF 5.2/PAC2002
/// from PTX*/PTY* with the scale factors LSGKP, LSGAL. Longitudinal and
/// lateral fitted separately (their ratio is the tyre's, not the file's).
fn relaxation_spec(t: &Tyre, o: &ReplayOptions) -> Option<Spec> {
    let legacy = matches!(t.version(), MfVersion::Mf52 | MfVersion::Pac2002);
    let (kx, ky) = if legacy {
        ("LSGKP", "LSGAL")
    } else {
        ("LONGITUDINAL_STIFFNESS", "LATERAL_STIFFNESS")
    };
    let q = |k: &'static str| {
        let v = file(t, k);
        let v = if v.is_finite() && v > 0.0 { v } else { 1.0 };
        p(k, vec![key(k)], v, LOWEST * v, 20.0 * v, 0.02 * v)
    };
    // σ = K/C: the longest lag is the file's at the lowest stiffness.
    let s = nominal_props(t, o);
    let lag = s.sigmax.max(s.sigmay) / LOWEST;
    Some(Spec {
        params: vec![q(kx).on(&[FX]), q(ky).on(&[FY, MZ])],
        kind: Some(TransientKind::Relaxation),
        memory: Memory::rolled(lag),
        prescan: 2,
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "relaxation",
        physics:
            "transient slip lag: the force builds up over a rolled distance (relaxation length)",
        n: 2,
        spec: relaxation_spec,
        words: |f| {
            let o = nominal_props(f.tyre(), &ReplayOptions::default());
            format!(
                "a lateral relaxation length of {:.3} m and a longitudinal one of {:.3} m at the nominal load",
                o.sigmay, o.sigmax
            )
        },
        reestimation: Reestimation::ThroughScales,
        refits_baseline: false,
    }
}
