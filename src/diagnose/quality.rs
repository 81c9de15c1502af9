//! quality — the before/after figures of a diagnosis: σ and NRMSE of the
//! baseline and of the extended model per channel and condition, on the
//! candidates' fit half and on the held-out half (see the `report` module's
//! "Quality figures").
//!
//! Must never: let the held-out half inform anything it scores (offsets
//! come from the fit half only).

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

/// One row of the quality table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QualityRow {
    pub channel: Channel,
    /// "all", "Fz 4000 N, γ 0.0°, p 220 kPa" or "Vx 58 km/h".
    pub condition: String,
    /// The condition's load (N) for a load/inclination/pressure condition;
    /// `None` for "all" and the per-speed rows.
    pub fz: Option<f64>,
    pub n: usize,
    pub sigma_before: f64,
    pub sigma_after: f64,
    pub nrmse_before: f64,
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
        let mut speeds: Vec<f64> = rec
            .segments
            .iter()
            .map(|g| (g.vx * 10.0).round() / 10.0)
            .filter(|v| v.is_finite())
            .collect();
        speeds.sort_by(f64::total_cmp);
        speeds.dedup();
        if speeds.len() > 1 {
            for v in speeds {
                let (mut yy, mut pb, mut pa) = (Vec::new(), Vec::new(), Vec::new());
                for g in rec
                    .segments
                    .iter()
                    .filter(|g| (g.vx * 10.0).round() / 10.0 == v)
                {
                    for r in ranges {
                        for i in g.start.max(r.start)..g.end.min(r.end).min(y.len()) {
                            yy.push(y[i]);
                            pb.push(sb[i]);
                            pa.push(sa[i]);
                        }
                    }
                }
                if !yy.is_empty() {
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
    pub in_sample: Vec<QualityRow>,
    pub out_of_sample: Vec<QualityRow>,
}
