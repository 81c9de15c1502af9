//! Plots of a fitted tyre against the recording it was fitted to: one SVG per
//! (channel, test condition) with the measured points and the model curve at
//! the condition's set points (what `tyrekit fit` writes beside `fit.json`).
//! Must never: change the tyre or the recording (it only draws them).

use crate::data::{Recording, SegmentKind};
use crate::fit::metrics::{condition_groups, Condition};
use crate::fit::mf_stages::{Channel, StageKind, FIT_MODE};
use crate::mf::{MfInput, Tyre};
use crate::{Error, Result};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

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
            for group in condition_groups(rec) {
                let cond = group.condition;
                let segs: Vec<_> = group
                    .segments
                    .iter()
                    .map(|&k| &rec.segments[k])
                    .filter(|s| s.kind == seg_kind)
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
