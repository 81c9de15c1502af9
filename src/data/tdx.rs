//! tdx — TYDEX measurement files (`.tdx`, TYDEX format 1.3): sections
//! `**HEADER`, `**COMMENTS`, `**CONSTANTS`, `**MEASURCHANNELS` (name,
//! description, unit, conversion factor, offset), `**MEASURDATA` (one row of
//! whitespace-separated values per time step), `**END`. Channel names follow
//! TYDEX (RUNTIME, LONGVEL, ROTSPEED, SLIPANGL, INCLANGL, LONGSLIP, INFLPRES,
//! FXW, FYW, FZW, MXW, MYW, MZW; C-system forces as FXC … select TYDEX C).
//!
//! Must never: accept a data row whose value count differs from the channel
//! list (the line is named), or drop a section it does not understand
//! without keeping it in the metadata.

use super::conventions::AxisSystem;
use super::{RawColumn, RawTable, Recording, SAMPLE_CHANNELS};
use crate::error::{Error, Result};

fn rerr(file: &str, loc: impl Into<String>, msg: impl Into<String>) -> Error {
    Error::Recording {
        file: file.to_string(),
        location: loc.into(),
        message: msg.into(),
    }
}

/// Read TYDEX text.
pub fn read(bytes: &[u8], file: &str) -> Result<RawTable> {
    super::csvio::limit_rows(read_unbounded(bytes, file)?, file)
}

/// [`read`] without the row limit.
fn read_unbounded(bytes: &[u8], file: &str) -> Result<RawTable> {
    let text = String::from_utf8_lossy(bytes);
    let mut t = RawTable::default();
    let mut section = String::new();
    let mut chans: Vec<(String, String, f64, f64)> = Vec::new();
    let mut cols: Vec<Vec<f64>> = Vec::new();
    let mut saw_data = false;
    let mut ended = false;
    for (li, line) in text.lines().enumerate() {
        let l = line.trim_end();
        if let Some(s) = l.trim_start().strip_prefix("**") {
            section = s.trim().to_ascii_uppercase();
            if section == "MEASURDATA" {
                saw_data = true;
                cols = vec![Vec::new(); chans.len()];
            }
            if section == "END" {
                ended = true;
                break;
            }
            continue;
        }
        if l.trim().is_empty() || l.trim_start().starts_with('!') {
            continue;
        }
        match section.as_str() {
            "HEADER" | "CONSTANTS" | "COMMENTS" => {
                let mut it = l.split_whitespace();
                let key = it.next().unwrap_or("").to_string();
                let rest: Vec<&str> = it.collect();
                t.meta.push((key, rest.join(" ")));
            }
            "MEASURCHANNELS" => {
                let toks: Vec<&str> = l.split_whitespace().collect();
                let nnum = toks
                    .iter()
                    .rev()
                    .take_while(|x| x.parse::<f64>().is_ok())
                    .count();
                if toks.len() < 2 + nnum.min(toks.len()) && nnum == 0 {
                    return Err(rerr(
                        file,
                        format!("line {}", li + 1),
                        "channel line needs at least a name and a unit",
                    ));
                }
                let nums: Vec<f64> = toks[toks.len() - nnum..]
                    .iter()
                    .filter_map(|x| x.parse().ok())
                    .collect();
                let unit = if toks.len() > nnum + 1 {
                    toks[toks.len() - nnum - 1]
                } else {
                    ""
                };
                let factor = nums.first().copied().unwrap_or(1.0);
                let offset = nums.get(1).copied().unwrap_or(0.0);
                chans.push((toks[0].to_string(), unit.to_string(), factor, offset));
            }
            "MEASURDATA" => {
                let mut k = 0;
                for tok in l.split_whitespace() {
                    if k >= chans.len() {
                        return Err(rerr(
                            file,
                            format!("line {}", li + 1),
                            format!("more than the {} declared channels", chans.len()),
                        ));
                    }
                    let v: f64 = tok.parse().map_err(|_| {
                        rerr(
                            file,
                            format!("line {}, channel '{}'", li + 1, chans[k].0),
                            format!("'{tok}' is not a number"),
                        )
                    })?;
                    cols[k].push(v * chans[k].2 + chans[k].3);
                    k += 1;
                }
                if k != chans.len() {
                    return Err(rerr(
                        file,
                        format!("line {}", li + 1),
                        format!(
                            "{k} values, {} channels declared (truncated row?)",
                            chans.len()
                        ),
                    ));
                }
            }
            other => t.meta.push((other.to_string(), l.trim().to_string())),
        }
    }
    if chans.is_empty() {
        return Err(rerr(
            file,
            "**MEASURCHANNELS",
            "no measurement channels declared",
        ));
    }
    if !saw_data {
        return Err(rerr(
            file,
            "**MEASURDATA",
            "section missing (file truncated?)",
        ));
    }
    if !ended {
        t.meta.push((
            "note".into(),
            "no **END marker (file may be truncated)".into(),
        ));
    }
    if chans.iter().any(|c| {
        matches!(
            c.0.to_ascii_uppercase().as_str(),
            "FXC" | "FYC" | "FZC" | "MXC" | "MYC" | "MZC"
        )
    }) {
        t.axes = Some(AxisSystem::TydexC);
    }
    for ((name, unit, _, _), data) in chans.into_iter().zip(cols) {
        t.columns.push(RawColumn {
            name,
            unit: Some(unit),
            data,
        });
    }
    Ok(t)
}

