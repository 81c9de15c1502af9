//! mat — a small reader and writer for MATLAB MAT-file level 5 (the format
//! `save -v6` / `-v7` writes, including `miCOMPRESSED` zlib elements), covering
//! what tyre-test exports use: numeric arrays (any stored integer/float type),
//! character arrays, structs and cells. MCOS objects (`table`, `timetable`)
//! are recognised and reported as unsupported, never misread.
//!
//! Written here rather than taken from `matfile` 0.5 because that crate reads
//! numeric arrays only (no char arrays, no structs: the TTC `channel` struct
//! of names/units would be lost) and cannot write, while the rig simulator
//! must write `.mat` files. Format: MathWorks, "MAT-File Format" (R2024a),
//! chapter 1 "Level 5 MAT-File Format".
//!
//! Must never: panic or over-allocate on a truncated/corrupt file (every
//! length is checked against the bytes actually present), or silently turn a
//! non-numeric variable into numbers.

use std::io::{Read, Write};

/// Data types of the level-5 format (tag field "data type").
mod mi {
    pub const INT8: u32 = 1;
    pub const UINT8: u32 = 2;
    pub const INT16: u32 = 3;
    pub const UINT16: u32 = 4;
    pub const INT32: u32 = 5;
    pub const UINT32: u32 = 6;
    pub const SINGLE: u32 = 7;
    pub const DOUBLE: u32 = 9;
    pub const INT64: u32 = 12;
    pub const UINT64: u32 = 13;
    pub const MATRIX: u32 = 14;
    pub const COMPRESSED: u32 = 15;
    pub const UTF8: u32 = 16;
    pub const UTF16: u32 = 17;
    pub const UTF32: u32 = 18;
}

/// Array classes (low byte of the array-flags word).
mod mx {
    pub const CELL: u8 = 1;
    pub const STRUCT: u8 = 2;
    pub const OBJECT: u8 = 3;
    pub const CHAR: u8 = 4;
    pub const SPARSE: u8 = 5;
    pub const OPAQUE: u8 = 17;
}

/// A MATLAB value as far as tyre-test files need it.
#[derive(Clone, Debug, PartialEq)]
pub enum MatValue {
    /// Numeric or logical array, column-major, real part converted to f64.
    Numeric {
        /// Array dimensions in MATLAB order (rows, columns, …).
        dims: Vec<usize>,
        /// Values in column-major order.
        data: Vec<f64>,
    },
    /// Character array (rows joined with '\n' when more than one row).
    Char {
        /// Array dimensions as stored (rows, columns).
        dims: Vec<usize>,
        /// The characters, one line per row, trailing NULs and blanks trimmed.
        text: String,
    },
    /// Struct array: field names and, per element, one value per field.
    Struct {
        /// Dimensions of the struct array (1×1 for a scalar struct).
        dims: Vec<usize>,
        /// Field names, in stored order.
        fields: Vec<String>,
        /// One entry per struct element (column-major); each holds the
        /// values in the order of `fields`.
        elements: Vec<Vec<MatValue>>,
    },
    /// Cell array, column-major.
    Cell {
        /// Dimensions of the cell array.
        dims: Vec<usize>,
        /// The cells, column-major.
        items: Vec<MatValue>,
    },
    /// A class this reader does not decode (objects such as `table`, sparse …).
    Unsupported {
        /// What the value is (e.g. "sparse"), with advice where there is some.
        class: String,
    },
}

