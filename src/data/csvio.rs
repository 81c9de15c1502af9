//! csvio — CSV recordings in ISO-W SI: reading (header row of channel names,
//! optionally with ` [unit]` suffixes as MFeval's `TyreData.csv` has them;
//! aliases such as MFeval's `Time, Vx, W, SA, IA, Rl, Re, P, Fx, Fy, Fz, Mx,
//! Mz, SR, Phit` are accepted by the loader) and writing the clean table with
//! the columns `time,Vx,omega,Fz,kappa,alpha,gamma,phit,P,Fx,Fy,Mx,My,Mz`
//! (those the recording lacks left out), then the extra channels and the
//! test structure (`segment`, `sweep_dir`, `t_in_segment`).
//!
//! Must never: accept a row with a wrong field count or a non-numeric value
//! without naming the line and column.

use super::{RawColumn, RawTable, Recording, SAMPLE_CHANNELS};
use crate::error::{Error, Result};

fn rerr(file: &str, loc: impl Into<String>, msg: impl Into<String>) -> Error {
    Error::Recording {
        file: file.to_string(),
        location: loc.into(),
        message: msg.into(),
    }
}

/// Read CSV bytes into a raw table (units from `[unit]` suffixes if present).
pub fn read(bytes: &[u8], file: &str) -> Result<RawTable> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| rerr(file, format!("byte {}", e.valid_up_to()), "not UTF-8 text"))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let Some((_, head)) = lines.next() else {
        return Err(rerr(file, "line 1", "empty file: no header row"));
    };
    let sep = if head.contains(',') {
        ','
    } else if head.contains(';') {
        ';'
    } else {
        '\t'
    };
    let names: Vec<String> = head
        .split(sep)
        .map(|s| s.trim().trim_matches('"').to_string())
        .collect();
    let ncol = names.len();
    if let Some(i) = names.iter().position(|n| n.is_empty()) {
        return Err(rerr(
            file,
            "line 1",
            format!("column {} has no name", i + 1),
        ));
    }
    let mut cols: Vec<Vec<f64>> = (0..ncol)
        .map(|_| Vec::with_capacity(bytes.len() / (ncol * 8).max(1)))
        .collect();
    for (li, l) in lines {
        let mut k = 0;
        for tok in l.split(sep) {
            if k >= ncol {
                return Err(rerr(
                    file,
                    format!("line {}", li + 1),
                    format!("more than {ncol} fields"),
                ));
            }
            let tok = tok.trim();
            let v = if tok.is_empty() {
                f64::NAN
            } else {
                match tok.parse::<f64>() {
                    Ok(v) => v,
                    Err(_) => {
                        return Err(rerr(
                            file,
                            format!("line {}, column '{}'", li + 1, names[k]),
                            format!("'{tok}' is not a number"),
                        ))
                    }
                }
            };
            cols[k].push(v);
            k += 1;
        }
        if k != ncol {
            return Err(rerr(
                file,
                format!("line {}", li + 1),
                format!("{k} fields, {ncol} expected (truncated line?)"),
            ));
        }
    }
    Ok(RawTable {
        columns: names
            .into_iter()
            .zip(cols)
            .map(|(name, data)| RawColumn {
                name,
                unit: None,
                data,
            })
            .collect(),
        meta: vec![],
        axes: None,
    })
}

/// The CSV text of a recording (ISO-W SI).
pub fn write(rec: &Recording) -> String {
    use std::fmt::Write;
    let idx: Vec<usize> = (0..SAMPLE_CHANNELS.len())
        .filter(|&k| rec.has(SAMPLE_CHANNELS[k]))
        .collect();
    let mut s = String::with_capacity(rec.samples.len() * 16 * (idx.len() + rec.extra.len() + 3));
    let mut head: Vec<String> = idx
        .iter()
        .map(|&k| SAMPLE_CHANNELS[k].to_string())
        .collect();
    head.extend(rec.extra.iter().map(|(n, _)| n.clone()));
    head.extend(["segment", "sweep_dir", "t_in_segment"].map(String::from));
    let _ = writeln!(s, "{}", head.join(","));
    let mut seg_of = vec![-1i64; rec.samples.len()];
    for (k, g) in rec.segments.iter().enumerate() {
        for x in &mut seg_of[g.start..g.end.min(rec.samples.len())] {
            *x = k as i64;
        }
    }
    for (i, smp) in rec.samples.iter().enumerate() {
        let v = smp.values();
        let mut first = true;
        for &k in &idx {
            if !first {
                s.push(',');
            }
            first = false;
            let _ = write!(s, "{}", super::ttc::fmt_num(v[k]));
        }
        for (_, e) in &rec.extra {
            let _ = write!(
                s,
                ",{}",
                super::ttc::fmt_num(e.get(i).copied().unwrap_or(f64::NAN))
            );
        }
        let _ = writeln!(
            s,
            ",{},{},{}",
            seg_of[i],
            rec.sweep_dir.get(i).copied().unwrap_or(0),
            super::ttc::fmt_num(rec.t_in_segment.get(i).copied().unwrap_or(f64::NAN))
        );
    }
    s
}
