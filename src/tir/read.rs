//! read — gives meaning to a parsed `.tir` document: `[UNITS]`, the key
//! table, defaults, warnings, and what is kept for the writer.
//!
//! Rules (see `tir/mod.rs` for the user-facing summary):
//! * a key of [`KEYS`] (or an alias of [`ALIASES`](super::keys::ALIASES)) is
//!   recognised in any section except `[UNITS]`, converted to SI by its
//!   [`Dim`](super::keys::Dim), and removed from the document (it lives in
//!   `MfParams`);
//! * a key given twice: the later value wins, with a warning naming both lines;
//! * an empty or non-numeric value of a numeric key is treated as not given
//!   (default used) with a warning (MFeval reads such values as NaN);
//! * everything else (strings, unknown keys and sections, tables, verbatim
//!   blocks) stays in the document.
//!
//! Must never: panic, or convert a value whose dimension it does not know.

use super::keys::{lookup_key, MfParams, KEYS, N_KEYS};
use super::parse::{parse_doc, truncate, Section, TirDoc, Value};
use super::units::{UnitKind, Units};
use super::{version, MfVersion, TyreSide};
use crate::error::{Error, Result};

/// Legacy spellings that look like table keys but are NOT read as them
/// (MFeval 4.0 ignores them too): `(legacy, table key)`.
pub const LEGACY_SPELLINGS: [(&str, &str); 10] = [
    ("QFZ1", "Q_FZ1"),
    ("QFZ2", "Q_FZ2"),
    ("QFZ3", "Q_FZ3"),
    ("QV1", "Q_V1"),
    ("QV2", "Q_V2"),
    ("QFCX1", "Q_FCX"),
    ("QFCY1", "Q_FCY"),
    ("QFCX", "Q_FCX"),
    ("QFCY", "Q_FCY"),
    ("QRE0", "Q_RE0"),
];

