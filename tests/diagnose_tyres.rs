//! The diagnosis's own baseline on tyres other than the dev set's: rig
//! control recordings (no concealed effect; sensor noise, offsets and
//! scatter only) from real files of `../shared/data/tir/` — MFeval's FSAE
//! default tyre, a PAC2002 car tyre, a 22.5" truck tyre at 21.7 kN, an
//! MF 5.2 car tyre, the two 35 kN PAC2002 tyres, MF 6.2's example car tyre
//! and a TTC-fitted MF 6.1 FSAE tyre (the last two: MF 6.x files the
//! dev set's generator did not use, as the hidden recordings' tyres may
//! be) —, each diagnosed as a user runs it
//! (`tyrekit diagnose REC.mat --report DIR`, no `--tir`).
//!
//! Asserted per tyre: verdict `none`, PDX3 (camber on Fx friction, absent
//! from the upright drive/brake runs) kept at its start, and the baseline
//! fitted from the built-in tyre stands within [`MISFIT_RATIO`] of the noise
//! floor on every channel (`baseline_fit` of `diagnosis.json`): a control the baseline
//! cannot fit would be reported as "baseline misfit", and every effect
//! hidden in a recording of that tyre would go unnamed. The first probe
//! (28 Nov 2026) found the FSAE tyre's Fx at 3.98× — its PKX2 = −80 lay
//! outside the fit's box (±50). This test's recording of it, box ±50: Fx
//! 2.87×, Fy 2.31×, Mz 3.11× (fails); box ±200: 1.92×, 1.42×, 1.72×.
//! The two PAC2002 tyres of FNOMIN 35 kN are here for the data-driven
//! start's load bins: the rig's load ramps merged the sweeps' loads into
//! one bin, no load trend was estimated and the fit stayed in the built-in
//! tyre's basin — HMMWV Fx 39.4×, Mz 9.4×; Generic Fx 39.3×, Mz 9.1× (fails);
//! with the ramps left out of the bins (`fit::initial`, RAMP_SHARE):
//! 0.34×/1.30×/1.49× and 0.35×/1.35×/2.21×.
//!
//! What this does not show: the rig is the project's own, so it proves the
//! fit's reach over real parameter sets, not the diagnosis's generality
//! (that is `diagnose_devset`'s job). Skips with a message without
//! `../shared`.

use crate::common;

use std::path::Path;
use std::process::Command;
use tyrekit::diagnose::report::MISFIT_RATIO;
use tyrekit::mf::Tyre;
use tyrekit::rig::{effects, simulate, RigConfig};

/// The tyres: (file, why it is here).
const TYRES: [(&str, &str); 8] = [
    ("FSAE_Defaults.tir", "MFeval's FSAE default; PKX2 = -80"),
    ("Sedan_Pac02Tire.tir", "PAC2002 car tyre; PEY4 = -760"),
    (
        "335_65R22_5_G275MSA_60psi.tir",
        "truck tyre, FNOMIN 21.7 kN, PDY1 < 0",
    ),
    ("MagicFormula52_Parameters.tir", "MF 5.2 car tyre"),
    (
        "HMMWV_Pac02Tire.tir",
        "PAC2002 off-road tyre, FNOMIN 35 kN; needs the data-driven start's load bins",
    ),
    (
        "Generic_Pac02Tire.tir",
        "PAC2002 generic tyre; needs the data-driven start's load bins",
    ),
    ("MagicFormula62_Parameters.tir", "MF 6.2 car tyre"),
    (
        "Hoosier-20.5x7x13R25B-ISO.TIR",
        "MF 6.1 FSAE tyre fitted to TTC data",
    ),
];

/// What a probe recording conceals and how the rig runs it.
struct Case<'a> {
    /// The rig's effect ("none": a control).
    effect: &'a str,
    /// Its level.
    level: f64,
    /// Its second formulation, where the rig has one.
    alt: bool,
    /// Inclinations of the cornering blocks (rad), in time order.
    inclinations: Vec<f64>,
    /// Drive/brake at 32, 40 and 48 km/h (a speed programme, as tyre tests
    /// and the dev set's speed recordings run one), else at 40 km/h.
    speeds: bool,
}

