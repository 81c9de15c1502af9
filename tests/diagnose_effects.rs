//! rig::effects: each concealed effect changes the forces in its physical
//! direction, and stays concealed (a few % of the peak force, rms).

use tyrekit::data::{Sample, Segment, SegmentKind};
use tyrekit::mf::Tyre;
use tyrekit::rig::{effects, simulate, Noise, RigConfig, RigRun};

/// Three pressures, inclinations 0 and 4°, three loads, drive/brake at two
/// slip angles: every effect has the conditions it acts on.
fn cfg(tyre: &Tyre) -> RigConfig {
    let mut c = RigConfig::standard(tyre, 3);
    c.noise = Noise::none();
    c.programme.inclinations = vec![0.0, 4f64.to_radians()];
    c.programme.loads.truncate(3);
    c.programme.db_alphas.truncate(2);
    c
}

fn run(tyre: &Tyre, name: &str, level: f64) -> RigRun {
    let mut m = effects::concealed(name, tyre.clone(), level).unwrap();
    simulate(&cfg(tyre), m.as_mut())
}

/// rms of the force change and the peak force, over segments of `kind`, channel `ch`.
fn change(ctrl: &RigRun, eff: &RigRun, kind: SegmentKind, ch: fn(&Sample) -> f64) -> (f64, f64) {
    let (mut ss, mut n, mut peak) = (0.0, 0usize, 0.0f64);
    for g in ctrl.plan.iter().filter(|g| g.kind == kind) {
        for i in g.start..g.end {
            let d = ch(&eff.truth[i]) - ch(&ctrl.truth[i]);
            ss += d * d;
            n += 1;
            peak = peak.max(ch(&ctrl.truth[i]).abs());
        }
    }
    ((ss / n.max(1) as f64).sqrt(), peak)
}

fn fy(s: &Sample) -> f64 {
    s.fy
}
fn fx(s: &Sample) -> f64 {
    s.fx
}

/// Peak |F| of one segment.
fn seg_peak(r: &RigRun, g: &Segment, ch: fn(&Sample) -> f64) -> f64 {
    r.truth[g.start..g.end]
        .iter()
        .map(|s| ch(s).abs())
        .fold(0.0, f64::max)
}

/// Concealment: the rms change is between 0.3 % and 8 % of the peak force —
/// visible in a noise-free comparison, but "a plain fit looks reasonable".
fn assert_concealed(name: &str, rms: f64, peak: f64) {
    let r = rms / peak;
    println!(
        "{name}: rms change {rms:.1} N = {:.2} % of peak {peak:.0} N",
        100.0 * r
    );
    assert!(
        (0.003..0.08).contains(&r),
        "{name}: rms change {:.2} % of peak",
        100.0 * r
    );
}

