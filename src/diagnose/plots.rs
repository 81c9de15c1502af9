//! plots — the pictures of a diagnosis (plotters' SVG backend, text as SVG
//! `<text>`, no font files), one set per force channel the recording has:
//! * `residual_slip_CH.svg` — residual map: measured − model against the
//!   driving slip, coloured by load, baseline beside extended model;
//! * `residual_load_CH.svg` — per segment the relative force scale error
//!   (Σ r·F / Σ F², the statistic of [`super::locate`]) against load,
//!   baseline and extended (a load, pressure or friction error shows as a
//!   trend or an offset);
//! * `hysteresis_CH.svg` — the residual binned over slip for rising and for
//!   falling sweeps: a lag opens a loop between them;
//! * `drift_CH.svg` — the signed residual (+ = measured stronger) against
//!   time in the run and per segment against the accumulated frictional
//!   energy: a temperature or wear state drifts;
//! * `overlay_CH.svg` — measured, baseline and extended model against slip
//!   (Fy–α, Mz–α, Fx–κ) per load level, lightest first: at each level the
//!   held-out segment the verdict changes most (a fitted one, marked, where
//!   the level has none held out);
//! * `before_after_CH.svg` (a verdict other than `none`) — per condition of
//!   the held-out half (load, inclination, pressure) the NRMSE of the
//!   baseline and of the extended model against the load in kN;
//! * `residual_pressure_CH.svg` (verdict `pressure` only) — per segment the
//!   relative force scale error against the segment's mean recorded
//!   pressure (kPa), baseline and extended: the verdict's own evidence;
//! * `residual_speed_CH.svg` (verdict `speed_friction` only) — the same
//!   against the segment's belt speed (km/h);
//! * `residual_inclination_CH.svg` (verdict `camber` only) — the same
//!   against the segment's inclination (degrees);
//! * `slip_channel.svg` (when the recorded slip ratio disagrees with the
//!   free-rolling radius, [`super::slip_channel`]) — per load level the
//!   wheel's own V/Ω, the radius SR was computed with and the baseline's and
//!   extended file's Re(Fz) in mm; beside it the free-rolling SR read as a
//!   force, K_x·(SR − mean SR)/Fz in % of Fz: the `rolling_radius` evidence.
//!
//! The list comes back ordered for the reader (issue #15: plots first, the
//! evidence for the verdict against the verdict's own variable first of
//! all): the verdict's evidence plots (`evidence_stems`), the channel the
//! verdict gains most in held out first, then the rest in the order above.
//!
//! Must never: draw more than a few thousand points per series (strided),
//! or fail on a channel the recording lacks (it is skipped).

use super::report::{channel_present, channel_series, split, Diagnosis};
use crate::data::Recording;
use crate::error::{Error, Result};
use crate::fit::metrics::same_load_level;
use crate::residual::Channel;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Most points drawn per scatter series.
const MAX_POINTS: usize = 4000;
/// Slip bins of the hysteresis and drift curves.
const BINS: usize = 30;

/// A picture written into the report directory.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Plot {
    /// File name inside the report directory.
    pub file: String,
    /// Report key of the channel drawn ("FX", "FY", "MZ").
    pub channel: &'static str,
    /// What to look for, one sentence.
    pub caption: String,
}

/// One thing to draw in a panel.
enum Series {
    /// Points, colour, legend label, radius (px).
    Points(Vec<(f64, f64)>, RGBColor, String, u32),
    Line(Vec<(f64, f64)>, RGBColor, u32, String),
}

const GREY: RGBColor = RGBColor(150, 150, 150);
const BASE: RGBColor = RGBColor(31, 119, 180);
const EXT: RGBColor = RGBColor(214, 39, 40);
const RISE: RGBColor = RGBColor(31, 119, 180);
const FALL: RGBColor = RGBColor(255, 127, 14);

fn perr(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Other(format!("{}: cannot draw: {e}", path.display()))
}

fn span<'a>(pts: impl Iterator<Item = &'a (f64, f64)>) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts {
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 > x1 {
        return ((-1.0, 1.0), (-1.0, 1.0));
    }
    let pad = |a: f64, b: f64| ((b - a) * 0.05).max(1e-9 * a.abs().max(b.abs()).max(1e-9));
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    ((x0 - px, x1 + px), (y0 - py, y1 + py))
}

