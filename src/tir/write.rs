//! write — renders a [`TyreParams`] as `.tir` text that reads back to
//! bit-identical parameters.
//!
//! Layout: header comments, `[MDI_HEADER]`, `[UNITS]` (always SI), the
//! sections of the key table in table order (each with the kept entries of
//! the same-named section first: strings such as PROPERTY_FILE_FORMAT, unknown
//! keys), then every other kept section (vendor sections, tables, custom
//! sections added through the API) in document order.
//!
//! Numbers are written with Rust's shortest round-trip formatting (`{:?}`:
//! the shortest decimal that parses back to the same `f64`), never a lossy
//! `%e`. A key the source file did not give (listed in `defaulted`) whose
//! value is still its default is written as a `$` comment, so the written file
//! leaves it not given as well (MFeval, and so the MF code, treat some absent
//! keys differently from the same value given).
//!
//! Must never: write something the reader would read differently (names and
//! strings that cannot be represented are sanitised, see [`sanitize_text`]).

use super::keys::{KEYS, N_KEYS};
use super::parse::{Section, Table, Value};
use super::units::UnitKind;
use super::{version, MfVersion, TyreParams, TyreSide};
use std::fmt::Write as _;

/// Shortest round-trip text of a number.
pub fn fmt_num(x: f64) -> String {
    format!("{x:?}")
}

/// Make a string safe inside single quotes on one line: `'` becomes `"`,
/// line breaks become blanks.
pub fn sanitize_text(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '\'' => '"',
            '\n' | '\r' => ' ',
            c => c,
        })
        .collect()
}

/// Make a key or section name safe: only letters, digits and `_ . - / ( )`.
fn sanitize_name(s: &str) -> String {
    let t: String = s
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-' | '/' | '(' | ')') {
                c
            } else {
                '_'
            }
        })
        .collect();
    // A line starting with `(` would be read as a verbatim block.
    if t.is_empty() || t.starts_with('(') {
        format!("_{t}")
    } else {
        t
    }
}

fn fmt_value(v: &Value) -> String {
    match v {
        Value::Number(x) if x.is_finite() => fmt_num(*x),
        Value::Number(x) => format!("'{x}'"),
        Value::Text(s) => format!("'{}'", sanitize_text(s)),
        Value::Word(s) => {
            let clean = sanitize_text(s);
            if clean.contains(['$', '!', '=']) || clean.trim() != clean || clean.is_empty() {
                format!("'{clean}'")
            } else {
                clean
            }
        }
        Value::Empty => String::new(),
    }
}

fn line(out: &mut String, key: &str, value: &str, comment: &str) {
    let _ = write!(out, "{key:<24} = {value}");
    let c = comment.replace(['\n', '\r'], " ");
    if !c.trim().is_empty() {
        let pad = 16usize.saturating_sub(value.chars().count());
        let _ = write!(out, "{:pad$} $ {}", "", c.trim());
    }
    out.push('\n');
}

fn separator(out: &mut String, label: &str) {
    let _ = writeln!(
        out,
        "$---------------------------------------------------{label}"
    );
}

fn entries(out: &mut String, sec: &Section) {
    let units = sec.name.eq_ignore_ascii_case("UNITS");
    for e in &sec.entries {
        // Keys of the table live in `p`, TYRESIDE in `side`, the units are
        // written SI above: writing them here too would make a duplicate.
        if super::keys::lookup_key(&e.key).is_some()
            || e.key.eq_ignore_ascii_case("TYRESIDE")
            || (units && UnitKind::from_key(&e.key).is_some())
        {
            continue;
        }
        line(
            out,
            &sanitize_name(&e.key),
            &fmt_value(&e.value),
            &e.comment,
        );
    }
}

fn table(out: &mut String, t: &Table) {
    if !t.columns.is_empty() {
        let cols: Vec<String> = t.columns.iter().map(|c| sanitize_name(c)).collect();
        let _ = writeln!(out, "{{{}}}", cols.join(" "));
    }
    for row in &t.rows {
        let cells: Vec<String> = row
            .iter()
            .map(|&x| {
                if x.is_finite() {
                    fmt_num(x)
                } else {
                    "0.0".into()
                }
            })
            .collect();
        let _ = writeln!(out, " {}", cells.join("  "));
    }
}

fn rest_of_section(out: &mut String, sec: &Section) {
    if let Some(t) = &sec.table {
        table(out, t);
    }
    for r in &sec.raw {
        out.push_str(r);
        out.push('\n');
    }
}

