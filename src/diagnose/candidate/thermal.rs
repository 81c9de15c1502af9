//! thermal — a tread temperature driven by frictional power with friction depending on it (`[THERMAL]` section, see crate::transient::extension).
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{p, param, ParamCandidate, Spec, Target};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::transient::extension::THERMAL_SECTION;

fn thermal_spec(_: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let th = |k| Target::Section(THERMAL_SECTION, k);
    Some(Spec {
        params: vec![
            p("CAPACITY", vec![th("CAPACITY")], 4000.0, 200.0, 1e5, 200.0),
            p("MU_T0", vec![th("MU_T0")], 0.0, -0.5, 0.5, 0.002),
            p("MU_T1", vec![th("MU_T1")], 0.0, -1.0, 1.0, 0.002),
            p("MU_T2", vec![th("MU_T2")], 0.0, -1.0, 1.0, 0.002),
        ],
        fixed: vec![(th("COOLING"), 40.0), (th("SHARE"), 0.5)],
        sequential: true,
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "thermal",
        physics: "a tread temperature driven by frictional power, with friction depending on it",
        n: 4,
        spec: thermal_spec,
        words: |f| {
            let c = param(f, "CAPACITY");
            let m = |x: f64| {
                100.0 * (param(f, "MU_T0") + param(f, "MU_T1") * x + param(f, "MU_T2") * x * x)
            };
            format!(
                "a tread heat capacity of {c:.0} J/K (time constant {:.0} s with 40 W/K cooling); friction {:+.1} % at ambient, {:+.1} % at +25 K, {:+.1} % at +50 K",
                c / 40.0,
                m(0.0),
                m(0.5),
                m(1.0)
            )
        },
    }
}