/// Draw `series` into `area` with a title and axis labels; `yr` forces a
/// common y range (panels compared side by side).
fn panel(
    area: &DrawingArea<SVGBackend, Shift>,
    path: &Path,
    title: &str,
    xl: &str,
    yl: &str,
    series: &[Series],
    yr: Option<(f64, f64)>,
) -> Result<()> {
    let all = series.iter().flat_map(|s| match s {
        Series::Points(p, ..) | Series::Line(p, ..) => p.iter(),
    });
    let ((x0, x1), (mut y0, mut y1)) = span(all);
    if let Some((a, b)) = yr {
        (y0, y1) = (a, b);
    }
    let mut ch = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| perr(path, e))?;
    ch.configure_mesh()
        .x_desc(xl)
        .y_desc(yl)
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(|e| perr(path, e))?;
    let mut labelled = false;
    for s in series {
        match s {
            Series::Points(p, c, label, r) => {
                let (c, r) = (*c, *r);
                let a = ch
                    .draw_series(p.iter().map(move |&q| Circle::new(q, r, c.filled())))
                    .map_err(|e| perr(path, e))?;
                if !label.is_empty() {
                    labelled = true;
                    a.label(label.clone())
                        .legend(move |(x, y)| Circle::new((x + 8, y), 3, c.filled()));
                }
            }
            Series::Line(p, c, w, label) => {
                let (c, w) = (*c, *w);
                let a = ch
                    .draw_series(LineSeries::new(p.iter().copied(), c.stroke_width(w)))
                    .map_err(|e| perr(path, e))?;
                if !label.is_empty() {
                    labelled = true;
                    a.label(label.clone()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2))
                    });
                }
            }
        }
    }
    if labelled {
        ch.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| perr(path, e))?;
    }
    Ok(())
}

/// The panels of a figure.
type Areas<'a> = [DrawingArea<SVGBackend<'a>, Shift>];
/// A curve as (x, y) points.
type Curve = Vec<(f64, f64)>;

/// A figure of `cols` panels side by side.
fn figure(path: &Path, cols: usize, draw: &dyn Fn(&Areas) -> Result<()>) -> Result<()> {
    figure_grid(path, 1, cols, draw)
}

/// A figure of `rows` × `cols` panels, filled row by row.
fn figure_grid(
    path: &Path,
    rows: usize,
    cols: usize,
    draw: &dyn Fn(&Areas) -> Result<()>,
) -> Result<()> {
    let size = (560 * cols as u32, 440 * rows as u32);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| perr(path, e))?;
    let areas = root.split_evenly((rows, cols));
    draw(&areas)?;
    root.present().map_err(|e| perr(path, e))?;
    Ok(())
}

/// `x` rounded to a tenth, without a negative zero ("-0.0°").
fn tenth(x: f64) -> f64 {
    (x * 10.0).round() / 10.0 + 0.0
}

/// Per condition (load, inclination, pressure) the held-out NRMSE of the
/// baseline and of the extended model against the condition's load in kN:
/// the before/after of the verdict per condition, drawn from the quality
/// table's held-out rows. `None` when the channel has no condition rows.
fn before_after(
    rows: &[super::report::QualityRow],
    c: &Chan,
    verdict: &str,
    dir: &Path,
) -> Result<Option<Plot>> {
    let pts = |after: bool| -> Curve {
        rows.iter()
            .filter(|r| r.channel == c.ch)
            .filter_map(|r| {
                let v = if after { r.nrmse_after } else { r.nrmse_before };
                r.fz.map(|fz| (fz / 1e3, 100.0 * v))
            })
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect()
    };
    let (b, a) = (pts(false), pts(true));
    if b.is_empty() {
        return Ok(None);
    }
    let file = format!("before_after_{}.svg", c.name.to_lowercase());
    let path = dir.join(&file);
    let lo = b
        .iter()
        .chain(&a)
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min);
    let hi = b.iter().chain(&a).map(|p| p.1).fold(0.0, f64::max);
    let yr = (0.0f64.min(lo), 1.05 * hi);
    figure(&path, 1, &|ar| {
        panel(
            &ar[0],
            &path,
            &format!("{} held-out NRMSE per condition", c.ch.name()),
            "Fz (condition) [kN]",
            "NRMSE [%]",
            &[
                Series::Points(b.clone(), BASE, "baseline".into(), 4),
                Series::Points(a.clone(), EXT, after_label(verdict), 3),
            ],
            Some(yr),
        )
    })?;
    Ok(Some(Plot {
        file,
        channel: c.name,
        caption: format!(
            "Before and after per condition: each load, inclination and pressure of the held-out half, the {} NRMSE of the baseline (blue) and of the extended model (red) against the load; red below blue is where the verdict helps.",
            c.ch.name()
        ),
    }))
}

/// Most panels of the per-load overlay (a programme has 3–6 load levels).
const MAX_PANELS: usize = 6;

/// The load levels (N) of a programme's segment loads, lightest first: a
/// new level where a load is not [`same_load_level`] as the last level's first
/// load; each level its first (lightest) load.
fn load_levels(fz: impl Iterator<Item = f64>) -> Vec<f64> {
    crate::stats::anchored_levels(fz, |x| *x, same_load_level)
        .into_iter()
        .map(|l| l[0])
        .collect()
}