impl MatValue {
    /// Numeric data, if numeric.
    pub fn as_numeric(&self) -> Option<&[f64]> {
        match self {
            MatValue::Numeric { data, .. } => Some(data),
            _ => None,
        }
    }
    /// Text, if a char array; a cell of strings is joined with ", ".
    pub fn as_text(&self) -> Option<String> {
        match self {
            MatValue::Char { text, .. } => Some(text.clone()),
            MatValue::Cell { items, .. } => {
                let v: Option<Vec<String>> = items.iter().map(|i| i.as_text()).collect();
                v.map(|v| v.join(", "))
            }
            _ => None,
        }
    }
    /// Field of a scalar struct.
    pub fn field(&self, name: &str) -> Option<&MatValue> {
        match self {
            MatValue::Struct {
                fields, elements, ..
            } => {
                let i = fields.iter().position(|f| f == name)?;
                elements.first().and_then(|e| e.get(i))
            }
            _ => None,
        }
    }
    /// Short description of the kind, for messages.
    pub fn kind(&self) -> String {
        match self {
            MatValue::Numeric { dims, .. } => format!("numeric {}", dims_str(dims)),
            MatValue::Char { .. } => "char".into(),
            MatValue::Struct { dims, .. } => format!("struct {}", dims_str(dims)),
            MatValue::Cell { dims, .. } => format!("cell {}", dims_str(dims)),
            MatValue::Unsupported { class } => format!("unsupported class {class}"),
        }
    }
    /// A real column/row vector of f64 from a slice.
    pub fn column(data: Vec<f64>) -> MatValue {
        MatValue::Numeric {
            dims: vec![data.len(), 1],
            data,
        }
    }
    /// A 1×n char array.
    pub fn text(s: &str) -> MatValue {
        MatValue::Char {
            dims: vec![1, s.chars().count()],
            text: s.to_string(),
        }
    }
}

fn dims_str(d: &[usize]) -> String {
    d.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join("x")
}

/// Parse failure: where (variable path) and what.
#[derive(Debug, Clone, PartialEq)]
pub struct MatError {
    /// Variable (or "header") the problem was found in, with byte offset.
    pub location: String,
    /// What is wrong, in words.
    pub message: String,
}

type R<T> = Result<T, MatError>;

fn err<T>(location: &str, message: impl Into<String>) -> R<T> {
    Err(MatError {
        location: location.to_string(),
        message: message.into(),
    })
}

/// Deepest nesting of structs and cells accepted (TTC files nest 3 deep; a
/// hostile file nested 10 000 deep overflowed the stack).
pub const MAX_DEPTH: usize = 32;
/// Inflated bytes allowed per byte of file (zlib reaches ~1000:1 on a bomb;
/// measurement data compresses 1.2–5:1).
pub const INFLATE_RATIO: usize = 64;
/// Absolute cap on the inflated bytes of one file (all its variables).
pub const MAX_INFLATED: usize = 256 << 20;
/// Absolute cap on the numeric values of one file (all its arrays): 256 MiB
/// of f64; with [`MAX_INFLATED`] this bounds the reader's peak memory
/// (measured in `tests/reader_bounds.rs`).
pub const MAX_VALUES: usize = 32 << 20;

/// What one file may still use (shared by the decoding threads).
struct Budget {
    inflated: std::sync::atomic::AtomicUsize,
    values: std::sync::atomic::AtomicUsize,
}

impl Budget {
    /// Take `n` from `pool`; false (and nothing taken) when it has less.
    fn take(pool: &std::sync::atomic::AtomicUsize, n: usize) -> bool {
        use std::sync::atomic::Ordering::SeqCst;
        pool.fetch_update(SeqCst, SeqCst, |left| left.checked_sub(n))
            .is_ok()
    }
}

