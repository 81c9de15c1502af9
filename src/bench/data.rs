//! Benchmark section `data`: how fast recordings load (the issue asks for a
//! million rows in under 2 s) and how fast the rig simulator runs a standard
//! programme (~120 000 samples at 100 Hz).
//! Must never: assert on a timing (figures are printed, machines are noisy).

use crate::data::{load, LoadOptions};
use crate::error::{Error, Result};
use crate::mf::Tyre;
use crate::rig::{simulate, RigConfig, SteadyMf};
use std::time::Instant;

/// Run this section, printing its figures.
pub fn run(ctx: &super::BenchContext) -> Result<()> {
    let tyre = Tyre::builtin();
    // Rig: the standard programme at 100 Hz.
    let cfg = RigConfig::standard(&tyre, 1);
    let t0 = Instant::now();
    let run = simulate(&cfg, &mut SteadyMf::new(tyre.clone()));
    println!(
        "[data] rig: standard programme, {} samples, {} segments: {:.3} s",
        run.rows(),
        run.plan.len(),
        t0.elapsed().as_secs_f64()
    );
    // Loading: the same programme at a rate giving ~1e6 rows (1e5 with --quick).
    let target = if ctx.quick { 100_000.0 } else { 1_000_000.0 };
    let mut big = RigConfig::standard(&tyre, 2);
    big.sample_rate = 100.0 * target / run.rows() as f64;
    let r = simulate(&big, &mut SteadyMf::new(tyre));
    let scratch = super::ScratchDir::new("data")?;
    let dir = scratch.path();
    let mat = dir.join("big.mat");
    let dat = dir.join("big.dat");
    r.write_mat(&mat, true)?;
    r.write_dat(&dat)?;
    // The clean 14-column ISO CSV of the same rows.
    let l = load(&mat, &LoadOptions::default())?;
    let csv = dir.join("big.csv");
    std::fs::write(&csv, crate::data::csvio::write(&l.recording))
        .map_err(|e| Error::io(&csv, e))?;
    for (what, p) in [
        ("TTC .mat (zlib)", &mat),
        ("TTC .dat", &dat),
        ("ISO CSV", &csv),
    ] {
        let bytes = std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
        let t0 = Instant::now();
        let l = load(p, &LoadOptions::default())?;
        println!(
            "[data] load {what:<16} {:>8} rows, {:>4} MB: {:.3} s (read, units, signs, κ, warm-up, {} segments)",
            l.report.rows_read,
            bytes / 1_000_000,
            t0.elapsed().as_secs_f64(),
            l.recording.segments.len()
        );
    }
    Ok(())
}
