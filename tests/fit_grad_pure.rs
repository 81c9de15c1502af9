//! The closed-form pure-slip gradients (`tyrekit::fit::grad_pure`, used by
//! the pure Fx and pure Fy fit stages) against num-dual's forward-mode
//! derivatives through the generic Magic Formula (the same stage built
//! `with_analytic(false)`), for every coefficient of the channel, and the
//! values against `Model::solve`.
//!
//! Tyres: the built-in MF 6.1 and real files of `../shared/data/tir` (MF 6.1,
//! 6.2, 5.2, PAC2002; skipped when absent), each as given and with its
//! coefficients perturbed at random (seeded) so that zero terms (pressure,
//! camber, PKY5 …) become active and the value shortcuts (PKY4 = 2, PKX3 =
//! 0, E = 0) are left. Inputs: random α, κ ≠ 0 (so Gyκ, SVyκ, Gxα act), γ,
//! pressure, loads including Fz = 0, negative and low speeds; in the fit's
//! use mode and with range limits and α* on (clipped E, sign conventions of
//! γ*, α* and Vx < 0).

use crate::common;

use rand::{Rng, SeedableRng};
use tyrekit::fit::grad_pure::{FX_KEYS, FY_KEYS};
use tyrekit::fit::mf_stages::{Channel, MfStage, StageData};
use tyrekit::fit::{Param, Problem};
use tyrekit::mf::{form_of, Conditions, MfInput, Model, UseMode};
use tyrekit::tir::keys::key_index;
use tyrekit::tir::TyreParams;

fn tyres() -> Vec<TyreParams> {
    let mut v = vec![TyreParams::builtin()];
    for f in [
        "MagicFormula61_Parameters.tir",
        "MagicFormula62_Parameters.tir",
        "MagicFormula52_Parameters.tir",
        "Generic_Pac02Tire.tir",
        "HoosierR20.tir",
        "335_65R22_5_G275MSA_40psi.tir",
    ] {
        let p = common::shared().join("data/tir").join(f);
        if p.exists() {
            v.push(TyreParams::from_file(&p).unwrap());
        } else {
            eprintln!("SKIP {}: absent", p.display());
        }
    }
    v
}

/// `t` with every coefficient of `keys` moved: ×(1 ± 30 %) plus a small
/// offset (zero terms become active), PKY4 kept in its box (1, 5].
fn perturbed(t: &TyreParams, keys: &[&str], rng: &mut impl Rng) -> TyreParams {
    let mut t = t.clone();
    for k in keys {
        let i = key_index(k).unwrap();
        let v = t.p.as_slice()[i];
        let mut nv = v * rng.gen_range(0.7..1.3) + rng.gen_range(-0.05..0.05);
        if *k == "pky4" {
            nv = nv.clamp(1.2, 4.0);
        }
        t.p.as_mut_slice()[i] = nv;
    }
    t
}

fn conditions(t: &TyreParams, rng: &mut impl Rng, mode: UseMode) -> Vec<Conditions> {
    let p = &t.p;
    (0..300)
        .map(|i| {
            let inp = MfInput {
                fz: if i == 7 {
                    0.0
                } else {
                    p.fnomin * rng.gen_range(0.2..2.0)
                },
                kappa: if i % 5 == 0 {
                    0.0
                } else {
                    rng.gen_range(-0.2..0.2)
                },
                alpha: rng.gen_range(-0.3..0.3),
                gamma: rng.gen_range(-0.1..0.1),
                p: p.nompres * rng.gen_range(0.7..1.3),
                vx: match i % 7 {
                    0 => -rng.gen_range(2.0..30.0),
                    1 => rng.gen_range(0.2..1.5), // low speed: smoothed shifts
                    _ => rng.gen_range(2.0..30.0),
                },
                ..Default::default()
            };
            Conditions::new(p, &inp, mode).0
        })
        .collect()
}

const MODES: [UseMode; 2] = [
    tyrekit::fit::mf_stages::FIT_MODE,
    UseMode {
        limits: true,
        alpha_star: true,
        turn_slip: false,
    },
];

