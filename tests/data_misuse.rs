//! Fail loudly: the real lateral test `TyreData.csv` given with SAE signs,
//! with the slip angle in degrees under a `[rad]` label, or with no force
//! channel at all, must make `fit`, `diagnose` and `replay` exit non-zero
//! with a message naming the likely cause and the flag that fixes it — and
//! the same SAE file read with `--axes sae` must fit. Runs the binary.
//! Skips (with a message) when ../shared is absent.

use crate::common::scratch;
use std::path::Path;
use std::process::Command;

const TYREDATA: &str = "../shared/data/measurements/TyreData.csv";

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tyrekit"))
}

/// `name` in the test's scratch folder `d`.
fn shared() -> Option<String> {
    match std::fs::read_to_string(TYREDATA) {
        Ok(s) => Some(s),
        Err(_) => {
            eprintln!("SKIP: {TYREDATA} not found (the shared data are not at hand)");
            None
        }
    }
}

/// TyreData with the columns named in `map` transformed.
fn rewrite(text: &str, header: impl Fn(&str) -> String, map: &[(&str, f64)]) -> String {
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let scale: Vec<f64> = head
        .iter()
        .map(|h| {
            map.iter()
                .find(|(n, _)| h.split_whitespace().next() == Some(n))
                .map_or(1.0, |m| m.1)
        })
        .collect();
    let mut out = head.iter().map(|h| header(h)).collect::<Vec<_>>().join(",");
    out.push('\n');
    for l in lines {
        let row: Vec<String> = l
            .split(',')
            .zip(&scale)
            .map(|(v, k)| match v.parse::<f64>() {
                Ok(x) if *k != 1.0 => format!("{}", x * k),
                _ => v.to_string(),
            })
            .collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// SAE signs: Fy, Fz, Mz, α, φt flip (SAE = ISO rotated 180° about x).
fn sae(text: &str) -> String {
    rewrite(
        text,
        |h| h.to_string(),
        &[
            ("Fy", -1.0),
            ("Fz", -1.0),
            ("Mz", -1.0),
            ("SA", -1.0),
            ("Phit", -1.0),
        ],
    )
}

fn run(args: &[&str]) -> (bool, String) {
    let o = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    (o.status.success(), err)
}

fn assert_fails(args: &[&str], needles: &[&str]) {
    let (ok, err) = run(args);
    assert!(!ok, "{args:?} exited 0; stderr: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: stderr lacks '{n}': {err}");
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn sae_signs_read_as_iso_stop_every_command() {
    let d = scratch("misuse");
    let Some(text) = shared() else { return };
    let p = d.path().join("sae.csv");
    std::fs::write(&p, sae(&text)).unwrap();
    let out = d.path().join("sae.tir");
    let rep = d.path().join("sae_report");
    let needles = ["Fz < 0", "--axes sae"];
    assert_fails(&["fit", s(&p), "--out", s(&out), "--only", "fy"], &needles);
    assert!(!out.exists(), "a .tir was written");
    assert_fails(&["diagnose", s(&p), "--report", s(&rep)], &needles);
    assert_fails(
        &[
            "replay",
            s(&p),
            "--tir",
            "src/tir/builtin.tir",
            "--out",
            s(&d.path().join("sae_sim.csv")),
        ],
        &needles,
    );
    assert_fails(&["data", "summary", s(&p)], &needles);
}

#[test]
fn sae_file_with_axes_sae_fits() {
    let d = scratch("misuse");
    let Some(text) = shared() else { return };
    let p = d.path().join("sae_ok.csv");
    std::fs::write(&p, sae(&text)).unwrap();
    let out = d.path().join("sae_ok.tir");
    let (ok, err) = run(&[
        "fit",
        s(&p),
        "--axes",
        "sae",
        "--out",
        s(&out),
        "--only",
        "fy",
    ]);
    assert!(ok, "{err}");
    assert!(out.exists());
}

#[test]
fn degrees_in_a_radian_column_stop_fit_and_diagnose() {
    let d = scratch("misuse");
    let Some(text) = shared() else { return };
    let deg = 180.0 / std::f64::consts::PI;
    let p = d.path().join("deg.csv");
    // SA values in degrees, the header still says [rad].
    std::fs::write(&p, rewrite(&text, |h| h.to_string(), &[("SA", deg)])).unwrap();
    let needles = ["degrees", "alpha", "SA [deg]"];
    let out = d.path().join("deg.tir");
    assert_fails(&["fit", s(&p), "--out", s(&out), "--only", "fy"], &needles);
    assert!(!out.exists());
    assert_fails(
        &[
            "diagnose",
            s(&p),
            "--report",
            s(&d.path().join("deg_report")),
        ],
        &needles,
    );
}

#[test]
fn no_usable_stage_is_an_error_not_a_written_file() {
    let d = scratch("misuse");
    // A recording with load and speed but no force or moment channel: every
    // stage is skipped, so nothing may be written and the exit is non-zero.
    let p = d.path().join("noforce.csv");
    let mut t = String::from("time,Vx,omega,Fz,alpha,gamma\n");
    for i in 0..400 {
        let a = 0.2 * ((i as f64) * 0.05).sin();
        t.push_str(&format!(
            "{},{},{},{},{a},0\n",
            i as f64 * 0.01,
            10.0,
            33.0,
            4000.0
        ));
    }
    std::fs::write(&p, t).unwrap();
    let out = d.path().join("noforce.tir");
    assert_fails(
        &["fit", s(&p), "--out", s(&out)],
        &["no stage had usable data"],
    );
    assert!(!out.exists());
    assert_fails(
        &[
            "diagnose",
            s(&p),
            "--report",
            s(&d.path().join("noforce_report")),
        ],
        &["cannot be analysed"],
    );
}

#[test]
fn a_drive_brake_run_without_any_slip_says_why_no_stage_fits() {
    let d = scratch("misuse");
    // Braking sweeps at 4 kN (|Fx| to 60 % of Fz) with no wheel speed and
    // no slip channel: κ cannot be known and free rolling cannot be
    // assumed. The error must name the missing slip, not only count zero
    // samples in segments that are plainly there.
    let p = d.path().join("noslip.csv");
    let mut t = String::from("time,Vx,Fz,alpha,gamma,Fx,Fy\n");
    for i in 0..2000 {
        let x = ((i as f64) * 0.01).sin();
        t.push_str(&format!(
            "{},10,4000,0,0,{},{}\n",
            i as f64 * 0.01,
            -2400.0 * x,
            30.0 * x
        ));
    }
    std::fs::write(&p, t).unwrap();
    let out = d.path().join("noslip.tir");
    assert_fails(
        &["fit", s(&p), "--out", s(&out)],
        &["no slip ratio κ", "data summary"],
    );
    assert!(!out.exists());
}