/// A recording of `tyre` with `case` concealed at `path`: the rig's
/// standard programme at one pressure (all three for `pressure`), cornering
/// at the case's inclinations, drive/brake at two slip angles.
fn record(tyre: &Tyre, case: &Case, seed: u64, path: &Path) {
    let mut c = RigConfig::standard(tyre, seed);
    let pr = &mut c.programme;
    if case.effect != "pressure" {
        pr.pressures = vec![pr.pressures[1]];
    }
    pr.inclinations = case.inclinations.clone();
    pr.db_alphas.truncate(2);
    if case.speeds {
        pr.db_speeds = [32.0, 40.0, 48.0].iter().map(|v| v / 3.6).collect();
    }
    let (effect, level) = (case.effect, case.level);
    let mut truth = case
        .alt
        .then(|| effects::concealed_alt(effect, tyre.clone(), level))
        .flatten()
        .or_else(|| effects::concealed(effect, tyre.clone(), level))
        .expect("a rig effect");
    simulate(&c, truth.as_mut())
        .write_mat(path, true)
        .expect("write .mat");
}

/// A control recording of `tyre`: [`record`] without an effect, cornering
/// at 0 and 2°.
fn control(tyre: &Tyre, seed: u64, path: &Path) {
    let case = Case {
        effect: "none",
        level: 1.0,
        alt: false,
        inclinations: vec![0.0, 2f64.to_radians()],
        speeds: false,
    };
    record(tyre, &case, seed, path);
}

/// `tyrekit diagnose REC --report DIR` as a user runs it (no `--tir`) on
/// the control of tyre file `what`: asserts it succeeded; returns its
/// stderr and `diagnosis.json`.
fn diagnose(what: &str, rec: &Path, report: &Path) -> (String, serde_json::Value) {
    let o = Command::new(env!("CARGO_BIN_EXE_tyrekit"))
        .args(["diagnose", rec.to_str().unwrap(), "--report"])
        .arg(report)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{what}: {err}");
    let d = serde_json::from_str(&std::fs::read_to_string(report.join("diagnosis.json")).unwrap())
        .unwrap();
    (err, d)
}

#[test]
fn the_baseline_fits_controls_of_other_real_tyres_within_the_noise() {
    let tir = common::shared().join("data/tir");
    if !tir.exists() {
        eprintln!("SKIP the_baseline_fits_controls_of_other_real_tyres_within_the_noise: ../shared/data/tir is absent");
        return;
    }
    let tmp = common::scratch("diag-tyres");
    let dir = tmp.path();
    let mut bad = Vec::new();
    for (k, (file, why)) in TYRES.iter().enumerate() {
        let tyre = Tyre::from_file(&tir.join(file)).expect("a shared tyre file");
        let rec = dir.join(format!("control{k}.mat"));
        control(&tyre, 100 + k as u64, &rec);
        let report = dir.join(format!("control{k}"));
        let (_, d) = diagnose(file, &rec, &report);
        let fits: Vec<(String, f64)> = d["baseline_fit"]
            .as_array()
            .expect("baseline_fit")
            .iter()
            .map(|f| {
                (
                    f["channel"].as_str().unwrap_or("?").to_string(),
                    f["ratio"].as_f64().unwrap_or(f64::NAN),
                )
            })
            .collect();
        println!(
            "{file} ({why}): verdict {}, baseline/noise {fits:?}",
            d["verdict"]
        );
        assert_eq!(fits.len(), 3, "{file}: Fx, Fy and Mz scored");
        // The drive/brake runs are upright (`db_inclinations` = [0]): the
        // camber term of Fx friction is not in the data and must keep the
        // start's value (the built-in tyre's). Before the stages judged the
        // inclination spread robustly, a few samples at 1° where a block's
        // inclination changed freed it: FSAE −50, MF 5.2 +50 (its bounds).
        let pdx3 = |t: &Tyre| t.params().p.get("pdx3").unwrap_or(f64::NAN);
        let fitted = Tyre::from_file(&report.join("baseline.tir")).expect("baseline.tir");
        if pdx3(&fitted) != pdx3(&Tyre::builtin()) {
            bad.push(format!(
                "{file}: PDX3 {} fitted from upright Fx data",
                pdx3(&fitted)
            ));
        }
        if d["verdict"] != "none" || fits.iter().any(|(_, r)| !(*r < MISFIT_RATIO)) {
            bad.push(format!("{file}: verdict {}, {fits:?}", d["verdict"]));
        }
    }
    assert!(
        bad.is_empty(),
        "controls not fitted within the noise: {bad:?}"
    );
}