/// Everything [`read`] produces.
pub struct ReadOut {
    /// Equation set detected from FITTYP / PROPERTY_FILE_FORMAT.
    pub version: MfVersion,
    /// Numeric parameters converted to SI through `[UNITS]`, defaults filled in.
    pub p: MfParams,
    /// TYRESIDE of the file ([`TyreSide::Left`] when absent).
    pub side: TyreSide,
    /// Names of the table keys the file did not give validly (defaults used).
    pub defaulted: Vec<&'static str>,
    /// Table keys given with an empty or non-numeric value, with their line
    /// (1-based); read as not given.
    pub invalid: Vec<(&'static str, usize)>,
    /// Reader warnings with line numbers (duplicates, odd values …), capped.
    pub warnings: Vec<String>,
    /// Everything that is not a table key (strings, tables, unknown keys
    /// and sections), kept for the writer.
    pub doc: TirDoc,
}

/// Read `.tir` text; `file` labels errors and warnings.
pub fn read(text: &str, file: &str) -> Result<ReadOut> {
    let mut warnings = Vec::new();
    let mut doc = parse_doc(text, &mut warnings);
    let version = version::detect(&doc, file, &mut warnings)?;
    let units = take_units(&mut doc, file, &mut warnings)?;

    let mut p = MfParams::default();
    let mut given: [usize; N_KEYS] = [0; N_KEYS];
    let mut side = TyreSide::default();
    let mut side_line = 0usize;
    let mut unconverted: Vec<String> = Vec::new();
    let mut comments: Vec<(&'static str, String)> = Vec::new();
    let mut invalid: Vec<(&'static str, usize)> = Vec::new();

    for sec in doc.sections.iter_mut() {
        let entries = std::mem::take(&mut sec.entries);
        // First line of each unknown key of this section (upper case), for the
        // duplicate warning; duplicates are removed after the loop in linear time.
        let mut seen: std::collections::HashMap<String, usize> = Default::default();
        for e in entries {
            if e.key.eq_ignore_ascii_case("TYRESIDE") {
                if side_line != 0 {
                    warnings.push(format!(
                        "line {}: TYRESIDE given again (first at line {}); the later value is used",
                        side_line.max(e.line),
                        side_line.min(e.line)
                    ));
                }
                if e.line >= side_line {
                    side_line = e.line;
                    side = parse_side(&e.value, e.line, &mut warnings);
                }
                continue;
            }
            let Some(i) = lookup_key(&e.key) else {
                keep_unknown(sec, e, &units, &mut warnings, &mut unconverted, &mut seen);
                continue;
            };
            let def = &KEYS[i];
            if !sec.name.eq_ignore_ascii_case(def.section) && !sec.name.is_empty() {
                warnings.push(format!(
                    "line {}: {} found in [{}] (usually in [{}]); used",
                    e.line, e.key, sec.name, def.section
                ));
            }
            match e.value {
                Value::Number(x) => {
                    // Later in the file wins (sections met twice are merged
                    // into their first place, so compare lines, not order).
                    let (first, later) = (given[i].min(e.line), given[i].max(e.line));
                    if given[i] != 0 {
                        warnings.push(format!(
                            "line {later}: {} given again (first at line {first}); the later value is used",
                            def.name
                        ));
                    }
                    if e.line >= given[i] {
                        p.as_mut_slice()[i] = units.to_si(def.dim, x);
                        given[i] = e.line;
                        if !e.comment.is_empty() {
                            comments.push((def.name, e.comment));
                        }
                    }
                }
                ref other => {
                    // A value that starts like a number but does not parse
                    // (`0.3.1`, `1,5`, `2e`) is a typo in a number: refusing it
                    // is safer than running on a silently defaulted radius or
                    // load. Words (`MASS = kg`, seen in published files) and
                    // empty values are only warned about.
                    if let Some(s) = other.as_str() {
                        let t = s.trim();
                        if t.starts_with(|c: char| {
                            c.is_ascii_digit() || matches!(c, '+' | '-' | '.')
                        }) {
                            return Err(Error::Tir {
                                file: file.to_string(),
                                line: e.line,
                                key: def.name.to_string(),
                                message: format!("expected a number, found {:?}", truncate(t)),
                            });
                        }
                    }
                    let found = match other.as_str() {
                        Some(s) => format!("found {:?}", truncate(s)),
                        None => "found an empty value".to_string(),
                    };
                    warnings.push(format!(
                        "line {}: {}: expected a number, {found}; treated as not given \
                         (default {:?} unless the key is given elsewhere)",
                        e.line, def.name, def.default
                    ));
                    invalid.push((def.name, e.line));
                }
            }
        }
        if seen.len() < sec.entries.len() {
            keep_last(&mut sec.entries);
        }
        convert_table(sec, &units, &mut warnings);
    }
    cap_warnings(&mut warnings);
    plausibility(&p, &given, &units, &mut warnings);
    for (k, c) in comments {
        doc.key_comments.insert(k.to_string(), c);
    }
    if !unconverted.is_empty() {
        warnings.push(format!(
            "[UNITS] is not SI, but these keys are not in tyrekit's key table, so their values \
             were kept as written, not converted: {}",
            unconverted.join(", ")
        ));
    }

    let defaulted = KEYS
        .iter()
        .zip(given.iter())
        .filter(|(_, &g)| g == 0)
        .map(|(k, _)| k.name)
        .collect();
    Ok(ReadOut {
        version,
        p,
        side,
        defaulted,
        invalid,
        warnings,
        doc,
    })
}

/// Keep a key that is not in the table: later duplicates win; legacy
/// spellings are named in a warning.
fn keep_unknown(
    sec: &mut Section,
    e: super::parse::Entry,
    units: &Units,
    warnings: &mut Vec<String>,
    unconverted: &mut Vec<String>,
    seen: &mut std::collections::HashMap<String, usize>,
) {
    if let Some((legacy, real)) = LEGACY_SPELLINGS
        .iter()
        .find(|(l, _)| l.eq_ignore_ascii_case(&e.key))
    {
        warnings.push(format!(
            "line {}: {legacy} is a legacy spelling of {real}; like MFeval, tyrekit does not read it \
             ({real} keeps its own value); the key is kept for the writer",
            e.line
        ));
    }
    let upper = e.key.to_ascii_uppercase();
    if let Some(first) = seen.get(&upper) {
        warnings.push(format!(
            "line {}: {} given again in [{}] (first at line {first}); the later value is used",
            e.line, e.key, sec.name
        ));
    } else {
        seen.insert(upper, e.line);
    }
    if matches!(e.value, Value::Number(_)) && !units.is_si() {
        unconverted.push(format!("{} (line {})", e.key, e.line));
    }
    sec.entries.push(e);
}

/// Keep only the last entry of each key (case-insensitive), in the order of
/// those last entries: what removing the earlier one at each duplicate gave,
/// in linear time.
fn keep_last(entries: &mut Vec<super::parse::Entry>) {
    let mut seen = std::collections::HashSet::new();
    let mut out: Vec<super::parse::Entry> = std::mem::take(entries)
        .into_iter()
        .rev()
        .filter(|e| seen.insert(e.key.to_ascii_uppercase()))
        .collect();
    out.reverse();
    *entries = out;
}

/// At most this many warnings are kept (a hostile file can give one per
/// line); the rest are counted in a last warning.
pub const MAX_WARNINGS: usize = 200;

fn cap_warnings(w: &mut Vec<String>) {
    if w.len() > MAX_WARNINGS {
        let more = w.len() - MAX_WARNINGS;
        w.truncate(MAX_WARNINGS);
        w.push(format!(
            "… and {more} more warnings (only the first {MAX_WARNINGS} are listed)"
        ));
        w.shrink_to_fit();
    }
}

fn parse_side(v: &Value, line: usize, warnings: &mut Vec<String>) -> TyreSide {
    let s = v.as_str().unwrap_or("").trim().to_ascii_uppercase();
    match s.as_str() {
        "LEFT" | "L" => TyreSide::Left,
        "RIGHT" | "R" => TyreSide::Right,
        "SYMMETRIC" | "SYM" => TyreSide::Symmetric,
        "UNKNOWN" => TyreSide::Unknown,
        _ => {
            warnings.push(format!(
                "line {line}: TYRESIDE: expected 'LEFT', 'RIGHT', 'SYMMETRIC' or 'UNKNOWN', found {v:?}; UNKNOWN used"
            ));
            TyreSide::Unknown
        }
    }
}

/// Read and remove the unit keys of `[UNITS]` (the section itself is dropped
/// when nothing else is in it: the writer writes its own, SI).
fn take_units(doc: &mut TirDoc, file: &str, warnings: &mut Vec<String>) -> Result<Units> {
    let mut units = Units::SI;
    let Some(idx) = doc
        .sections
        .iter()
        .position(|s| s.name.eq_ignore_ascii_case("UNITS"))
    else {
        return Ok(units);
    };
    let sec = &mut doc.sections[idx];
    let entries = std::mem::take(&mut sec.entries);
    for e in entries {
        let Some(kind) = UnitKind::from_key(&e.key) else {
            warnings.push(format!(
                "line {}: {} is not a unit key of [UNITS] (LENGTH, FORCE, ANGLE, MASS, TIME, PRESSURE); kept as is",
                e.line, e.key
            ));
            sec.entries.push(e);
            continue;
        };
        let name = match &e.value {
            Value::Text(s) | Value::Word(s) => s.trim().to_string(),
            Value::Empty => {
                warnings.push(format!(
                    "line {}: {}: empty unit; SI ({}) assumed",
                    e.line,
                    e.key,
                    kind.si_name()
                ));
                continue;
            }
            Value::Number(x) => x.to_string(),
        };
        match kind.factor(&name) {
            Some(f) => units.set(kind, f),
            None => {
                return Err(Error::Tir {
                    file: file.to_string(),
                    line: e.line,
                    key: e.key.clone(),
                    message: format!(
                        "unknown {} unit '{}' (expected one of {})",
                        kind.key().to_ascii_lowercase(),
                        truncate(&name),
                        kind.accepted()
                    ),
                })
            }
        }
    }
    if sec.is_empty() {
        doc.sections.remove(idx);
    }
    Ok(units)
}

/// Dimension of a table column, by its `{...}` name or, without a header,
/// by the section it is in.
fn column_dims(sec: &Section, ncols: usize) -> Vec<Option<super::keys::Dim>> {
    use super::keys::Dim;
    let by_name = |c: &str| match c.to_ascii_lowercase().as_str() {
        "pen" | "defl" | "deflection" | "penetration" | "rho" => Some(Dim::Length),
        "fz" | "force" | "load" => Some(Dim::Force),
        "radial" | "width" => Some(Dim::One),
        _ => None,
    };
    let Some(t) = &sec.table else {
        return Vec::new();
    };
    if !t.columns.is_empty() {
        return (0..ncols)
            .map(|j| t.columns.get(j).and_then(|c| by_name(c)))
            .collect();
    }
    let name = sec.name.to_ascii_uppercase();
    let fixed: &[Dim] = match name.as_str() {
        "SHAPE" => &[Dim::One, Dim::One],
        "DEFLECTION_LOAD_CURVE" | "BOTTOMING_CURVE" => &[Dim::Length, Dim::Force],
        _ => &[],
    };
    (0..ncols).map(|j| fixed.get(j).copied()).collect()
}

fn convert_table(sec: &mut Section, units: &Units, warnings: &mut Vec<String>) {
    if units.is_si() {
        return;
    }
    let ncols = match &sec.table {
        Some(t) => t.rows.iter().map(Vec::len).max().unwrap_or(0),
        None => return,
    };
    let dims = column_dims(sec, ncols);
    let name = sec.name.clone();
    let Some(t) = sec.table.as_mut() else { return };
    if dims.iter().any(Option::is_none) {
        warnings.push(format!(
            "line {}: table of [{name}]: unknown column dimension, values kept as written (not converted by [UNITS])",
            t.line
        ));
    }
    for row in t.rows.iter_mut() {
        for (x, d) in row.iter_mut().zip(dims.iter()) {
            if let Some(d) = d {
                *x = units.to_si(*d, *x);
            }
        }
    }
}

/// Warn (never refuse) when a converted size, load or pressure is far outside
/// anything a tyre has: the usual sign of a wrong `[UNITS]` section.
fn plausibility(p: &MfParams, given: &[usize; N_KEYS], units: &Units, warnings: &mut Vec<String>) {
    const RANGES: [(&str, f64, f64, &str); 4] = [
        ("UNLOADED_RADIUS", 0.05, 5.0, "m"),
        ("FNOMIN", 10.0, 1e6, "N"),
        ("NOMPRES", 1e3, 1e8, "Pa"),
        ("INFLPRES", 1e3, 1e8, "Pa"),
    ];
    for (name, lo, hi, unit) in RANGES {
        let Some(i) = super::keys::key_index(name) else {
            continue;
        };
        let x = p.as_slice()[i];
        if given[i] != 0 && x != 0.0 && !(lo..=hi).contains(&x.abs()) {
            let hint = if unit == "Pa" && units.pressure.is_none() {
                " ([UNITS] has no PRESSURE key, so pressures are read in FORCE/LENGTH^2)"
            } else {
                ""
            };
            warnings.push(format!(
                "line {}: {name} = {x} {unit} after [UNITS] conversion is outside {lo}..{hi} {unit}; \
                 check the [UNITS] section{hint}",
                given[i]
            ));
        }
    }
}
