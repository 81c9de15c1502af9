//! speed_friction — friction that changes monotonically with the sliding
//! speed, of general shape: `[SPEED_FRICTION]` DMU, VC, MU0, the scale
//! s = (1 + MU0)·(1 − DMU·x/(1 + x)), x = Vs/VC, Vs = |Vx|·√(κ² + tan²α) (see
//! [`crate::transient::extension`]). Two parameters cover the MF's LMUV law
//! (DMU = 1, VC = V0/LMUV: a fall without end), a fall that levels off
//! (DMU < 1, the Stribeck-type shape of rubber friction) and a rise (DMU < 0),
//! always monotone in Vs — the one-parameter LMUV form alone cannot level
//! off, and a friction that does is then explained by nothing. MU0 lets
//! the law turn about the friction the baseline already fitted (its
//! average over the recorded sliding speeds): without it the law can only
//! lower the baseline's friction everywhere, which the data refuse.
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{p, param, ParamCandidate, Spec, Target};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::transient::extension::{speed_friction, SPEED_KEYS, SPEED_SECTION};

/// Range of DMU: a fall of at most 80 % of the friction at high sliding
/// speed (1 − DMU ≥ 0.2; a tyre keeps most of its grip when sliding), a
/// rise of at most 30 %.
const DMU_RANGE: (f64, f64) = (-0.3, 0.8);
/// Range of VC (m/s): the sliding speeds a tyre test covers (a few cm/s at
/// the onset of sliding to ~10 m/s locked at the belt speeds of a rig); a
/// VC beyond them is a law that the data see as linear.
const VC_RANGE: (f64, f64) = (0.05, 30.0);
/// Range of MU0: the friction level at zero sliding speed within ±30 % of
/// the baseline's (a baseline further off is a misfit, not this physics).
const MU0_RANGE: (f64, f64) = (-0.3, 0.3);

fn speed_spec(_: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let s = |k| vec![Target::Section(SPEED_SECTION, k)];
    Some(Spec {
        params: vec![
            // Start at a small fall (not 0: at DMU = 0 the cost does not
            // depend on VC, and its difference column would be zero).
            p(
                "DMU",
                s(SPEED_KEYS[0]),
                0.02,
                DMU_RANGE.0,
                DMU_RANGE.1,
                0.002,
            ),
            p("VC", s(SPEED_KEYS[1]), 2.0, VC_RANGE.0, VC_RANGE.1, 0.02),
            p(
                "MU0",
                s(SPEED_KEYS[2]),
                0.0,
                MU0_RANGE.0,
                MU0_RANGE.1,
                0.002,
            ),
        ],
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "speed_friction",
        physics: "friction changes with the sliding speed",
        n: 3,
        spec: speed_spec,
        words: |f| {
            let (d, v, m) = (param(f, "DMU"), param(f, "VC"), param(f, "MU0"));
            let at = |vs: f64| 100.0 * ((1.0 + m) * speed_friction(d, v, vs) - 1.0);
            format!(
                "friction {:+.1} % at 0.2 m/s sliding speed, {:+.1} % at 1 m/s, {:+.1} % at 5 m/s against the baseline, falling by {:.1} % of its level from zero to high sliding speed (DMU = {d:.3}, VC = {v:.2} m/s, MU0 = {m:.3})",
                at(0.2),
                at(1.0),
                at(5.0),
                100.0 * d
            )
        },
    }
}
