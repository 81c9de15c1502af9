//! The tyre's own geometry: the radii fitted from a recording (no force
//! stage, so this checks the geometry alone) reproduce the recorded effective
//! rolling radius Re = V/Ω of every free-rolling sample within 1 %, evaluated
//! from the written-and-read-back file as the FMU does (use mode 111, Ω
//! given); the keys the data cannot determine are marked in the file. On the
//! real lateral test TyreData.csv and on dev-set recordings (one speed and
//! several speeds). Skips (with a message) when ../shared is absent.

use std::path::Path;
use tyrekit::data::{load, LoadOptions, Recording};
use tyrekit::fit::mf_fit::{fit_mf, MfFitOptions};
use tyrekit::mf::{MfInput, Tyre, UseMode};
use tyrekit::tir::TyreParams;

fn rec(path: &str) -> Option<Recording> {
    if !Path::new(path).exists() {
        eprintln!("SKIP: {path} not found (the shared data are not at hand)");
        return None;
    }
    Some(
        load(Path::new(path), &LoadOptions::default())
            .unwrap()
            .recording,
    )
}

/// Fit only the geometry (no force stage) and return the file as read back.
fn geometry_only(r: &Recording) -> (TyreParams, String) {
    let opts = MfFitOptions {
        only: vec![],
        geometry: true,
        ..Default::default()
    };
    let fit = fit_mf(std::slice::from_ref(r), TyreParams::builtin(), &opts, None).unwrap();
    let text = fit.tyre.to_tir_string();
    (TyreParams::from_tir_str(&text, "fitted").unwrap(), text)
}

/// Free rolling as the test defines it, independently of the fitter: |α| <
/// 1°, loaded, and no drive/brake torque — |SR| < 0.3 % where a slip ratio
/// is recorded (TTC: V/Ω differs from Re by SR itself, so this bounds the
/// part of the error that is the sample's own slip), else |Fx| < 5 % Fz;
/// in a programme without drive/brake runs (`lateral_only`) every sample:
/// nothing drives the wheel, whatever Fx the rolling resistance gives.
fn free_rolling(r: &Recording, lateral_only: bool) -> Vec<(f64, f64, f64, f64)> {
    let re = r.extra("Re").expect("a recorded Re");
    let sr = r.extra("SR");
    let fmax = r.samples.iter().map(|s| s.fz).fold(0.0, f64::max);
    r.samples
        .iter()
        .enumerate()
        .filter(|(i, s)| {
            let free = lateral_only
                || match sr {
                    Some(v) => v[*i].abs() < 0.003,
                    None => s.fx.abs() < 0.05 * s.fz,
                };
            s.alpha.abs() < 1f64.to_radians() && s.fz > 0.1 * fmax && free && re[*i].is_finite()
        })
        .map(|(i, s)| (s.fz, s.omega, s.p, re[i]))
        .collect()
}

fn check_re(path: &str, lateral_only: bool) {
    let Some(r) = rec(path) else { return };
    let (t, text) = geometry_only(&r);
    let tyre = Tyre::new(t).unwrap();
    let free = free_rolling(&r, lateral_only);
    assert!(
        free.len() > 100,
        "{path}: {} free-rolling samples",
        free.len()
    );
    let mut worst = 0.0f64;
    for &(fz, omega, p, re) in &free {
        let o = tyre.evaluate(
            &MfInput {
                fz,
                omega,
                p,
                vx: omega * re,
                ..Default::default()
            },
            UseMode::default(),
        );
        worst = worst.max(((o.re - re) / re).abs());
    }
    println!(
        "{path}: {} free-rolling samples, largest |Re error| {:.3} %",
        free.len(),
        100.0 * worst
    );
    // The acceptance bound of the issue: 1 %.
    assert!(worst < 0.01, "{path}: Re off by {:.2} %", 100.0 * worst);
    // What the data cannot determine is marked on its line.
    for k in ["WIDTH", "MASS", "RIM_RADIUS"] {
        // The last such line: [UNITS] has a MASS line of its own.
        let line = text
            .lines()
            .rfind(|l| l.starts_with(k) && l[k.len()..].trim_start().starts_with('='))
            .unwrap();
        assert!(line.contains("$ NOT DETERMINED"), "{line}");
    }
    // The built-in tyre's radius is gone: R0 is this tyre's (between the
    // largest recorded Re and 1.1 × it).
    let r0 = tyre.params().p.unloaded_radius;
    let re_max = free.iter().map(|f| f.3).fold(0.0, f64::max);
    assert!(
        r0 >= 0.995 * re_max && r0 < 1.1 * re_max,
        "R0 {r0} vs Re ≤ {re_max}"
    );
}

#[test]
fn tyredata_radii() {
    check_re("../shared/data/measurements/TyreData.csv", false);
}

#[test]
fn dev_set_radii_one_speed() {
    check_re("../shared/data/diagnose-dev/r15.dat.gz", false);
}

#[test]
fn dev_set_radii_several_speeds() {
    check_re("../shared/data/diagnose-dev/r08.dat.gz", false);
}

/// A lateral-only programme of a tyre with a large rolling resistance
/// (free-rolling Fx ≈ −10 % Fz, |SR| ≈ 0.5 %): neither |SR| < 0.3 % nor
/// |Fx| < 5 % Fz finds free rolling there, yet no torque drives the wheel —
/// the radii must still come from the data (they once stayed the built-in
/// tyre's 0.3135 m on such a recording, and the replay with the wheel speed
/// then gave κ ≈ 0.5 and Fx = +1000 N against a measured −150 N).
#[test]
fn dev_set_radii_lateral_only_with_rolling_resistance() {
    check_re("../shared/data/diagnose-dev/r03.dat.gz", true);
}