/// Compare the closed form with num-dual for `channel` over `keys` on `t`.
/// Tolerance: 1e-10 of the entry, with a floor of 1e-11 of the column's
/// largest entry — the two evaluate the same expression in different
/// orders (reverse vs forward accumulation), so they agree to a few
/// hundred ulps of the terms summed; an entry that cancels to near zero
/// carries that absolute rounding, hence the floor. Returns the worst
/// relative difference seen.
fn compare(t: &TyreParams, channel: Channel, keys: &[&str], conds: Vec<Conditions>) -> f64 {
    let form = form_of(t.version);
    let params: Vec<Param> = keys
        .iter()
        .map(|k| Param::unbounded(k, t.p.get(k).unwrap()))
        .collect();
    let theta: Vec<f64> = params.iter().map(|p| p.start).collect();
    let model = Model::new(t.p.clone(), form);
    let truth: Vec<f64> = conds.iter().map(|c| channel.of(&model.solve(c))).collect();
    let m = conds.len();
    let data = StageData {
        conds,
        meas: vec![vec![0.0; m]],
        ..Default::default()
    };
    let an = MfStage::new(form, &t.p, params.clone(), &data, 0, channel).unwrap();
    assert!(an.is_analytic(), "{}: closed form not used", t.source);
    let ad = MfStage::new(form, &t.p, params, &data, 0, channel)
        .unwrap()
        .with_analytic(false);
    assert!(!ad.is_analytic());
    let n = keys.len();
    let cols: Vec<usize> = (0..n).collect();
    let (mut r1, mut r2) = (vec![0.0; m], vec![0.0; m]);
    let mut j1 = nalgebra::DMatrix::zeros(m, n);
    let mut j2 = nalgebra::DMatrix::zeros(m, n);
    an.jacobian(&theta, &cols, &mut r1, &mut j1.as_view_mut());
    ad.jacobian(&theta, &cols, &mut r2, &mut j2.as_view_mut());
    let mut r3 = vec![0.0; m];
    an.residuals(&theta, &mut r3);
    // Values: the closed form repeats Model's operations, so it matches
    // Model::solve to rounding (1e-13 of the force scale, Fz).
    for i in 0..m {
        let scale = data.conds[i].fz.max(1.0);
        for (what, v) in [
            ("jacobian r", r1[i]),
            ("dual r", r2[i]),
            ("residuals", r3[i]),
        ] {
            assert!(
                (v - truth[i]).abs() <= 1e-13 * scale,
                "{} {channel:?} sample {i}: {what} {v} vs solve {}",
                t.source,
                truth[i]
            );
        }
    }
    let mut worst = 0.0f64;
    for (j, k) in keys.iter().enumerate() {
        let cmax = (0..m).map(|i| j2[(i, j)].abs()).fold(0.0, f64::max);
        for i in 0..m {
            let (a, b) = (j1[(i, j)], j2[(i, j)]);
            let tol = 1e-10 * b.abs() + 1e-11 * cmax;
            assert!(
                (a - b).abs() <= tol || (a == 0.0 && b == 0.0),
                "{} {channel:?} d/d{k} sample {i} ({:?}): closed form {a:e} vs num-dual {b:e}",
                t.source,
                data.conds[i]
            );
            if b != 0.0 {
                worst = worst.max((a - b).abs() / b.abs());
            }
        }
    }
    worst
}

#[test]
fn pure_fy_gradient_matches_num_dual() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for t in tyres() {
        for tyre in [t.clone(), perturbed(&t, &FY_KEYS, &mut rng)] {
            for mode in MODES {
                let conds = conditions(&tyre, &mut rng, mode);
                let w = compare(&tyre, Channel::Fy, &FY_KEYS, conds);
                eprintln!("{} Fy {mode:?}: worst relative {w:.1e}", tyre.source);
            }
        }
    }
}

#[test]
fn pure_fx_gradient_matches_num_dual() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    for t in tyres() {
        for tyre in [t.clone(), perturbed(&t, &FX_KEYS, &mut rng)] {
            for mode in MODES {
                let conds = conditions(&tyre, &mut rng, mode);
                let w = compare(&tyre, Channel::Fx, &FX_KEYS, conds);
                eprintln!("{} Fx {mode:?}: worst relative {w:.1e}", tyre.source);
            }
        }
    }
}

/// Curvature factors above 1 with range limits on: E is clipped to 1 and its
/// coefficients get no derivative, as with num-dual.
#[test]
fn clipped_curvature_matches_num_dual() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
    let mut t = TyreParams::builtin();
    t.set("PEY1", 1.6).unwrap();
    t.set("PEX1", 1.6).unwrap();
    let conds = conditions(&t, &mut rng, MODES[1]);
    compare(&t, Channel::Fy, &FY_KEYS, conds.clone());
    compare(&t, Channel::Fx, &FX_KEYS, conds);
}

/// A table holding a coefficient outside the channel's closed form falls
/// back to num-dual.
#[test]
fn other_coefficients_fall_back_to_num_dual() {
    let t = TyreParams::builtin();
    let data = StageData {
        conds: vec![Conditions::default(); 3],
        meas: vec![vec![0.0; 3]],
        ..Default::default()
    };
    let params = vec![
        Param::unbounded("pdy1", 1.0),
        Param::unbounded("rby1", 10.0),
    ];
    let s = MfStage::new(form_of(t.version), &t.p, params, &data, 0, Channel::Fy).unwrap();
    assert!(!s.is_analytic());
}
