//! tir — the TNO/ADAMS tyre property file (`.tir`): reading, unit conversion,
//! model-version recognition, defaults, and writing back.
//!
//! `[UNITS]` is applied on read, so everything leaving this module is SI.
//! Must never: panic on any input bytes, silently mis-read a non-Magic-Formula
//! file, or lose a section/key it does not understand (they are kept for the writer).
//!
//! # Reading
//! The file is first lexed into a document model ([`parse`]: sections,
//! entries, tables, verbatim blocks), then given meaning ([`read`]):
//! * the version comes from FITTYP / PROPERTY_FILE_FORMAT / TIRE_VERSION
//!   ([`version`]); files of other tyre models (Harty, Fiala, …) are refused
//!   with an error saying which model and why;
//! * `[UNITS]` is honoured ([`units`]); an unknown unit is an error;
//! * keys of the table [`KEYS`] are recognised in any section, so files that
//!   put dimension keys under `[MODEL]` still read; `LFZ0` is read as `LFZO`;
//!   the legacy spellings `QFZ2`, `QV1`, `QV2`, `QFCX1`… are NOT read as
//!   `Q_FZ2` etc. (MFeval 4.0 ignores them, and tyrekit matches MFeval): they
//!   are kept as unknown keys, with a warning;
//! * a missing key takes the table default and is listed in
//!   [`TyreParams::defaulted`]; an empty or non-numeric value of a numeric key
//!   (`WIDTH =`, `MASS = kg`) is treated as missing, with a warning
//!   (deliberate difference: MFeval reads empty values as NaN);
//! * a key or section given twice: the later value wins, with a warning
//!   naming both lines.
//!
//! Every error is an [`Error::Tir`] naming the file, the line, the key and
//! what was expected. Warnings are strings starting `line N:`.
//!
//! # Keeping what is not a parameter, and custom sections
//! Everything that is not a key of the table (strings such as
//! PROPERTY_FILE_FORMAT, unknown keys, vendor sections, `[SHAPE]` and other
//! tables, `(COMMENTS)` blocks, header `!` comments) stays in
//! [`TyreParams::doc`] and is written back by [`TyreParams::to_tir_string`].
//! The same document is the API for additions: [`TyreParams::extra_section`]
//! returns a [`Section`] (created if absent) whose entries the writer writes,
//! e.g. a `[LUGRE]` or `[THERMAL]` section of numeric keys:
//! ```
//! # use tyrekit::tir::TyreParams;
//! let mut t = TyreParams::builtin();
//! t.extra_section("LUGRE").set("SIGMA0", 500.0);
//! t.set_string("MODEL", "COMMENT_BY", "fit 2026-11-22");
//! let back = TyreParams::from_tir_str(&t.to_tir_string(), "rt").unwrap();
//! assert_eq!(back.extra_number("LUGRE", "SIGMA0"), Some(500.0));
//! assert_eq!(back.p, t.p);
//! ```
//! Values of such custom keys are stored and written as given (SI by
//! convention); `[UNITS]` converts only keys of the table and known tables.

pub mod keys;
pub mod parse;
pub mod provenance;
pub mod read;
pub mod units;
pub mod version;
pub mod write;

pub use keys::{Dim, KeyDef, MfParams, KEYS, N_KEYS};
pub use parse::{Entry, Section, Table, TirDoc, Value};

use crate::error::{Error, Result};
use std::path::Path;

/// Which Magic Formula equation set a property file is written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum MfVersion {
    /// MSC ADAMS PAC2002 (no FITTYP, or PROPERTY_FILE_FORMAT = 'PAC2002').
    Pac2002,
    /// MF-Tyre 5.x / MF 5.2 (FITTYP 5, 6 or 52).
    Mf52,
    /// MF 6.1 (FITTYP 61).
    Mf61,
    /// MF 6.2 (FITTYP 62).
    Mf62,
}

/// Which side of the vehicle the file's coefficients were measured for (TYRESIDE).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum TyreSide {
    /// `LEFT` (also the default when the file gives no TYRESIDE): the
    /// coefficients describe a tyre on the left of the vehicle.
    #[default]
    Left,
    /// `RIGHT`: the coefficients describe a right-hand tyre; the FMU
    /// mirrors it about the wheel's x-z plane when asked for the left.
    Right,
    /// `SYMMETRIC`: the coefficients hold for either side, never mirrored.
    Symmetric,
    /// `UNKNOWN`, or a value that was not recognised; counts as LEFT
    /// (MF-Tyre's default).
    Unknown,
}

