//! Round trip of the Magic Formula fit: rig recordings (standard programme:
//! pure lateral and drive/brake sweeps at several loads, cambers and
//! pressures, with the rig's sensor noise and offsets) simulated from real
//! `.tir` files of `../shared/data/tir/`, fitted from a different start (the
//! built-in tyre) → fitted curves within 1 % of the peak force of the truth
//! over the data's range, and identifiable parameters near the truth.
//! Also: the written `.tir` reloads to the same parameters and forces.

use crate::common;

use tyrekit::data::Recording;
use tyrekit::fit::mf_fit::{fit_mf, MfFit, MfFitOptions};
use tyrekit::fit::mf_stages::{StageKind, FIT_MODE};
use tyrekit::mf::{MfInput, Tyre};
use tyrekit::rig::{simulate, RigConfig, SteadyMf};
use tyrekit::tir::TyreParams;

fn rig(truth: &Tyre, seed: u64) -> RigConfig {
    RigConfig::standard(truth, seed)
}

/// Simulate the standard programme from `truth`, write it as a TTC `.mat`,
/// read it back as a user's recording would be.
fn recording(truth: &Tyre, seed: u64, dir: &std::path::Path) -> Recording {
    let cfg = rig(truth, seed);
    let run = simulate(&cfg, &mut SteadyMf::new(truth.clone()));
    let path = dir.join(format!("rig_{seed}.mat"));
    run.write_mat(&path, true).expect("write .mat");
    Recording::from_file(&path).expect("read back the rig recording")
}

/// The built-in tyre with the truth's nominal values (the parameters are
/// relative to FNOMIN/NOMPRES, so comparing them needs the same nominals;
/// the CLI takes them from the data or the `--start` file).
fn start_with_nominals(truth: &TyreParams) -> TyreParams {
    let mut s = TyreParams::builtin();
    for k in ["FNOMIN", "NOMPRES", "INFLPRES", "LONGVL", "UNLOADED_RADIUS"] {
        s.set(k, truth.get(k).unwrap()).unwrap();
    }
    s
}

/// The shared file `file` as truth, its standard programme recorded with
/// `seed` and fitted (stages `only`) from the built-in tyre; None (with a
/// SKIP message) without `../shared`.
fn fit_shared(
    file: &str,
    seed: u64,
    only: Vec<StageKind>,
) -> Option<(TyreParams, Tyre, [Recording; 1], MfFit)> {
    let path = common::shared().join("data/tir").join(file);
    if !path.exists() {
        eprintln!(
            "SKIP: {} absent (shared data not available)",
            path.display()
        );
        return None;
    }
    let truth_p = TyreParams::from_file(&path).unwrap();
    let truth = Tyre::new(truth_p.clone()).unwrap();
    let tmp = common::scratch(&format!("fit-mf-rt-{seed}"));
    let recs = [recording(&truth, seed, tmp.path())];
    let opts = MfFitOptions {
        only,
        nominal_from_data: false,
        ..Default::default()
    };
    let res = fit_mf(&recs, start_with_nominals(&truth_p), &opts, None).unwrap();
    Some((truth_p, truth, recs, res))
}

