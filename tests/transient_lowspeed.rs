//! Low speed and standstill: a wheel at rest under a constant tangential force
//! is a stiff damped spring; a parked car on a 15 % slope holds with no creep
//! beyond the elastic deflection; the same rolling at 0.01 m/s.
//!
//! The wheel carries a quarter-car mass m = Fz/g·… coupled by co-simulation
//! (the tyre sees the mass's velocity held over each step; semi-implicit Euler
//! for the mass), at 1 ms and 10 ms communication steps.

use crate::common;
use common::*;
use tyrekit::mf::Tyre;
use tyrekit::transient::{InputMode, TransientKind, TransientModel};

/// Slope 15 %: along-slope weight = Fz·0.15 with Fz = m·g·cos θ.
const SLOPE: f64 = 0.15;

struct Hold {
    /// Final position (m) and speed (m/s) of the mass.
    x: f64,
    v: f64,
    /// Mean position over [40, 50] s and [50, 60] s.
    mean_a: f64,
    mean_b: f64,
    /// Final tyre force along the slope (N).
    f: f64,
    /// Largest |speed| in the last 10 s.
    vmax_late: f64,
}

/// Mass on the tyre under `fext`, longitudinal (locked wheel, ω = 0) or lateral
/// (vx = `roll`, ω = roll/Re), for 60 s.
fn hold(m: &mut TransientModel, tyre: &Tyre, lateral: bool, roll: f64, dt: f64) -> Hold {
    let mass = FZ / G * (1.0f64 + SLOPE * SLOPE).sqrt();
    let fext = FZ * SLOPE;
    let (mut x, mut v) = (0.0, 0.0);
    let n = (60.0 / dt).round() as usize;
    let (mut sa, mut sb, mut na, mut nb) = (0.0, 0.0, 0, 0);
    let mut vmax_late = 0.0f64;
    let mut f = 0.0;
    let r = re(tyre, roll);
    for k in 0..n {
        let inp = if lateral {
            vel(roll, v, roll / r)
        } else {
            vel(v, 0.0, 0.0)
        };
        let out = m.step(tyre, &inp, dt).unwrap();
        f = if lateral { out.fy } else { out.fx };
        v += (fext + f) / mass * dt;
        x += v * dt;
        let t = (k + 1) as f64 * dt;
        if t > 40.0 && t <= 50.0 {
            sa += x;
            na += 1;
        } else if t > 50.0 {
            sb += x;
            nb += 1;
            vmax_late = vmax_late.max(v.abs());
        }
    }
    Hold {
        x,
        v,
        mean_a: sa / na as f64,
        mean_b: sb / nb as f64,
        f,
        vmax_late,
    }
}

/// Parked on the slope (vx = ω = 0), braking and side force, relaxation and
/// LuGre: after 60 s the force balances the slope force within 0.1 %, the
/// mass has settled (|v| < 1e-4 m/s over the last 10 s: the residual of a
/// lightly damped mode with the file's DAMP_VLOW), the mean position moved
/// less than 1 µm between [40,50] s and [50,60] s (no creep), and the
/// displacement is the elastic deflection F/C within 5 % (C the carcass
/// stiffness: the tyre holds as a spring, not by sliding).
#[test]
fn parked_on_slope_holds_without_creep() {
    let tyre = Tyre::builtin();
    let (cx, cy) = carcass(&tyre);
    let fext = FZ * SLOPE;
    for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
        for lateral in [false, true] {
            for dt in [1e-3, 1e-2] {
                let mut m = model(kind, InputMode::Velocities);
                let h = hold(&mut m, &tyre, lateral, 0.0, dt);
                let what = format!("{} lateral {lateral} dt {dt}", kind.name());
                assert!((h.f + fext).abs() < 1e-3 * fext, "{what}: force {}", h.f);
                assert!(h.vmax_late < 1e-4, "{what}: late speed {}", h.vmax_late);
                assert!(
                    (h.mean_b - h.mean_a).abs() < 1e-6,
                    "{what}: creep {} m",
                    h.mean_b - h.mean_a
                );
                let c = if lateral { cy } else { cx };
                let defl = fext / c;
                assert!(
                    (h.x.abs() / defl - 1.0).abs() < 0.05,
                    "{what}: displacement {} m vs elastic {defl} m (v {})",
                    h.x,
                    h.v
                );
            }
        }
    }
}

/// Rolling at 0.01 m/s under a constant side force: the force settles to the
/// load within 0.1 %, and the lateral speed settles to the physical slip
/// |Vx|·tan α' of the slip angle the model reports (1 %): drift at exactly the
/// rate the slip angle implies, no more.
#[test]
fn rolling_at_one_cm_per_second_settles() {
    let tyre = Tyre::builtin();
    let fext = FZ * SLOPE;
    for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
        for dt in [1e-3, 1e-2] {
            let mut m = model(kind, InputMode::Velocities);
            let h = hold(&mut m, &tyre, true, 0.01, dt);
            let what = format!("{} dt {dt}", kind.name());
            assert!((h.f + fext).abs() < 1e-3 * fext, "{what}: force {}", h.f);
            let r = re(&tyre, 0.01);
            let out = m.step(&tyre, &vel(0.01, h.v, 0.01 / r), dt).unwrap();
            let expect = 0.01 * out.alpha.tan();
            assert!(
                (h.v - expect).abs() <= 0.01 * expect.abs() + 1e-7,
                "{what}: lateral speed {} vs |Vx|·tan α' = {expect}",
                h.v
            );
        }
    }
}

/// At exactly vx = ω = 0 with no motion the model produces no force and its
/// state does not move (no division by zero, no spurious creep), at any dt.
#[test]
fn at_rest_nothing_moves() {
    let tyre = Tyre::builtin();
    for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
        for dt in [1e-5, 1e-2] {
            let mut m = model(kind, InputMode::Velocities);
            for _ in 0..100 {
                let out = m.step(&tyre, &vel(0.0, 0.0, 0.0), dt).unwrap();
                assert_eq!((out.fx, out.fy), (0.0, 0.0));
            }
            assert!(m.state.x.iter().all(|x| *x == 0.0));
        }
    }
}

/// Starting and stopping are smooth: a speed ramp 0 → 5 m/s → 0 over 4 s with
/// a constant slip ratio and slip angle gives forces whose step-to-step change
/// never exceeds 1 % of Fz·μ per ms (no jumps, no sign chatter through 0).
#[test]
fn smooth_start_and_stop() {
    let tyre = Tyre::builtin();
    let dt = 1e-3;
    for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
        let mut m = model(kind, InputMode::Velocities);
        let r = re(&tyre, 1.0);
        let (mut px, mut py) = (0.0, 0.0);
        let mut sign_changes = 0;
        for k in 0..4000 {
            let t = k as f64 * dt;
            let vx = 5.0 * (std::f64::consts::PI * t / 4.0).sin().powi(2);
            let out = m
                .step(&tyre, &vel(vx, -0.03 * vx, vx * 1.05 / r), dt)
                .unwrap();
            let lim = 0.01 * FZ * tyre.params().p.pdx1;
            assert!(
                (out.fx - px).abs() < lim && (out.fy - py).abs() < lim,
                "{} t {t}: jump ({} → {}, {} → {})",
                kind.name(),
                px,
                out.fx,
                py,
                out.fy
            );
            if k > 0 && out.fx * px < 0.0 {
                sign_changes += 1;
            }
            px = out.fx;
            py = out.fy;
        }
        assert!(sign_changes <= 1, "{}: Fx sign chatter", kind.name());
    }
}