/// Common y range of several point sets (robust: 0.5 % / 99.5 % quantiles,
/// so a few wild samples do not flatten the picture).
fn common_range(sets: &[&[(f64, f64)]]) -> (f64, f64) {
    let mut v: Vec<f64> = sets
        .iter()
        .flat_map(|s| s.iter().map(|p| p.1))
        .filter(|y| y.is_finite())
        .collect();
    if v.is_empty() {
        return (-1.0, 1.0);
    }
    v.sort_by(f64::total_cmp);
    let q = |f: f64| v[((v.len() - 1) as f64 * f) as usize];
    let (a, b) = (q(0.005), q(0.995));
    let pad = ((b - a) * 0.08).max(1e-9);
    (a - pad, b + pad)
}

/// Per-sample data of one channel for the plots.
struct Chan<'a> {
    ch: Channel,
    /// The channel's report key ("FY"), as in `diagnosis.json`.
    name: &'static str,
    unit: &'static str,
    meas: Vec<f64>,
    base: Vec<f64>,
    ext: Vec<f64>,
    slip: Vec<f64>,
    slip_label: &'static str,
    rec: &'a Recording,
}

impl Chan<'_> {
    fn r(&self, i: usize, after: bool) -> f64 {
        self.meas[i] - if after { self.ext[i] } else { self.base[i] }
    }
    fn slip_deg(&self, i: usize) -> f64 {
        if self.ch == Channel::Fx {
            self.slip[i]
        } else {
            self.slip[i].to_degrees()
        }
    }
    /// Sample indices inside segments, strided to at most `max`.
    fn inside(&self, max: usize) -> Vec<usize> {
        let n: usize = self.rec.segments.iter().map(|g| g.len()).sum();
        let k = (n / max).max(1);
        let mut v = Vec::new();
        for g in &self.rec.segments {
            v.extend((g.start..g.end.min(self.meas.len())).step_by(k));
        }
        v.retain(|&i| self.meas[i].is_finite() && self.base[i].is_finite());
        v
    }
}

/// Draw every picture of the diagnosis into `dir`.
pub fn draw_all(rec: &Recording, d: &Diagnosis, dir: &Path) -> Result<Vec<Plot>> {
    let mut out = Vec::new();
    for ch in Channel::SCORED {
        let (name, unit) = (ch.key(), ch.unit());
        if !channel_present(rec, ch) {
            continue;
        }
        let (meas, base, slip) = channel_series(rec, &d.baseline_sim, ch);
        let (_, ext, _) = channel_series(rec, &d.extended_sim, ch);
        let c = Chan {
            ch,
            name,
            unit,
            meas,
            base,
            ext,
            slip,
            slip_label: if ch == Channel::Fx {
                "kappa [-]"
            } else {
                "alpha [deg]"
            },
            rec,
        };
        if c.inside(10).is_empty() {
            continue;
        }
        out.push(residual_slip(&c, d.verdict(), dir)?);
        out.push(residual_load(&c, d.verdict(), dir)?);
        out.push(hysteresis(&c, d.verdict(), dir)?);
        out.push(drift(&c, &d.energy, d.verdict(), dir)?);
        out.push(overlay(&c, d.verdict(), dir)?);
        if d.verdict() != "none" {
            if let Some(p) = before_after(&d.report.quality.out_of_sample, &c, d.verdict(), dir)? {
                out.push(p);
            }
        }
        match d.verdict() {
            "pressure" => out.push(residual_pressure(&c, d.verdict(), dir)?),
            "speed_friction" => out.push(residual_speed(&c, d.verdict(), dir)?),
            "camber" => out.push(residual_inclination(&c, d.verdict(), dir)?),
            _ => {}
        }
    }
    if let Some(sc) = d.report.slip_channel.as_ref().filter(|s| s.found) {
        out.push(slip_channel(sc, dir)?);
    }
    // The verdict's channels by its held-out gain, best first.
    let gain = |ch: &str| {
        d.report
            .effects
            .iter()
            .find(|e| e.name == d.verdict())
            .and_then(|e| e.channels.iter().find(|c| c.channel.key() == ch))
            .map_or(f64::NEG_INFINITY, |c| c.oos_gain)
    };
    Ok(reader_order(out, evidence_stems(d.verdict()), gain))
}

/// The file-name stems of the plots that show `verdict`'s own evidence,
/// most telling first: the residual against the verdict's own variable
/// (pressure, belt speed, inclination, load), rising against falling
/// sweeps for a lag, drift against frictional energy for a temperature
/// state, the free-rolling slip for a radius.
pub(crate) fn evidence_stems(verdict: &str) -> &'static [&'static str] {
    match verdict {
        "pressure" => &["residual_pressure"],
        "speed_friction" => &["residual_speed", "residual_slip"],
        "camber" => &["residual_inclination"],
        "load_sensitivity" => &["residual_load"],
        "relaxation" | "lugre" => &["hysteresis"],
        "thermal" => &["drift"],
        "rolling_radius" => &["slip_channel"],
        _ => &[],
    }
}