fn round_trip(file: &str, seed: u64) {
    let only = vec![StageKind::PureFx, StageKind::PureFy];
    let Some((truth_p, truth, recs, res)) = fit_shared(file, seed, only) else {
        return;
    };
    println!("{file}:\n{}", res.report.to_text());
    let fitted = Tyre::new(res.tyre.clone()).unwrap();
    let rec = &recs[0];

    // Curves on a grid inside the data's range (loads, slip) at the nominal
    // pressure and zero camber. Tolerance: 1 % of the truth's peak force at
    // that load (the requirement); the noise (≈ 1 % of peak per
    // sample, averaged over thousands) does not use it up.
    // The data's range: the load set points of the sweeps, and the slip
    // reached in pure lateral (pure longitudinal) segments.
    use tyrekit::data::SegmentKind as K;
    let pure = |k: K| {
        rec.segments
            .iter()
            .filter(move |g| g.kind == k)
            .flat_map(|g| &rec.samples[g.start..g.end])
    };
    let minmax = |it: &mut dyn Iterator<Item = f64>| {
        it.filter(|v| v.is_finite())
            .fold((f64::MAX, f64::MIN), |a, v| (a.0.min(v), a.1.max(v)))
    };
    let (fz0, fz1) = minmax(&mut rec.segments.iter().map(|g| g.fz));
    let (a0, a1) = minmax(&mut pure(K::PureLateral).map(|s| s.alpha));
    let (k0, k1) = minmax(&mut pure(K::PureLongitudinal).map(|s| s.kappa));
    println!("grid: Fz {fz0}..{fz1} N, alpha {a0}..{a1}, kappa {k0}..{k1}");
    // The rig's constant sensor offsets are part of what was measured: a fit
    // cannot tell an α offset from ply steer (PHY1) or a force offset from
    // PVY1/PVX1, so the truth is compared as the rig recorded it: forces
    // + offset at the recorded α = true α + α offset.
    let nz = rig(&truth, seed).noise;
    let truth_rec = |x: &MfInput| {
        let f = truth.forces(
            &MfInput {
                alpha: x.alpha - nz.alpha_offset,
                ..*x
            },
            FIT_MODE,
        );
        (f.fx + nz.fx_offset, f.fy + nz.fy_offset)
    };
    let mut worst = (0.0f64, 0.0f64);
    for i in 0..=6 {
        let fz = fz0 + (fz1 - fz0) * i as f64 / 6.0;
        let base = MfInput {
            fz,
            vx: truth_p.p.longvl.max(5.0),
            p: truth_p.p.nompres,
            ..Default::default()
        };
        let grid = |lo: f64, hi: f64| (0..=40).map(move |j| lo + (hi - lo) * j as f64 / 40.0);
        let peak_y = grid(a0, a1)
            .map(|a| {
                truth
                    .forces(&MfInput { alpha: a, ..base }, FIT_MODE)
                    .fy
                    .abs()
            })
            .fold(0.0, f64::max);
        let peak_x = grid(k0, k1)
            .map(|k| {
                truth
                    .forces(&MfInput { kappa: k, ..base }, FIT_MODE)
                    .fx
                    .abs()
            })
            .fold(0.0, f64::max);
        for a in grid(a0, a1) {
            let x = MfInput { alpha: a, ..base };
            let e = (fitted.forces(&x, FIT_MODE).fy - truth_rec(&x).1).abs();
            worst.1 = worst.1.max(e / peak_y);
        }
        for k in grid(k0, k1) {
            let x = MfInput { kappa: k, ..base };
            let e = (fitted.forces(&x, FIT_MODE).fx - truth_rec(&x).0).abs();
            worst.0 = worst.0.max(e / peak_x);
        }
    }
    println!(
        "{file}: worst |fitted − truth| / peak: Fx {:.3} %, Fy {:.3} %",
        100.0 * worst.0,
        100.0 * worst.1
    );
    // How well the truth itself explains the recorded Fx (with the κ the
    // data layer reconstructs from ω, V and the radii): the fitted model
    // must do at least as well (it is fitted to exactly this) — and when the
    // truth explains the data to better than 1.5 %, the fitted Fx curve must
    // be within 1 % of peak like Fy. (MagicFormula61_Parameters: the
    // recorded κ departs from the truth's κ; see the printed σ.)
    let (mut e_t, mut e_f, mut y2) = (0.0, 0.0, 0.0);
    for s in pure(K::PureLongitudinal) {
        if !(s.fx.is_finite() && s.fz > 0.0) {
            continue;
        }
        let x = MfInput {
            fz: s.fz,
            kappa: s.kappa,
            alpha: s.alpha,
            gamma: s.gamma,
            vx: s.vx,
            p: s.p,
            ..Default::default()
        };
        e_t += (truth_rec(&x).0 - s.fx).powi(2);
        e_f += (fitted.forces(&x, FIT_MODE).fx - s.fx).powi(2);
        y2 += s.fx * s.fx;
    }
    let (s_t, s_f) = ((e_t / y2).sqrt(), (e_f / y2).sqrt());
    println!(
        "{file}: sigma_Fx of the truth {:.2} %, of the fit {:.2} %",
        100.0 * s_t,
        100.0 * s_f
    );
    assert!(
        s_f <= s_t * 1.001,
        "{file}: fit explains Fx worse than the truth"
    );
    if s_t < 0.015 {
        assert!(
            worst.0 < 0.01,
            "{file}: Fx curve off by {:.3} % of peak",
            100.0 * worst.0
        );
    }
    assert!(
        worst.1 < 0.01,
        "{file}: Fy curve off by {:.3} % of peak",
        100.0 * worst.1
    );

    // Identifiable parameters near the truth: the peak friction PDY1 is well
    // determined (2 %); the shape factor PCY1 trades off against the
    // curvature factors E (5 %).
    for (name, tol) in [("pdy1", 0.02), ("pcy1", 0.05)] {
        let (t, f) = (truth_p.get(name).unwrap(), res.tyre.get(name).unwrap());
        println!("{name}: truth {t}, fitted {f}");
        assert!(
            (f - t).abs() <= tol * t.abs(),
            "{file}: {name} fitted {f}, truth {t}"
        );
    }
}

