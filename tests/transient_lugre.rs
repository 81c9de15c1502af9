//! LuGre: steady state = MF within 1 % over the slip range (pure and combined),
//! hysteresis under oscillating slip, the Stribeck curve, braking to a stop and
//! driving off, and the [LUGRE] section.

use crate::common;
use common::*;
use tyrekit::mf::Tyre;
use tyrekit::transient::{InputMode, LuGreFriction, LuGreParams, TransientKind, TransientOptions};

/// Steady state (after 2 s at constant slip, ≥ 50 time constants) against the
/// MF at the same slips: within 1 % of the MF force, plus 0.1 % of Fz where the
/// MF force crosses zero.
#[test]
fn steady_state_equals_magic_formula() {
    let tyre = Tyre::builtin();
    let v = 15.0;
    let mut cases = Vec::new();
    for i in -20..=20 {
        cases.push((i as f64 * 0.05, 0.0));
        cases.push((0.0, i as f64 * 0.6f64.to_radians()));
    }
    for (k, a) in [(0.05, 0.05), (-0.1, -0.08), (0.3, 0.15), (-0.6, 0.2)] {
        cases.push((k, a));
    }
    for (k, a) in cases {
        let mut m = model(TransientKind::LuGre, InputMode::Slips);
        let mut out = Default::default();
        for _ in 0..2000 {
            out = m.step(&tyre, &slips(v, k, a), 1e-3).unwrap();
        }
        let o = mf(&tyre, v, k, a);
        for (got, want, n) in [(out.fx, o.fx, "Fx"), (out.fy, o.fy, "Fy")] {
            assert!(
                (got - want).abs() <= 0.01 * want.abs() + 1e-3 * FZ,
                "κ {k} α {a}: {n} {got} vs MF {want}"
            );
        }
    }
}

/// With force at zero slip (SVx/SHx shifts, camber thrust): the steady state
/// still equals the MF within 1 % (+0.1 % Fz), including near zero slip, where
/// the offset force is carried directly and only the slip-generated part by
/// the bristles. Shifts and camber: PVX1 = 0.03, PHY1 = 0.004, PVY1 = 0.02, γ = 3°.
#[test]
fn steady_state_equals_magic_formula_with_offsets() {
    use tyrekit::mf::{MfInput, UseMode};
    let mut params = tyrekit::tir::TyreParams::builtin();
    params.p.pvx1 = 0.03;
    params.p.phy1 = 0.004;
    params.p.pvy1 = 0.02;
    let tyre = Tyre::new(params).unwrap();
    let (v, gamma) = (15.0, 3f64.to_radians());
    for (k, a) in [
        (0.0, 0.0),
        (0.002, 0.0),
        (-0.01, 0.0),
        (0.0, 0.003),
        (0.0, -0.02),
        (0.2, 0.1),
    ] {
        let mut m = model(TransientKind::LuGre, InputMode::Slips);
        let mut inp = slips(v, k, a);
        inp.gamma = gamma;
        let mut out = Default::default();
        for _ in 0..2000 {
            out = m.step(&tyre, &inp, 1e-3).unwrap();
        }
        let out: tyrekit::transient::WheelOutput = out;
        let o = tyre.evaluate(
            &MfInput {
                fz: FZ,
                kappa: k,
                alpha: a,
                gamma,
                vx: v,
                ..Default::default()
            },
            UseMode::default(),
        );
        for (got, want, n) in [(out.fx, o.fx, "Fx"), (out.fy, o.fy, "Fy")] {
            assert!(
                (got - want).abs() <= 0.01 * want.abs() + 1e-3 * FZ,
                "κ {k} α {a}: {n} {got} vs MF {want}"
            );
        }
    }
}