/// `plots` reordered for the reader: those whose file starts with one of
/// `stems` first (by stem, then by `gain` of their channel, highest first),
/// then the others in the order drawn. Stable.
fn reader_order(plots: Vec<Plot>, stems: &[&str], gain: impl Fn(&str) -> f64) -> Vec<Plot> {
    let rank = |p: &Plot| {
        stems
            .iter()
            .position(|s| p.file.starts_with(s))
            .unwrap_or(stems.len())
    };
    let mut evidence: Vec<Plot> = plots
        .iter()
        .filter(|p| rank(p) < stems.len())
        .cloned()
        .collect();
    evidence.sort_by(|a, b| {
        rank(a)
            .cmp(&rank(b))
            .then(gain(b.channel).total_cmp(&gain(a.channel)))
    });
    evidence.extend(plots.into_iter().filter(|p| rank(p) == stems.len()));
    evidence
}

/// The rolling-radius evidence from the data channels (see the module docs).
fn slip_channel(sc: &super::slip_channel::SlipChannel, dir: &Path) -> Result<Plot> {
    let file = "slip_channel.svg".to_string();
    let path = dir.join(&file);
    let kn = |f: &dyn Fn(&super::slip_channel::Level) -> f64| -> Vec<(f64, f64)> {
        sc.levels
            .iter()
            .map(|l| (l.fz / 1e3, f(l)))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    let own = kn(&|l| 1e3 * l.re_free);
    let mean = sc.levels.iter().map(|l| l.sr).sum::<f64>() / sc.levels.len().max(1) as f64;
    let share = kn(&|l| 100.0 * l.kx * (l.sr - mean) / l.fz);
    let bound = 100.0 * super::slip_channel::FORCE_SHARE;
    let (x0, x1) = (
        own.first().map_or(0.0, |p| p.0),
        own.last().map_or(1.0, |p| p.0),
    );
    figure(&path, 2, &|a| {
        panel(
            &a[0],
            &path,
            "free-rolling radius against load",
            "Fz [kN]",
            "radius [mm]",
            &[
                Series::Points(
                    own.clone(),
                    GREY,
                    "V/Omega at free rolling (the tyre's)".into(),
                    4,
                ),
                Series::Line(
                    kn(&|l| 1e3 * l.re_slip),
                    RGBColor(44, 160, 44),
                    2,
                    "radius SR was computed with".into(),
                ),
                Series::Line(
                    kn(&|l| 1e3 * l.re_base),
                    BASE,
                    2,
                    "baseline file Re(Fz)".into(),
                ),
                Series::Line(
                    kn(&|l| 1e3 * l.re_extended),
                    EXT,
                    2,
                    "extended file Re(Fz)".into(),
                ),
            ],
            None,
        )?;
        panel(
            &a[1],
            &path,
            "free-rolling SR read as slip: Kx (SR - mean)/Fz",
            "Fz [kN]",
            "Fx [% of Fz]",
            &[
                Series::Points(share.clone(), EXT, "per load level".into(), 4),
                Series::Line(
                    vec![(x0, bound), (x1, bound)],
                    GREY,
                    1,
                    "finding bound (5 %)".into(),
                ),
                Series::Line(vec![(x0, -bound), (x1, -bound)], GREY, 1, String::new()),
            ],
            None,
        )
    })?;
    Ok(Plot {
        file,
        channel: "FX",
        caption: format!(
            "Rolling radius from the data channels: at free rolling the wheel's own radius V/Ω (grey) and the radius the recorded slip ratio SR assumes (green) part with load; read as slip, SR would give Fx up to {:.0} % of Fz (right; the finding bound is 5 %). The extended file's Re(Fz) (red) follows the tyre's radius, the baseline's (blue) the slip channel's.",
            100.0 * sc.force_share
        ),
    })
}

fn after_label(verdict: &str) -> String {
    if verdict == "none" {
        "extended = baseline (verdict none)".into()
    } else {
        format!("extended ({verdict})")
    }
}

fn residual_slip(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    let file = format!("residual_slip_{}.svg", c.name.to_lowercase());
    let path = dir.join(&file);
    let idx = c.inside(MAX_POINTS);
    let loads = load_levels(c.rec.segments.iter().map(|g| g.fz));
    let level_of = |fz: f64| loads.iter().position(|&l| same_load_level(l, fz));
    let seg_of = segment_index(c.rec);
    let series = |after: bool| -> Vec<Series> {
        loads
            .iter()
            .enumerate()
            .map(|(li, &l)| {
                let pts: Vec<(f64, f64)> = idx
                    .iter()
                    .filter(|&&i| {
                        seg_of[i].is_some_and(|k| level_of(c.rec.segments[k].fz) == Some(li))
                    })
                    .map(|&i| (c.slip_deg(i), c.r(i, after)))
                    .collect();
                let (r, g, b) = Palette99::pick(li).to_rgba().rgb();
                Series::Points(pts, RGBColor(r, g, b), format!("Fz {:.2} kN", l / 1e3), 1)
            })
            .collect()
    };
    let (sb, sa) = (series(false), series(true));
    let pts = |s: &[Series]| -> Vec<(f64, f64)> {
        s.iter()
            .flat_map(|x| match x {
                Series::Points(p, ..) | Series::Line(p, ..) => p.clone(),
            })
            .collect()
    };
    let yr = common_range(&[&pts(&sb), &pts(&sa)]);
    let yl = format!("measured − model [{}]", c.unit);
    figure(&path, 2, &|a| {
        panel(
            &a[0],
            &path,
            &format!("{} residual vs slip: baseline", c.ch.name()),
            c.slip_label,
            &yl,
            &sb,
            Some(yr),
        )?;
        panel(
            &a[1],
            &path,
            &format!("{} residual vs slip: {}", c.ch.name(), after_label(verdict)),
            c.slip_label,
            &yl,
            &sa,
            Some(yr),
        )
    })?;
    Ok(Plot {
        file,
        channel: c.name,
        caption: format!(
            "{} residual map against slip, coloured by load: structure (a slope at small slip = stiffness error, a bulge near the peak = friction error, a band that splits = hysteresis) should vanish from left to right.",
            c.ch.name()
        ),
    })
}

/// Segment index of every sample (None outside segments).
fn segment_index(rec: &Recording) -> Vec<Option<usize>> {
    let mut v = vec![None; rec.samples.len()];
    for (k, g) in rec.segments.iter().enumerate() {
        for x in v.iter_mut().take(g.end).skip(g.start) {
            *x = Some(k);
        }
    }
    v
}

/// Per segment: relative scale error Σ r·F / Σ F² of the model `after` or not.
fn scale_error(c: &Chan, k: usize, after: bool) -> f64 {
    let g = &c.rec.segments[k];
    let (mut srf, mut sff) = (0.0, 0.0);
    for i in g.start..g.end.min(c.meas.len()) {
        let f = if after { c.ext[i] } else { c.base[i] };
        let r = c.r(i, after);
        if r.is_finite() && f.is_finite() {
            srf += r * f;
            sff += f * f;
        }
    }
    if sff > 0.0 {
        srf / sff
    } else {
        f64::NAN
    }
}

/// What a per-segment scale-error plot draws against.
struct SegmentAxis {
    /// File name stem (`residual_load`).
    stem: &'static str,
    /// The condition's name in the title ("load").
    what: &'static str,
    /// Axis label with unit.
    label: &'static str,
    /// The condition's value of a segment, in the axis' unit.
    x: fn(&Recording, &crate::data::Segment) -> f64,
    /// What to look for, after "Per segment, the CH residual as a share of
    /// the model force (+ = measured stronger) against ".
    look_for: &'static str,
}

/// Per segment the relative force scale error against a condition of the
/// segment, baseline and extended.
fn segment_scale_plot(c: &Chan, verdict: &str, dir: &Path, ax: &SegmentAxis) -> Result<Plot> {
    let file = format!("{}_{}.svg", ax.stem, c.name.to_lowercase());
    let path = dir.join(&file);
    let pts = |after: bool| -> Vec<(f64, f64)> {
        c.rec
            .segments
            .iter()
            .enumerate()
            .map(|(k, g)| ((ax.x)(c.rec, g), 100.0 * scale_error(c, k, after)))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect()
    };
    let (b, a) = (pts(false), pts(true));
    let yr = common_range(&[&b, &a]);
    figure(&path, 1, &|ar| {
        panel(
            &ar[0],
            &path,
            &format!(
                "{} force scale error per segment vs {}",
                c.ch.name(),
                ax.what
            ),
            ax.label,
            "Σ r·F / Σ F² [%]",
            &[
                Series::Points(b.clone(), BASE, "baseline".into(), 3),
                Series::Points(a.clone(), EXT, after_label(verdict), 3),
            ],
            Some(yr),
        )
    })?;
    Ok(Plot {
        file,
        channel: c.name,
        caption: format!(
            "Per segment, the {} residual as a share of the model force (+ = measured stronger) against {}",
            c.ch.name(),
            ax.look_for
        ),
    })
}

fn residual_load(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    segment_scale_plot(
        c,
        verdict,
        dir,
        &SegmentAxis {
            stem: "residual_load",
            what: "load",
            label: "Fz [kN]",
            x: |_, g| g.fz / 1e3,
            look_for: "load: a trend with load is a load-sensitivity error, scatter between segments at one load a pressure, speed or temperature effect.",
        },
    )
}

/// Per segment the relative force scale error against the segment's mean
/// recorded pressure (kPa), baseline and extended (the evidence of a
/// `pressure` verdict: a slope that the extended model flattens).
fn residual_pressure(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    segment_scale_plot(
        c,
        verdict,
        dir,
        &SegmentAxis {
            stem: "residual_pressure",
            what: "pressure",
            label: "recorded inflation pressure (segment mean) [kPa]",
            x: |rec, g| super::factor::segment_mean(&rec.samples, g, |s| s.p) / 1e3,
            look_for: "the recorded inflation pressure: a slope in the baseline is the pressure dependence the baseline lacks; the extended model should flatten it.",
        },
    )
}

/// Per segment the relative force scale error against the belt speed
/// (km/h): the evidence of a `speed_friction` verdict across belt speeds.
fn residual_speed(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    segment_scale_plot(
        c,
        verdict,
        dir,
        &SegmentAxis {
            stem: "residual_speed",
            what: "belt speed",
            label: "belt speed (segment mean) [km/h]",
            x: |_, g| 3.6 * g.vx,
            look_for: "the belt speed: friction that falls with sliding speed leaves the faster segments weaker than the baseline; the extended model should flatten the trend.",
        },
    )
}

/// Per segment the relative force scale error against the inclination
/// (degrees): the evidence of a `camber` verdict.
fn residual_inclination(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    segment_scale_plot(
        c,
        verdict,
        dir,
        &SegmentAxis {
            stem: "residual_inclination",
            what: "inclination",
            label: "inclination angle [deg]",
            x: |_, g| g.gamma.to_degrees(),
            look_for: "the inclination angle: a trend is camber acting on the force differently from the model; the extended model should flatten it.",
        },
    )
}

/// Mean of y per x bin over `idx`, rising and falling sweeps apart.
fn binned(c: &Chan, idx: &[usize], y: &dyn Fn(usize) -> f64) -> (Curve, Curve) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &i in idx {
        let s = c.slip_deg(i);
        if s.is_finite() {
            lo = lo.min(s);
            hi = hi.max(s);
        }
    }
    if hi <= lo {
        return (vec![], vec![]);
    }
    let mut acc = vec![[0.0f64; 4]; BINS];
    for &i in idx {
        let (s, v) = (c.slip_deg(i), y(i));
        if !(s.is_finite() && v.is_finite()) {
            continue;
        }
        let b = (((s - lo) / (hi - lo)) * BINS as f64).min(BINS as f64 - 1.0) as usize;
        match c.rec.sweep_dir.get(i) {
            Some(1) => {
                acc[b][0] += v;
                acc[b][1] += 1.0;
            }
            Some(-1) => {
                acc[b][2] += v;
                acc[b][3] += 1.0;
            }
            _ => {}
        }
    }
    let mid = |b: usize| lo + (hi - lo) * (b as f64 + 0.5) / BINS as f64;
    let curve = |k: usize| {
        acc.iter()
            .enumerate()
            .filter(|(_, a)| a[k + 1] >= 3.0)
            .map(|(b, a)| (mid(b), a[k] / a[k + 1]))
            .collect::<Vec<_>>()
    };
    (curve(0), curve(2))
}

