//! The extension physics (src/transient/extension.rs) through the library's
//! `TransientModel::step` — the code the FMU and `replay` run: a neutral
//! extension changes nothing, each term acts as its equation says, the tread
//! temperature is a state slot that heats with frictional power and is
//! cleared by reset, and the parameters survive the .tir writer.

use crate::common;

use common::{model, slips, FZ};
use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::tir::TyreParams;
use tyrekit::transient::extension::{SLOT_TEMP, THERMAL_SECTION};
use tyrekit::transient::{InputMode, TransientKind, WheelInput, WheelOutput, N_STATES};

fn with(f: impl FnOnce(&mut TyreParams)) -> Tyre {
    let mut p = Tyre::builtin().params().clone();
    f(&mut p);
    Tyre::new(p).unwrap()
}

fn step_once(t: &Tyre, kind: TransientKind, kappa: f64, alpha: f64) -> WheelOutput {
    step_at(t, kind, kappa, alpha, FZ)
}

fn step_at(t: &Tyre, kind: TransientKind, kappa: f64, alpha: f64, fz: f64) -> WheelOutput {
    let mut m = model(kind, InputMode::Slips);
    // 5 s held: every transient model settles (rolled distance ≫ σ).
    m.step(
        t,
        &WheelInput {
            fz,
            ..slips(20.0, kappa, alpha)
        },
        5.0,
    )
    .unwrap()
}

#[test]
fn plain_and_neutral_extensions_are_bit_identical() {
    let plain = Tyre::builtin();
    assert!(plain.extension().is_none());
    // A [THERMAL] section with zero friction coefficients: the hook runs,
    // but s = c = 1 exactly, so the forces must be identical to the bit.
    let neutral = with(|p| {
        p.extra_section(THERMAL_SECTION).set("MU_T1", 0.0);
    });
    assert!(neutral.extension().is_some());
    for kind in common::KINDS {
        for (k, a) in [(0.0, 0.0), (0.05, 0.02), (-0.3, -0.2)] {
            let (x, y) = (
                step_once(&plain, kind, k, a),
                step_once(&neutral, kind, k, a),
            );
            assert_eq!(
                (x.fx, x.fy, x.mz),
                (y.fx, y.fy, y.mz),
                "{kind:?} κ {k} α {a}"
            );
        }
    }
}

#[test]
fn load_sensitivity_scales_peak_and_stiffness() {
    let plain = Tyre::builtin();
    let fz0 = plain.params().p.fnomin;
    // At 1.5·Fz0: dfz = 0.5.
    let (fz, dfz) = (1.5 * fz0, 0.5);
    let ext = with(|p| {
        let s = p.extra_section("LOAD_SENSITIVITY");
        s.set("MU_DFZ1", -0.2);
        s.set("K_DFZ1", 0.3);
    });
    let s = 1.0 - 0.2 * dfz;
    let c = 1.0 + 0.3 * dfz;
    let st = TransientKind::Steady;
    // Small slip: the force scales with the stiffness c (similarity
    // F = s·F0(c·α/s) ≈ c·K·α; 1e-4 rad keeps the curvature below 1e-4).
    let d = |t: &Tyre| step_at(t, st, 0.0, 1e-4, fz).fy - step_at(t, st, 0.0, 0.0, fz).fy;
    let ratio = d(&ext) / d(&plain);
    assert!(
        (ratio - c).abs() < 1e-3 * c,
        "stiffness ratio {ratio}, expected {c}"
    );
    // Locked wheel (κ = −1): F = s·F0(c·κ/s) with F0 nearly flat there, so
    // the ratio is s to the curve's residual slope (< 1 %).
    let r = step_at(&ext, st, -1.0, 0.0, fz).fx / step_at(&plain, st, -1.0, 0.0, fz).fx;
    assert!((r - s).abs() < 0.01, "peak ratio {r} expected {s}");
    // At the nominal load nothing changes (dfz = 0), to the bit.
    let (a, b) = (
        step_at(&plain, st, 0.05, 0.05, fz0),
        step_at(&ext, st, 0.05, 0.05, fz0),
    );
    assert_eq!((a.fx, a.fy), (b.fx, b.fy));
}

