//! `tyrekit replay` and `tyrekit diagnose` from the command line: the replay
//! CSV's columns exactly, every output of diagnose (diagnosis.json with the
//! issue's keys, report.html, baseline.tir, extended.tir), extended.tir
//! loading in the library and replaying, and clear errors (exit code 1, a
//! message naming the flag or file, no panic) on bad flags and files.

use crate::common::scratch;
use std::path::Path;
use std::process::{Command, Output};
use tyrekit::mf::Tyre;
use tyrekit::rig::{effects, simulate, RigConfig};

fn tyrekit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A clean failure: exit code 1, the message names `needle`, no panic.
fn fails_clearly(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(needle), "'{needle}' not in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn replay_and_diagnose_commands() {
    let tmp = scratch("diag-cli");
    let dir = tmp.path();
    let tyre = Tyre::builtin();
    let tir = dir.join("base.tir");
    tyre.params().write(&tir).unwrap();
    let mut cfg = RigConfig::standard(&tyre, 2);
    cfg.programme.pressures.truncate(1);
    cfg.programme.inclinations.truncate(1);
    cfg.programme.loads.truncate(2);
    cfg.programme.db_alphas.truncate(1);
    let mut m = effects::concealed("relaxation", tyre.clone(), 1.5).unwrap();
    let rec = dir.join("rig.mat");
    simulate(&cfg, m.as_mut()).write_mat(&rec, true).unwrap();

    // replay: the rig records Mx but not My, so exactly these columns.
    let out = dir.join("sim.csv");
    let o = tyrekit(&["replay", s(&rec), "--tir", s(&tir), "--out", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let header = text.lines().next().unwrap();
    assert_eq!(header, "time,Fx,Fy,Mz,Fx_sim,Fy_sim,Mz_sim,Mx,Mx_sim");
    // Every row has as many fields as the header, and the recording's rows.
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert!(rows.len() > 1000);
    assert!(rows.iter().all(|r| r.split(',').count() == 9));

    // A recording without Mx/My (CSV with the base columns only): exactly
    // the seven columns.
    let csv = dir.join("small.csv");
    let mut c = String::from("time,Vx,omega,Fz,kappa,alpha,gamma,phit,P,Fx,Fy,Mz\n");
    for i in 0..200 {
        let a = 0.1 * ((i as f64) * 0.05).sin();
        c.push_str(&format!(
            "{},10,33,4000,0,{a},0,0,220000,0,{},{}\n",
            i as f64 * 0.01,
            -40000.0 * a,
            500.0 * a
        ));
    }
    std::fs::write(&csv, c).unwrap();
    let o = tyrekit(&["replay", s(&csv), "--tir", s(&tir), "--out", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("time,Fx,Fy,Mz,Fx_sim,Fy_sim,Mz_sim\n"),
        "{}",
        &text[..60]
    );

    // Bad flags and files: exit code 1, a message naming them, no panic.
    fails_clearly(
        &tyrekit(&[
            "replay",
            s(&rec),
            "--tir",
            s(&tir),
            "--out",
            s(&out),
            "--transient",
            "magic",
        ]),
        "--transient magic",
    );
    let missing = dir.join("nope.mat");
    fails_clearly(
        &tyrekit(&["replay", s(&missing), "--tir", s(&tir), "--out", s(&out)]),
        "nope.mat",
    );
    let rep = dir.join("report");
    fails_clearly(
        &tyrekit(&["diagnose", s(&missing), "--report", s(&rep)]),
        "nope.mat",
    );
    fails_clearly(
        &tyrekit(&[
            "diagnose",
            s(&rec),
            "--report",
            s(&rep),
            "--tir",
            s(&dir.join("nope.tir")),
        ]),
        "nope.tir",
    );
    let bad_tir = dir.join("bad.tir");
    std::fs::write(
        &bad_tir,
        "[MODEL]\nFITTYP = 61\n[VERTICAL]\nFNOMIN = 4.0.0\n",
    )
    .unwrap();
    fails_clearly(
        &tyrekit(&[
            "diagnose",
            s(&rec),
            "--report",
            s(&rep),
            "--tir",
            s(&bad_tir),
        ]),
        "FNOMIN",
    );
    let o = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(["diagnose", s(&rec), "--report", s(&rep), "--bogus"])
        .output()
        .unwrap();
    assert_ne!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--bogus"));

    // diagnose with the true tyre as baseline: every output, the issue's
    // keys. (Which effect it names is the proof tests' business,
    // tests/diagnose_proof.rs; here the outputs must agree with each other.)
    let o = tyrekit(&["diagnose", s(&rec), "--tir", s(&tir), "--report", s(&rep)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("diagnosis.json")).unwrap())
            .unwrap();
    let verdict = j["verdict"].as_str().unwrap().to_string();
    assert!(stdout.contains(&format!("verdict: {verdict}")), "{stdout}");
    assert!(j["explanation"].as_str().unwrap().len() > 40);
    let effects = j["effects"].as_array().unwrap();
    assert_eq!(effects[0]["name"], verdict.as_str(), "verdict first");
    for e in effects {
        for k in [
            "name",
            "score",
            "evidence",
            "parameters",
            "nrmse_before",
            "nrmse_after",
        ] {
            assert!(!e[k].is_null(), "{k}");
        }
        for c in ["FX", "FY", "MZ"] {
            assert!(e["nrmse_before"][c].is_number(), "{c}");
            assert!(e["nrmse_after"][c].is_number(), "{c}");
        }
    }
    for f in ["report.html", "baseline.tir", "extended.tir"] {
        assert!(rep.join(f).is_file(), "{f}");
    }
    // extended.tir loads in the library, differs from the baseline when an
    // effect is named, and replays from the command line.
    let ext = Tyre::from_file(&rep.join("extended.tir")).unwrap();
    let base = Tyre::from_file(&rep.join("baseline.tir")).unwrap();
    assert_eq!(
        ext.params().to_tir_string() != base.params().to_tir_string(),
        verdict != "none",
        "extended.tir vs baseline.tir for verdict {verdict}"
    );
    let o = tyrekit(&[
        "replay",
        s(&rec),
        "--tir",
        s(&rep.join("extended.tir")),
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
