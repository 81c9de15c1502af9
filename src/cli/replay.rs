//! `tyrekit replay` — step a recording's measured inputs through the tyre
//! model the FMU runs and write measured and simulated forces side by side
//! (see [`crate::diagnose::replay`] for the time base and the resets).
//!
//! Must never: panic on a bad file or flag (errors name the file and flag).

use crate::diagnose::replay::{replay, write_csv, ReplayOptions};
use crate::mf::UseMode;
use crate::transient::TransientKind;
use crate::{Error, Result};
use std::path::PathBuf;

/// Arguments of `tyrekit replay`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The recording (TTC .mat/.dat, TYDEX, CSV).
    pub recording: PathBuf,
    /// Tyre property file (.tir).
    #[arg(long)]
    pub tir: PathBuf,
    /// Output CSV: time,Fx,Fy,Mz,Fx_sim,Fy_sim,Mz_sim[,Mx,My,Mx_sim,My_sim] (ISO-W, SI).
    #[arg(long)]
    pub out: PathBuf,
    /// Transient model: steady | relaxation | lugre.
    #[arg(long, default_value = "steady")]
    pub transient: String,
    /// MFeval use mode (hundreds limits 1 on/2 off, tens α* 1 off/2 on, units turn slip).
    #[arg(long, default_value_t = 111)]
    pub use_mode: u32,
}

/// Run the command.
pub fn run(a: Args) -> Result<()> {
    let kind = TransientKind::parse(&a.transient).ok_or_else(|| {
        Error::Input(format!(
            "--transient {}: expected steady, relaxation or lugre",
            a.transient
        ))
    })?;
    let use_mode = UseMode::from_code(a.use_mode).ok_or_else(|| {
        Error::Input(format!(
            "--use-mode {}: expected three digits, each 1 or 2 (e.g. 111)",
            a.use_mode
        ))
    })?;
    let tyre = super::load_tyre(&a.tir)?;
    let rec = crate::data::Recording::from_file(&a.recording)?;
    let opts = ReplayOptions {
        kind,
        use_mode,
        ..Default::default()
    };
    let rp = replay(&rec, &tyre, &opts)?;
    let f = std::fs::File::create(&a.out).map_err(|e| Error::io(&a.out, e))?;
    write_csv(&rec, &rp, f).map_err(|e| Error::io(&a.out, e))?;
    eprintln!(
        "replayed {} samples ({} runs, {} skipped) with {} model -> {}",
        rec.samples.len(),
        rp.runs.len(),
        rp.skipped,
        kind.name(),
        a.out.display()
    );
    Ok(())
}