/// Oscillating slip (κ = 0.05 ± 0.04 at 10 Hz, 10 m/s): Fx against κ is a loop,
/// not a line: at the mean slip the rising and falling branches differ by
/// more than 10 % of the force swing, and the loop encloses an area.
#[test]
fn hysteresis_under_oscillating_slip() {
    let tyre = Tyre::builtin();
    let (v, f, dt) = (10.0, 10.0, 1e-4);
    let w = 2.0 * std::f64::consts::PI * f;
    let mut m = model(TransientKind::LuGre, InputMode::Slips);
    let (mut up, mut down) = (f64::NAN, f64::NAN);
    let (mut fmin, mut fmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut area = 0.0;
    let (mut kp, mut fp) = (f64::NAN, f64::NAN);
    let n = (1.0 / dt) as usize;
    for i in 0..n {
        let t = (i + 1) as f64 * dt;
        let k = 0.05 + 0.04 * (w * t).sin();
        let out = m.step(&tyre, &slips(v, k, 0.0), dt).unwrap();
        if t > 0.5 {
            fmin = fmin.min(out.fx);
            fmax = fmax.max(out.fx);
            if kp.is_finite() {
                area += 0.5 * (out.fx + fp) * (k - kp);
                if (kp - 0.05) * (k - 0.05) <= 0.0 {
                    if k > kp {
                        up = out.fx;
                    } else {
                        down = out.fx;
                    }
                }
            }
            kp = k;
            fp = out.fx;
        }
    }
    let swing = fmax - fmin;
    assert!(swing > 0.0);
    assert!(
        (up - down).abs() > 0.1 * swing,
        "branches at mean slip: up {up}, down {down}, swing {swing}"
    );
    assert!(area.abs() > 0.01 * swing * 0.08, "loop area {area}");
}

/// Stribeck friction function (own parameters, pure sliding at standstill:
/// vx = 0, wheel spinning): the steady force is Fz·g(vr) with
/// g = μc + (μs − μc)·exp(−(vr/vs)^δ), within 0.5 %: high at low sliding
/// speed, falling towards μc.
#[test]
fn stribeck_effect() {
    let tyre = Tyre::builtin();
    let p = LuGreParams {
        friction: LuGreFriction::Stribeck,
        mu_c: 0.8,
        mu_s: 1.2,
        vs: 1.0,
        delta: 2.0,
        ..Default::default()
    };
    let o = TransientOptions {
        lugre: p,
        ..Default::default()
    };
    let r = re(&tyre, 0.0);
    let mut last = f64::INFINITY;
    for vr in [0.05, 0.2, 0.5, 1.0, 2.0, 5.0] {
        let mut m = model_opts(TransientKind::LuGre, InputMode::Velocities, o);
        let mut out = Default::default();
        for _ in 0..2000 {
            out = m.step(&tyre, &vel(0.0, 0.0, vr / r), 1e-3).unwrap();
        }
        let g = 0.8 + 0.4 * (-(vr / 1.0f64).powi(2)).exp();
        assert!(
            (out.fx / (FZ * g) - 1.0).abs() < 0.005,
            "vr {vr}: Fx {} vs {}",
            out.fx,
            FZ * g
        );
        assert!(out.fx < last, "not falling with sliding speed");
        last = out.fx;
    }
}

/// Braking a quarter vehicle to a stop with LuGre, then driving off with a
/// drive torque: the vehicle stops (speed reaches 0), holds (it springs back
/// on the tyre by no more than the elastic deflection), and then accelerates smoothly: speed never
/// decreases by more than 1 mm/s, Fx stays positive after the first 50 ms.
#[test]
fn braking_to_stop_and_driving_off() {
    use tyrekit::transient::scenario::{BrakeControl, BrakingScenario};
    let tyre = Tyre::builtin();
    let sc = BrakingScenario {
        v0: 10.0,
        kind: TransientKind::LuGre,
        control: BrakeControl::Locked,
        ..Default::default()
    };
    let r = sc.run(&tyre).unwrap();
    assert!(r.stopped, "did not stop: {r:?}");
    // At rest the sliding force is released by the tyre spring: the vehicle
    // rocks back by at most twice the elastic deflection μFz/Cx and comes to
    // rest within it (no roll-away).
    let (cx, _) = carcass(&tyre);
    let elastic = r.a_max * (FZ / G).max(sc.mass) / cx;
    assert!(
        r.rebound < 2.0 * elastic * 1.1,
        "rebound {} m vs elastic {elastic} m: {r:?}",
        r.rebound
    );
    assert!(
        r.rest_offset.abs() < 1.1 * elastic,
        "rest {} m: {r:?}",
        r.rest_offset
    );

    // Drive off from rest: drive torque ramps to 600 N m over 0.5 s.
    let mass = FZ / G;
    let iw = 1.2;
    let dt = 1e-3;
    let mut m = model(TransientKind::LuGre, InputMode::Velocities);
    let (mut v, mut om) = (0.0f64, 0.0f64);
    let mut vmax = 0.0f64;
    for k in 0..3000 {
        let t = k as f64 * dt;
        let out = m.step(&tyre, &vel(v, 0.0, om), dt).unwrap();
        let torque = 600.0 * (t / 0.5).min(1.0);
        v += out.fx / mass * dt;
        om += (torque - out.fx * out.re) / iw * dt;
        if t > 0.05 {
            assert!(out.fx > 0.0, "t {t}: Fx {}", out.fx);
        }
        assert!(v > vmax - 1e-3, "t {t}: speed fell from {vmax} to {v}");
        vmax = vmax.max(v);
    }
    assert!(v > 2.0, "did not drive off: v = {v}");
}

/// [LUGRE] section: read, written back and read again to the same values;
/// bad values name the file, line and key.
#[test]
fn lugre_section_round_trip() {
    let text = "[MODEL]\nFITTYP = 61\n[LUGRE]\nSIGMA0X = 150 $ bristle\nSIGMA1X = 0.5\nMUC = 0.8\nMUS = 1.1\nVS = 2.5\nDELTA = 0.7\nKAPPA_L = 6\n[OTHER]\nMUC = 9\n";
    let p = LuGreParams::from_tir_text(text, "x.tir").unwrap();
    assert_eq!(p.friction, LuGreFriction::Stribeck);
    assert_eq!(
        (p.sigma0x, p.sigma1x, p.mu_c, p.mu_s),
        (150.0, 0.5, 0.8, 1.1)
    );
    assert_eq!((p.vs, p.delta, p.kappa_l), (2.5, 0.7, 6.0));
    let back = LuGreParams::from_tir_text(&p.to_tir_section(), "y.tir").unwrap();
    assert_eq!(back, p);
    assert_eq!(
        LuGreParams::from_tir_text("", "z.tir").unwrap(),
        LuGreParams::default()
    );
    let e = LuGreParams::from_tir_text("[LUGRE]\nVS = 0\n", "bad.tir").unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("bad.tir:2") && msg.contains("VS"), "{msg}");
    let e = LuGreParams::from_tir_text("[LUGRE]\n\nMUC = abc\n", "bad.tir").unwrap_err();
    assert!(e.to_string().contains("bad.tir:3"), "{e}");
}

