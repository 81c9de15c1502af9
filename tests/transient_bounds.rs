//! Issue 16, transient part: LuGre stays within its friction limit in any
//! slip history, turn slip is defined at standstill in steady mode, and one
//! absurd-but-accepted step does not poison the relaxation state.

use crate::common;

use common::{vel, FZ};
use tyrekit::mf::{Tyre, UseMode};
use tyrekit::transient::lugre::LUGRE_FRICTION_MARGIN;
use tyrekit::transient::{InputMode, TransientConfig, TransientKind, TransientModel, WheelInput};

/// The three transient models.
const KINDS: [TransientKind; 3] = [
    TransientKind::Steady,
    TransientKind::Relaxation,
    TransientKind::LuGre,
];

/// A model of `kind` on wheel-speed input with MFeval use mode `code`.
fn velocities_model(kind: TransientKind, code: u32) -> TransientModel {
    TransientModel::new(TransientConfig {
        kind,
        input_mode: InputMode::Velocities,
        use_mode: UseMode::from_code(code).unwrap(),
    })
}

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
    for kind in KINDS {
        let mut m = velocities_model(kind, 112);
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

/// The overturning moment on a road of another friction (the similarity
/// method, `transient::mf_at`), against two formulations of Mx written
/// into the built-in file: (a) inclination and load terms only (QSX2,
/// QSX4 with QSX8 = 0, QSX10): a road's friction does not move the
/// contact patch's lateral offset under camber, so Mx at μ ×0.5 and ×3
/// equals Mx at ×1 — before 1 Dec 2026 all of Mx was scaled by μ; (b)
/// the lateral-force term only (QSX3): Mx follows Fy, Mx_s/Mx_1 =
/// Fy_s/Fy_1. Inclination 4°, α 5°, κ 0.03, nominal load.
#[test]
fn overturning_moment_scales_with_the_lateral_force_not_with_the_road() {
    use tyrekit::mf::MfInput;
    use tyrekit::transient::{mf_at, Slip};
    let with = |keys: &[(&str, f64)]| {
        let mut p = tyrekit::tir::TyreParams::builtin();
        for k in [
            "QSX1", "QSX2", "QSX3", "QSX4", "QSX8", "QSX10", "QSX12", "QSX13", "QSX14",
        ] {
            p.set(k, 0.0).unwrap();
        }
        for (k, v) in keys {
            p.set(k, *v).unwrap();
        }
        Tyre::new(p).unwrap()
    };
    let camber_only = with(&[("QSX2", 1.2), ("QSX4", 4.9), ("QSX10", 0.28)]);
    let fy_only = with(&[("QSX3", 0.1)]);
    let base = MfInput {
        fz: FZ,
        gamma: 4f64.to_radians(),
        vx: 20.0,
        p: f64::NAN,
        ..Default::default()
    };
    let mode = UseMode::default();
    let slip = Slip::new(0.03, 5f64.to_radians().tan());
    for s in [0.5, 3.0] {
        let (a1, a_s) = (
            mf_at(&camber_only, &base, mode, slip, 1.0),
            mf_at(&camber_only, &base, mode, slip, s),
        );
        assert!(a1.mx.abs() > 20.0, "camber Mx too small to test: {}", a1.mx);
        assert!(
            (a_s.mx - a1.mx).abs() <= 1e-12 * a1.mx.abs(),
            "μ ×{s}: camber Mx {} against {} on the file's road",
            a_s.mx,
            a1.mx
        );
        let (b1, b_s) = (
            mf_at(&fy_only, &base, mode, slip, 1.0),
            mf_at(&fy_only, &base, mode, slip, s),
        );
        assert!(
            (b_s.fy / b1.fy - 1.0).abs() > 0.05,
            "μ ×{s} leaves Fy unchanged: nothing tested"
        );
        assert!(
            (b_s.mx / b1.mx - b_s.fy / b1.fy).abs() <= 1e-9,
            "μ ×{s}: Fy-driven Mx ratio {} against Fy ratio {}",
            b_s.mx / b1.mx,
            b_s.fy / b1.fy
        );
    }
}

/// The FMU fuzzer's find (1 Dec 2026, seed 20261201, FMU mutant 2130):
/// LuGre, wheel speed input, limit checks off, 86° inclination on a road
/// of 4.28 times the file's friction at 0.3 N load — an accepted step gave
/// Mx = −1.01 N m, above the fuzzer's 10·Fz·R0 bound, because Mx's
/// inclination terms were scaled by the road friction. Now every moment
/// stays within that bound, in every transient model.
#[test]
fn a_grippy_road_does_not_scale_the_camber_overturning_moment() {
    let tyre = Tyre::builtin();
    let r0 = tyre.params().p.unloaded_radius;
    for kind in KINDS {
        let mut m = velocities_model(kind, 212);
        let inp = WheelInput {
            vx: 10.0,
            vy: 5.5e-301,
            omega: -1.0,
            fz: 0.3,
            gamma: -1.5,
            mu_scale: 4.277775267530101,
            ..Default::default()
        };
        for _ in 0..10 {
            let o = m.step(&tyre, &inp, 1e-3).unwrap();
            let worst = o.mx.abs().max(o.my.abs()).max(o.mz.abs());
            assert!(
                worst <= 10.0 * inp.fz * r0,
                "{kind:?}: |M| {worst} N m above 10·Fz·R0 = {} N m (Mx {}, My {}, Mz {})",
                10.0 * inp.fz * r0,
                o.mx,
                o.my,
                o.mz
            );
        }
    }
}