/// Read all variables of a level-5 MAT file, in file order.
pub fn read(bytes: &[u8]) -> R<Vec<(String, MatValue)>> {
    if bytes.len() < 128 {
        return err(
            "header",
            format!(
                "file is {} bytes, shorter than the 128-byte MAT-file header (truncated or not a MAT file)",
                bytes.len()
            ),
        );
    }
    if bytes.starts_with(b"MATLAB 7.3") || bytes.starts_with(b"\x89HDF") {
        return err(
            "header",
            "MAT-file version 7.3 (HDF5) is not supported; re-save with save(..., '-v7')",
        );
    }
    let big = match &bytes[126..128] {
        b"IM" => false,
        b"MI" => true,
        _ => {
            return err(
                "header",
                "no 'IM'/'MI' endian indicator at byte 126: not a level-5 MAT file",
            )
        }
    };
    // First pass: locate the top-level elements (cheap); second: decode them,
    // the compressed ones on two threads (each variable is its own zlib stream).
    let mut elems: Vec<(u32, usize, usize, String)> = Vec::new();
    let mut pos = 128usize;
    let mut k = 0usize;
    while pos + 8 <= bytes.len() {
        let loc = format!("element {k} at byte {pos}");
        let (ty, n, hdr, small) = tag(bytes, pos, big, &loc)?;
        let body_start = pos + hdr;
        if small {
            pos += 8;
            k += 1;
            continue;
        }
        let end = body_start.checked_add(n).filter(|&e| e <= bytes.len());
        let Some(end) = end else {
            return err(
                &loc,
                format!(
                    "element declares {n} bytes but only {} remain (file truncated)",
                    bytes.len() - body_start
                ),
            );
        };
        if ty == mi::COMPRESSED || ty == mi::MATRIX {
            elems.push((ty, body_start, end, loc));
        }
        pos = if ty == mi::COMPRESSED {
            end
        } else {
            end + pad8(n)
        };
        k += 1;
    }
    if pos < bytes.len() && bytes.len() - pos < 8 && bytes[pos..].iter().any(|&b| b != 0) {
        return err(
            &format!("byte {pos}"),
            "trailing partial element (file truncated)",
        );
    }
    let cap = bytes
        .len()
        .saturating_mul(INFLATE_RATIO)
        .saturating_add(1 << 20)
        .min(MAX_INFLATED);
    let budget = Budget {
        inflated: cap.into(),
        values: MAX_VALUES.into(),
    };
    let decode = |(ty, a, b, loc): &(u32, usize, usize, String)| -> R<(String, MatValue)> {
        let body = &bytes[*a..*b];
        if *ty == mi::MATRIX {
            return matrix(body, big, loc, 0, &budget);
        }
        let mut dec = Vec::new();
        let left = budget.inflated.load(std::sync::atomic::Ordering::SeqCst);
        let inflated = flate2::read::ZlibDecoder::new(body)
            .take(left as u64 + 1)
            .read_to_end(&mut dec);
        if dec.len() > left || !Budget::take(&budget.inflated, dec.len()) {
            return err(
                loc,
                format!(
                    "compressed variables inflate to more than {} MiB for a {}-byte file \
                     (at most {INFLATE_RATIO} times the file size, {} MiB in all): \
                     a decompression bomb or a corrupt file; refused",
                    cap >> 20,
                    bytes.len(),
                    MAX_INFLATED >> 20
                ),
            );
        }
        inflated.map_err(|e| MatError {
            location: loc.clone(),
            message: format!("zlib stream of a compressed variable is corrupt or truncated: {e}"),
        })?;
        let (ty2, n2, hdr2, _) = tag(&dec, 0, big, loc)?;
        if ty2 != mi::MATRIX {
            return err(
                loc,
                format!("compressed element holds data type {ty2}, expected miMATRIX (14)"),
            );
        }
        if hdr2 + n2 > dec.len() {
            return err(
                loc,
                "compressed variable is shorter than its declared size (truncated)",
            );
        }
        matrix(&dec[hdr2..hdr2 + n2], big, loc, 0, &budget)
    };
    // Split the work by bytes between two threads.
    let total: usize = elems.iter().map(|e| e.2 - e.1).sum();
    let mut acc = 0;
    let cut = elems
        .iter()
        .position(|e| {
            acc += e.2 - e.1;
            acc * 2 >= total
        })
        .map_or(elems.len(), |i| i + 1);
    let (first, second) = elems.split_at(cut);
    let (ra, rb) = std::thread::scope(|sc| {
        let h = sc.spawn(|| second.iter().map(decode).collect::<R<Vec<_>>>());
        let ra = first.iter().map(decode).collect::<R<Vec<_>>>();
        (
            ra,
            h.join()
                .unwrap_or_else(|_| err("decoder", "decoder thread failed")),
        )
    });
    let mut out = ra?;
    out.extend(rb?);
    Ok(out)
}

fn pad8(n: usize) -> usize {
    (8 - n % 8) % 8
}

fn u32_at(b: &[u8], p: usize, big: bool) -> u32 {
    let a = [b[p], b[p + 1], b[p + 2], b[p + 3]];
    if big {
        u32::from_be_bytes(a)
    } else {
        u32::from_le_bytes(a)
    }
}

/// Read a tag at `p`: (type, nbytes, header length, small-element flag).
fn tag(b: &[u8], p: usize, big: bool, loc: &str) -> R<(u32, usize, usize, bool)> {
    if p + 8 > b.len() {
        return err(loc, "data element tag cut off (truncated)");
    }
    let w0 = u32_at(b, p, big);
    if w0 >> 16 != 0 {
        // Small data element: 2-byte size, 2-byte type, 4 bytes of data.
        let n = (w0 >> 16) as usize;
        if n > 4 {
            return err(loc, format!("small data element claims {n} bytes (max 4)"));
        }
        return Ok((w0 & 0xffff, n, 4, true));
    }
    Ok((w0, u32_at(b, p + 4, big) as usize, 8, false))
}

