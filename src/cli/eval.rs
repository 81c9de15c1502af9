//! `tyrekit eval` — evaluate the steady-state Magic Formula over an input CSV
//! and write MFeval's 30 output columns.
//!
//! Input columns (header required, any order, extra columns ignored):
//! `Fz,kappa,alpha,gamma,phit,Vx,P,omega`, or the reference CSV's `in_Fz,…`
//! names. `P` and `omega` may be missing or empty (P → INFLPRES, omega 0 →
//! estimated). Rows are evaluated as one batch (instKya along the rows).
//!
//! Must never: panic on a malformed file; every error names the file, line
//! and column.

use crate::mf::{MfInput, MfOutput, Tyre, UseMode, OUTPUT_COLUMNS};
use crate::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Arguments of `tyrekit eval`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Tyre property file (.tir); the built-in tyre when omitted.
    #[arg(long)]
    pub tir: Option<PathBuf>,
    /// Input CSV with columns Fz,kappa,alpha,gamma,phit,Vx,P,omega (or in_Fz,…).
    #[arg(long)]
    pub input: PathBuf,
    /// Output CSV (MFeval's 30 columns).
    #[arg(long)]
    pub output: PathBuf,
    /// MFeval use mode: hundreds limits (1 on, 2 off), tens α* (1 off, 2 on),
    /// units turn slip (1 off, 2 on).
    #[arg(long, default_value_t = 111)]
    pub use_mode: u32,
    /// Force model: mf (the Magic Formula) or brush (`crate::brush`: Fx, Fy,
    /// Mz from the brush, Mx = 0, the other columns from the MF).
    #[arg(long, default_value = "mf")]
    pub force_model: String,
}

/// Input column names, in `MfInput` order; `required` ones must be present.
const INPUTS: [(&str, bool); 8] = [
    ("Fz", true),
    ("kappa", true),
    ("alpha", true),
    ("gamma", true),
    ("phit", true),
    ("Vx", true),
    ("P", false),
    ("omega", false),
];

/// Read the input CSV into rows of `MfInput`.
pub fn read_inputs(path: &Path) -> Result<Vec<MfInput>> {
    let file = path.display().to_string();
    let err = |line: usize, msg: String| Error::Recording {
        file: file.clone(),
        location: format!("line {line}"),
        message: msg,
    };
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(false)
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| err(1, format!("cannot read: {e}")))?;
    let header = rdr
        .headers()
        .map_err(|e| err(1, format!("cannot read the header: {e}")))?
        .clone();
    // `in_X` first: a reference CSV also has output columns named Fz, P, omega….
    let find = |n: &str| {
        header
            .iter()
            .position(|h| h == format!("in_{n}"))
            .or_else(|| header.iter().position(|h| h == n))
    };
    let mut idx = [None; 8];
    for (k, (name, required)) in INPUTS.iter().enumerate() {
        idx[k] = find(name);
        if idx[k].is_none() && *required {
            return Err(err(
                1,
                format!(
                    "missing column '{name}' (or 'in_{name}'); the header must name Fz,kappa,alpha,gamma,phit,Vx and optionally P,omega; found: {}",
                    header.iter().collect::<Vec<_>>().join(",")
                ),
            ));
        }
    }
    let mut rows = Vec::new();
    for (n, rec) in rdr.records().enumerate() {
        let line = n + 2;
        let rec = rec.map_err(|e| err(line, format!("{e}")))?;
        let mut v = [0.0f64; 8];
        for (k, (name, required)) in INPUTS.iter().enumerate() {
            let Some(i) = idx[k] else { continue };
            let s = rec.get(i).unwrap_or("");
            v[k] = if s.is_empty() && !required {
                0.0
            } else {
                parse_number(s).ok_or_else(|| {
                    err(
                        line,
                        format!(
                            "column '{}': '{s}' is not a number",
                            header.get(i).unwrap_or(name)
                        ),
                    )
                })?
            };
        }
        rows.push(MfInput {
            fz: v[0],
            kappa: v[1],
            alpha: v[2],
            gamma: v[3],
            phit: v[4],
            vx: v[5],
            p: v[6],
            omega: v[7],
        });
    }
    Ok(rows)
}

/// A number, accepting MATLAB/Octave's `NaN`, `Inf`, `-Inf`.
fn parse_number(s: &str) -> Option<f64> {
    match s {
        "NaN" | "nan" => Some(f64::NAN),
        "Inf" | "inf" => Some(f64::INFINITY),
        "-Inf" | "-inf" => Some(f64::NEG_INFINITY),
        _ => s.parse().ok(),
    }
}

/// Shortest round-trip text of a number, with MFeval's NaN/Inf spelling.
fn fmt_number(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x.is_infinite() {
        if x > 0.0 { "Inf" } else { "-Inf" }.into()
    } else {
        format!("{x:?}")
    }
}

/// Write outputs as CSV with the [`OUTPUT_COLUMNS`] header.
pub fn write_outputs(path: &Path, out: &[MfOutput]) -> Result<()> {
    let f = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut w = std::io::BufWriter::new(f);
    let io = |e| Error::io(path, e);
    writeln!(w, "{}", OUTPUT_COLUMNS.join(",")).map_err(io)?;
    for o in out {
        let line: Vec<String> = o.to_array().iter().map(|&x| fmt_number(x)).collect();
        writeln!(w, "{}", line.join(",")).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Run the command.
pub fn run(args: Args) -> Result<()> {
    let mode = UseMode::from_code(args.use_mode).ok_or_else(|| {
        Error::Input(format!(
            "--use-mode {}: expected three digits, hundreds 1|2 (limits), tens 1|2 (alpha*), units 1|2 (turn slip), e.g. 111",
            args.use_mode
        ))
    })?;
    let tyre = match &args.tir {
        Some(p) => super::load_tyre(p)?,
        None => Tyre::builtin(),
    };
    let inputs = read_inputs(&args.input)?;
    let mut out = vec![MfOutput::default(); inputs.len()];
    tyre.evaluate_batch(&inputs, mode, &mut out);
    match crate::brush::ForceModelKind::parse(&args.force_model) {
        Some(crate::brush::ForceModelKind::Mf) => {}
        Some(crate::brush::ForceModelKind::Brush) => brush_columns(&tyre, &inputs, &mut out)?,
        None => {
            return Err(Error::Input(format!(
                "--force-model {}: expected mf or brush",
                args.force_model
            )))
        }
    }
    write_outputs(&args.output, &out)
}

/// Replace Fx, Fy, Mx, Mz by the brush model's (parameters from the file's
/// `[BRUSH]` section, MF-derived defaults), Kxκ/Kyα/μ by its own.
fn brush_columns(tyre: &Tyre, inputs: &[MfInput], out: &mut [MfOutput]) -> Result<()> {
    let (b, d) = crate::brush::BrushParams::from_tyre(tyre)?;
    for n in &d.notes {
        eprintln!("warning: {n}");
    }
    for (i, o) in inputs.iter().zip(out.iter_mut()) {
        let f = b.forces(&crate::brush::BrushInput::new(i.fz, i.kappa, i.alpha.tan()));
        o.fx = f.fx;
        o.fy = f.fy;
        o.mx = 0.0;
        o.mz = if i.vx < 0.0 { -f.mz } else { f.mz };
        let fz = i.fz.max(0.0);
        o.kxk = b.slip_stiffness(fz);
        o.kya = -b.cornering_stiffness(fz);
        o.mux = f.mu_k;
        o.muy = f.mu_k;
    }
    Ok(())
}
