//! parse — the `.tir` document model and the line lexer that builds it.
//!
//! A [`TirDoc`] is what a property file *says*, before any meaning is given to
//! it: sections in file order, their `KEY = value` entries (with line numbers),
//! numeric tables (`{pen fz}` …), verbatim blocks (`(COMMENTS)`), and the
//! comment lines of the file header. The reader ([`super::read`]) turns it
//! into parameters; whatever it does not consume stays in the document that
//! [`super::TyreParams`] keeps for the writer.
//!
//! The lexer accepts the format as found in the wild: CRLF or LF, tabs,
//! trailing blanks, `$` and `!` comments (a `$` inside a `!` comment or inside
//! a quoted string does not start a comment), single-quoted strings, unquoted
//! strings with blanks, empty values, Fortran `D` exponents, numbers without
//! blank after `=`, and lines it does not understand (kept, with a warning).
//!
//! Must never: panic on any input, or drop a line silently (every line is
//! either stored, a comment, or named in a warning).

/// A value on the right of `=`.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// An unquoted number (`0.3135`, `5.6519e+005`, `1.0D-3`).
    Number(f64),
    /// A single-quoted string, without its quotes (`'meter'` → `meter`).
    Text(String),
    /// An unquoted value that is not a number (`R25B 16 x 7.5 on 10x7 Rim`, `kg`).
    Word(String),
    /// Nothing after `=`.
    Empty,
}

impl Value {
    /// The number, if this is one.
    pub fn as_number(&self) -> Option<f64> {
        match self {
            Value::Number(x) => Some(*x),
            _ => None,
        }
    }

    /// The text of a quoted or unquoted string value.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Text(s) | Value::Word(s) => Some(s),
            _ => None,
        }
    }

    /// A quoted string value.
    pub fn text(s: impl Into<String>) -> Self {
        Value::Text(s.into())
    }
}

impl From<f64> for Value {
    fn from(x: f64) -> Self {
        Value::Number(x)
    }
}

impl From<&str> for Value {
    fn from(s: &str) -> Self {
        Value::Text(s.to_string())
    }
}

/// One `KEY = value` line.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// Key as written (case kept).
    pub key: String,
    /// Parsed value.
    pub value: Value,
    /// Trailing `$` comment without the `$` (may be empty).
    pub comment: String,
    /// 1-based line in the source (0 for entries added through the API).
    pub line: usize,
}

impl Entry {
    /// An entry made in code (no source line, no comment).
    pub fn new(key: impl Into<String>, value: impl Into<Value>) -> Self {
        Entry {
            key: key.into(),
            value: value.into(),
            comment: String::new(),
            line: 0,
        }
    }
}

/// A numeric table (`[SHAPE]`, `[DEFLECTION_LOAD_CURVE]`, `[BOTTOMING_CURVE]` …).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Table {
    /// Column names from the `{...}` header; empty when the file gave none.
    pub columns: Vec<String>,
    /// Rows of numbers (SI after reading, where the column's dimension is known).
    pub rows: Vec<Vec<f64>>,
    /// 1-based line of the header or first row (0 if made in code).
    pub line: usize,
}

/// One `[SECTION]` with everything it held.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Section {
    /// Name as written, without brackets.
    pub name: String,
    /// 1-based line of the header (0 for the implicit section before the first header, or made in code).
    pub line: usize,
    /// `KEY = value` entries in file order.
    pub entries: Vec<Entry>,
    /// Numeric table, if the section has one.
    pub table: Option<Table>,
    /// Verbatim lines (`(COMMENTS)` blocks, `{comment_string}`, quoted lines,
    /// and lines the lexer did not understand), written back as they were.
    pub raw: Vec<String>,
}

impl Section {
    /// An empty section named `name`.
    pub fn new(name: impl Into<String>) -> Self {
        Section {
            name: name.into(),
            ..Section::default()
        }
    }

    /// The value of `key` (case-insensitive).
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.entries
            .iter()
            .rev()
            .find(|e| e.key.eq_ignore_ascii_case(key))
            .map(|e| &e.value)
    }

    /// The number `key` holds, if it holds one.
    pub fn number(&self, key: &str) -> Option<f64> {
        self.get(key).and_then(Value::as_number)
    }

    /// Set `key` (replacing an existing entry of that name, case-insensitive),
    /// or append it.
    pub fn set(&mut self, key: &str, value: impl Into<Value>) {
        let value = value.into();
        match self
            .entries
            .iter_mut()
            .find(|e| e.key.eq_ignore_ascii_case(key))
        {
            Some(e) => e.value = value,
            None => self.entries.push(Entry::new(key, value)),
        }
    }

    /// Remove `key`; returns the value it had.
    pub fn remove(&mut self, key: &str) -> Option<Value> {
        let i = self
            .entries
            .iter()
            .position(|e| e.key.eq_ignore_ascii_case(key))?;
        Some(self.entries.remove(i).value)
    }

    /// Whether the section holds nothing to write.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty() && self.table.is_none() && self.raw.is_empty()
    }
}