/// Sub-element reader over the body of one miMATRIX.
struct Sub<'a> {
    b: &'a [u8],
    p: usize,
    big: bool,
    loc: String,
}

impl<'a> Sub<'a> {
    /// Next sub-element: (type, data slice).
    fn next(&mut self, what: &str) -> R<(u32, &'a [u8])> {
        let (ty, n, hdr, small) = tag(self.b, self.p, self.big, &format!("{} ({what})", self.loc))?;
        let s = self.p + hdr;
        if s + n > self.b.len() {
            return err(
                &self.loc,
                format!(
                    "{what}: {n} bytes declared, {} present (truncated)",
                    self.b.len().saturating_sub(s)
                ),
            );
        }
        let data = &self.b[s..s + n];
        self.p = if small { self.p + 8 } else { s + n + pad8(n) };
        Ok((ty, data))
    }
}

fn to_f64(ty: u32, d: &[u8], big: bool, loc: &str) -> R<Vec<f64>> {
    macro_rules! conv {
        ($t:ty, $n:expr) => {{
            if d.len() % $n != 0 {
                return err(
                    loc,
                    format!(
                        "{} bytes is not a whole number of {}-byte values",
                        d.len(),
                        $n
                    ),
                );
            }
            d.chunks_exact($n)
                .map(|c| {
                    let a: [u8; $n] = c.try_into().unwrap_or([0; $n]);
                    (if big {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }) as f64
                })
                .collect()
        }};
    }
    Ok(match ty {
        mi::DOUBLE => conv!(f64, 8),
        mi::SINGLE => conv!(f32, 4),
        mi::INT8 => d.iter().map(|&x| x as i8 as f64).collect(),
        mi::UINT8 => d.iter().map(|&x| x as f64).collect(),
        mi::INT16 => conv!(i16, 2),
        mi::UINT16 => conv!(u16, 2),
        mi::INT32 => conv!(i32, 4),
        mi::UINT32 => conv!(u32, 4),
        mi::INT64 => conv!(i64, 8),
        mi::UINT64 => conv!(u64, 8),
        _ => return err(loc, format!("data type {ty} is not numeric")),
    })
}

fn to_text(ty: u32, d: &[u8], big: bool, loc: &str) -> R<Vec<char>> {
    Ok(match ty {
        mi::UTF8 | mi::INT8 | mi::UINT8 => String::from_utf8_lossy(d).chars().collect(),
        mi::UTF16 | mi::UINT16 | mi::INT16 => {
            let u: Vec<u16> = d
                .chunks_exact(2)
                .map(|c| {
                    if big {
                        u16::from_be_bytes([c[0], c[1]])
                    } else {
                        u16::from_le_bytes([c[0], c[1]])
                    }
                })
                .collect();
            char::decode_utf16(u)
                .map(|c| c.unwrap_or('\u{fffd}'))
                .collect()
        }
        mi::UTF32 | mi::UINT32 | mi::INT32 => d
            .chunks_exact(4)
            .map(|c| {
                let a = [c[0], c[1], c[2], c[3]];
                let v = if big {
                    u32::from_be_bytes(a)
                } else {
                    u32::from_le_bytes(a)
                };
                char::from_u32(v).unwrap_or('\u{fffd}')
            })
            .collect(),
        _ => return err(loc, format!("char data stored as type {ty}")),
    })
}