/// A loaded tyre property file: numeric parameters in SI plus everything else
/// the file held (strings, tables, unknown keys and sections) for the writer.
#[derive(Clone, Debug)]
pub struct TyreParams {
    /// Equation set the file is written for.
    pub version: MfVersion,
    /// Numeric parameters, SI, defaults filled in.
    pub p: MfParams,
    /// TYRESIDE of the file (LEFT when the file does not say).
    pub side: TyreSide,
    /// Names of the keys of [`KEYS`] that the file did not give (defaults used).
    pub defaulted: Vec<&'static str>,
    /// Keys of [`KEYS`] the file gave with an empty or non-numeric value
    /// (`WIDTH =`, `MASS = kg`), with their line: read as not given (MFeval
    /// reads such values as NaN). Also in `defaulted` unless given validly
    /// on another line.
    pub invalid: Vec<(&'static str, usize)>,
    /// Warnings met while reading (duplicate keys, odd values …), with line numbers.
    pub warnings: Vec<String>,
    /// Where it came from (file path or a label).
    pub source: String,
    /// Everything of the file that is not a key of [`KEYS`] (see the module
    /// doc), written back by the writer. Keys of the table never live here.
    pub doc: TirDoc,
}

/// Largest `.tir` accepted (bytes): 80 times the largest published file
/// (MF 6.2 template, 26 kB). Together with linear-time reading and capped
/// warnings this bounds the reader's memory (measured in
/// `tests/reader_bounds.rs`).
pub const MAX_TIR_BYTES: usize = 2 << 20;

fn too_big(n: usize, name: &str) -> Result<()> {
    if n > MAX_TIR_BYTES {
        return Err(Error::Tir {
            file: name.to_string(),
            line: 0,
            key: String::new(),
            message: format!(
                "{n} bytes, more than any tyre property file (limit {MAX_TIR_BYTES} bytes); \
                 is this a .tir?"
            ),
        });
    }
    Ok(())
}

/// The bytes of a `.tir` file: only a regular file (not a FIFO, device or
/// directory) of at most [`MAX_TIR_BYTES`], opened non-blocking so that a
/// FIFO cannot stall the caller (the FMU's `tyre_file`), read no further
/// than the limit (so `/dev/zero`-like files cannot fill memory).
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let mut o = std::fs::OpenOptions::new();
    o.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NONBLOCK);
    }
    let f = o.open(path).map_err(|e| Error::io(path, e))?;
    let meta = f.metadata().map_err(|e| Error::io(path, e))?;
    let name = path.display().to_string();
    if !meta.is_file() {
        return Err(Error::Tir {
            file: name,
            line: 0,
            key: String::new(),
            message: "not a regular file (a directory, FIFO or device); give a .tir file".into(),
        });
    }
    too_big(meta.len().try_into().unwrap_or(usize::MAX), &name)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    f.take(MAX_TIR_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    too_big(bytes.len(), &name)?;
    Ok(bytes)
}

/// The built-in tyre's property file (MF 6.1, SI; see its header for the source).
pub const BUILTIN_TIR: &str = include_str!("builtin.tir");

impl TyreParams {
    /// Read a `.tir` file from disk ([`read_file`]: a regular file of at most
    /// [`MAX_TIR_BYTES`], opened without blocking).
    pub fn from_file(path: &Path) -> Result<Self> {
        let bytes = read_file(path)?;
        Self::from_bytes(&bytes, &path.display().to_string())
    }