/// A whole property file as written (see the module doc).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct TirDoc {
    /// `!` comment lines of the file header (before the first section and
    /// inside `[MDI_HEADER]`), without the leading `!`.
    pub header_comments: Vec<String>,
    /// Sections in order of first appearance; a section that appears twice
    /// is merged into its first occurrence (with a warning).
    pub sections: Vec<Section>,
    /// Trailing `$` comments of the keys of the key table (whose values live
    /// in `MfParams`), by key name, so the writer can put them back.
    pub key_comments: std::collections::BTreeMap<String, String>,
}

impl TirDoc {
    /// The section named `name` (case-insensitive).
    pub fn section(&self, name: &str) -> Option<&Section> {
        self.sections
            .iter()
            .find(|s| s.name.eq_ignore_ascii_case(name))
    }

    /// The section named `name`, created (appended) if absent.
    pub fn section_mut(&mut self, name: &str) -> &mut Section {
        let i = match self
            .sections
            .iter()
            .position(|s| s.name.eq_ignore_ascii_case(name))
        {
            Some(i) => i,
            None => {
                self.sections.push(Section::new(name));
                self.sections.len() - 1
            }
        };
        &mut self.sections[i]
    }

    /// The entry named `key` (case-insensitive) in any section, with its
    /// section name; when there are several, the one latest in the file
    /// (highest line), as the reader's "later wins" rule.
    pub fn find(&self, key: &str) -> Option<(&str, &Entry)> {
        self.sections
            .iter()
            .flat_map(|s| s.entries.iter().map(move |e| (s.name.as_str(), e)))
            .filter(|(_, e)| e.key.eq_ignore_ascii_case(key))
            .max_by_key(|(_, e)| e.line)
    }
}

/// Parse a number as `.tir` files write them: Rust float syntax plus Fortran
/// `D` exponents; only finite values count as numbers.
pub fn parse_number(s: &str) -> Option<f64> {
    let s = s.trim();
    if s.is_empty() {
        return None;
    }
    // Only plain decimal syntax: refuse "inf", "nan", "infinity" that Rust accepts.
    if !s
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E' | b'd' | b'D'))
    {
        return None;
    }
    let x = if s.contains(['d', 'D']) {
        s.replace(['d', 'D'], "e").parse::<f64>().ok()?
    } else {
        s.parse::<f64>().ok()?
    };
    x.is_finite().then_some(x)
}

/// Index of the first comment character (`$` or `!`) outside single quotes.
fn comment_start(s: &str) -> Option<usize> {
    let mut quoted = false;
    for (i, c) in s.char_indices() {
        match c {
            '\'' => quoted = !quoted,
            '$' | '!' if !quoted => return Some(i),
            _ => {}
        }
    }
    None
}

/// Split `text` into code and comment (comment without its `$`/`!`, trimmed).
fn split_comment(s: &str) -> (&str, &str) {
    match comment_start(s) {
        Some(i) => (&s[..i], s[i + 1..].trim()),
        None => (s, ""),
    }
}

/// Whether a key name is something the writer can put back unchanged.
fn plausible_key(k: &str) -> bool {
    !k.is_empty()
        && k.len() <= 128
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-' | '/' | '(' | ')'))
}

/// Parse the right-hand side of `=` into value and comment.
/// `warn` receives a problem description (the caller adds line/key).
fn parse_value(rhs: &str, warn: &mut dyn FnMut(String)) -> (Value, String) {
    let t = rhs.trim_start();
    if let Some(rest) = t.strip_prefix('\'') {
        return match rest.find('\'') {
            Some(end) => {
                let s = rest[..end].to_string();
                let after = rest[end + 1..].trim();
                let comment = match after.chars().next() {
                    None => String::new(),
                    Some('$') | Some('!') => after[1..].trim().to_string(),
                    Some(_) => {
                        warn(format!(
                            "text after the quoted value ignored: {:?}",
                            truncate(after)
                        ));
                        let (_, c) = split_comment(after);
                        c.to_string()
                    }
                };
                (Value::Text(s), comment)
            }
            None => {
                warn("quoted value has no closing quote; taken to the end of the line".into());
                (Value::Text(rest.trim_end().to_string()), String::new())
            }
        };
    }
    let (code, comment) = split_comment(t);
    let code = code.trim();
    let v = if code.is_empty() {
        Value::Empty
    } else if let Some(x) = parse_number(code) {
        Value::Number(x)
    } else {
        Value::Word(code.to_string())
    };
    (v, comment.to_string())
}