/// Decode the body of a miMATRIX element: (name, value).
fn matrix(
    body: &[u8],
    big: bool,
    loc: &str,
    depth: usize,
    budget: &Budget,
) -> R<(String, MatValue)> {
    if depth > MAX_DEPTH {
        return err(
            loc,
            format!("structs/cells nested more than {MAX_DEPTH} deep; not a recording"),
        );
    }
    if body.is_empty() {
        // An empty miMATRIX is a valid empty array (e.g. an empty struct field).
        return Ok((
            String::new(),
            MatValue::Numeric {
                dims: vec![0, 0],
                data: vec![],
            },
        ));
    }
    let mut s = Sub {
        b: body,
        p: 0,
        big,
        loc: loc.to_string(),
    };
    let (_, flags) = s.next("array flags")?;
    if flags.len() < 8 {
        return err(loc, "array flags shorter than 8 bytes");
    }
    let f0 = u32_at(flags, 0, big);
    let class = (f0 & 0xff) as u8;
    let complex = f0 & 0x0800 != 0;
    if class == mx::OPAQUE {
        return Ok((
            opaque_name(body, big).unwrap_or_default(),
            MatValue::Unsupported {
                class: "opaque MATLAB object (e.g. table); save it as a struct of columns or export CSV".into(),
            },
        ));
    }
    let (dty, dd) = s.next("dimensions")?;
    let dimsf = to_f64(dty, dd, big, loc)?;
    let dims: Vec<usize> = dimsf.iter().map(|&x| x.max(0.0) as usize).collect();
    let count = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    let Some(count) = count else {
        return err(loc, "array dimensions overflow");
    };
    let (_, nm) = s.next("array name")?;
    let name = String::from_utf8_lossy(nm).to_string();
    let loc = if name.is_empty() {
        loc.to_string()
    } else {
        format!("variable '{name}'")
    };
    s.loc = loc.clone();
    let v = match class {
        6..=15 => {
            if !Budget::take(&budget.values, count) {
                return err(
                    &loc,
                    format!(
                        "more than {} million numeric values in the file; refused (a recording \
                         that large should be split)",
                        MAX_VALUES / 1_000_000
                    ),
                );
            }
            let (ty, d) = s.next("real part")?;
            let data = to_f64(ty, d, big, &loc)?;
            if data.len() != count {
                return err(
                    &loc,
                    format!(
                        "{} values stored for dimensions {} ({count} expected)",
                        data.len(),
                        dims_str(&dims)
                    ),
                );
            }
            if complex {
                let _ = s.next("imaginary part")?;
            }
            MatValue::Numeric { dims, data }
        }
        mx::CHAR => {
            let (ty, d) = s.next("characters")?;
            let chars = to_text(ty, d, big, &loc)?;
            if chars.len() != count {
                return err(
                    &loc,
                    format!(
                        "{} characters stored for dimensions {}",
                        chars.len(),
                        dims_str(&dims)
                    ),
                );
            }
            let rows = dims.first().copied().unwrap_or(0).max(1);
            let cols = chars.len().checked_div(rows).unwrap_or(0);
            // Column-major: character (r, c) is at c*rows + r.
            let mut lines = Vec::with_capacity(rows);
            for r in 0..rows {
                let line: String = (0..cols).filter_map(|c| chars.get(c * rows + r)).collect();
                lines.push(line.trim_end_matches(['\0', ' ']).to_string());
            }
            MatValue::Char {
                dims,
                text: lines.join("\n"),
            }
        }
        mx::STRUCT | mx::OBJECT | mx::CELL if count > body.len().max(1 << 16) => {
            return err(
                &loc,
                format!(
                    "implausible dimensions {} for a {}-byte array",
                    dims_str(&dims),
                    body.len()
                ),
            );
        }
        mx::STRUCT | mx::OBJECT => {
            if class == mx::OBJECT {
                let _ = s.next("class name")?;
            }
            let (lt, ld) = s.next("field name length")?;
            let len = to_f64(lt, ld, big, &loc)?.first().copied().unwrap_or(0.0) as usize;
            let (_, fd) = s.next("field names")?;
            let fields: Vec<String> = if len == 0 {
                vec![]
            } else {
                fd.chunks(len)
                    .map(|c| {
                        let end = c.iter().position(|&b| b == 0).unwrap_or(c.len());
                        String::from_utf8_lossy(&c[..end]).to_string()
                    })
                    .filter(|f| !f.is_empty())
                    .collect()
            };
            let mut elements = Vec::with_capacity(count.min(1 << 16));
            for e in 0..count {
                let mut vals = Vec::with_capacity(fields.len());
                for f in &fields {
                    let (ty, d) = s.next(&format!("field '{f}'"))?;
                    if ty != mi::MATRIX {
                        return err(
                            &loc,
                            format!("field '{f}' of element {e} is type {ty}, expected miMATRIX"),
                        );
                    }
                    vals.push(matrix(d, big, &format!("{loc}.{f}"), depth + 1, budget)?.1);
                }
                elements.push(vals);
            }
            MatValue::Struct {
                dims,
                fields,
                elements,
            }
        }
        mx::CELL => {
            let mut items = Vec::with_capacity(count.min(1 << 16));
            for i in 0..count {
                let (ty, d) = s.next(&format!("cell {i}"))?;
                if ty != mi::MATRIX {
                    return err(&loc, format!("cell {i} is type {ty}, expected miMATRIX"));
                }
                items.push(matrix(d, big, &format!("{loc}{{{i}}}"), depth + 1, budget)?.1);
            }
            MatValue::Cell { dims, items }
        }
        mx::SPARSE => MatValue::Unsupported {
            class: "sparse".into(),
        },
        c => MatValue::Unsupported {
            class: format!("class {c}"),
        },
    };
    Ok((name, v))
}