fn hysteresis(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    let file = format!("hysteresis_{}.svg", c.name.to_lowercase());
    let path = dir.join(&file);
    let idx = c.inside(usize::MAX);
    let (rb, fb) = binned(c, &idx, &|i| c.r(i, false));
    let (ra, fa) = binned(c, &idx, &|i| c.r(i, true));
    let yr = common_range(&[&rb, &fb, &ra, &fa]);
    let yl = format!("mean residual [{}]", c.unit);
    figure(&path, 2, &|a| {
        panel(
            &a[0],
            &path,
            &format!("{} residual, rising vs falling slip: baseline", c.ch.name()),
            c.slip_label,
            &yl,
            &[
                Series::Line(rb.clone(), RISE, 2, "rising".into()),
                Series::Line(fb.clone(), FALL, 2, "falling".into()),
            ],
            Some(yr),
        )?;
        panel(
            &a[1],
            &path,
            &format!("{}: {}", c.ch.name(), after_label(verdict)),
            c.slip_label,
            &yl,
            &[
                Series::Line(ra.clone(), RISE, 2, "rising".into()),
                Series::Line(fa.clone(), FALL, 2, "falling".into()),
            ],
            Some(yr),
        )
    })?;
    Ok(Plot {
        file,
        channel: c.name,
        caption: format!(
            "Hysteresis: the {} residual averaged in {BINS} slip bins, rising sweeps against falling ones. Two curves apart = the measured force depends on where the slip came from (transient lag, bristle hysteresis); they should close on the right.",
            c.ch.name()
        ),
    })
}

