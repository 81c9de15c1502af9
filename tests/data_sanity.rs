//! Real-recording sanity checks: a TTC cornering export whose wheel-speed
//! channel is dead (N ≈ 0 rpm, so the recorded RE = V/N is ±3.7e5 cm and SR ≈
//! −1, as some real FSAE TTC cornering exports are), built in the TTC channel
//! layout by the rig simulator and written as `.dat` and `.mat`, SI and US
//! units; a broken moment channel; the same faults in TYDEX. The broken
//! channel must be rejected by name, the rows kept, κ taken as free rolling
//! and every sweep found as pure lateral (not `combined`).

use crate::common::scratch;
use tyrekit::data::{load, LoadOptions, Loaded, Recording, SegmentKind};
use tyrekit::mf::Tyre;
use tyrekit::rig::{simulate, RigConfig, RigRun, SteadyMf, TtcUnits};

/// `name` in the test's scratch folder `d`.
/// A cornering-only TTC programme (no drive/brake runs): three loads, two
/// inclinations, one pressure, no warm-up (kept short).
fn cornering_run(units: TtcUnits) -> RigRun {
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 7);
    cfg.units = units;
    let p = &mut cfg.programme;
    p.db_alphas.clear();
    p.pressures = vec![p.pressures[1]];
    p.inclinations = vec![0.0, 2f64.to_radians()];
    p.loads = vec![4000.0, 2000.0, 6000.0];
    p.warmup = None;
    simulate(&cfg, &mut SteadyMf::new(tyre))
}

fn col<'a>(r: &'a mut RigRun, name: &str) -> &'a mut Vec<f64> {
    &mut r
        .table
        .columns
        .iter_mut()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .data
}

/// N reads ≈ 0 rpm throughout; RE = V/N and SR follow from it as the
/// export computes them.
fn kill_wheel_speed(r: &mut RigRun) {
    let n = col(r, "N");
    for (i, x) in n.iter_mut().enumerate() {
        *x = 1e-3 * ((i % 3) as f64 - 1.0);
    }
    for (i, x) in col(r, "RE").iter_mut().enumerate() {
        *x = if i % 2 == 0 { 3.7e5 } else { -3.7e5 };
    }
    for x in col(r, "SR").iter_mut() {
        *x = -1.0 + 1e-5;
    }
}