/// Best-effort name of an opaque (MCOS) variable: flags, then the name element.
fn opaque_name(body: &[u8], big: bool) -> Option<String> {
    let mut s = Sub {
        b: body,
        p: 0,
        big,
        loc: String::new(),
    };
    s.next("flags").ok()?;
    let (_, n) = s.next("name").ok()?;
    Some(String::from_utf8_lossy(n).to_string())
}

// ---------------------------------------------------------------- writer

fn put_tag(out: &mut Vec<u8>, ty: u32, n: usize) {
    out.extend_from_slice(&ty.to_le_bytes());
    out.extend_from_slice(&(n as u32).to_le_bytes());
}

fn put_el(out: &mut Vec<u8>, ty: u32, data: &[u8]) {
    put_tag(out, ty, data.len());
    out.extend_from_slice(data);
    out.resize(out.len() + pad8(data.len()), 0);
}

/// Encode one miMATRIX element (tag included).
fn encode_matrix(name: &str, v: &MatValue) -> Vec<u8> {
    let mut b = Vec::new();
    let (class, dims): (u8, Vec<usize>) = match v {
        MatValue::Numeric { dims, .. } => (6, dims.clone()),
        MatValue::Char { text, .. } => (mx::CHAR, vec![1, text.encode_utf16().count()]),
        MatValue::Struct { dims, .. } => (mx::STRUCT, dims.clone()),
        MatValue::Cell { dims, .. } => (mx::CELL, dims.clone()),
        MatValue::Unsupported { .. } => (6, vec![0, 0]),
    };
    let mut flags = [0u8; 8];
    flags[0] = class;
    put_el(&mut b, mi::UINT32, &flags);
    let d: Vec<u8> = dims
        .iter()
        .flat_map(|&x| (x as i32).to_le_bytes())
        .collect();
    put_el(&mut b, mi::INT32, &d);
    put_el(&mut b, mi::INT8, name.as_bytes());
    match v {
        MatValue::Numeric { data, .. } => {
            let d: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
            put_el(&mut b, mi::DOUBLE, &d);
        }
        MatValue::Char { text, .. } => {
            let d: Vec<u8> = text.encode_utf16().flat_map(|u| u.to_le_bytes()).collect();
            put_el(&mut b, mi::UINT16, &d);
        }
        MatValue::Struct {
            fields, elements, ..
        } => {
            let len = fields.iter().map(|f| f.len() + 1).max().unwrap_or(1).max(1);
            put_el(&mut b, mi::INT32, &(len as i32).to_le_bytes());
            let mut names = vec![0u8; len * fields.len()];
            for (i, f) in fields.iter().enumerate() {
                names[i * len..i * len + f.len()].copy_from_slice(f.as_bytes());
            }
            put_el(&mut b, mi::INT8, &names);
            for e in elements {
                for fv in e {
                    b.extend_from_slice(&encode_matrix("", fv));
                }
            }
        }
        MatValue::Cell { items, .. } => {
            for it in items {
                b.extend_from_slice(&encode_matrix("", it));
            }
        }
        MatValue::Unsupported { .. } => put_el(&mut b, mi::DOUBLE, &[]),
    }
    let mut out = Vec::with_capacity(b.len() + 8);
    put_tag(&mut out, mi::MATRIX, b.len());
    out.extend_from_slice(&b);
    out
}

