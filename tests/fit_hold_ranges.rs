//! Two completeness items of the Magic Formula fit (issue 6):
//! - the written tyre's validity ranges (PRESMIN/PRESMAX, FZMAX, ALPMIN/MAX,
//!   KPUMIN/MAX, CAMMIN/MAX) cover the fitted data, so the FMU's limit
//!   checks (use modes 1xx) do not clip the conditions the tyre was fitted
//!   on;
//! - the hold list (`FitOptions::hold`, `tyrekit fit --hold`) keeps the
//!   named coefficients at their start values, and an unknown key is an
//!   error naming it.
//!
//! Data: the rig's standard programme (pressures 0.85/1/1.15 × NOMPRES,
//! loads 0.5–1.5 × FNOMIN, cambers 0–4°) from the built-in tyre at a low
//! sample rate (a few seconds of fitting in release).

use crate::common::scratch;
use std::path::{Path, PathBuf};
use tyrekit::data::Recording;
use tyrekit::fit::mf_fit::{fit_mf, MfFitOptions};
use tyrekit::fit::mf_stages::{StageKind, FIT_MODE};
use tyrekit::fit::ParamStatus;
use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::rig::{simulate, RigConfig, SteadyMf};
use tyrekit::tir::TyreParams;

/// The rig recording written to `DIR/rig.mat` (DIR the test's scratch folder).
fn rig_file(dir: &Path) -> PathBuf {
    let truth = Tyre::builtin();
    let mut cfg = RigConfig::standard(&truth, 5);
    cfg.sample_rate = 40.0;
    let run = simulate(&cfg, &mut SteadyMf::new(truth));
    let path = dir.join("rig.mat");
    run.write_mat(&path, false).unwrap();
    path
}

/// The rig recording, read back whole (its folder ends with this call).
fn recording(tag: &str) -> Recording {
    let d = scratch(&format!("fit-hold-{tag}"));
    Recording::from_file(&rig_file(d.path())).unwrap()
}

fn opts(only: Vec<StageKind>) -> MfFitOptions {
    MfFitOptions {
        only,
        nominal_from_data: false,
        ..Default::default()
    }
}

fn span(rec: &Recording, f: fn(&tyrekit::data::Sample) -> f64) -> (f64, f64) {
    rec.samples
        .iter()
        .map(f)
        .filter(|v| v.is_finite())
        .fold((f64::MAX, f64::MIN), |a, v| (a.0.min(v), a.1.max(v)))
}

#[test]
fn fitted_tyre_ranges_cover_the_data() {
    let rec = recording("ranges");
    let mut start = TyreParams::builtin();
    let pn = start.get("NOMPRES").unwrap();
    // A start file valid only near nominal pressure, load and small slip.
    start.set("PRESMIN", 0.95 * pn).unwrap();
    start.set("PRESMAX", 1.05 * pn).unwrap();
    start.set("FZMAX", start.get("FNOMIN").unwrap()).unwrap();
    start.set("ALPMIN", -0.05).unwrap();
    start.set("ALPMAX", 0.05).unwrap();
    start.set("CAMMIN", -0.01).unwrap();
    start.set("CAMMAX", 0.01).unwrap();
    let fit = fit_mf(
        std::slice::from_ref(&rec),
        start.clone(),
        &opts(vec![StageKind::PureFy]),
        None,
    )
    .unwrap();
    let t = &fit.tyre;
    for (lo, hi, f) in [
        (
            "PRESMIN",
            "PRESMAX",
            (|s| s.p) as fn(&tyrekit::data::Sample) -> f64,
        ),
        ("ALPMIN", "ALPMAX", |s| s.alpha),
        ("CAMMIN", "CAMMAX", |s| s.gamma),
    ] {
        let (a, b) = span(&rec, f);
        assert!(
            t.get(lo).unwrap() <= a && t.get(hi).unwrap() >= b,
            "{lo}/{hi} = {}/{} do not cover the data's {a}..{b}",
            t.get(lo).unwrap(),
            t.get(hi).unwrap()
        );
    }
    let (_, fz_hi) = span(&rec, |s| s.fz);
    assert!(t.get("FZMAX").unwrap() >= fz_hi);
    // The data's pressures span 0.85–1.15 × NOMPRES (± sensor noise).
    assert!(t.get("PRESMIN").unwrap() < 0.85 * pn && t.get("PRESMAX").unwrap() > 1.15 * pn);
    // A limit the data lie inside is kept (FZMIN is never lowered).
    assert_eq!(t.get("FZMIN"), start.get("FZMIN"));
    // Written and reloaded, the fitted tyre with the limit checks on (use
    // mode 1xx, as the FMU runs) gives the same Fy at the lowest pressure
    // as without them: the pressure is no longer clipped. (With the start
    // file's PRESMIN it would be evaluated at 0.95 × NOMPRES instead.)
    let d = scratch("fit-hold-tir");
    let path = d.path().join("fitted.tir");
    t.write(&path).unwrap();
    let tyre = Tyre::from_file(&path).unwrap();
    let x = MfInput {
        fz: t.get("FNOMIN").unwrap(),
        alpha: 0.04,
        p: 0.86 * pn,
        vx: 10.0,
        ..Default::default()
    };
    let limited = UseMode {
        limits: true,
        ..FIT_MODE
    };
    let (a, b) = (tyre.forces(&x, limited).fy, tyre.forces(&x, FIT_MODE).fy);
    assert!((a - b).abs() <= 1e-9 * b.abs(), "{a} vs {b}");
}