#[test]
fn round_trip_mf61_parameters() {
    round_trip("MagicFormula61_Parameters.tir", 11);
}

#[test]
fn round_trip_reference_tvd3() {
    round_trip("reference_tire_tvd3.tir", 13);
}

#[test]
fn round_trip_pacejka_book() {
    round_trip("PacejkaBook_Defaults.tir", 12);
}

/// A TTC-fitted FSAE tyre (MF 6.1) whose Fx curvature has opposite signs
/// driving and braking (PEX1 0.46, PEX4 −1.17: Ex +0.99 driving, −0.08
/// braking). PEX4 confined to ±0.99 cannot give it, and from a start with
/// the mean curvature negative LM cannot reach it (between the two
/// branches lies PEX1 = 0, where PEX4 is not identified): the fit ended at
/// PEX4 = +3 (its bound) with σ_Fx 1.43 % against the truth's 0.87 % and
/// its Fx curve 3.9 % of the peak off (4 Dec 2026; the diagnosis's
/// control recordings of this tyre then missed the drive-side Fx by 3 %).
/// The flat-top start of `fit::initial` reaches it. Fx only: this file's
/// Fy camber and pressure terms (PEY5 −118, PPY5 −131) are not identified
/// by the rig's one-sided inclinations (0°, 2°, 4°) and its Fy curve is
/// 2 % of the peak off either way.
#[test]
fn round_trip_ttc_hoosier_r25b_fx() {
    let file = "Hoosier-20.5x7x13R25B-ISO.TIR";
    let Some((truth_p, truth, recs, res)) = fit_shared(file, 14, vec![StageKind::PureFx]) else {
        return;
    };
    let fitted = Tyre::new(res.tyre.clone()).unwrap();
    let (pex1, pex4) = (res.tyre.get("pex1").unwrap(), res.tyre.get("pex4").unwrap());
    println!("PEX1 {pex1} (truth 0.458), PEX4 {pex4} (truth −1.173)");
    // The branch: drive-side Ex above 0.5, brake-side below 0.2.
    let ex = |s: f64| pex1 * (1.0 - pex4 * s);
    assert!(
        ex(1.0) > 0.5 && ex(-1.0) < 0.2,
        "Ex {:.3} driving, {:.3} braking: not the file's branch",
        ex(1.0),
        ex(-1.0)
    );
    // Fx within 1 % of the peak over the data's loads and κ ±0.2, upright,
    // nominal pressure, against the truth as the rig recorded it (its
    // constant Fx offset added; κ needs no offset).
    let nz = rig(&truth, 14).noise;
    let (fz0, fz1) = recs[0]
        .segments
        .iter()
        .fold((f64::MAX, f64::MIN), |a, g| (a.0.min(g.fz), a.1.max(g.fz)));
    let mut worst = 0.0f64;
    for i in 0..=6 {
        let base = MfInput {
            fz: fz0 + (fz1 - fz0) * i as f64 / 6.0,
            vx: truth_p.p.longvl.max(5.0),
            p: truth_p.p.nompres,
            ..Default::default()
        };
        let at = |t: &Tyre, k: f64| t.forces(&MfInput { kappa: k, ..base }, FIT_MODE).fx;
        let ks: Vec<f64> = (0..=40).map(|j| -0.2 + 0.4 * j as f64 / 40.0).collect();
        let peak = ks.iter().map(|&k| at(&truth, k).abs()).fold(0.0, f64::max);
        for &k in &ks {
            worst = worst.max((at(&fitted, k) - at(&truth, k) - nz.fx_offset).abs() / peak);
        }
    }
    println!("worst |fitted − truth| / peak: Fx {:.3} %", 100.0 * worst);
    assert!(
        worst < 0.01,
        "Fx curve off by {:.3} % of peak",
        100.0 * worst
    );
}
