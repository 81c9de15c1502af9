//! Quarter-vehicle braking from 100 km/h: locked wheel and slip control
//! (~15 %), stopping distance against S = v0·τ/2 + v0²/(2·a_max).

use crate::common;
use tyrekit::mf::Tyre;
use tyrekit::transient::scenario::{BrakeControl, BrakingScenario};
use tyrekit::transient::TransientKind;

/// Both runs stop within 10 % of the textbook estimate (which ignores the
/// wheel's spin-down and the relaxation lag, and assumes a_max from the start);
/// the slip controller holds the mean slip within 0.01 of 15 % and, on a tyre
/// whose force peaks before locking, stops shorter than the locked wheel;
/// at rest, no roll-back beyond the tyre's elastic deflection.
#[test]
fn braking_from_100_kmh() {
    let tyre = Tyre::builtin();
    for kind in [TransientKind::Relaxation, TransientKind::LuGre] {
        let locked = BrakingScenario {
            kind,
            ..Default::default()
        };
        let abs = BrakingScenario {
            control: BrakeControl::SlipControl {
                target: 0.15,
                min_speed: 3.0,
            },
            ..locked
        };
        let rl = locked.run(&tyre).unwrap();
        let ra = abs.run(&tyre).unwrap();
        println!(
            "{}: locked {rl:?}\n{}: slip control {ra:?}",
            kind.name(),
            kind.name()
        );
        for r in [&rl, &ra] {
            assert!(r.stopped);
            assert!(
                (r.stopping_distance / r.textbook_distance - 1.0).abs() < 0.10,
                "{}: {} m vs textbook {} m",
                kind.name(),
                r.stopping_distance,
                r.textbook_distance
            );
        }
        assert!(
            (ra.mean_slip + 0.15).abs() < 0.03,
            "mean slip {}",
            ra.mean_slip
        );
        assert!(rl.mean_slip < -0.9, "locked mean slip {}", rl.mean_slip);
        // After the stop the vehicle springs back on the tyre by at most twice
        // the deflection friction can hold (μ_peak·Fz/Cx), and rests within it.
        let (cx, _) = common::carcass(&tyre);
        let elastic = ra.a_max * locked.mass / cx;
        for r in [&rl, &ra] {
            assert!(r.rebound < 2.2 * elastic, "{}: rebound {r:?}", kind.name());
            assert!(
                r.rest_offset.abs() < 1.1 * elastic,
                "{}: rest {r:?}",
                kind.name()
            );
        }
        if ra.a_max > rl.a_max * 1.05 {
            assert!(ra.stopping_distance < rl.stopping_distance);
        }
    }
}

/// The braking runs barely depend on the communication step: stopping
/// distances at 10 ms and 1 ms agree with 0.1 ms within 0.5 % (both models,
/// non-linear relaxation too, locked and slip-controlled).
#[test]
fn braking_is_step_size_independent() {
    use tyrekit::transient::TransientOptions;
    let tyre = Tyre::builtin();
    for (kind, nonlinear) in [
        (TransientKind::Relaxation, false),
        (TransientKind::Relaxation, true),
        (TransientKind::LuGre, false),
    ] {
        for control in [
            BrakeControl::Locked,
            BrakeControl::SlipControl {
                target: 0.15,
                min_speed: 3.0,
            },
        ] {
            let run = |dt: f64| {
                BrakingScenario {
                    kind,
                    control,
                    dt,
                    options: TransientOptions {
                        nonlinear,
                        ..Default::default()
                    },
                    ..Default::default()
                }
                .run(&tyre)
                .unwrap()
                .stopping_distance
            };
            let fine = run(1e-4);
            for dt in [1e-3, 1e-2] {
                let d = run(dt);
                assert!(
                    (d / fine - 1.0).abs() < 0.005,
                    "{} nl {nonlinear} {control:?} dt {dt}: {d} m vs {fine} m",
                    kind.name()
                );
            }
        }
    }
}
