//! lugre — dynamic friction with bristle hysteresis (`[LUGRE]` section), replayed with the LuGre transient model.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{nominal_props, p, param, ParamCandidate, Spec, Target};
use super::work::Memory;
use super::Reestimation;
use super::{FX, FY, MZ};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::transient::lugre::SECTION as LUGRE_SECTION;
use crate::transient::TransientKind;

/// Lowest bristle stiffness fitted, as a fraction of the start.
const LOWEST: f64 = 0.05;

fn lugre_spec(t: &Tyre, o: &ReplayOptions) -> Option<Spec> {
    let s = nominal_props(t, o);
    let fz0 = t.params().p.fnomin.max(1.0);
    // Start: bristles lagging like a 0.3 m relaxation length, K/(Fz0·0.3 m).
    let s0 = |k: f64| (k.abs() / (fz0 * 0.3)).clamp(1.0, 1e5);
    let (sx, sy) = (s0(s.kxk), s0(s.kya));
    // At small slip the bristles lag like a relaxation length K/(Fz0·σ0):
    // the longest at the lowest stiffness of the range.
    let lag = (s.kxk.abs() / (fz0 * LOWEST * sx)).max(s.kya.abs() / (fz0 * LOWEST * sy));
    let sec = |k| vec![Target::Section(LUGRE_SECTION, k)];
    Some(Spec {
        params: vec![
            p(
                "SIGMA0X",
                sec("SIGMA0X"),
                sx,
                LOWEST * sx,
                20.0 * sx,
                0.02 * sx,
            )
            .on(&[FX]),
            p(
                "SIGMA0Y",
                sec("SIGMA0Y"),
                sy,
                LOWEST * sy,
                20.0 * sy,
                0.02 * sy,
            )
            .on(&[FY, MZ]),
            p("MUS", sec("MUS"), 1.0, 0.7, 2.0, 0.01),
        ],
        kind: Some(TransientKind::LuGre),
        memory: Memory::rolled(lag),
        prescan: 2,
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "lugre",
        physics: "dynamic friction with bristle hysteresis (LuGre): the force lags and overshoots with the sliding history",
        n: 3,
        spec: lugre_spec,
        words: |f| {
            let mut parts = Vec::new();
            for (k, what) in [("SIGMA0X", "longitudinal"), ("SIGMA0Y", "lateral")] {
                let v = param(f, k);
                if v.is_finite() {
                    parts.push(format!("{v:.0} 1/m ({what})"));
                }
            }
            format!(
                "LuGre bristle stiffness {} per unit load, static/Coulomb friction ratio {:.3}",
                parts.join(" and "),
                param(f, "MUS")
            )
        },
        reestimation: Reestimation::No,
        refits_baseline: false,
    }
}
