//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};

/// `../shared` next to the crate, or `$TYREKIT_SHARED` (for worktrees that
/// live elsewhere). Tests skip with a message when it is absent.
pub fn shared() -> PathBuf {
    let p = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared")).to_path_buf();
    match std::env::var_os("TYREKIT_SHARED") {
        Some(s) if !p.exists() => PathBuf::from(s),
        _ => p,
    }
}

/// A CSV number with MATLAB/Octave's NaN/Inf spelling.
#[allow(dead_code)]
pub fn num(s: &str) -> f64 {
    match s {
        "NaN" | "" => f64::NAN,
        "Inf" => f64::INFINITY,
        "-Inf" => f64::NEG_INFINITY,
        _ => s.parse().unwrap_or_else(|_| panic!("bad number {s:?}")),
    }
}

/// The 8 MFeval inputs of a reference CSV row (`col` maps a header name to
/// its index).
#[allow(dead_code)]
pub fn reference_input(r: &[f64], col: impl Fn(&str) -> usize) -> tyrekit::mf::MfInput {
    tyrekit::mf::MfInput {
        fz: r[col("in_Fz")],
        kappa: r[col("in_kappa")],
        alpha: r[col("in_alpha")],
        gamma: r[col("in_gamma")],
        phit: r[col("in_phit")],
        vx: r[col("in_Vx")],
        p: r[col("in_P")],
        omega: r[col("in_omega")],
    }
}