/// The controls of [`TYRES`] again with other seeds of the rig's noise,
/// scatter and non-uniformity: every verdict `none`. The live test runs one
/// seed per tyre, and the selection's floor ([`MIN_GAIN`], 2.5 %) was set
/// above the largest gain a control of it had shown (the MF 5.2 example's
/// camber, 2.4 %); this asks how often another seed crosses it. Printed per
/// control: the verdict and the largest held-out gain of any candidate in a
/// channel where its BIC fell (what the floor is measured against).
/// `TYREKIT_CONTROL_SEEDS=n` seeds per tyre (default 3: 24 diagnoses,
/// ≈ 3–6 min on 2 cores). Measured 4 Dec 2026: MF 5.2's seed 3103 named
/// `camber` (QDZ8 alone, Mz −5.3 % held out, Mz BIC −0.3); since a
/// candidate made of the baseline's own keys needs positive evidence
/// (`diagnose::candidate::REFIT_EVIDENCE`) all 24 `none`.
///
/// [`MIN_GAIN`]: tyrekit::diagnose::candidate::MIN_GAIN
#[test]
#[ignore = "on demand (24 diagnoses, ≈ 6 min): the controls of the live test with other seeds"]
fn controls_of_other_real_tyres_with_other_seeds_name_nothing() {
    let tir = common::shared().join("data/tir");
    if !tir.exists() {
        eprintln!("SKIP controls_of_other_real_tyres_with_other_seeds_name_nothing: ../shared/data/tir is absent");
        return;
    }
    let seeds: u64 = std::env::var("TYREKIT_CONTROL_SEEDS")
        .map(|v| v.parse().expect("TYREKIT_CONTROL_SEEDS: a count"))
        .unwrap_or(3);
    let tmp = common::scratch("diag-seeds");
    let dir = tmp.path();
    let mut named = Vec::new();
    let mut largest: f64 = 0.0;
    for (k, (file, _)) in TYRES.iter().enumerate() {
        let tyre = Tyre::from_file(&tir.join(file)).expect("a shared tyre file");
        for j in 1..=seeds {
            let seed = 100 + k as u64 + 1000 * j;
            let tag = format!("control{k}_{seed}");
            let rec = dir.join(format!("{tag}.mat"));
            control(&tyre, seed, &rec);
            let (_, d) = diagnose(file, &rec, &dir.join(&tag));
            let best = d["effects"]
                .as_array()
                .into_iter()
                .flatten()
                .filter(|e| e["name"] != "none")
                .flat_map(|e| {
                    e["channels"]
                        .as_array()
                        .into_iter()
                        .flatten()
                        .filter(|c| {
                            c["acts"] == true && c["delta_bic"].as_f64().is_some_and(|b| b < 0.0)
                        })
                        .map(move |c| {
                            (
                                c["oos_gain"].as_f64().unwrap_or(f64::NAN),
                                format!(
                                    "{} {}",
                                    e["name"].as_str().unwrap_or("?"),
                                    c["channel"].as_str().unwrap_or("?")
                                ),
                            )
                        })
                })
                .max_by(|a, b| a.0.total_cmp(&b.0));
            let verdict = d["verdict"].as_str().unwrap_or("?").to_string();
            println!(
                "{file} seed {seed}: {verdict}; largest gain {}",
                best.as_ref()
                    .map_or("none".into(), |(g, w)| format!("{:.1} % ({w})", 100.0 * g))
            );
            if let Some((g, _)) = &best {
                largest = largest.max(*g);
            }
            if verdict != "none" {
                named.push(format!(
                    "{file} seed {seed}: {verdict}: {}",
                    d["explanation"]
                ));
            }
        }
    }
    println!("largest control gain {:.1} %", 100.0 * largest);
    assert!(named.is_empty(), "controls named: {named:#?}");
}

/// A control of the all-zero template file (`TIR_template.tir`: every
/// force coefficient 0, so the rig records noise and zeros only while it
/// sweeps α to ±12° and κ to ±0.2): both force channels are rejected as
/// not following their slip (`data::sanity`), and nothing is named. Probed
/// 30 Nov 2026 before that rejection: the baseline fitted Fx to its noise
/// and the diagnosis named `load_sensitivity` (Fx −16 %, K_FZ2 at its
/// bound) on this control.
#[test]
fn a_recording_whose_forces_follow_no_slip_names_nothing() {
    let tir = common::shared().join("data/tir/TIR_template.tir");
    if !tir.exists() {
        eprintln!("SKIP a_recording_whose_forces_follow_no_slip_names_nothing: ../shared/data/tir is absent");
        return;
    }
    let tmp = common::scratch("diag-dead");
    let dir = tmp.path();
    let rec = dir.join("template.mat");
    control(
        &Tyre::from_file(&tir).expect("the template file"),
        102,
        &rec,
    );
    let report = dir.join("template");
    let (err, d) = diagnose("TIR_template.tir", &rec, &report);
    for ch in ["Fx", "Fy"] {
        assert!(
            err.contains(&format!(
                "channel '{ch}' rejected: it does not follow the slip"
            )),
            "{ch} not rejected: {err}"
        );
    }
    assert_eq!(d["verdict"], "none", "{}", d["explanation"]);
}