/// TYDEX names and units for the [`SAMPLE_CHANNELS`] (W system).
const TDX_NAMES: [(&str, &str, &str); 14] = [
    ("RUNTIME", "Running time", "s"),
    ("LONGVEL", "Longitudinal velocity", "m/s"),
    ("ROTSPEED", "Wheel rotational speed", "rad/s"),
    ("FZW", "Vertical force", "N"),
    ("LONGSLIP", "Longitudinal slip", "-"),
    ("SLIPANGL", "Slip angle", "rad"),
    ("INCLANGL", "Inclination angle", "rad"),
    ("TURNSLIP", "Turn slip", "1/m"),
    ("INFLPRES", "Inflation pressure", "Pa"),
    ("FXW", "Longitudinal force", "N"),
    ("FYW", "Lateral force", "N"),
    ("MXW", "Overturning moment", "Nm"),
    ("MYW", "Rolling resistance moment", "Nm"),
    ("MZW", "Aligning moment", "Nm"),
];

/// TYDEX text of a recording (W axis system, SI units).
pub fn write(rec: &Recording) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "**HEADER");
    let _ = writeln!(s, "RELEASE    1.3");
    let _ = writeln!(
        s,
        "MEASID     {}",
        rec.source.replace(char::is_whitespace, "_")
    );
    let _ = writeln!(s, "SUPPLIER   tyrekit");
    let _ = writeln!(s, "COORDSYS   W");
    let _ = writeln!(s, "**COMMENTS");
    let _ = writeln!(
        s,
        "written by tyrekit: ISO-W (TYDEX W) axes, SI units, warm-up removed"
    );
    let _ = writeln!(s, "**CONSTANTS");
    let _ = writeln!(
        s,
        "NSEGMENTS  Number of test segments           -          {}",
        rec.segments.len()
    );
    let _ = writeln!(s, "**MEASURCHANNELS");
    let idx: Vec<usize> = (0..SAMPLE_CHANNELS.len())
        .filter(|&k| rec.has(SAMPLE_CHANNELS[k]))
        .collect();
    for &k in &idx {
        let (n, d, u) = TDX_NAMES[k];
        let _ = writeln!(s, "{n:<10}{d:<30}{u:<10}1 0 0");
    }
    for (n, _) in &rec.extra {
        let name: String = n
            .chars()
            .filter(|c| c.is_ascii_alphanumeric() || *c == '_')
            .take(10)
            .collect();
        let _ = writeln!(
            s,
            "{name:<10}{:<30}{:<10}1 0 0",
            "extra channel",
            super::extra_si_unit(n)
        );
    }
    let _ = writeln!(s, "**MEASURDATA");
    for (i, smp) in rec.samples.iter().enumerate() {
        let v = smp.values();
        let mut first = true;
        for &k in &idx {
            if !first {
                s.push(' ');
            }
            first = false;
            let _ = write!(s, "{}", super::ttc::fmt_num(v[k]));
        }
        for (_, e) in &rec.extra {
            let _ = write!(
                s,
                " {}",
                super::ttc::fmt_num(e.get(i).copied().unwrap_or(f64::NAN))
            );
        }
        s.push('\n');
    }
    let _ = writeln!(s, "**END");
    s
}
