//! Helpers shared by the `tests/tir_*.rs` tests: the shared `.tir` folder and
//! an independent, deliberately naive scan of `KEY = number` lines.
#![allow(dead_code)]

use std::path::PathBuf;

/// `../shared/data/tir` relative to the crate root, if present.
pub fn tir_dir() -> Option<PathBuf> {
    // `../shared` from the project root; `../../shared` when the crate is a
    // git worktree one level further down (work/wt/<branch>).
    let d = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/tir"));
    let d2 = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/data/tir"
    ));
    if d.is_dir() {
        Some(d)
    } else if d2.is_dir() {
        Some(d2)
    } else {
        eprintln!(
            "SKIP: {} is absent, so the tests over the shared .tir files do not run",
            d.display()
        );
        None
    }
}

/// Every `.tir`/`.TIR` file of the shared folder, sorted by name.
pub fn tir_files() -> Vec<PathBuf> {
    let Some(d) = tir_dir() else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = std::fs::read_dir(&d)
        .expect("shared tir folder readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .map(|x| x.eq_ignore_ascii_case("tir"))
                .unwrap_or(false)
        })
        .collect();
    v.sort();
    v
}

pub fn file_name(p: &std::path::Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// The last numeric value written for `key` on a line of its own
/// (`KEY = number`, optional `$` comment), scanning the raw text line by line
/// without the crate's parser. Comment lines (`$`, `!`) are skipped.
pub fn scan_last_number(text: &str, key: &str) -> Option<f64> {
    let mut found = None;
    for line in text.lines() {
        let l = line.trim();
        if l.starts_with('$') || l.starts_with('!') {
            continue;
        }
        let Some(rest) = l.strip_prefix(key) else {
            continue;
        };
        let rest = rest.trim_start();
        let Some(rhs) = rest.strip_prefix('=') else {
            continue;
        };
        let rhs = rhs.split('$').next().unwrap_or("").trim();
        if let Ok(x) = rhs.parse::<f64>() {
            found = Some(x);
        }
    }
    found
}