fn drift(c: &Chan, energy: &[f64], verdict: &str, dir: &Path) -> Result<Plot> {
    let file = format!("drift_{}.svg", c.name.to_lowercase());
    let path = dir.join(&file);
    let u = |i: usize, after: bool| {
        let f = if after { c.ext[i] } else { c.base[i] };
        c.r(i, after) * f.signum()
    };
    // Binned over time in run (all segments pooled).
    let idx = c.inside(usize::MAX);
    let tmax = idx
        .iter()
        .map(|&i| c.rec.t_in_segment.get(i).copied().unwrap_or(f64::NAN))
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    let by_time = |after: bool| {
        let mut acc = vec![(0.0, 0.0); BINS];
        for &i in &idx {
            let t = c.rec.t_in_segment.get(i).copied().unwrap_or(f64::NAN);
            let v = u(i, after);
            if t.is_finite() && v.is_finite() && tmax > 0.0 {
                let b = ((t / tmax) * BINS as f64).min(BINS as f64 - 1.0) as usize;
                acc[b].0 += v;
                acc[b].1 += 1.0;
            }
        }
        acc.iter()
            .enumerate()
            .filter(|(_, a)| a.1 >= 3.0)
            .map(|(b, a)| (tmax * (b as f64 + 0.5) / BINS as f64, a.0 / a.1))
            .collect::<Vec<_>>()
    };
    // Per segment mean against the energy at its middle (kJ).
    let by_energy = |after: bool| {
        c.rec
            .segments
            .iter()
            .filter_map(|g| {
                let (mut s, mut n) = (0.0, 0.0);
                for i in g.start..g.end.min(c.meas.len()) {
                    let v = u(i, after);
                    if v.is_finite() {
                        s += v;
                        n += 1.0;
                    }
                }
                let e = energy.get((g.start + g.end) / 2).copied()?;
                (n > 0.0 && e.is_finite()).then(|| (e / 1e3, s / n))
            })
            .collect::<Vec<_>>()
    };
    let (tb, ta, eb, ea) = (
        by_time(false),
        by_time(true),
        by_energy(false),
        by_energy(true),
    );
    let yl = format!("signed residual, + = measured stronger [{}]", c.unit);
    figure(&path, 2, &|a| {
        panel(
            &a[0],
            &path,
            &format!("{} residual vs time in run", c.ch.name()),
            "time since the segment began [s]",
            &yl,
            &[
                Series::Line(tb.clone(), BASE, 2, "baseline".into()),
                Series::Line(ta.clone(), EXT, 2, after_label(verdict)),
            ],
            None,
        )?;
        panel(
            &a[1],
            &path,
            &format!("{} residual per segment vs frictional energy", c.ch.name()),
            "accumulated frictional energy [kJ]",
            &yl,
            &[
                Series::Points(eb.clone(), BASE, "baseline".into(), 3),
                Series::Points(ea.clone(), EXT, after_label(verdict), 3),
            ],
            None,
        )
    })?;
    Ok(Plot {
        file,
        channel: c.name,
        caption: format!(
            "Drift: the signed {} residual (+ = measured stronger than the model) against time within a run and, per segment, against the frictional energy put into the tread since the start. A trend is a state that builds up (tread temperature, wear); it should flatten on the extended model.",
            c.ch.name()
        ),
    })
}

