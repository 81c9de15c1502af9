//! ttc — the FSAE Tire Test Consortium / Calspan TIRF exports: the MATLAB
//! `.mat` file (one column vector per channel — ET, V, N, SA, IA, RL, RE, P,
//! FX, FY, FZ, MX, MZ, NFX, NFY, SR, SL, TSTI, TSTC, TSTO, RST, AMBTMP, RUN …
//! — plus a `channel` struct of names and units and the strings `source`,
//! `testid`, `tireid`) and the `.dat` text export (a row of channel names, a
//! row of units, then the data). Both SI and US-customary exports: the units
//! are always read from the file. Also the writers the rig simulator uses.
//!
//! Must never: assume a unit the file does not state, or accept a data row
//! with the wrong number of values (the line is named in the error).

use super::mat::{self, MatValue};
use super::{RawColumn, RawTable};
use crate::error::{Error, Result};

fn rerr(file: &str, loc: impl Into<String>, msg: impl Into<String>) -> Error {
    Error::Recording {
        file: file.to_string(),
        location: loc.into(),
        message: msg.into(),
    }
}

/// Names/units from the `channel` variable, in whichever of the layouts
/// MATLAB exports produce: struct array with `name`/`units` per element, or a
/// scalar struct holding cells or a char matrix.
fn channel_units(ch: &MatValue) -> Vec<(String, String)> {
    let list = |v: Option<&MatValue>| -> Vec<String> {
        match v {
            Some(MatValue::Cell { items, .. }) => items
                .iter()
                .map(|i| i.as_text().unwrap_or_default())
                .collect(),
            Some(MatValue::Char { text, .. }) => {
                text.lines().map(|l| l.trim().to_string()).collect()
            }
            _ => vec![],
        }
    };
    match ch {
        MatValue::Struct {
            fields, elements, ..
        } => {
            let fi = |n: &str| fields.iter().position(|f| f.eq_ignore_ascii_case(n));
            let (Some(ni), Some(ui)) = (fi("name"), fi("units").or(fi("unit"))) else {
                return vec![];
            };
            if elements.len() == 1 {
                let names = list(elements[0].get(ni));
                let units = list(elements[0].get(ui));
                if names.len() > 1 || matches!(elements[0].get(ni), Some(MatValue::Cell { .. })) {
                    return names.into_iter().zip(units).collect();
                }
            }
            elements
                .iter()
                .map(|e| {
                    (
                        e.get(ni).and_then(|v| v.as_text()).unwrap_or_default(),
                        e.get(ui).and_then(|v| v.as_text()).unwrap_or_default(),
                    )
                })
                .collect()
        }
        _ => vec![],
    }
}

/// Read a TTC `.mat` export.
pub fn read_mat(bytes: &[u8], file: &str) -> Result<RawTable> {
    super::csvio::limit_rows(read_mat_unbounded(bytes, file)?, file)
}

/// [`read_mat`] without the row limit.
fn read_mat_unbounded(bytes: &[u8], file: &str) -> Result<RawTable> {
    let vars = mat::read(bytes).map_err(|e| rerr(file, e.location, e.message))?;
    let mut t = RawTable::default();
    let units: Vec<(String, String)> = vars
        .iter()
        .find(|(n, _)| n == "channel")
        .map(|(_, v)| channel_units(v))
        .unwrap_or_default();
    let mut rows: Option<usize> = None;
    let mut unsupported = Vec::new();
    for (name, v) in vars {
        // MATLAB's own subsystem data (unnamed, or `__function_workspace__`) is not a channel.
        if name.is_empty() || name.starts_with("__") {
            continue;
        }
        match v {
            MatValue::Numeric { dims, data }
                if dims.iter().filter(|&&d| d > 1).count() <= 1 && data.len() > 1 =>
            {
                let unit = units
                    .iter()
                    .find(|(n, _)| n.eq_ignore_ascii_case(&name))
                    .map(|(_, u)| u.clone());
                match rows {
                    None => rows = Some(data.len()),
                    Some(r) if r != data.len() => {
                        return Err(rerr(
                            file,
                            format!("variable '{name}'"),
                            format!("{} values, but earlier channels have {r} (file truncated or channels of different length)", data.len()),
                        ))
                    }
                    _ => {}
                }
                t.columns.push(RawColumn { name, unit, data });
            }
            MatValue::Numeric { .. } => {}
            MatValue::Char { text, .. } => t.meta.push((name, text)),
            MatValue::Unsupported { class } => unsupported.push(format!("'{name}' ({class})")),
            _ => {}
        }
    }
    if t.columns.is_empty() {
        let why = if unsupported.is_empty() {
            "no column-vector channels found".to_string()
        } else {
            format!(
                "no column-vector channels; unsupported variables: {}",
                unsupported.join(", ")
            )
        };
        return Err(rerr(file, "variables", why));
    }
    if units.is_empty() {
        t.meta
            .push(("note".into(), "no 'channel' struct: units unknown".into()));
    }
    Ok(t)
}

