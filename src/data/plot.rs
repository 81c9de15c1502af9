//! plot — SVG pictures of a recording (plotters' SVG backend; text stays SVG
//! `<text>`, no font files needed): the channels over time, and Fy(α),
//! Mz(α) and Fx(κ) per test condition, one curve per load.
//!
//! Must never: draw more than a few thousand points per curve (large
//! recordings are thinned by a stride), or fail on absent channels (their
//! panels/files are skipped).

use super::{Recording, SegmentKind};
use crate::error::{Error, Result};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const MAX_POINTS: usize = 4000;

fn perr(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Other(format!("{}: cannot draw: {e}", path.display()))
}

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    (lo - pad, hi + pad)
}

/// One channel for plotting: name with unit, value from a sample.
type Chan = (&'static str, &'static str, fn(&super::Sample) -> f64);

const TIME_CHANNELS: [Chan; 10] = [
    ("Fz", "Fz [N]", |s| s.fz),
    ("alpha", "alpha [deg]", |s| s.alpha.to_degrees()),
    ("kappa", "kappa [-]", |s| s.kappa),
    ("gamma", "gamma [deg]", |s| s.gamma.to_degrees()),
    ("P", "P [kPa]", |s| s.p / 1e3),
    ("Vx", "Vx [m/s]", |s| s.vx),
    ("Fx", "Fx [N]", |s| s.fx),
    ("Fy", "Fy [N]", |s| s.fy),
    ("Mz", "Mz [Nm]", |s| s.mz),
    ("Mx", "Mx [Nm]", |s| s.mx),
];

/// Draw all pictures of `rec` into `dir`; returns the files written.
pub fn plot_recording(rec: &Recording, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut out = Vec::new();
    out.push(time_plot(rec, dir)?);
    // Condition groups.
    let lat: Vec<usize> = (0..rec.segments.len())
        .filter(|&i| rec.segments[i].kind == SegmentKind::PureLateral)
        .collect();
    let lon: Vec<usize> = (0..rec.segments.len())
        .filter(|&i| {
            matches!(
                rec.segments[i].kind,
                SegmentKind::PureLongitudinal | SegmentKind::Combined
            )
        })
        .collect();
    let key_lat = |i: &usize| {
        let g = &rec.segments[*i];
        (
            (g.p / 1e3).round() as i64,
            (g.gamma.to_degrees() * 10.0).round() as i64,
        )
    };
    let key_lon = |i: &usize| {
        let g = &rec.segments[*i];
        (
            (g.p / 1e3).round() as i64,
            (g.alpha.to_degrees() * 10.0).round() as i64,
        )
    };
    let groups = |idx: &[usize], key: &dyn Fn(&usize) -> (i64, i64)| {
        let mut keys: Vec<(i64, i64)> = idx.iter().map(key).collect();
        keys.sort();
        keys.dedup();
        keys.into_iter()
            .map(|k| {
                (
                    k,
                    idx.iter()
                        .copied()
                        .filter(|i| key(i) == k)
                        .collect::<Vec<_>>(),
                )
            })
            .collect::<Vec<_>>()
    };
    if rec.has("alpha") {
        for ((p, g), segs) in groups(&lat, &key_lat) {
            let tag = format!("p{p}kPa_gamma{:.1}deg", g as f64 / 10.0);
            let cond = format!("P {p} kPa, gamma {:.1} deg", g as f64 / 10.0);
            if rec.has("Fy") {
                out.push(curve_plot(
                    rec,
                    dir,
                    &format!("fy_alpha_{tag}.svg"),
                    &format!("Fy(alpha), {cond}"),
                    &segs,
                    ("alpha [deg]", |s| s.alpha.to_degrees()),
                    ("Fy [N]", |s| s.fy),
                )?);
            }
            if rec.has("Mz") {
                out.push(curve_plot(
                    rec,
                    dir,
                    &format!("mz_alpha_{tag}.svg"),
                    &format!("Mz(alpha), {cond}"),
                    &segs,
                    ("alpha [deg]", |s| s.alpha.to_degrees()),
                    ("Mz [Nm]", |s| s.mz),
                )?);
            }
        }
    }
    if rec.has("kappa") && rec.has("Fx") {
        for ((p, a), segs) in groups(&lon, &key_lon) {
            let tag = format!("p{p}kPa_alpha{:.1}deg", a as f64 / 10.0);
            let cond = format!("P {p} kPa, alpha {:.1} deg", a as f64 / 10.0);
            out.push(curve_plot(
                rec,
                dir,
                &format!("fx_kappa_{tag}.svg"),
                &format!("Fx(kappa), {cond}"),
                &segs,
                ("kappa [-]", |s| s.kappa),
                ("Fx [N]", |s| s.fx),
            )?);
        }
    }
    Ok(out)
}