    /// Parse `.tir` bytes (UTF-8, or Latin-1 when not valid UTF-8); `name` labels errors.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<Self> {
        too_big(bytes.len(), name)?;
        Self::from_tir_str(&parse::decode(bytes), name)
    }

    /// Parse `.tir` text; `name` labels errors.
    pub fn from_tir_str(text: &str, name: &str) -> Result<Self> {
        too_big(text.len(), name)?;
        let r = read::read(text, name)?;
        Ok(TyreParams {
            version: r.version,
            p: r.p,
            side: r.side,
            defaulted: r.defaulted,
            invalid: r.invalid,
            warnings: r.warnings,
            source: name.to_string(),
            doc: r.doc,
        })
    }

    /// The project's built-in default tyre: the 205/60R15 reference
    /// passenger-car tyre of Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed.,
    /// Appendix 3, as MF 6.1 (`src/tir/builtin.tir`).
    pub fn builtin() -> Self {
        match Self::from_tir_str(BUILTIN_TIR, "<built-in>") {
            Ok(t) => t,
            // Unreachable (a unit test reads the file); never panic anyway.
            Err(e) => TyreParams {
                version: MfVersion::Mf61,
                p: MfParams {
                    fittyp: 61.0,
                    ..MfParams::default()
                },
                side: TyreSide::Left,
                defaulted: KEYS.iter().map(|k| k.name).collect(),
                invalid: Vec::new(),
                warnings: vec![format!(
                    "built-in file unreadable ({e}); table defaults used"
                )],
                source: "<built-in>".into(),
                doc: TirDoc::default(),
            },
        }
    }

    /// Render as `.tir` text (SI units); reads back to bit-identical `p`,
    /// the same `version`, `side` and `defaulted`, and the kept document.
    ///
    /// Keys listed in `defaulted` whose value is still the default are
    /// written as `$` comments (so they stay "not given"); a non-finite value
    /// in `p` (NaN/inf, which no file can hold) is written as a comment too
    /// and reads back as the default. See [`mod@write`] for the layout.
    pub fn to_tir_string(&self) -> String {
        write::to_tir_string(self)
    }

    /// Write as a `.tir` file.
    pub fn write(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.to_tir_string()).map_err(|e| Error::io(path, e))
    }

    /// Value of a key of the table (case-insensitive, aliases accepted), SI.
    pub fn get(&self, key: &str) -> Option<f64> {
        keys::lookup_key(key).map(|i| self.p.as_slice()[i])
    }

    /// Set a key of the table (SI value) and remove it from `defaulted`.
    /// Errors for a key that is not in the table (use
    /// [`extra_section`](Self::extra_section) for custom keys).
    pub fn set(&mut self, key: &str, value: f64) -> Result<()> {
        let i = keys::lookup_key(key).ok_or_else(|| Error::Tir {
            file: self.source.clone(),
            line: 0,
            key: key.to_string(),
            message: "not a key of the Magic Formula key table (custom keys go in extra_section)"
                .into(),
        })?;
        self.p.as_mut_slice()[i] = value;
        let name = KEYS[i].name;
        self.defaulted.retain(|&d| d != name);
        Ok(())
    }

    /// The kept section `name` (case-insensitive), if any.
    pub fn section(&self, name: &str) -> Option<&Section> {
        self.doc.section(name)
    }

    /// The kept or custom section `name` (case-insensitive), created at the
    /// end if absent. Its entries, table and verbatim lines are written back.
    /// Keys of [`KEYS`] put here are ignored by the writer (they live in `p`:
    /// use [`set`](Self::set)).
    pub fn extra_section(&mut self, name: &str) -> &mut Section {
        self.doc.section_mut(name)
    }

    /// A kept value by section and key (case-insensitive).
    pub fn extra(&self, section: &str, key: &str) -> Option<&Value> {
        self.doc.section(section)?.get(key)
    }

    /// A kept number by section and key.
    pub fn extra_number(&self, section: &str, key: &str) -> Option<f64> {
        self.extra(section, key)?.as_number()
    }

    /// A kept string value by key, in whichever section it is
    /// (e.g. `PROPERTY_FILE_FORMAT`, `FUNCTION_NAME`, `CONSTRUCTION`).
    pub fn string(&self, key: &str) -> Option<&str> {
        self.doc.find(key).and_then(|(_, e)| e.value.as_str())
    }

    /// Set a quoted string key in a section (created if absent).
    pub fn set_string(&mut self, section: &str, key: &str, text: &str) {
        self.extra_section(section).set(key, Value::text(text));
    }

    /// The numeric table of a section (`SHAPE`, `DEFLECTION_LOAD_CURVE` …), SI.
    pub fn table(&self, section: &str) -> Option<&Table> {
        self.doc.section(section)?.table.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_reads_clean() {
        let t = TyreParams::from_tir_str(BUILTIN_TIR, "builtin").unwrap();
        assert_eq!(t.version, MfVersion::Mf61);
        assert!(t.warnings.is_empty(), "{:?}", t.warnings);
        assert_eq!(t.p.fittyp, 61.0);
    }
}
