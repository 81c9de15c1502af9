//! The Magic Formula fit on a real flat-belt lateral test
//! (`../shared/data/measurements/TyreData.csv`): pure Fy and Mz from the
//! built-in start, σ_Fy below 5 % (the requirement), the report's
//! plots drawn; and the written `.tir` reloads to the same parameters and
//! forces.

use crate::common;

use tyrekit::data::Recording;
use tyrekit::fit::mf_fit::{fit_mf, overall_sigma, MfFitOptions};
use tyrekit::fit::mf_stages::{StageKind, FIT_MODE};
use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::tir::TyreParams;

#[test]
fn tyredata_fy_mz_fit_and_tir_reload() {
    let path = common::shared().join("data/measurements/TyreData.csv");
    if !path.exists() {
        eprintln!(
            "SKIP: {} absent (shared data not available)",
            path.display()
        );
        return;
    }
    let recs = [Recording::from_file(&path).unwrap()];
    let opts = MfFitOptions {
        only: vec![StageKind::PureFy, StageKind::Mz],
        ..Default::default()
    };
    let res = fit_mf(&recs, TyreParams::builtin(), &opts, None).unwrap();
    println!("{}", res.report.to_text());
    let s_fy = overall_sigma(&res.report.metrics, "Fy").unwrap();
    let s_mz = overall_sigma(&res.report.metrics, "Mz").unwrap();
    println!("sigma Fy {:.2} %, Mz {:.2} %", 100.0 * s_fy, 100.0 * s_mz);
    assert!(s_fy < 0.05, "σ_Fy = {:.2} % (must be < 5 %)", 100.0 * s_fy);
    // Mz: no requirement in the issue; it must at least beat the start tyre
    // by a wide margin (a broken Mz stage would not).
    assert!(s_mz < 0.35, "σ_Mz = {:.2} %", 100.0 * s_mz);
    // Nominal values came from the data: FNOMIN inside the tested loads.
    let fnom = res.tyre.p.fnomin;
    let loads: Vec<f64> = recs[0].segments.iter().map(|s| s.fz).collect();
    let (lo, hi) = loads
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &f| (a.0.min(f), a.1.max(f)));
    assert!(
        fnom >= lo && fnom <= hi,
        "FNOMIN {fnom} outside the loads [{lo}, {hi}]"
    );

    // Report plots.
    let tmp = common::scratch("fit-mf-td");
    let dir = tmp.path();
    let fitted = Tyre::new(res.tyre.clone()).unwrap();
    let plots = tyrekit::fit::plot::plot_fit(&fitted, &recs[0], &opts.only, dir).unwrap();
    assert!(
        plots.len() >= 2,
        "expected plots of Fy and Mz per condition"
    );
    let svg = std::fs::read_to_string(&plots[0]).unwrap();
    assert!(svg.contains("<svg") && svg.contains("polyline") || svg.contains("<path"));

    // The written .tir reloads bit-exactly and evaluates the same forces.
    let text = res.tyre.to_tir_string();
    let back = TyreParams::from_tir_str(&text, "fitted.tir").unwrap();
    let (a, b) = (res.tyre.p.as_slice(), back.p.as_slice());
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
            "key {} : written {x:e}, read back {y:e}",
            tyrekit::tir::keys::KEYS[i].name
        );
    }
    let t2 = Tyre::new(back).unwrap();
    for (fz, alpha, gamma) in [
        (3000.0, 0.05, 0.0),
        (6000.0, -0.15, 0.03),
        (1200.0, 0.2, 0.06),
    ] {
        let x = MfInput {
            fz,
            alpha,
            gamma,
            vx: 15.0,
            ..Default::default()
        };
        for mode in [FIT_MODE, UseMode::default()] {
            assert_eq!(fitted.forces(&x, mode), t2.forces(&x, mode));
        }
    }
}

/// The same real test with its wheel-speed, effective-radius and slip-ratio
/// columns removed — the form many shared lateral tests take — loads with
/// κ = 0 (it rolls freely) and fits pure Fy as well as the full file:
/// before, κ stayed NaN and no stage had a usable sample. The full file
/// records SR = 0 throughout, so the two fits see the same slips; 5 % of σ
/// leaves room for the segmenter's and the geometry's use of the removed
/// columns, nothing more.
#[test]
fn tyredata_without_wheel_speed_fits_as_free_rolling() {
    let path = common::shared().join("data/measurements/TyreData.csv");
    let Ok(text) = std::fs::read_to_string(&path) else {
        eprintln!(
            "SKIP: {} absent (shared data not available)",
            path.display()
        );
        return;
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !["W [rad/s]", "Re [m]", "SR [-]"].contains(&header[i].trim()))
        .collect();
    assert_eq!(
        keep.len(),
        header.len() - 3,
        "columns not found: {header:?}"
    );
    let pick = |l: &str| {
        let f: Vec<&str> = l.split(',').collect();
        keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join(",")
    };
    let mut cut = pick(&header.join(","));
    for l in lines {
        cut.push('\n');
        cut.push_str(&pick(l));
    }
    let tmp = common::scratch("fit-mf-td-now");
    let p = tmp.path().join("TyreData_no_wheel_speed.csv");
    std::fs::write(&p, cut).unwrap();
    let loaded = tyrekit::data::load(&p, &tyrekit::data::LoadOptions::default()).unwrap();
    assert!(
        loaded
            .report
            .kappa
            .starts_with("κ = 0: no wheel speed or slip channel"),
        "{}",
        loaded.report.kappa
    );
    let opts = MfFitOptions {
        only: vec![StageKind::PureFy],
        ..Default::default()
    };
    let sigma_fy = |rec: Recording| {
        let res = fit_mf(&[rec], TyreParams::builtin(), &opts, None).unwrap();
        overall_sigma(&res.report.metrics, "Fy").unwrap()
    };
    let without = sigma_fy(loaded.recording);
    let full = sigma_fy(Recording::from_file(&path).unwrap());
    println!(
        "σ_Fy without wheel speed {:.3} %, full file {:.3} %",
        100.0 * without,
        100.0 * full
    );
    assert!(
        without < 1.05 * full,
        "σ_Fy {without} without wheel speed against {full}"
    );
}