fn is_numeric_line(l: &str) -> bool {
    let mut toks = l.split(['\t', ',', ' ']).filter(|s| !s.is_empty());
    match toks.next() {
        Some(t) => {
            t.parse::<f64>().is_ok()
                && toks.all(|t| t.parse::<f64>().is_ok() || t.eq_ignore_ascii_case("nan"))
        }
        None => false,
    }
}

fn split_fields(l: &str) -> Vec<&str> {
    if l.contains('\t') {
        l.split('\t').map(|s| s.trim()).collect()
    } else if l.contains(',') {
        l.split(',').map(|s| s.trim()).collect()
    } else {
        l.split_whitespace().collect()
    }
}

/// Read a TTC `.dat` text export.
pub fn read_dat(bytes: &[u8], file: &str) -> Result<RawTable> {
    super::csvio::limit_rows(read_dat_unbounded(bytes, file)?, file)
}

/// [`read_dat`] without the row limit.
fn read_dat_unbounded(bytes: &[u8], file: &str) -> Result<RawTable> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        rerr(
            file,
            format!("byte {}", e.valid_up_to()),
            "not UTF-8/ASCII text",
        )
    })?;
    let lines: Vec<&str> = text.lines().collect();
    let Some(first_data) = lines.iter().position(|l| is_numeric_line(l)) else {
        return Err(rerr(file, "data", "no numeric data rows found"));
    };
    let header: Vec<(usize, &str)> = lines[..first_data]
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .collect();
    if header.is_empty() {
        return Err(rerr(file, "line 1", "no header row of channel names"));
    }
    let (names_line, units_line) = if header.len() >= 2 {
        (header[header.len() - 2], Some(header[header.len() - 1]))
    } else {
        (header[0], None)
    };
    let mut t = RawTable::default();
    for (i, l) in &header[..header.len().saturating_sub(2)] {
        t.meta
            .push((format!("line {}", i + 1), l.trim().to_string()));
    }
    let names: Vec<String> = split_fields(names_line.1)
        .into_iter()
        .map(String::from)
        .filter(|s| !s.is_empty())
        .collect();
    let units: Vec<String> = units_line
        .map(|(_, l)| split_fields(l).into_iter().map(String::from).collect())
        .unwrap_or_default();
    if units_line.is_some() && units.len() != names.len() {
        return Err(rerr(
            file,
            format!("line {}", units_line.map_or(0, |u| u.0 + 1)),
            format!("{} units for {} channel names", units.len(), names.len()),
        ));
    }
    let tab = lines[first_data].contains('\t');
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(MAX_THREADS)
        .min((lines.len() - first_data) / ROWS_PER_THREAD);
    let cols = parse_rows(&lines, first_data, &names, tab, file, threads)?;
    for (i, (n, d)) in names.into_iter().zip(cols).enumerate() {
        t.columns.push(RawColumn {
            name: n,
            unit: units.get(i).cloned(),
            data: d,
        });
    }
    Ok(t)
}

/// Rows one parser thread takes at least: below this the threads cost more
/// than they save.
const ROWS_PER_THREAD: usize = 100_000;
/// Most parser threads (the number parsing scales to about this many).
const MAX_THREADS: usize = 4;

/// The data rows `lines[first..]` as one column per name, parsed in
/// `threads` contiguous blocks side by side (number parsing is most of a
/// `.dat` load: a million 20-channel rows are 20 million numbers). The
/// blocks are joined in order and the first error in file order is the one
/// returned: the result is the single pass's for any `threads`.
fn parse_rows(
    lines: &[&str],
    first: usize,
    names: &[String],
    tab: bool,
    file: &str,
    threads: usize,
) -> Result<Vec<Vec<f64>>> {
    let body = &lines[first..];
    let block = body.len().div_ceil(threads.max(1)).max(1);
    let mut blocks = body.chunks(block).enumerate();
    // The first block on this thread (a small file starts none), the others
    // beside it — as the CSV reader and the `.mat` decoder split their work.
    let parts: Vec<Result<Vec<Vec<f64>>>> = std::thread::scope(|s| {
        let head = blocks.next();
        let rest: Vec<_> = blocks
            .map(|(b, rows)| {
                s.spawn(move || parse_block(rows, first + b * block, names, tab, file))
            })
            .collect();
        let mut parts = vec![head.map_or_else(
            || Ok(vec![Vec::new(); names.len()]),
            |(_, rows)| parse_block(rows, first, names, tab, file),
        )];
        parts.extend(rest.into_iter().map(|h| {
            h.join()
                .unwrap_or_else(|_| Err(rerr(file, "data", "a parser thread failed")))
        }));
        parts
    });
    let mut parts = parts.into_iter();
    let mut cols = parts.next().unwrap_or_else(|| Ok(Vec::new()))?;
    for p in parts {
        for (c, mut more) in cols.iter_mut().zip(p?) {
            c.append(&mut more);
        }
    }
    Ok(cols)
}