/// Shorten a string for a message.
pub(crate) fn truncate(s: &str) -> String {
    if s.chars().count() <= 60 {
        s.to_string()
    } else {
        let t: String = s.chars().take(57).collect();
        format!("{t}...")
    }
}

/// Decode file bytes: UTF-8 when valid, otherwise Latin-1 (every byte one
/// character), so no byte sequence is refused and `°`, `µ` of old Windows
/// files survive.
pub fn decode(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    match std::str::from_utf8(bytes) {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => std::borrow::Cow::Owned(bytes.iter().map(|&b| b as char).collect()),
    }
}

/// Where verbatim-block state stands while lexing.
#[derive(PartialEq)]
enum Block {
    None,
    /// After a `(NAME)` line: `{...}` and quoted lines belong to it.
    Raw,
}

/// Build the document from text. Problems that do not stop reading are
/// pushed to `warnings` as `line N: …`.
pub fn parse_doc(text: &str, warnings: &mut Vec<String>) -> TirDoc {
    let mut doc = TirDoc::default();
    // Index into doc.sections of the current section; None before the first header.
    let mut cur: Option<usize> = None;
    let mut block = Block::None;
    // A table started by `{...}` or by a first numeric row in the current section.
    let mut table_line_of_section: Option<usize> = None;
    // Section index by upper-case name: a file of many distinct sections
    // reads in linear time (a linear search per header was quadratic).
    let mut by_name: std::collections::HashMap<String, usize> = Default::default();

    for (i, raw_line) in text.split('\n').enumerate() {
        let ln = i + 1;
        let line = raw_line.trim_end_matches(['\r', ' ', '\t', '\0']);
        let line = line.trim_start_matches([' ', '\t', '\r', '\u{feff}', '\0']);
        if line.is_empty() {
            continue;
        }
        let first = line.chars().next().unwrap_or(' ');
        match first {
            '$' => continue,
            '!' => {
                let in_header = match cur {
                    None => true,
                    Some(ci) => doc.sections[ci].name.eq_ignore_ascii_case("MDI_HEADER"),
                };
                if in_header {
                    doc.header_comments.push(line[1..].to_string());
                }
                continue;
            }
            '[' => {
                block = Block::None;
                table_line_of_section = None;
                let (code, _) = split_comment(line);
                let code = code.trim();
                let name = match code.find(']') {
                    Some(end) => {
                        let rest = code[end + 1..].trim();
                        if !rest.is_empty() {
                            warnings.push(format!(
                                "line {ln}: text after section header ignored: {:?}",
                                truncate(rest)
                            ));
                        }
                        code[1..end].trim()
                    }
                    None => {
                        warnings.push(format!(
                            "line {ln}: section header without ']': {:?}",
                            truncate(code)
                        ));
                        code[1..].trim()
                    }
                };
                let name = name.to_string();
                match by_name.get(&name.to_ascii_uppercase()).copied() {
                    Some(k) => {
                        warnings.push(format!(
                            "line {ln}: section [{name}] appears again (first at line {}); \
                             merged, later values win",
                            doc.sections[k].line
                        ));
                        cur = Some(k);
                    }
                    None => {
                        by_name.insert(name.to_ascii_uppercase(), doc.sections.len());
                        doc.sections.push(Section {
                            name,
                            line: ln,
                            ..Section::default()
                        });
                        cur = Some(doc.sections.len() - 1);
                    }
                }
                continue;
            }
            _ => {}
        }
        let ci = match cur {
            Some(ci) => ci,
            None => {
                // Content before any section header: keep it in an unnamed section.
                doc.sections.push(Section::default());
                let ci = doc.sections.len() - 1;
                cur = Some(ci);
                ci
            }
        };
        if first == '(' {
            block = Block::Raw;
            doc.sections[ci].raw.push(line.to_string());
            continue;
        }
        if block == Block::Raw && (first == '{' || first == '\'') {
            doc.sections[ci].raw.push(line.to_string());
            continue;
        }
        block = Block::None;
        if first == '{' {
            let (code, _) = split_comment(line);
            let inner = code.trim().trim_start_matches('{');
            let inner = inner.split('}').next().unwrap_or("");
            let columns: Vec<String> = inner.split_whitespace().map(str::to_string).collect();
            let sec = &mut doc.sections[ci];
            if let Some(old) = &sec.table {
                if table_line_of_section.is_none() {
                    warnings.push(format!(
                        "line {ln}: table of [{}] given again (first at line {}); the later one is used",
                        sec.name, old.line
                    ));
                }
            }
            sec.table = Some(Table {
                columns,
                rows: Vec::new(),
                line: ln,
            });
            table_line_of_section = Some(ln);
            continue;
        }
        let (code, comment) = split_comment(line);
        if let Some(eq) = code.find('=') {
            let key = code[..eq].trim();
            if !plausible_key(key) {
                warnings.push(format!(
                    "line {ln}: not a key name {:?}; line kept as is",
                    truncate(key)
                ));
                doc.sections[ci].raw.push(line.to_string());
                continue;
            }
            // Re-split the right-hand side with quote awareness (a `$` inside
            // quotes is not a comment): use the part of `line` after '='.
            let rhs = &line[eq + 1..];
            let mut msgs = Vec::new();
            let (value, comment) = parse_value(rhs, &mut |m| msgs.push(m));
            for m in msgs {
                warnings.push(format!("line {ln}: {key}: {m}"));
            }
            doc.sections[ci].entries.push(Entry {
                key: key.to_string(),
                value,
                comment,
                line: ln,
            });
            continue;
        }
        // A table row?
        let nums: Option<Vec<f64>> = code.split_whitespace().map(parse_number).collect();
        match nums {
            Some(row) if !row.is_empty() => {
                let sec = &mut doc.sections[ci];
                if table_line_of_section.is_none() {
                    if let Some(old) = &sec.table {
                        warnings.push(format!(
                            "line {ln}: table of [{}] given again (first at line {}); the later one is used",
                            sec.name, old.line
                        ));
                    }
                    sec.table = Some(Table {
                        columns: Vec::new(),
                        rows: Vec::new(),
                        line: ln,
                    });
                    table_line_of_section = Some(ln);
                }
                if let Some(t) = sec.table.as_mut() {
                    if let Some(first_row) = t.rows.first() {
                        if first_row.len() != row.len() {
                            warnings.push(format!(
                                "line {ln}: table row of [{}] has {} values, the first row {}",
                                sec.name,
                                row.len(),
                                first_row.len()
                            ));
                        }
                    }
                    t.rows.push(row);
                }
            }
            _ => {
                let _ = comment;
                warnings.push(format!(
                    "line {ln}: line not understood (neither [SECTION], KEY = value, table row nor comment); kept as is: {:?}",
                    truncate(line)
                ));
                doc.sections[ci].raw.push(line.to_string());
            }
        }
    }
    doc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(s: &str) -> (TirDoc, Vec<String>) {
        let mut w = Vec::new();
        let d = parse_doc(s, &mut w);
        (d, w)
    }

    #[test]
    fn numbers() {
        assert_eq!(parse_number("5.6519e+005"), Some(565190.0));
        assert_eq!(parse_number("1.0D-3"), Some(1e-3));
        assert_eq!(parse_number("=52"), None);
        assert_eq!(parse_number("nan"), None);
        assert_eq!(parse_number("inf"), None);
        assert_eq!(parse_number("1e999"), None);
        assert_eq!(parse_number("-.5"), Some(-0.5));
    }

    #[test]
    fn values_and_comments() {
        let (d, w) = doc(
            "[A]\r\nK1 = 'a $ b' $ c\r\nK2 =\t3.5\t$x\nK3 = R25B 16 x 7.5 on 10x7 Rim\nK4 =\nK5='unterminated\n",
        );
        let s = d.section("A").unwrap();
        assert_eq!(s.get("K1"), Some(&Value::Text("a $ b".into())));
        assert_eq!(s.entries[0].comment, "c");
        assert_eq!(s.number("K2"), Some(3.5));
        assert_eq!(
            s.get("K3"),
            Some(&Value::Word("R25B 16 x 7.5 on 10x7 Rim".into()))
        );
        assert_eq!(s.get("K4"), Some(&Value::Empty));
        assert_eq!(s.get("k5"), Some(&Value::Text("unterminated".into())));
        assert_eq!(w.len(), 1, "{w:?}");
    }

    #[test]
    fn bang_comment_with_dollar_and_tables() {
        let (d, w) = doc(
            "!$Revision: 1.15 $\n[MDI_HEADER]\n! more\n(COMMENTS)\n{comment_string}\n'x = 1'\n[SHAPE]\n{radial width}\n 1.0 0.0\n 0.9\t1.0\n[X]\n1 2\n",
        );
        assert_eq!(d.header_comments, vec!["$Revision: 1.15 $", " more"]);
        assert_eq!(d.section("MDI_HEADER").unwrap().raw.len(), 3);
        let t = d.section("SHAPE").unwrap().table.as_ref().unwrap();
        assert_eq!(t.columns, vec!["radial", "width"]);
        assert_eq!(t.rows, vec![vec![1.0, 0.0], vec![0.9, 1.0]]);
        assert!(d
            .section("X")
            .unwrap()
            .table
            .as_ref()
            .unwrap()
            .columns
            .is_empty());
        assert!(w.is_empty(), "{w:?}");
    }
}
