//! speed_friction — friction that changes monotonically with the sliding
//! speed, of general shape: `[SPEED_FRICTION]` DMU, VC, VREF, the scale
//! s = g(Vs)/g(σ·VREF), g(v) = 1 − DMU·x/(1 + x), x = v/VC,
//! Vs = |Vx|·σ, σ = √(κ² + tan²α) (see [`crate::transient::extension`]).
//!
//! The shape: two parameters cover the MF's LMUV law (DMU = 1,
//! VC = V0/LMUV: a fall without end), a fall that levels off (DMU < 1,
//! the Stribeck-type shape of rubber friction), a nearly linear fall
//! (VC far above the sliding speeds) and a rise (DMU < 0), always monotone
//! in Vs — the one-parameter LMUV form alone cannot level off.
//!
//! The reference: a baseline Magic Formula fitted to a recording that
//! carries the law has absorbed it at the recorded belt speeds — its peak
//! and its fall after the peak hold g(σ·V) at every slip σ. Laid over it
//! again, the law would count the fall twice and leave the difference
//! between belt speeds — the only part the baseline cannot hold —
//! unexplained (the dev set's speed programmes: the Fx ratio between belt
//! speeds is 1 at small slip and falls with slip, as g(σ·V')/g(σ·V) does).
//! VREF is that belt speed: 0 when the baseline's friction is the one at
//! zero sliding speed (a model measured without the effect, the project's
//! rig proof), about the recorded belt speed when the baseline was fitted
//! to data carrying the law. Its cost has a valley at each, which LM
//! cannot cross, so the fit starts from both ([`Spec::restarts`]). On a
//! recording at one belt speed only VREF = 0 can change anything, and a
//! law about the recorded speed changes nothing: no extra freedom wins by
//! itself there. The level MU0 of the section is not fitted (a friction
//! level error at every speed is the baseline's, not this physics).
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{p, param, ParamCandidate, Spec, Target};
use super::Reestimation;
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::transient::extension::{SpeedLaw, SPEED_KEYS, SPEED_SECTION};

/// Range of DMU: a fall of at most 80 % of the friction at high sliding
/// speed (1 − DMU ≥ 0.2; a tyre keeps most of its grip when sliding), a
/// rise of at most 30 %.
const DMU_RANGE: (f64, f64) = (-0.3, 0.8);
/// Range of VC (m/s): the sliding speeds a tyre test covers (a few cm/s at
/// the onset of sliding to ~10 m/s locked at the belt speeds of a rig); a
/// VC beyond them is a law that the data see as linear.
const VC_RANGE: (f64, f64) = (0.05, 30.0);
/// Range of VREF (m/s): zero sliding speed up to 144 km/h, above the belt
/// speeds of flat-track rigs (TTC: 25–72 km/h).
const VREF_RANGE: (f64, f64) = (0.0, 40.0);

fn speed_spec(t: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let s = |k| vec![Target::Section(SPEED_SECTION, k)];
    // The second start of VREF: the file's reference speed LONGVL (the
    // baseline of `diagnose` sets it to the recording's mean belt speed).
    let v0 = t.params().p.longvl;
    let restarts = if v0.is_finite() && v0 > VREF_RANGE.0 && v0 < VREF_RANGE.1 {
        vec![vec![("VREF", v0)]]
    } else {
        vec![]
    };
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
                "VREF",
                s(SPEED_KEYS[3]),
                0.0,
                VREF_RANGE.0,
                VREF_RANGE.1,
                0.05,
            )
            .natural_lo(),
        ],
        restarts,
        ..Spec::default()
    })
}

/// The fitted law (MU0 = 0).
fn law(f: &dyn super::Fitted) -> SpeedLaw {
    SpeedLaw {
        dmu: param(f, "DMU"),
        vc: param(f, "VC"),
        mu0: 0.0,
        vref: param(f, "VREF"),
    }
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "speed_friction",
        physics: "friction changes with the sliding speed",
        n: 3,
        spec: speed_spec,
        words: |f| {
            let l = law(f);
            let g = |vs: f64| 100.0 * (SpeedLaw { vref: 0.0, ..l }.scale(vs, 1.0) - 1.0);
            // Below 2 m/s (7 km/h, under any tyre-test belt speed) the
            // reference is zero sliding speed in all but rounding.
            let reference = if l.vref < 2.0 {
                "the baseline's friction taken as the one at (near) zero sliding speed".to_string()
            } else {
                let kph = |v: f64| 3.6 * v;
                let at = |v: f64| 100.0 * (l.scale(v, 0.1) - 1.0);
                format!(
                    "the baseline's friction holding at {:.0} km/h belt speed, so at slip 0.1 the friction is {:+.1} % at {:.0} km/h and {:+.1} % at {:.0} km/h against the baseline",
                    kph(l.vref),
                    at(0.75 * l.vref),
                    kph(0.75 * l.vref),
                    at(1.25 * l.vref),
                    kph(1.25 * l.vref)
                )
            };
            format!(
                "against its level at zero sliding speed, friction {:+.1} % at 1 m/s sliding speed, {:+.1} % at 3 m/s and {:+.1} % at high sliding speed (DMU = {:.3}, VC = {:.2} m/s, VREF = {:.2} m/s); {reference}",
                g(1.0),
                g(3.0),
                -100.0 * l.dmu,
                l.dmu,
                l.vc,
                l.vref
            )
        },
        reestimation: Reestimation::ThroughScales,
        refits_baseline: false,
    }
}
