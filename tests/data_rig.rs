//! Rig simulator → TTC `.mat` / `.dat` → reader: the ISO-W truth comes back
//! within the rig's noise, the signs are right, the warm-up is cut where the
//! programme starts, and the test matrix (segments and set points) is found.

use crate::common::scratch;
use std::path::{Path, PathBuf};
use tyrekit::data::{load, Format, LoadOptions, Loaded, ReChoice, Recording, SegmentKind};
use tyrekit::mf::Tyre;
use tyrekit::rig::{simulate, Noise, RigConfig, RigRun, SteadyMf, TtcUnits};

/// `name` in the test's scratch folder `d`.
fn run(units: TtcUnits, seed: u64) -> (RigConfig, RigRun) {
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, seed);
    cfg.units = units;
    let mut m = SteadyMf::new(tyre);
    let r = simulate(&cfg, &mut m);
    (cfg, r)
}

fn read(p: &Path, re: ReChoice) -> Loaded {
    let o = LoadOptions {
        re,
        ..Default::default()
    };
    load(p, &o).unwrap()
}

/// Truth row of a recorded sample, matched by its exact time stamp.
fn truth_index(r: &RigRun, t: f64) -> usize {
    let i = r.truth.partition_point(|s| s.time < t - 1e-9);
    assert!(
        (r.truth[i].time - t).abs() < 1e-9,
        "no truth row at t = {t}"
    );
    i
}

