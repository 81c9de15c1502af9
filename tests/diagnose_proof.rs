//! The proof of the diagnosis (issue 7): rig recordings with one concealed
//! effect, written as TTC `.mat` files and read back through
//! `Recording::from_file` (the real data path: SAE→ISO, units, warm-up cut,
//! segmentation, κ from the recording), from three tyres of
//! `../shared/data/tir/`, every effect at two strengths, second formulations
//! of three effects, and controls with no effect (noise and sensor offsets
//! only). Baseline: the truth tyre without the effect (the model a user has).
//!
//! Asserted per recording: the verdict ([`candidate::select`]) names the
//! right effect (controls: none), and the extended model recovers at least
//! half of the held-out error gap between the baseline and the truth
//! (the rig's noise-free forces at the recorded instants), both scored on
//! the diagnosis' held-out half with a fixed yardstick
//! ([`candidate::held_out_sse`]: offsets removed, each channel weighted by
//! 1/its measured variance). Printed per recording: each candidate's pooled
//! held-out gain/ΔBIC and the right candidate's per-channel held-out gains.
//!
//! `TYREKIT_PROOF_FILTER=name` restricts the run to effects whose name
//! contains it (development aid; the full run is the proof).

use crate::common;

use std::path::Path;
use tyrekit::data::{load, LoadOptions, ReChoice, Recording};
use tyrekit::diagnose::candidate::{self, all, evaluate, held_out_sse, select, Candidate};
use tyrekit::diagnose::replay::{replay, ReplayOptions};
use tyrekit::mf::{Forces, MfInput, Tyre};
use tyrekit::rig::{effects, simulate, RigConfig, RigInput, TruthModel};

const TYRES: [&str; 3] = [
    "PacejkaBook_Defaults.tir",
    "reference_tire_tvd3.tir",
    "FSAE_Defaults.tir",
];

/// Goals known not to be met today (label, "verdict" | "recovered", why):
/// printed, not asserted; every other case is asserted, and a case listed
/// here that passes is reported so the list shrinks.
const KNOWN: &[(&str, &str, &str)] = &[];

/// A reduced programme with the conditions `effect` acts on: three loads,
/// drive/brake at two slip angles; three pressures only for `pressure`,
/// inclinations 0 and 4° only for `camber`; 50 Hz recorded (100 Hz simulated).
fn config(tyre: &Tyre, effect: &str, seed: u64) -> RigConfig {
    let mut c = RigConfig::standard(tyre, seed);
    c.decimate = 2;
    let pr = &mut c.programme;
    if effect != "pressure" {
        let pnom = pr.pressures[1];
        pr.pressures = vec![pnom];
    }
    pr.inclinations = if effect == "camber" {
        vec![0.0, 4f64.to_radians()]
    } else {
        vec![0.0]
    };
    pr.loads.truncate(3);
    pr.db_alphas.truncate(2);
    c
}

fn opts() -> ReplayOptions {
    common::diagnose_opts()
}

/// Simulate, write a TTC .mat, read it back.
fn record(
    tyre: &Tyre,
    effect: &str,
    model: &mut dyn TruthModel,
    seed: u64,
    dir: &Path,
) -> Recording {
    let run = simulate(&config(tyre, effect, seed), model);
    let path = dir.join(format!("rig_{seed}.mat"));
    run.write_mat(&path, true).unwrap();
    // κ from the recorded wheel speed with the baseline model's effective
    // rolling radius (the default free-rolling linear Re(Fz) fit leaves a
    // load-dependent κ bias that is itself a rolling-radius signature).
    let o = LoadOptions {
        re: ReChoice::Model(Box::new(tyre.clone())),
        ..Default::default()
    };
    load(&path, &o).unwrap().recording
}

/// The truth model replayed on the recording's inputs as the diagnosis
/// sees them (smoothed, [`candidate::smoothed_inputs`]): the best any model
/// can do from those inputs — its held-out error is the floor of the gap.
fn replay_truth(model: &mut dyn TruthModel, rec: &Recording) -> Vec<Forces> {
    let rec = candidate::smoothed_inputs(rec);
    model.reset();
    let mut last = f64::NAN;
    rec.samples
        .iter()
        .map(|s| {
            let dt = if last.is_finite() { s.time - last } else { 0.0 };
            last = s.time;
            let inp = RigInput {
                time: s.time,
                mf: MfInput {
                    fz: s.fz,
                    kappa: s.kappa,
                    alpha: s.alpha,
                    gamma: s.gamma,
                    phit: 0.0,
                    vx: s.vx,
                    p: s.p,
                    omega: s.omega,
                },
                v_belt: s.vx / s.alpha.cos(),
                step: 0,
            };
            model.sample(&inp, dt.max(0.0)).forces
        })
        .collect()
}

struct Outcome {
    label: String,
    verdict: String,
    gain: f64,
    recovered: f64,
}

