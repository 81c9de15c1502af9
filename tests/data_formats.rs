//! Readers and writers: CSV and TYDEX round trips, MFeval-style aliases with
//! `[unit]` suffixes, rows with NaN / out-of-range values dropped and
//! counted, missing channels reported, and malformed or truncated files
//! rejected with an error naming the file and the place.

use crate::common::scratch;
use std::path::{Path, PathBuf};
use tyrekit::data::{csvio, load, tdx, Format, LoadOptions, Loaded};
use tyrekit::mf::Tyre;
use tyrekit::rig::{simulate, RigConfig, SteadyMf};
use tyrekit::Error;

/// `content` written to `name` in the test's scratch folder `d`.
fn tmp(d: &Path, name: &str, content: &[u8]) -> PathBuf {
    let p = d.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

fn load_str(d: &Path, name: &str, content: &str) -> tyrekit::Result<Loaded> {
    load(&tmp(d, name, content.as_bytes()), &LoadOptions::default())
}

fn expect_recording_error(r: tyrekit::Result<Loaded>, want_loc: &str) -> String {
    match r {
        Err(Error::Recording {
            file,
            location,
            message,
        }) => {
            assert!(!file.is_empty());
            assert!(
                location.contains(want_loc),
                "location '{location}' lacks '{want_loc}' ({message})"
            );
            message
        }
        Err(e) => panic!("wrong error kind: {e}"),
        Ok(_) => panic!("malformed file accepted"),
    }
}

/// Sample-by-sample equality, NaN (absent channel) equal to NaN.
fn same_samples(a: &[tyrekit::data::Sample], b: &[tyrekit::data::Sample]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        for (u, v) in x.values().iter().zip(y.values()) {
            assert!(*u == v || (u.is_nan() && v.is_nan()), "{x:?} vs {y:?}");
        }
    }
}

fn rig_loaded(d: &Path, name: &str) -> Loaded {
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 2);
    cfg.decimate = 5;
    cfg.programme.pressures.truncate(1);
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let p = tmp(d, name, &tyrekit::data::ttc::write_mat(&r.table, true));
    load(&p, &LoadOptions::default()).unwrap()
}

#[test]
fn csv_and_tydex_round_trip_the_clean_table() {
    let d = scratch("data-formats");
    let l = rig_loaded(d.path(), "small-rt.mat");
    let rec = &l.recording;
    let csv = csvio::write(rec);
    let head = csv.lines().next().unwrap();
    assert!(
        head.starts_with("time,Vx,omega,Fz,kappa,alpha,gamma,P,Fx,Fy,Mx,Mz,"),
        "{head}"
    );
    assert!(head.ends_with("segment,sweep_dir,t_in_segment"));
    let opts = LoadOptions {
        remove_warmup: false,
        ..Default::default()
    };
    let back = load(&tmp(d.path(), "rt.csv", csv.as_bytes()), &opts).unwrap();
    same_samples(&back.recording.samples, &rec.samples);
    assert_eq!(back.report.kappa, "recorded channel");
    // Same structure found again on the clean table.
    assert_eq!(back.recording.segments.len(), rec.segments.len());
    let t = tdx::write(rec);
    assert!(t.contains("**MEASURCHANNELS") && t.contains("SLIPANGL") && t.ends_with("**END\n"));
    let back = load(&tmp(d.path(), "rt.tdx", t.as_bytes()), &opts).unwrap();
    assert_eq!(back.report.format, "Tydex");
    same_samples(&back.recording.samples, &rec.samples);
    assert_eq!(back.recording.segments.len(), rec.segments.len());
}

