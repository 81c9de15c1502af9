//! `tyrekit data …` — summarise, convert and plot tyre test recordings.
//! Arguments and printing only; the work is in [`crate::data`].

use crate::data::conventions::AxisSystem;
use crate::data::{self, Format, LoadOptions, Loaded, ReChoice, SegmentKind};
use crate::error::{Error, Result};
use std::path::PathBuf;

/// How to read a recording: the flags `data`, `fit`, `diagnose` and `replay`
/// share (one definition, flattened into each command).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct RecordingArgs {
    /// Force the format instead of detecting it: mat | dat | tdx | csv.
    #[arg(long)]
    pub format: Option<String>,
    /// Axis system of the file: sae | iso-w | adapted-iso | tydex-w | tydex-c
    /// (default: SAE for TTC files, TYDEX W for .tdx, ISO-W for CSV).
    #[arg(long)]
    pub axes: Option<String>,
    /// Effective rolling radius for κ = Ω·Re/(V·cos α) − 1 where κ is computed
    /// from wheel speed: free-rolling (Re(Fz) fitted on the recording's
    /// free-rolling samples), recorded, loaded, or model (the Re(Fz) of the
    /// command's tyre file: --tir, or --start for fit). Default: model where
    /// `diagnose` is given --tir, else free-rolling.
    #[arg(long)]
    pub re: Option<String>,
}

impl RecordingArgs {
    /// Loader options from the flags; `tyre` is the tyre `--re model` uses
    /// (None: `--re model` is an error naming `tyre_flag`).
    pub fn options(&self, tyre: Option<&crate::mf::Tyre>, tyre_flag: &str) -> Result<LoadOptions> {
        let mut o = LoadOptions::default();
        if let Some(f) = &self.format {
            o.format = Some(Format::parse(f).ok_or_else(|| {
                Error::Input(format!("--format '{f}': expected mat, dat, tdx or csv"))
            })?);
        }
        if let Some(a) = &self.axes {
            o.axes = Some(AxisSystem::parse(a).ok_or_else(|| {
                Error::Input(format!(
                    "--axes '{a}': expected sae, iso-w, adapted-iso, tydex-w or tydex-c"
                ))
            })?);
        }
        if let Some(r) = &self.re {
            o.re = if r.trim().eq_ignore_ascii_case("model") {
                let t =
                    tyre.ok_or_else(|| Error::Input(format!("--re model needs {tyre_flag} FILE")))?;
                ReChoice::Model(Box::new(t.clone()))
            } else {
                ReChoice::parse(r).ok_or_else(|| {
                    Error::Input(format!(
                        "--re '{r}': expected free-rolling, recorded, loaded or model"
                    ))
                })?
            };
        }
        Ok(o)
    }
}

/// Load every recording with `o`, printing each rejected channel as a
/// warning on stderr (prefixed by the command's name).
pub fn load_all(paths: &[PathBuf], o: &LoadOptions, cmd: &str) -> Result<Vec<data::Loaded>> {
    let mut out = Vec::with_capacity(paths.len());
    for p in paths {
        let l = data::load(p, o)?;
        for r in &l.report.rejected {
            eprintln!("tyrekit {cmd}: warning: {}: {r}", p.display());
        }
        if l.report.dropped_total > 0 {
            let why: Vec<String> = l
                .report
                .dropped
                .iter()
                .map(|(r, n)| format!("{n} {r}"))
                .collect();
            eprintln!(
                "tyrekit {cmd}: {}: {} of {} rows dropped ({}): see `tyrekit data summary`",
                p.display(),
                l.report.dropped_total,
                l.report.rows_read,
                why.join("; ")
            );
        }
        if !l.report.slip_reference.is_empty() {
            eprintln!(
                "tyrekit {cmd}: {}: slip reference {}",
                p.display(),
                l.report.slip_reference
            );
        }
        out.push(l);
    }
    Ok(out)
}

/// Options of the `data` subcommands: how to read a recording.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ReadArgs {
    #[command(flatten)]
    pub rec: RecordingArgs,
    /// Tyre property file for --re model.
    #[arg(long)]
    pub tir: Option<PathBuf>,
    /// Always compute κ from wheel speed, even when the file records it.
    #[arg(long)]
    pub compute_kappa: bool,
    /// Keep the warm-up (do not detect and cut it).
    #[arg(long)]
    pub keep_warmup: bool,
}

