//! The fitter's one-channel evaluation (`tyrekit::fit::channels::eval`)
//! against the full combined-slip solution (`Model::solve`): for MF 6.1,
//! MF 5.2 and PAC2002 files, over loads, slips (κ and α both non-zero, so
//! the combined-slip weights act), inclinations and pressures, the `f64`
//! values are bit-identical and the dual-number derivatives agree to
//! rounding (1e-12 relative: the same operations, except that the full
//! solution's Fy reuses Fy0 computed once for Mz, which can reorder nothing
//! that changes the derivative beyond an ulp or two).

use crate::common;

use tyrekit::fit::channels::{eval, eval_from, eval_given};
use tyrekit::fit::mf_stages::{conditions_of, Channel, StageKind};
use tyrekit::mf::num_dual::Dual64;
use tyrekit::mf::{form_of, Model};
use tyrekit::tir::keys::key_index;
use tyrekit::tir::TyreParams;

const CHANNELS: [Channel; 5] = [
    Channel::Fx,
    Channel::Fy,
    Channel::Mx,
    Channel::My,
    Channel::Mz,
];

fn tyres() -> Vec<TyreParams> {
    let mut v = vec![TyreParams::builtin()];
    for f in ["MagicFormula52_Parameters.tir", "Generic_Pac02Tire.tir"] {
        let p = common::shared().join("data/tir").join(f);
        if p.exists() {
            v.push(TyreParams::from_file(&p).unwrap());
        } else {
            eprintln!("SKIP {}: absent", p.display());
        }
    }
    v
}

fn samples(t: &TyreParams) -> Vec<tyrekit::data::Sample> {
    let p = &t.p;
    let mut out = Vec::new();
    for i in 0..400 {
        let x = i as f64;
        out.push(tyrekit::data::Sample {
            fz: p.fnomin * (0.2 + 1.6 * ((x * 0.37).sin() * 0.5 + 0.5)),
            kappa: 0.15 * (x * 0.71).sin(),
            alpha: 0.2 * (x * 0.53).cos(),
            gamma: 0.06 * (x * 0.29).sin(),
            p: p.nompres * (1.0 + 0.15 * (x * 0.13).cos()),
            vx: 15.0 + 5.0 * (x * 0.11).sin(),
            ..Default::default()
        });
    }
    out
}

/// `t`'s model with key `k` seeded as the dual part.
fn seeded(t: &TyreParams, k: &str) -> Model<Dual64> {
    let ki = key_index(k).unwrap();
    let pd = t.p.map(|i, v| {
        if i == ki {
            Dual64::new(v, 1.0)
        } else {
            Dual64::from(v)
        }
    });
    Model::new(pd, form_of(t.version))
}

#[test]
fn one_channel_values_are_bit_identical_to_solve() {
    for t in tyres() {
        let m = Model::new(t.p.clone(), form_of(t.version));
        for s in samples(&t) {
            let c = conditions_of(&t.p, &s);
            let full = m.solve(&c);
            for ch in CHANNELS {
                let (a, b) = (eval(&m, &c, ch), ch.of(&full));
                assert_eq!(a.to_bits(), b.to_bits(), "{} {ch:?}: {a} vs {b}", t.source);
            }
        }
    }
}

#[test]
fn one_channel_derivatives_match_solve() {
    // A parameter of every stage: Fx, Fy, Mz, combined, Mx, My terms.
    let keys = [
        "PKX1", "PEX1", "PKY1", "PEY2", "QBZ1", "RBY1", "QSX3", "QSY1",
    ];
    for t in tyres() {
        for k in keys {
            let m = seeded(&t, k);
            for s in samples(&t).iter().step_by(7) {
                let c = conditions_of(&t.p, s);
                let full = m.solve(&c);
                for ch in CHANNELS {
                    let (a, b) = (eval(&m, &c, ch).eps, ch.of(&full).eps);
                    assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1e-300),
                        "{} {ch:?} d/d{k}: {a} vs {b}",
                        t.source
                    );
                }
            }
        }
    }
}

