//! Benchmark section `diagnose`: wall time of `replay` (steady, relaxation),
//! of `locate` (one channel) and of the whole `diagnose` pipeline on a rig
//! recording of the standard programme (~120 000 samples; `--quick`: one
//! pressure, ~40 000). Goal (issue 7): diagnose of 150 000 samples ≤ 60 s,
//! all candidates included — only `none` and `relaxation` exist so far, so
//! the figure is a lower bound until the other candidates land.
//!
//! Must never: assert on timings (figures are reported, not checked).

use crate::diagnose::locate::frictional_energy;
use crate::diagnose::replay::{replay, ReplayOptions};
use crate::diagnose::report::{diagnose, locate_channel};
use crate::mf::Tyre;
use crate::rig::{effects, simulate, RigConfig};
use crate::transient::TransientKind;
use std::time::Instant;

/// Run this section, printing its figures.
pub fn run(ctx: &super::BenchContext) -> crate::Result<()> {
    let tyre = Tyre::builtin();
    let mut cfg = RigConfig::standard(&tyre, 1);
    if ctx.quick {
        cfg.programme.pressures.truncate(1);
    }
    let mut truth = effects::concealed("relaxation", tyre.clone(), 1.0)
        .ok_or_else(|| crate::Error::Other("no relaxation effect".into()))?;
    let run = simulate(&cfg, truth.as_mut());
    let dir = std::env::temp_dir().join(format!("tyrekit-bench-diag-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| crate::Error::io(&dir, e))?;
    let path = dir.join("rig.mat");
    run.write_mat(&path, false)?;
    let rec = crate::data::Recording::from_file(&path)?;
    let _ = std::fs::remove_dir_all(&dir);
    let n = rec.samples.len();
    println!(
        "[diagnose] recording: {n} samples, {} segments",
        rec.segments.len()
    );
    for kind in [TransientKind::Steady, TransientKind::Relaxation] {
        let o = ReplayOptions {
            kind,
            ..Default::default()
        };
        let t0 = Instant::now();
        let r = replay(&rec, &tyre, &o)?;
        let s = t0.elapsed().as_secs_f64();
        println!(
            "[diagnose] replay {:<10} {:8.3} s  ({:.0} ns/sample, {} runs)",
            kind.name(),
            s,
            s * 1e9 / n as f64,
            r.runs.len()
        );
    }
    let base = replay(&rec, &tyre, &ReplayOptions::default())?;
    let t0 = Instant::now();
    let e = frictional_energy(&rec);
    let f = locate_channel(&rec, &base.sim, &e, "FY");
    println!(
        "[diagnose] locate FY (999 permutations) {:8.3} s  (top: {})",
        t0.elapsed().as_secs_f64(),
        f.first().map_or("-", |x| x.name)
    );
    let t0 = Instant::now();
    let d = diagnose(&rec, &tyre, &ReplayOptions::default())?;
    let s = t0.elapsed().as_secs_f64();
    println!(
        "[diagnose] diagnose (candidates none, relaxation) {s:8.3} s, {:.1} s per 150 000 samples (goal ≤ 60 s); verdict {}",
        s * 150_000.0 / n as f64,
        d.verdict
    );
    Ok(())
}