impl ReadArgs {
    /// Loader options from the flags.
    pub fn options(&self) -> Result<LoadOptions> {
        let tyre = self.tir.as_ref().map(|t| super::load_tyre(t)).transpose()?;
        let mut o = self.rec.options(tyre.as_ref(), "--tir")?;
        if self.compute_kappa {
            o.kappa = data::KappaSource::Computed;
        }
        o.remove_warmup = !self.keep_warmup;
        Ok(o)
    }
}

/// `tyrekit data` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Print the test matrix of recordings (conditions × rows × slip range),
    /// with dropped rows, missing channels and the warm-up removed.
    Summary {
        /// Recording files.
        files: Vec<std::path::PathBuf>,
        #[command(flatten)]
        read: ReadArgs,
        /// Print the summary as JSON instead of text.
        #[arg(long)]
        json: bool,
        /// Also print the SAE/ISO sign table.
        #[arg(long)]
        signs: bool,
    },
    /// Write the clean ISO-W SI table (warm-up removed, test structure attached).
    Convert {
        /// Recording file.
        file: PathBuf,
        /// Output format: csv | tdx.
        #[arg(long)]
        to: String,
        /// Output file.
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        read: ReadArgs,
    },
    /// Draw the channels over time and Fy(α), Mz(α), Fx(κ) by condition (SVG).
    Plot {
        /// Recording file.
        file: PathBuf,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        read: ReadArgs,
    },
}

/// Run the command.
pub fn run(cmd: Command) -> Result<()> {
    match cmd {
        Command::Summary {
            files,
            read,
            json,
            signs,
        } => {
            if files.is_empty() {
                return Err(Error::Input(
                    "data summary: give at least one recording file".into(),
                ));
            }
            let o = read.options()?;
            let mut all = Vec::new();
            for f in &files {
                let l = data::load(f, &o)?;
                if json {
                    all.push(summary_json(&l));
                } else {
                    print_out(&summary_text(&l));
                }
            }
            if json {
                print_out(&format!(
                    "{}\n",
                    serde_json::to_string_pretty(&all).unwrap_or_default()
                ));
            }
            if signs {
                print_out("\nSign factors mapping recorded values onto ISO-W (iso = factor · recorded):\n\n");
                print_out(&data::conventions::sign_table_markdown());
            }
            Ok(())
        }
        Command::Convert {
            file,
            to,
            out,
            read,
        } => {
            let l = data::load(&file, &read.options()?)?;
            let text = match to.to_ascii_lowercase().as_str() {
                "csv" => data::csvio::write(&l.recording),
                "tdx" | "tydex" => data::tdx::write(&l.recording),
                other => return Err(Error::Input(format!("--to '{other}': expected csv or tdx"))),
            };
            std::fs::write(&out, text).map_err(|e| Error::io(&out, e))?;
            eprintln!(
                "{}: {} rows, {} segments written to {} ({} rows dropped, warm-up {})",
                file.display(),
                l.recording.samples.len(),
                l.recording.segments.len(),
                out.display(),
                l.report.dropped_total,
                l.report
                    .warmup
                    .as_ref()
                    .map_or("none".to_string(), |w| format!("{} rows cut", w.samples))
            );
            Ok(())
        }
        Command::Plot { file, out, read } => {
            let l = data::load(&file, &read.options()?)?;
            let files = data::plot::plot_recording(&l.recording, &out)?;
            for f in files {
                print_out(&format!("{}\n", f.display()));
            }
            Ok(())
        }
    }
}

/// Print to stdout; a closed pipe (`… | head`) is not an error worth a panic.
fn print_out(text: &str) {
    use std::io::Write;
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
}

fn fmt_range(lo: f64, hi: f64, scale: f64, prec: usize) -> String {
    if !lo.is_finite() {
        return "-".into();
    }
    format!("{:.p$} … {:.p$}", lo * scale, hi * scale, p = prec)
}

/// A number with `prec` decimals, or "-" when the channel is missing (never
/// "NaN" in the summary).
fn num(x: f64, prec: usize) -> String {
    if x.is_finite() {
        format!("{x:.prec$}")
    } else {
        "-".into()
    }
}

fn minmax(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.filter(|x| x.is_finite())
        .fold((f64::NAN, f64::NAN), |(a, b), x| (a.min(x), b.max(x)))
}

