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

/// A parse failure inside a chunk: (line index within the chunk, column, message).
type ChunkErr = (usize, Option<usize>, String);

/// Parse data lines of one chunk into columns.
fn parse_chunk(text: &str, ncol: usize, sep: char) -> Result<Vec<Vec<f64>>, ChunkErr> {
    let mut cols: Vec<Vec<f64>> = (0..ncol)
        .map(|_| Vec::with_capacity(text.len() / (ncol * 10).max(1)))
        .collect();
    for (li, l) in text.lines().enumerate() {
        if l.trim().is_empty() || l.starts_with('#') {
            continue;
        }
        let mut k = 0;
        for tok in l.split(sep) {
            if k >= ncol {
                return Err((li, None, format!("more than {ncol} fields")));
            }
            let tok = tok.trim();
            let v = if tok.is_empty() {
                f64::NAN
            } else {
                match tok.parse::<f64>() {
                    Ok(v) => v,
                    Err(_) => return Err((li, Some(k), format!("'{tok}' is not a number"))),
                }
            };
            cols[k].push(v);
            k += 1;
        }
        if k != ncol {
            return Err((
                li,
                None,
                format!("{k} fields, {ncol} expected (truncated line?)"),
            ));
        }
    }
    Ok(cols)
}

/// The most rows any reader accepts (CSV, TTC .dat/.mat, TYDEX): 2 million,
/// 5.5 h at 100 Hz or 33 min at 1 kHz. Interpreting a recording costs about
/// 250 bytes per row whatever the file's size per row, so this is what keeps a
/// 50 MB hostile file of short rows within 1 GB (`tests/reader_bounds.rs`).
pub const MAX_ROWS: usize = 2_000_000;

/// Refuse a table of more than [`MAX_ROWS`] rows, naming the file.
pub(crate) fn limit_rows(t: RawTable, file: &str) -> Result<RawTable> {
    let n = t.columns.iter().map(|c| c.data.len()).max().unwrap_or(0);
    if n > MAX_ROWS {
        return Err(rerr(
            file,
            "data",
            format!("{n} rows, more than the {MAX_ROWS} a recording may have; split the file"),
        ));
    }
    Ok(t)
}

/// Read CSV bytes into a raw table (units from `[unit]` suffixes if present).
/// Large files are parsed on two threads (split at a line boundary).
pub fn read(bytes: &[u8], file: &str) -> Result<RawTable> {
    super::csvio::limit_rows(read_unbounded(bytes, file)?, file)
}

/// [`read`] without the row limit.
fn read_unbounded(bytes: &[u8], file: &str) -> Result<RawTable> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| rerr(file, format!("byte {}", e.valid_up_to()), "not UTF-8 text"))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Header: the first non-empty, non-comment line.
    let mut head_end = 0;
    let mut head = "";
    let mut head_line = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        head_end += l.len();
        if !l.trim().is_empty() && !l.starts_with('#') {
            head = l.trim_end_matches(['\n', '\r']);
            head_line = i;
            break;
        }
    }
    if head.is_empty() {
        return Err(rerr(file, "line 1", "empty file: no header row"));
    }
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
            format!("line {}", head_line + 1),
            format!("column {} has no name", i + 1),
        ));
    }
    let body = &text[head_end..];
    let split = if body.len() > 1 << 20 {
        body[body.len() / 2..]
            .find('\n')
            .map_or(body.len(), |p| body.len() / 2 + p + 1)
    } else {
        body.len()
    };
    let (a, b) = body.split_at(split);
    let (ra, rb) = std::thread::scope(|sc| {
        let hb = sc.spawn(|| parse_chunk(b, ncol, sep));
        let ra = parse_chunk(a, ncol, sep);
        (
            ra,
            hb.join()
                .unwrap_or_else(|_| Err((0, None, "parser thread failed".into()))),
        )
    });
    let to_err = |(li, col, msg): ChunkErr, base: usize| {
        let line = head_line + 2 + base + li;
        let loc = match col {
            Some(k) => format!("line {line}, column '{}'", names[k]),
            None => format!("line {line}"),
        };
        rerr(file, loc, msg)
    };
    let mut cols = ra.map_err(|e| to_err(e, 0))?;
    let cb = rb.map_err(|e| to_err(e, a.lines().count()))?;
    for (c, mut d) in cols.iter_mut().zip(cb) {
        c.append(&mut d);
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