fn diagnose_one(
    tyre: &Tyre,
    expect: &str,
    label: &str,
    make: &dyn Fn() -> Box<dyn TruthModel>,
    seed: u64,
) -> Outcome {
    // The recording is read back whole: its folder goes at the block's end.
    let rec = {
        let d = common::scratch(&format!("proof-{seed}"));
        record(tyre, expect, make().as_mut(), seed, d.path())
    };
    let truth = replay_truth(make().as_mut(), &rec);
    let owned = all();
    let cands: Vec<&dyn Candidate> = owned.iter().map(|c| c.as_ref()).collect();
    let ev = evaluate(&rec, tyre, &opts(), &cands).unwrap();
    let verdict = select(&ev).map_or("none".to_string(), |i| ev[i].0.name.clone());
    // Baseline, extension and truth all on the inputs the diagnosis uses.
    let srec = candidate::smoothed_inputs(&rec);
    let base = replay(&srec, tyre, &opts()).unwrap().sim;
    let (sb, st) = (held_out_sse(&srec, &base), held_out_sse(&srec, &truth));
    let right = ev.iter().find(|(e, _)| e.name == expect).unwrap();
    let se = held_out_sse(&srec, &right.1.predict(&srec).unwrap());
    let recovered = if sb > st {
        (sb - se) / (sb - st)
    } else {
        f64::NAN
    };
    let table: Vec<String> = ev
        .iter()
        .map(|(e, _)| format!("{} {:.3}/{:+.0}", e.name, e.oos_gain, e.delta_bic))
        .collect();
    println!(
        "{label:<40} verdict {verdict:<16} gap recovered {:>6.1} % (base {sb:.1}, ext {se:.1}, truth {st:.1})  [{}]",
        100.0 * recovered,
        table.join(", ")
    );
    let ch = |e: &candidate::Evaluation| {
        e.channels
            .iter()
            .map(|c| format!("{} {:+.3}", c.channel, c.oos_gain))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!("    {} [{}]", right.0.describe, ch(&right.0));
    if let Some(i) = select(&ev) {
        if ev[i].0.name != expect {
            println!("    verdict's channels: [{}]", ch(&ev[i].0));
        }
    }
    Outcome {
        label: label.into(),
        verdict,
        gain: right.0.oos_gain,
        recovered,
    }
}

#[test]
fn every_effect_is_named_and_recovered_controls_get_none() {
    let dir = common::shared().join("data/tir");
    if !dir.exists() {
        eprintln!(
            "skipped: {} not found (the shared tyre files)",
            dir.display()
        );
        return;
    }
    let filter = std::env::var("TYREKIT_PROOF_FILTER").unwrap_or_default();
    let t0 = std::time::Instant::now();
    let mut out = Vec::new();
    let mut seed = 100;
    let tyres: Vec<String> = match std::env::var("TYREKIT_PROOF_TYRES") {
        Ok(v) => v.split(',').map(|x| x.to_string()).collect(),
        Err(_) => TYRES.iter().map(|x| x.to_string()).collect(),
    };
    for (ti, name) in tyres.iter().enumerate() {
        let tyre = Tyre::from_file(&dir.join(name)).unwrap();
        for effect in effects::EFFECTS {
            if !effect.contains(filter.as_str()) {
                continue;
            }
            let levels: &[f64] = if effect == "none" {
                &[0.0]
            } else {
                &[1.0, 2.0]
            };
            for &level in levels {
                seed += 1;
                let make = || effects::concealed(effect, tyre.clone(), level).unwrap();
                let label = format!("{name} {effect} ×{level}");
                out.push((effect, diagnose_one(&tyre, effect, &label, &make, seed)));
            }
            // Second formulations, one tyre each (rotating).
            let k = effects::EFFECTS
                .iter()
                .position(|e| *e == effect)
                .unwrap_or(0);
            if effects::concealed_alt(effect, tyre.clone(), 1.0).is_some() && ti == k % 3 {
                seed += 1;
                let make = || effects::concealed_alt(effect, tyre.clone(), 1.0).unwrap();
                let label = format!("{name} {effect} (2nd form)");
                out.push((effect, diagnose_one(&tyre, effect, &label, &make, seed)));
            }
        }
    }
    println!(
        "proof: {} recordings in {:.1} s",
        out.len(),
        t0.elapsed().as_secs_f64()
    );
    let mut failures = Vec::new();
    let known = |label: &str, what: &str| KNOWN.iter().any(|(l, w, _)| *l == label && *w == what);
    for (effect, o) in &out {
        let (v_ok, r_ok) = (
            o.verdict == *effect,
            *effect == "none" || o.recovered >= 0.5,
        );
        for (ok, what) in [(v_ok, "verdict"), (r_ok, "recovered")] {
            if ok && known(&o.label, what) {
                println!("now met, remove from KNOWN: {} {what}", o.label);
            }
            if !ok && !known(&o.label, what) {
                failures.push(format!(
                    "{}: verdict {} (held-out gain of the right one {:.3}), {:.1} % of the gap recovered",
                    o.label,
                    o.verdict,
                    o.gain,
                    100.0 * o.recovered
                ));
            }
        }
    }
    for (l, w, why) in KNOWN {
        println!("known shortfall: {l} ({w}): {why}");
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
