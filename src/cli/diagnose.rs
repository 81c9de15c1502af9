//! `tyrekit diagnose` — arguments and dispatch: the baseline (`--tir`, or the
//! steady MF 6.1 fitted to the recordings with the candidates' parameters
//! held, [`crate::diagnose::baseline`]), replay, locate, the candidate
//! extensions, the verdict in words, and the report directory:
//! `diagnosis.json`, `report.html` with its SVG plots, `baseline.tir`,
//! `extended.tir` (see [`crate::diagnose::report`]). Progress bars on stderr
//! when it is a terminal.
//!
//! Must never: panic on bad input (errors name the file or flag), or draw
//! progress when stderr is not a terminal.

use crate::data::ReChoice;
use crate::diagnose::baseline::{fit_baseline, HELD_PRESSURE_KEYS};
use crate::diagnose::case::{Case, Outcome};
use crate::diagnose::{html, plots};
use crate::fit::Progress;
use crate::{Error, Result};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

/// Arguments of `tyrekit diagnose`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// --json, --quiet, --threads.
    #[command(flatten)]
    pub manners: super::manners::Manners,
    /// Recordings (TTC .mat/.dat, TYDEX, CSV); merged with a gap between them.
    #[arg(required = true)]
    pub recordings: Vec<PathBuf>,
    /// Report directory (created).
    #[arg(long)]
    pub report: PathBuf,
    /// Baseline tyre (.tir). Default: fit the steady MF 6.1 to the recordings.
    #[arg(long)]
    pub tir: Option<PathBuf>,
    /// How to read the recordings. `--re`: model (the baseline's Re(Fz); the
    /// default with --tir), free-rolling (the default without --tir), recorded
    /// or loaded. With --tir, `free-rolling` would absorb part of a
    /// rolling-radius effect into κ before the diagnosis sees it, and leaves a
    /// load-dependent κ bias of its own.
    #[command(flatten)]
    pub read: crate::cli::data::RecordingArgs,
    /// Write extended.tir as the fitted baseline plus the extension only:
    /// do not fit the baseline's Magic Formula again beneath a named
    /// extension (see the README, "re-estimation"). Without --tir only.
    #[arg(long)]
    pub keep_baseline: bool,
}

