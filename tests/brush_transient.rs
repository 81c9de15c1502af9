//! The brush as the force model of the transient models (what the FMU's
//! `force_model = brush` and `replay --force-model brush` run): the steady
//! model returns the brush's forces, the relaxation and LuGre models settle
//! to them under constant slip, with the brush's own relaxation length
//! σα = C_y/C_Fy, and a step allocates nothing.

use crate::allocations_on_this_thread;
use tyrekit::brush::{BrushInput, BrushParams};
use tyrekit::mf::Tyre;
use tyrekit::transient::{
    InputMode, TransientConfig, TransientKind, TransientModel, TransientOptions, WheelInput,
};

fn model(kind: TransientKind, b: BrushParams) -> TransientModel {
    TransientModel::with_options(
        TransientConfig {
            kind,
            input_mode: InputMode::Slips,
            ..Default::default()
        },
        TransientOptions {
            brush: Some(b),
            ..Default::default()
        },
    )
}

#[test]
fn transient_models_settle_to_the_brush() {
    let tyre = Tyre::builtin();
    let (b, _) = BrushParams::from_tyre(&tyre).unwrap();
    for (kappa, alpha) in [(0.0, 0.03), (0.0, -0.15), (0.05, 0.0), (-0.08, 0.04)] {
        let inp = WheelInput {
            vx: 20.0,
            omega: 20.0 / 0.3,
            fz: 4500.0,
            kappa_in: kappa,
            alpha_in: alpha,
            mu_scale: 1.0,
            ..Default::default()
        };
        let want = b.forces(&BrushInput::new(4500.0, kappa, f64::tan(alpha)));
        let mut m = model(TransientKind::Steady, b);
        let o = m.step(&tyre, &inp, 1e-3).unwrap();
        // the same function on the same inputs: equal to round-off
        assert!((o.fy - want.fy).abs() < 1e-9 * 4500.0 && (o.fx - want.fx).abs() < 1e-9 * 4500.0);
        assert!((o.mz - want.mz).abs() < 1e-9 * 4500.0);
        for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
            let mut m = model(kind, b);
            let mut o = m.step(&tyre, &inp, 1e-3).unwrap();
            let sigma = o.sigma_y;
            // σα from the brush: C_y/C_Fy (≥ a), not the MF's Kyα/Cy
            let expect = b.lateral_relaxation(4500.0);
            assert!(
                (sigma - expect).abs() < 1e-9,
                "{kind:?}: σα {sigma} vs {expect}"
            );
            // 2 s at 20 m/s = 40 m ≫ σ: settled to 0.5 % of the force scale
            // (LuGre's bristle settles exponentially as well).
            for _ in 0..2000 {
                o = m.step(&tyre, &inp, 1e-3).unwrap();
            }
            let tol = 5e-3 * 4500.0;
            assert!(
                (o.fy - want.fy).abs() < tol,
                "{kind:?} κ {kappa} α {alpha}: Fy {} vs {}",
                o.fy,
                want.fy
            );
            assert!(
                (o.fx - want.fx).abs() < tol,
                "{kind:?} κ {kappa} α {alpha}: Fx {} vs {}",
                o.fx,
                want.fx
            );
        }
    }
}

#[test]
fn lag_follows_the_brush_relaxation_length() {
    // A step in α from rest: the linear relaxation model reaches 1 − e⁻¹ of
    // the (small-slip, linear) steady force after rolling σα.
    let tyre = Tyre::builtin();
    let (b, _) = BrushParams::from_tyre(&tyre).unwrap();
    let fz = 4000.0;
    let sigma = b.lateral_relaxation(fz);
    let want = b.forces(&BrushInput::new(fz, 0.0, 0.002f64.tan())).fy;
    let mut m = model(TransientKind::Relaxation, b);
    let v = 10.0;
    let inp = WheelInput {
        vx: v,
        omega: v / 0.3,
        fz,
        alpha_in: 0.002,
        mu_scale: 1.0,
        ..Default::default()
    };
    let dt = 1e-4;
    let n = (sigma / v / dt).round() as usize;
    let mut o = Default::default();
    for _ in 0..n {
        o = m.step(&tyre, &inp, dt).unwrap();
    }
    let ratio = o.fy / want;
    // exact exponential solution; the tolerance covers rounding n and the
    // 0.2 % non-linearity of the force at α = 0.002
    assert!(
        (ratio - (1.0 - (-1.0f64).exp())).abs() < 0.01,
        "ratio {ratio}"
    );
}

#[test]
fn brush_step_does_not_allocate() {
    let tyre = Tyre::builtin();
    let (b, _) = BrushParams::from_tyre(&tyre).unwrap();
    let mut ms: Vec<_> = [
        TransientKind::Steady,
        TransientKind::Relaxation,
        TransientKind::LuGre,
    ]
    .into_iter()
    .map(|k| model(k, b))
    .collect();
    let before = allocations_on_this_thread();
    for m in ms.iter_mut() {
        for i in 0..200 {
            let inp = WheelInput {
                vx: 15.0,
                omega: 50.0,
                fz: 4000.0,
                kappa_in: 0.001 * i as f64,
                alpha_in: 0.002 * i as f64,
                ..Default::default()
            };
            let _ = m.step(&tyre, &inp, 1e-3).unwrap();
        }
    }
    assert_eq!(allocations_on_this_thread(), before);
}
