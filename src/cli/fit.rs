//! `tyrekit fit` — fit the Magic Formula to recordings and write a complete
//! `.tir` (SI units): staged fit ([`crate::fit::mf_fit`]), progress bar on
//! stderr, quality table on stdout, and with `--report DIR` a `fit.json` and
//! SVG plots of model against data per condition.
//!
//! Must never: overwrite the start file unless `--out` names it, panic on
//! user data, or draw progress when stderr is not a terminal.

use crate::data::Recording;
use crate::fit::mf_fit::{fit_mf, MfFitOptions};
use crate::fit::mf_stages::StageKind;
use crate::fit::plot::plot_fit;
use crate::fit::{Holdout, Progress};
use crate::mf::Tyre;
use crate::tir::{MfVersion, TyreParams};
use crate::{Error, Result};
use std::path::PathBuf;

/// Arguments of `tyrekit fit`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// --json, --quiet, --threads.
    #[command(flatten)]
    pub manners: super::manners::Manners,
    /// Recordings (any format `tyrekit data` reads).
    #[arg(required = true)]
    pub recordings: Vec<PathBuf>,
    /// The fitted tyre property file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Start tyre (.tir); its FNOMIN, NOMPRES, LONGVL are kept. Default: the built-in tyre.
    #[arg(long)]
    pub start: Option<PathBuf>,
    /// Equation set: mf61, mf62, mf52, pac2002 (default: that of the start tyre).
    #[arg(long)]
    pub model: Option<String>,
    /// Stages, comma-separated: fx, fy, mz, combined, mx, my, transient (default: all
    /// but transient, each where the data carry its channel; `transient`, the relaxation lengths, replays the recordings and runs
    /// only when named).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// Hold data out of the fit: none, run[:K], condition[:K], tail:F (the last
    /// fraction F of each recording's time, e.g. tail:0.3).
    #[arg(long, default_value = "none")]
    pub holdout: String,
    /// Directory for fit.json and the SVG plots.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Coefficients to hold at their start values, comma-separated .tir keys
    /// (e.g. PKY4,PEY3); a key no stage fits is an error.
    #[arg(long, value_delimiter = ',')]
    pub hold: Vec<String>,
    /// How to read the recordings (`--re model` uses the start tyre).
    #[command(flatten)]
    pub read: crate::cli::data::RecordingArgs,
}

fn parse_model(s: &str) -> Result<MfVersion> {
    match s.to_ascii_lowercase().as_str() {
        "mf61" => Ok(MfVersion::Mf61),
        "mf62" => Ok(MfVersion::Mf62),
        "mf52" => Ok(MfVersion::Mf52),
        "pac2002" => Ok(MfVersion::Pac2002),
        _ => Err(Error::Input(format!(
            "--model '{s}': expected mf61, mf62, mf52, pac2002 or brush"
        ))),
    }
}