/// Mean and standard deviation of the recorded − truth differences.
fn diff_stats(
    rec: &Recording,
    r: &RigRun,
    f: impl Fn(&tyrekit::data::Sample) -> f64,
) -> (f64, f64) {
    let d: Vec<f64> = rec
        .samples
        .iter()
        .filter(|s| s.fz > 100.0)
        .map(|s| f(s) - f(&r.truth[truth_index(r, s.time)]))
        .collect();
    let n = d.len() as f64;
    let m = d.iter().sum::<f64>() / n;
    let sd = (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (m, sd)
}

fn check_recovery(rec: &Recording, r: &RigRun, cfg: &RigConfig) {
    let nz = &cfg.noise;
    // With ~10^5 samples the sample mean of the difference equals the offset
    // to within a few σ/√n (< 0.1 N) and the sample σ equals the rig's σ to
    // within 1 %; the tolerances below (1 N, 0.02 Nm, 5 % of σ) leave room for
    // the unit round trips (lbf, ft-lb) and nothing else.
    let (m, sd) = diff_stats(rec, r, |s| s.fy);
    assert!(
        (m - nz.fy_offset).abs() < 1.0 && (sd / nz.fy - 1.0).abs() < 0.05,
        "Fy: mean {m} sd {sd}"
    );
    let (m, sd) = diff_stats(rec, r, |s| s.fx);
    assert!(
        (m - nz.fx_offset).abs() < 1.0 && (sd / nz.fx - 1.0).abs() < 0.05,
        "Fx: mean {m} sd {sd}"
    );
    let (m, sd) = diff_stats(rec, r, |s| s.fz);
    assert!(
        m.abs() < 1.0 && (sd / nz.fz - 1.0).abs() < 0.05,
        "Fz: mean {m} sd {sd}"
    );
    let (m, sd) = diff_stats(rec, r, |s| s.mz);
    assert!(
        (m - nz.mz_offset).abs() < 0.02 && (sd / nz.mz - 1.0).abs() < 0.05,
        "Mz: mean {m} sd {sd}"
    );
    let (m, sd) = diff_stats(rec, r, |s| s.alpha);
    assert!(
        (m - nz.alpha_offset).abs() < 1e-4 && (sd / nz.alpha - 1.0).abs() < 0.05,
        "alpha: mean {m} sd {sd}"
    );
    let (m, _) = diff_stats(rec, r, |s| s.gamma);
    assert!(m.abs() < 1e-5, "gamma: mean {m}");
    let (m, _) = diff_stats(rec, r, |s| s.p);
    assert!(m.abs() < 20.0, "P: mean {m}");
    // Vx = V·cos α: noise 0.02 m/s on V.
    let (m, sd) = diff_stats(rec, r, |s| s.vx);
    assert!(m.abs() < 0.005 && sd < 0.03, "Vx: mean {m} sd {sd}");
}

fn check_matrix(rec: &Recording, r: &RigRun) {
    let segs = &rec.segments;
    assert_eq!(segs.len(), r.plan.len(), "segment count");
    let count = |k: SegmentKind| segs.iter().filter(|s| s.kind == k).count();
    // 3 pressures × 3 inclinations × 5 loads cornering; 3 pressures × 3 slip
    // angles × 5 loads drive/brake, of which the α = 0 ones are pure.
    assert_eq!(count(SegmentKind::PureLateral), 45);
    assert_eq!(count(SegmentKind::PureLongitudinal), 15);
    assert_eq!(count(SegmentKind::Combined), 30);
    for (g, p) in segs.iter().zip(&r.plan) {
        assert_eq!(g.kind, p.kind);
        // Load wander σ 15 N and noise 10 N: the median sits within 2 % of the set point.
        assert!((g.fz / p.fz - 1.0).abs() < 0.02, "Fz {} vs {}", g.fz, p.fz);
        assert!(
            (g.gamma - p.gamma).abs() < 0.05f64.to_radians(),
            "γ {} vs {}",
            g.gamma,
            p.gamma
        );
        assert!((g.p - p.p).abs() < 500.0, "P {} vs {}", g.p, p.p);
        assert!((g.vx - p.vx).abs() < 0.05, "V {} vs {}", g.vx, p.vx);
        if p.kind != SegmentKind::PureLateral {
            // α set point + the rig's 0.03° offset.
            assert!(
                (g.alpha - p.alpha).abs() < 0.1f64.to_radians(),
                "α {} vs {}",
                g.alpha,
                p.alpha
            );
        }
        // The segment covers the programme step: starts/ends within 1.5 s of it.
        let t0 = r.truth[p.start].time;
        let t1 = r.truth[p.end - 1].time;
        assert!(
            (rec.samples[g.start].time - t0).abs() < 1.5,
            "start {} vs {t0}",
            rec.samples[g.start].time
        );
        assert!(
            (rec.samples[g.end - 1].time - t1).abs() < 1.5,
            "end {} vs {t1}",
            rec.samples[g.end - 1].time
        );
    }
}

fn check_warmup(l: &Loaded, r: &RigRun) {
    let w = l.report.warmup.as_ref().expect("warm-up detected");
    let t_prog = r.truth[r.warmup_rows].time;
    // Cut within 1.5 s before (the cut keeps a margin) and never after the programme start.
    assert!(
        w.t_end <= t_prog + 1e-9 && w.t_end > t_prog - 1.5,
        "cut at {} s, programme starts at {t_prog} s",
        w.t_end
    );
    assert!(!w.reason.is_empty());
    assert_eq!(l.recording.samples[0].time, w.t_end);
}

fn check_sweep_dir(rec: &Recording) {
    // In lateral segments, +1 must go with rising α and −1 with falling α
    // (away from the turning points, where the rate changes sign).
    let (mut agree, mut total) = (0, 0);
    for g in rec
        .segments
        .iter()
        .filter(|g| g.kind == SegmentKind::PureLateral)
    {
        for i in g.start + 20..g.end - 20 {
            let rate = (rec.samples[i + 20].alpha - rec.samples[i - 20].alpha)
                / (rec.samples[i + 20].time - rec.samples[i - 20].time);
            if rate.abs() > 2f64.to_radians() {
                total += 1;
                if (rate > 0.0) == (rec.sweep_dir[i] > 0) {
                    agree += 1;
                }
            }
        }
        assert!(rec.t_in_segment[g.start] == 0.0);
        assert!(
            (rec.t_in_segment[g.end - 1]
                - (rec.samples[g.end - 1].time - rec.samples[g.start].time))
                .abs()
                < 1e-9
        );
    }
    assert!(total > 10_000);
    assert!(agree as f64 > 0.995 * total as f64, "{agree}/{total}");
}

#[test]
fn rig_mat_and_dat_recover_the_iso_truth() {
    let d = scratch("data-rig");
    let (cfg, r) = run(TtcUnits::Si, 7);
    assert!(r.rows() > 100_000);
    // Raw TTC signs: a positive ISO slip angle is a negative SAE SA, and
    // the loaded tyre shows FZ < 0; FY has the sign opposite to ISO Fy.
    let sa = r.table.column("SA").unwrap();
    let fz = r.table.column("FZ").unwrap();
    let fy = r.table.column("FY").unwrap();
    let mut n_checked = 0;
    for (i, t) in r.truth.iter().enumerate() {
        if t.alpha > 5f64.to_radians() && t.fz > 1000.0 {
            assert!(
                sa.data[i] < -4.8,
                "ISO α {} → SAE SA {}",
                t.alpha.to_degrees(),
                sa.data[i]
            );
            assert!(fz.data[i] < -900.0);
            if t.fy.abs() > 200.0 {
                assert_eq!(fy.data[i].signum(), -t.fy.signum());
            }
            n_checked += 1;
        }
    }
    assert!(n_checked > 1000);
    // The built-in tyre's ISO Fy opposes α (PKY1 < 0 in ISO): a positive SAE
    // SA therefore gives a positive ISO Fy after reading.
    let pm = d.path().join("rig.mat");
    let pd = d.path().join("rig.dat");
    r.write_mat(&pm, true).unwrap();
    r.write_dat(&pd).unwrap();
    for p in [&pm, &pd] {
        let l = read(p, ReChoice::FreeRolling);
        assert_eq!(l.report.dropped_total, 0, "{:?}", l.report.dropped);
        assert!(
            l.report.missing.iter().all(|m| m == "phit" || m == "My"),
            "{:?}",
            l.report.missing
        );
        check_recovery(&l.recording, &r, &cfg);
        check_matrix(&l.recording, &r);
        check_warmup(&l, &r);
        check_sweep_dir(&l.recording);
        // Recorded SR/SL and the TTC extras are kept.
        for e in ["SR", "SL", "Rl", "Re", "TSTC", "NFY"] {
            assert!(l.recording.extra(e).is_some(), "extra {e} missing");
        }
    }
}

#[test]
fn kappa_from_wheel_speed_and_the_disturbed_recorded_re() {
    let d = scratch("data-rig");
    let (_, r) = run(TtcUnits::Si, 11);
    let p = d.path().join("kappa.mat");
    r.write_mat(&p, false).unwrap();
    // Free-rolling Re(Fz): κ within noise of the imposed κ. Noise on Ω
    // (0.02 rad/s of ~37 rad/s) and V (0.02 of 11.1 m/s) gives σκ ≈ 0.0018.
    let l = read(&p, ReChoice::FreeRolling);
    let rec = &l.recording;
    let mut worst = 0.0f64;
    let mut n = 0;
    for g in rec
        .segments
        .iter()
        .filter(|g| g.kind != SegmentKind::PureLateral)
    {
        for s in &rec.samples[g.start..g.end] {
            let t = &r.truth[truth_index(&r, s.time)];
            worst = worst.max((s.kappa - t.kappa).abs());
            n += 1;
        }
    }
    assert!(n > 30_000);
    assert!(worst < 0.012, "worst κ error {worst} (6σ ≈ 0.011)");
    assert!(
        l.report.kappa.contains("free-rolling"),
        "{}",
        l.report.kappa
    );
    // The recorded RE (= V/Ω) follows the slip: κ from it stays near 1/cos α − 1,
    // nowhere near the ±0.2 imposed.
    let l2 = read(&p, ReChoice::Recorded);
    let kmax = l2
        .recording
        .segments
        .iter()
        .filter(|g| g.kind == SegmentKind::PureLongitudinal)
        .flat_map(|g| l2.recording.samples[g.start..g.end].iter())
        .map(|s| s.kappa.abs())
        .fold(0.0, f64::max);
    assert!(kmax < 0.02, "κ from recorded RE reached {kmax}");
    // The model's Re(Fz): with the rig's own truth model it matches too.
    let l3 = read(&p, ReChoice::Model(Box::new(Tyre::builtin())));
    let g = l3
        .recording
        .segments
        .iter()
        .find(|g| g.kind == SegmentKind::PureLongitudinal)
        .unwrap();
    let err = l3.recording.samples[g.start..g.end]
        .iter()
        .map(|s| (s.kappa - r.truth[truth_index(&r, s.time)].kappa).abs())
        .fold(0.0, f64::max);
    assert!(err < 0.012, "κ with model Re: {err}");
}

#[test]
fn us_customary_export_reads_to_the_same_si_values() {
    let d = scratch("data-rig");
    let (cfg, r) = run(TtcUnits::UsCustomary, 3);
    let units: Vec<&str> = r
        .table
        .columns
        .iter()
        .map(|c| c.unit.as_deref().unwrap())
        .collect();
    assert!(units.contains(&"lb") && units.contains(&"psi") && units.contains(&"mph"));
    let p = d.path().join("us.dat");
    r.write_dat(&p).unwrap();
    let l = read(&p, ReChoice::FreeRolling);
    check_recovery(&l.recording, &r, &cfg);
    check_matrix(&l.recording, &r);
}

#[test]
fn rig_is_reproducible_and_noise_free_run_is_exact() {
    let d = scratch("data-rig");
    let (_, a) = run(TtcUnits::Si, 5);
    let (_, b) = run(TtcUnits::Si, 5);
    assert_eq!(a.table.columns, b.table.columns);
    let (_, c) = run(TtcUnits::Si, 6);
    assert_ne!(a.table.columns, c.table.columns);
    // Without noise the read-back equals the truth to rounding.
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 1);
    cfg.noise = Noise::none();
    cfg.programme.db_alphas.clear();
    cfg.decimate = 4;
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let p = d.path().join("exact.mat");
    r.write_mat(&p, true).unwrap();
    let l = load(
        &p,
        &LoadOptions {
            format: Some(Format::TtcMat),
            ..Default::default()
        },
    )
    .unwrap();
    for s in l.recording.samples.iter().filter(|s| s.fz > 1.0) {
        let t = &r.truth[truth_index(&r, s.time)];
        assert!((s.fy - t.fy).abs() < 1e-9 * (1.0 + t.fy.abs()));
        assert!((s.alpha - t.alpha).abs() < 1e-12);
        assert!((s.fz - t.fz).abs() < 1e-9 * t.fz);
    }
    // Decimated to 25 Hz: the matrix is still found.
    assert_eq!(l.recording.segments.len(), 45);
}

