//! `tyrekit diagnose` — arguments and dispatch: replay, locate, evaluate the
//! candidate extensions, write `DIR/diagnosis.json`, `DIR/baseline.tir` and
//! `DIR/extended.tir` (see [`crate::diagnose::report`]).
//!
//! Current state: the baseline must be given with `--tir` (fitting the
//! baseline MF 6.1 from the recording is not wired yet); candidates `none`
//! and `relaxation`; no HTML report or plots yet.
//!
//! Must never: panic on bad input (errors name the file or flag).

use crate::diagnose::replay::ReplayOptions;
use crate::diagnose::report::{diagnose, merge};
use crate::mf::Tyre;
use crate::{Error, Result};
use std::path::PathBuf;

/// Arguments of `tyrekit diagnose`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Recordings (TTC .mat/.dat, TYDEX, CSV); merged with a gap between them.
    #[arg(required = true)]
    pub recordings: Vec<PathBuf>,
    /// Report directory (created).
    #[arg(long)]
    pub report: PathBuf,
    /// Baseline tyre (.tir).
    #[arg(long)]
    pub tir: Option<PathBuf>,
}

/// Run the command.
pub fn run(a: Args) -> Result<()> {
    let Some(tir) = &a.tir else {
        return Err(Error::Input(
            "diagnose: fitting the baseline from the recording is not wired yet; pass --tir base.tir".into(),
        ));
    };
    let tyre = Tyre::from_file(tir)?;
    let mut recs = Vec::new();
    for p in &a.recordings {
        recs.push(crate::data::Recording::from_file(p)?);
    }
    let rec = merge(recs);
    std::fs::create_dir_all(&a.report).map_err(|e| Error::io(&a.report, e))?;
    let d = diagnose(&rec, &tyre, &ReplayOptions::default())?;
    tyre.params().write(&a.report.join("baseline.tir"))?;
    d.extended.params().write(&a.report.join("extended.tir"))?;
    let jp = a.report.join("diagnosis.json");
    let text = serde_json::to_string_pretty(&d.json)
        .map_err(|e| Error::Other(format!("diagnosis.json: {e}")))?;
    std::fs::write(&jp, text).map_err(|e| Error::io(&jp, e))?;
    println!("verdict: {} ({})", d.verdict, jp.display());
    Ok(())
}