#[test]
fn moments_given_their_force_are_the_one_channel_values() {
    // The Mx (My) stage computes Fy (Fx) once per sample and passes it in:
    // in `f64` the value must be the same bits as evaluating the force
    // inside; with a moment coefficient seeded, value and derivative the
    // same to rounding (1e-12 relative, as above: the force carries no
    // derivative of a moment coefficient either way, but the dual model's
    // Fy is its own rounding of the `f64` one; measured: ulps apart).
    for t in tyres() {
        let mf = Model::new(t.p.clone(), form_of(t.version));
        for (k, ch, force) in [
            ("QSX3", Channel::Mx, Channel::Fy),
            ("QSX9", Channel::Mx, Channel::Fy),
            ("QSY1", Channel::My, Channel::Fx),
            ("QSY2", Channel::My, Channel::Fx),
        ] {
            let m = seeded(&t, k);
            for s in samples(&t).iter().step_by(3) {
                let c = conditions_of(&t.p, s);
                let f = eval(&mf, &c, force);
                let (a, b) = (eval_given(&m, &c, ch, Some(f)), eval(&m, &c, ch));
                for (what, x, y) in [("value", a.re, b.re), ("derivative", a.eps, b.eps)] {
                    assert!(
                        (x - y).abs() <= 1e-12 * y.abs().max(1e-300),
                        "{} {ch:?} {what} (d/d{k}): {x} vs {y}",
                        t.source
                    );
                }
                let v = eval_given(&mf, &c, ch, Some(f));
                assert_eq!(v.to_bits(), eval(&mf, &c, ch).to_bits());
            }
        }
    }
}

/// Every key of the aligning-torque and combined-slip stage tables: the
/// parameters whose stages take the pure-slip terms as given.
fn mz_and_combined_keys() -> Vec<&'static str> {
    [StageKind::Mz, StageKind::Combined]
        .iter()
        .flat_map(|k| k.table().iter().map(|e| e.0))
        .collect()
}

/// Every `step`-th sample's conditions and its pure-slip terms under `m0`.
fn conditions_and_terms(
    t: &TyreParams,
    m0: &Model,
    step: usize,
) -> (Vec<tyrekit::mf::Conditions>, Vec<tyrekit::mf::PureTerms>) {
    let conds: Vec<_> = samples(t)
        .iter()
        .step_by(step)
        .map(|s| conditions_of(&t.p, s))
        .collect();
    let terms = conds.iter().map(|c| m0.pure_terms(c)).collect();
    (conds, terms)
}

#[test]
fn pure_terms_are_unmoved_by_the_mz_and_combined_coefficients() {
    // The Mz and combined stages compute each sample's pure-slip terms once,
    // from the start tyre, and move only the keys of their tables. So for a
    // tyre with any one of those keys changed, the channels from the
    // *unchanged* tyre's terms must be the same bits as evaluated afresh; a
    // table key that entered Fx0, Fy0 or Fy0 at γ = 0 would fail here.
    for t in tyres() {
        let form = form_of(t.version);
        let (conds, terms) = conditions_and_terms(&t, &Model::new(t.p.clone(), form), 5);
        // `None`: the unchanged tyre itself.
        for k in std::iter::once(None).chain(mz_and_combined_keys().into_iter().map(Some)) {
            let ki = k.map(|k| key_index(k).unwrap());
            let p =
                t.p.map(|i, v| if Some(i) == ki { v * 1.3 + 0.02 } else { v });
            let m = Model::new(p, form);
            for (c, pt) in conds.iter().zip(&terms) {
                for ch in CHANNELS {
                    let (a, b) = (eval_from(&m, c, ch, pt), eval(&m, c, ch));
                    let same = a.to_bits() == b.to_bits();
                    assert!(same, "{} {k:?} {ch:?}: {a} vs {b}", t.source);
                }
            }
        }
    }
}

#[test]
fn channels_from_pure_terms_carry_the_derivatives_of_mz_and_combined_keys() {
    // With one of those keys seeded, value and derivative from the given
    // terms agree with the full evaluation to rounding (1e-12 relative, as
    // above), and the derivative is not trivially zero everywhere.
    for t in tyres() {
        let m0 = Model::new(t.p.clone(), form_of(t.version));
        let (conds, terms) = conditions_and_terms(&t, &m0, 9);
        for k in mz_and_combined_keys() {
            let m = seeded(&t, k);
            let mut moved = false;
            for (c, pt) in conds.iter().zip(&terms) {
                for ch in [Channel::Fx, Channel::Fy, Channel::Mz] {
                    let (a, b) = (eval_from(&m, c, ch, pt), eval(&m, c, ch));
                    moved |= b.eps != 0.0;
                    for (what, x, y) in [("value", a.re, b.re), ("derivative", a.eps, b.eps)] {
                        assert!(
                            (x - y).abs() <= 1e-12 * y.abs().max(1e-300),
                            "{} {ch:?} {what} (d/d{k}): {x} vs {y}",
                            t.source
                        );
                    }
                }
            }
            // A key the file leaves at zero can be inert (e.g. a camber
            // term times a zero scaling); report, do not fail.
            if !moved {
                eprintln!("{}: {k} moves none of Fx, Fy, Mz here", t.source);
            }
        }
    }
}