fn bar(m: &super::manners::Manners, len: u64, template: &str) -> Option<ProgressBar> {
    m.progress().then(|| {
        let b = ProgressBar::new(len);
        b.set_style(
            ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    })
}

/// Run the command.
pub fn run(a: Args) -> Result<()> {
    let t0 = std::time::Instant::now();
    if let Some(tir) = &a.tir {
        if !tir.is_file() {
            return Err(Error::Input(format!(
                "--tir {}: no such file",
                tir.display()
            )));
        }
    }
    let given = a.tir.as_ref().map(|t| super::load_tyre(t)).transpose()?;
    let mut opts = a.read.options(given.as_ref(), "--tir")?;
    if a.read.re.is_none() {
        opts.re = match &given {
            Some(t) => ReChoice::Model(Box::new(t.clone())),
            None => ReChoice::FreeRolling,
        };
    }
    let recs: Vec<_> = crate::cli::data::load_all(&a.recordings, &opts, "diagnose")?
        .into_iter()
        .map(|l| l.recording)
        .collect();
    let mut inputs = a.recordings.clone();
    inputs.extend(a.tir.iter().cloned());
    let mut prov = crate::tir::provenance::Provenance::of_inputs(&inputs)?;
    std::fs::create_dir_all(&a.report).map_err(|e| Error::io(&a.report, e))?;
    let (case, note) = match (&a.tir, given) {
        (Some(tir), Some(t)) => (
            Case::given(t, recs),
            format!("Baseline: {} (given with --tir).", tir.display()),
        ),
        _ => {
            let b = bar(&a.manners, 100, "{prefix:>12} [{bar:30}] {pos}/{len} {msg}");
            let mut cb = |p: &Progress| {
                if let Some(b) = &b {
                    b.set_prefix(format!("fit {}", p.stage));
                    b.set_length(p.max_iterations as u64);
                    b.set_position(p.iteration as u64);
                    b.set_message(format!("cost {:.4e}", p.cost));
                }
            };
            let threads = a.manners.threads();
            let fit = fit_baseline(&recs, threads, Some(&mut cb))?;
            if let Some(b) = &b {
                b.finish_and_clear();
            }
            for s in &fit.skipped {
                eprintln!("tyrekit diagnose: baseline fit stage skipped: {s}");
            }
            if fit.report.stages.is_empty() {
                return Err(Error::Input(format!(
                    "diagnose: the baseline fit found no usable data in any stage ({}): the recording cannot be analysed",
                    fit.skipped.join("; ")
                )));
            }
            prov.lines = crate::cli::provenance::report_lines(&fit.report);
            let sig = |ch: &str| {
                crate::fit::mf_fit::overall_sigma(&fit.report.metrics, ch)
                    .map_or("–".into(), |v| format!("{:.1} %", 100.0 * v))
            };
            let case = Case::fitted(&fit, recs, !a.keep_baseline)?;
            let dropped = &case.dropped;
            let mut note = format!(
                "Baseline: steady MF 6.1 fitted to the recordings (every {}. sample; σ Fx {}, Fy {}, Mz {}), started from the built-in tyre with FNOMIN/NOMPRES/LONGVL from the data; each channel diagnosed on the segment kinds it was fitted on (Mz on cornering only); held (so the candidates can name them): relaxation lengths, pressure terms {} (0, data pooled at the median pressure), LMUV and all scaling factors, BREFF/DREFF/FREFF.",
                fit.stride,
                sig("Fx"),
                sig("Fy"),
                sig("Mz"),
                HELD_PRESSURE_KEYS.join(" "),
            );
            if !dropped.is_empty() {
                note.push_str(&format!(
                    " Not diagnosed: {} (the data have no segments to fit {} on).",
                    dropped.join(", "),
                    if dropped.len() == 1 { "it" } else { "them" }
                ));
            }
            match (fit.zeroed.is_some(), fit.zero_fit_gain) {
                (true, Some(g)) => note.push_str(&format!(
                    " Sensor zeros in the baseline's residual (its intercept over load, which the MF's load-proportional shifts cannot take up): {}; without them the MF fits {:.1} % better, so the diagnosis compares the recording with them subtracted with the MF fitted without them (the plots and held-out figures are of that copy), while baseline.tir and extended.tir — the verdict fitted again beneath the first fit — are fitted to the recording as measured (the FMU has no sensor).",
                    fit.zeros.in_words(),
                    100.0 * g
                )),
                (false, Some(g)) => note.push_str(&format!(
                    " Sensor zeros in the baseline's residual: {}; left to the MF's shifts (without them it fits only {:.1} % better, under the {:.0} % that would change the comparison).",
                    fit.zeros.in_words(),
                    100.0 * g,
                    100.0 * crate::diagnose::sensor_zero::MIN_FIT_GAIN
                )),
                _ => {}
            }
            if !fit.zeros.not_estimated.is_empty() {
                note.push_str(&format!(
                    " No sensor zero estimated for {}.",
                    fit.zeros.not_estimated.join("; ")
                ));
            }
            (case, note)
        }
    };
    let m = &a.manners;
    m.say(&note);
    let rec = case.rec();
    let steps = bar(m, 4, "{prefix:>12} [{bar:30}] {pos}/{len} {msg} {elapsed}");
    if let Some(b) = &steps {
        b.set_prefix("diagnose");
    }
    let mut step = |s: &str| {
        if let Some(b) = &steps {
            if !b.message().is_empty() {
                b.inc(1);
            }
            b.set_message(s.to_string());
        }
    };
    // Without --tir the baseline is fitted again beneath a named extension
    // for extended.tir (diagnose::case).
    let Outcome {
        diagnosis: d,
        baseline_file: mut base,
        extended_file: mut ext,
    } = case.diagnose(a.manners.threads(), &mut step)?;
    let mut report = d.report.clone();
    prov.stamp(&mut base);
    base.write(&a.report.join("baseline.tir"))?;
    prov.lines
        .push(format!("diagnosis verdict: {}", d.verdict()));
    prov.stamp(&mut ext);
    ext.write(&a.report.join("extended.tir"))?;
    let pl = plots::draw_all(rec, &d, &a.report)?;
    if let Some(b) = &steps {
        b.finish_and_clear();
    }
    report.baseline = Some(note.clone());
    report.plots = serde_json::to_value(&pl).ok();
    let jp = a.report.join("diagnosis.json");
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| Error::Other(format!("diagnosis.json: {e}")))?;
    std::fs::write(&jp, text).map_err(|e| Error::io(&jp, e))?;
    // The --json result: diagnosis.json's content plus where the page is.
    let mut json =
        serde_json::to_value(&report).map_err(|e| Error::Other(format!("diagnosis.json: {e}")))?;
    json["report_html"] = serde_json::to_value(a.report.join("report.html")).unwrap_or_default();
    let hp = a.report.join("report.html");
    std::fs::write(&hp, html::page(&d, &pl, &rec.source, &note)).map_err(|e| Error::io(&hp, e))?;
    m.say(format_args!("verdict: {}", d.verdict()));
    if let Some(e) = d.report.verdict_evidence {
        m.say(format_args!("evidence: {}", e.in_words()));
    }
    m.say(d.explanation());
    for r in d
        .report
        .quality
        .out_of_sample
        .iter()
        .filter(|r| r.condition == "all")
    {
        m.say(format_args!(
            "  held out {}: σ {:.2} % -> {:.2} %, NRMSE {:.2} % -> {:.2} %",
            r.channel.name(),
            100.0 * r.sigma_before,
            100.0 * r.sigma_after,
            100.0 * r.nrmse_before,
            100.0 * r.nrmse_after
        ));
    }
    if let Some(w) = d.report.extended_parameters_in_words() {
        m.say(format_args!(
            "  extended.tir: {} refitted on every segment (the held-out figures above are the half fit's): {w}",
            d.verdict()
        ));
    }
    m.say(format_args!(
        "wrote {} ({} plots), {}, baseline.tir, extended.tir in {:.1} s",
        hp.display(),
        pl.len(),
        jp.display(),
        t0.elapsed().as_secs_f64()
    ));
    m.result(&json)?;
    Ok(())
}