/// Tyres of the effects probe: (file, why). None of them made the dev set.
const EFFECT_TYRES: [(&str, &str); 4] = [
    ("MagicFormula62_Parameters.tir", "MF 6.2 car tyre"),
    ("Sedan_Pac02Tire.tir", "PAC2002 car tyre"),
    ("HoosierR20.tir", "MF 6.1 FSAE tyre"),
    (
        "335_65R22_5_G275MSA_60psi.tir",
        "truck tyre, FNOMIN 21.7 kN",
    ),
];

/// The physics the dev set conceals, each at the rig's level 2 (its second
/// formulation where it has one — a compound softening with temperature,
/// an exponential speed law, a power law in load — so the formulas differ
/// from the proof's first ones), with whether the recording is a speed
/// programme. Speed friction runs in one, as its dev-set recordings do: at
/// one belt speed the sliding speed is the slip times a constant, and a
/// friction falling with it is a slip-curve shape the fitted Magic Formula
/// holds. A second control (last, so that the others keep their seeds)
/// runs the speed programme: a named speed friction must not be the
/// programme's doing.
const PROBE_EFFECTS: [(&str, bool); 8] = [
    ("none", false),
    ("relaxation", false),
    ("thermal", false),
    ("load_sensitivity", false),
    ("pressure", false),
    ("speed_friction", true),
    ("rolling_radius", false),
    ("none", true),
];