/// Write variables as a level-5 MAT file (little-endian); each variable is
/// zlib-compressed (`miCOMPRESSED`, as MATLAB's default `-v7`) when `compress`.
pub fn write(vars: &[(String, MatValue)], compress: bool, header_text: &str) -> Vec<u8> {
    let mut out = Vec::new();
    let mut h = format!("MATLAB 5.0 MAT-file, {header_text}").into_bytes();
    h.resize(116, b' ');
    out.extend_from_slice(&h);
    out.extend_from_slice(&[0u8; 8]);
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    for (name, v) in vars {
        let m = encode_matrix(name, v);
        if compress {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            // Writing to a Vec cannot fail.
            let _ = z.write_all(&m);
            let c = z.finish().unwrap_or_default();
            put_tag(&mut out, mi::COMPRESSED, c.len());
            out.extend_from_slice(&c);
        } else {
            out.extend_from_slice(&m);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_vars() -> Vec<(String, MatValue)> {
        vec![
            (
                "FY".into(),
                MatValue::column(vec![1.5, -2.25, 1e300, f64::NAN]),
            ),
            ("source".into(), MatValue::text("Calspan TIRF — test")),
            (
                "channel".into(),
                MatValue::Struct {
                    dims: vec![1, 1],
                    fields: vec!["name".into(), "units".into()],
                    elements: vec![vec![
                        MatValue::Cell {
                            dims: vec![1, 2],
                            items: vec![MatValue::text("FY"), MatValue::text("SA")],
                        },
                        MatValue::Cell {
                            dims: vec![1, 2],
                            items: vec![MatValue::text("N"), MatValue::text("deg")],
                        },
                    ]],
                },
            ),
        ]
    }

    #[test]
    fn round_trip_compressed_and_plain() {
        for compress in [false, true] {
            let bytes = write(&sample_vars(), compress, "test");
            let back = read(&bytes).unwrap();
            assert_eq!(back.len(), 3);
            let fy = back[0].1.as_numeric().unwrap();
            assert_eq!(&fy[..3], &[1.5, -2.25, 1e300]);
            assert!(fy[3].is_nan());
            assert_eq!(back[1].1.as_text().unwrap(), "Calspan TIRF — test");
            let ch = &back[2].1;
            assert_eq!(ch.field("name").unwrap().as_text().unwrap(), "FY, SA");
            assert_eq!(ch.field("units").unwrap().as_text().unwrap(), "N, deg");
        }
    }

    /// A hand-assembled file with small data elements, int16 storage of a
    /// double array and a multi-row char array (layouts MATLAB itself writes).
    #[test]
    fn reads_small_elements_and_narrow_storage() {
        let mut body = Vec::new();
        put_el(&mut body, mi::UINT32, &[6, 0, 0, 0, 0, 0, 0, 0]);
        put_el(&mut body, mi::INT32, &[3, 0, 0, 0, 1, 0, 0, 0]);
        // name "x" as a small element: size 1, type miINT8.
        body.extend_from_slice(&((1u32 << 16) | mi::INT8).to_le_bytes());
        body.extend_from_slice(&[b'x', 0, 0, 0]);
        let d: Vec<u8> = [-3i16, 7, 300]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        put_el(&mut body, mi::INT16, &d);
        let mut f = write(&[], false, "hand");
        put_tag(&mut f, mi::MATRIX, body.len());
        f.extend_from_slice(&body);
        let v = read(&f).unwrap();
        assert_eq!(v[0].0, "x");
        assert_eq!(v[0].1.as_numeric().unwrap(), &[-3.0, 7.0, 300.0]);
    }

    #[test]
    fn truncation_is_reported_not_panicked() {
        for compress in [false, true] {
            let bytes = write(&sample_vars(), compress, "t");
            for cut in [0, 50, 127, 130, 140, bytes.len() / 2, bytes.len() - 3] {
                let r = read(&bytes[..cut]);
                assert!(
                    r.is_err(),
                    "cut at {cut} of {} (compress {compress}) accepted",
                    bytes.len()
                );
            }
        }
        // Every truncation point and single-byte corruption: an error or a
        // value, never a panic or a huge allocation.
        for compress in [false, true] {
            let bytes = write(&sample_vars(), compress, "t");
            for cut in 0..bytes.len() {
                let _ = read(&bytes[..cut]);
            }
            for i in 128..bytes.len() {
                for x in [0x00u8, 0xff, 0x7f] {
                    let mut b = bytes.clone();
                    b[i] ^= x.max(1);
                    let _ = read(&b);
                }
            }
        }
        // Garbage after a valid header must not panic either.
        let mut g = write(&[], false, "g");
        g.extend((0..400u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8));
        let _ = read(&g);
    }
}
