//! The load-sensitivity candidate against two formulations written for
//! this test (not the rig's default ones): peak friction linear in load,
//! and friction and stiffness saturating over the load range (tanh) — the
//! candidate's curve (natural splines through knot loads) is neither, so a
//! pass means it follows the physics, not one formula. The control (the
//! plain MF) must stay `none`.

use crate::common;

use tyrekit::diagnose::report::diagnose;
use tyrekit::mf::Tyre;
use tyrekit::rig::effects::{Scaling, ScalingKind};
use tyrekit::rig::{simulate, RigConfig, SteadyMf, TruthModel};
use tyrekit::transient::extension::{LOAD_FZ_KEYS, LOAD_MU_KEYS, LOAD_SECTION};

/// The rig's ISO-W truth over its five loads (0.5…1.5·Fnom), one pressure
/// and inclination, with 12 N / 0.4 N·m white sensor noise (the rig's
/// default levels).
fn recording(tyre: &Tyre, m: &mut dyn TruthModel, seed: u64) -> tyrekit::data::Recording {
    let mut cfg = RigConfig::standard(tyre, 11);
    cfg.noise = tyrekit::rig::Noise::none();
    cfg.programme.pressures.truncate(1);
    cfg.programme.inclinations.truncate(1);
    cfg.programme.db_alphas.truncate(2);
    common::noisy_recording(simulate(&cfg, m), "load", 12.0, 0.4, seed)
}

/// Named, and the fitted friction change at each knot load within 2
/// percentage points of the formulation's own s(Fz) − 1 (the truth is the
/// baseline tyre plus this scaling, so the curve has only the noise to
/// miss: 12 N on thousands of samples moves a knot by well under 1 %; the
/// rest is the spline's shape between knots and the stiffness/friction
/// trade-off of the similarity method, allowed another 1 %).
fn check(kind: ScalingKind, a: f64, s_of: impl Fn(f64) -> f64, seed: u64) {
    let tyre = Tyre::builtin();
    let mut m = Scaling::new(tyre.clone(), kind, a);
    let rec = recording(&tyre, &mut m, seed);
    let d = diagnose(&rec, &tyre, &common::diagnose_opts()).unwrap();
    println!("{kind:?}: {}", d.explanation());
    assert_eq!(
        d.verdict(),
        "load_sensitivity",
        "{kind:?}: {}",
        d.explanation()
    );
    let fnom = tyre.params().p.fnomin;
    let p = d.extended.params();
    let mut n = 0;
    for (fk, mk) in LOAD_FZ_KEYS.iter().zip(LOAD_MU_KEYS) {
        let (Some(fz), Some(mu)) = (
            p.extra_number(LOAD_SECTION, fk),
            p.extra_number(LOAD_SECTION, mk),
        ) else {
            continue;
        };
        n += 1;
        let want = s_of(fz / fnom - 1.0) - 1.0;
        println!(
            "  {kind:?} Fz {fz:.0} N: fitted {:+.2} %, truth {:+.2} %",
            100.0 * mu,
            100.0 * want
        );
        assert!(
            (mu - want).abs() < 0.02,
            "{kind:?} at {fz:.0} N: {mu:.4} vs {want:.4}"
        );
    }
    assert!(n >= 3, "{n} knots in the extended file");
}

#[test]
fn linear_friction_in_load_is_named_and_recovered() {
    let a = 0.08;
    check(ScalingKind::LoadLinear, a, |dfz| 1.0 - a * dfz, 31);
}

#[test]
fn saturating_friction_and_stiffness_are_named_and_recovered() {
    let a = 0.06;
    check(
        ScalingKind::LoadSaturating,
        a,
        |dfz| 1.0 - a * (2.0 * dfz).tanh(),
        32,
    );
}

#[test]
fn control_stays_none() {
    let tyre = Tyre::builtin();
    let mut m = SteadyMf::new(tyre.clone());
    let rec = recording(&tyre, &mut m, 33);
    let d = diagnose(&rec, &tyre, &common::diagnose_opts()).unwrap();
    assert_eq!(d.verdict(), "none", "{}", d.explanation());
}
