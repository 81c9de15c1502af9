//! The `[BRUSH]` section of the `.tir`: given keys win over the MF-derived
//! defaults, the writer's section reads back identically, and bad values are
//! refused naming the key.

use tyrekit::brush::{BrushParams, SECTION};
use tyrekit::mf::Tyre;
use tyrekit::tir::TyreParams;

#[test]
fn section_round_trips_and_overrides_defaults() {
    let mut t = Tyre::builtin().params().clone();
    let (mut b, d) = BrushParams::from_tyre(&Tyre::builtin()).unwrap();
    assert!(d.given.is_empty() && d.derived.len() == 9);
    b.points = 33;
    b.cpy = 1.234e7;
    b.compliance = 0.0;
    b.mu_s = 1.1;
    b.mu_k = 0.9;
    b.write_to(&mut t);
    let text = t.to_tir_string();
    let back = TyreParams::from_tir_str(&text, "rt.tir").unwrap();
    let (b2, d2) = BrushParams::from_tyre(&Tyre::new(back).unwrap()).unwrap();
    assert_eq!(b, b2);
    assert_eq!(d2.given.len(), 9);
}

#[test]
fn bad_values_are_refused_with_the_key() {
    for (key, val, needle) in [
        ("POINTS", 100.0, "POINTS"),
        ("POINTS", 2.5, "POINTS"),
        ("CPY", -1.0, "CPY"),
        ("CARCASS_COMPLIANCE", -1e-6, "CARCASS_COMPLIANCE"),
        ("MUS", 0.5, "MUS"), // below the MF-derived MUK
    ] {
        let mut t = Tyre::builtin().params().clone();
        t.extra_section(SECTION).set(key, val);
        let e = BrushParams::from_tyre(&Tyre::new(t).unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{key}={val}: {e}");
    }
}
