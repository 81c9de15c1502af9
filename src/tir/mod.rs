//! tir — the TNO/ADAMS tyre property file (`.tir`): reading, unit conversion,
//! model-version recognition, defaults, and writing back.
//!
//! `[UNITS]` is applied on read, so everything leaving this module is SI.
//! Must never: panic on any input bytes, silently mis-read a non-Magic-Formula
//! file, or lose a section/key it does not understand (they are kept for the writer).
//!
//! STUB (to be replaced by the `.tir` reader work of issue #2): the API below is
//! the contract other modules build on.

pub mod keys;

pub use keys::{Dim, KeyDef, MfParams, KEYS, N_KEYS};

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
    #[default]
    Left,
    Right,
    Symmetric,
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
    /// TYRESIDE of the file.
    pub side: TyreSide,
    /// Names of the keys of [`KEYS`] that the file did not give (defaults used).
    pub defaulted: Vec<&'static str>,
    /// Warnings met while reading (duplicate keys, odd values …), with line numbers.
    pub warnings: Vec<String>,
    /// Where it came from (file path or a label).
    pub source: String,
}

impl TyreParams {
    /// Read a `.tir` file from disk.
    pub fn from_file(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8_lossy(&bytes);
        Self::from_tir_str(&text, &path.display().to_string())
    }

    /// Parse `.tir` text; `name` labels errors.
    pub fn from_tir_str(text: &str, name: &str) -> Result<Self> {
        // Placeholder: KEY = number only, no units, no version detection.
        let mut p = MfParams::default();
        for line in text.lines() {
            let line = line.split('$').next().unwrap_or("");
            if let Some((k, v)) = line.split_once('=') {
                if let Ok(x) = v.trim().parse::<f64>() {
                    p.set(k.trim(), x);
                }
            }
        }
        let version = match p.fittyp as i64 {
            61 => MfVersion::Mf61,
            62 => MfVersion::Mf62,
            5 | 6 | 52 => MfVersion::Mf52,
            _ => MfVersion::Pac2002,
        };
        let _ = name;
        Ok(TyreParams {
            version,
            p,
            side: TyreSide::Left,
            defaulted: Vec::new(),
            warnings: Vec::new(),
            source: name.to_string(),
        })
    }

    /// The project's built-in default tyre (a passenger-car tyre from published values).
    pub fn builtin() -> Self {
        let mut t = Self::from_tir_str("", "<built-in>").expect("empty text parses");
        t.version = MfVersion::Mf61;
        t.p.fittyp = 61.0;
        t
    }

    /// Render as `.tir` text (SI units).
    pub fn to_tir_string(&self) -> String {
        let mut s = String::new();
        let mut section = "";
        for (k, v) in KEYS.iter().zip(self.p.as_slice()) {
            if k.section != section {
                section = k.section;
                s.push_str(&format!("[{}]\n", section));
            }
            s.push_str(&format!("{} = {:e}\n", k.name, v));
        }
        s
    }

    /// Write as a `.tir` file.
    pub fn write(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.to_tir_string()).map_err(|e| Error::io(path, e))
    }
}