#[test]
fn lmuv_lowers_friction_with_sliding_speed() {
    let plain = Tyre::builtin();
    let ext = with(|p| p.set("LMUV", 0.5).unwrap());
    let v0 = plain.params().p.longvl;
    // Locked wheel at 20 m/s: Vs = 20 m/s, s = 1/(1 + 0.5·20/V0) (MF 6.1 eq. 4.E7).
    let s = 1.0 / (1.0 + 0.5 * 20.0 / v0);
    let (b0, b1) = (
        step_once(&plain, TransientKind::Steady, -1.0, 0.0).fx,
        step_once(&ext, TransientKind::Steady, -1.0, 0.0).fx,
    );
    assert!(
        ((b1 / b0) - s).abs() < 0.01,
        "ratio {} expected {s}",
        b1 / b0
    );
    // Free rolling: no sliding, no change.
    let (r0, r1) = (
        step_once(&plain, TransientKind::Steady, 0.0, 0.0),
        step_once(&ext, TransientKind::Steady, 0.0, 0.0),
    );
    assert_eq!(r0.fx, r1.fx);
}

#[test]
fn tread_temperature_heats_with_friction_power_and_resets() {
    let (cap, cool, share) = (2000.0, 40.0, 0.5);
    let ext = with(|p| {
        let s = p.extra_section(THERMAL_SECTION);
        s.set("CAPACITY", cap);
        s.set("COOLING", cool);
        s.set("SHARE", share);
        s.set("MU_T1", -0.2);
    });
    // The temperature must be a serialised slot (checked at compile time).
    const _: () = assert!(SLOT_TEMP < N_STATES);
    let mut m = model(TransientKind::Steady, InputMode::Slips);
    let inp = slips(15.0, 0.0, 0.1);
    let first = m.step(&ext, &inp, 0.01).unwrap();
    // Run 10 time constants (C/h = 50 s) in 0.1 s steps: the node reaches
    // its equilibrium ΔT = q·P/h with P = |Fy·Vsy| of the (now cooler-grip) tyre.
    let mut last = first;
    for _ in 0..5000 {
        last = m.step(&ext, &inp, 0.1).unwrap();
    }
    let dt_k = m.state.x[SLOT_TEMP];
    let p = (last.fy * last.vsy).abs();
    let eq = share * p / cool;
    assert!(dt_k > 5.0, "tread barely heats: ΔT = {dt_k} K");
    assert!((dt_k - eq).abs() < 1e-3 * eq, "ΔT {dt_k} vs q·P/h {eq}");
    // Friction follows by the similarity method: F = s·F0(α') with
    // tan α' = tan α/s, s = 1 − 0.2·ΔT/50 K, F0 the plain steady MF (at
    // equilibrium the temperature at the step's start equals its end).
    let s = 1.0 - 0.2 * dt_k / 50.0;
    let f0 = Tyre::builtin()
        .evaluate(
            &MfInput {
                fz: FZ,
                alpha: (0.1f64.tan() / s).atan(),
                vx: 15.0,
                ..Default::default()
            },
            UseMode::default(),
        )
        .fy;
    // 1e-6: after 10 time constants the node is within e^-10 ≈ 5e-5 of its
    // equilibrium, so s at the last step's start differs from s(ΔT) by < 1e-6.
    assert!(
        (last.fy - s * f0).abs() < 1e-6 * f0.abs(),
        "Fy {} vs s·F0 {}",
        last.fy,
        s * f0
    );
    assert!(
        last.fy.abs() < first.fy.abs(),
        "a hot tread must grip less here"
    );
    m.reset();
    assert_eq!(m.state.x[SLOT_TEMP], 0.0);
    // Cools back towards ambient when the sliding stops.
    let mut m2 = m.clone();
    m2.state.x[SLOT_TEMP] = 20.0;
    m2.step(&ext, &slips(15.0, 0.0, 0.0), cap / cool).unwrap();
    let e = (-1.0f64).exp() * 20.0;
    assert!(
        (m2.state.x[SLOT_TEMP] - e).abs() < 1e-9,
        "{}",
        m2.state.x[SLOT_TEMP]
    );
}

#[test]
fn extension_survives_the_tir_writer_and_bad_values_are_refused() {
    let ext = with(|p| {
        let s = p.extra_section(THERMAL_SECTION);
        s.set("CAPACITY", 3000.0);
        s.set("MU_T2", -0.1);
        p.extra_section("LOAD_SENSITIVITY").set("MU_DFZ2", 0.05);
        p.set("LMUV", 0.3).unwrap();
    });
    let text = ext.params().to_tir_string();
    let back = Tyre::new(TyreParams::from_tir_str(&text, "roundtrip").unwrap()).unwrap();
    assert_eq!(back.extension(), ext.extension());
    let mut p = Tyre::builtin().params().clone();
    p.extra_section(THERMAL_SECTION).set("CAPACITY", -1.0);
    let e = Tyre::new(p).unwrap_err().to_string();
    assert!(e.contains("CAPACITY"), "{e}");
}
