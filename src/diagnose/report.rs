//! report — the `diagnose` pipeline end to end for one (merged) recording:
//! replay the baseline, locate the residual structure per channel, evaluate
//! the candidates, choose the verdict, and build `diagnosis.json`.
//!
//! Verdict rule: the candidate with the largest out-of-sample gain, if that
//! gain exceeds [`MIN_GAIN`] and its BIC falls; otherwise `none`.
//!
//! Must never: name an effect whose held-out improvement is within noise.

use super::candidate::{all, evaluate, Candidate, CHANNELS};
use super::locate::{frictional_energy, locate, Finding, LocateOptions, Residuals};
use super::replay::{replay, ReplayOptions};
use crate::data::Recording;
use crate::error::Result;
use crate::fit::metrics::nrmse;
use crate::mf::{Forces, Tyre};
use serde_json::{json, Map, Value};

/// Smallest held-out gain that names an effect (the rule: [`super::candidate::select`]).
pub use super::candidate::MIN_GAIN;

/// NRMSE per channel (FX, FY, MZ) of `sim` against the recording.
pub fn nrmse_map(rec: &Recording, sim: &[Forces]) -> Value {
    let mut m = Map::new();
    for (name, fs, fm) in CHANNELS {
        let y: Vec<f64> = rec.samples.iter().map(fm).collect();
        let p: Vec<f64> = sim.iter().map(fs).collect();
        let v = nrmse(&p, &y);
        m.insert(
            name.into(),
            if v.is_finite() { json!(v) } else { Value::Null },
        );
    }
    Value::Object(m)
}

/// Locate findings of one channel.
pub fn locate_channel(
    rec: &Recording,
    sim: &[Forces],
    energy: &[f64],
    channel: &str,
) -> Vec<Finding> {
    let (meas, simc, slip): (Vec<f64>, Vec<f64>, Vec<f64>) = match channel {
        "FX" => (
            rec.samples.iter().map(|s| s.fx).collect(),
            sim.iter().map(|f| f.fx).collect(),
            rec.samples.iter().map(|s| s.kappa).collect(),
        ),
        "MZ" => (
            rec.samples.iter().map(|s| s.mz).collect(),
            sim.iter().map(|f| f.mz).collect(),
            rec.samples.iter().map(|s| s.alpha).collect(),
        ),
        _ => (
            rec.samples.iter().map(|s| s.fy).collect(),
            sim.iter().map(|f| f.fy).collect(),
            rec.samples.iter().map(|s| s.alpha).collect(),
        ),
    };
    let r: Vec<f64> = meas.iter().zip(&simc).map(|(m, s)| m - s).collect();
    let d = Residuals {
        r: &r,
        sim: &simc,
        slip: &slip,
        sweep_dir: &rec.sweep_dir,
        t_in_segment: &rec.t_in_segment,
        energy,
        segments: &rec.segments,
    };
    locate(&d, &LocateOptions::default())
}

/// The diagnosis and the chosen extended tyre.
pub struct Diagnosis {
    pub json: Value,
    pub verdict: String,
    pub extended: Tyre,
}

/// Run the diagnosis of `rec` against the baseline `tyre`.
pub fn diagnose(rec: &Recording, tyre: &Tyre, opts: &ReplayOptions) -> Result<Diagnosis> {
    let base = replay(rec, tyre, opts)?;
    let energy = frictional_energy(rec);
    let mut loc = Map::new();
    for ch in ["FY", "FX", "MZ"] {
        let f = locate_channel(rec, &base.sim, &energy, ch);
        loc.insert(ch.into(), serde_json::to_value(&f).unwrap_or(Value::Null));
    }
    let owned = all();
    let cands: Vec<&dyn Candidate> = owned.iter().map(|c| c.as_ref()).collect();
    let ev = evaluate(rec, tyre, opts, &cands)?;
    let before = nrmse_map(rec, &base.sim);
    let best = super::candidate::select(&ev).map(|i| &ev[i]);
    let verdict = best.map_or("none".to_string(), |(e, _)| e.name.clone());
    let mut effects = Vec::new();
    let mut order: Vec<usize> = (0..ev.len()).collect();
    order.sort_by_key(|&i| if ev[i].0.name == verdict { 0 } else { 1 });
    for i in order {
        let (e, fitted) = &ev[i];
        let sim = fitted.predict(rec)?;
        let params: Map<String, Value> = e
            .parameters
            .iter()
            .map(|(k, v)| (k.clone(), json!(v)))
            .collect();
        effects.push(json!({
            "name": e.name,
            "score": e.oos_gain,
            "delta_bic": e.delta_bic,
            "evidence": format!(
                "fitted on even segments, scored on odd ones: removes {:.1} % of the baseline's held-out squared error (BIC change {:+.1})",
                100.0 * e.oos_gain, e.delta_bic
            ),
            "parameters": params,
            "nrmse_before": before,
            "nrmse_after": nrmse_map(rec, &sim),
        }));
    }
    let extended = best.map_or_else(|| tyre.clone(), |(_, f)| f.tyre().clone());
    let json = json!({
        "verdict": verdict,
        "effects": effects,
        "locate": loc,
        "candidates_implemented": owned.iter().map(|c| c.name()).collect::<Vec<_>>(),
        "samples": rec.samples.len(),
        "segments": rec.segments.len(),
    });
    Ok(Diagnosis {
        json,
        verdict,
        extended,
    })
}

/// Concatenate recordings (each later one shifted in time behind a gap, so
/// the replay resets between them).
pub fn merge(recs: Vec<Recording>) -> Recording {
    let mut out = Recording::default();
    let mut t_end = f64::NEG_INFINITY;
    for r in recs {
        let off = if out.samples.is_empty() {
            0.0
        } else {
            let t0 = r.samples.first().map_or(0.0, |s| s.time);
            t_end + 100.0 - t0
        };
        let base = out.samples.len();
        out.source = if out.source.is_empty() {
            r.source.clone()
        } else {
            format!("{} + {}", out.source, r.source)
        };
        for mut s in r.samples {
            s.time += off;
            t_end = t_end.max(s.time);
            out.samples.push(s);
        }
        for c in r.channels {
            if !out.channels.contains(&c) {
                out.channels.push(c);
            }
        }
        for mut g in r.segments {
            g.start += base;
            g.end += base;
            out.segments.push(g);
        }
        out.sweep_dir.extend(r.sweep_dir);
        out.t_in_segment.extend(r.t_in_segment);
    }
    out
}