/// Run the command.
pub fn run(args: Args) -> Result<()> {
    let mut opts = MfFitOptions {
        holdout: Holdout::parse(&args.holdout)?,
        threads: args.manners.threads(),
        ..Default::default()
    };
    if !args.only.is_empty() {
        let mut only = Vec::new();
        for w in &args.only {
            if w.trim().eq_ignore_ascii_case("transient") {
                opts.transient = true;
                continue;
            }
            only.push(StageKind::parse(w).ok_or_else(|| {
                Error::Input(format!(
                    "--only '{w}': expected fx, fy, mz, combined, mx, my or transient"
                ))
            })?);
        }
        opts.only = only;
    }
    opts.fit.hold = args.hold.clone();
    opts.geometry = true;
    let mut start = match &args.start {
        Some(p) => {
            opts.nominal_from_data = false;
            opts.generic_start = false;
            let t = TyreParams::from_file(p)?;
            super::show_warnings(&p.display().to_string(), &t.warnings);
            t
        }
        None => TyreParams::builtin(),
    };
    let brush = args
        .model
        .as_deref()
        .is_some_and(|m| m.eq_ignore_ascii_case("brush"));
    if let Some(m) = args.model.as_ref().filter(|_| !brush) {
        start.version = parse_model(m)?;
    }
    let start_tyre = (args.read.re.is_some())
        .then(|| Tyre::new(start.clone()))
        .transpose()?;
    let load = args.read.options(start_tyre.as_ref(), "--start")?;
    let loaded = crate::cli::data::load_all(&args.recordings, &load, "fit")?;
    // Time origin of each recording before its warm-up cut (for --holdout tail).
    opts.t_origins = loaded
        .iter()
        .map(|l| l.report.warmup.as_ref().map(|w| w.t_start))
        .collect();
    let recs: Vec<Recording> = loaded.into_iter().map(|l| l.recording).collect();

    let bar = args.manners.progress().then(|| {
        let b = indicatif::ProgressBar::new(100);
        b.set_style(
            indicatif::ProgressStyle::with_template("{prefix:>10} [{bar:30}] {pos}/{len} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let mut cb = |p: &Progress| {
        if let Some(b) = &bar {
            b.set_prefix(p.stage.to_string());
            b.set_length(p.max_iterations as u64);
            b.set_position(p.iteration as u64);
            b.set_message(format!("cost {:.4e}", p.cost));
        }
    };
    let res = fit_mf(&recs, start, &opts, Some(&mut cb))?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let mut res = res;
    if brush {
        // The brush beside the MF: started from the fitted MF's defaults,
        // written as the [BRUSH] section of the same file.
        let mf = Tyre::new(res.tyre.clone())?;
        let (b0, _) = crate::brush::BrushParams::from_tyre(&mf)?;
        let bf = crate::fit::brush::fit_brush(&recs, b0)?;
        bf.params.write_to(&mut res.tyre);
        let (mfy, mmz, mfx) = crate::fit::brush::mf_pure_slip_sigmas(&recs, &mf);
        args.manners.say(format_args!(
            "brush fit ({} side-slip, {} longitudinal samples at |gamma| <= 0.5 deg, {} LM iterations): CPY {:.4e} N/m2, CPX {:.4e} N/m2, CARCASS_COMPLIANCE {:.4e} m/N, SIGMA_C {:.3} m, MUK {:.3}, MU_DFZ {:.3}",
            bf.n_lateral, bf.n_longitudinal, bf.iterations, bf.params.cpy, bf.params.cpx,
            bf.params.compliance, bf.params.sigma_c, bf.params.mu_k, bf.params.mu_dfz
        ));
        args.manners.say("pure slip   sigma_Fy  sigma_Mz  sigma_Fx");
        args.manners.say(format_args!(
            "brush       {:8.4}  {:8.4}  {:8.4}",
            bf.sigma_fy, bf.sigma_mz, bf.sigma_fx
        ));
        args.manners
            .say(format_args!("MF          {mfy:8.4}  {mmz:8.4}  {mfx:8.4}"));
    }
    // The fitted tyre passes the same validation as any loaded one before
    // it is written (a refusal is an error; doubts are shown).
    let checked = Tyre::checked(res.tyre.clone())?;
    let n_read = res.tyre.warnings.len();
    super::show_warnings(
        &args.out.display().to_string(),
        &checked.warnings()[n_read..],
    );
    for s in &res.skipped {
        eprintln!("tyrekit fit: stage skipped: {s}");
    }
    for d in &res.decisions {
        eprintln!("tyrekit fit: {d}");
    }
    if res.report.stages.is_empty() && res.report.relaxation.is_empty() {
        return Err(Error::Input(format!(
            "fit: no stage had usable data ({}); nothing written to {}",
            res.skipped.join("; "),
            args.out.display()
        )));
    }
    let mut tyre = res.tyre.clone();
    let mut inputs = args.recordings.clone();
    inputs.extend(args.start.iter().cloned());
    crate::cli::provenance::stamp_fit(&mut tyre, &inputs, &res)?;
    tyre.write(&args.out)?;
    let m = &args.manners;
    if let Some(g) = &res.geometry {
        for l in g.lines() {
            m.say(l);
        }
    }
    m.say(res.report.to_text().trim_end());
    m.say(format_args!("wrote {}", args.out.display()));
    if let Some(dir) = &args.report {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        res.report.write_json(&dir.join("fit.json"))?;
        let tyre = Tyre::new(res.tyre.clone())?;
        let mut n = 0;
        for rec in &recs {
            n += plot_fit(&tyre, rec, &opts.only, dir)?.len();
        }
        m.say(format_args!(
            "wrote {} and {n} plots",
            dir.join("fit.json").display()
        ));
    }
    let report: serde_json::Value = serde_json::from_str(&res.report.to_json()?)
        .map_err(|e| Error::Other(format!("fit report: {e}")))?;
    m.result(&serde_json::json!({
        "tir": args.out,
        "skipped": res.skipped,
        "report": report,
    }))?;
    Ok(())
}