#[test]
fn mfeval_aliases_units_nan_and_range() {
    let d = scratch("data-formats");
    // MFeval column names with units; degrees and kPa are converted.
    let text = "Time [s],Vx [m/s],W [rad/s],SA [deg],IA [deg],Rl [m],Re [m],P [kPa],Fx [N],Fy [N],Fz [N],Mx [Nm],Mz [Nm],SR [-],Phit [-]\n\
        0.0,16,64,1,0,0.25,0.253,83,0,-300,1600,-10,5,0,0\n\
        0.1,16,64,2,0,0.25,0.253,83,0,NaN,1600,-10,5,0,0\n\
        0.2,16,64,3,0,0.25,0.253,83,0,-900,1600,-10,5,0,0\n\
        0.3,16,64,95,0,0.25,0.253,83,0,-900,1600,-10,5,0,0\n\
        0.4,16,64,4,0,0.25,0.253,83,0,-1100,1600,-10,5,,0\n";
    let l = load_str(d.path(), "mfeval.csv", text).unwrap();
    let r = &l.recording;
    assert_eq!(l.report.rows_read, 5);
    // NaN Fy, α = 95° and an empty SR are dropped, each counted once.
    assert_eq!(l.report.dropped_total, 3, "{:?}", l.report.dropped);
    assert!(l
        .report
        .dropped
        .iter()
        .any(|(w, n)| w.starts_with("Fy") && *n == 1));
    assert!(l
        .report
        .dropped
        .iter()
        .any(|(w, n)| w.starts_with("alpha") && w.contains("outside") && *n == 1));
    assert!(l
        .report
        .dropped
        .iter()
        .any(|(w, n)| w.starts_with("kappa") && *n == 1));
    assert_eq!(r.samples.len(), 2);
    assert!((r.samples[1].alpha - 3f64.to_radians()).abs() < 1e-15);
    assert!((r.samples[0].p - 83_000.0).abs() < 1e-9);
    assert_eq!(l.report.missing, vec!["My".to_string()]);
    assert!(r.extra("Rl").is_some());
}

#[test]
fn missing_channels_are_reported() {
    let d = scratch("data-formats");
    let l = load_str(
        d.path(),
        "min.csv",
        "time,Fz,alpha,Fy\n0,1000,0.01,-100\n0.1,1000,0.02,-200\n",
    )
    .unwrap();
    for m in ["Vx", "omega", "gamma", "P", "Fx", "Mx", "My", "Mz", "phit"] {
        assert!(
            l.report.missing.iter().any(|x| x == m),
            "{m} not reported missing"
        );
    }
    // No wheel speed or slip channel, no Fx: a cornering test rolls freely,
    // and κ = 0 is taken and said, not left NaN (which no fit stage can use).
    assert!(
        l.report
            .kappa
            .starts_with("κ = 0: no wheel speed or slip channel"),
        "{}",
        l.report.kappa
    );
    assert!(l.recording.samples.iter().all(|s| s.kappa == 0.0));
    // No normal load: an error, not a guess.
    expect_recording_error(load_str(d.path(), "nofz.csv", "time,Fy\n0,1\n"), "FZ");
}