#[test]
fn warmup_at_its_own_load_is_cut_as_an_irregular_segment() {
    let d = scratch("data-rig");
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 21);
    if let Some(w) = cfg.programme.warmup.as_mut() {
        w.fz = Some(1200.0);
    }
    cfg.decimate = 2;
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let p = d.path().join("warm.mat");
    r.write_mat(&p, true).unwrap();
    let l = read(&p, ReChoice::FreeRolling);
    let w = l.report.warmup.as_ref().expect("warm-up detected");
    let t_prog = r.truth[r.warmup_rows].time;
    // The programme begins with the 1.5 s load transition from the warm-up
    // load; the cut must fall between its start and the first sweep.
    let t_sweep = r.truth[r.plan[0].start].time;
    assert!(
        w.t_end <= t_sweep + 1e-9 && w.t_end >= t_prog - 1e-9,
        "cut at {} s, programme at {t_prog} s, first sweep at {t_sweep} s: {}",
        w.t_end,
        w.reason
    );
    assert!(w.reason.contains("unlike the programme"), "{}", w.reason);
    assert_eq!(l.recording.segments.len(), r.plan.len());
}

/// Other tyres, more noise, another sample rate: the structure is still found.
#[test]
fn structure_survives_other_tyres_noise_and_rates() {
    let d = scratch("data-rig");
    let shared = std::env::var("TYREKIT_SHARED")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../shared").into());
    let mut tyres = vec![("builtin".to_string(), Tyre::builtin())];
    for f in ["FSAE_Defaults.tir", "CityBus_Pac02Tire.tir"] {
        let p = PathBuf::from(&shared).join("data/tir").join(f);
        match Tyre::from_file(&p) {
            Ok(t) => tyres.push((f.to_string(), t)),
            Err(_) => println!("SKIP {f}: not readable ({})", p.display()),
        }
    }
    for (name, tyre) in tyres {
        let mut cfg = RigConfig::standard(&tyre, 13);
        cfg.sample_rate = 50.0;
        let n = &mut cfg.noise;
        // Twice the default sensor noise and load wander (σ 30 N, the upper
        // end of the 17–35 N seen in the real TyreData.csv).
        for x in [
            &mut n.fx,
            &mut n.fy,
            &mut n.fz,
            &mut n.mz,
            &mut n.mx,
            &mut n.alpha,
            &mut n.p,
            &mut n.v,
            &mut n.fz_wander,
        ] {
            *x *= 2.0;
        }
        let r = simulate(&cfg, &mut SteadyMf::new(tyre));
        let p = d.path().join(format!("robust-{name}.mat"));
        r.write_mat(&p, true).unwrap();
        let l = read(&p, ReChoice::FreeRolling);
        assert_eq!(l.recording.segments.len(), r.plan.len(), "{name}");
        for (g, q) in l.recording.segments.iter().zip(&r.plan) {
            assert_eq!(g.kind, q.kind, "{name}");
            // The median of a 16 s run of wander with σ 30 N and τ 1 s has
            // σ ≈ 30/√8 ≈ 11 N; 40 N is about 4σ.
            assert!(
                (g.fz - q.fz).abs() < 40.0,
                "{name}: Fz {} vs {}",
                g.fz,
                q.fz
            );
        }
        assert!(l.report.warmup.is_some(), "{name}");
        let _ = std::fs::remove_file(&p);
    }
}