/// The `.tir` text of `t` (see the module doc).
pub fn to_tir_string(t: &TyreParams) -> String {
    let mut out = String::with_capacity(32 * 1024);
    let doc = &t.doc;
    for c in &doc.header_comments {
        let _ = writeln!(out, "!{}", c.replace(['\n', '\r'], " "));
    }
    if doc.header_comments.is_empty() {
        let _ = writeln!(
            out,
            "! Written by tyrekit (SI units). Source: {}",
            t.source.replace(['\n', '\r'], " ")
        );
    }
    if let Some(pre) = doc.sections.iter().find(|s| s.name.is_empty()) {
        entries(&mut out, pre);
        rest_of_section(&mut out, pre);
    }

    // [MDI_HEADER]
    separator(&mut out, "mdi_header");
    out.push_str("[MDI_HEADER]\n");
    let mdi = doc.section("MDI_HEADER");
    for (k, v) in [
        ("FILE_TYPE", Value::text("tir")),
        ("FILE_VERSION", Value::Number(3.0)),
        ("FILE_FORMAT", Value::text("ASCII")),
    ] {
        if mdi.and_then(|s| s.get(k)).is_none() {
            line(&mut out, k, &fmt_value(&v), "");
        }
    }
    if let Some(s) = mdi {
        entries(&mut out, s);
        rest_of_section(&mut out, s);
    }

    // [UNITS]
    separator(&mut out, "units");
    out.push_str("[UNITS]\n");
    for k in UnitKind::ALL {
        line(&mut out, k.key(), &format!("'{}'", k.si_name()), "");
    }
    if let Some(s) = doc.section("UNITS") {
        entries(&mut out, s);
        rest_of_section(&mut out, s);
    }

    // The key table's sections.
    let values = t.p.as_slice();
    let mut i = 0;
    while i < N_KEYS {
        let name = KEYS[i].section;
        let end = (i..N_KEYS)
            .find(|&j| KEYS[j].section != name)
            .unwrap_or(N_KEYS);
        separator(&mut out, &name.to_ascii_lowercase());
        let _ = writeln!(out, "[{name}]");
        let kept = doc.section(name);
        if name == "MODEL" {
            model_strings(&mut out, t, kept);
        } else if let Some(s) = kept {
            entries(&mut out, s);
        }
        for (j, &x) in values.iter().enumerate().take(end).skip(i) {
            key_line(&mut out, t, j, x);
        }
        if let Some(s) = kept {
            rest_of_section(&mut out, s);
        }
        i = end;
    }

    // Everything else, in document order.
    for s in &doc.sections {
        let n = s.name.as_str();
        if n.is_empty()
            || n.eq_ignore_ascii_case("MDI_HEADER")
            || n.eq_ignore_ascii_case("UNITS")
            || KEYS.iter().any(|k| k.section.eq_ignore_ascii_case(n))
        {
            continue;
        }
        separator(&mut out, &n.to_ascii_lowercase());
        let _ = writeln!(out, "[{}]", sanitize_name(n));
        entries(&mut out, s);
        rest_of_section(&mut out, s);
    }
    out
}

/// `[MODEL]` strings: PROPERTY_FILE_FORMAT consistent with the version,
/// TYRESIDE from `side`, then the other kept entries.
fn model_strings(out: &mut String, t: &TyreParams, kept: Option<&Section>) {
    let pff = kept.and_then(|s| s.get("PROPERTY_FILE_FORMAT"));
    if t.version == MfVersion::Pac2002 {
        line(out, "PROPERTY_FILE_FORMAT", "'PAC2002'", "");
    } else if let Some(v) = pff {
        line(out, "PROPERTY_FILE_FORMAT", &fmt_value(v), "");
    }
    let side = match t.side {
        TyreSide::Left => "LEFT",
        TyreSide::Right => "RIGHT",
        TyreSide::Symmetric => "SYMMETRIC",
        TyreSide::Unknown => "UNKNOWN",
    };
    line(out, "TYRESIDE", &format!("'{side}'"), "");
    if let Some(s) = kept {
        let mut rest = s.clone();
        rest.remove("PROPERTY_FILE_FORMAT");
        entries(out, &rest);
    }
}

fn key_line(out: &mut String, t: &TyreParams, j: usize, x: f64) {
    let k = &KEYS[j];
    if k.name == "FITTYP" {
        // The version must survive the round trip: FITTYP as read when it
        // names this version, else the version's own number; none for PAC2002.
        match version::canonical_fittyp(t.version) {
            None => {
                let _ = writeln!(out, "$FITTYP not written: PAC2002 property file");
                return;
            }
            Some(_) if t.defaulted.contains(&"FITTYP") && x.to_bits() == k.default.to_bits() => {
                // The version came from PROPERTY_FILE_FORMAT / TIRE_VERSION,
                // which are kept: leave FITTYP not given, as in the source.
                let _ = writeln!(out, "$FITTYP not in the source file");
                return;
            }
            Some(c) => {
                let v = if version::from_fittyp(x) == Some(t.version) {
                    x
                } else {
                    c
                };
                line(out, k.name, &fmt_num(v), "Magic Formula version");
                return;
            }
        }
    }
    let defaulted = t.defaulted.contains(&k.name);
    if defaulted && x.to_bits() == k.default.to_bits() {
        let _ = writeln!(
            out,
            "${:<23} = {}  (not in the source file: default)",
            k.name,
            fmt_num(x)
        );
    } else if x.is_finite() {
        let comment = t.doc.key_comments.get(k.name).map_or("", String::as_str);
        line(out, k.name, &fmt_num(x), comment);
    } else {
        let _ = writeln!(
            out,
            "${:<23} = {}  (not finite: not written)",
            k.name,
            fmt_num(x)
        );
    }
}