#[test]
fn effects_are_concealed_and_point_the_right_way() {
    let tyre = Tyre::builtin();
    let ctrl = run(&tyre, "none", 1.0);
    // Control against itself: no change at all (deterministic truths).
    let again = run(&tyre, "none", 1.0);
    assert_eq!(change(&ctrl, &again, SegmentKind::PureLateral, fy).0, 0.0);

    // Lag effects: the change opposes the force's rate of change (the force
    // follows late): Σ ΔFy·dFy/dt < 0 over the lateral sweeps.
    for name in ["relaxation", "lugre"] {
        let e = run(&tyre, name, 1.0);
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLateral, fy);
        assert_concealed(name, rms, peak);
        let mut corr = 0.0;
        for g in ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLateral)
        {
            for i in g.start + 1..g.end {
                let rate = ctrl.truth[i].fy - ctrl.truth[i - 1].fy;
                corr += (e.truth[i].fy - ctrl.truth[i].fy) * rate;
            }
        }
        assert!(corr < 0.0, "{name}: the force does not lag ({corr})");
    }

    // Thermal: the tread heats (temperature written), friction falls at the
    // end of the programme against the beginning (Topt above the running temperature
    // the tyre reaches is not assumed: only that the ratio changes over time).
    {
        let e = run(&tyre, "thermal", 1.0);
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLateral, fy);
        assert_concealed("thermal", rms, peak);
        let lat: Vec<&Segment> = ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLateral)
            .collect();
        let ratio = |g: &Segment| seg_peak(&e, g, fy) / seg_peak(&ctrl, g, fy);
        let (r0, r1) = (ratio(lat[0]), ratio(lat[lat.len() - 1]));
        println!("thermal: peak ratio first {r0:.4}, last {r1:.4}");
        assert!(
            (r1 - r0).abs() > 0.005,
            "thermal: no drift of friction over the run"
        );
        let tcol = e.table.column("TSTC").unwrap();
        let tmax = tcol.data.iter().cloned().fold(f64::MIN, f64::max);
        assert!(
            tmax > 40.0,
            "thermal: tread temperature channel peaks at {tmax} °C"
        );
    }

    // Load sensitivity: the peak-force ratio falls with load.
    // Pressure: the peak-force ratio falls with pressure.
    for (name, key) in [("load_sensitivity", 0usize), ("pressure", 1)] {
        let e = run(&tyre, name, 1.0);
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLateral, fy);
        assert_concealed(name, rms, peak);
        let mut pts: Vec<(f64, f64)> = ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLateral && g.gamma == 0.0)
            .map(|g| {
                let x = if key == 0 { g.fz } else { g.p };
                (x, seg_peak(&e, g, fy) / seg_peak(&ctrl, g, fy))
            })
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (lo, hi) = (pts[0], pts[pts.len() - 1]);
        println!(
            "{name}: peak ratio {:.4} at {:.0}, {:.4} at {:.0}",
            lo.1, lo.0, hi.1, hi.0
        );
        assert!(hi.1 < lo.1 - 0.01, "{name}: peak ratio does not fall");
    }

    // Speed friction: the peak falls (large sliding speed), the linear
    // region (small sliding speed) barely changes.
    {
        let e = run(&tyre, "speed_friction", 1.0);
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLateral, fy);
        assert_concealed("speed_friction", rms, peak);
        let (mut lin, mut big) = ((0.0, 0.0), (0.0, 0.0));
        for g in ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLateral)
        {
            for i in g.start..g.end {
                let a = ctrl.truth[i].alpha.abs().to_degrees();
                let (c, x) = (ctrl.truth[i].fy.abs(), e.truth[i].fy.abs());
                if a < 1.0 {
                    lin.0 += c;
                    lin.1 += x;
                } else if a > 8.0 {
                    big.0 += c;
                    big.1 += x;
                }
            }
        }
        let (rl, rb) = (lin.1 / lin.0, big.1 / big.0);
        println!("speed_friction: |Fy| ratio {rl:.4} at |α| < 1°, {rb:.4} at |α| > 8°");
        assert!(
            rb < rl - 0.01 && rl > 0.99,
            "speed_friction: wrong slip dependence"
        );
    }

    // Rolling radius: drive/brake Fx shifted at κ ≈ 0, with the sign of the
    // load change (Re larger at high load → the tyre sees more drive slip).
    {
        let e = run(&tyre, "rolling_radius", 1.0);
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLongitudinal, fx);
        assert_concealed("rolling_radius", rms, peak);
        let fnom = tyre.params().p.fnomin;
        for g in ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLongitudinal)
        {
            let dfz = g.fz / fnom - 1.0;
            let mut shift = 0.0;
            let mut n = 0;
            for i in g.start..g.end {
                if ctrl.truth[i].kappa.abs() < 0.005 {
                    shift += e.truth[i].fx - ctrl.truth[i].fx;
                    n += 1;
                }
            }
            let shift = shift / n.max(1) as f64;
            println!("rolling_radius: Fz {:.0} N: ΔFx at κ≈0 {shift:.1} N", g.fz);
            if dfz.abs() > 0.1 {
                assert!(
                    shift * dfz > 0.0,
                    "rolling_radius: Fx shift sign at Fz {}",
                    g.fz
                );
            } else {
                assert!(
                    shift.abs() < 1.0,
                    "rolling_radius: shift at nominal load {shift}"
                );
            }
        }
    }

    // Camber: nothing at γ = 0; at γ = 4° a change that is largest at small α.
    {
        let e = run(&tyre, "camber", 1.0);
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLateral, fy);
        assert_concealed("camber", rms, peak);
        for g in ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLateral)
        {
            let d = (g.start..g.end)
                .map(|i| (e.truth[i].fy - ctrl.truth[i].fy).abs())
                .fold(0.0, f64::max);
            if g.gamma == 0.0 {
                assert!(d < 1e-9, "camber: change {d} N at γ = 0");
            } else {
                assert!(d > 10.0, "camber: no change at γ = {}", g.gamma);
            }
        }
    }
}

#[test]
fn stronger_level_means_larger_change() {
    let tyre = Tyre::builtin();
    let ctrl = run(&tyre, "none", 1.0);
    for name in &effects::EFFECTS[1..] {
        let kind = if *name == "rolling_radius" {
            SegmentKind::PureLongitudinal
        } else {
            SegmentKind::PureLateral
        };
        let ch = if *name == "rolling_radius" { fx } else { fy };
        let r1 = change(&ctrl, &run(&tyre, name, 1.0), kind, ch).0;
        let r2 = change(&ctrl, &run(&tyre, name, 2.0), kind, ch).0;
        println!("{name}: rms change {r1:.1} N at level 1, {r2:.1} N at level 2");
        // LuGre: level 2 halves the bristle stiffness (twice the lag at
        // small slip), which at least doubles the rms change here too.
        assert!(r2 > 1.3 * r1, "{name}: level 2 not stronger");
    }
    assert!(effects::concealed("no_such_effect", tyre, 1.0).is_none());
}

/// The second formulations are concealed too, and act where their physics
/// says: the exponential speed friction and the softening compound lower the
/// lateral peak, the power-law load sensitivity lowers it at the high load.
#[test]
fn second_formulations_are_concealed() {
    let tyre = Tyre::builtin();
    let ctrl = run(&tyre, "none", 1.0);
    for name in ["thermal", "speed_friction", "load_sensitivity"] {
        let mut m = effects::concealed_alt(name, tyre.clone(), 1.0).unwrap();
        let e = simulate(&cfg(&tyre), m.as_mut());
        let (rms, peak) = change(&ctrl, &e, SegmentKind::PureLateral, fy);
        assert_concealed(name, rms, peak);
        let lat = ctrl
            .plan
            .iter()
            .filter(|g| g.kind == SegmentKind::PureLateral)
            .max_by(|a, b| a.fz.total_cmp(&b.fz))
            .unwrap();
        let ratio = seg_peak(&e, lat, fy) / seg_peak(&ctrl, lat, fy);
        assert!(ratio < 0.995, "{name}: peak ratio {ratio} at the high load");
    }
    assert!(effects::concealed_alt("camber", tyre, 1.0).is_none());
}