/// One block of data rows; `first` is the index of `rows[0]` among the
/// file's lines (for the line numbers in errors).
fn parse_block(
    rows: &[&str],
    first: usize,
    names: &[String],
    tab: bool,
    file: &str,
) -> Result<Vec<Vec<f64>>> {
    let ncol = names.len();
    let mut cols: Vec<Vec<f64>> = vec![Vec::with_capacity(rows.len()); ncol];
    for (i, l) in rows.iter().enumerate() {
        let li = first + i;
        if l.trim().is_empty() {
            continue;
        }
        let mut k = 0;
        let l = l.trim_end();
        // Either splitter on the stack: a boxed one cost an allocation per line.
        let (mut by_tab, mut by_space);
        let toks: &mut dyn Iterator<Item = &str> = if tab {
            by_tab = l.split('\t');
            &mut by_tab
        } else {
            by_space = l.split_whitespace();
            &mut by_space
        };
        for tok in toks {
            if k >= ncol {
                return Err(rerr(
                    file,
                    format!("line {}", li + 1),
                    format!("more than {ncol} values"),
                ));
            }
            let tok = tok.trim();
            let v = if tok.is_empty() {
                f64::NAN
            } else {
                tok.parse::<f64>().map_err(|_| {
                    rerr(
                        file,
                        format!("line {}, column '{}'", li + 1, names[k]),
                        format!("'{tok}' is not a number"),
                    )
                })?
            };
            cols[k].push(v);
            k += 1;
        }
        if k != ncol {
            return Err(rerr(
                file,
                format!("line {}", li + 1),
                format!("{k} values, {ncol} expected (truncated line?)"),
            ));
        }
    }
    Ok(cols)
}

/// Write a TTC-layout `.mat` (channels as column vectors, `channel` struct
/// array of name/units, meta entries as strings; zlib-compressed elements).
pub fn write_mat(t: &RawTable, compress: bool) -> Vec<u8> {
    let mut vars: Vec<(String, MatValue)> = Vec::new();
    for c in &t.columns {
        vars.push((c.name.clone(), MatValue::column(c.data.clone())));
    }
    vars.push((
        "channel".into(),
        MatValue::Struct {
            dims: vec![1, t.columns.len()],
            fields: vec!["name".into(), "units".into()],
            elements: t
                .columns
                .iter()
                .map(|c| {
                    vec![
                        MatValue::text(&c.name),
                        MatValue::text(c.unit.as_deref().unwrap_or("")),
                    ]
                })
                .collect(),
        },
    ));
    for (k, v) in &t.meta {
        vars.push((k.clone(), MatValue::text(v)));
    }
    mat::write(&vars, compress, "written by tyrekit rig")
}

/// Write a TTC-layout `.dat`: meta lines, names row, units row, tab-separated data.
pub fn write_dat(t: &RawTable) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    for (k, v) in &t.meta {
        let _ = writeln!(s, "{k}: {v}");
    }
    let names: Vec<&str> = t.columns.iter().map(|c| c.name.as_str()).collect();
    let units: Vec<&str> = t
        .columns
        .iter()
        .map(|c| c.unit.as_deref().unwrap_or("-"))
        .collect();
    let _ = writeln!(s, "{}", names.join("\t"));
    let _ = writeln!(s, "{}", units.join("\t"));
    for i in 0..t.rows() {
        for (k, c) in t.columns.iter().enumerate() {
            if k > 0 {
                s.push('\t');
            }
            let _ = write!(s, "{}", fmt_num(c.data[i]));
        }
        s.push('\n');
    }
    s
}

/// Compact number formatting: round-trip-exact shortest representation.
pub fn fmt_num(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        vec!["ET".into(), "FZ".into()]
    }

    /// Ten data rows after a header line, one of them empty.
    fn lines(bad: &[usize]) -> Vec<String> {
        let mut v = vec!["ET\tFZ".to_string()];
        for i in 0..10 {
            v.push(if i == 4 {
                String::new()
            } else if bad.contains(&i) {
                format!("{i}\tx{i}")
            } else {
                format!("{}\t{}", i as f64 * 0.01, -100.0 - i as f64)
            });
        }
        v
    }

    fn parse(bad: &[usize], threads: usize) -> Result<Vec<Vec<f64>>> {
        let owned = lines(bad);
        let l: Vec<&str> = owned.iter().map(|s| s.as_str()).collect();
        parse_rows(&l, 1, &names(), true, "t.dat", threads)
    }

    #[test]
    fn blocks_parsed_side_by_side_give_the_single_pass_s_columns() {
        let one = parse(&[], 1).unwrap();
        assert_eq!(one[0].len(), 9, "the empty line is skipped");
        assert_eq!(one[1][4], -105.0, "row order kept across the skipped line");
        for threads in [0, 2, 3, 4, 20] {
            assert_eq!(parse(&[], threads).unwrap(), one, "{threads} threads");
        }
    }

    #[test]
    fn the_first_bad_line_in_file_order_is_named_whatever_the_blocks() {
        // Data rows 6 and 8 are bad: file lines 8 and 10 (header = line 1).
        for threads in [1, 2, 3, 4] {
            let e = parse(&[8, 6], threads).unwrap_err().to_string();
            assert!(e.contains("line 8") && e.contains("'x6'"), "{threads}: {e}");
        }
    }
}