/// A speed programme (drive/brake blocks at 32, 40 and 48 km/h, as tyre
/// tests run them): every drive/brake segment is found at its own belt
/// speed, in the programme's order, and the cornering stays at `speed`.
#[test]
fn drive_brake_blocks_at_several_belt_speeds_are_found_at_their_speeds() {
    let d = scratch("data-rig");
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 31);
    let pr = &mut cfg.programme;
    pr.pressures.truncate(1);
    pr.inclinations.truncate(1);
    pr.loads.truncate(2);
    pr.db_alphas.truncate(1);
    let kph = [32.0, 40.0, 48.0];
    pr.db_speeds = kph.iter().map(|v| v / 3.6).collect();
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let p = d.path().join("speeds.mat");
    r.write_mat(&p, true).unwrap();
    let l = read(&p, ReChoice::FreeRolling);
    let segs = &l.recording.segments;
    assert_eq!(segs.len(), r.plan.len());
    let long: Vec<f64> = segs
        .iter()
        .filter(|s| s.kind == SegmentKind::PureLongitudinal)
        .map(|s| s.vx * 3.6)
        .collect();
    // Two loads per speed; belt-speed noise 0.05 m/s, so the median of a
    // segment is within a few mm/s of its set point: 0.2 km/h is ample and
    // far below the 8 km/h step between speeds.
    assert_eq!(long.len(), 6, "{long:?}");
    for (i, v) in long.iter().enumerate() {
        assert!((v - kph[i / 2]).abs() < 0.2, "segment {i}: {v} km/h");
    }
    for s in segs.iter().filter(|s| s.kind == SegmentKind::PureLateral) {
        assert!(
            (s.vx * 3.6 - 40.0).abs() < 0.2,
            "cornering at {} km/h",
            s.vx * 3.6
        );
    }
    // The truth follows the belt: Vx of every drive/brake row (α = 0) is
    // its segment's set point exactly.
    for q in r
        .plan
        .iter()
        .filter(|q| q.kind == SegmentKind::PureLongitudinal)
    {
        assert!(r.truth[q.start..q.end].iter().all(|s| s.vx == q.vx));
    }
}