#[test]
fn malformed_files_name_the_place() {
    let d = scratch("data-formats");
    // CSV: short row, non-number.
    expect_recording_error(
        load_str(d.path(), "short.csv", "time,Fz,Fy\n0,1000,5\n0.1,1000\n"),
        "line 3",
    );
    let m = expect_recording_error(
        load_str(d.path(), "text.csv", "time,Fz,Fy\n0,1000,abc\n"),
        "line 2, column 'Fy'",
    );
    assert!(m.contains("abc"));
    // TTC .dat: unit row mismatch, truncated last row, unknown unit.
    let dat = "ET\tV\tSA\tFZ\tFY\ns\tkph\tdeg\tN\tN\n0\t40\t1\t-1000\t50\n0.01\t40\t1";
    expect_recording_error(load_str(d.path(), "trunc.dat", dat), "line 4");
    let dat = "ET\tV\tSA\tFZ\tFY\ns\tkph\tdeg\tkgf\tN\n0\t40\t1\t-1000\t50\n";
    let m = expect_recording_error(load_str(d.path(), "unit.dat", dat), "FZ");
    assert!(m.contains("kgf"));
    let dat = "ET\tV\tSA\tFZ\tFY\ns\tkph\tdeg\tN\n0\t40\t1\t-1000\t50\n";
    expect_recording_error(load_str(d.path(), "units.dat", dat), "line 2");
    // TYDEX without data section, and a data row with too few values.
    let t = "**HEADER\nRELEASE 1.3\n**MEASURCHANNELS\nRUNTIME time s 1 0 0\nFZW load N 1 0 0\n";
    expect_recording_error(load_str(d.path(), "nodata.tdx", t), "MEASURDATA");
    let t = "**HEADER\n**MEASURCHANNELS\nRUNTIME time s 1 0 0\nFZW load N 1 0 0\n**MEASURDATA\n0 1000\n0.1\n**END\n";
    expect_recording_error(load_str(d.path(), "row.tdx", t), "line 7");
    // MAT: a valid file cut short.
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 9);
    cfg.decimate = 50;
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let bytes = tyrekit::data::ttc::write_mat(&r.table, true);
    let p = tmp(d.path(), "cut.mat", &bytes[..bytes.len() * 2 / 3]);
    let e = load(&p, &LoadOptions::default());
    let m = expect_recording_error(e, "element");
    assert!(m.contains("truncated"), "{m}");
    // Unknown format.
    let p = tmp(d.path(), "mystery.bin", b"\x00\x01\x02");
    assert!(matches!(
        load(&p, &LoadOptions::default()),
        Err(Error::Recording { .. })
    ));
    // Forcing the format overrides detection.
    let p = tmp(d.path(), "renamed.txt", b"time,Fz\n0,1000\n0.1,1000\n");
    let o = LoadOptions {
        format: Some(Format::Csv),
        ..Default::default()
    };
    assert!(load(&p, &o).is_ok());
}

/// Load speed: a million rows (14 ISO columns) as CSV and as compressed .mat.
/// Run with `cargo test --release --test suite data_formats:: -- --ignored --nocapture`.
#[test]
#[ignore]
fn million_rows_load_time() {
    let d = scratch("data-formats");
    let n = 1_000_000;
    let mut s = String::from("time,Vx,omega,Fz,kappa,alpha,gamma,P,Fx,Fy,Mx,My,Mz\n");
    for i in 0..n {
        let t = i as f64 * 0.01;
        let a = (t * 0.3).sin() * 0.2;
        s.push_str(&format!(
            "{t},{},{},{},{},{a},0.0349,83000,{},{},{},{},{}\n",
            16.0 + 0.01 * (t * 2.0).cos(),
            64.0 + 0.1 * (t * 1.3).sin(),
            1500.0 + 100.0 * (t * 0.01).sin(),
            0.01 * (t * 0.7).sin(),
            -15.0 * a * 1000.0,
            -20.0 * a * 100.0,
            30.0 * a,
            -5.0,
            8.0 * a * 10.0,
        ));
    }
    let p = tmp(d.path(), "million.csv", s.as_bytes());
    let t0 = std::time::Instant::now();
    let l = load(&p, &LoadOptions::default()).unwrap();
    let dt = t0.elapsed();
    assert_eq!(
        l.recording.samples.len()
            + l.report.dropped_total
            + l.report.warmup.as_ref().map_or(0, |w| w.samples),
        n
    );
    println!(
        "1e6-row CSV ({} MB): loaded in {:.3} s",
        s.len() / 1_000_000,
        dt.as_secs_f64()
    );
    // The same as a TTC .mat (SAE, TTC units, compressed).
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 1);
    cfg.sample_rate = 800.0;
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let bytes = tyrekit::data::ttc::write_mat(&r.table, true);
    let p = tmp(d.path(), "big.mat", &bytes);
    let t0 = std::time::Instant::now();
    let l = load(&p, &LoadOptions::default()).unwrap();
    println!(
        "{}-row TTC .mat ({} channels, {} MB compressed): loaded in {:.3} s",
        r.rows(),
        r.table.columns.len(),
        bytes.len() / 1_000_000,
        t0.elapsed().as_secs_f64()
    );
    assert!(l.recording.segments.len() == r.plan.len());
}