/// The radius the rig's slip ratio was computed with, RE·(1 + SR) (RE = V/Ω),
/// against the fitted file's Re, averaged per load level and belt speed over
/// the free-rolling samples: no systematic departure beyond what a slip
/// error may carry (2·10⁻⁴: 0.4 % of Fz of Fx at a slip stiffness of 20·Fz)
/// plus 3.5 standard errors of the group's mean (the samples carry the
/// speed channels' noise; 3.5: a family-wise 1 % over the ≈ 15 groups of a
/// recording, Bonferroni). Before 29 Nov the dev set's speed
/// programme r08 got a growth with speed from the tie of Rω to the loaded
/// radius (+0.14 % at 48 km/h, −0.08 % at 32) and a tied Re 0.07 % off at
/// the outer loads.
fn check_re_bias(path: &str) {
    check_re_bias_thinned(path, 1, true);
}

/// [`check_re_bias`] with the geometry fitted to every `stride`-th sample
/// (as `diagnose` thins a long recording for its baseline) and checked on
/// all of them, grouped by load level and, with `by_speed`, belt speed.
fn check_re_bias_thinned(path: &str, stride: usize, by_speed: bool) {
    let Some(r) = rec(path) else { return };
    let (t, _) = geometry_only(&tyrekit::diagnose::baseline::decimate(&r, stride));
    let tyre = Tyre::new(t).unwrap();
    let sr = r.extra("SR").expect("a recorded SR");
    let re = r.extra("Re").expect("a recorded Re");
    let fmax = r.samples.iter().map(|s| s.fz).fold(0.0, f64::max);
    let mut groups = std::collections::BTreeMap::<(i64, i64), Vec<f64>>::new();
    for (i, s) in r.samples.iter().enumerate() {
        if !(s.alpha.abs() < 1f64.to_radians() && s.fz > 0.1 * fmax && sr[i].abs() < 0.003) {
            continue;
        }
        let rig = re[i] * (1.0 + sr[i]);
        let o = tyre.evaluate(
            &MfInput {
                fz: s.fz,
                omega: s.omega,
                p: s.p,
                vx: s.vx,
                ..Default::default()
            },
            UseMode::default(),
        );
        let key = (
            (s.fz / (0.05 * fmax)).round() as i64,
            if by_speed {
                (3.6 * s.vx / 4.0).round() as i64
            } else {
                0
            },
        );
        groups.entry(key).or_default().push(o.re / rig - 1.0);
    }
    let (mut checked, mut off) = (0, Vec::new());
    for ((load, speed), e) in &groups {
        if e.len() < 20 {
            continue;
        }
        let n = e.len() as f64;
        let mean = e.iter().sum::<f64>() / n;
        let sd = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let tol = 2e-4 + 3.5 * sd / n.sqrt();
        let speed = if by_speed {
            format!("{} km/h", 4 * speed)
        } else {
            "all speeds".to_string()
        };
        println!(
            "{path}: load {:.0} %, {speed}: {} samples, Re bias {:+.4} % (tolerance {:.4} %)",
            5 * load,
            e.len(),
            100.0 * mean,
            100.0 * tol
        );
        if mean.abs() >= tol {
            off.push(format!(
                "{:+.4} % at {:.0} % load, {speed}",
                100.0 * mean,
                5 * load,
            ));
        }
        checked += 1;
    }
    assert!(
        checked >= 6,
        "{path}: {checked} groups of free-rolling samples"
    );
    assert!(
        off.is_empty(),
        "{path}: the file's Re is off the rig's radius: {off:?}"
    );
}

#[test]
fn dev_set_radius_is_unbiased_by_load_and_speed() {
    check_re_bias("../shared/data/diagnose-dev/r08.dat.gz");
    check_re_bias("../shared/data/diagnose-dev/r17.dat.gz");
}

/// Dev-set r07: a rig whose slip ratio was computed with one radius at
/// every load (197.5 mm; the tyre's own V/Ω falls from 200.3 to 198.0 mm).
/// Fitted on every sample, or every 3rd or 5th (the stride `diagnose`
/// thins this recording by is 3), the file's Re follows that constant
/// radius. Until 1 Dec the thinned fits found no Re(Fz) with non-negative
/// deflection terms (the flat radius's unconstrained terms came out
/// negative), took the loaded radius's tie unchecked — Re 2 % above the
/// rig's at low load — and the diagnosis's baseline.tir replayed the
/// drive/brake runs' Fx 2.6× worse than the answers' least-squares
/// baseline (NRMSE 0.0175 against 0.0067). Grouped by load only: the
/// question is Re(Fz), and r07's groups per belt speed hold ~30 samples
/// each whose rig radius itself scatters by up to 0.07 % (15 % load: 197.57
/// mm at 32 km/h, 197.45 and 197.43 mm at 40 and 48), beyond the standard
/// error those correlated 100 Hz samples suggest; the speed test is r08's
/// and r17's above.
#[test]
fn dev_set_radius_is_fitted_whatever_the_thinning() {
    for stride in [1, 3, 5] {
        check_re_bias_thinned("../shared/data/diagnose-dev/r07.dat.gz", stride, false);
    }
}
