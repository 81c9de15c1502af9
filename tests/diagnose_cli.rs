//! `tyrekit replay` and `tyrekit diagnose` from the command line.

use std::process::Command;
use tyrekit::mf::Tyre;
use tyrekit::rig::{effects, simulate, RigConfig};

#[test]
fn replay_and_diagnose_commands() {
    let dir = std::env::temp_dir().join(format!("tyrekit-diag-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
    let exe = env!("CARGO_BIN_EXE_tyrekit");

    let out = dir.join("sim.csv");
    let st = Command::new(exe)
        .args([
            "replay",
            rec.to_str().unwrap(),
            "--tir",
            tir.to_str().unwrap(),
        ])
        .args(["--out", out.to_str().unwrap(), "--transient", "relaxation"])
        .status()
        .unwrap();
    assert!(st.success());
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("time,Fx,Fy,Mz,Fx_sim,Fy_sim,Mz_sim,Mx,Mx_sim\n"),
        "{}",
        &text[..80]
    );

    // A bad flag is an error with a message, not a panic.
    let o = Command::new(exe)
        .args([
            "replay",
            rec.to_str().unwrap(),
            "--tir",
            tir.to_str().unwrap(),
        ])
        .args(["--out", out.to_str().unwrap(), "--transient", "magic"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--transient magic"));

    let rep = dir.join("report");
    let st = Command::new(exe)
        .args([
            "diagnose",
            rec.to_str().unwrap(),
            "--tir",
            tir.to_str().unwrap(),
        ])
        .args(["--report", rep.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(st.success());
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("diagnosis.json")).unwrap())
            .unwrap();
    assert_eq!(j["verdict"], "relaxation");
    assert_eq!(j["effects"][0]["name"], "relaxation");
    for k in ["FX", "FY", "MZ"] {
        assert!(j["effects"][0]["nrmse_before"][k].is_number(), "{k}");
    }
    let before = j["effects"][0]["nrmse_before"]["FY"].as_f64().unwrap();
    let after = j["effects"][0]["nrmse_after"]["FY"].as_f64().unwrap();
    assert!(after < before, "FY nrmse {before} -> {after}");
    // extended.tir loads and differs from the baseline in the relaxation keys.
    let ext = Tyre::from_file(&rep.join("extended.tir")).unwrap();
    assert_ne!(
        ext.params().p.lateral_stiffness,
        tyre.params().p.lateral_stiffness
    );
    assert!(rep.join("baseline.tir").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