/// Without a wheel speed, κ comes from what else the file holds: the rig's
/// slip ratio SR where it reads as one (a TTC export without N; in a CSV,
/// SR is the κ column itself), κ = 0 on a run that rolls freely, and
/// nothing (reported missing, with why) on a drive/brake run without either.
#[test]
fn slip_without_a_wheel_speed() {
    let d = scratch("data-formats");
    // TTC layout (SAE axes, kph, deg): a brake sweep to SR = ∓0.1, Fx ±800 N at 1 kN.
    let ttc = |sr_scale: f64, with_sr: bool| {
        let mut t = String::from(if with_sr {
            "ET\tV\tSA\tIA\tP\tFX\tFY\tFZ\tSR\ns\tkph\tdeg\tdeg\tkPa\tN\tN\tN\t-\n"
        } else {
            "ET\tV\tSA\tIA\tP\tFX\tFY\tFZ\ns\tkph\tdeg\tdeg\tkPa\tN\tN\tN\n"
        });
        for i in 0..400 {
            let x = 2.0 * (i as f64 / 400.0) - 1.0;
            t.push_str(&format!(
                "{:.2}\t40\t0.02\t0\t83\t{:.1}\t-10\t-1000",
                0.01 * i as f64,
                -800.0 * x
            ));
            if with_sr {
                t.push_str(&format!("\t{:.5}", -0.1 * x * sr_scale));
            }
            t.push('\n');
        }
        t
    };
    let l = load_str(d.path(), "sr.dat", &ttc(1.0, true)).unwrap();
    assert!(
        l.report.kappa.starts_with("κ = the recorded slip ratio SR"),
        "{}",
        l.report.kappa
    );
    for (i, s) in l.recording.samples.iter().enumerate() {
        let x = 2.0 * (i as f64 / 400.0) - 1.0;
        assert!((s.kappa + 0.1 * x).abs() < 1e-9, "κ {} at row {i}", s.kappa);
    }
    // SR in percent is not a ratio: not taken as κ, and the run brakes, so no κ = 0 either.
    let l = load_str(d.path(), "srpct.dat", &ttc(100.0, true)).unwrap();
    assert!(
        l.report.kappa.starts_with("missing") && l.report.kappa.contains("does not roll freely"),
        "{}",
        l.report.kappa
    );
    // No slip channel on a drive/brake run: the same.
    let l = load_str(d.path(), "nosr.dat", &ttc(1.0, false)).unwrap();
    assert!(l.report.kappa.starts_with("missing"), "{}", l.report.kappa);
    // A CSV that rolls freely (|Fx| ≪ Fz) without wheel speed or slip: κ = 0.
    let mut t = String::from("time,Vx,Fz,alpha,Fx,Fy\n");
    for i in 0..200 {
        let a = 0.1 * (0.05 * i as f64).sin();
        t.push_str(&format!(
            "{},10,1000,{a},-15,{}\n",
            0.01 * i as f64,
            -20000.0 * a
        ));
    }
    let l = load_str(d.path(), "free.csv", &t).unwrap();
    assert!(l.report.kappa.starts_with("κ = 0"), "{}", l.report.kappa);
    assert!(l.recording.samples.iter().all(|s| s.kappa == 0.0));
}

