//! quality — the before/after figures of a diagnosis: σ and NRMSE of the
//! baseline and of the extended model per channel and condition, on the
//! candidates' fit half and on the held-out half (see the `report` module's
//! "Quality figures").
//!
//! Must never: let the held-out half inform anything it scores (offsets
//! come from the fit half only).

use crate::data::structure::SegmentOptions;
use crate::data::Recording;
use crate::error::Result;
use crate::fit::metrics::{self, nrmse, sigma};
use crate::mf::Forces;
use crate::residual::Channel;
use serde::Serialize;
use std::ops::Range;

/// (measured, simulated, driving slip) of one channel.
pub fn channel_series(
    rec: &Recording,
    sim: &[Forces],
    channel: Channel,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let s = &rec.samples;
    (
        s.iter().map(|s| channel.measured(s)).collect(),
        sim.iter().map(|f| channel.of_forces(f)).collect(),
        s.iter().map(|s| channel.driving_slip(s)).collect(),
    )
}

/// Whether the recording carries `channel`.
pub fn channel_present(rec: &Recording, channel: Channel) -> bool {
    rec.has(channel.name())
}

/// The candidates' split ([`super::candidate::split`]) as sample ranges:
/// (fit half, held-out half).
pub fn split(rec: &Recording) -> (Vec<Range<usize>>, Vec<Range<usize>>) {
    let (fit, test) = super::candidate::split(rec);
    (ranges(&fit), ranges(&test))
}