fn time_plot(rec: &Recording, dir: &Path) -> Result<PathBuf> {
    let path = dir.join("channels_time.svg");
    let chans: Vec<&Chan> = TIME_CHANNELS.iter().filter(|c| rec.has(c.0)).collect();
    let h = 160 * chans.len().max(1) as u32;
    let root = SVGBackend::new(&path, (1200, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| perr(&path, e))?;
    let panels = root.split_evenly((chans.len().max(1), 1));
    let s = &rec.samples;
    let stride = (s.len() / MAX_POINTS).max(1);
    let (t0, t1) = range(s.iter().map(|x| x.time));
    for (c, area) in chans.iter().zip(panels.iter()) {
        let (lo, hi) = range(s.iter().map(c.2));
        let mut ch = ChartBuilder::on(area)
            .margin(6)
            .x_label_area_size(24)
            .y_label_area_size(60)
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(|e| perr(&path, e))?;
        ch.configure_mesh()
            .y_desc(c.1)
            .x_desc("time [s]")
            .light_line_style(WHITE)
            .draw()
            .map_err(|e| perr(&path, e))?;
        ch.draw_series(LineSeries::new(
            s.iter()
                .step_by(stride)
                .map(|x| (x.time, (c.2)(x)))
                .filter(|p| p.1.is_finite()),
            &BLUE,
        ))
        .map_err(|e| perr(&path, e))?;
        // Segment boundaries as light vertical bands' edges.
        for g in &rec.segments {
            let ts = s[g.start].time;
            ch.draw_series(std::iter::once(PathElement::new(
                vec![(ts, lo), (ts, hi)],
                RGBColor(200, 200, 200),
            )))
            .map_err(|e| perr(&path, e))?;
        }
    }
    root.present().map_err(|e| perr(&path, e))?;
    Ok(path.clone())
}

type Axis = (&'static str, fn(&super::Sample) -> f64);

fn curve_plot(
    rec: &Recording,
    dir: &Path,
    file: &str,
    title: &str,
    segs: &[usize],
    x: Axis,
    y: Axis,
) -> Result<PathBuf> {
    let path = dir.join(file);
    let s = &rec.samples;
    let all = || {
        segs.iter()
            .flat_map(|&i| s[rec.segments[i].start..rec.segments[i].end].iter())
    };
    let (x0, x1) = range(all().map(x.1));
    let (y0, y1) = range(all().map(y.1));
    let root = SVGBackend::new(&path, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| perr(&path, e))?;
    let mut ch = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| perr(&path, e))?;
    ch.configure_mesh()
        .x_desc(x.0)
        .y_desc(y.0)
        .draw()
        .map_err(|e| perr(&path, e))?;
    let mut loads: Vec<i64> = segs
        .iter()
        .map(|&i| (rec.segments[i].fz / 10.0).round() as i64 * 10)
        .collect();
    loads.sort();
    loads.dedup();
    for &i in segs {
        let g = &rec.segments[i];
        let li = loads
            .iter()
            .position(|&l| l == (g.fz / 10.0).round() as i64 * 10)
            .unwrap_or(0);
        let col = Palette99::pick(li).to_rgba();
        let n = g.end - g.start;
        let stride = (n / MAX_POINTS).max(1);
        let pts: Vec<(f64, f64)> = s[g.start..g.end]
            .iter()
            .step_by(stride)
            .map(|p| (x.1(p), y.1(p)))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let series = ch
            .draw_series(LineSeries::new(pts, col.stroke_width(1)))
            .map_err(|e| perr(&path, e))?;
        // One legend entry per load (the first segment at that load).
        if segs
            .iter()
            .position(|&j| (rec.segments[j].fz / 10.0).round() == (g.fz / 10.0).round())
            == segs.iter().position(|&j| j == i)
        {
            series
                .label(format!("Fz {:.0} N", g.fz))
                .legend(move |(px, py)| {
                    PathElement::new(vec![(px, py), (px + 16, py)], col.stroke_width(2))
                });
        }
    }
    ch.configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| perr(&path, e))?;
    root.present().map_err(|e| perr(&path, e))?;
    Ok(path.clone())
}