/// TTC layout without wheel speed or slip channel: `blocks` of (seconds,
/// braking) at 1 kN, 100 Hz; cornering blocks sweep SA ±8° with Fx at
/// `fx0` plus ±25 N of deterministic noise, braking blocks sweep Fx from 0
/// to −1200 N and back at SA 0.
fn ttc_without_slip(blocks: &[(f64, bool)], fx0: f64) -> String {
    let mut t = String::from("ET\tV\tSA\tIA\tP\tFX\tFY\tFZ\ns\tkph\tdeg\tdeg\tkPa\tN\tN\tN\n");
    let mut i = 0usize;
    for &(secs, braking) in blocks {
        let n = (secs * 100.0) as usize;
        for k in 0..n {
            let u = k as f64 / n as f64;
            let noise = 25.0 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
            let (sa, fx) = if braking {
                (0.0, -1200.0 * (std::f64::consts::PI * u).sin())
            } else {
                (8.0 * (std::f64::consts::TAU * u).sin(), fx0 + noise)
            };
            // SAE: FY falls with SA (as TTC data), FZ negative when loaded.
            t.push_str(&format!(
                "{:.2}\t40\t{sa:.3}\t0\t83\t{fx:.1}\t{:.1}\t-1000\n",
                0.01 * i as f64,
                -150.0 * sa
            ));
            i += 1;
        }
    }
    t
}

/// A recording that corners and brakes, shared without wheel speed or slip
/// channel: the cornering blocks roll freely and keep κ = 0, the braking
/// rows (whose slip nothing tells) are dropped with that reason, and a
/// brake-only run is still refused.
#[test]
fn cornering_blocks_of_a_run_without_any_slip_keep_free_rolling() {
    let d = scratch("data-formats");
    let t = ttc_without_slip(&[(20.0, false), (10.0, true), (20.0, false)], 0.0);
    let l = load_str(d.path(), "mixed.dat", &t).unwrap();
    assert!(
        l.report
            .kappa
            .starts_with("κ = 0 on the freely rolling stretches"),
        "{}",
        l.report.kappa
    );
    let r = &l.recording;
    assert!(r.samples.iter().all(|s| s.kappa == 0.0));
    // The braking block's rows beyond the free-rolling band (|Fx| > 150 N
    // of 1200: all but 2 × 0.4 s of its 10 s) are gone, the cornering rows stay.
    let dropped = l.report.dropped_total;
    assert!((900..=930).contains(&dropped), "{dropped} rows dropped");
    assert!(l
        .report
        .dropped
        .iter()
        .any(|(why, n)| why.contains("kappa: unknown") && *n == dropped));
    assert!(
        r.samples.iter().all(|s| s.fx.abs() < 160.0),
        "a braking row kept"
    );
    assert!(r.samples.iter().filter(|s| s.alpha.abs() > 0.02).count() > 3500);
    // Brake-only: nothing rolls freely for 2 s; its sweeps hold near the
    // peak for 4 s each, a dense band of Fx/Fz that must not pass for a
    // free-rolling level.
    let l = load_str(
        d.path(),
        "brake.dat",
        &ttc_without_slip(&[(10.0, true), (10.0, true)], 0.0),
    )
    .unwrap();
    assert!(l.report.kappa.starts_with("missing"), "{}", l.report.kappa);
    assert_eq!(l.report.dropped_total, 0);
}

/// Free rolling is judged against the run's own free-rolling level: a tyre
/// (or a force-sensor zero) with Fx at −9 % of Fz throughout — as one FSAE
/// tyre of the dev set — still rolls freely (|Fx| < 10 % Fz had refused it).
#[test]
fn a_cornering_run_with_a_free_rolling_fx_offset_rolls_freely() {
    let d = scratch("data-formats");
    let l = load_str(
        d.path(),
        "offset.dat",
        &ttc_without_slip(&[(30.0, false)], -90.0),
    )
    .unwrap();
    assert!(
        l.report
            .kappa
            .starts_with("κ = 0: no wheel speed or slip channel"),
        "{}",
        l.report.kappa
    );
    assert_eq!(l.report.dropped_total, 0);
    assert!(l.recording.samples.iter().all(|s| s.kappa == 0.0));
}
