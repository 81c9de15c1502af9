//! `tyrekit fit` — fit the Magic Formula to recordings and write a complete
//! `.tir` (SI units): staged fit ([`crate::fit::mf_fit`]), progress bar on
//! stderr, quality table on stdout, and with `--report DIR` a `fit.json` and
//! SVG plots of model against data per condition.
//!
//! Must never: overwrite the start file unless `--out` names it, panic on
//! user data, or draw progress when stderr is not a terminal.

use crate::data::{Recording, SegmentKind};
use crate::fit::metrics::Condition;
use crate::fit::mf_fit::{fit_mf, MfFitOptions};
use crate::fit::mf_stages::{Channel, StageKind, FIT_MODE};
use crate::fit::{Holdout, Progress};
use crate::mf::{MfInput, Tyre};
use crate::tir::{MfVersion, TyreParams};
use crate::{Error, Result};
use plotters::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Arguments of `tyrekit fit`.
#[derive(clap::Args, Debug)]
pub struct Args {
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

    let bar = std::io::stderr().is_terminal().then(|| {
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
        println!(
            "brush fit ({} side-slip, {} longitudinal samples at |gamma| <= 0.5 deg, {} LM iterations): CPY {:.4e} N/m2, CPX {:.4e} N/m2, CARCASS_COMPLIANCE {:.4e} m/N, SIGMA_C {:.3} m, MUK {:.3}, MU_DFZ {:.3}",
            bf.n_lateral, bf.n_longitudinal, bf.iterations, bf.params.cpy, bf.params.cpx,
            bf.params.compliance, bf.params.sigma_c, bf.params.mu_k, bf.params.mu_dfz
        );
        println!("pure slip   sigma_Fy  sigma_Mz  sigma_Fx");
        println!(
            "brush       {:8.4}  {:8.4}  {:8.4}",
            bf.sigma_fy, bf.sigma_mz, bf.sigma_fx
        );
        println!("MF          {mfy:8.4}  {mmz:8.4}  {mfx:8.4}");
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
    if let Some(g) = &res.geometry {
        for l in g.lines() {
            println!("{l}");
        }
    }
    print!("{}", res.report.to_text());
    println!("wrote {}", args.out.display());
    if let Some(dir) = &args.report {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        res.report.write_json(&dir.join("fit.json"))?;
        let tyre = Tyre::new(res.tyre.clone())?;
        let mut n = 0;
        for rec in &recs {
            n += plot_fit(&tyre, rec, &opts.only, dir)?.len();
        }
        println!("wrote {} and {n} plots", dir.join("fit.json").display());
    }
    Ok(())
}

/// One SVG per (channel, condition): measured points and the model curve at
/// the condition's set points over the slip range of the data.
pub fn plot_fit(
    tyre: &Tyre,
    rec: &Recording,
    stages: &[StageKind],
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let stem = Path::new(&rec.source)
        .file_stem()
        .map_or("rec".into(), |s| s.to_string_lossy().into_owned());
    for &kind in stages {
        let (seg_kind, channels) = kind.segments_and_channels();
        for &ch in channels {
            if !rec.has(ch.name()) {
                continue;
            }
            for cond in crate::fit::metrics::conditions(rec) {
                let segs: Vec<_> = rec
                    .segments
                    .iter()
                    .filter(|s| s.kind == seg_kind && Condition::of(s).same(&cond))
                    .collect();
                if segs.is_empty() {
                    continue;
                }
                let lateral = seg_kind == SegmentKind::PureLateral;
                let slip = |s: &crate::data::Sample| if lateral { s.alpha } else { s.kappa };
                let mut pts = Vec::new();
                for g in &segs {
                    let step = (g.len() / 1500).max(1);
                    for s in rec.samples[g.start..g.end.min(rec.samples.len())]
                        .iter()
                        .step_by(step)
                    {
                        let (x, y) = (slip(s), ch.measured(s));
                        if x.is_finite() && y.is_finite() {
                            pts.push((x, y));
                        }
                    }
                }
                if pts.len() < 2 {
                    continue;
                }
                let (x0, x1) = pts
                    .iter()
                    .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.0), a.1.max(p.0)));
                let g0 = segs[0];
                let curve: Vec<(f64, f64)> = (0..=200)
                    .map(|k| {
                        let x = x0 + (x1 - x0) * k as f64 / 200.0;
                        let inp = MfInput {
                            fz: cond.fz,
                            gamma: cond.gamma,
                            p: cond.p,
                            vx: if g0.vx.is_finite() && g0.vx > 0.0 {
                                g0.vx
                            } else {
                                10.0
                            },
                            alpha: if lateral { x } else { g0.alpha },
                            kappa: if lateral { 0.0 } else { x },
                            ..Default::default()
                        };
                        (x, ch.of_forces(&tyre.forces(&inp, FIT_MODE)))
                    })
                    .collect();
                let name = format!(
                    "{stem}_{}_{}_fz{:.0}_g{:.1}_p{:.0}.svg",
                    kind.name().replace(' ', "_"),
                    ch.name(),
                    cond.fz,
                    cond.gamma.to_degrees(),
                    cond.p / 1e3
                );
                let path = dir.join(name);
                draw(&path, ch, lateral, &pts, &curve, &cond)?;
                out.push(path);
            }
        }
    }
    Ok(out)
}

fn draw(
    path: &Path,
    ch: Channel,
    lateral: bool,
    pts: &[(f64, f64)],
    curve: &[(f64, f64)],
    cond: &Condition,
) -> Result<()> {
    let perr =
        |e: &dyn std::fmt::Display| Error::Other(format!("{}: cannot draw: {e}", path.display()));
    let all = pts.iter().chain(curve);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    let pad = |a: f64, b: f64| ((b - a) * 0.05).max(1e-9);
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| perr(&e))?;
    let caption = format!(
        "{} vs {}: Fz {:.0} N, gamma {:.1} deg, P {:.0} kPa (grey data, red model)",
        ch.name(),
        if lateral { "alpha" } else { "kappa" },
        cond.fz,
        cond.gamma.to_degrees(),
        cond.p / 1e3
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 - px)..(x1 + px), (y0 - py)..(y1 + py))
        .map_err(|e| perr(&e))?;
    chart
        .configure_mesh()
        .x_desc(if lateral { "alpha [rad]" } else { "kappa [-]" })
        .y_desc(if ch == Channel::Mz { "Nm" } else { "N" })
        .draw()
        .map_err(|e| perr(&e))?;
    chart
        .draw_series(
            pts.iter()
                .map(|&p| Circle::new(p, 1, RGBColor(150, 150, 150).filled())),
        )
        .map_err(|e| perr(&e))?;
    chart
        .draw_series(LineSeries::new(curve.iter().copied(), RED.stroke_width(2)))
        .map_err(|e| perr(&e))?;
    root.present().map_err(|e| perr(&e))?;
    Ok(())
}
