//! timing — developer timing spans of the fit, printed to stderr only when
//! the environment variable `TYREKIT_TIMING` is set (issue #14, Speed: the
//! per-stage and per-phase breakdown of a staged fit). Each span reports its
//! wall time and the process CPU time (both cores' work) on drop.
//!
//! Must never: print anything when `TYREKIT_TIMING` is unset, change what
//! the fit computes, or keep state between spans (no global mutable state).

use std::time::Instant;

/// Process CPU time in seconds (all threads), from `clock_gettime`.
fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec the call writes into.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// One timed span; prints `timing: LABEL wall … s cpu … s` when dropped.
pub struct Span {
    label: String,
    wall: Instant,
    cpu: f64,
}

impl Drop for Span {
    fn drop(&mut self) {
        eprintln!(
            "timing: {:<40} wall {:8.3} s  cpu {:8.3} s",
            self.label,
            self.wall.elapsed().as_secs_f64(),
            cpu_seconds() - self.cpu
        );
    }
}

/// Whether timing spans are on (`TYREKIT_TIMING` set).
pub fn enabled() -> bool {
    std::env::var_os("TYREKIT_TIMING").is_some()
}

/// A span named by `label()` (only called when timing is on), or `None`.
pub fn span(label: impl FnOnce() -> String) -> Option<Span> {
    enabled().then(|| Span {
        label: label(),
        wall: Instant::now(),
        cpu: cpu_seconds(),
    })
}

/// Print `timing: ` and the line made by `line()` (only called when timing
/// is on): a figure of the run that is not a span (an LM round's costs, a
/// re-estimation round's gain).
pub fn note(line: impl FnOnce() -> String) {
    if enabled() {
        eprintln!("timing: {}", line());
    }
}
