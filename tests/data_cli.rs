//! `tyrekit data summary | convert | plot` end to end on a rig recording.

use crate::common::scratch;
use std::process::Command;
use tyrekit::mf::Tyre;
use tyrekit::rig::{simulate, RigConfig, SteadyMf};

fn tyrekit(args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

#[test]
fn summary_convert_plot() {
    let tmp = scratch("data-cli");
    let d = tmp.path();
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 4);
    cfg.decimate = 4;
    let r = simulate(&cfg, &mut SteadyMf::new(tyre));
    let dat = d.join("run.dat");
    r.write_dat(&dat).unwrap();
    let dat_s = dat.to_str().unwrap();

    let (ok, out, err) = tyrekit(&["data", "summary", dat_s, "--signs"]);
    assert!(ok, "{err}");
    assert!(out.contains("test matrix: 90 segments"), "{out}");
    assert!(
        out.contains("45 pure lateral, 15 pure longitudinal, 30 combined"),
        "{out}"
    );
    assert!(out.contains("warm-up removed:") && !out.contains("warm-up removed: none"));
    assert!(out.contains("missing:  phit My"));
    assert!(out.contains("| Fy | −1 (flip)"));

    let (ok, out, _) = tyrekit(&["data", "summary", dat_s, "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v[0]["segments"].as_array().unwrap().len(), 90);

    let csv = d.join("clean.csv");
    let (ok, _, err) = tyrekit(&[
        "data",
        "convert",
        dat_s,
        "--to",
        "csv",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("time,Vx,omega,Fz,kappa,alpha,gamma,P,Fx,Fy,Mx,Mz,"));
    // The clean CSV summarises to the same matrix (no second warm-up cut).
    let (ok, out, _) = tyrekit(&["data", "summary", csv.to_str().unwrap()]);
    assert!(
        ok && out.contains("test matrix: 90 segments") && out.contains("warm-up removed: none"),
        "{out}"
    );

    let tdx = d.join("clean.tdx");
    let (ok, _, _) = tyrekit(&[
        "data",
        "convert",
        dat_s,
        "--to",
        "tdx",
        "--out",
        tdx.to_str().unwrap(),
    ]);
    assert!(
        ok && std::fs::read_to_string(&tdx)
            .unwrap()
            .starts_with("**HEADER")
    );

    let plots = d.join("plots");
    let (ok, out, err) = tyrekit(&["data", "plot", dat_s, "--out", plots.to_str().unwrap()]);
    assert!(ok, "{err}");
    // Time traces + Fy(α), Mz(α) for 9 (P, γ) groups + Fx(κ) for 9 (P, α) groups.
    assert_eq!(out.lines().count(), 1 + 18 + 9, "{out}");
    let svg = std::fs::read_to_string(plots.join("channels_time.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("<text"));

    // Bad arguments: clear errors, non-zero exit.
    let (ok, _, err) = tyrekit(&["data", "convert", dat_s, "--to", "xls", "--out", "x"]);
    assert!(!ok && err.contains("expected csv or tdx"));
    let (ok, _, err) = tyrekit(&["data", "summary", dat_s, "--axes", "nasa"]);
    assert!(!ok && err.contains("--axes"));
}
