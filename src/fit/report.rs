//! report — the fit's results for people (aligned plain-text tables) and for
//! programs (`fit.json`, serde).
//!
//! Tables show SI values except where a person reads another unit more
//! easily (inclination in degrees, pressure in kPa, σ and NRMSE in percent);
//! the column headers say which.
//!
//! Must never: round values in the JSON (only the tables are rounded).

use super::identify::Verdict;
use super::metrics::ChannelMetric;
use super::solve::{FitOutcome, ParamStatus};
use super::transient::RelaxationFit;

/// Everything a fit produced, as written to `fit.json`.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct FitReport {
    /// Where the data came from.
    pub sources: Vec<String>,
    /// One entry per stage, in order.
    pub stages: Vec<FitOutcome>,
    /// Metrics on the data the fit used.
    pub metrics: Vec<ChannelMetric>,
    /// Metrics on held-out data (empty without `--holdout`).
    pub holdout_metrics: Vec<ChannelMetric>,
    /// The relaxation-length stage, one entry per direction (empty unless run).
    #[serde(default)]
    pub relaxation: Vec<RelaxationFit>,
    /// (channel name, segment kind) of every channel a stage fitted, in
    /// stage order: a stage's channels where recorded, on the rows it
    /// fitted them on (the pure Fy stage of data without cornering sweeps
    /// fits the drive/brake rows near free rolling, and the combined stage
    /// leaves Mz out where no stage fitted its pure-slip shape).
    #[serde(default)]
    pub fitted: Vec<(String, crate::data::SegmentKind)>,
}

impl FitReport {
    /// Pretty JSON.
    pub fn to_json(&self) -> crate::Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| crate::Error::Other(format!("fit.json: cannot serialise the report: {e}")))
    }

    /// Write the JSON to `path` (e.g. `DIR/fit.json`).
    pub fn write_json(&self, path: &std::path::Path) -> crate::Result<()> {
        std::fs::write(path, self.to_json()?).map_err(|e| crate::Error::io(path, e))
    }

    /// All tables: parameters per stage, then the quality tables.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for st in &self.stages {
            s.push_str(&param_table(st));
            s.push('\n');
        }
        if !self.relaxation.is_empty() {
            s.push_str(&relaxation_table(&self.relaxation));
            s.push('\n');
        }
        if !self.metrics.is_empty() {
            s.push_str("Quality (fitted data)\n");
            s.push_str(&metrics_table(&self.metrics));
            s.push('\n');
        }
        if !self.holdout_metrics.is_empty() {
            s.push_str("Quality (held-out data)\n");
            s.push_str(&metrics_table(&self.holdout_metrics));
        }
        s
    }
}

/// Lay out rows as an aligned table: the first column left-aligned, the rest
/// right-aligned, a dashed rule under the header.
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let ncol = header.len();
    let mut w: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (k, c) in r.iter().enumerate().take(ncol) {
            w[k] = w[k].max(c.chars().count());
        }
    }
    let line = |cells: Vec<&str>| {
        let mut l = String::new();
        for (k, c) in cells.iter().enumerate() {
            let pad = w[k].saturating_sub(c.chars().count());
            if k > 0 {
                l.push_str("  ");
            }
            if k == 0 {
                l.push_str(c);
                l.push_str(&" ".repeat(pad));
            } else {
                l.push_str(&" ".repeat(pad));
                l.push_str(c);
            }
        }
        l.trim_end().to_string() + "\n"
    };
    let mut out = line(header.to_vec());
    out.push_str(&line(
        w.iter()
            .map(|&n| "-".repeat(n))
            .collect::<Vec<_>>()
            .iter()
            .map(|s| s.as_str())
            .collect(),
    ));
    for r in rows {
        out.push_str(&line(r.iter().map(|s| s.as_str()).collect()));
    }
    out
}

fn num(v: f64) -> String {
    if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e5) {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{:.2}", 100.0 * v)
    } else {
        "-".into()
    }
}

/// Parameter table of one stage: name, start, value, standard error, status.
pub fn param_table(st: &FitOutcome) -> String {
    let rows: Vec<Vec<String>> = st
        .params
        .iter()
        .map(|p| {
            let status = match &p.status {
                ParamStatus::Fixed => "fixed".to_string(),
                ParamStatus::Fitted => "fitted".to_string(),
                ParamStatus::AtBound => "at bound".to_string(),
                ParamStatus::NotIdentified { reason } => match reason {
                    Verdict::NoEffect => "not identified (no effect)".to_string(),
                    Verdict::Collinear { with } => {
                        format!("not identified (collinear with {})", with.join(", "))
                    }
                    Verdict::Identified => "identified".to_string(),
                },
            };
            vec![
                p.name.clone(),
                num(p.start),
                num(p.value),
                p.stderr.map_or("-".into(), num),
                status,
            ]
        })
        .collect();
    let mut corr = String::new();
    if !st.correlated.is_empty() {
        corr.push_str("strongly correlated estimates:");
        for (a, b, r) in &st.correlated {
            corr.push_str(&format!(" {a}/{b} ({r:+.3})"));
        }
        corr.push('\n');
    }
    format!(
        "Stage '{}': cost {} -> {} in {} iterations ({:?}), {} residuals\n{}{}",
        st.stage,
        num(st.initial_cost),
        num(st.cost),
        st.iterations,
        st.termination,
        st.n_residuals,
        table(
            &["parameter", "start", "value", "std. error", "status"],
            &rows
        ),
        corr
    )
}

/// Quality table: channel, condition, n, σ %, NRMSE %, RMS.
pub fn metrics_table(m: &[ChannelMetric]) -> String {
    let rows: Vec<Vec<String>> = m
        .iter()
        .map(|c| {
            let (fz, g, p) = match &c.condition {
                Some(k) => (
                    format!("{:.0}", k.fz),
                    format!("{:.2}", k.gamma.to_degrees()),
                    format!("{:.1}", k.p / 1000.0),
                ),
                None => ("all".into(), "".into(), "".into()),
            };
            vec![
                c.channel.clone(),
                fz,
                g,
                p,
                c.n.to_string(),
                pct(c.sigma),
                pct(c.nrmse),
                num(c.rms),
            ]
        })
        .collect();
    table(
        &[
            "channel",
            "Fz [N]",
            "gamma [deg]",
            "p [kPa]",
            "n",
            "sigma [%]",
            "NRMSE [%]",
            "RMS [SI]",
        ],
        &rows,
    )
}

/// The relaxation stage: per direction the key, start and fitted value, the
/// relaxation length at FNOMIN, and the replay cost of the steady model, the
/// start and the fit.
pub fn relaxation_table(r: &[RelaxationFit]) -> String {
    let rows: Vec<Vec<String>> = r
        .iter()
        .map(|x| {
            vec![
                x.channel.clone(),
                x.key.clone(),
                format!("{:.6e}", x.start),
                format!("{:.6e}", x.value),
                format!("{:.4}", x.sigma_start),
                format!("{:.4}", x.sigma),
                format!("{:.4e}", x.cost_steady),
                format!("{:.4e}", x.cost),
                if x.identified {
                    "fitted".to_string()
                } else {
                    format!("held: {}", x.note)
                },
            ]
        })
        .collect();
    let mut s = String::from(
        "Stage transient (relaxation lengths, replayed through the relaxation model)\n",
    );
    s.push_str(&table(
        &[
            "channel",
            "key",
            "start",
            "fitted",
            "σ start (m)",
            "σ fitted (m)",
            "cost steady",
            "cost fitted",
            "status",
        ],
        &rows,
    ));
    s
}