/// The text summary of one loaded recording.
pub fn summary_text(l: &Loaded) -> String {
    use std::fmt::Write;
    let r = &l.recording;
    let p = &l.report;
    let mut s = String::new();
    let _ = writeln!(s, "== {}", p.file);
    let _ = writeln!(s, "format {}, axes {} → ISO-W SI", p.format, p.axes);
    for (k, v) in &p.meta {
        let _ = writeln!(s, "  {k}: {v}");
    }
    let _ = writeln!(
        s,
        "rows: {} read, {} dropped, {} kept",
        p.rows_read,
        p.dropped_total,
        r.samples.len()
    );
    for (why, n) in &p.dropped {
        let _ = writeln!(s, "  dropped {n:>8}  {why}");
    }
    let _ = writeln!(s, "channels: {}", r.channels.join(" "));
    let _ = writeln!(
        s,
        "missing:  {}",
        if p.missing.is_empty() {
            "none".into()
        } else {
            p.missing.join(" ")
        }
    );
    if !r.extra.is_empty() {
        let ex: Vec<String> = p
            .extra_units
            .iter()
            .map(|(n, u)| {
                if u.is_empty() {
                    n.clone()
                } else {
                    format!("{n} [{u}]")
                }
            })
            .collect();
        let _ = writeln!(s, "extra:    {}", ex.join(" "));
    }
    let _ = writeln!(s, "kappa:    {}", p.kappa);
    if !p.slip_reference.is_empty() {
        let _ = writeln!(s, "slip ref: {}", p.slip_reference);
    }
    match &p.warmup {
        Some(w) => {
            let _ = writeln!(
                s,
                "warm-up removed: {} rows, t = {:.2} … {:.2} s: {}",
                w.samples, w.t_start, w.t_end, w.reason
            );
        }
        None => {
            let _ = writeln!(s, "warm-up removed: none");
        }
    }
    for n in &p.notes {
        let _ = writeln!(s, "note: {n}");
    }
    for n in &p.rejected {
        let _ = writeln!(s, "warning: {n}");
    }
    let _ = writeln!(s, "\ntest matrix: {} segments", r.segments.len());
    let _ = writeln!(
        s,
        "{:>4} {:<13} {:>9} {:>7} {:>8} {:>7} {:>7} {:>8} {:>8} {:>19} {:>17}",
        "#",
        "kind",
        "Fz [N]",
        "γ [°]",
        "P [kPa]",
        "V[km/h]",
        "α [°]",
        "rows",
        "dur [s]",
        "α range [°]",
        "κ range"
    );
    for (i, g) in r.segments.iter().enumerate() {
        let seg = &r.samples[g.start..g.end];
        let (a0, a1) = minmax(seg.iter().map(|x| x.alpha));
        let (k0, k1) = minmax(seg.iter().map(|x| x.kappa));
        let _ = writeln!(
            s,
            "{:>4} {:<13} {:>9} {:>7} {:>8} {:>7} {:>7} {:>8} {:>8.1} {:>19} {:>17}",
            i,
            g.kind.label(),
            num(g.fz, 0),
            num(g.gamma.to_degrees(), 2),
            num(g.p / 1e3, 1),
            num(g.vx * 3.6, 1),
            if g.alpha.is_finite() {
                format!("{:.2}", g.alpha.to_degrees())
            } else {
                "swept".into()
            },
            g.len(),
            seg.last().map_or(0.0, |x| x.time) - seg[0].time,
            fmt_range(a0, a1, 180.0 / std::f64::consts::PI, 2),
            fmt_range(k0, k1, 1.0, 3)
        );
    }
    let count = |k: SegmentKind| r.segments.iter().filter(|g| g.kind == k).count();
    let _ = writeln!(
        s,
        "segments: {} pure lateral, {} pure longitudinal, {} combined, {} other; {} of {} rows in segments\n",
        count(SegmentKind::PureLateral),
        count(SegmentKind::PureLongitudinal),
        count(SegmentKind::Combined),
        count(SegmentKind::Other),
        r.segments.iter().map(|g| g.len()).sum::<usize>(),
        r.samples.len()
    );
    s
}

/// The machine-readable summary of one loaded recording.
pub fn summary_json(l: &Loaded) -> serde_json::Value {
    serde_json::json!({
        "report": l.report,
        "channels": l.recording.channels,
        "segments": l.recording.segments.iter().map(|g| serde_json::json!({
            "start": g.start, "end": g.end, "kind": g.kind,
            "fz": g.fz, "gamma": g.gamma, "p": g.p, "vx": g.vx,
            "alpha": if g.alpha.is_finite() { Some(g.alpha) } else { None },
        })).collect::<Vec<_>>(),
    })
}
