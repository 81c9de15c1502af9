//! provenance (command side) — the lines a command adds to the header of
//! the `.tir` it writes ([`crate::tir::provenance`]): the fitted stages, σ
//! and NRMSE per channel as the fit report computed them, and the geometry
//! keys set or left undetermined.
//!
//! Must never: invent a figure (only what the report holds is written).

use crate::fit::mf_fit::MfFit;
use crate::fit::{ChannelMetric, FitReport};
use crate::tir::provenance::Provenance;
use crate::tir::TyreParams;
use crate::Result;
use std::path::PathBuf;

/// "Fy σ 3.90 % NRMSE 2.10 % (n 1234)" for each overall channel metric.
fn quality(m: &[ChannelMetric]) -> Vec<String> {
    m.iter()
        .filter(|x| x.condition.is_none())
        .map(|x| {
            format!(
                "{} σ {:.2} % NRMSE {:.2} % (n {})",
                x.channel,
                100.0 * x.sigma,
                100.0 * x.nrmse,
                x.n
            )
        })
        .collect()
}

/// Header lines of a fit report: stages, in-sample and held-out quality.
pub fn report_lines(r: &FitReport) -> Vec<String> {
    let mut v = Vec::new();
    let stages: Vec<&str> = r.stages.iter().map(|s| s.stage.as_str()).collect();
    v.push(format!(
        "fitted stages: {}{}",
        if stages.is_empty() {
            "none".to_string()
        } else {
            stages.join(", ")
        },
        if r.relaxation.is_empty() {
            ""
        } else {
            ", relaxation lengths"
        }
    ));
    let q = quality(&r.metrics);
    if !q.is_empty() {
        v.push(format!("quality on the fitted data: {}", q.join("; ")));
    }
    let h = quality(&r.holdout_metrics);
    if !h.is_empty() {
        v.push(format!("quality on the held-out data: {}", h.join("; ")));
    }
    v
}

/// Stamp a fitted tyre: command, inputs with SHA-256, stages, quality,
/// skipped stages, the gated stages' decisions and held terms, geometry.
pub fn stamp_fit(tyre: &mut TyreParams, inputs: &[PathBuf], fit: &MfFit) -> Result<()> {
    let mut p = Provenance::of_inputs(inputs)?;
    p.lines = report_lines(&fit.report);
    p.lines
        .extend(fit.skipped.iter().map(|s| format!("stage skipped: {s}")));
    p.lines.extend(fit.decisions.iter().cloned());
    if let Some(g) = &fit.geometry {
        p.lines.extend(g.lines());
    }
    p.stamp(tyre);
    Ok(())
}