/// [LUGRE] through the `.tir` custom-section API: parameters stored in a tyre
/// file's section are written by the `.tir` writer, read back by the reader
/// and give the same LuGre parameters (round trip exact: the writer keeps
/// full precision); a file without the section gives the defaults, and a
/// non-numeric or out-of-range value is refused naming the file and key.
#[test]
fn lugre_section_round_trips_through_tir_writer() {
    use tyrekit::tir::TyreParams;
    let p = LuGreParams {
        friction: LuGreFriction::Stribeck,
        sigma0x: 151.25,
        sigma0y: 98.5,
        sigma1x: 0.37,
        sigma1y: 0.0,
        sigma2: 1.0 / 3.0,
        mu_c: 0.8,
        mu_s: 1.1,
        vs: 2.5,
        delta: 0.7,
        kappa_l: 6.0,
        breakaway: 0.4,
    };
    let mut t = TyreParams::builtin();
    assert_eq!(
        LuGreParams::from_tyre_params(&t).unwrap(),
        LuGreParams::default()
    );
    p.write_to(&mut t);
    let text = t.to_tir_string();
    assert!(text.contains("[LUGRE]"), "writer dropped the section");
    let back = TyreParams::from_tir_str(&text, "rt.tir").unwrap();
    assert_eq!(LuGreParams::from_tyre_params(&back).unwrap(), p);
    // The model reads the same tyre data from the round-tripped file.
    assert_eq!(back.p.fnomin, t.p.fnomin);
    let mut b = TyreParams::from_tir_str(&text, "bad.tir").unwrap();
    b.extra_section("LUGRE").set("VS", 0.0);
    let e = LuGreParams::from_tyre_params(&b).unwrap_err().to_string();
    assert!(e.contains("bad.tir") && e.contains("VS"), "{e}");
    b.set_string("LUGRE", "VS", "fast");
    let e = LuGreParams::from_tyre_params(&b).unwrap_err().to_string();
    assert!(e.contains("bad.tir") && e.contains("VS"), "{e}");
}

/// Leaving a slip for exactly zero slip: the bristle deflection relaxes over
/// the rolled distance as it does at any small slip (θ takes its limit
/// Fz·σ0·|Vx|/K at zero own slip; it was 0/0 → 0 and froze the last force).
/// After 0.5 s at 15 m/s (7.5 m rolled, many relaxation lengths) the forces
/// at κ = 0, α = 0 equal those at κ = α = 1e-12 and the MF's zero-slip force
/// within 0.1 % of Fz.
#[test]
fn deflection_relaxes_at_exactly_zero_slip() {
    let tyre = Tyre::builtin();
    let v = 15.0;
    let run = |k0: f64, a0: f64| {
        let mut m = model(TransientKind::LuGre, InputMode::Slips);
        for _ in 0..1000 {
            m.step(&tyre, &slips(v, 0.05, 3f64.to_radians()), 1e-3)
                .unwrap();
        }
        let mut out = Default::default();
        for _ in 0..500 {
            out = m.step(&tyre, &slips(v, k0, a0), 1e-3).unwrap();
        }
        let out: tyrekit::transient::WheelOutput = out;
        out
    };
    let (zero, tiny) = (run(0.0, 0.0), run(1e-12, 1e-12));
    let o = mf(&tyre, v, 0.0, 0.0);
    for (a, b, want, n) in [
        (zero.fx, tiny.fx, o.fx, "Fx"),
        (zero.fy, tiny.fy, o.fy, "Fy"),
    ] {
        assert!(
            (a - b).abs() <= 1e-3 * FZ && (a - want).abs() <= 1e-3 * FZ,
            "{n}: {a} at zero slip, {b} at 1e-12, MF {want}"
        );
    }
}