#[test]
fn held_coefficients_keep_their_start_values() {
    let rec = recording("hold");
    let start = TyreParams::builtin();
    let mut o = opts(vec![StageKind::PureFy]);
    o.fit.hold = vec!["PDY1".into(), "pky1".into()];
    let fit = fit_mf(std::slice::from_ref(&rec), start.clone(), &o, None).unwrap();
    let stage = &fit.report.stages[0];
    for k in ["pdy1", "pky1"] {
        let p = stage.param(k).unwrap();
        assert_eq!(p.status, ParamStatus::Fixed, "{k}");
        assert_eq!(p.value, p.start, "{k}");
        assert_eq!(fit.tyre.get(k), start.get(k), "{k}");
    }
    // The others are fitted (the rig data are the built-in tyre plus noise
    // and offsets, so at least PCY1 moves off its start).
    let p = stage.param("pcy1").unwrap();
    assert!(matches!(
        p.status,
        ParamStatus::Fitted | ParamStatus::AtBound
    ));
    assert_ne!(p.value, p.start);
}

#[test]
fn unknown_hold_key_is_an_error_naming_it() {
    let rec = recording("unknown");
    for (key, why) in [("PDY99", "not a .tir key"), ("FNOMIN", "no fit stage fits")] {
        let mut o = opts(vec![StageKind::PureFy]);
        o.fit.hold = vec!["pdy1".into(), key.into()];
        let e = fit_mf(std::slice::from_ref(&rec), TyreParams::builtin(), &o, None)
            .err()
            .unwrap_or_else(|| panic!("hold {key} accepted"))
            .to_string();
        assert!(e.contains(key) && e.contains(why), "{e}");
    }
}

/// `tyrekit fit --hold`: the written tyre keeps the held keys' start values;
/// an unknown key fails the command with a message naming it.
#[test]
fn cli_hold_option() {
    let tmp = scratch("fit-hold-cli");
    let dir = tmp.path();
    let rec = rig_file(dir);
    let out = dir.join("fitted.tir");
    let run = |hold: &str| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_tyrekit"))
            .args(["fit", rec.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .args(["--only", "fy", "--hold", hold])
            .output()
            .unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stderr).to_string(),
        )
    };
    let (ok, err) = run("PDY1,PKY1");
    assert!(ok, "{err}");
    let fitted = TyreParams::from_file(&out).unwrap();
    let start = TyreParams::builtin();
    for k in ["PDY1", "PKY1"] {
        assert_eq!(fitted.get(k), start.get(k), "{k}");
    }
    assert_ne!(fitted.get("PCY1"), start.get("PCY1"));
    let (ok, err) = run("PDY1,PXY7");
    assert!(!ok && err.contains("PXY7"), "{err}");
}