/// Effects concealed in rig recordings of four tyres the dev set did not
/// use, each diagnosed as a user runs it (no `--tir`: the baseline is
/// fitted from the built-in tyre). Asserted: no wrong name (a verdict is the
/// concealed effect or `none`, whose words may say the baseline misfits),
/// the controls `none`; printed: the verdict table and how many were named.
///
/// The programme is the rig's at one pressure (three for `pressure`) and
/// one belt speed (three for speed friction and the second control, see
/// [`PROBE_EFFECTS`]), cornering upright, drive/brake at two slip angles.
/// One effect cannot be told from the baseline here, so `none` is the right
/// answer for it, not a miss: the rig's rolling-radius error
/// (κ' = (1 + κ)(1 + a·dfz) − 1) is a load-proportional slip shift, which
/// PHX2 holds in Fx (in Fy's combined-slip terms it does not: some tyres'
/// recordings end in "baseline misfit", README). (Speed friction at one belt speed, until 4 Dec 2026: named
/// on 0 of 4; in the speed programme on 4 of 4.) Cornering is upright because inclination blocks run in time
/// order (0° then 2°, as in many TTC runs) let the baseline's camber terms
/// take up a tread temperature rising through the run, and the thermal
/// candidate, screened against that baseline, then loses on the held-out
/// inclination (3 Dec 2026, before the candidate fitted the Fx level:
/// thermal named on 0 of 4 tyres that way, held-out Fy 5–69 % worse; the
/// MF 6.2 tyre's recording after it: `none` too) — a known limit written in
/// the README.
///
/// On demand: the rig is the project's own, so this is the fit's and the
/// candidates' reach over other tyres, not the diagnosis's generality (the
/// dev set's job). `TYREKIT_PROBE_FILTER=name` runs the effects whose name
/// contains it; `TYREKIT_PROBE_SPEEDS=all` records every effect in the
/// speed programme (does a speed programme make another effect look like
/// speed friction?) — it did (4 Dec 2026: thermal → speed friction on the
/// PAC2002 and the Hoosier, rolling radius → thermal on MF 6.2), mended by
/// the overshadow rule's second case (the PAC2002) and by the thermal
/// candidate's combined-slip weights scored against their reference (the
/// other two; no wrong name in 32, thermal named on 4 of 4).
/// `TYREKIT_PROBE_TYRES=a.tir,b.tir` probes those files of
/// `../shared/data/tir` instead of [`EFFECT_TYRES`]: with MF 5.2's example,
/// the TTC-fitted MF 6.1 Hoosier R25B, a PAC2002 SUV and a PAC2002 van tyre
/// (4 Dec 2026) one wrong name in 32 — the Hoosier's speed-programme
/// control, `rolling_radius` on Mz alone, then `thermal`, both from a
/// baseline held to |PEX4| ≤ 0.99 where the file has −1.17 (README, "More
/// tyres"); since PEX4's box holds it, no wrong name in 32, named 17 of 24.
/// `TYREKIT_PROBE_CAMBER=0,2` corners at those inclinations (degrees, in
/// that order) instead of upright: the known limit above, measured 4 Dec
/// 2026 (stop 69): no wrong name in 32, thermal named on 0 of 4, load
/// sensitivity 2 of 4, named 14 of 24. Tried then and not kept: the thermal
/// candidate fitting the baseline's camber keys again beside its curve
/// (PDY3; then PDY3, QDZ3, QDZ8), scored against them alone — held-out Fy
/// turned from 30–384 % worse to 7–25 % better, but Fx stayed 9–27 % worse
/// on three tyres and those keys alone, fitted on one half, made the other
/// half's Mz 9–194 % worse: still 0 of 4.
#[test]
#[ignore = "on demand (32 recordings through the whole diagnosis, ≈ 320 s on 2 cores)"]
fn effects_on_other_tyres_get_no_wrong_name() {
    let tir = common::shared().join("data/tir");
    if !tir.exists() {
        eprintln!("SKIP effects_on_other_tyres_get_no_wrong_name: ../shared/data/tir is absent");
        return;
    }
    let tmp = common::scratch("diag-tyre-effects");
    let dir = tmp.path();
    let filter = std::env::var("TYREKIT_PROBE_FILTER").unwrap_or_default();
    let all_speeds = std::env::var("TYREKIT_PROBE_SPEEDS").is_ok_and(|v| v == "all");
    let inclinations: Vec<f64> = std::env::var("TYREKIT_PROBE_CAMBER")
        .ok()
        .map(|v| {
            v.split(',')
                .map(|x| {
                    x.trim()
                        .parse::<f64>()
                        .expect("TYREKIT_PROBE_CAMBER: degrees, comma-separated")
                        .to_radians()
                })
                .collect()
        })
        .unwrap_or_else(|| vec![0.0]);
    let mut wrong = Vec::new();
    let (mut named, mut concealed) = (0, 0);
    let tyres: Vec<(String, &str)> = match std::env::var("TYREKIT_PROBE_TYRES") {
        Ok(v) if !v.trim().is_empty() => v
            .split(',')
            .map(|f| (f.trim().to_string(), "chosen by TYREKIT_PROBE_TYRES"))
            .collect(),
        _ => EFFECT_TYRES
            .iter()
            .map(|&(f, why)| (f.to_string(), why))
            .collect(),
    };
    for (k, (file, why)) in tyres.iter().enumerate() {
        let file = file.as_str();
        let tyre = Tyre::from_file(&tir.join(file)).expect("a shared tyre file");
        for (e, &(effect, speeds)) in PROBE_EFFECTS.iter().enumerate() {
            if !filter.is_empty() && !effect.contains(filter.as_str()) {
                continue;
            }
            let speeds = speeds || all_speeds;
            let tag = format!("t{k}_{effect}{}", if speeds { "_speeds" } else { "" });
            let rec = dir.join(format!("{tag}.mat"));
            let seed = 300 + 10 * k as u64 + e as u64;
            let case = Case {
                effect,
                level: 2.0,
                alt: true,
                inclinations: inclinations.clone(),
                speeds,
            };
            record(&tyre, &case, seed, &rec);
            let (_, d) = diagnose(file, &rec, &dir.join(&tag));
            let verdict = d["verdict"].as_str().unwrap_or("?").to_string();
            let programme = if speeds { "3 speeds" } else { "1 speed" };
            let grade = d["verdict_evidence"]["grade"].as_str().unwrap_or("-");
            println!("{file} ({why}) | {effect} | {programme} | {verdict} | evidence {grade}");
            if effect != "none" {
                concealed += 1;
                named += usize::from(verdict == effect);
            }
            let allowed = verdict == effect || (effect != "none" && verdict == "none");
            if !allowed {
                wrong.push(format!(
                    "{file} {effect} ({programme}): {verdict}: {}",
                    d["explanation"]
                ));
            }
        }
    }
    println!("named {named} of {concealed}");
    assert!(wrong.is_empty(), "wrong names: {wrong:#?}");
}
