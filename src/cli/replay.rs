//! `tyrekit replay` — step a recording's measured inputs through the tyre
//! model the FMU runs and write measured and simulated forces side by side
//! (see [`crate::residual::replay`] for the time base and the resets).
//!
//! Must never: panic on a bad file or flag (errors name the file and flag).

use crate::mf::UseMode;
use crate::residual::{replay, write_csv, ReplayOptions};
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
    /// Transient model: file (as the tyre file's [TYREKIT] TRANSIENT says, steady when it says nothing) | steady | relaxation | lugre.
    #[arg(long, default_value = "file")]
    pub transient: String,
    /// MFeval use mode (hundreds limits 1 on/2 off, tens α* 1 off/2 on, units turn slip).
    #[arg(long, default_value_t = 111)]
    pub use_mode: u32,
    /// How to read the recording (`--re model` uses --tir's Re(Fz)).
    #[command(flatten)]
    pub read: crate::cli::data::RecordingArgs,
    /// Steady-state force model under the transient model: mf or brush.
    #[arg(long, default_value = "mf")]
    pub force_model: String,
}

/// Run the command.
pub fn run(a: Args) -> Result<()> {
    let use_mode = UseMode::from_code(a.use_mode).ok_or_else(|| {
        Error::Input(format!(
            "--use-mode {}: expected three digits, each 1 or 2 (e.g. 111)",
            a.use_mode
        ))
    })?;
    let from_file = a
        .transient
        .trim()
        .eq_ignore_ascii_case(TransientKind::FROM_FILE);
    if !from_file && TransientKind::parse(&a.transient).is_none() {
        return Err(Error::Input(format!(
            "--transient {}: expected file (as the tyre file says), steady, relaxation or lugre",
            a.transient
        )));
    }
    let tyre = super::load_tyre(&a.tir)?;
    // "file": the tyre file's [TYREKIT] TRANSIENT (a bad value there is
    // an error naming the file and key), steady without one.
    let kind = TransientKind::resolve(&a.transient, tyre.params())?;
    let load = a.read.options(Some(&tyre), "--tir")?;
    let rec = crate::cli::data::load_all(std::slice::from_ref(&a.recording), &load, "replay")?
        .remove(0)
        .recording;
    let brush = match crate::brush::ForceModelKind::parse(&a.force_model) {
        Some(crate::brush::ForceModelKind::Mf) => None,
        Some(crate::brush::ForceModelKind::Brush) => {
            Some(crate::brush::BrushParams::from_tyre(&tyre)?.0)
        }
        None => {
            return Err(Error::Input(format!(
                "--force-model {}: expected mf or brush",
                a.force_model
            )))
        }
    };
    // As the FMU runs by default: κ from the wheel speed where recorded.
    let mut opts = ReplayOptions {
        kind,
        use_mode,
        wheel_speed: true,
        ..Default::default()
    };
    opts.options.brush = brush;
    let mode = crate::residual::input_mode(&rec, &opts);
    let rp = replay(&rec, &tyre, &opts)?;
    let f = std::fs::File::create(&a.out).map_err(|e| Error::io(&a.out, e))?;
    write_csv(&rec, &rp, f).map_err(|e| Error::io(&a.out, e))?;
    eprintln!(
        "replayed {} samples ({} runs, {} skipped) with {} model, {} -> {}",
        rec.samples.len(),
        rp.runs.len(),
        rp.skipped,
        kind.name(),
        match mode {
            crate::transient::InputMode::Velocities
                if rec.extra(crate::data::slip::SLIP_RADIUS_CHANNEL).is_some() =>
                "κ from the wheel speed the rig's slip ratio SR implies (Vx·(1 + SR)/Re_SR) and the tyre's Re(Fz)",
            crate::transient::InputMode::Velocities =>
                "κ from the wheel speed and the tyre's Re(Fz)",
            crate::transient::InputMode::Slips => "slips as recorded (no wheel speed)",
        },
        a.out.display()
    );
    Ok(())
}
