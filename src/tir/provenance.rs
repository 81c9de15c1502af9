//! provenance — the header a written `.tir` carries about where it came
//! from: the tyrekit version, the command line, every input file with its
//! SHA-256 (`sha2` crate), and lines the writing command adds (fitted stages,
//! σ / NRMSE per channel, what the data could not determine). Written as `!`
//! comment lines at the top of the file ([`super::write`]); the start tyre's
//! own header follows, so a version named there (`TIRE_VERSION`) survives.
//!
//! Must never: fail silently on an input it cannot hash (an unreadable input
//! is an error naming it), or write a line break into a header line.

use super::TyreParams;
use crate::error::{Error, Result};
use sha2::{Digest, Sha256};
use std::path::Path;

/// Marker of the first provenance line (also how a re-stamped file's old
/// provenance is recognised and replaced rather than piled up).
pub const MARK: &str = " Written by tyrekit ";

/// Where a written tyre file came from.
#[derive(Clone, Debug, Default)]
pub struct Provenance {
    /// The command line as run (arguments with blanks quoted).
    pub command: String,
    /// Input files: (name as given, SHA-256 hex).
    pub inputs: Vec<(String, String)>,
    /// Further lines (stages, quality, undetermined keys …).
    pub lines: Vec<String>,
}

/// SHA-256 of a file's bytes, lower-case hex.
pub fn sha256_file(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    Ok(sha256_hex(&bytes))
}

/// SHA-256 of bytes, lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// This process's command line, arguments containing blanks single-quoted.
pub fn command_line() -> String {
    std::env::args()
        .enumerate()
        .map(|(i, a)| {
            let a = if i == 0 {
                Path::new(&a)
                    .file_name()
                    .map_or(a.clone(), |f| f.to_string_lossy().into_owned())
            } else {
                a
            };
            if a.contains(char::is_whitespace) || a.is_empty() {
                format!("'{a}'")
            } else {
                a
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

impl Provenance {
    /// The running command and the hashes of `inputs` (recordings, start or
    /// base tyre files).
    pub fn of_inputs<P: AsRef<Path>>(inputs: &[P]) -> Result<Provenance> {
        let mut v = Vec::with_capacity(inputs.len());
        for p in inputs {
            let p = p.as_ref();
            v.push((p.display().to_string(), sha256_file(p)?));
        }
        Ok(Provenance {
            command: command_line(),
            inputs: v,
            lines: Vec::new(),
        })
    }

    /// The header lines (without the `!`).
    pub fn header_lines(&self, start_source: &str) -> Vec<String> {
        let mut h = vec![
            format!("{MARK}{} (SI units)", env!("CARGO_PKG_VERSION")),
            format!(" command: {}", self.command),
        ];
        for (n, s) in &self.inputs {
            h.push(format!(" input: {n}  sha256 {s}"));
        }
        h.push(format!(" start tyre: {start_source}"));
        h.extend(self.lines.iter().map(|l| format!(" {l}")));
        h.into_iter()
            .map(|l| l.replace(['\n', '\r'], " "))
            .collect()
    }

    /// Put the header on `t`: these lines first, then the start tyre's own
    /// header comments (an earlier tyrekit provenance block is replaced).
    pub fn stamp(&self, t: &mut TyreParams) {
        let old = std::mem::take(&mut t.doc.header_comments);
        let mut h = self.header_lines(&t.source);
        let kept: Vec<String> = if old.first().is_some_and(|l| l.starts_with(MARK)) {
            // Drop the old block: it runs to the marker of the start tyre's header.
            let k = old.iter().position(|l| l == START_HEADER);
            k.map_or(Vec::new(), |k| old[k + 1..].to_vec())
        } else {
            old
        };
        if !kept.is_empty() {
            h.push(START_HEADER.to_string());
            h.extend(kept);
        }
        t.doc.header_comments = h;
    }
}

/// Line separating the provenance from the start tyre's own header.
const START_HEADER: &str = " --- header of the start tyre:";