fn read(p: &std::path::Path) -> Loaded {
    load(p, &LoadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn count(rec: &Recording, k: SegmentKind) -> usize {
    rec.segments.iter().filter(|s| s.kind == k).count()
}

fn rejected(l: &Loaded, ch: &str) -> bool {
    l.report
        .rejected
        .iter()
        .any(|r| r.contains(&format!("'{ch}'")))
}

/// The dead-wheel-speed checks shared by every format.
fn check_dead_wheel_speed(l: &Loaded, plan_lateral: usize, what: &str) {
    let rec = &l.recording;
    assert!(
        rejected(l, "omega"),
        "{what}: wheel speed not rejected: {:?}",
        l.report.rejected
    );
    assert!(!rec.has("omega"), "{what}: omega still listed");
    // Rows kept: nothing dropped for the dead channel (the rig's lead-in at
    // zero speed is all the loader may cut, as the warm-up/lead-in).
    assert_eq!(
        l.report.dropped_total, 0,
        "{what}: dropped {:?}",
        l.report.dropped
    );
    // κ as free rolling, exactly 0 (the test rolls freely: it has no drive/brake runs).
    assert!(
        l.report.kappa.starts_with("κ = 0"),
        "{what}: κ {}",
        l.report.kappa
    );
    assert!(
        rec.samples.iter().all(|s| s.kappa == 0.0),
        "{what}: κ not 0"
    );
    // Segment kinds: every programmed sweep pure lateral, none combined.
    assert_eq!(
        count(rec, SegmentKind::Combined),
        0,
        "{what}: combined segments"
    );
    assert_eq!(
        count(rec, SegmentKind::PureLateral),
        plan_lateral,
        "{what}: lateral segments {:?}",
        rec.segments.iter().map(|s| s.kind).collect::<Vec<_>>()
    );
}

#[test]
fn ttc_dead_wheel_speed_dat_and_mat_si_and_us() {
    let d = scratch("data-sanity");
    for units in [TtcUnits::Si, TtcUnits::UsCustomary] {
        let mut run = cornering_run(units);
        let plan_lateral = run
            .plan
            .iter()
            .filter(|s| s.kind == SegmentKind::PureLateral)
            .count();
        assert!(plan_lateral >= 6, "the programme has {plan_lateral} sweeps");
        kill_wheel_speed(&mut run);
        let dat = d.path().join(format!("dead_{units:?}.dat"));
        let mat = d.path().join(format!("dead_{units:?}.mat"));
        run.write_dat(&dat).unwrap();
        run.write_mat(&mat, true).unwrap();
        for p in [&dat, &mat] {
            let l = read(p);
            let what = format!("{} ({units:?})", p.display());
            check_dead_wheel_speed(&l, plan_lateral, &what);
            // The recorded RE (V/N of a dead N) and the pinned SR are rejected too.
            assert!(
                rejected(&l, "Re"),
                "{what}: RE kept: {:?}",
                l.report.rejected
            );
            assert!(l.recording.extra("Re").is_none(), "{what}: RE kept");
            assert!(
                rejected(&l, "SR"),
                "{what}: SR kept: {:?}",
                l.report.rejected
            );
            // The loaded radius is healthy and stays.
            assert!(l.recording.extra("Rl").is_some(), "{what}: RL lost");
        }
    }
}

#[test]
fn healthy_ttc_cornering_keeps_its_channels() {
    let d = scratch("data-sanity");
    // Control: the same export with a working wheel speed loses nothing.
    let run = cornering_run(TtcUnits::Si);
    let p = d.path().join("healthy.dat");
    run.write_dat(&p).unwrap();
    let l = read(&p);
    assert!(l.report.rejected.is_empty(), "{:?}", l.report.rejected);
    assert!(l.recording.has("omega") && l.recording.extra("Re").is_some());
    // κ from wheel speed: small on a free-rolling cornering test (|κ| < 0.02:
    // the rig's noise on Ω and V is 0.02 %, the free-rolling Re fit exact).
    let worst = l
        .recording
        .samples
        .iter()
        .filter(|s| s.fz > 1000.0)
        .fold(0.0f64, |m, s| m.max(s.kappa.abs()));
    assert!(worst < 0.02, "largest |κ| {worst}");
}

#[test]
fn absurd_moment_channel_loses_the_channel_not_the_rows() {
    let d = scratch("data-sanity");
    let mut run = cornering_run(TtcUnits::Si);
    // Mx reads an absurd 9.9e5 N-m on 98 % of the rows (a saturated or
    // mis-scaled channel).
    let mx = col(&mut run, "MX");
    let n = mx.len();
    for (i, x) in mx.iter_mut().enumerate() {
        if i % 50 != 0 {
            *x = 9.9e5;
        }
    }
    let p = d.path().join("absurd_mx.dat");
    run.write_dat(&p).unwrap();
    let l = read(&p);
    assert!(rejected(&l, "Mx"), "{:?}", l.report.rejected);
    assert!(!l.recording.has("Mx"));
    assert_eq!(l.report.dropped_total, 0, "{:?}", l.report.dropped);
    assert!(l.recording.samples.len() as f64 > 0.9 * n as f64);
    assert!(l.recording.has("Fy") && l.recording.has("Mz"));
    assert!(count(&l.recording, SegmentKind::PureLateral) >= 6);
}

#[test]
fn tydex_dead_wheel_speed_and_pinned_slip() {
    let d = scratch("data-sanity");
    let run = cornering_run(TtcUnits::Si);
    let p = d.path().join("healthy_for_tdx.dat");
    run.write_dat(&p).unwrap();
    let mut rec = read(&p).recording;
    let plan_lateral = count(&rec, SegmentKind::PureLateral);
    // A TYDEX file with a dead wheel speed and a recorded slip ratio pinned at −1.
    for s in rec.samples.iter_mut() {
        s.omega = 0.0;
        s.kappa = -1.0;
    }
    rec.extra
        .retain(|(n, _)| n != "Re" && n != "SR" && n != "SL");
    let tdx = d.path().join("dead.tdx");
    std::fs::write(&tdx, tyrekit::data::tdx::write(&rec)).unwrap();
    let l = read(&tdx);
    assert!(rejected(&l, "kappa"), "{:?}", l.report.rejected);
    check_dead_wheel_speed(&l, plan_lateral, "TYDEX");
}

/// A short full programme (cornering and drive/brake blocks) of `tyre`: three
/// loads, upright, one pressure, no warm-up.
fn full_run(tyre: &Tyre, seed: u64) -> RigRun {
    let mut cfg = RigConfig::standard(tyre, seed);
    let p = &mut cfg.programme;
    p.pressures = vec![p.pressures[1]];
    p.inclinations = vec![0.0];
    p.db_alphas.truncate(2);
    p.loads = vec![4000.0, 2000.0, 6000.0];
    p.warmup = None;
    simulate(&cfg, &mut SteadyMf::new(tyre.clone()))
}

/// A force channel that does not follow its slip is a dead load cell (or
/// one in a unit far larger than its label) and is rejected by name, rows
/// kept: an FX that reads a 30 N zero and ±10 N of noise through the
/// drive/brake sweeps to κ = ±0.2, and an FY written in kN under an `N`
/// label (values 1000× too small). Fitted, either would give a tyre
/// without that force, and a diagnosis would read the channel's noise.
#[test]
fn a_force_channel_that_does_not_follow_its_slip_is_rejected() {
    let d = scratch("data-sanity");
    let run = full_run(&Tyre::builtin(), 11);
    let mut dead_fx = run.clone();
    for (i, x) in col(&mut dead_fx, "FX").iter_mut().enumerate() {
        *x = 30.0 + 10.0 * (((i * 7919) % 201) as f64 / 100.0 - 1.0);
    }
    let mut kn_fy = run;
    col(&mut kn_fy, "FY").iter_mut().for_each(|x| *x /= 1000.0);
    for (r, dead, live) in [(dead_fx, "Fx", "Fy"), (kn_fy, "Fy", "Fx")] {
        let p = d.path().join(format!("dead_{dead}.dat"));
        r.write_dat(&p).unwrap();
        let l = read(&p);
        assert!(
            rejected(&l, dead),
            "{dead} not rejected: {:?}",
            l.report.rejected
        );
        let why = l.report.rejected.join(" ");
        assert!(why.contains("does not follow the slip"), "{why}");
        assert!(!l.recording.has(dead), "{dead} still listed");
        assert!(
            l.recording.has(live) && l.recording.has("Mz"),
            "{live} or Mz lost"
        );
        assert!(!rejected(&l, live), "{live} rejected: {why}");
        assert_eq!(l.report.dropped_total, 0, "{:?}", l.report.dropped);
    }
}

/// An aligning-moment channel that does not follow the lateral force is a
/// dead moment cell (or one a thousand times too small: kN·m under an
/// `N-m` label) and is rejected by name, rows and forces kept: an MZ that
/// reads a 2 N m zero and ±1 N m of noise through the cornering sweeps,
/// and the same programme's MZ divided by 1000. Fitted, either would give
/// a tyre with zero pneumatic trail. The healthy recording's MZ implies a
/// trail well above the 1 mm bound (checked here too), and the ice
/// recording below keeps its Mz as well.
#[test]
fn a_moment_channel_that_does_not_follow_the_lateral_force_is_rejected() {
    let d = scratch("data-sanity");
    let run = full_run(&Tyre::builtin(), 13);
    let mut dead = run.clone();
    for (i, x) in col(&mut dead, "MZ").iter_mut().enumerate() {
        *x = 2.0 + (((i * 7919) % 201) as f64 / 100.0 - 1.0);
    }
    let mut knm = run.clone();
    col(&mut knm, "MZ").iter_mut().for_each(|x| *x /= 1000.0);
    for (r, what) in [(dead, "dead"), (knm, "kN m")] {
        let p = d
            .path()
            .join(format!("dead_mz_{}.dat", what.replace(' ', "_")));
        r.write_dat(&p).unwrap();
        let l = read(&p);
        assert!(
            rejected(&l, "Mz"),
            "{what}: Mz kept: {:?}",
            l.report.rejected
        );
        let why = l.report.rejected.join(" ");
        assert!(why.contains("does not follow the lateral force"), "{why}");
        assert!(!l.recording.has("Mz"), "{what}: Mz still listed");
        assert!(
            l.recording.has("Fx") && l.recording.has("Fy") && !rejected(&l, "Fy"),
            "{what}: a force lost: {why}"
        );
        assert_eq!(l.report.dropped_total, 0, "{:?}", l.report.dropped);
    }
    let p = d.path().join("live_mz.dat");
    run.write_dat(&p).unwrap();
    let l = read(&p);
    assert!(l.report.rejected.is_empty(), "{:?}", l.report.rejected);
    // The healthy Mz: its trail between α = ±(1…3)° is centimetres.
    let band = |lo: f64, hi: f64| -> (Vec<f64>, Vec<f64>) {
        l.recording
            .samples
            .iter()
            .filter(|s| s.fz > 1000.0 && (lo..=hi).contains(&s.alpha.to_degrees()))
            .map(|s| (s.fy / s.fz, s.mz / s.fz))
            .unzip()
    };
    let med = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let ((py, pz), (ny, nz)) = (band(1.0, 3.0), band(-3.0, -1.0));
    let trail = ((med(pz) - med(nz)) / (med(py) - med(ny))).abs();
    assert!(
        trail > 10.0 * tyrekit::data::sanity::DEAD_TRAIL,
        "healthy trail {trail} m"
    );
}

/// The control: a tyre on ice — the built-in tyre's peak friction scaled
/// to 6 % (LMUX = LMUY = 0.06: |F| ≤ 0.06–0.08 Fz) — keeps both force
/// channels, as does the same programme at normal friction. The rule's
/// bound (0.02 between the two sides of the slip) lies a factor five below
/// what ice gives.
#[test]
fn force_channels_of_a_tyre_on_ice_are_kept() {
    let d = scratch("data-sanity");
    let mut ice = tyrekit::tir::TyreParams::builtin();
    ice.set("LMUX", 0.06).unwrap();
    ice.set("LMUY", 0.06).unwrap();
    for (t, what) in [(Tyre::new(ice).unwrap(), "ice"), (Tyre::builtin(), "dry")] {
        let p = d.path().join(format!("forces_{what}.dat"));
        full_run(&t, 12).write_dat(&p).unwrap();
        let l = read(&p);
        assert!(
            l.report.rejected.is_empty(),
            "{what}: {:?}",
            l.report.rejected
        );
        assert!(l.recording.has("Fx") && l.recording.has("Fy"), "{what}");
        // The recording does carry the ice's small forces: the rule passed
        // a channel with |F|/Fz ≤ 0.1, not a large one.
        let peak = l
            .recording
            .samples
            .iter()
            .filter(|s| s.fz > 1000.0)
            .map(|s| (s.fx / s.fz).abs().max((s.fy / s.fz).abs()))
            .fold(0.0f64, f64::max);
        if what == "ice" {
            assert!(peak < 0.15, "ice: peak |F|/Fz {peak}");
        } else {
            assert!(peak > 0.8, "dry: peak |F|/Fz {peak}");
        }
    }
}