fn overlay(c: &Chan, verdict: &str, dir: &Path) -> Result<Plot> {
    let file = format!("overlay_{}.svg", c.name.to_lowercase());
    let path = dir.join(&file);
    let (_, held_out) = super::candidate::split(c.rec);
    // Segments ranked by the change the verdict makes (or by the baseline's
    // error when it changes nothing), held-out ones before fitted ones.
    let sse = |r: &std::ops::Range<usize>, after: bool| {
        r.clone()
            .map(|i| c.r(i, after))
            .filter(|v| v.is_finite())
            .map(|v| v * v)
            .sum::<f64>()
    };
    let finite =
        |r: &std::ops::Range<usize>| r.clone().filter(|&i| c.r(i, false).is_finite()).count();
    let n = c.meas.len();
    let mut ranked: Vec<(bool, f64, f64, std::ops::Range<usize>)> = c
        .rec
        .segments
        .iter()
        .map(|g| (g, g.start.min(n)..g.end.min(n)))
        .filter(|(_, r)| finite(r) >= 10)
        .map(|(g, r)| {
            let key = if verdict == "none" {
                sse(&r, false)
            } else {
                sse(&r, false) - sse(&r, true)
            };
            (held_out.get(r.start) == Some(&true), key, g.fz, r)
        })
        .collect();
    ranked.sort_by(|a, b| b.0.cmp(&a.0).then(b.1.total_cmp(&a.1)));
    // One panel per load level (the level's held-out segment the verdict
    // changes most; a fitted one where the level has none held out),
    // lightest load first: the curves per load.
    let mut panels: Vec<(f64, bool, std::ops::Range<usize>)> = Vec::new();
    for (out, _, fz, r) in &ranked {
        if !panels.iter().any(|(l, ..)| same_load_level(*l, *fz)) {
            panels.push((*fz, *out, r.clone()));
        }
    }
    panels.truncate(MAX_PANELS);
    panels.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut ranked: Vec<(bool, std::ops::Range<usize>)> =
        panels.into_iter().map(|(_, out, r)| (out, r)).collect();
    if ranked.is_empty() {
        ranked = split(c.rec)
            .0
            .into_iter()
            .take(1)
            .map(|r| (false, r))
            .collect();
    }
    let cols = ranked.len().clamp(1, 3);
    let rows = ranked.len().max(1).div_ceil(cols);
    figure_grid(&path, rows, cols, &|a| {
        for (k, (out, r)) in ranked.iter().enumerate() {
            let stride = (r.len() / 1500).max(1);
            let line = |v: &[f64]| -> Vec<(f64, f64)> {
                r.clone()
                    .step_by(stride)
                    .map(|i| (c.slip_deg(i), v[i]))
                    .filter(|p| p.0.is_finite() && p.1.is_finite())
                    .collect()
            };
            let g = c.rec.segments.iter().find(|g| g.start == r.start);
            let title = g.map_or("segment".into(), |g| {
                format!(
                    "Fz {:.2} kN, γ {:.1}°, {:.0} kPa, {:.0} km/h{}",
                    g.fz / 1e3,
                    tenth(g.gamma.to_degrees()),
                    g.p / 1e3,
                    3.6 * g.vx,
                    if *out { "" } else { " (fit half)" }
                )
            });
            let mut series = vec![
                Series::Points(line(&c.meas), GREY, "measured".into(), 1),
                Series::Line(line(&c.base), BASE, 1, "baseline".into()),
            ];
            if verdict != "none" {
                series.push(Series::Line(line(&c.ext), EXT, 1, after_label(verdict)));
            }
            panel(
                &a[k],
                &path,
                &title,
                c.slip_label,
                &format!("{} [{}]", c.ch.name(), c.unit),
                &series,
                None,
            )?;
        }
        Ok(())
    })?;
    Ok(Plot {
        file,
        channel: c.name,
        caption: format!(
            "Measured (grey), baseline (blue) and extended model (red) {} per load, lightest first: at each load level the held-out segment (not fitted by the candidates) the verdict changes most, or a fitted one (marked) where the level has none held out.",
            c.ch.name()
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::{evidence_stems, reader_order, Plot};

    fn plot(file: &str, channel: &'static str) -> Plot {
        Plot {
            file: file.into(),
            channel,
            caption: String::new(),
        }
    }

    fn files(v: &[Plot]) -> Vec<&str> {
        v.iter().map(|p| p.file.as_str()).collect()
    }

    /// Drawn per channel in the fixed order; read with the verdict's own
    /// evidence first, its best channel leading, the rest as drawn.
    #[test]
    fn the_verdict_s_evidence_leads_its_best_channel_first() {
        let drawn = || {
            let mut v = Vec::new();
            for ch in ["FX", "FY", "MZ"] {
                for stem in ["residual_slip", "residual_load", "hysteresis", "drift"] {
                    v.push(plot(&format!("{stem}_{}.svg", ch.to_lowercase()), ch));
                }
            }
            v
        };
        // Mz gains most, then Fx; Fy not scored.
        let gain = |ch: &str| match ch {
            "MZ" => 0.20,
            "FX" => 0.05,
            _ => f64::NEG_INFINITY,
        };
        let v = reader_order(drawn(), evidence_stems("relaxation"), gain);
        assert_eq!(
            files(&v)[..4],
            [
                "hysteresis_mz.svg",
                "hysteresis_fx.svg",
                "hysteresis_fy.svg",
                "residual_slip_fx.svg"
            ]
        );
        assert_eq!(v.len(), 12);
        let v = reader_order(drawn(), evidence_stems("thermal"), gain);
        assert_eq!(files(&v)[0], "drift_mz.svg");
        // Two stems: by stem first, then by gain.
        let mut d = drawn();
        d.push(plot("residual_speed_fx.svg", "FX"));
        let v = reader_order(d, evidence_stems("speed_friction"), gain);
        assert_eq!(
            files(&v)[..3],
            [
                "residual_speed_fx.svg",
                "residual_slip_mz.svg",
                "residual_slip_fx.svg"
            ]
        );
        // No verdict: the drawing order stands.
        let v = reader_order(drawn(), evidence_stems("none"), gain);
        assert_eq!(files(&v), files(&drawn()));
    }

    /// Load-controlled set points a few newtons apart are one level; the
    /// programme's set points (≥ 30 % apart) are not.
    #[test]
    fn load_levels_merge_a_set_point_s_scatter() {
        let l = super::load_levels(
            [
                1556.0,
                667.0,
                222.0,
                1111.0,
                445.0,
                1561.0,
                449.0,
                331.0,
                226.0,
                f64::NAN,
            ]
            .into_iter(),
        );
        assert_eq!(l, [222.0, 331.0, 445.0, 667.0, 1111.0, 1556.0]);
        assert!(super::load_levels(std::iter::empty()).is_empty());
    }

    /// Every candidate the diagnosis can name has evidence to show first.
    #[test]
    fn every_named_effect_has_its_evidence() {
        let all = crate::diagnose::candidate::all();
        assert!(all.len() >= 8);
        for c in all.iter().filter(|c| c.name() != "none") {
            assert!(!evidence_stems(c.name()).is_empty(), "{}", c.name());
        }
    }
}
