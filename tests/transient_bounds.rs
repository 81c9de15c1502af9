//! Issue 16, transient part: LuGre stays within its friction limit in any
//! slip history, turn slip is defined at standstill in steady mode, and one
//! absurd-but-accepted step does not poison the relaxation state.

use crate::common;

use common::{vel, FZ};
use tyrekit::mf::{Tyre, UseMode};
use tyrekit::transient::lugre::LUGRE_FRICTION_MARGIN;
use tyrekit::transient::{InputMode, TransientConfig, TransientKind, TransientModel, WheelInput};

/// LuGre at 100 m/s with the wheel speed reversing the slip every 0.5 ms
/// (κ = ±0.2, a brake/drive chatter): |Fx| stays within
/// LUGRE_FRICTION_MARGIN·max(μx·Fz, |Fx,MF|) = about 1.05·μx·Fz. Before the
/// bound the damping term σ1·ż gave 5·Fz at each reversal.
#[test]
fn lugre_is_bounded_by_friction_under_slip_reversals() {
    let tyre = Tyre::builtin();
    let mut m = common::model(TransientKind::LuGre, InputMode::Velocities);
    let vx = 100.0;
    let re = common::re(&tyre, vx);
    let mut worst = 0.0f64;
    let mut mux = 0.0;
    let dt = 1e-4;
    for i in 0..20_000 {
        // 0.5 ms per half period: 5 steps of 0.1 ms.
        let k = if (i / 5) % 2 == 0 { 0.2 } else { -0.2 };
        let o = m
            .step(&tyre, &vel(vx, 0.0, vx * (1.0 + k) / re), dt)
            .unwrap();
        mux = o.mux;
        worst = worst.max(o.fx.abs() / (o.mux * FZ));
        assert!(o.fx.is_finite() && o.fy.is_finite());
    }
    // μx·Fz is the MF's peak D (Pacejka 4.E16); the bound adds 5 %.
    assert!(mux > 0.5, "mux = {mux}");
    assert!(
        worst <= LUGRE_FRICTION_MARGIN + 1e-9,
        "max |Fx|/(mux Fz) = {worst}, bound {LUGRE_FRICTION_MARGIN}"
    );
}

/// Steady mode with turn slip at vx = 0 exactly: finite forces, no error
/// (the issue: fmi2Error whenever vx was 0).
#[test]
fn steady_turn_slip_is_defined_at_standstill() {
    let tyre = Tyre::builtin();
    for kind in [
        TransientKind::Steady,
        TransientKind::Relaxation,
        TransientKind::LuGre,
    ] {
        let mut m = TransientModel::new(TransientConfig {
            kind,
            input_mode: InputMode::Velocities,
            use_mode: UseMode::from_code(112).unwrap(),
        });
        for (vy, omega, phit) in [
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.5),
            (0.1, 0.0, -2.0),
            (0.0, 1.0, 1.0),
        ] {
            let inp = WheelInput {
                phit,
                ..vel(0.0, vy, omega)
            };
            let o = m
                .step(&tyre, &inp, 1e-3)
                .unwrap_or_else(|e| panic!("{kind:?} vy={vy} omega={omega} phit={phit}: {e}"));
            for v in [o.fx, o.fy, o.mx, o.my, o.mz] {
                assert!(v.is_finite(), "{kind:?}: {o:?}");
            }
            // Standing still, a tyre transmits at most friction (μ ≈ 1 here).
            assert!(
                o.fx.abs() <= 1.5 * FZ && o.fy.abs() <= 1.5 * FZ,
                "{kind:?}: {o:?}"
            );
        }
    }
}

/// One step with vy at its physical limit (150 m/s, the FMU's max) in
/// relaxation mode, then valid straight running: the lateral force is back
/// near zero after a few relaxation lengths (the issue: vy = 1e300 pinned Fy
/// at −3187 N for 21 s).
#[test]
fn relaxation_recovers_from_an_extreme_step() {
    let tyre = Tyre::builtin();
    for nonlinear in [false, true] {
        let mut m = TransientModel::with_options(
            TransientConfig {
                kind: TransientKind::Relaxation,
                input_mode: InputMode::Velocities,
                use_mode: UseMode::default(),
            },
            tyrekit::transient::TransientOptions {
                nonlinear,
                ..Default::default()
            },
        );
        let vx = 10.0;
        let w = vx / common::re(&tyre, vx);
        for _ in 0..100 {
            m.step(&tyre, &vel(vx, 0.0, w), 1e-3).unwrap();
        }
        m.step(&tyre, &vel(vx, 150.0, w), 1e-3).unwrap();
        m.step(&tyre, &vel(vx, -150.0, -2000.0), 1e-3).unwrap();
        // 1 s at 10 m/s = 10 m, > 10 relaxation lengths (σα ≈ 0.5 m at 4 kN).
        let mut last = None;
        for _ in 0..1000 {
            last = Some(m.step(&tyre, &vel(vx, 0.0, w), 1e-3).unwrap());
        }
        let o = last.unwrap();
        assert!(
            o.fy.abs() < 0.02 * FZ,
            "nonlinear={nonlinear}: Fy = {} after 1 s",
            o.fy
        );
        assert!(
            o.fx.abs() < 0.05 * FZ,
            "nonlinear={nonlinear}: Fx = {} after 1 s",
            o.fx
        );
    }
}