/// The runs of `true` in `mask` as half-open ranges.
pub(crate) fn ranges(mask: &[bool]) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &m) in mask.iter().chain(std::iter::once(&false)).enumerate() {
        match (m, start) {
            (true, None) => start = Some(i),
            (false, Some(a)) => {
                out.push(a..i);
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// The belt speeds of the programme, ascending: each the sample-weighted
/// mean (m/s) of the segments within the segmenter's speed tolerance
/// (max(0.8 m/s, 5 %), [`SegmentOptions::default`]) of the slowest of its
/// level, with their indices.
fn speed_levels(rec: &Recording) -> Vec<(f64, Vec<usize>)> {
    let t = SegmentOptions::default();
    let segs = &rec.segments;
    crate::stats::anchored_levels(
        0..segs.len(),
        |&k| segs[k].vx,
        |anchor, v| v - anchor <= t.v_abs.max(t.v_rel * v.abs()),
    )
    .into_iter()
    .map(|m| {
        let w = |k: &usize| segs[*k].len().max(1) as f64;
        let total: f64 = m.iter().map(w).sum();
        let v = m.iter().map(|k| w(k) * segs[*k].vx).sum::<f64>() / total;
        (v, m)
    })
    .collect()
}

/// One row of the quality table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QualityRow {
    /// The scored channel (written as its key, "FY").
    pub channel: Channel,
    /// "all", "Fz 4000 N, γ 0.0°, p 220 kPa" or "Vx 58 km/h".
    pub condition: String,
    /// The condition's load (N) for a load/inclination/pressure condition;
    /// `None` for "all" and the per-speed rows.
    pub fz: Option<f64>,
    /// Samples of the condition with a finite measured value.
    pub n: usize,
    /// σ = √(Σ(sim − test)² / Σ test²) of the baseline (dimensionless;
    /// its offset, estimated on the fit half, removed).
    pub sigma_before: f64,
    /// The same of the verdict's extended model.
    pub sigma_after: f64,
    /// NRMSE = RMS(sim − test) / (max test − min test) of the baseline
    /// (dimensionless; offset removed likewise).
    pub nrmse_before: f64,
    /// The same of the verdict's extended model.
    pub nrmse_after: f64,
}

/// `sim` plus its constant offset from the measurement, estimated as the
/// mean of (measured − sim) over `fit` (the fit half only, so the held-out
/// half stays unseen).
fn with_offset(y: &[f64], sim: &[f64], fit: &[Range<usize>]) -> Vec<f64> {
    let (mut s, mut n) = (0.0, 0.0);
    for r in fit {
        for i in r.clone() {
            let d = y[i] - sim[i];
            if d.is_finite() {
                s += d;
                n += 1.0;
            }
        }
    }
    let o = if n > 0.0 { s / n } else { 0.0 };
    sim.iter().map(|v| v + o).collect()
}

/// Before/after σ and NRMSE per channel and condition over `ranges`. Each
/// model's constant channel offset (a sensor zero, not physics — the
/// scoring of the candidates treats it so too) is estimated on the fit
/// half `fit` and removed first.
pub fn quality(
    rec: &Recording,
    before: &[Forces],
    after: &[Forces],
    fit: &[Range<usize>],
    ranges: &[Range<usize>],
) -> Result<Vec<QualityRow>> {
    let mut rows = Vec::new();
    for ch in Channel::SCORED {
        if !channel_present(rec, ch) {
            continue;
        }
        let name = ch.name();
        let (_, sb, _) = channel_series(rec, before, ch);
        let (y, sa, _) = channel_series(rec, after, ch);
        let (sb, sa) = (with_offset(&y, &sb, fit), with_offset(&y, &sa, fit));
        let mb = metrics::evaluate(rec, name, &sb, Some(ranges))?;
        let ma = metrics::evaluate(rec, name, &sa, Some(ranges))?;
        for (b, a) in mb.iter().zip(&ma) {
            rows.push(QualityRow {
                channel: ch,
                condition: b.condition.as_ref().map_or("all".into(), |c| {
                    format!(
                        "Fz {:.0} N, γ {:.1}°, p {:.0} kPa",
                        c.fz,
                        (c.gamma.to_degrees() * 10.0).round() / 10.0 + 0.0,
                        c.p / 1e3
                    )
                }),
                fz: b.condition.as_ref().map(|c| c.fz),
                n: b.n,
                sigma_before: b.sigma,
                sigma_after: a.sigma,
                nrmse_before: b.nrmse,
                nrmse_after: a.nrmse,
            });
        }
        // Per speed, when the programme has more than one.
        let speeds = speed_levels(rec);
        if speeds.len() > 1 {
            for (v, members) in speeds {
                let (mut yy, mut pb, mut pa) = (Vec::new(), Vec::new(), Vec::new());
                for g in members.iter().map(|&k| &rec.segments[k]) {
                    for r in ranges {
                        for i in g.start.max(r.start)..g.end.min(r.end).min(y.len()) {
                            yy.push(y[i]);
                            pb.push(sb[i]);
                            pa.push(sa[i]);
                        }
                    }
                }
                if yy.iter().any(|x| x.is_finite()) {
                    rows.push(QualityRow {
                        channel: ch,
                        condition: format!("Vx {:.0} km/h", 3.6 * v),
                        fz: None,
                        n: yy.iter().filter(|x| x.is_finite()).count(),
                        sigma_before: sigma(&pb, &yy),
                        sigma_after: sigma(&pa, &yy),
                        nrmse_before: nrmse(&pb, &yy),
                        nrmse_after: nrmse(&pa, &yy),
                    });
                }
            }
        }
    }
    Ok(rows)
}

/// The before/after quality tables of `diagnosis.json`.
#[derive(Clone, Debug, Serialize)]
pub struct QualityReport {
    /// The model "after" is: the verdict's name.
    pub model_after: String,
    /// How the halves were formed, in words.
    pub split: &'static str,
    /// Rows over the candidates' fit half.
    pub in_sample: Vec<QualityRow>,
    /// Rows over the held-out half (segments the candidates never saw).
    pub out_of_sample: Vec<QualityRow>,
}

#[cfg(test)]
mod tests {
    use crate::data::{Recording, Segment, SegmentKind};

    /// Speed-controlled repeats (8.86, 8.90, 8.93 m/s) are one level; 32,
    /// 40 and 48 km/h three; each level's speed is its sample-weighted mean.
    #[test]
    fn speed_levels_pool_the_repeats_of_a_set_point() {
        let seg = |start: usize, len: usize, vx: f64| Segment {
            start,
            end: start + len,
            kind: SegmentKind::PureLongitudinal,
            fz: 1000.0,
            gamma: 0.0,
            p: 83e3,
            vx,
            alpha: 0.0,
        };
        let rec = Recording {
            segments: vec![
                seg(0, 10, 11.10),
                seg(10, 10, 8.90),
                seg(20, 30, 13.33),
                seg(50, 10, 8.86),
                seg(60, 10, 8.93),
                seg(70, 10, f64::NAN),
            ],
            ..Default::default()
        };
        let l = super::speed_levels(&rec);
        let members: Vec<&[usize]> = l.iter().map(|(_, m)| m.as_slice()).collect();
        assert_eq!(members, [&[3, 1, 4][..], &[0], &[2]]);
        assert!((l[0].0 - (8.86 + 8.90 + 8.93) / 3.0).abs() < 1e-12);
        assert_eq!(l[2].0, 13.33);
    }
}
