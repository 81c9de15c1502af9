//! load_sensitivity — friction and slip stiffness depending on load beyond the Magic Formula's forms (`[LOAD_SENSITIVITY]` section).
//!
//! Must never: fit a parameter outside the range written here, or describe
//! a value the fit did not produce.

use super::param::{p, param, ParamCandidate, Spec, Target};
use crate::mf::Tyre;
use crate::residual::ReplayOptions;
use crate::transient::extension::LOAD_SECTION;

fn load_spec(_: &Tyre, _: &ReplayOptions) -> Option<Spec> {
    let l = |k| vec![Target::Section(LOAD_SECTION, k)];
    Some(Spec {
        params: vec![
            p("MU_DFZ1", l("MU_DFZ1"), 0.0, -0.5, 0.5, 0.002),
            p("MU_DFZ2", l("MU_DFZ2"), 0.0, -0.5, 0.5, 0.002),
            p("K_DFZ1", l("K_DFZ1"), 0.0, -0.5, 0.5, 0.002),
        ],
        ..Spec::default()
    })
}

/// The candidate.
pub(super) fn candidate() -> ParamCandidate {
    ParamCandidate {
        name: "load_sensitivity",
        physics: "peak friction and slip stiffness depend on load beyond the Magic Formula's forms",
        n: 3,
        spec: load_spec,
        words: |f| {
            let (a, b, k) = (param(f, "MU_DFZ1"), param(f, "MU_DFZ2"), param(f, "K_DFZ1"));
            format!(
                "peak friction {:+.1} % at half the nominal load and {:+.1} % at 1.5×; slip stiffness {:+.1} % per 100 % load change",
                100.0 * (-0.5 * a + 0.25 * b),
                100.0 * (0.5 * a + 0.25 * b),
                100.0 * k
            )
        },
    }
}
